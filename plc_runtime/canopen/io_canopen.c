/* io_canopen.c: the `canopen` I/O backend of plcrt. Nodes and bindings come
 * from the configuration file ([canopen] and [canopen.NAME] sections, see
 * docs/canopen.md); the master itself is the frame-level core (co_master.h)
 * on a SocketCAN raw socket.
 * Scan thread: read_inputs drains the socket, advances time-outs and copies
 * the TPDO data received since the last cycle into the %I areas;
 * write_outputs packs the %Q areas into RPDOs and sends them, then SYNC.
 * Messages the master produces in the scan go through a lock-free queue
 * to a small logging thread that prints them: the scan never waits on it. */
#include <errno.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include "io_backend.h"
#include "log.h"
#include "co_master.h"
#include "co_socketcan.h"
#include "eds.h"

#define MAX_NODES 32
#define MAX_BINDS 256
#define LOGQ 64

typedef struct bind {
    uint8_t node;           /* index in nodes[] */
    uint8_t tx;             /* 1: input from a TPDO, 0: output to an RPDO */
    uint8_t pdo;            /* 0..3 */
    uint8_t bits;           /* width of the mapped object */
    uint16_t off;           /* bit offset of the object in the PDO (+ bit) */
    int8_t bit;             /* -1: whole object; 0..63: one bit of it */
    uint16_t index;
    uint8_t sub;
    plc_loc loc;
} bind;

typedef struct nodecfg_ex {
    char name[32];
    int has_id, pdo_given;  /* pdo_given: some rpdoN/tpdoN key was set */
    int hb_given;           /* a heartbeat_* key was set */
    int guard_given;        /* guard_time_ms was set */
    int drivetype;          /* seed 000 DRIVETYPE +-91..94 of an APOSS axis on this node, or 0 */
    long encodertype;       /* seed 000 ENCODERTYPE of an APOSS axis whose encoder is this node, or 0 */
    int enc_dev, enc_id;    /* its device type (50: CiA 406) and node id */
    char enc_text[24];      /* as written, for messages */
    char eds[256];          /* the node's EDS/DCF file, or "" */
    plc_loc status, ok;
    int has_status, has_ok;
} nodecfg_ex;

typedef struct st {
    char ifname[32];
    unsigned sync_every;
    unsigned boot_ms, sdo_ms, wait_ms;
    unsigned cansynctimer_ms;   /* SYNC period in ms (seed 000 CANSYNCTIMER); 0 = sync_every */
    int nnodes;
    co_node nodes[MAX_NODES];
    nodecfg_ex ex[MAX_NODES];
    int nbinds;
    bind binds[MAX_BINDS];
    int fd;
    int link_down;
    co_frame pending;
    int have_pending;
    co_master m;
    co_time last_poll;      /* when poll_bus last read the bus */
    /* log queue: one producer (the scan thread) and one consumer (the
       logging thread), lock-free: the scan never waits for the logger */
    pthread_t logger;
    int logger_on;
    atomic_int quit;
    atomic_uint lq_head, lq_tail, lq_lost;
    struct { int err; char msg[200]; } lq[LOGQ];
    int direct_log;         /* main thread phases: print at once */
} st;

static co_time mono(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (co_time)ts.tv_sec * 1000000000ull + (co_time)ts.tv_nsec;
}

static void logcb(void *ctx, int err, const char *msg)
{
    st *s = ctx;
    if (s->direct_log) {
        plc_log(err ? LOG_ERROR : LOG_INFO, "canopen: %s", msg);
        return;
    }
    unsigned t = atomic_load_explicit(&s->lq_tail, memory_order_relaxed);
    if (t - atomic_load_explicit(&s->lq_head, memory_order_acquire) >= LOGQ) {
        atomic_fetch_add_explicit(&s->lq_lost, 1, memory_order_relaxed);
        return;
    }
    s->lq[t % LOGQ].err = err;
    snprintf(s->lq[t % LOGQ].msg, sizeof s->lq[t % LOGQ].msg, "%s", msg);
    atomic_store_explicit(&s->lq_tail, t + 1, memory_order_release);    /* the slot is written */
}

