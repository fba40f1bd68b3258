/* mbmap.c: see mbmap.h and docs/modbus.md. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "mbmap.h"

/* ---- cells: one addressable unit of a table ---------------------------- */

typedef struct cell {
    uint8_t *p;          /* element storage in the server's view */
    unsigned size;       /* bytes of the element */
    unsigned nwords, w;  /* registers of the element, this one's index (0 = most significant) */
    int writable, is_bool;
    uint32_t target;     /* for the write log */
} cell;

static mb_item *find_item(mb_shared *m, int table, unsigned a)
{
    for (size_t i = 0; i < m->nitems; i++) {
        mb_item *it = &m->items[i];
        if (it->table == table && a >= it->addr && a < it->addr + it->nregs) return it;
    }
    return NULL;
}

static int item_cell(mb_shared *m, int table, unsigned a, cell *c)
{
    mb_item *it = find_item(m, table, a);
    if (!it) return -1;
    *c = (cell){ m->snap[m->front].items[it - m->items], it->size, it->nregs, a - it->addr, it->writable,
                 it->is_bool, MB_REC_ITEM | (uint32_t)(it - m->items) };
    return 0;
}

static void img_cell(mb_shared *m, uint8_t *p, unsigned size, unsigned nwords, unsigned w, int writable, cell *c)
{
    *c = (cell){ p, size, nwords, w, writable, 0, (uint32_t)(p - (uint8_t *)&m->snap[m->front].img) };
}

static int resolve(mb_shared *m, int table, unsigned a, cell *c)
{
    plc_image *s = &m->snap[m->front].img;
    switch (table) {
    case MB_COILS:
        if (a < MB_BITS) { img_cell(m, s->qx + a, 1, 1, 0, 1, c); c->is_bool = 1; return 0; }
        break;
    case MB_DISCRETE:
        if (a < MB_BITS) { img_cell(m, s->ix + a, 1, 1, 0, 0, c); c->is_bool = 1; return 0; }
        break;
    case MB_INPUT:
        if (a < MB_INPUT_IMG) { img_cell(m, s->iw + 2 * a, 2, 1, 0, 0, c); return 0; }
        if (a >= MB_DIAG_BASE && a < MB_DIAG_BASE + MB_DIAG_N) {
            *c = (cell){ (uint8_t *)&m->snap[m->front].diag[a - MB_DIAG_BASE], 2, 1, 0, 0, 0, 0 };
            return 0;
        }
        if (a >= MB_IODIAG_BASE && a < MB_IODIAG_BASE + MB_IODIAG_N) {
            *c = (cell){ (uint8_t *)&m->snap[m->front].diag[MB_DIAG_N + a - MB_IODIAG_BASE], 2, 1, 0, 0, 0, 0 };
            return 0;
        }
        break;
    case MB_HOLDING:
        if (a < 1024) { img_cell(m, s->qw + 2 * a, 2, 1, 0, 1, c); return 0; }
        if (a < 2048) { img_cell(m, s->mw + 2 * (a - 1024), 2, 1, 0, 1, c); return 0; }
        if (a < 4096) { img_cell(m, s->md + 4 * ((a - 2048) / 2), 4, 2, (a - 2048) % 2, 1, c); return 0; }
        if (a < 8192) { img_cell(m, s->ml + 8 * ((a - 4096) / 4), 8, 4, (a - 4096) % 4, 1, c); return 0; }
        break;
    }
    return item_cell(m, table, a, c);
}

static void store(uint8_t *p, unsigned size, uint64_t x)
{
    uint8_t b = (uint8_t)x; uint16_t h = (uint16_t)x; uint32_t w = (uint32_t)x;
    switch (size) {
    case 1: memcpy(p, &b, 1); break;
    case 2: memcpy(p, &h, 2); break;
    case 4: memcpy(p, &w, 4); break;
    default: memcpy(p, &x, 8); break;
    }
}

static uint16_t cell_get(const cell *c)
{
    uint64_t x = plc_load(c->p, c->size);
    return (uint16_t)(x >> (16 * (c->nwords - 1 - c->w)));
}

