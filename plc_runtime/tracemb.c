/* tracemb.c: see tracemb.h and docs/trace.md. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "log.h"
#include "scan.h"
#include "tracemb.h"

_Static_assert(TB_END == MB_TRACE_END, "the block's end in mbmap.h");

#define OWNER_STALE_NS (30 * 1000000000ull)   /* an owner silent this long gives way */

enum { EX_FUNCTION = 1, EX_ADDRESS = 2, EX_VALUE = 3, EX_BUSY = 6 };

enum {   /* mailbox commands */
    C_CLAIM = 1, C_RELEASE, C_CHANNELS, C_SETUP, C_ARM, C_TRIGGER, C_STOP, C_NEXT,
    C_LOOKUP = 16, C_FORCE, C_UNFORCE, C_UNFORCE_ALL
};
enum {   /* selector: what the window shows */
    W_CYCLES = 0x100, W_TICKS = 0x101, W_VAR = 0x200, W_FORCED = 0x300, W_CHANNELS = 0x400
};

struct tracemb {
    trace *t;
    forcing *f;
    const plc_program *p;
    uint64_t period_ns;
    int owned;
    uint16_t owner;
    uint64_t owner_ns;
    trace_setup setup;
    uint16_t sel[TB_SEL_N + 1];
    uint32_t res_index;
    uint16_t res_type, res_size;
};

tracemb *tb_new(trace *t, forcing *f, const plc_program *p, uint64_t period_ns)
{
    tracemb *b = calloc(1, sizeof *b);
    if (!b) return NULL;
    *b = (tracemb){ .t = t, .f = f, .p = p, .period_ns = period_ns };
    b->setup.decim = 1;
    return b;
}

void tb_free(tracemb *b) { free(b); }

int tb_flush(tracemb *b) { return force_flush(b->f); }

static unsigned u16(const uint8_t *p) { return (unsigned)p[0] << 8 | p[1]; }
static uint32_t r32(const uint16_t *r) { return (uint32_t)r[0] << 16 | r[1]; }
static void put32(uint16_t *r, uint32_t v) { r[0] = (uint16_t)(v >> 16); r[1] = (uint16_t)v; }
static void put64(uint16_t *r, uint64_t v)
{
    for (int i = 0; i < 4; i++) r[i] = (uint16_t)(v >> (48 - 16 * i));
}

static int overlaps(unsigned a, unsigned n, unsigned lo, unsigned hi) { return a < hi && a + n > lo; }

int tb_touches(const uint8_t *q, size_t n)
{
    if (n < 5) return 0;
    unsigned a = u16(q + 1), cnt = q[0] == 6 ? 1 : u16(q + 3);
    if (overlaps(a, cnt, TB_BASE, TB_END)) return 1;
    return q[0] == 23 && n >= 9 && overlaps(u16(q + 5), u16(q + 7), TB_BASE, TB_END);
}

/* ---- what is read --------------------------------------------------------- */

static int readable(unsigned a, unsigned n)
{
    return (a >= TB_BASE && a + n <= TB_BASE + TB_STATUS_N) || (a >= TB_SEL && a + n <= TB_END);
}

static void status(tracemb *b, uint16_t *s)
{
    trace *t = b->t;
    trace_buf *h = trace_take(t);
    memset(s, 0, TB_STATUS_N * sizeof *s);
    s[0] = 0x5452;                              /* "TR" */
    s[1] = 1;
    s[2] = trace_running(t) ? (uint16_t)(atomic_load(&t->arm_req) ? TRACE_ARMED : atomic_load(&t->state_pub)) : TRACE_IDLE;
    s[3] = h != NULL;
    s[4] = (uint16_t)b->owned;
    s[5] = (uint16_t)b->setup.nchan;
    put32(s + 6, t->cap);
    put32(s + 8, atomic_load(&t->done_seq));
    if (h) {
        put32(s + 10, h->seq);
        put32(s + 12, h->setup.samples);
        put32(s + 14, h->setup.pre);
        s[16] = (uint16_t)(h->setup.decim > 0xFFFF ? 0xFFFF : h->setup.decim);
        s[17] = (uint16_t)h->setup.nchan;
    }
    put32(s + 18, (uint32_t)b->period_ns);
    put32(s + 20, (uint32_t)b->p->nvars);
    s[22] = (uint16_t)b->f->allowed;
    s[23] = (uint16_t)force_count(b->f);
    put32(s + 24, b->res_index);
    s[26] = b->res_type;
    s[27] = b->res_size;
}