static void *logger(void *arg)
{
    st *s = arg;
    for (;;) {
        int err = 0, have = 0, quit = atomic_load(&s->quit);
        char msg[200];
        unsigned h = atomic_load_explicit(&s->lq_head, memory_order_relaxed);
        if (h != atomic_load_explicit(&s->lq_tail, memory_order_acquire)) {
            err = s->lq[h % LOGQ].err;
            memcpy(msg, s->lq[h % LOGQ].msg, sizeof msg);
            atomic_store_explicit(&s->lq_head, h + 1, memory_order_release);  /* the slot is free */
            have = 1;
        }
        unsigned lost = atomic_exchange_explicit(&s->lq_lost, 0, memory_order_relaxed);
        if (have)
            plc_log(err ? LOG_ERROR : LOG_INFO, "canopen: %s", msg);
        if (lost)
            plc_log(LOG_WARN, "canopen: %u messages dropped", lost);
        if (!have) {
            if (quit)
                return NULL;
            usleep(20000);
        }
    }
}

static void *create(void)
{
    st *s = calloc(1, sizeof *s);
    if (!s)
        return NULL;
    strcpy(s->ifname, "can0");
    s->sync_every = 1;
    s->boot_ms = 2000;
    s->sdo_ms = 500;
    s->wait_ms = 5000;
    s->fd = -1;
    return s;
}

static int num(const char *v, unsigned long max, unsigned long *out, char *err, size_t n)
{
    char *end;
    errno = 0;
    /* decimal, or hexadecimal with 0x: never octal, so that id = 010 is
    ** node 10 (as every other integer of the file), not node 8 */
    int hex = v[0] == '0' && (v[1] == 'x' || v[1] == 'X');
    unsigned long x = strtoul(v, &end, hex ? 16 : 10);
    while (*end == ' ' || *end == '\t')
        end++;
    if (errno || end == v || *end || *v == '-' || x > max) {
        snprintf(err, n, "'%s' is not a number in 0..%lu", v, max);
        return -1;
    }
    *out = x;
    return 0;
}

/* "0x6200:01" -> index, sub */
static int parse_obj(const char **p, uint16_t *index, uint8_t *sub)
{
    char *end;
    unsigned long i = strtoul(*p, &end, 16);
    if (end == *p || *end != ':' || i > 0xFFFF)
        return -1;
    const char *q = end + 1;
    unsigned long s = strtoul(q, &end, 16);
    if (end == q || s > 0xFF)
        return -1;
    *index = (uint16_t)i;
    *sub = (uint8_t)s;
    *p = end;
    return 0;
}

/* "0x6411:01:16 0x6411:02:16 ..." or "none" */
static int parse_map(const char *v, co_pdo_map *m, char *err, size_t n)
{
    memset(m, 0, sizeof *m);
    m->trans = 1;
    if (!strcmp(v, "none"))
        return 0;
    const char *p = v;
    while (*p) {
        while (*p == ' ' || *p == ',' || *p == '\t')
            p++;
        if (!*p)
            break;
        if (m->n >= CO_PDO_MAX_ENTRIES) {
            snprintf(err, n, "more than %d mapped objects", CO_PDO_MAX_ENTRIES);
            return -1;
        }
        co_map_entry *e = &m->e[m->n];
        char *end;
        if (parse_obj(&p, &e->index, &e->sub) || *p != ':') {
            snprintf(err, n, "'%s': expected entries INDEX:SUB:BITS (hex index and sub), or none", v);
            return -1;
        }
        unsigned long b = strtoul(p + 1, &end, 10);
        if (end == p + 1 || b < 1 || b > 64) {
            snprintf(err, n, "'%s': the width of 0x%04X:%02X must be 1..64 bits", v, e->index, e->sub);
            return -1;
        }
        e->bits = (uint8_t)b;
        p = end;
        m->n++;
    }
    return co_pdo_check(m, err, n);
}

static int node_of(st *s, const char *section, char *err, size_t n)
{
    for (int i = 0; i < s->nnodes; i++)
        if (!strcmp(s->ex[i].name, section))
            return i;
    if (s->nnodes >= MAX_NODES) {
        snprintf(err, n, "more than %d nodes", MAX_NODES);
        return -1;
    }
    int i = s->nnodes++;
    memset(&s->nodes[i], 0, sizeof s->nodes[i]);
    co_node_cfg_cia401(&s->nodes[i].cfg, 0);
    snprintf(s->ex[i].name, sizeof s->ex[i].name, "%s", section);
    return i;
}

