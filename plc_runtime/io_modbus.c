/*
** io_modbus.c: the `modbus_io` backend: remote I/O modules polled as a
** Modbus master (libmodbus), over TCP or RTU, one [modbus_io.NAME] section
** per device (docs/remote-io.md).
**
** The idea: the scan never talks to a device. Each line (a TCP device, or
** a serial port with the slaves that share it) has a thread that polls its
** devices; a device and the scan trade whole buffers through atomic index
** swaps (triple buffers, as mbmap.h does with the Modbus server): the poll
** thread publishes each complete round of inputs with its `ok` state and
** time, the scan publishes the device's outputs every cycle. Neither ever
** waits for the other.
**
** Faults (no answer, late or stalled answer, exception, garbage, CRC error,
** disconnection) drop the device's `ok` at once; its inputs hold their last
** value, or take their safe values once `safe_after_ms` passed without an
** answer. Each fault is counted, and logged once when the device is lost
** and once when it is back. A lost TCP device is reconnected, a lost RTU
** slave retried, after a back-off that doubles from 100 ms up to
** `reconnect_max_ms`; when it answers again every output is written anew.
*/
#include <errno.h>
#include <modbus.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>
#include "config.h"
#include "io_backend.h"
#include "log.h"

#define MBIO_DEVICES 60
#define MBIO_BLOCKS 32          /* read and write blocks of one device */
#define MBIO_VALS 4096          /* registers and bits of one device, each way */
#define FRESH 4u

enum { T_COIL, T_DISCRETE, T_INPUT, T_HOLDING };
static const char *tables[] = { "coil", "discrete", "input", "holding" };

typedef struct blk {
    int write;                  /* 0 read, 1 write */
    int table;                  /* T_* */
    unsigned start, count;      /* Modbus address and count */
    plc_loc loc;                /* the first image location */
    long long safe;             /* read: value after safe_after_ms */
    unsigned off;               /* into the device's value arrays */
    char text[80];              /* "read input 0 2 %ID0", for messages */
} blk;

typedef struct line line;

typedef struct dev {
    char name[48];
    int has_host, has_device, has_unit, has_slave;
    char host[128];
    int port, unit;
    char device[128];
    int baud, data_bits, stop_bits;
    char parity;
    int period_ms, timeout_ms, reconnect_max_ms, safe_after_ms;
    int low_first;              /* 32-bit values: low word first */
    int has_ok;
    plc_loc ok;
    blk b[MBIO_BLOCKS];
    int nb;
    unsigned nin, nout;         /* values read, values written */
    line *ln;
    /* inputs: poll thread -> scan */
    uint16_t *ibuf[3];
    uint8_t iok[3];
    uint64_t istamp[3];
    _Atomic unsigned imid;
    unsigned iback, ifront;     /* poll thread's, scan's */
    /* outputs: scan -> poll thread */
    uint16_t *obuf[3];
    _Atomic unsigned omid;
    unsigned oback, ofront;
    int out_seen;               /* poll: an output buffer has arrived */
    uint16_t *written;          /* poll: the values last written */
    uint64_t *wrote_ns;         /* poll: per block, when last written */
    uint16_t *work;             /* poll: the round being read */
    uint16_t *last;             /* poll: the last good inputs */
    /* poll thread's state */
    int good;                   /* 1 after a good round, 0 after a fault */
    int safe_out;               /* the safe values are published */
    int rewrite;                /* every output to be written again */
    uint64_t next_ns, retry_ns, backoff_ns, last_good_ns, lost_ns;
    /* counters (poll thread writes, scan reads) */
    _Atomic uint32_t rounds, timeouts, exceptions, bad_frames, losses, last_exc, round_us, ok_now;
    /* scan's */
    uint64_t age_ns;
} dev;

struct line {
    int rtu;
    dev *d[MBIO_DEVICES];
    int nd;
    modbus_t *ctx;
    int connected;
    pthread_t th;
    int started;
    uint64_t retry_ns, backoff_ns;
};

typedef struct mbio {
    dev *d[MBIO_DEVICES];
    int nd;
    line ln[MBIO_DEVICES];
    int nl;
    uint64_t tick_ns;
    _Atomic int stop;
    _Atomic uint32_t faults;
} mbio;

static uint64_t mono(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (uint64_t)t.tv_sec * 1000000000u + (uint64_t)t.tv_nsec;
}

#define LD(x) atomic_load_explicit(&(x), memory_order_relaxed)
#define ST(x, v) atomic_store_explicit(&(x), (v), memory_order_relaxed)
#define INC(x) atomic_fetch_add_explicit(&(x), 1, memory_order_relaxed)

/* ---- configuration ------------------------------------------------------ */

static void *create(void) { return calloc(1, sizeof(mbio)); }

