/* stats.c */
#include "stats.h"

#define LD(x) atomic_load_explicit(&(x), memory_order_relaxed)
#define ST(x, v) atomic_store_explicit(&(x), (v), memory_order_relaxed)

static void hist_reset(stat_hist *h)
{
    ST(h->n, 0); ST(h->sum_ns, 0); ST(h->min_ns, UINT64_MAX); ST(h->max_ns, 0);
    for (int i = 0; i <= STATS_BINS; i++) ST(h->bin[i], 0);
}

void stats_reset(plc_stats *s)
{
    hist_reset(&s->exec);
    hist_reset(&s->lat);
    ST(s->cycles, 0); ST(s->overruns, 0); ST(s->overruns_exec, 0); ST(s->missed, 0); ST(s->io_errors, 0);
}

void stat_add(stat_hist *h, uint64_t ns)
{
    uint64_t us = ns / 1000;
    unsigned b = us < STATS_BINS ? (unsigned)us : STATS_BINS;
    ST(h->bin[b], LD(h->bin[b]) + 1);
    ST(h->sum_ns, LD(h->sum_ns) + ns);
    if (ns < LD(h->min_ns)) ST(h->min_ns, ns);
    if (ns > LD(h->max_ns)) ST(h->max_ns, ns);
    ST(h->n, LD(h->n) + 1);
}

/* Upper edge of the bin holding the q-quantile, capped at the maximum. */
static uint64_t quantile(const stat_hist *h, uint64_t n, double q, uint64_t max)
{
    uint64_t want = (uint64_t)(q * (double)n), seen = 0;
    if (want >= n) want = n - 1;
    for (unsigned b = 0; b < STATS_BINS; b++) {
        seen += LD(h->bin[b]);
        if (seen > want) {
            uint64_t edge = (uint64_t)(b + 1) * 1000;
            return edge < max ? edge : max;
        }
    }
    return max;
}

void stat_summarize(const stat_hist *h, stat_summary *o)
{
    o->n = LD(h->n);
    if (!o->n) { *o = (stat_summary){0}; return; }
    o->min_ns = LD(h->min_ns);
    o->max_ns = LD(h->max_ns);
    o->mean_ns = LD(h->sum_ns) / o->n;
    o->p99_ns = quantile(h, o->n, 0.99, o->max_ns);
    o->p999_ns = quantile(h, o->n, 0.999, o->max_ns);
}

static void line(FILE *f, const char *name, const stat_hist *h)
{
    stat_summary s;
    stat_summarize(h, &s);
    fprintf(f, "  %-13s min %8.1f  mean %8.1f  p99 %8.1f  p99.9 %8.1f  max %8.1f us\n",
            name, s.min_ns / 1e3, s.mean_ns / 1e3, s.p99_ns / 1e3,
            s.p999_ns / 1e3, s.max_ns / 1e3);
}

void stats_print(FILE *f, const plc_stats *s, uint64_t tick)
{
    fprintf(f, "plcrt: statistics: %llu cycles of %.1f us, %llu overruns (%llu periods skipped), %llu I/O errors\n",
            (unsigned long long)LD(s->cycles), tick / 1e3,
            (unsigned long long)LD(s->overruns), (unsigned long long)LD(s->missed),
            (unsigned long long)LD(s->io_errors));
    if (LD(s->overruns))
        fprintf(f, "  overruns: %llu with the program's execution alone over the period, %llu after a late wake-up\n",
                (unsigned long long)LD(s->overruns_exec),
                (unsigned long long)(LD(s->overruns) - LD(s->overruns_exec)));
    line(f, "wake latency", &s->lat);
    line(f, "execution", &s->exec);
}