/* Update the view and record the whole element in the batch filling. */
static void cell_set(mb_shared *m, const cell *c, uint16_t v)
{
    if (c->is_bool) store(c->p, c->size, v != 0);
    else {
        unsigned sh = 16 * (c->nwords - 1 - c->w);
        uint64_t x = plc_load(c->p, c->size);
        x = (x & ~((uint64_t)0xffff << sh)) | ((uint64_t)v << sh);
        store(c->p, c->size, x);
    }
    uint32_t *ix = (c->target & MB_REC_ITEM) ? &m->item_idx[c->target & ~MB_REC_ITEM]
                                              : &m->img_idx[c->target];
    mb_batch *b = m->fill;
    mb_rec *r = *ix ? &b->rec[*ix - 1] : &b->rec[b->n++];
    if (!*ix) *ix = (uint32_t)b->n;
    r->target = c->target;
    r->len = (uint8_t)c->size;
    memcpy(r->data, c->p, c->size);
}

/* ---- requests ---------------------------------------------------------- */

enum { EX_FUNCTION = 1, EX_ADDRESS = 2, EX_VALUE = 3, EX_BUSY = 6 };

static size_t exc(mb_shared *m, uint8_t *rsp, uint8_t fc, int code)
{
    atomic_fetch_add_explicit(&m->exceptions, 1, memory_order_relaxed);
    rsp[0] = fc | 0x80;
    rsp[1] = (uint8_t)code;
    return 2;
}

static unsigned u16(const uint8_t *p) { return (unsigned)p[0] << 8 | p[1]; }

/* Check [a, a+n) of a table: 0, or an exception code. */
static int check(mb_shared *m, int table, unsigned a, unsigned n, int write)
{
    if (a + n > 65536) return EX_ADDRESS;
    for (unsigned i = 0; i < n; i++) {
        cell c;
        if (resolve(m, table, a + i, &c)) return EX_ADDRESS;
        if (write && !c.writable) return EX_ADDRESS;
    }
    if (write && m->fill->n + n > MB_LOG_MAX) return EX_BUSY;
    return 0;
}

static size_t read_bits(mb_shared *m, int table, unsigned a, unsigned n, uint8_t *rsp)
{
    rsp[1] = (uint8_t)((n + 7) / 8);
    memset(rsp + 2, 0, rsp[1]);
    for (unsigned i = 0; i < n; i++) {
        cell c;
        resolve(m, table, a + i, &c);
        if (cell_get(&c)) rsp[2 + i / 8] |= (uint8_t)(1u << (i % 8));
    }
    return 2 + rsp[1];
}

static size_t read_regs(mb_shared *m, int table, unsigned a, unsigned n, uint8_t *rsp)
{
    rsp[1] = (uint8_t)(2 * n);
    for (unsigned i = 0; i < n; i++) {
        cell c;
        resolve(m, table, a + i, &c);
        uint16_t v = cell_get(&c);
        rsp[2 + 2 * i] = (uint8_t)(v >> 8);
        rsp[3 + 2 * i] = (uint8_t)v;
    }
    return 2 + 2 * n;
}

/* 1 when writing vals at [a, a+n) would leave a REAL or LREAL symbol nan
** or infinite (exception 03): the value would run through the program into
** the outputs. Whole values are judged as the request leaves them (the
** exponent is in the most significant register, so one register alone
** decides it as well). */
static int not_finite(mb_shared *m, unsigned a, unsigned n, const uint8_t *vals)
{
    for (unsigned i = 0; i < n;) {
        cell c;
        resolve(m, MB_HOLDING, a + i, &c);
        if (!(c.target & MB_REC_ITEM) || !m->items[c.target & ~MB_REC_ITEM].is_float) { i++; continue; }
        uint64_t x = plc_load(c.p, c.size);
        unsigned k = i;
        for (; k < n && c.w + (k - i) < c.nwords; k++) {
            unsigned sh = 16 * (c.nwords - 1 - (c.w + (k - i)));
            x = (x & ~((uint64_t)0xffff << sh)) | ((uint64_t)u16(vals + 2 * k) << sh);
        }
        if (c.size == 4) {
            uint32_t u = (uint32_t)x;
            float f;
            memcpy(&f, &u, 4);
            if (!isfinite(f)) return 1;
        } else {
            double d;
            memcpy(&d, &x, 8);
            if (!isfinite(d)) return 1;
        }
        i = k;
    }
    return 0;
}

static void write_regs(mb_shared *m, unsigned a, unsigned n, const uint8_t *vals)
{
    for (unsigned i = 0; i < n; i++) {
        cell c;
        resolve(m, MB_HOLDING, a + i, &c);
        cell_set(m, &c, (uint16_t)u16(vals + 2 * i));
    }
}