static int config(void *vs, const char *section, const char *key, const char *v, char *err, size_t n)
{
    st *s = vs;
    unsigned long x;
    if (!strcmp(section, "canopen")) {
        if (!strcmp(key, "interface")) {
            if (!*v || strlen(v) >= 16) {
                snprintf(err, n, "'%s' is not an interface name", v);
                return -1;
            }
            snprintf(s->ifname, sizeof s->ifname, "%s", v);
            return 0;
        }
        unsigned *dst = !strcmp(key, "sync_every") ? &s->sync_every
                      : !strcmp(key, "boot_timeout_ms") ? &s->boot_ms
                      : !strcmp(key, "sdo_timeout_ms") ? &s->sdo_ms
                      : !strcmp(key, "startup_wait_ms") ? &s->wait_ms
                      : !strcmp(key, "cansynctimer_ms") ? &s->cansynctimer_ms : NULL;
        if (!dst) {
            snprintf(err, n, "unknown key (known: interface, sync_every, cansynctimer_ms, boot_timeout_ms, "
                     "sdo_timeout_ms, startup_wait_ms)");
            return -1;
        }
        if (num(v, 600000, &x, err, n))
            return -1;
        *dst = (unsigned)x;
        return 0;
    }
    int i = node_of(s, section, err, n);
    if (i < 0)
        return -1;
    co_node_cfg *c = &s->nodes[i].cfg;
    nodecfg_ex *ex = &s->ex[i];
    if (!strcmp(key, "id")) {
        if (num(v, 127, &x, err, n) || x < 1) {
            snprintf(err, n, "node id '%s' must be 1..127", v);
            return -1;
        }
        c->id = (uint8_t)x;
        ex->has_id = 1;
        return 0;
    }
    if (!strcmp(key, "device_type")) {
        if (num(v, 0xFFFFFFFFul, &x, err, n))
            return -1;
        c->device_type = (uint32_t)x;
        c->check_type = 1;
        return 0;
    }
    if (!strcmp(key, "heartbeat_producer_ms") || !strcmp(key, "heartbeat_consumer_ms")) {
        if (num(v, 65535, &x, err, n))
            return -1;
        if (key[10] == 'p')
            c->hb_producer_ms = (uint16_t)x;
        else
            c->hb_consumer_ms = (uint16_t)x;
        ex->hb_given = 1;
        return 0;
    }
    if (!strcmp(key, "guard_time_ms")) {
        if (num(v, 65535, &x, err, n))
            return -1;
        c->guard_ms = (uint16_t)x;
        ex->guard_given = 1;
        return 0;
    }
    if (!strcmp(key, "eds")) {
        if (!*v || strlen(v) >= sizeof ex->eds) {
            snprintf(err, n, "'%s': expected the path of the node's EDS or DCF file", v);
            return -1;
        }
        snprintf(ex->eds, sizeof ex->eds, "%s", v);
        return 0;
    }
    if (!strcmp(key, "drivetype")) {
        char *end;
        long d = strtol(v, &end, 10);
        if (end == v || *end || labs(d) < 91 || labs(d) > 94) {
            snprintf(err, n, "drivetype '%s': seed 000's CANopen I/O module drive types are 91..94 (analog "
                     "output 1..4, guarded) or -91..-94 (without guarding)", v);
            return -1;
        }
        ex->drivetype = (int)d;
        return 0;
    }
    if (!strcmp(key, "encodertype")) {
        char *end;
        long d = strtol(v, &end, 10);
        long a = labs(d) % 100000, dev = a / 1000, id = a % 1000;
        if (end == v || *end || labs(d) > 199999 || dev < 1 || dev > 50 || id < 1 || id > 127) {
            snprintf(err, n, "encodertype '%s': seed 000's bus encoders are guard x (busoffset + device type "
                     "x 1000 + id): guard +1 (guarded) or -1, busoffset 0 or 100000, device type 1..50 "
                     "(50 a CiA 406 encoder), id the node's, e.g. 50005 or -50005 for a CiA 406 encoder on node 5", v);
            return -1;
        }
        ex->encodertype = d;
        ex->enc_dev = (int)dev;
        ex->enc_id = (int)id;
        snprintf(ex->enc_text, sizeof ex->enc_text, "%ld", d);
        return 0;
    }
    if (!strcmp(key, "life_factor")) {
        if (num(v, 255, &x, err, n) || x < 1) {
            snprintf(err, n, "life factor '%s' must be 1..255", v);
            return -1;
        }
        c->life_factor = (uint8_t)x;
        return 0;
    }
    if ((!strncmp(key, "rpdo", 4) || !strncmp(key, "tpdo", 4)) && key[4] >= '1' && key[4] <= '4' && !key[5]) {
        int tx = key[0] == 't';
        co_pdo_map *m = tx ? &c->tpdo[key[4] - '1'] : &c->rpdo[key[4] - '1'];
        if (!ex->pdo_given) {               /* the first PDO key drops the defaults */
            memset(c->rpdo, 0, sizeof c->rpdo);
            memset(c->tpdo, 0, sizeof c->tpdo);
            ex->pdo_given = 1;
        }
        return parse_map(v, m, err, n);
    }
    if (!strcmp(key, "status") || !strcmp(key, "ok")) {
        plc_loc l;
        int is_ok = key[0] == 'o';
        if (plc_loc_parse(v, &l) || l.area != 'I' || (is_ok ? l.size != 'X' : l.size != 'W')) {
            snprintf(err, n, "'%s' is not an input %s (e.g. %s)", v, is_ok ? "bit" : "word",
                     is_ok ? "%IX10.0" : "%IW20");
            return -1;
        }
        if (is_ok) { ex->ok = l; ex->has_ok = 1; } else { ex->status = l; ex->has_status = 1; }
        return 0;
    }
    if (!strcmp(key, "bind")) {
        /* "INDEX:SUB[.BIT] %LOC" */
        bind *b = &s->binds[s->nbinds];
        const char *p = v;
        if (s->nbinds >= MAX_BINDS) {
            snprintf(err, n, "more than %d bindings", MAX_BINDS);
            return -1;
        }
        memset(b, 0, sizeof *b);
        b->bit = -1;
        if (parse_obj(&p, &b->index, &b->sub)) {
            snprintf(err, n, "'%s': expected INDEX:SUB[.BIT] %%LOCATION, e.g. 0x6200:01 %%QB0", v);
            return -1;
        }
        if (*p == '.') {
            char *end;
            unsigned long bit = strtoul(p + 1, &end, 10);
            if (end == p + 1 || bit > 63) {
                snprintf(err, n, "'%s': bit number must be 0..63", v);
                return -1;
            }
            b->bit = (int8_t)bit;
            p = end;
        }
        while (*p == ' ' || *p == '\t')
            p++;
        if (plc_loc_parse(p, &b->loc) || b->loc.area == 'M') {
            snprintf(err, n, "'%s' is not an %%I or %%Q location", p);
            return -1;
        }
        b->node = (uint8_t)i;
        s->nbinds++;
        return 0;
    }
    snprintf(err, n, "unknown key (known: id, device_type, heartbeat_producer_ms, "
             "heartbeat_consumer_ms, guard_time_ms, life_factor, drivetype, encodertype, eds, rpdo1..4, tpdo1..4, bind, "
             "status, ok)");
    return -1;
}

