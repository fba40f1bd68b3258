/*
** trace.h: a cycle-exact trace of up to 32 program variables, sampled by
** the scan at the end of a cycle, every n-th cycle, into preallocated
** buffers, with a trigger (manual, the edge of a BOOL, a level crossed in a
** direction) and a pre-trigger count; single or repeated.
**
** The idea: two capture buffers change hands through one atomic each. The
** scan fills the buffer it owns (a ring while it waits for the trigger) and,
** once the capture is complete, hands it to the server (release store);
** the server reads only completed captures and gives a buffer back when the
** client is done with it. Requests go the other way as atomic flags (arm,
** stop, manual trigger); the setup is copied by the scan when it takes the
** arm request, and the server does not touch it while a trace runs. On the
** scan's path: a copy of each channel's value, a comparison, no lock, no
** allocation, no wait.
**
** Threads: trace_cycle belongs to the scan; trace_arm, trace_stop,
** trace_trigger, trace_take, trace_next, trace_running to one server thread.
*/
#ifndef TRACE_H
#define TRACE_H

#include <stdatomic.h>
#include <stdint.h>
#include "program.h"

#define TRACE_CHANNELS 32
#define TRACE_MIN_SAMPLES 16

enum trace_trig { TRIG_MANUAL, TRIG_RISE, TRIG_FALL, TRIG_UP, TRIG_DOWN, TRIG_KINDS };
/* The scan's state, as published (status register 60002). */
enum trace_state { TRACE_IDLE, TRACE_ARMED, TRACE_TRIGGERED, TRACE_WAIT_BUFFER };

/* Type codes of elementary variables (0: not traceable). */
enum {
    TT_NONE, TT_BOOL, TT_SINT, TT_USINT, TT_BYTE, TT_INT, TT_UINT, TT_WORD,
    TT_DINT, TT_UDINT, TT_DWORD, TT_LINT, TT_ULINT, TT_LWORD, TT_REAL, TT_LREAL
};
/* The type code of a variable of the program (TT_NONE for TIME, STRING,
** structures and function-block instances). */
int trace_type(const plc_var *v);
/* A raw value (the variable's bytes, zero-extended) as a number. */
double trace_number(uint64_t raw, int type);

typedef struct trace_chan {
    const void *addr;
    uint32_t var;                  /* index in the program's variable table */
    uint8_t size, type;
} trace_chan;

typedef struct trace_setup {
    trace_chan ch[TRACE_CHANNELS];
    int nchan;
    uint32_t decim;                /* a sample every decim-th cycle */
    uint32_t samples, pre;         /* per capture; pre < samples */
    int trig;                      /* enum trace_trig */
    trace_chan tv;                 /* the trigger variable (not manual) */
    double level;                  /* TRIG_UP, TRIG_DOWN */
    int repeat;                    /* re-arm after each capture */
} trace_setup;

typedef struct trace_buf {
    uint64_t *val;                 /* samples x nchan values, sample-major */
    uint32_t *cycle, *tick;        /* per sample: cycle number, PLC tick */
    trace_setup setup;             /* what it holds */
    uint32_t first;                /* ring index of the capture's first sample */
    uint32_t seq;                  /* 1, 2, ... in the order completed */
    _Atomic int owner;             /* 0 free, 1 the scan's, 2 completed */
} trace_buf;

typedef struct trace {
    uint32_t cap;                  /* samples per channel and buffer */
    trace_buf buf[2];
    /* server -> scan */
    trace_setup req;               /* read by the scan when it takes arm */
    _Atomic int arm_req, stop_req, trig_req;
    /* the scan's */
    trace_setup run;
    int state;
    trace_buf *cur;
    uint32_t w, n, left, dc, first, seq;
    double prev;
    /* scan -> anyone */
    _Atomic int state_pub;
    _Atomic uint32_t done_seq;
    /* the server's */
    trace_buf *held;               /* the capture being read */
} trace;

/* Allocate and touch (so that the scan never faults a page in) two buffers
** of cap samples x 32 channels. NULL when out of memory. */
trace *trace_new(uint32_t cap);
void trace_free(trace *t);

/* Scan: end of a cycle (cycle: cycles run before this one; tick: PLC ticks). */
void trace_cycle(trace *t, uint32_t cycle, uint32_t tick);

/* Server. A trace runs from trace_arm to its last capture or trace_stop. */
int trace_running(trace *t);
/* Arm with setup (the caller checked it); a capture held is given back. */
void trace_arm(trace *t, const trace_setup *setup);
void trace_stop(trace *t);
void trace_trigger(trace *t);
/* The completed capture held for reading (the oldest one completed), or NULL. */
trace_buf *trace_take(trace *t);
/* Give the capture held back (repeat: the next one becomes readable). */
void trace_next(trace *t);
/* Value of channel c at sample i (0 = first) of a completed capture. */
uint64_t trace_value(const trace_buf *b, int c, uint32_t i);
uint32_t trace_index(const trace_buf *b, uint32_t i);

#endif
