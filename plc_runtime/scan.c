/* scan.c: see scan.h. */
#include <errno.h>
#include <string.h>
#include <time.h>
#include "scan.h"

#define LD(x) atomic_load_explicit(&(x), memory_order_relaxed)

uint64_t scan_now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (uint64_t)t.tv_sec * 1000000000u + (uint64_t)t.tv_nsec;
}

static void sleep_until(uint64_t ns)
{
    struct timespec t = { (time_t)(ns / 1000000000u), (long)(ns % 1000000000u) };
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &t, NULL) == EINTR) {}
}

static void put32(uint16_t *d, int at, uint64_t v)
{
    if (v > 0xFFFFFFFFu) v = 0xFFFFFFFFu;
    d[at] = (uint16_t)(v >> 16);
    d[at + 1] = (uint16_t)v;
}

void scan_diag(scan *s, uint16_t *d)
{
    plc_stats *st = &s->stats;
    uint64_t n;
    memset(d, 0, MB_DIAG_ALL * sizeof *d);
    put32(d, MBD_CYCLES, LD(st->cycles));
    put32(d, MBD_OVERRUNS, LD(st->overruns));
    put32(d, MBD_MISSED, LD(st->missed));
    put32(d, MBD_OVERRUNS_EXEC, LD(st->overruns_exec));
    n = LD(st->exec.n);
    if (n) {
        put32(d, MBD_EXEC_MIN, LD(st->exec.min_ns) / 1000);
        put32(d, MBD_EXEC_MEAN, LD(st->exec.sum_ns) / n / 1000);
        put32(d, MBD_EXEC_MAX, LD(st->exec.max_ns) / 1000);
        put32(d, MBD_LAT_MIN, LD(st->lat.min_ns) / 1000);
        put32(d, MBD_LAT_MEAN, LD(st->lat.sum_ns) / n / 1000);
        put32(d, MBD_LAT_MAX, LD(st->lat.max_ns) / 1000);
    }
    put32(d, MBD_EXEC_P99, LD(s->exec_p99_ns) / 1000);
    put32(d, MBD_LAT_P99, LD(s->lat_p99_ns) / 1000);
    put32(d, MBD_TICK_US, s->period_ns / 1000);
    if (s->mb) {
        put32(d, MBD_CLIENTS, LD(s->mb->clients));
        put32(d, MBD_REFUSED, LD(s->mb->refused));
        put32(d, MBD_REQUESTS, LD(s->mb->requests));
        put32(d, MBD_EXCEPTIONS, LD(s->mb->exceptions));
        put32(d, MBD_EVICTED, LD(s->mb->evicted));
        put32(d, MBD_DROPPED, LD(s->mb->dropped));
        put32(d, MBD_EXCHANGE_MAX, LD(s->mb->exchange_max_ns) / 1000);
        put32(d, MBD_RTU_SERVED, LD(s->mb->rtu_served));
        put32(d, MBD_RTU_BAD, LD(s->mb->rtu_bad));
    }
    put32(d, MBD_RETAIN_SAVES, LD(s->retain_saves));
    put32(d, MBD_RETAIN_ERRORS, LD(s->retain_errors));
    put32(d, MBD_IO_ERRORS, LD(st->io_errors));
    if (s->force) put32(d, MBD_FORCED, (uint64_t)force_count(s->force));
    put32(d, MBD_UPTIME_S, (scan_now_ns() - s->started_ns) / 1000000000u);
    if (s->io->diag) {
        /* every backend's block from input register 20000; the first
        ** backend's first 64 registers also where they always were */
        s->io->diag(s->io_state, d + MB_DIAG_N, MB_IODIAG_N);
        memcpy(d + MBD_BACKEND, d + MB_DIAG_N, (MB_DIAG_N - MBD_BACKEND) * sizeof *d);
    }
}

static void take_samples(scan *s)
{
    if (atomic_load_explicit(&s->sample_req, memory_order_acquire) != 1) return;
    for (size_t i = 0; i < s->nsamples; i++)
        memcpy(s->samples[i].dst, s->samples[i].src, s->samples[i].n);
    atomic_store_explicit(&s->sample_req, 2, memory_order_release);
}

int scan_sample_now(scan *s, const scan_sample *v, size_t n, int running, int timeout_ms)
{
    if (!running) {
        for (size_t i = 0; i < n; i++) memcpy(v[i].dst, v[i].src, v[i].n);
        return 0;
    }
    s->samples = v;
    s->nsamples = n;
    atomic_store_explicit(&s->sample_req, 1, memory_order_release);
    for (int t = 0; t < timeout_ms * 4; t++) {
        if (atomic_load_explicit(&s->sample_req, memory_order_acquire) == 2) {
            atomic_store(&s->sample_req, 0);
            return 0;
        }
        struct timespec q = { 0, 250000 };
        nanosleep(&q, NULL);
    }
    /* withdraw the request; if the scan took it meanwhile, that is fine */
    int one = 1;
    if (!atomic_compare_exchange_strong(&s->sample_req, &one, 0)) {
        atomic_store(&s->sample_req, 0);
        return 0;
    }
    return -1;
}

