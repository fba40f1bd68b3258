/* SYNC producer (COB-ID 0x080): one SYNC every `every` PLC cycles,
 * optionally with the CiA 301 counter byte (1..overflow). */
#ifndef CO_SYNC_H
#define CO_SYNC_H

#include "co_frame.h"

typedef struct co_sync {
    unsigned every;         /* cycles between SYNCs, >= 1; 0 = no SYNC */
    unsigned phase;         /* cycles since the last SYNC */
    uint8_t overflow;       /* counter overflow value (2..240), 0 = no counter */
    uint8_t counter;
    uint32_t sent;
} co_sync;

void co_sync_init(co_sync *s, unsigned every, uint8_t overflow);
/* Call once per cycle: 1 and the SYNC in *f when one is due, else 0. */
int co_sync_cycle(co_sync *s, co_frame *f);

#endif