/* find the mapped object of a binding; 0 or -1 with a message */
static int resolve(st *s, bind *b, char *err, size_t n)
{
    co_node_cfg *c = &s->nodes[b->node].cfg;
    b->tx = b->loc.area == 'I';
    for (unsigned k = 0; k < CO_PDO_PER_NODE; k++) {
        const co_pdo_map *m = b->tx ? &c->tpdo[k] : &c->rpdo[k];
        for (unsigned e = 0; e < m->n; e++)
            if (m->e[e].index == b->index && m->e[e].sub == b->sub) {
                b->pdo = (uint8_t)k;
                b->bits = m->e[e].bits;
                b->off = (uint16_t)co_pdo_offset(m, e);
                unsigned w = b->loc.size == 'X' ? 1 : plc_loc_width(&b->loc) * 8;
                if (b->bit >= 0) {
                    if (b->bit >= b->bits || w != 1) {
                        snprintf(err, n, "[%s] bind 0x%04X:%02X.%d: %s", s->ex[b->node].name,
                                 b->index, b->sub, b->bit, w != 1 ? "a bit binds to an X location"
                                 : "bit beyond the object's width");
                        return -1;
                    }
                } else if (b->bits > w) {
                    snprintf(err, n, "[%s] bind 0x%04X:%02X: %u-bit object does not fit a %u-bit location",
                             s->ex[b->node].name, b->index, b->sub, b->bits, w);
                    return -1;
                }
                return 0;
            }
    }
    snprintf(err, n, "[%s] bind 0x%04X:%02X: object not mapped in any %s of node %u",
             s->ex[b->node].name, b->index, b->sub, b->tx ? "TPDO (for an input)" : "RPDO (for an output)",
             c->id);
    return -1;
}