static int int_in(const char *v, long lo, long hi, int *out, char *err, size_t n)
{
    char *end;
    errno = 0;
    long x = strtol(v, &end, 10);
    if (end == v || *end || errno || x < lo || x > hi) {
        snprintf(err, n, "'%s' is not a decimal number in %ld..%ld", v, lo, hi);
        return -1;
    }
    *out = (int)x;
    return 0;
}

static dev *dev_of(mbio *m, const char *sec, char *err, size_t n)
{
    const char *name = sec + strlen("modbus_io");
    if (*name != '.' || !name[1]) {
        snprintf(err, n, "a device needs a name: [modbus_io.NAME]");
        return NULL;
    }
    name++;
    for (int i = 0; i < m->nd; i++)
        if (!strcmp(m->d[i]->name, name)) return m->d[i];
    if (strlen(name) >= sizeof m->d[0]->name) {
        snprintf(err, n, "device name longer than %zu characters", sizeof m->d[0]->name - 1);
        return NULL;
    }
    if (m->nd >= MBIO_DEVICES) { snprintf(err, n, "more than %d devices", MBIO_DEVICES); return NULL; }
    dev *d = calloc(1, sizeof *d);
    if (!d) { snprintf(err, n, "out of memory"); return NULL; }
    snprintf(d->name, sizeof d->name, "%s", name);
    d->port = 502; d->unit = 1;
    d->baud = 19200; d->data_bits = 8; d->stop_bits = 1; d->parity = 'E';
    d->timeout_ms = 100; d->reconnect_max_ms = 2000;
    m->d[m->nd++] = d;
    return d;
}

/* "TABLE START COUNT LOCATION [safe=N]" */
static int block(dev *d, int write, const char *v, char *err, size_t n)
{
    if (d->nb >= MBIO_BLOCKS) { snprintf(err, n, "more than %d read and write blocks", MBIO_BLOCKS); return -1; }
    blk *b = &d->b[d->nb];
    memset(b, 0, sizeof *b);
    char tab[16], s_start[16], s_count[16], s_loc[24], s_safe[40] = "", extra[2];
    int k = sscanf(v, "%15s %15s %15s %23s %39s %1s", tab, s_start, s_count, s_loc, s_safe, extra);
    if (k < 4 || k > (write ? 4 : 5)) {
        snprintf(err, n, "'%.60s': expected TABLE START COUNT LOCATION%s", v, write ? "" : " [safe=VALUE]");
        return -1;
    }
    b->table = -1;
    for (int i = 0; i < 4; i++) if (!strcasecmp(tab, tables[i])) b->table = i;
    if (b->table < 0) { snprintf(err, n, "table '%s' is not coil, discrete, input or holding", tab); return -1; }
    if (write && (b->table == T_DISCRETE || b->table == T_INPUT)) {
        snprintf(err, n, "'%s': discrete inputs and input registers cannot be written (write = coil or holding)", tab);
        return -1;
    }
    int start, count;
    if (int_in(s_start, 0, 65535, &start, err, n)) return -1;
    int bits = b->table == T_COIL || b->table == T_DISCRETE;
    int maxc = bits ? (write ? MODBUS_MAX_WRITE_BITS : MODBUS_MAX_READ_BITS)
                    : (write ? MODBUS_MAX_WRITE_REGISTERS : MODBUS_MAX_READ_REGISTERS);
    if (int_in(s_count, 1, maxc, &count, err, n)) {
        snprintf(err, n, "count '%s' is not in 1..%d (one request of this table)", s_count, maxc);
        return -1;
    }
    if (start + count > 65536) { snprintf(err, n, "%d + %d registers pass address 65535", start, count); return -1; }
    b->write = write; b->start = (unsigned)start; b->count = (unsigned)count;
    if (plc_loc_parse(s_loc, &b->loc)) {
        snprintf(err, n, "'%s' is not a located address inside the process image", s_loc);
        return -1;
    }
    char want = write ? 'Q' : 'I';
    if (write ? b->loc.area != 'Q' : b->loc.area == 'Q') {
        snprintf(err, n, "'%s': a %s block goes to %s", s_loc, write ? "write" : "read",
                 write ? "an output (%QX, %QW, %QD)" : "an input (%IX, %IW, %ID) or memory (%MX, %MW, %MD)");
        return -1;
    }
    want = b->loc.area;
    if (bits && b->loc.size != 'X') {
        snprintf(err, n, "'%s': %ss are bits: give a %%%cX location", s_loc, tables[b->table], want);
        return -1;
    }
    if (!bits && b->loc.size != 'W' && b->loc.size != 'D') {
        snprintf(err, n, "'%s': registers go to %%%cW (16-bit) or %%%cD (32-bit, two registers each)", s_loc, want, want);
        return -1;
    }
    if (b->loc.size == 'D' && count % 2) {
        snprintf(err, n, "'%s': a %%%cD takes two registers: give an even count", s_loc, want);
        return -1;
    }
    unsigned room = b->loc.size == 'X' ? PLC_IMG_X * 8 - (b->loc.index * 8 + b->loc.bit)
                  : b->loc.size == 'W' ? PLC_IMG_W - b->loc.index : 2 * (PLC_IMG_D - b->loc.index);
    if ((unsigned)count > room) { snprintf(err, n, "'%s': %d values pass the end of the image", s_loc, count); return -1; }
    if (s_safe[0]) {
        char *end;
        if (strncmp(s_safe, "safe=", 5)) { snprintf(err, n, "'%s': the only option is safe=VALUE", s_safe); return -1; }
        errno = 0;
        b->safe = strtoll(s_safe + 5, &end, 10);
        long long lo = bits ? 0 : b->loc.size == 'W' ? -32768 : INT32_MIN;
        long long hi = bits ? 1 : b->loc.size == 'W' ? 65535 : UINT32_MAX;
        if (end == s_safe + 5 || *end || errno || b->safe < lo || b->safe > hi) {
            snprintf(err, n, "'%s': a decimal value in %lld..%lld", s_safe, lo, hi);
            return -1;
        }
    }
    unsigned *used = write ? &d->nout : &d->nin;
    if (*used + (unsigned)count > MBIO_VALS) { snprintf(err, n, "more than %d values %s", MBIO_VALS, write ? "written" : "read"); return -1; }
    b->off = *used;
    *used += (unsigned)count;
    snprintf(b->text, sizeof b->text, "%s %s %d %d %s", write ? "write" : "read", tables[b->table], start, count, s_loc);
    d->nb++;
    return 0;
}

