/*
 * Cost of ISGDAMP per sample: one instance disabled, then with 1, 2 and 3
 * DIRECT stages (order 2, 53 Hz, Q 10, 1 ms), each called CALLS times on a
 * 53 Hz load speed after the call that takes its parameters.  Prints
 * "stages N ns_per_call X" lines: the best of 5 runs' means over the calls
 * (clock_gettime), less the same loop's cost without the call.
 * Built with the compiler's output of bench/isg/figures.st (which holds
 * ISGDAMP), configuration and resource files included as one translation
 * unit, as plcrt builds a program.
 *
 *   isg_cost CALLS
 */
#include "Config0.c"
#include "Res0.c"
#include "accessor.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

IEC_TIME __CURRENT_TIME;
BOOL __DEBUG;
#define __LOCATED_VAR(type, name, ...) type __s##name; type *name = &__s##name;
#include "LOCATED_VARIABLES.h"
#undef __LOCATED_VAR

#define V(x) __GET_VAR(x)

static ISGDAMP dmp;

__attribute__((noinline)) static void call_counted(ISGDAMP *d) { ISGDAMP_body__(d); }
__attribute__((noinline)) static void call_none(ISGDAMP *d) { __asm__ volatile("" : : "r"(d) : "memory"); }

static long long now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1000000000LL + t.tv_nsec;
}

int main(int argc, char **argv)
{
    long calls = argc > 1 ? atol(argv[1]) : 0;
    if (calls < 1) {
        fprintf(stderr, "usage: isg_cost CALLS\n");
        return 2;
    }
    double empty = -1.0;
    for (int n = 0; n <= 3; n++) {
        ISGDAMP_init__(&dmp, 0);
        V(dmp.V_MAX) = 100000.0;
        V(dmp.TS) = (IEC_TIME){0, 1000000};
        V(dmp.PARAM).ENABLE = n > 0;
        V(dmp.PARAM).V_ADD_MAX_FACT = 100;
        for (int i = 0; i < n; i++) {
            ISG_STAGE *s = &V(dmp.PARAM).STAGE.table[i];
            s->MODE = 1;
            s->FILTER.ORDER = 2;
            s->FILTER.FG_F0 = 53.0;
            s->FILTER.Q_FACTOR = 10.0;
            s->WEIGHT_FACT_NUM = 100;
            s->WEIGHT_FACT_DENOM = 200;
        }
        V(dmp.STANDSTILL) = 1;
        ISGDAMP_body__(&dmp);
        V(dmp.STANDSTILL) = 0;
        if (n > 0 && !V(dmp.ACTIVE)) {
            fprintf(stderr, "isg_cost: %d stages not active\n", n);
            return 1;
        }
        double best = -1.0, sum = 0.0;
        for (int run = 0; run < 10; run++) {
            void (*f)(ISGDAMP *) = run % 2 ? call_counted : call_none;
            long long t0 = now_ns();
            for (long k = 0; k < calls; k++) {
                V(dmp.V_IST2) = 7500.0 * sin(0.333 * (double)(k % 1000));
                V(dmp.V_SOLL) = 100.0;
                f(&dmp);
                sum += V(dmp.V_OUT);
            }
            double ns = (double)(now_ns() - t0) / (double)calls;
            if (run % 2 == 0) {
                empty = empty < 0.0 || ns < empty ? ns : empty;
            } else if (best < 0.0 || ns < best) {
                best = ns;
            }
        }
        printf("stages %d ns_per_call %.1f check %g\n", n, best - empty, sum);
    }
    return 0;
}
