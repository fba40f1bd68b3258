#include "co_hb.h"
#include "co_nmt.h"

void co_hb_init(co_hb *h, uint8_t node, co_time period)
{
    *h = (co_hb){ .node = node, .state = CO_ST_UNKNOWN, .period = period };
}

enum co_hb_event co_hb_rx(co_hb *h, const co_frame *f, co_time now)
{
    if (f->id != (uint32_t)CO_FC_HB + h->node || f->rtr || f->len < 1)
        return CO_HB_NONE;
    uint8_t st = f->data[0] & 0x7F;
    uint8_t old = h->state, was_lost = h->lost;
    h->state = st;
    h->last = now;
    h->active = 1;
    h->lost = 0;
    if (st == CO_ST_BOOTUP) {
        h->bootups++;
        return CO_HB_BOOTUP;
    }
    if (was_lost)
        return CO_HB_BACK;
    return st != old ? CO_HB_STATE : CO_HB_NONE;
}

enum co_hb_event co_hb_tick(co_hb *h, co_time now)
{
    if (!h->period || !h->active || h->lost || now - h->last <= h->period)
        return CO_HB_NONE;
    h->lost = 1;
    h->losses++;
    return CO_HB_LOST;
}
