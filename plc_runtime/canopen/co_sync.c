#include <string.h>
#include "co_sync.h"

void co_sync_init(co_sync *s, unsigned every, uint8_t overflow)
{
    memset(s, 0, sizeof *s);
    s->every = every;
    s->overflow = (overflow >= 2 && overflow <= 240) ? overflow : 0;
    s->phase = every ? every - 1 : 0;     /* the first cycle sends one */
}

int co_sync_cycle(co_sync *s, co_frame *f)
{
    if (!s->every)
        return 0;
    if (++s->phase < s->every)
        return 0;
    s->phase = 0;
    memset(f, 0, sizeof *f);
    f->id = CO_FC_SYNC;
    if (s->overflow) {
        s->counter = s->counter >= s->overflow ? 1 : s->counter + 1;
        f->len = 1;
        f->data[0] = s->counter;
    }
    s->sent++;
    return 1;
}