static int config(void *st, const char *sec, const char *key, const char *v, char *err, size_t n)
{
    mbio *m = st;
    dev *d = dev_of(m, sec, err, n);
    if (!d) return -1;
    if (!strcmp(key, "host")) {
        if (!*v || strlen(v) >= sizeof d->host) { snprintf(err, n, "a host name or address of at most %zu characters", sizeof d->host - 1); return -1; }
        snprintf(d->host, sizeof d->host, "%s", v);
        d->has_host = 1;
        return 0;
    }
    if (!strcmp(key, "device")) {
        if (!*v || strlen(v) >= sizeof d->device) { snprintf(err, n, "a serial device path of at most %zu characters", sizeof d->device - 1); return -1; }
        snprintf(d->device, sizeof d->device, "%s", v);
        d->has_device = 1;
        return 0;
    }
    if (!strcmp(key, "port")) return int_in(v, 1, 65535, &d->port, err, n);
    if (!strcmp(key, "unit")) { d->has_unit = 1; return int_in(v, 0, 255, &d->unit, err, n); }
    if (!strcmp(key, "slave")) { d->has_slave = 1; return int_in(v, 1, 247, &d->unit, err, n); }
    if (!strcmp(key, "baud")) return int_in(v, 50, 4000000, &d->baud, err, n);
    if (!strcmp(key, "data_bits")) return int_in(v, 5, 8, &d->data_bits, err, n);
    if (!strcmp(key, "stop_bits")) return int_in(v, 1, 2, &d->stop_bits, err, n);
    if (!strcmp(key, "parity")) {
        if (!strcasecmp(v, "none")) d->parity = 'N';
        else if (!strcasecmp(v, "even")) d->parity = 'E';
        else if (!strcasecmp(v, "odd")) d->parity = 'O';
        else { snprintf(err, n, "'%s' is not none, even or odd", v); return -1; }
        return 0;
    }
    if (!strcmp(key, "period_ms")) return int_in(v, 0, 3600000, &d->period_ms, err, n);
    if (!strcmp(key, "timeout_ms")) return int_in(v, 1, 60000, &d->timeout_ms, err, n);
    if (!strcmp(key, "reconnect_max_ms")) return int_in(v, 100, 600000, &d->reconnect_max_ms, err, n);
    if (!strcmp(key, "safe_after_ms")) return int_in(v, 0, 3600000, &d->safe_after_ms, err, n);
    if (!strcmp(key, "word_order")) {
        if (!strcmp(v, "high_first")) d->low_first = 0;
        else if (!strcmp(v, "low_first")) d->low_first = 1;
        else { snprintf(err, n, "'%s' is not high_first or low_first", v); return -1; }
        return 0;
    }
    if (!strcmp(key, "ok")) {
        if (plc_loc_parse(v, &d->ok) || d->ok.area != 'I' || d->ok.size != 'X') {
            snprintf(err, n, "'%s' is not an input bit (%%IXn.m)", v);
            return -1;
        }
        d->has_ok = 1;
        return 0;
    }
    if (!strcmp(key, "read")) return block(d, 0, v, err, n);
    if (!strcmp(key, "write")) return block(d, 1, v, err, n);
    snprintf(err, n, "unknown key (host, port, unit, device, baud, parity, data_bits, stop_bits, slave, "
             "period_ms, timeout_ms, reconnect_max_ms, safe_after_ms, word_order, ok, read, write)");
    return -1;
}

