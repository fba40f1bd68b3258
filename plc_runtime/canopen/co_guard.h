/* Node guarding (CiA 301) for one node: the master sends a remote frame on
 * 0x700 + node every guard time; the node answers with its NMT state and a
 * toggle bit that alternates from 0 after each (re)start.  An answer whose
 * toggle bit is not the expected one is no answer.  The node is lost when no
 * good answer came for guard time x life factor; the RTRs go on while it is
 * lost, so that its first good answer says it is back.
 * The node guards the master in turn with the same two numbers (0x100C,
 * 0x100D), written at configuration. */
#ifndef CO_GUARD_H
#define CO_GUARD_H

#include "co_frame.h"

enum co_guard_event {
    CO_GUARD_NONE,
    CO_GUARD_STATE,         /* a good answer with a state different from the last */
    CO_GUARD_TOGGLE,        /* an answer with the wrong toggle bit: ignored */
    CO_GUARD_LOST,          /* no good answer for guard time x life factor */
    CO_GUARD_BACK           /* a lost node answers again */
};

typedef struct co_guard {
    uint8_t node;
    uint8_t life;           /* life time factor */
    uint8_t active;         /* guarding started */
    uint8_t lost;
    uint8_t toggle;         /* expected toggle bit of the next answer (0 or 0x80) */
    uint8_t state;          /* NMT state of the last good answer */
    co_time period;         /* guard time, ns; 0 = not guarded */
    co_time last;           /* time of the last good answer (or of the start) */
    co_time next_rtr;
    uint32_t rtrs, answers, toggle_errors, losses;
} co_guard;

void co_guard_init(co_guard *g, uint8_t node, co_time period, uint8_t life);
/* (Re)start guarding at now: the toggle expected is 0 again. */
void co_guard_start(co_guard *g, co_time now);
/* Feed a frame; frames of other ids, remote frames and boot-ups give
 * CO_GUARD_NONE. */
enum co_guard_event co_guard_rx(co_guard *g, const co_frame *f, co_time now);
/* Check the life time; *rtr is set to 1 and f filled when an RTR is due. */
enum co_guard_event co_guard_tick(co_guard *g, co_time now, co_frame *f, int *rtr);

#endif
