/*
** stats.h: cycle statistics. One writer (the scan thread) records each
** cycle's wake latency and execution time; other threads read summaries at
** any time (relaxed atomics: a summary may straddle a cycle, never tears a
** counter). Histograms of 1 us bins up to STATS_BINS us, then one overflow
** bin (percentiles falling in it report the maximum).
*/
#ifndef PLC_STATS_H
#define PLC_STATS_H

#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>

#define STATS_BINS 10000

typedef struct stat_hist {
    _Atomic uint64_t n, sum_ns, min_ns, max_ns;
    _Atomic uint32_t bin[STATS_BINS + 1];
} stat_hist;

typedef struct stat_summary {
    uint64_t n, min_ns, max_ns, mean_ns, p99_ns, p999_ns;
} stat_summary;

typedef struct plc_stats {
    stat_hist exec, lat;
    _Atomic uint64_t cycles, overruns, missed, io_errors;
    /* overruns in which the program's execution alone lasted a period or
       more (too slow for the period); the others began with a late wake-up */
    _Atomic uint64_t overruns_exec;
} plc_stats;

void stats_reset(plc_stats *s);
void stat_add(stat_hist *h, uint64_t ns);          /* scan thread only */
void stat_summarize(const stat_hist *h, stat_summary *out);
void stats_print(FILE *f, const plc_stats *s, uint64_t ticktime_ns);

#endif