static void flush(st *s)
{
    for (;;) {
        if (!s->have_pending && !co_master_pop(&s->m, &s->pending))
            return;
        s->have_pending = 1;
        int r = co_can_send(s->fd, &s->pending);
        if (r == 0)
            return;                 /* controller queue full: next cycle */
        s->have_pending = 0;
        if (r < 0) {
            if (!s->link_down) {
                s->link_down = 1;
                co_master_bus(&s->m, CO_BUS_DOWN, "interface down");
            }
            while (co_master_pop(&s->m, &s->pending))
                ;                   /* drop: nothing reaches the bus */
            return;
        }
    }
}

static void poll_bus(st *s)
{
    co_frame f;
    co_time now = mono(), age;
    int r;
    /* each frame at the time it arrived (a guarding answer, a heartbeat,
     * an SDO reply count from then, not from this scan), but not before
     * the last look at the bus: a wall clock stepped forward must not
     * date a frame into the past */
    while ((r = co_can_recv(s->fd, &f, &age)) == 1)
        co_master_rx(&s->m, &f, age < now - s->last_poll ? now - age : s->last_poll);
    if (r < 0 || s->link_down) {
        int up = co_can_link_up(s->fd, s->ifname);
        if (up != 1 && !s->link_down) {
            s->link_down = 1;
            co_master_bus(&s->m, CO_BUS_DOWN, "interface down");
        } else if (up == 1 && s->link_down) {
            s->link_down = 0;
            co_master_bus(&s->m, CO_BUS_OK, "interface up again");
        }
    }
    co_master_tick(&s->m, now);
    s->last_poll = now;
}

static void loc_text(const plc_loc *l, char *out, size_t n)
{
    if (l->size == 'X')
        snprintf(out, n, "%%%cX%u.%u", l->area, l->index, l->bit);
    else
        snprintf(out, n, "%%%c%c%u", l->area, l->size, l->index);
}

/* Every input the master writes into the image (bind to an %I location,
** status, ok) in a place of its own: two nodes bound to one input (a
** section copied and not edited) would leave the program the second one's
** values only, without a word. (Outputs may repeat: one %Q driving two
** objects.) 0, or -1 naming both. */
static int list_inputs(void *vs, plc_image *img, io_input_use *in, int max)
{
    st *s = vs;
    int k = 0;
    char t[32];
    for (int i = 0; i < s->nbinds; i++) {
        const bind *b = &s->binds[i];
        if (b->loc.area != 'I' || k >= max)
            continue;
        loc_text(&b->loc, t, sizeof t);
        in[k].p = plc_loc_ptr(img, &b->loc);
        in[k].w = plc_loc_width(&b->loc);
        if (b->bit >= 0)
            snprintf(in[k++].who, sizeof in[0].who, "[%.40s] bind 0x%04X:%02X.%d %s", s->ex[b->node].name, b->index,
                     b->sub, b->bit, t);
        else
            snprintf(in[k++].who, sizeof in[0].who, "[%.40s] bind 0x%04X:%02X %s", s->ex[b->node].name, b->index,
                     b->sub, t);
    }
    for (int i = 0; i < s->nnodes; i++)
        for (int j = 0; j < 2; j++) {
            const plc_loc *l = j ? &s->ex[i].ok : &s->ex[i].status;
            if (!(j ? s->ex[i].has_ok : s->ex[i].has_status) || k >= max)
                continue;
            loc_text(l, t, sizeof t);
            in[k].p = plc_loc_ptr(img, l);
            in[k].w = plc_loc_width(l);
            snprintf(in[k++].who, sizeof in[0].who, "[%.40s] %s %s", s->ex[i].name, j ? "ok" : "status", t);
        }
    return k;
}

static int inputs_apart(st *s, plc_image *img, char *err, size_t n)
{
    io_input_use in[MAX_BINDS + 2 * MAX_NODES];
    return io_inputs_apart(in, list_inputs(s, img, in, (int)(sizeof in / sizeof in[0])), err, n);
}