int mb_pdu_shape(const uint8_t *q, size_t n)
{
    unsigned cnt = n >= 5 ? u16(q + 3) : 0;
    switch (q[0]) {
    case 1: case 2: return n == 5 && cnt >= 1 && cnt <= 2000;
    case 3: case 4: return n == 5 && cnt >= 1 && cnt <= 125;
    case 5: return n == 5 && (cnt == 0xFF00 || cnt == 0);
    case 6: return n == 5;
    case 15: return n >= 6 && cnt >= 1 && cnt <= 1968 && q[5] == (cnt + 7) / 8 && n == 6u + q[5];
    case 16: return n >= 6 && cnt >= 1 && cnt <= 123 && q[5] == 2 * cnt && n == 6u + q[5];
    case 23: {
        if (n < 10) return 0;
        unsigned wn = u16(q + 7);
        return cnt >= 1 && cnt <= 125 && wn >= 1 && wn <= 121 && q[9] == 2 * wn && n == 10u + q[9];
    }
    }
    return -1;
}

static size_t serve(mb_shared *m, const uint8_t *q, size_t n, uint8_t *rsp)
{
    uint8_t fc = q[0];
    unsigned a = n >= 3 ? u16(q + 1) : 0, cnt = n >= 5 ? u16(q + 3) : 0;
    int e, shape = mb_pdu_shape(q, n);
    rsp[0] = fc;
    if (shape < 0) return exc(m, rsp, fc, EX_FUNCTION);
    if (!shape) return exc(m, rsp, fc, EX_VALUE);
    switch (fc) {
    case 1: case 2: {
        int t = fc == 1 ? MB_COILS : MB_DISCRETE;
        if ((e = check(m, t, a, cnt, 0))) return exc(m, rsp, fc, e);
        return read_bits(m, t, a, cnt, rsp);
    }
    case 3: case 4: {
        int t = fc == 3 ? MB_HOLDING : MB_INPUT;
        if ((e = check(m, t, a, cnt, 0))) return exc(m, rsp, fc, e);
        return read_regs(m, t, a, cnt, rsp);
    }
    case 5: {
        if ((e = check(m, MB_COILS, a, 1, 1))) return exc(m, rsp, fc, e);
        cell c;
        resolve(m, MB_COILS, a, &c);
        cell_set(m, &c, cnt ? 1 : 0);
        memcpy(rsp, q, 5);
        return 5;
    }
    case 6: {
        if ((e = check(m, MB_HOLDING, a, 1, 1))) return exc(m, rsp, fc, e);
        if (not_finite(m, a, 1, q + 3)) return exc(m, rsp, fc, EX_VALUE);
        write_regs(m, a, 1, q + 3);
        memcpy(rsp, q, 5);
        return 5;
    }
    case 15: {
        if ((e = check(m, MB_COILS, a, cnt, 1))) return exc(m, rsp, fc, e);
        for (unsigned i = 0; i < cnt; i++) {
            cell c;
            resolve(m, MB_COILS, a + i, &c);
            cell_set(m, &c, (q[6 + i / 8] >> (i % 8)) & 1);
        }
        memcpy(rsp, q, 5);
        return 5;
    }
    case 16: {
        if ((e = check(m, MB_HOLDING, a, cnt, 1))) return exc(m, rsp, fc, e);
        if (not_finite(m, a, cnt, q + 6)) return exc(m, rsp, fc, EX_VALUE);
        write_regs(m, a, cnt, q + 6);
        memcpy(rsp, q, 5);
        return 5;
    }
    case 23: {
        unsigned wa = u16(q + 5), wn = u16(q + 7);
        if ((e = check(m, MB_HOLDING, wa, wn, 1)) || (e = check(m, MB_HOLDING, a, cnt, 0)))
            return exc(m, rsp, fc, e);
        if (not_finite(m, wa, wn, q + 10)) return exc(m, rsp, fc, EX_VALUE);
        write_regs(m, wa, wn, q + 10);        /* the write comes first */
        return read_regs(m, MB_HOLDING, a, cnt, rsp);
    }
    }
    return exc(m, rsp, fc, EX_FUNCTION);
}

size_t mb_process(mb_shared *m, const uint8_t *q, size_t n, uint8_t *rsp)
{
    atomic_fetch_add_explicit(&m->requests, 1, memory_order_relaxed);
    if (n < 1) return exc(m, rsp, 0, EX_FUNCTION);
    mb_flush(m);                       /* serve from the newest snapshot */
    size_t r;
    int e = 0;
    if (m->block.touches && (q[0] == 3 || q[0] == 6 || q[0] == 16 || q[0] == 23) && m->block.touches(q, n)) {
        r = m->block.serve(m->block.arg, q, n, rsp, &e);
        if (e) atomic_fetch_add_explicit(&m->exceptions, 1, memory_order_relaxed);
    } else {
        r = serve(m, q, n, rsp);
    }
    mb_flush(m);                       /* and hand a write over at once */
    return r;
}

