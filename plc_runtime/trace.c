/* trace.c: see trace.h and docs/trace.md. */
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "plc_image.h"
#include "trace.h"

#define ACQ memory_order_acquire
#define REL memory_order_release
#define RLX memory_order_relaxed

static const struct { const char *name; int type; } types[] = {
    { "BOOL", TT_BOOL }, { "SINT", TT_SINT }, { "USINT", TT_USINT }, { "BYTE", TT_BYTE },
    { "INT", TT_INT }, { "UINT", TT_UINT }, { "WORD", TT_WORD }, { "DINT", TT_DINT },
    { "UDINT", TT_UDINT }, { "DWORD", TT_DWORD }, { "LINT", TT_LINT }, { "ULINT", TT_ULINT },
    { "LWORD", TT_LWORD }, { "REAL", TT_REAL }, { "LREAL", TT_LREAL },
};

int trace_type(const plc_var *v)
{
    for (size_t i = 0; i < sizeof types / sizeof types[0]; i++)
        if (!strcasecmp(v->type, types[i].name)) return types[i].type;
    return TT_NONE;
}

double trace_number(uint64_t raw, int type)
{
    float f;
    double d;
    switch (type) {
    case TT_BOOL: return raw != 0;
    case TT_SINT: return (int8_t)raw;
    case TT_INT: return (int16_t)raw;
    case TT_DINT: return (int32_t)raw;
    case TT_LINT: return (double)(int64_t)raw;
    case TT_REAL: { uint32_t u = (uint32_t)raw; memcpy(&f, &u, 4); return f; }
    case TT_LREAL: memcpy(&d, &raw, 8); return d;
    default: return (double)raw;
    }
}

trace *trace_new(uint32_t cap)
{
    trace *t = calloc(1, sizeof *t);
    if (!t) return NULL;
    t->cap = cap;
    for (int i = 0; i < 2; i++) {
        trace_buf *b = &t->buf[i];
        b->val = malloc((size_t)cap * TRACE_CHANNELS * sizeof *b->val);
        b->cycle = malloc((size_t)cap * sizeof *b->cycle);
        b->tick = malloc((size_t)cap * sizeof *b->tick);
        if (!b->val || !b->cycle || !b->tick) { trace_free(t); return NULL; }
        memset(b->val, 0, (size_t)cap * TRACE_CHANNELS * sizeof *b->val);
        memset(b->cycle, 0, (size_t)cap * sizeof *b->cycle);
        memset(b->tick, 0, (size_t)cap * sizeof *b->tick);
        atomic_init(&b->owner, 0);
    }
    return t;
}

void trace_free(trace *t)
{
    if (!t) return;
    for (int i = 0; i < 2; i++) {
        free(t->buf[i].val);
        free(t->buf[i].cycle);
        free(t->buf[i].tick);
    }
    free(t);
}

/* ---- the scan's side ------------------------------------------------------ */

static void publish(trace *t, int state)
{
    t->state = state;
    atomic_store_explicit(&t->state_pub, state, REL);
}

/* Take a free buffer and start filling it; else wait for one. */
static void start(trace *t)
{
    trace_buf *b = NULL;
    for (int i = 0; i < 2 && !b; i++)
        if (atomic_load_explicit(&t->buf[i].owner, ACQ) == 0) b = &t->buf[i];
    if (!b) { publish(t, TRACE_WAIT_BUFFER); return; }
    atomic_store_explicit(&b->owner, 1, RLX);
    t->cur = b;
    t->w = t->n = t->dc = 0;
    publish(t, TRACE_ARMED);
}

static int triggered(trace *t)
{
    const trace_setup *s = &t->run;
    if (s->trig == TRIG_MANUAL) {
        if (!atomic_load_explicit(&t->trig_req, RLX)) return 0;
        atomic_store_explicit(&t->trig_req, 0, RLX);
        return 1;
    }
    double x = trace_number(plc_load(s->tv.addr, s->tv.size), s->tv.type), p = t->prev;
    int have = t->n > 1;
    t->prev = x;
    if (!have) return 0;
    switch (s->trig) {
    case TRIG_RISE: return p == 0 && x != 0;
    case TRIG_FALL: return p != 0 && x == 0;
    case TRIG_UP: return p < s->level && x >= s->level;
    default: return p > s->level && x <= s->level;
    }
}

