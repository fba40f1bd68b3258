#include "co_guard.h"

void co_guard_init(co_guard *g, uint8_t node, co_time period, uint8_t life)
{
    *g = (co_guard){ .node = node, .period = period, .life = life ? life : 1 };
}

void co_guard_start(co_guard *g, co_time now)
{
    if (!g->period)
        return;
    g->active = 1;
    g->lost = 0;
    g->toggle = 0;
    g->last = now;
    g->next_rtr = now;
}

enum co_guard_event co_guard_rx(co_guard *g, const co_frame *f, co_time now)
{
    if (!g->period || !g->active || f->id != (uint32_t)CO_FC_HB + g->node || f->rtr || f->len < 1
        || (f->data[0] & 0x7F) == 0)
        return CO_GUARD_NONE;
    if ((f->data[0] & 0x80) != g->toggle) {
        g->toggle_errors++;
        return CO_GUARD_TOGGLE;
    }
    g->toggle ^= 0x80;
    g->answers++;
    uint8_t st = f->data[0] & 0x7F, old = g->state;
    g->state = st;
    g->last = now;
    if (g->lost) {
        g->lost = 0;
        return CO_GUARD_BACK;
    }
    return st != old ? CO_GUARD_STATE : CO_GUARD_NONE;
}

enum co_guard_event co_guard_tick(co_guard *g, co_time now, co_frame *f, int *rtr)
{
    *rtr = 0;
    if (!g->period || !g->active)
        return CO_GUARD_NONE;
    if (now >= g->next_rtr) {
        *f = (co_frame){ .id = (uint32_t)CO_FC_HB + g->node, .rtr = 1, .len = 1 };
        *rtr = 1;
        g->rtrs++;
        /* the next one a guard time on, never a burst after a late tick */
        g->next_rtr += g->period;
        if (g->next_rtr <= now)
            g->next_rtr = now + g->period;
    }
    if (!g->lost && now - g->last > g->period * g->life) {
        g->lost = 1;
        g->losses++;
        return CO_GUARD_LOST;
    }
    return CO_GUARD_NONE;
}