static unsigned width(unsigned size) { return size <= 2 ? 1 : size / 2; }

/* The window for selector sel, or -1 when it selects nothing there is. */
static int window(tracemb *b, const uint16_t *sel, uint16_t *w)
{
    unsigned what = sel[0];
    uint32_t first = r32(sel + 1);
    trace_buf *h = trace_take(b->t);
    memset(w, 0, TB_WIN_N * sizeof *w);
    if (what < TRACE_CHANNELS || what == W_CYCLES || what == W_TICKS) {
        if (!h || first >= h->setup.samples) return -1;
        if (what < TRACE_CHANNELS && what >= (unsigned)h->setup.nchan) return -1;
        unsigned ww = what < TRACE_CHANNELS ? width(h->setup.ch[what].size) : 2;
        for (unsigned i = 0; (i + 1) * ww <= TB_WIN_N && first + i < h->setup.samples; i++) {
            uint64_t v = what == W_CYCLES ? h->cycle[trace_index(h, first + i)]
                       : what == W_TICKS ? h->tick[trace_index(h, first + i)]
                       : trace_value(h, (int)what, first + i);
            for (unsigned k = 0; k < ww; k++) w[i * ww + k] = (uint16_t)(v >> (16 * (ww - 1 - k)));
        }
        return 0;
    }
    if (what == W_VAR) {
        if (first >= b->p->nvars) return -1;
        const plc_var *v = &b->p->vars[first];
        w[0] = (uint16_t)trace_type(v);
        w[1] = v->size;
        w[2] = (uint16_t)(force_area(v) | (force_is_forced(b->f, first) ? 0x100 : 0));
        const char *s = v->path;
        for (unsigned i = 0; s[i] && i < 2 * (TB_WIN_N - 3); i++)
            w[3 + i / 2] |= (uint16_t)((uint8_t)s[i] << (i % 2 ? 0 : 8));
        return 0;
    }
    if (what == W_FORCED) {
        const force_table *l = &b->f->list;
        if (first > (uint32_t)l->n) return -1;
        w[0] = (uint16_t)l->n;
        for (unsigned i = 0; first + i < (uint32_t)l->n && 1 + 6 * (i + 1) <= TB_WIN_N; i++) {
            const force_entry *e = &l->e[first + i];
            uint8_t by[8];
            uint64_t v = 0;
            memcpy(by, &e->raw, 8);
            for (int k = 0; k < e->size; k++) v |= (uint64_t)by[k] << (8 * k);
            put32(w + 1 + 6 * i, e->var);
            put64(w + 3 + 6 * i, v);
        }
        return 0;
    }
    if (what == W_CHANNELS) {
        if (!h || first > (uint32_t)h->setup.nchan) return -1;
        for (unsigned i = 0; first + i < (uint32_t)h->setup.nchan && 4 * (i + 1) <= TB_WIN_N; i++) {
            const trace_chan *c = &h->setup.ch[first + i];
            put32(w + 4 * i, c->var);
            w[4 * i + 2] = c->type;
            w[4 * i + 3] = c->size;
        }
        return 0;
    }
    return -1;
}