/* ---- the exchange with the scan -------------------------------------------- */

/* poll thread: publish inputs (vals NULL: the safe values) */
static void publish_in(dev *d, const uint16_t *vals, int ok, uint64_t stamp)
{
    uint16_t *o = d->ibuf[d->iback];
    if (vals) memcpy(o, vals, d->nin * sizeof *o);
    else
        for (int i = 0; i < d->nb; i++) {
            blk *b = &d->b[i];
            if (b->write) continue;
            for (unsigned k = 0; k < b->count; k++) {
                uint16_t w = (uint16_t)b->safe;
                if (b->loc.size == 'D') {
                    uint32_t x = (uint32_t)b->safe;
                    int hi = (k % 2 == 0) != d->low_first;
                    w = (uint16_t)(hi ? x >> 16 : x);
                }
                o[b->off + k] = w;
            }
        }
    d->iok[d->iback] = (uint8_t)ok;
    d->istamp[d->iback] = stamp;
    d->iback = atomic_exchange_explicit(&d->imid, d->iback | FRESH, memory_order_acq_rel) & 3;
    ST(d->ok_now, (uint32_t)ok);
}

static int rd(void *st, plc_image *img, uint64_t now)
{
    mbio *m = st;
    (void)now;
    uint64_t t = m->nd ? mono() : 0;
    for (int i = 0; i < m->nd; i++) {
        dev *d = m->d[i];
        if (atomic_load_explicit(&d->imid, memory_order_relaxed) & FRESH)
            d->ifront = atomic_exchange_explicit(&d->imid, d->ifront, memory_order_acq_rel) & 3;
        const uint16_t *v = d->ibuf[d->ifront];
        d->age_ns = d->istamp[d->ifront] && t > d->istamp[d->ifront] ? t - d->istamp[d->ifront] : 0;
        if (d->has_ok) *plc_loc_ptr(img, &d->ok) = d->iok[d->ifront];
        if (!d->istamp[d->ifront] && !d->iok[d->ifront]) continue;     /* nothing read yet */
        for (int j = 0; j < d->nb; j++) {
            blk *b = &d->b[j];
            if (b->write) continue;
            const uint16_t *x = v + b->off;
            if (b->loc.size == 'X') {
                uint8_t *p = plc_loc_ptr(img, &b->loc);
                for (unsigned k = 0; k < b->count; k++) p[k] = (uint8_t)(x[k] != 0);
            } else if (b->loc.size == 'W') {
                uint8_t *p = plc_loc_ptr(img, &b->loc);
                for (unsigned k = 0; k < b->count; k++) img_set16(p, k, (int16_t)x[k]);
            } else {
                uint8_t *p = plc_loc_ptr(img, &b->loc);
                for (unsigned k = 0; k < b->count; k += 2) {
                    uint32_t hi = d->low_first ? x[k + 1] : x[k], lo = d->low_first ? x[k] : x[k + 1];
                    img_set32(p, k / 2, (int32_t)(hi << 16 | lo));
                }
            }
        }
    }
    return 0;
}

static int wr(void *st, const plc_image *img)
{
    mbio *m = st;
    for (int i = 0; i < m->nd; i++) {
        dev *d = m->d[i];
        if (!d->nout) continue;
        uint16_t *o = d->obuf[d->oback];
        for (int j = 0; j < d->nb; j++) {
            blk *b = &d->b[j];
            if (!b->write) continue;
            uint16_t *x = o + b->off;
            if (b->loc.size == 'X') {
                const uint8_t *p = img->qx + b->loc.index * 8 + b->loc.bit;
                for (unsigned k = 0; k < b->count; k++) x[k] = p[k] != 0;
            } else if (b->loc.size == 'W') {
                for (unsigned k = 0; k < b->count; k++) x[k] = (uint16_t)img_get16(img->qw, b->loc.index + k);
            } else {
                for (unsigned k = 0; k < b->count; k += 2) {
                    uint32_t y = (uint32_t)img_get32(img->qd, b->loc.index + k / 2);
                    x[k + d->low_first] = (uint16_t)(y >> 16);
                    x[k + !d->low_first] = (uint16_t)y;
                }
            }
        }
        d->oback = atomic_exchange_explicit(&d->omid, d->oback | FRESH, memory_order_acq_rel) & 3;
    }
    return 0;
}

