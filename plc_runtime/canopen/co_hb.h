/* Heartbeat consumer for one node (COB-ID 0x700 + node). Monitoring starts
 * with the first heartbeat; a node silent for longer than the consumer time
 * is lost until it is heard again. */
#ifndef CO_HB_H
#define CO_HB_H

#include "co_frame.h"

enum co_hb_event {
    CO_HB_NONE,         /* nothing new */
    CO_HB_STATE,        /* a heartbeat with a state different from the last */
    CO_HB_BOOTUP,       /* a boot-up message (state 0x00) */
    CO_HB_LOST,         /* consumer time elapsed without a heartbeat */
    CO_HB_BACK          /* a lost node is heard again */
};

typedef struct co_hb {
    uint8_t node;
    uint8_t state;          /* last state heard, CO_ST_UNKNOWN before */
    uint8_t lost;
    uint8_t active;         /* monitoring (a heartbeat has been heard) */
    co_time period;         /* consumer time, ns; 0 = not monitored */
    co_time last;           /* time of the last heartbeat */
    uint32_t bootups, losses;
} co_hb;

void co_hb_init(co_hb *h, uint8_t node, co_time period);
/* Feed a frame; frames of other ids give CO_HB_NONE. */
enum co_hb_event co_hb_rx(co_hb *h, const co_frame *f, co_time now);
/* Check the consumer time. */
enum co_hb_event co_hb_tick(co_hb *h, co_time now);

#endif