/* the node's EDS/DCF: device type (unless device_type is given), PDO
** mappings (unless rpdoN/tpdoN keys are), start-up SDO writes */
static int use_eds(st *s, int i, char *err, size_t n)
{
    co_node_cfg *c = &s->nodes[i].cfg;
    nodecfg_ex *ex = &s->ex[i];
    eds_info *e = malloc(sizeof *e);
    char m[400];
    if (!e) {
        snprintf(err, n, "[%s] eds: out of memory", ex->name);
        return -1;
    }
    if (eds_load(ex->eds, c->id, e, m, sizeof m)) {
        snprintf(err, n, "[%s] eds (node %u): %s", ex->name, c->id, m);
        free(e);
        return -1;
    }
    if (e->has_device_type && !c->check_type) {
        c->device_type = e->device_type;
        c->check_type = 1;
    }
    if (e->has_pdo && !ex->pdo_given) {
        memcpy(c->rpdo, e->rpdo, sizeof c->rpdo);
        memcpy(c->tpdo, e->tpdo, sizeof c->tpdo);
    }
    for (int k = 0; k < e->nwrites; k++) {
        if (c->nextra >= sizeof c->extra / sizeof c->extra[0]) {
            snprintf(err, n, "[%s] eds %s: more than %zu start-up writes", ex->name, ex->eds,
                     sizeof c->extra / sizeof c->extra[0]);
            free(e);
            return -1;
        }
        c->extra[c->nextra++] = e->w[k];
    }
    free(e);
    return 0;
}

/* seed 000 ENCODERTYPE: the id in it is the node's; a CiA 406 encoder
   (device type 50) without PDO keys or EDS gets its position value 0x6004
   in TPDO2, synchronous, as CiA 406 predefines it and the seed's "data
   exchange via PDO 2" says; every other PDO is switched off */
static int encoder_node(st *s, int i, char *err, size_t n)
{
    co_node_cfg *c = &s->nodes[i].cfg;
    nodecfg_ex *ex = &s->ex[i];
    if (ex->enc_id != c->id) {
        snprintf(err, n, "[%s] encodertype %s names node %d, but the section's id is %u: write "
                 "encodertype = %ld", ex->name, ex->enc_text, ex->enc_id, c->id,
                 (ex->encodertype < 0 ? -1 : 1) * (labs(ex->encodertype) - ex->enc_id + c->id));
        return -1;
    }
    if (ex->enc_dev == 50 && !ex->pdo_given && !ex->eds[0]) {
        memset(c->rpdo, 0, sizeof c->rpdo);
        memset(c->tpdo, 0, sizeof c->tpdo);
        for (unsigned k = 0; k < CO_PDO_PER_NODE; k++)
            c->rpdo[k].trans = c->tpdo[k].trans = 1;
        c->tpdo[1].n = 1;
        c->tpdo[1].e[0] = (co_map_entry){ 0x6004, 0, 32 };
    }
    return 0;
}

/* the position value must reach the program: a bind of a 32-bit TPDO object
   (0x6004:00 for a CiA 406 encoder) to a double word */
static int encoder_bound(st *s, int i, char *err, size_t n)
{
    nodecfg_ex *ex = &s->ex[i];
    int enc406 = ex->enc_dev == 50;
    for (int k = 0; k < s->nbinds; k++) {
        const bind *b = &s->binds[k];
        if (b->node != i || !b->tx || b->bit >= 0 || b->bits != 32)
            continue;
        if (!enc406 || (b->index == 0x6004 && b->sub == 0))
            return 0;
    }
    snprintf(err, n, "[%s] encodertype %s: no 32-bit position value bound to the program: add %s",
             ex->name, ex->enc_text, enc406 ? "bind = 0x6004:00 %ID0 (the encoder's position value, "
             "in its TPDO2)" : "a tpdoN key mapping the drive's position (e.g. 0x6064:00:32) and bind = "
             "0x6064:00 %ID0");
    return -1;
}

