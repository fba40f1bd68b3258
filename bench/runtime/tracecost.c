/*
** tracecost: what a 16-channel trace adds to a scan, per cycle. The trace
** engine (plc_runtime/trace.c) is called as the scan calls it, armed on a
** trigger that never fires (the ring keeps turning: the costliest steady
** state), 16 DINT channels, 16384 samples; beside the same loop without
** the trace. Twice: with the data hot in cache, and with 4 MB of other
** memory walked between cycles (as a 1 ms scan finds its caches after the
** rest of the machine ran), the walk not timed.
**
** usage: tracecost [CYCLES]   prints mean ns per cycle
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "trace.h"

static volatile int32_t vars[16];
static volatile uint8_t trig;

static uint64_t now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (uint64_t)t.tv_sec * 1000000000u + (uint64_t)t.tv_nsec;
}

/* the stand-in for a program: every channel changes every cycle */
__attribute__((noinline)) static void program(uint32_t c)
{
    for (int i = 0; i < 16; i++) vars[i] = (int32_t)(c * (uint32_t)(i + 1));
}

/* Cycles alternately without and with the trace (so that drift and noise
** fall on both alike); the mean ns of each in base and with. A cycle over
** 20 us was preempted (a shared machine): left out of both means, counted. */
static unsigned long preempted;
static void run(trace *t, uint32_t cycles, uint8_t *junk, size_t njunk, double *base, double *with)
{
    uint64_t sum[2] = { 0, 0 }, n[2] = { 0, 0 };
    for (uint32_t c = 0; c < 2 * cycles; c++) {
        int on = c & 1;
        if (junk) for (size_t k = 0; k < njunk; k += 64) junk[k]++;
        uint64_t a = now_ns();
        program(c);
        if (on) trace_cycle(t, c / 2, c / 2);
        uint64_t d = now_ns() - a;
        if (d > 20000) { preempted++; continue; }
        sum[on] += d;
        n[on]++;
    }
    *base = n[0] ? (double)sum[0] / (double)n[0] : 0;
    *with = n[1] ? (double)sum[1] / (double)n[1] : 0;
}

int main(int argc, char **argv)
{
    uint32_t cycles = argc > 1 ? (uint32_t)atoi(argv[1]) : 200000;
    trace *t = trace_new(16384);
    size_t njunk = 4u << 20;
    uint8_t *junk = calloc(1, njunk);
    if (!t || !junk) return 1;
    trace_setup s;
    memset(&s, 0, sizeof s);
    for (int i = 0; i < 16; i++) s.ch[i] = (trace_chan){ (const void *)&vars[i], (uint32_t)i, 4, TT_DINT };
    s.nchan = 16;
    s.decim = 1;
    s.samples = 16384;
    s.pre = 100;
    s.trig = TRIG_RISE;
    s.tv = (trace_chan){ (const void *)&trig, 16, 1, TT_BOOL };
    trace_arm(t, &s);
    for (int pass = 0; pass < 2; pass++) {
        uint8_t *j = pass ? junk : NULL;
        uint32_t n = pass ? cycles / 10 : cycles;
        double base, with;
        run(t, n, j, njunk, &base, &with);
        printf("  %s: scan stand-in %.0f ns/cycle, with a 16-channel trace %.0f ns/cycle: the trace adds %.0f ns "
               "(target <= 1000)\n", pass ? "caches cold (4 MB walked between cycles)" : "caches hot",
               base, with, with - base);
    }
    printf("  (%lu cycles over 20 us, preempted, left out)\n", preempted);
    trace_free(t);
    free(junk);
    return 0;
}
