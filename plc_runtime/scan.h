/*
** scan.h: the real-time scan thread. Each period (absolute
** clock_nanosleep on CLOCK_MONOTONIC): read inputs -> apply Modbus writes
** -> run the program -> publish to Modbus -> write outputs; forcing
** (force.h) after the inputs and after the program, the trace (trace.h)
** at the end of the cycle. The Modbus
** steps take and give whole buffers (mbmap.h): no lock, no waiting, no
** allocation; their longest cost is kept for the diagnostics. A cycle that
** ends past the next period boundary is an overrun: counted, and the next
** cycle starts on the first boundary still ahead (never a burst).
*/
#ifndef SCAN_H
#define SCAN_H

#include <stdatomic.h>
#include <stddef.h>
#include "force.h"
#include "io_backend.h"
#include "mbmap.h"
#include "program.h"
#include "stats.h"
#include "trace.h"

typedef struct scan_sample { void *src, *dst; size_t n; } scan_sample;

typedef struct scan {
    const plc_program *prog;
    const io_backend_ops *io;
    void *io_state;
    mb_shared *mb;                 /* NULL: no Modbus */
    trace *trace;                  /* NULL: no trace */
    forcing *force;                /* NULL: no forcing */
    uint64_t period_ns;
    long base_sec, base_nsec;      /* __CURRENT_TIME at PLC time 0 */
    plc_stats stats;
    _Atomic uint64_t exec_p99_ns, lat_p99_ns;   /* set by housekeeping */
    _Atomic uint64_t retain_saves, retain_errors;
    _Atomic int stop;
    /* the watchdog (scan_watchdog): SCAN_IN_PROGRAM while the program runs,
    ** since program_ns; SCAN_HALTED once the watchdog took the outputs */
    _Atomic int phase;
    _Atomic uint64_t program_ns;
    /* copies of variables taken by the scan between two cycles */
    _Atomic int sample_req;        /* 0 idle, 1 asked, 2 done */
    const scan_sample *samples;
    size_t nsamples;
    uint64_t started_ns;
} scan;

enum { SCAN_OUTSIDE = 0, SCAN_IN_PROGRAM = 1, SCAN_HALTED = 2 };

void *scan_thread(void *arg);
/* Housekeeping: 1 when the program has been running for limit_ns or more
** in one cycle (an endless loop, say); from then on the scan never touches
** the I/O, the image's publication or the Modbus exchange again, so that
** the caller owns the outputs. 0 otherwise (also once the program returned:
** the scan and the watchdog never both hold the outputs). */
int scan_watchdog(scan *s, uint64_t limit_ns);
/* One cycle: inputs, Modbus writes, program, publish, outputs. */
void scan_cycle(scan *s, uint64_t plc_ns, unsigned long tick);
uint64_t scan_now_ns(void);
/* Copy samples[] atomically with respect to cycles: through the scan when it
** runs (waiting up to timeout_ms), directly otherwise. 0, or -1 on timeout. */
int scan_sample_now(scan *s, const scan_sample *v, size_t n, int running, int timeout_ms);
/* Fill the diagnostic registers (mbmap.h MBD_*). */
void scan_diag(scan *s, uint16_t *diag);

#endif