/* Registers [a, a+n) of the readable parts, with selector sel. */
static int read_regs(tracemb *b, unsigned a, unsigned n, const uint16_t *sel, uint16_t *out)
{
    uint16_t s[TB_STATUS_N], w[TB_WIN_N];
    if (a < TB_SEL) {
        status(b, s);
        memcpy(out, s + (a - TB_BASE), n * sizeof *out);
        return 0;
    }
    if (a + n > TB_WIN && window(b, sel, w)) return -1;
    for (unsigned i = 0; i < n; i++) {
        unsigned r = a + i;
        out[i] = r < TB_WIN ? sel[r - TB_SEL] : w[r - TB_WIN];
    }
    return 0;
}

/* ---- commands ------------------------------------------------------------- */

/* A path written as characters, two per register (high byte first). */
static void get_path(const uint16_t *r, unsigned n, char *s, size_t sn)
{
    size_t k = 0;
    for (unsigned i = 0; i < n && k + 2 < sn; i++) {
        s[k++] = (char)(r[i] >> 8);
        s[k++] = (char)r[i];
    }
    s[k] = 0;
}

/* The variable named path: exactly (case-insensitive) or, failing that, the
** one variable whose path ends with "." path. -1 if none, -2 if several. */
static long lookup(const plc_program *p, const char *path)
{
    size_t n = strlen(path);
    long hit = -1;
    if (!n) return -1;
    for (size_t i = 0; i < p->nvars; i++)
        if (!strcasecmp(p->vars[i].path, path)) return (long)i;
    for (size_t i = 0; i < p->nvars; i++) {
        const char *v = p->vars[i].path;
        size_t m = strlen(v);
        if (m > n && v[m - n - 1] == '.' && !strcasecmp(v + m - n, path)) {
            if (hit >= 0) return -2;
            hit = (long)i;
        }
    }
    return hit;
}

static int chan_of(tracemb *b, uint32_t var, trace_chan *c)
{
    if (var >= b->p->nvars) return EX_ADDRESS;
    const plc_var *v = &b->p->vars[var];
    int type = trace_type(v);
    if (type == TT_NONE) return EX_VALUE;
    *c = (trace_chan){ plc_var_addr(v), var, (uint8_t)v->size, (uint8_t)type };
    return 0;
}

static int cmd_setup(tracemb *b, const uint16_t *a, unsigned n)
{
    if (n != 13) return EX_VALUE;
    trace_setup s = b->setup;
    s.decim = a[0];
    s.samples = r32(a + 1);
    s.pre = r32(a + 3);
    s.trig = a[5];
    uint64_t lv = 0;
    for (int i = 0; i < 4; i++) lv = lv << 16 | a[8 + i];
    memcpy(&s.level, &lv, 8);
    s.repeat = a[12];
    if (!s.decim || !s.samples || s.samples > b->t->cap || s.pre >= s.samples || s.trig >= TRIG_KINDS
        || s.repeat > 1 || s.level != s.level)
        return EX_VALUE;
    if (s.trig != TRIG_MANUAL) {
        int e = chan_of(b, r32(a + 6), &s.tv);
        if (e) return e;
        if ((s.trig == TRIG_RISE || s.trig == TRIG_FALL) && s.tv.type != TT_BOOL) return EX_VALUE;
    }
    b->setup = s;
    return 0;
}