/* ---- polling ------------------------------------------------------------- */

enum { F_TIMEOUT, F_EXCEPTION, F_BADFRAME, F_LOST };

static int classify(int e)
{
    if (e == ETIMEDOUT) return F_TIMEOUT;
    if (e > MODBUS_ENOBASE && e <= EMBXGTAR) return F_EXCEPTION;
    if (e == EMBBADCRC || e == EMBBADDATA || e == EMBBADEXC || e == EMBMDATA || e == EMBBADSLAVE || e == EMBUNKEXC)
        return F_BADFRAME;
    return F_LOST;
}

static const char *fault_text(int kind)
{
    static const char *t[] = { "no answer in time", "exception", "a malformed answer", "connection lost" };
    return t[kind];
}

/* one request of block b; 0 or -1 with errno */
static int transfer(modbus_t *c, dev *d, blk *b, uint16_t *in, const uint16_t *out)
{
    uint8_t bits[MODBUS_MAX_READ_BITS];
    int r = -1;
    unsigned n = b->count;
    if (!b->write) {
        switch (b->table) {
        case T_COIL: r = modbus_read_bits(c, (int)b->start, (int)n, bits); break;
        case T_DISCRETE: r = modbus_read_input_bits(c, (int)b->start, (int)n, bits); break;
        case T_INPUT: r = modbus_read_input_registers(c, (int)b->start, (int)n, in + b->off); break;
        default: r = modbus_read_registers(c, (int)b->start, (int)n, in + b->off); break;
        }
        if (r >= 0 && (b->table == T_COIL || b->table == T_DISCRETE))
            for (unsigned k = 0; k < n; k++) in[b->off + k] = bits[k];
    } else if (b->table == T_COIL) {
        for (unsigned k = 0; k < n; k++) bits[k] = (uint8_t)out[b->off + k];
        r = n == 1 ? modbus_write_bit(c, (int)b->start, bits[0]) : modbus_write_bits(c, (int)b->start, (int)n, bits);
    } else {
        r = n == 1 ? modbus_write_register(c, (int)b->start, out[b->off]) : modbus_write_registers(c, (int)b->start, (int)n, out + b->off);
    }
    (void)d;
    return r < 0 ? -1 : 0;
}

static uint64_t period_of(mbio *m, dev *d)
{
    return d->period_ms ? (uint64_t)d->period_ms * 1000000u : m->tick_ns;
}

static void backoff(uint64_t *cur, uint64_t max_ns)
{
    *cur = *cur ? *cur * 2 : 100000000u;
    if (*cur > max_ns) *cur = max_ns;
}

/* a fault of device d: counted; logged once when the device is lost */
static void fault(mbio *m, dev *d, int kind, int e, uint64_t now)
{
    switch (kind) {
    case F_TIMEOUT: INC(d->timeouts); break;
    case F_EXCEPTION: INC(d->exceptions); ST(d->last_exc, (uint32_t)(e - MODBUS_ENOBASE)); break;
    case F_BADFRAME: INC(d->bad_frames); break;
    default: INC(d->losses); break;
    }
    if (d->good || !d->lost_ns) {
        INC(m->faults);
        if (kind == F_EXCEPTION)
            plc_log(LOG_WARN, "modbus_io %s: exception %d (%s): inputs %s, ok off", d->name, e - MODBUS_ENOBASE,
                    modbus_strerror(e), d->safe_after_ms ? "held, then safe" : "held");
        else
            plc_log(LOG_WARN, "modbus_io %s: %s (%s): inputs %s, ok off; retrying", d->name, fault_text(kind),
                    modbus_strerror(e), d->safe_after_ms ? "held, then safe" : "held");
        d->lost_ns = now;
    }
    d->good = 0;
    d->rewrite = 1;
    publish_in(d, d->safe_out ? NULL : d->last, 0, d->last_good_ns);
}

/* One poll round of device d: outputs that changed (or due again, or all
** after a fault), then every read block. 0, or -1 with the fault handled. */
static int round_(mbio *m, line *l, dev *d, uint64_t now)
{
    modbus_set_slave(l->ctx, d->unit);
    if (d->nout && (atomic_load_explicit(&d->omid, memory_order_relaxed) & FRESH)) {
        d->ofront = atomic_exchange_explicit(&d->omid, d->ofront, memory_order_acq_rel) & 3;
        d->out_seen = 1;
    }
    uint64_t per = period_of(m, d);
    for (int j = 0; j < d->nb; j++) {
        blk *b = &d->b[j];
        if (!b->write || !d->out_seen) continue;
        const uint16_t *o = d->obuf[d->ofront];
        if (!d->rewrite && !memcmp(o + b->off, d->written + b->off, b->count * sizeof *o)
            && now - d->wrote_ns[j] < per)
            continue;
        if (transfer(l->ctx, d, b, NULL, o)) return -1;
        memcpy(d->written + b->off, o + b->off, b->count * sizeof *o);
        d->wrote_ns[j] = now;
    }
    if (d->out_seen) d->rewrite = 0;
    for (int j = 0; j < d->nb; j++)
        if (!d->b[j].write && transfer(l->ctx, d, &d->b[j], d->work, NULL)) return -1;
    return 0;
}

