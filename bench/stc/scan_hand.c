/* The logic of scan.st written directly in C, as a programmer would. */
#include <math.h>
#include <stdint.h>
#include <stdbool.h>

typedef struct { float y; } filter;
typedef struct { int32_t n; bool done; } counter;

static struct {
    filter f[8];
    counter c[4];
    int32_t data[64];
    int32_t tick;
} s;

int32_t hand_out;

void hand_scan(void) {
    s.tick++;
    for (int i = 0; i < 64; i++) s.data[i] = (int32_t)((uint32_t)s.data[i] * 3u + (uint32_t)i - (uint32_t)s.tick);
    int32_t acc = 0;
    for (int i = 0; i < 64; i++) {
        if (s.data[i] % 2 == 0) acc = (int32_t)((uint32_t)acc + (uint32_t)(s.data[i] / 4));
        else acc = (int32_t)((uint32_t)acc - (uint32_t)s.data[i]);
    }
    for (int j = 0; j < 8; j++) s.f[j].y += 0.125f * ((float)acc - s.f[j].y);
    for (int j = 0; j < 4; j++) {
        if (s.c[j].n < 1000000) s.c[j].n++;
        s.c[j].done = s.c[j].n >= 1000000;
    }
    hand_out = acc + (int32_t)nearbyintf(s.f[7].y) + s.c[3].n;
}