static void complete(trace *t)
{
    trace_buf *b = t->cur;
    b->setup = t->run;
    b->first = t->first;
    b->seq = ++t->seq;
    atomic_store_explicit(&b->owner, 2, REL);
    atomic_store_explicit(&t->done_seq, t->seq, REL);
    t->cur = NULL;
    if (t->run.repeat) start(t);
    else publish(t, TRACE_IDLE);
}

void trace_cycle(trace *t, uint32_t cycle, uint32_t tick)
{
    if (atomic_load_explicit(&t->stop_req, ACQ)) {
        atomic_store_explicit(&t->stop_req, 0, RLX);
        if (t->cur) atomic_store_explicit(&t->cur->owner, 0, REL);
        t->cur = NULL;
        publish(t, TRACE_IDLE);
    }
    if (atomic_load_explicit(&t->arm_req, ACQ)) {
        t->run = t->req;
        atomic_store_explicit(&t->arm_req, 0, REL);
        start(t);
    }
    if (t->state == TRACE_WAIT_BUFFER) start(t);
    if (t->state != TRACE_ARMED && t->state != TRACE_TRIGGERED) return;
    const trace_setup *s = &t->run;
    uint32_t d = t->dc;                    /* a sample when it is 0 */
    t->dc = d + 1 == s->decim ? 0 : d + 1;
    if (d) return;
    trace_buf *b = t->cur;
    uint64_t *v = b->val + (size_t)t->w * (size_t)s->nchan;
    for (int c = 0; c < s->nchan; c++) v[c] = plc_load(s->ch[c].addr, s->ch[c].size);
    b->cycle[t->w] = cycle;
    b->tick[t->w] = tick;
    if (t->n < s->samples) t->n++;
    if (t->state == TRACE_ARMED && t->n > s->pre && triggered(t)) {
        t->first = t->w >= s->pre ? t->w - s->pre : t->w + s->samples - s->pre;
        t->left = s->samples - s->pre;
        publish(t, TRACE_TRIGGERED);
    } else if (t->state == TRACE_ARMED && s->trig != TRIG_MANUAL && t->n <= s->pre) {
        t->prev = trace_number(plc_load(s->tv.addr, s->tv.size), s->tv.type);
    }
    if (++t->w == s->samples) t->w = 0;
    if (t->state == TRACE_TRIGGERED && --t->left == 0) complete(t);
}

/* ---- the server's side ---------------------------------------------------- */

int trace_running(trace *t)
{
    if (atomic_load_explicit(&t->stop_req, ACQ)) return 0;
    return atomic_load_explicit(&t->arm_req, ACQ) || atomic_load_explicit(&t->state_pub, ACQ) != TRACE_IDLE;
}

/* Give back every completed capture (the held one included). */
static void give_back(trace *t)
{
    t->held = NULL;
    for (int i = 0; i < 2; i++) {
        int two = 2;
        atomic_compare_exchange_strong_explicit(&t->buf[i].owner, &two, 0, REL, RLX);
    }
}

void trace_arm(trace *t, const trace_setup *setup)
{
    give_back(t);
    t->req = *setup;
    atomic_store_explicit(&t->trig_req, 0, RLX);
    atomic_store_explicit(&t->arm_req, 1, REL);
}

void trace_stop(trace *t)
{
    if (atomic_load_explicit(&t->arm_req, ACQ) || atomic_load_explicit(&t->state_pub, ACQ) != TRACE_IDLE)
        atomic_store_explicit(&t->stop_req, 1, REL);
}

void trace_trigger(trace *t)
{
    atomic_store_explicit(&t->trig_req, 1, REL);
}

trace_buf *trace_take(trace *t)
{
    if (t->held) return t->held;
    trace_buf *best = NULL;
    for (int i = 0; i < 2; i++) {
        trace_buf *b = &t->buf[i];
        if (atomic_load_explicit(&b->owner, ACQ) == 2 && (!best || b->seq < best->seq)) best = b;
    }
    return t->held = best;
}

void trace_next(trace *t)
{
    if (t->held) atomic_store_explicit(&t->held->owner, 0, REL);
    t->held = NULL;
}

uint32_t trace_index(const trace_buf *b, uint32_t i)
{
    uint32_t k = b->first + i;
    return k >= b->setup.samples ? k - b->setup.samples : k;
}

uint64_t trace_value(const trace_buf *b, int c, uint32_t i)
{
    return b->val[(size_t)trace_index(b, i) * (size_t)b->setup.nchan + (size_t)c];
}