static int open_(void *vs, plc_image *img, uint64_t tick, char *err, size_t n)
{
    st *s = vs;
    if (!s->nnodes) {
        snprintf(err, n, "no node configured (add a [canopen.NAME] section with id = ...)");
        return -1;
    }
    for (int i = 0; i < s->nnodes; i++) {
        if (!s->ex[i].has_id) {
            snprintf(err, n, "[%s]: no id", s->ex[i].name);
            return -1;
        }
        co_node_cfg *c = &s->nodes[i].cfg;
        if (s->ex[i].eds[0] && use_eds(s, i, err, n))
            return -1;
        if (s->ex[i].encodertype && encoder_node(s, i, err, n))
            return -1;
        if ((s->ex[i].drivetype || s->ex[i].encodertype) && !s->ex[i].hb_given) {
            /* seed 000: the module is guarded (DRIVETYPE or ENCODERTYPE > 0)
               or not watched at all */
            int guarded = s->ex[i].drivetype > 0 || s->ex[i].encodertype > 0;
            if (guarded && !s->ex[i].guard_given)
                c->guard_ms = 100;
            if (!guarded)
                c->guard_ms = 0;
            c->hb_producer_ms = 0;
            c->hb_consumer_ms = 0;
        }
        if (c->guard_ms && !s->ex[i].hb_given) {
            c->hb_producer_ms = 0;          /* guarded: no heartbeat by default */
            c->hb_consumer_ms = 0;
        } else if (c->guard_ms && (c->hb_producer_ms || c->hb_consumer_ms)) {
            snprintf(err, n, "[%s]: guard_time_ms with a heartbeat: node %u is watched either by node guarding "
                     "or by its heartbeat (CiA 301); set heartbeat_producer_ms and heartbeat_consumer_ms to 0, "
                     "or drop guard_time_ms", s->ex[i].name, c->id);
            return -1;
        }
        for (int j = 0; j < i; j++)
            if (s->nodes[j].cfg.id == s->nodes[i].cfg.id) {
                snprintf(err, n, "[%s] and [%s] both have id %u", s->ex[j].name, s->ex[i].name,
                         s->nodes[i].cfg.id);
                return -1;
            }
    }
    for (int i = 0; i < s->nbinds; i++)
        if (resolve(s, &s->binds[i], err, n))
            return -1;
    for (int i = 0; i < s->nnodes; i++)
        if (s->ex[i].encodertype && encoder_bound(s, i, err, n))
            return -1;
    if (inputs_apart(s, img, err, n))
        return -1;
    if (s->cansynctimer_ms) {
        uint64_t p = (uint64_t)s->cansynctimer_ms * 1000000u;
        if (!tick || p % tick) {
            snprintf(err, n, "cansynctimer_ms = %u is not a whole number of PLC cycles (%.3f ms): SYNC goes "
                     "out with the cycle's outputs", s->cansynctimer_ms, (double)tick / 1e6);
            return -1;
        }
        s->sync_every = (unsigned)(p / tick);
    }
    s->fd = co_can_open(s->ifname, err, n);
    if (s->fd < 0)
        return -1;
    co_master_init(&s->m, s->nodes, s->nnodes, s->sync_every);
    s->m.boot_timeout = (co_time)s->boot_ms * CO_MS;
    s->m.sdo_timeout = (co_time)s->sdo_ms * CO_MS;
    for (int i = 0; i < s->nnodes; i++)
        s->nodes[i].sdo.timeout = s->m.sdo_timeout;
    s->m.log = logcb;
    s->m.log_ctx = s;
    s->direct_log = 1;
    /* start-up in the main thread: every node configured, or reported */
    co_time t0 = mono();
    co_master_start(&s->m, t0);
    while (!co_master_settled(&s->m) && mono() - t0 < (co_time)s->wait_ms * CO_MS) {
        flush(s);
        co_can_wait(s->fd, 2000000);
        poll_bus(s);
    }
    flush(s);
    int up = 0;
    for (int i = 0; i < s->nnodes; i++)
        up += s->nodes[i].phase == CO_PH_RUN;
    plc_log(up == s->nnodes ? LOG_INFO : LOG_ERROR, "canopen: %s: %d of %d nodes operational",
            s->ifname, up, s->nnodes);
    (void)img;
    s->direct_log = 0;
    if (pthread_create(&s->logger, NULL, logger, s) == 0)
        s->logger_on = 1;
    else
        s->direct_log = 1;
    return 0;
}