/* One cycle's work, between the wake-up and the statistics (a function of
** its own so that its cost can be measured, e.g. by callgrind). */
__attribute__((noinline)) void scan_cycle(scan *s, uint64_t plc_ns, unsigned long tick)
{
    const plc_program *p = s->prog;
    uint16_t diag[MB_DIAG_ALL];
    if (s->io->read_inputs(s->io_state, &plc_img, plc_ns))
        atomic_fetch_add_explicit(&s->stats.io_errors, 1, memory_order_relaxed);
    uint64_t x0 = s->mb ? scan_now_ns() : 0, x1 = 0;
    if (s->mb) {
        mb_apply(s->mb, &plc_img);
        x1 = scan_now_ns();
    }
    if (s->force) {
        force_begin(s->force);
        force_apply(s->force, FORCE_AFTER_INPUTS);
    }
    uint64_t ns = (uint64_t)s->base_nsec + plc_ns % 1000000000u;
    p->now->tv_sec = s->base_sec + (long)(plc_ns / 1000000000u) + (long)(ns / 1000000000u);
    p->now->tv_nsec = (long)(ns % 1000000000u);
    atomic_store_explicit(&s->program_ns, scan_now_ns(), memory_order_relaxed);
    atomic_store(&s->phase, SCAN_IN_PROGRAM);
    p->run(tick);
    if (atomic_exchange(&s->phase, SCAN_OUTSIDE) == SCAN_HALTED) {
        atomic_store(&s->phase, SCAN_HALTED);       /* the watchdog holds the outputs */
        return;
    }
    if (s->force) force_apply(s->force, FORCE_AFTER_PROGRAM);
    if (s->trace) trace_cycle(s->trace, (uint32_t)LD(s->stats.cycles), (uint32_t)tick);
    take_samples(s);
    if (s->mb) {
        scan_diag(s, diag);
        uint64_t x2 = scan_now_ns();
        mb_publish(s->mb, &plc_img, diag);
        /* the exchange's cost: landing the writes plus publishing */
        uint64_t x = x1 - x0 + scan_now_ns() - x2;
        if (x > LD(s->mb->exchange_max_ns))
            atomic_store_explicit(&s->mb->exchange_max_ns, x, memory_order_relaxed);
    }
    if (s->io->write_outputs(s->io_state, &plc_img))
        atomic_fetch_add_explicit(&s->stats.io_errors, 1, memory_order_relaxed);
}

int scan_watchdog(scan *s, uint64_t limit_ns)
{
    if (!limit_ns || atomic_load(&s->phase) != SCAN_IN_PROGRAM) return 0;
    if (scan_now_ns() - atomic_load_explicit(&s->program_ns, memory_order_relaxed) < limit_ns) return 0;
    int in = SCAN_IN_PROGRAM;
    return atomic_compare_exchange_strong(&s->phase, &in, SCAN_HALTED);
}

void *scan_thread(void *arg)
{
    scan *s = arg;
    uint64_t period = s->period_ns, k = 0;
    uint64_t start = scan_now_ns() + period, next = start;

    while (!atomic_load_explicit(&s->stop, memory_order_relaxed)) {
        sleep_until(next);
        uint64_t wake = scan_now_ns();
        scan_cycle(s, next - start, (unsigned long)k);
        if (atomic_load(&s->phase) == SCAN_HALTED) break;
        uint64_t end = scan_now_ns();
        stat_add(&s->stats.lat, wake > next ? wake - next : 0);
        stat_add(&s->stats.exec, end - wake);
        atomic_store_explicit(&s->stats.cycles, LD(s->stats.cycles) + 1, memory_order_relaxed);
        next += period;
        k++;
        if (end >= next) {
            uint64_t miss = (end - next) / period + 1;
            next += miss * period;
            k += miss;
            atomic_store_explicit(&s->stats.overruns, LD(s->stats.overruns) + 1, memory_order_relaxed);
            atomic_store_explicit(&s->stats.missed, LD(s->stats.missed) + miss, memory_order_relaxed);
            if (end - wake >= period)
                atomic_store_explicit(&s->stats.overruns_exec, LD(s->stats.overruns_exec) + 1, memory_order_relaxed);
        }
    }
    return NULL;
}