/* ---- exchange with the scan -------------------------------------------- */

/* Copy a batch's records into a snapshot (items: its symbol values) or, with
** items NULL, into the scan's image and the program's variables. */
static void replay(mb_shared *m, const mb_batch *b, plc_image *img, uint8_t (*items)[8])
{
    for (size_t i = 0; i < b->n; i++) {
        const mb_rec *r = &b->rec[i];
        if (r->target & MB_REC_ITEM) {
            size_t k = r->target & ~MB_REC_ITEM;
            memcpy(items ? items[k] : m->items[k].var, r->data, r->len);
        } else {
            memcpy((uint8_t *)img + r->target, r->data, r->len);
        }
    }
}

/* The server takes the newest snapshot as its view, with the writes it
** does not hold yet: the batch handed over (unless landed before the
** snapshot) and the one filling. */
static void take_snapshot(mb_shared *m)
{
    if (!(atomic_load_explicit(&m->mid, memory_order_acquire) & MB_FRESH)) return;
    unsigned old = atomic_exchange_explicit(&m->mid, m->front, memory_order_acq_rel);
    m->front = old & 3u;
    mb_snap *v = &m->snap[m->front];
    if (v->applied < m->given->seq) replay(m, m->given, &v->img, v->items);
    replay(m, m->fill, &v->img, v->items);
}

/* Hand the batch filling to the scan once the scan landed the previous one
** and the view holds it (the previous batch's buffer is reused). */
static void hand_over(mb_shared *m)
{
    mb_batch *b = m->fill;
    if (!b->n || atomic_load_explicit(&m->ready, memory_order_acquire)) return;
    if (m->snap[m->front].applied < m->given->seq) return;
    for (size_t i = 0; i < b->n; i++) {
        uint32_t t = b->rec[i].target;
        if (t & MB_REC_ITEM) m->item_idx[t & ~MB_REC_ITEM] = 0;
        else m->img_idx[t] = 0;
    }
    b->seq = m->given->seq + 1;
    m->fill = m->given;
    m->fill->n = 0;
    m->given = b;
    atomic_store_explicit(&m->ready, 1, memory_order_release);
}

int mb_flush(mb_shared *m)
{
    take_snapshot(m);
    hand_over(m);
    int more = m->block.flush && m->block.flush(m->block.arg);
    return more || m->fill->n > 0 || atomic_load_explicit(&m->ready, memory_order_relaxed);
}

void mb_apply(mb_shared *m, plc_image *img)
{
    if (!atomic_load_explicit(&m->ready, memory_order_acquire)) return;
    replay(m, m->given, img, NULL);
    m->landed = m->given->seq;
    atomic_store_explicit(&m->ready, 0, memory_order_release);
}

void mb_publish(mb_shared *m, const plc_image *img, const uint16_t *diag)
{
    mb_snap *b = &m->snap[m->back];
    plc_image *s = &b->img;
    memcpy(s->ix, img->ix, sizeof s->ix);
    memcpy(s->qx, img->qx, sizeof s->qx);
    memcpy(s->iw, img->iw, sizeof s->iw);
    memcpy(s->qw, img->qw, sizeof s->qw);
    memcpy(s->mw, img->mw, sizeof s->mw);
    memcpy(s->md, img->md, sizeof s->md);
    memcpy(s->ml, img->ml, sizeof s->ml);
    for (size_t i = 0; i < m->nitems; i++)
        memcpy(b->items[i], m->items[i].var, m->items[i].size);
    if (diag) memcpy(b->diag, diag, sizeof b->diag);
    b->applied = m->landed;
    unsigned old = atomic_exchange_explicit(&m->mid, m->back | MB_FRESH, memory_order_acq_rel);
    m->back = old & 3u;
}

void mb_drain(mb_shared *m, plc_image *img)
{
    mb_apply(m, img);
    replay(m, m->fill, img, NULL);
    m->fill->n = 0;
}

/* ---- set-up ------------------------------------------------------------ */

static const struct { const char *name; unsigned size; } types[] = {
    { "BOOL", 1 }, { "SINT", 1 }, { "USINT", 1 }, { "BYTE", 1 },
    { "INT", 2 }, { "UINT", 2 }, { "WORD", 2 },
    { "DINT", 4 }, { "UDINT", 4 }, { "DWORD", 4 }, { "REAL", 4 },
    { "LINT", 8 }, { "ULINT", 8 }, { "LWORD", 8 }, { "LREAL", 8 },
};