static int rd(void *vs, plc_image *img, uint64_t now_ns)
{
    st *s = vs;
    (void)now_ns;
    poll_bus(s);
    for (int i = 0; i < s->nbinds; i++) {
        bind *b = &s->binds[i];
        co_node *nd = &s->nodes[b->node];
        if (!b->tx || !(nd->rx_new & (1 << b->pdo)))
            continue;
        uint64_t v = co_bits_get(nd->rx[b->pdo], b->off, b->bits);
        uint8_t *p = plc_loc_ptr(img, &b->loc);
        if (b->bit >= 0)
            *p = (uint8_t)(v >> b->bit & 1);
        else if (b->loc.size == 'X')
            *p = (uint8_t)(v & 1);
        else {
            unsigned w = plc_loc_width(&b->loc);
            uint8_t tmp[8];
            for (unsigned k = 0; k < 8; k++)
                tmp[k] = (uint8_t)(v >> (8 * k));      /* image: host order (LE) */
            memcpy(p, tmp, w);
        }
    }
    for (int i = 0; i < s->nnodes; i++) {
        co_node *nd = &s->nodes[i];
        unsigned fresh = nd->rx_new ? 0x80 : 0;    /* bit 7: a TPDO came since the last cycle */
        nd->rx_new = 0;
        if (s->ex[i].has_status) {
            uint16_t w = (uint16_t)(nd->fault | fresh | nd->phase << 8);
            memcpy(plc_loc_ptr(img, &s->ex[i].status), &w, 2);
        }
        if (s->ex[i].has_ok)
            *plc_loc_ptr(img, &s->ex[i].ok) = nd->phase == CO_PH_RUN && !s->link_down
                                              && s->m.bus != CO_BUS_OFF;
    }
    return 0;
}

static int wr(void *vs, const plc_image *img)
{
    st *s = vs;
    for (int i = 0; i < s->nbinds; i++) {
        bind *b = &s->binds[i];
        if (b->tx)
            continue;
        co_node *nd = &s->nodes[b->node];
        const uint8_t *p = plc_loc_ptr((plc_image *)img, &b->loc);
        if (b->bit >= 0) {
            co_bits_put(nd->tx[b->pdo], b->off + (unsigned)b->bit, 1, *p & 1);
            continue;
        }
        uint64_t v = 0;
        if (b->loc.size == 'X')
            v = *p & 1;
        else
            for (unsigned k = 0; k < plc_loc_width(&b->loc); k++)
                v |= (uint64_t)p[k] << (8 * k);
        co_bits_put(nd->tx[b->pdo], b->off, b->bits, v);
    }
    co_master_cycle(&s->m, mono());
    flush(s);
    return 0;
}

static void safe(void *vs, plc_image *img)
{
    st *s = vs;
    (void)img;
    if (s->fd < 0)
        return;
    for (int i = 0; i < s->nnodes; i++)
        memset(s->nodes[i].tx, 0, sizeof s->nodes[i].tx);
    s->m.sync.phase = s->m.sync.every ? s->m.sync.every - 1 : 0;   /* SYNC now */
    co_master_cycle(&s->m, mono());
    for (int k = 0; k < 50 && (s->have_pending || s->m.qh != s->m.qt); k++) {
        flush(s);
        usleep(1000);
    }
    plc_log(LOG_INFO, "canopen: outputs of all nodes set to 0");
}

static void close_(void *vs)
{
    st *s = vs;
    if (s->logger_on) {
        atomic_store(&s->quit, 1);
        pthread_join(s->logger, NULL);
    }
    if (s->fd >= 0)
        close(s->fd);
    free(s);
}

/* 4 bus registers, then 6 per node for the first 10 nodes (docs/canopen.md) */
static size_t diag(void *vs, uint16_t *r, size_t max)
{
    st *s = vs;
    size_t k = 0;
#define PUT(v) do { if (k < max) r[k++] = (uint16_t)(v); } while (0)
    int up = 0;
    for (int i = 0; i < s->nnodes; i++)
        up += s->nodes[i].phase == CO_PH_RUN;
    PUT(s->m.bus);
    PUT(s->m.busoff_count);
    PUT(s->nnodes);
    PUT(up);
    for (int i = 0; i < s->nnodes && i < 10; i++) {
        co_node *nd = &s->nodes[i];
        PUT(nd->cfg.id | nd->phase << 8);
        PUT(nd->fault);
        PUT(nd->unexpected_boot);
        PUT(nd->hb_lost);
        PUT(nd->emcy_count);
        PUT(nd->last_emcy.code);
    }
#undef PUT
    return k;
}

const io_backend_ops io_canopen = {
    "canopen", create, config, open_, rd, wr, safe, close_, diag, list_inputs
};