static void poll_dev(mbio *m, line *l, dev *d, uint64_t now)
{
    uint64_t t0 = mono();
    if (round_(m, l, d, now)) {
        int e = errno, kind = classify(e);
        fault(m, d, kind, e, now);
        if (kind == F_EXCEPTION) return;            /* the link is fine: next period */
        backoff(&d->backoff_ns, (uint64_t)d->reconnect_max_ms * 1000000u);
        d->retry_ns = mono() + d->backoff_ns;
        if (!l->rtu || kind == F_LOST) {             /* a TCP stream out of step: anew */
            modbus_close(l->ctx);
            l->connected = 0;
            l->retry_ns = d->retry_ns;
        } else {
            modbus_flush(l->ctx);
        }
        return;
    }
    uint64_t t1 = mono();
    memcpy(d->last, d->work, d->nin * sizeof *d->work);
    d->last_good_ns = t1;
    if (!d->good && d->lost_ns)
        plc_log(LOG_INFO, "modbus_io %s: answering again after %.1f s, outputs written anew", d->name,
                (double)(t1 - d->lost_ns) / 1e9);
    d->good = 1;
    d->lost_ns = 0;
    d->safe_out = 0;
    d->backoff_ns = 0;
    publish_in(d, d->work, 1, t1);
    INC(d->rounds);
    ST(d->round_us, (uint32_t)((t1 - t0) / 1000));
}

static void sleep_until(uint64_t ns)
{
    struct timespec t = { (time_t)(ns / 1000000000u), (long)(ns % 1000000000u) };
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &t, NULL) == EINTR) {}
}

typedef struct line_arg { mbio *m; line *l; } line_arg;

static void *poll_thread(void *arg)
{
    line_arg *a = arg;
    mbio *m = a->m;
    line *l = a->l;
    free(a);
    while (!atomic_load(&m->stop)) {
        uint64_t now = mono(), wake = now + 20000000u;
        if (!l->connected) {
            if (now >= l->retry_ns) {
                if (modbus_connect(l->ctx) == 0) {
                    l->connected = 1;
                    l->backoff_ns = 0;
                } else {
                    int e = errno;
                    for (int i = 0; i < l->nd; i++)
                        if (l->d[i]->good || !l->d[i]->lost_ns) fault(m, l->d[i], F_LOST, e, now);
                        else INC(l->d[i]->losses);
                    uint64_t mx = (uint64_t)l->d[0]->reconnect_max_ms * 1000000u;
                    backoff(&l->backoff_ns, mx);
                    l->retry_ns = mono() + l->backoff_ns;
                }
            }
            if (!l->connected && l->retry_ns < wake) wake = l->retry_ns;
        }
        for (int i = 0; i < l->nd && l->connected && !atomic_load(&m->stop); i++) {
            dev *d = l->d[i];
            now = mono();
            if (now >= d->next_ns && now >= d->retry_ns) {
                uint64_t per = period_of(m, d);
                d->next_ns = d->next_ns + per > now ? d->next_ns + per : now;
                poll_dev(m, l, d, now);
            }
        }
        now = mono();
        for (int i = 0; i < l->nd; i++) {
            dev *d = l->d[i];
            /* inputs to their safe values once the device was lost long enough */
            if (!d->good && d->safe_after_ms && !d->safe_out && d->lost_ns
                && now - d->last_good_ns >= (uint64_t)d->safe_after_ms * 1000000u) {
                publish_in(d, NULL, 0, d->last_good_ns);
                d->safe_out = 1;
            }
            if (!d->good && d->safe_after_ms && !d->safe_out && d->lost_ns) {
                uint64_t at = d->last_good_ns + (uint64_t)d->safe_after_ms * 1000000u;
                if (at < wake) wake = at;
            }
            uint64_t due = d->next_ns > d->retry_ns ? d->next_ns : d->retry_ns;
            if (l->connected && due < wake) wake = due;
        }
        if (wake > mono()) sleep_until(wake);
    }
    return NULL;
}

/* ---- open, close --------------------------------------------------------- */

