/*
** Cost of one scan of a program with N axes (axes.st.in): 1 ms cycles.
**
**   epicpos_scan N WARM SCANS [timed]
**
** Runs WARM scans (start-up, and the axes' moves getting out of step), then
** SCANS scans through scan_counted(), never inlined, so that callgrind
** --toggle-collect counts them alone; with "timed" each of those is timed
** with clock_gettime and the mean, median, p99 and max printed in ns.
** Fails unless all N axes started up, none had a command refused or went
** into emergency, and they moved during the counted scans.  Built as plcrt
** builds a program: the configuration and resource files included.
*/
#include "Config0.c"
#include "Res0.c"
#include "accessor.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

IEC_TIME __CURRENT_TIME;
BOOL __DEBUG;
#define __LOCATED_VAR(type, name, ...) type __s##name; type *name = &__s##name;
#include "LOCATED_VARIABLES.h"
#include "../common/bench_clock.h"
#undef __LOCATED_VAR

static unsigned long tick;

static void scan(void)
{
    config_run__(tick++);
    __CURRENT_TIME.tv_nsec += (long)common_ticktime__;
    while (__CURRENT_TIME.tv_nsec >= 1000000000) {
        __CURRENT_TIME.tv_nsec -= 1000000000;
        __CURRENT_TIME.tv_sec++;
    }
}

__attribute__((noinline)) static void scan_counted(void) { scan(); }


int main(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: epicpos_scan N WARM SCANS [timed]\n");
        return 2;
    }
    long n = atol(argv[1]), warm = atol(argv[2]), scans = atol(argv[3]);
    int timed = argc > 4 && !strcmp(argv[4], "timed");
    long long *dt = timed ? calloc((size_t)scans, sizeof *dt) : NULL;
    if (scans < 1 || (timed && !dt)) return 2;

    config_init__();
    for (long i = 0; i < warm; i++) scan();
    DINT moves0 = __GET_VAR(RES0__INST0.NMOVES);
    for (long i = 0; i < scans; i++) {
        if (timed) {
            long long t0 = now_ns();
            scan_counted();
            dt[i] = now_ns() - t0;
        } else {
            scan_counted();
        }
    }
    DINT ready = __GET_VAR(RES0__INST0.NREADY), bad = __GET_VAR(RES0__INST0.NBAD);
    DINT moves = __GET_VAR(RES0__INST0.NMOVES) - moves0;
    if (ready != n || bad != 0 || moves < 1) {
        fprintf(stderr, "epicpos_scan: %d of %ld axes ready, %d in trouble, %d moves while counted\n",
                (int)ready, n, (int)bad, (int)moves);
        return 1;
    }
    printf("axes %ld scans %ld moves %d", n, scans, (int)moves);
    if (timed) {
        double sum = 0;
        for (long i = 0; i < scans; i++) sum += (double)dt[i];
        qsort(dt, (size_t)scans, sizeof *dt, cmp_ll);
        printf(" mean_ns %.0f median_ns %lld p99_ns %lld max_ns %lld", sum / (double)scans,
               dt[scans / 2], dt[scans * 99 / 100], dt[scans - 1]);
    }
    printf("\n");
    return 0;
}