static int cmd_force(tracemb *b, unsigned cmd, const uint16_t *a, unsigned n)
{
    if (!b->f->allowed) return EX_FUNCTION;
    if (cmd == C_UNFORCE_ALL) {
        if (n) return EX_VALUE;
        if (force_count(b->f)) plc_log(LOG_WARN, "force: every variable released");
        force_clear_all(b->f);
        return 0;
    }
    if (n != (cmd == C_FORCE ? 6u : 2u)) return EX_VALUE;
    uint32_t var = r32(a);
    if (var >= b->p->nvars) return EX_ADDRESS;
    const plc_var *v = &b->p->vars[var];
    if (cmd == C_UNFORCE) {
        if (force_is_forced(b->f, var)) plc_log(LOG_WARN, "force: %s released", v->path);
        force_clear(b->f, var);
        return 0;
    }
    uint64_t raw = 0;
    for (int i = 0; i < 4; i++) raw = raw << 16 | a[2 + i];
    int tt = trace_type(v);
    if (tt == TT_NONE) return EX_VALUE;
    /* a BOOL other than 0/1 is TRUE and NOT TRUE at once (NOT 2 = 253), and
    ** a nan or an infinity runs through every computation into the outputs
    ** (a DAC): neither is a value a program can be given */
    if (tt == TT_BOOL && raw > 1) return EX_VALUE;
    if ((tt == TT_REAL || tt == TT_LREAL) && !isfinite(trace_number(raw, tt))) return EX_VALUE;
    if (force_set(b->f, var, raw)) return EX_BUSY;        /* the table full */
    char val[32];
    snprintf(val, sizeof val, "%.17g", trace_number(raw, trace_type(v)));
    plc_log(LOG_WARN, "force: %s = %s (%d forced)", v->path, val, force_count(b->f));
    return 0;
}

/* Check and carry out a mailbox command: 0, or an exception code. */
static int command(tracemb *b, const uint16_t *r, unsigned n)
{
    if (n < 2) return EX_VALUE;
    uint16_t token = r[0];
    unsigned cmd = r[1];
    const uint16_t *a = r + 2;
    n -= 2;
    if (cmd == C_LOOKUP) {
        char path[2 * TB_CMD_N + 1];
        get_path(a, n, path, sizeof path);
        long i = lookup(b->p, path);
        if (i < 0) return i == -1 ? EX_ADDRESS : EX_VALUE;
        b->res_index = (uint32_t)i;
        b->res_type = (uint16_t)trace_type(&b->p->vars[i]);
        b->res_size = b->p->vars[i].size;
        return 0;
    }
    if (cmd >= C_FORCE && cmd <= C_UNFORCE_ALL) return cmd_force(b, cmd, a, n);
    if (cmd < C_CLAIM || cmd > C_NEXT) return EX_FUNCTION;

    trace *t = b->t;
    uint64_t now = scan_now_ns();
    if (cmd == C_CLAIM) {
        if (!token || n) return EX_VALUE;
        if (b->owned && b->owner != token && now - b->owner_ns < OWNER_STALE_NS) return EX_BUSY;
        b->owned = 1;
        b->owner = token;
        b->owner_ns = now;
        return 0;
    }
    if (!b->owned || token != b->owner) return EX_BUSY;
    b->owner_ns = now;
    int running = trace_running(t);
    switch (cmd) {
    case C_RELEASE:
        if (n) return EX_VALUE;
        trace_stop(t);
        b->owned = 0;
        return 0;
    case C_CHANNELS: {
        if (!n || n % 2 || n / 2 > TRACE_CHANNELS) return EX_VALUE;
        if (running) return EX_BUSY;
        trace_chan ch[TRACE_CHANNELS];
        for (unsigned i = 0; i < n / 2; i++) {
            int e = chan_of(b, r32(a + 2 * i), &ch[i]);
            if (e) return e;
        }
        memcpy(b->setup.ch, ch, sizeof ch);
        b->setup.nchan = (int)(n / 2);
        return 0;
    }
    case C_SETUP:
        if (running) return EX_BUSY;
        return cmd_setup(b, a, n);
    case C_ARM:
        if (n || !b->setup.nchan || !b->setup.samples) return EX_VALUE;
        if (running) return EX_BUSY;
        trace_arm(t, &b->setup);
        return 0;
    case C_TRIGGER:
        if (n || b->setup.trig != TRIG_MANUAL) return EX_VALUE;
        trace_trigger(t);
        return 0;
    case C_STOP:
        if (n) return EX_VALUE;
        trace_stop(t);
        return 0;
    default:                                    /* C_NEXT */
        if (n) return EX_VALUE;
        trace_next(t);
        return 0;
    }
}