static int check_dev(dev *d, char *err, size_t n)
{
    if (d->has_host == d->has_device) {
        snprintf(err, n, "[modbus_io.%s]: give host (Modbus TCP) or device (Modbus RTU on a serial port)%s", d->name,
                 d->has_host ? ", not both" : "");
        return -1;
    }
    if (d->has_host && d->has_slave) { snprintf(err, n, "[modbus_io.%s]: slave is for RTU; a TCP device takes unit", d->name); return -1; }
    if (d->has_device && d->has_unit) { snprintf(err, n, "[modbus_io.%s]: unit is for TCP; an RTU device takes slave", d->name); return -1; }
    if (!d->nb) { snprintf(err, n, "[modbus_io.%s]: nothing to poll: add read = ... or write = ...", d->name); return -1; }
    return 0;
}

static int list_inputs(void *st, plc_image *img, io_input_use *in, int max)
{
    mbio *m = st;
    int k = 0;
    for (int i = 0; i < m->nd; i++) {
        dev *d = m->d[i];
        for (int j = 0; j < d->nb && k < max; j++) {
            blk *b = &d->b[j];
            if (b->write) continue;
            in[k].p = plc_loc_ptr(img, &b->loc);
            in[k].w = b->loc.size == 'X' ? b->count : 2 * b->count;     /* bytes: a register is 2 */
            snprintf(in[k++].who, sizeof in[0].who, "[modbus_io.%.40s] %s", d->name, b->text);
        }
        if (d->has_ok && k < max) {
            in[k].p = plc_loc_ptr(img, &d->ok);
            in[k].w = 1;
            snprintf(in[k++].who, sizeof in[0].who, "[modbus_io.%.40s] ok", d->name);
        }
    }
    return k;
}

static int alloc_dev(dev *d)
{
    size_t ni = d->nin ? d->nin : 1, no = d->nout ? d->nout : 1;
    for (int i = 0; i < 3; i++)
        if (!(d->ibuf[i] = calloc(ni, 2)) || !(d->obuf[i] = calloc(no, 2))) return -1;
    if (!(d->written = calloc(no, 2)) || !(d->wrote_ns = calloc(MBIO_BLOCKS, 8)) || !(d->work = calloc(ni, 2))
        || !(d->last = calloc(ni, 2)))
        return -1;
    d->iback = 0; d->ifront = 1; atomic_init(&d->imid, 2u);
    d->oback = 0; d->ofront = 1; atomic_init(&d->omid, 2u);
    return 0;
}

static void stop_lines(mbio *m)
{
    atomic_store(&m->stop, 1);
    for (int i = 0; i < m->nl; i++)
        if (m->ln[i].started) { pthread_join(m->ln[i].th, NULL); m->ln[i].started = 0; }
}

static int open_(void *st, plc_image *img, uint64_t tick, char *err, size_t n)
{
    mbio *m = st;
    m->tick_ns = tick;
    if (!m->nd) { snprintf(err, n, "no device configured (add a [modbus_io.NAME] section, docs/remote-io.md)"); return -1; }
    for (int i = 0; i < m->nd; i++)
        if (check_dev(m->d[i], err, n)) return -1;
    io_input_use *in = malloc(MBIO_DEVICES * (MBIO_BLOCKS + 1) * sizeof *in);
    if (!in) { snprintf(err, n, "out of memory"); return -1; }
    int r = io_inputs_apart(in, list_inputs(m, img, in, MBIO_DEVICES * (MBIO_BLOCKS + 1)), err, n);
    free(in);
    if (r) return -1;
    /* lines: a TCP device each; the RTU devices of one serial port share one */
    for (int i = 0; i < m->nd; i++) {
        dev *d = m->d[i];
        line *l = NULL;
        if (d->has_device)
            for (int j = 0; j < i && !l; j++) {
                dev *o = m->d[j];
                if (!o->has_device || strcmp(o->device, d->device)) continue;
                if (o->baud != d->baud || o->parity != d->parity || o->data_bits != d->data_bits
                    || o->stop_bits != d->stop_bits) {
                    snprintf(err, n, "[modbus_io.%s] and [modbus_io.%s] share %s with different baud, parity, "
                             "data_bits or stop_bits: one line has one setting", o->name, d->name, d->device);
                    return -1;
                }
                if (o->unit == d->unit) {
                    snprintf(err, n, "[modbus_io.%s] and [modbus_io.%s] are both slave %d on %s", o->name, d->name,
                             d->unit, d->device);
                    return -1;
                }
                l = o->ln;
            }
        if (!l) {
            l = &m->ln[m->nl++];
            l->rtu = d->has_device;
            if (d->has_device) {
                l->ctx = modbus_new_rtu(d->device, d->baud, d->parity, d->data_bits, d->stop_bits);
            } else {
                char port[8];
                snprintf(port, sizeof port, "%d", d->port);
                l->ctx = modbus_new_tcp_pi(d->host, port);
            }
            if (!l->ctx) { snprintf(err, n, "[modbus_io.%s]: %s", d->name, modbus_strerror(errno)); return -1; }
            uint32_t s = (uint32_t)d->timeout_ms / 1000, us = (uint32_t)(d->timeout_ms % 1000) * 1000;
            modbus_set_response_timeout(l->ctx, s, us);
            modbus_set_byte_timeout(l->ctx, s, us);
        }
        l->d[l->nd++] = d;
        d->ln = l;
        if (alloc_dev(d)) { snprintf(err, n, "out of memory"); return -1; }
    }
    /* a serial port that cannot be opened is a configuration error */
    for (int i = 0; i < m->nl; i++) {
        line *l = &m->ln[i];
        if (!l->rtu) continue;
        if (modbus_connect(l->ctx)) {
            snprintf(err, n, "[modbus_io.%s] device %s: %s", l->d[0]->name, l->d[0]->device, modbus_strerror(errno));
            return -1;
        }
        l->connected = 1;
    }
    for (int i = 0; i < m->nl; i++) {
        line_arg *a = malloc(sizeof *a);
        if (!a) { stop_lines(m); snprintf(err, n, "out of memory"); return -1; }
        a->m = m; a->l = &m->ln[i];
        if (pthread_create(&m->ln[i].th, NULL, poll_thread, a)) {
            free(a);
            stop_lines(m);
            snprintf(err, n, "cannot start a polling thread");
            return -1;
        }
        m->ln[i].started = 1;
    }
    return 0;
}

