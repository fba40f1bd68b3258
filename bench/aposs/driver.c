/*
 * Time the scans of the APOSS axis benchmark program (bench/aposs/axes.st.in).
 *
 *   driver scans
 *
 * Runs the program's first scan (the axes' set-up) and a warm-up second of
 * scans, then times `scans` scans one by one.  Prints on one line
 * "median_ns M p99_ns P moves N bad B max_ns X": the median and 99th
 * percentile of the cost of one scan, the POSA commands given during the run (%QD0) and
 * the axes with an error or a refused command (%QD1), and the dearest scan.  Only the generated
 * code's contract is used (entry points, located variables).
 */
#include <stdlib.h>
#include <time.h>

#include "plc_harness.h"
#include "../common/bench_clock.h"


int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: %s scans\n", argv[0]);
        return 2;
    }
    long n = atol(argv[1]);
    int32_t *moves = located("%QD0", NULL), *bad = located("%QD1", NULL);
    if (n < 100 || !moves || !bad) {
        fprintf(stderr, "%s: under 100 scans or no %%QD0/%%QD1\n", argv[0]);
        return 2;
    }
    long long *t = malloc(sizeof *t * (size_t)n);
    if (!t)
        return 1;
    config_init__();
    unsigned long tick = 0;
    for (; tick < 1000; tick++) {   /* set-up and warm-up: not timed */
        config_run__(tick);
        tick_clock();
    }
    int32_t moves0 = *moves;
    for (long i = 0; i < n; i++, tick++) {
        long long t0 = now_ns();
        config_run__(tick);
        t[i] = now_ns() - t0;
        tick_clock();
    }
    qsort(t, (size_t)n, sizeof *t, cmp_ll);
    printf("median_ns %lld p99_ns %lld moves %ld bad %ld max_ns %lld\n", t[n / 2], t[n * 99 / 100],
           (long)(*moves - moves0), (long)*bad, t[n - 1]);
    free(t);
    return 0;
}