/* ---- requests ------------------------------------------------------------- */

static size_t exc(uint8_t *rsp, uint8_t fc, int code, int *e)
{
    rsp[0] = fc | 0x80;
    rsp[1] = (uint8_t)code;
    *e = 1;
    return 2;
}

static void get_regs(const uint8_t *p, unsigned n, uint16_t *r)
{
    for (unsigned i = 0; i < n; i++) r[i] = (uint16_t)u16(p + 2 * i);
}

/* A write of n registers at a: into the selector (sel updated) or the
** mailbox (carried out). 0, or an exception code; nothing changes then. */
static int write_regs(tracemb *b, unsigned a, unsigned n, const uint16_t *r, uint16_t *sel, int dry)
{
    if (a == TB_CMD) return dry ? 0 : command(b, r, n);
    if (a >= TB_SEL && a + n <= TB_SEL + TB_SEL_N) {
        memcpy(sel + (a - TB_SEL), r, n * sizeof *r);
        return 0;
    }
    return EX_ADDRESS;
}

size_t tb_serve(tracemb *b, const uint8_t *q, size_t n, uint8_t *rsp, int *e)
{
    uint8_t fc = q[0];
    unsigned a = u16(q + 1), cnt = u16(q + 3);
    uint16_t r[125], out[125], sel[TB_SEL_N + 1];
    int x;
    *e = 0;
    rsp[0] = fc;
    memcpy(sel, b->sel, sizeof sel);
    if (mb_pdu_shape(q, n) != 1) return exc(rsp, fc, EX_VALUE, e);
    switch (fc) {
    case 3:
        if (!readable(a, cnt) || read_regs(b, a, cnt, sel, out)) return exc(rsp, fc, EX_ADDRESS, e);
        break;
    case 6:
        r[0] = (uint16_t)cnt;
        if ((x = write_regs(b, a, 1, r, sel, 0))) return exc(rsp, fc, x, e);
        memcpy(b->sel, sel, sizeof sel);
        memcpy(rsp, q, 5);
        return 5;
    case 16:
        get_regs(q + 6, cnt, r);
        if ((x = write_regs(b, a, cnt, r, sel, 0))) return exc(rsp, fc, x, e);
        memcpy(b->sel, sel, sizeof sel);
        memcpy(rsp, q, 5);
        return 5;
    case 23: {
        unsigned wa = u16(q + 5), wn = u16(q + 7);
        get_regs(q + 10, wn, r);
        /* checked whole first: the write's place and the read with it */
        if ((x = write_regs(b, wa, wn, r, sel, 1))) return exc(rsp, fc, x, e);
        if (!readable(a, cnt)) return exc(rsp, fc, EX_ADDRESS, e);
        if (wa != TB_CMD && read_regs(b, a, cnt, sel, out)) return exc(rsp, fc, EX_ADDRESS, e);
        if (wa == TB_CMD && (x = command(b, r, wn))) return exc(rsp, fc, x, e);
        if (read_regs(b, a, cnt, sel, out)) return exc(rsp, fc, EX_ADDRESS, e);
        memcpy(b->sel, sel, sizeof sel);
        break;
    }
    default:
        return exc(rsp, fc, EX_FUNCTION, e);
    }
    rsp[1] = (uint8_t)(2 * cnt);
    for (unsigned i = 0; i < cnt; i++) {
        rsp[2 + 2 * i] = (uint8_t)(out[i] >> 8);
        rsp[3 + 2 * i] = (uint8_t)out[i];
    }
    return 2 + 2 * cnt;
}

static size_t serve_block(void *arg, const uint8_t *q, size_t n, uint8_t *rsp, int *e)
{
    return tb_serve(arg, q, n, rsp, e);
}

static int flush_block(void *arg) { return tb_flush(arg); }

mb_block tb_block(tracemb *b)
{
    return (mb_block){ tb_touches, serve_block, flush_block, b };
}