/* Outputs to their safe state: the scan stopped with %Q zeroed; each
** device's write blocks are written once more with those zeros. */
static void safe(void *st, plc_image *img)
{
    mbio *m = st;
    stop_lines(m);
    wr(m, img);
    for (int i = 0; i < m->nl; i++) {
        line *l = &m->ln[i];
        if (!l->ctx || (!l->connected && modbus_connect(l->ctx))) continue;
        l->connected = 1;
        for (int j = 0; j < l->nd; j++) {
            dev *d = l->d[j];
            if (!d->nout) continue;
            modbus_set_slave(l->ctx, d->unit);
            d->ofront = atomic_exchange(&d->omid, d->ofront) & 3;
            for (int k = 0; k < d->nb; k++)
                if (d->b[k].write && transfer(l->ctx, d, &d->b[k], NULL, d->obuf[d->ofront])) {
                    plc_log(LOG_WARN, "modbus_io %s: outputs not reset (%s)", d->name, modbus_strerror(errno));
                    break;
                }
        }
    }
}

static void close_(void *st)
{
    mbio *m = st;
    stop_lines(m);
    for (int i = 0; i < m->nl; i++)
        if (m->ln[i].ctx) { modbus_close(m->ln[i].ctx); modbus_free(m->ln[i].ctx); }
    for (int i = 0; i < m->nd; i++) {
        dev *d = m->d[i];
        for (int k = 0; k < 3; k++) { free(d->ibuf[k]); free(d->obuf[k]); }
        free(d->written); free(d->wrote_ns); free(d->work); free(d->last);
        free(d);
    }
    free(m);
}

/* 16 registers for the backend, then 16 per device (docs/remote-io.md) */
static size_t diag(void *st, uint16_t *r, size_t max)
{
    mbio *m = st;
    size_t need = 16 + 16 * (size_t)m->nd;
    if (need > max) need = max;
    memset(r, 0, need * sizeof *r);
#define PUT(at, v) do { if ((at) < max) r[at] = (uint16_t)(v); } while (0)
#define PUT32(at, v) do { uint32_t v_ = (v); PUT(at, v_ >> 16); PUT((at) + 1, v_); } while (0)
    uint32_t up = 0;
    for (int i = 0; i < m->nd; i++) up += LD(m->d[i]->ok_now);
    PUT(0, m->nd);
    PUT(1, up);
    PUT32(2, LD(m->faults));
    for (int i = 0; i < m->nd; i++) {
        dev *d = m->d[i];
        size_t b = 16 + 16 * (size_t)i;
        PUT32(b, LD(d->rounds));
        PUT32(b + 2, LD(d->timeouts));
        PUT32(b + 4, LD(d->exceptions));
        PUT32(b + 6, LD(d->bad_frames));
        PUT32(b + 8, LD(d->losses));
        PUT(b + 10, LD(d->ok_now));
        PUT(b + 11, LD(d->last_exc));
        PUT32(b + 12, LD(d->round_us));
        uint64_t age = d->age_ns / 1000;
        PUT32(b + 14, age > 0xFFFFFFFFu ? 0xFFFFFFFFu : (uint32_t)age);
    }
#undef PUT
#undef PUT32
    return need;
}

const io_backend_ops io_modbus = {
    "modbus_io", create, config, open_, rd, wr, safe, close_, diag, list_inputs
};