static unsigned fixed_end(int table)
{
    switch (table) {
    case MB_COILS: case MB_DISCRETE: return MB_BITS;
    case MB_INPUT: return MB_DIAG_BASE + MB_DIAG_N;
    default: return MB_HOLDING_N;
    }
}

static mb_shared *sym_fail(mb_shared *m, const plc_config *c, const cfg_symbol *y,
                           char *err, size_t errlen, const char *fmt, ...)
{
    char msg[300];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (snprintf(err, errlen, "%s:%d: [modbus.symbols] %s: %s", c->file, y->line, y->path, msg) < 0) err[0] = 0;
    mb_free(m);
    return NULL;
}

mb_shared *mb_new(const plc_config *c, const plc_program *p, char *err, size_t errlen)
{
    static const char *tabs[] = { "coil", "discrete input", "input register", "holding register" };
    mb_shared *m = calloc(1, sizeof *m);
    if (!m) { snprintf(err, errlen, "out of memory"); return NULL; }
    pthread_mutex_init(&m->serve, NULL);
    m->front = 0; m->back = 2;
    atomic_init(&m->mid, 1u);
    m->fill = &m->batch[0];
    m->given = &m->batch[1];
    size_t ns = c->nsymbols ? (size_t)c->nsymbols : 1;
    if (!(m->items = calloc(ns, sizeof *m->items)) || !(m->item_idx = calloc(ns, sizeof *m->item_idx))
        || !(m->snap[0].items = calloc(ns, 8)) || !(m->snap[1].items = calloc(ns, 8))
        || !(m->snap[2].items = calloc(ns, 8))) {
        mb_free(m);
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    for (int i = 0; i < c->nsymbols; i++) {
        const cfg_symbol *y = &c->symbols[i];
        mb_item *it = &m->items[i];
#define FAIL(...) return sym_fail(m, c, y, err, errlen, __VA_ARGS__)
        const plc_var *v = plc_var_find(p, y->path);
        if (!v) FAIL("no such variable in the program (see VARIABLES.csv)");
        unsigned size = 0;
        for (size_t t = 0; t < sizeof types / sizeof types[0]; t++)
            if (!strcasecmp(v->type, types[t].name)) size = types[t].size;
        if (!size) FAIL("type %s cannot be mapped (elementary types only)", v->type);
        it->is_bool = !strcasecmp(v->type, "BOOL");
        it->is_float = !strcasecmp(v->type, "REAL") || !strcasecmp(v->type, "LREAL");
        if ((y->table == MB_COILS || y->table == MB_DISCRETE) && !it->is_bool)
            FAIL("a %s holds a BOOL, not a %s", tabs[y->table], v->type);
        it->path = v->path;
        it->table = y->table;
        it->writable = y->writable;
        it->addr = y->addr;
        it->size = size;
        it->nregs = size <= 2 ? 1 : size / 2;
        it->var = plc_var_addr(v);
        if (it->addr < fixed_end(it->table))
            FAIL("%s %u lies inside the fixed map (0..%u)", tabs[it->table], it->addr, fixed_end(it->table) - 1);
        if (it->addr + it->nregs > 65536) FAIL("does not fit below address 65536");
        if (it->table == MB_INPUT && it->addr < MB_IODIAG_BASE + MB_IODIAG_N && it->addr + it->nregs > MB_IODIAG_BASE)
            FAIL("input registers %d..%d are the I/O backends' diagnostics (docs/modbus.md)", MB_IODIAG_BASE,
                 MB_IODIAG_BASE + MB_IODIAG_N - 1);
        if (it->table == MB_HOLDING && it->addr < MB_TRACE_END && it->addr + it->nregs > MB_TRACE_BASE)
            FAIL("holding registers %d..%d are the trace block (docs/trace.md)", MB_TRACE_BASE, MB_TRACE_END - 1);
        for (int j = 0; j < i; j++) {
            mb_item *o = &m->items[j];
            if (o->table == it->table && it->addr < o->addr + o->nregs && o->addr < it->addr + it->nregs)
                FAIL("overlaps %s at %s %u", o->path, tabs[o->table], o->addr);
        }
        m->nitems++;
#undef FAIL
    }
    return m;
}

void mb_free(mb_shared *m)
{
    if (!m) return;
    for (int i = 0; i < 3; i++) free(m->snap[i].items);
    pthread_mutex_destroy(&m->serve);
    free(m->items);
    free(m->item_idx);
    free(m);
}
