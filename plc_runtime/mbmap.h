/*
** mbmap.h: the Modbus address map (docs/modbus.md) and the exchange
** between the Modbus server thread and the scan.
**
** The idea: the scan never waits for Modbus. It shares nothing with the
** server that either side could hold; they trade whole buffers through
** atomic index swaps.
**
** - Image out (scan -> server): a triple buffer of snapshots. At the end of
**   each cycle the scan copies the image into its back snapshot and swaps
**   it into the middle slot (mb_publish); the server takes the newest one
**   when it serves a request. Neither ever waits for the other.
** - Writes in (server -> scan): a batch handed over whole. A write request
**   is checked whole (every address mapped and writable, values and counts
**   valid) before any of it lands, then goes into the server's view at once
**   (a client reads back what it wrote) and into the batch being filled,
**   one record per element (a later write replaces the value, so no amount
**   of writing fills it). The server hands a batch to the scan when the
**   scan took the previous one in; at the start of a cycle the scan lands
**   the batch handed to it, whole (mb_apply).
**
** Threads: mb_process and mb_flush belong to the server threads (TCP, and
** RTU on a serial line), one at a time: each holds `serve` around them
** (the scan never takes it); mb_apply and mb_publish to the scan; mb_drain
** to the main thread once all stopped. The counters are read by anyone.
*/
#ifndef MBMAP_H
#define MBMAP_H

#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>
#include "config.h"
#include "plc_image.h"
#include "program.h"

#define MB_BITS        8192    /* coils, discrete inputs: %QX/%IX0.0-1023.7 */
#define MB_HOLDING_N   8192    /* %QW, %MW, %MD, %ML */
#define MB_INPUT_IMG   1024    /* %IW */
#define MB_DIAG_BASE   1024    /* input registers of diagnostics */
#define MB_DIAG_N      128
#define MB_IODIAG_BASE 20000   /* input registers of the I/O backends' diagnostics */
#define MB_IODIAG_N    (IO_MULTI_MAX * IO_DIAG_BLOCK)   /* IO_DIAG_BLOCK per backend */
#define MB_DIAG_ALL    (MB_DIAG_N + MB_IODIAG_N)        /* the diag array: both */
#define MB_LOG_MAX     16384   /* pending writes: more than the writable cells */
#define MB_PDU_MAX     253
#define MB_TRACE_BASE  60000   /* holding registers of the trace block (tracemb.h) */
#define MB_TRACE_END   60429

/* Diagnostics: input register offsets from MB_DIAG_BASE; 32-bit values,
** two registers, high word first. Times in microseconds. */
enum {
    MBD_CYCLES = 0, MBD_OVERRUNS = 2, MBD_MISSED = 4,
    MBD_EXEC_MIN = 6, MBD_EXEC_MEAN = 8, MBD_EXEC_MAX = 10, MBD_EXEC_P99 = 12,
    MBD_LAT_MIN = 14, MBD_LAT_MEAN = 16, MBD_LAT_MAX = 18, MBD_LAT_P99 = 20,
    MBD_TICK_US = 22, MBD_CLIENTS = 24, MBD_REFUSED = 26, MBD_REQUESTS = 28,
    MBD_EXCEPTIONS = 30, MBD_RETAIN_SAVES = 32, MBD_RETAIN_ERRORS = 34,
    MBD_IO_ERRORS = 36, MBD_UPTIME_S = 38, MBD_OVERRUNS_EXEC = 40,
    MBD_EVICTED = 42, MBD_DROPPED = 44, MBD_EXCHANGE_MAX = 46, MBD_FORCED = 48,
    MBD_RTU_SERVED = 50, MBD_RTU_BAD = 52,
    MBD_BACKEND = 64               /* the first backend's first 64 registers */
};

typedef struct mb_item {           /* a program variable from the symbol map */
    const char *path;
    int table, writable;
    unsigned addr, nregs, size;
    int is_bool;
    int is_float;                  /* REAL or LREAL: nan and infinities refused */
    void *var;                     /* the value in the program */
} mb_item;

typedef struct mb_rec {
    uint32_t target;               /* offset in plc_image, or MB_REC_ITEM|i */
    uint8_t len;
    uint8_t data[8];
} mb_rec;
#define MB_REC_ITEM 0x80000000u

typedef struct mb_batch {          /* writes handed to the scan in one piece */
    mb_rec rec[MB_LOG_MAX];
    size_t n;
    uint64_t seq;                  /* 1, 2, ... in the order handed over */
} mb_batch;

typedef struct mb_snap {           /* what clients read: one cycle's image */
    plc_image img;
    uint16_t diag[MB_DIAG_ALL];
    uint64_t applied;              /* the last batch landed before it */
    uint8_t (*items)[8];           /* symbol values */
} mb_snap;

/* Registers served by another module in the server thread (the trace
** block, tracemb.h): requests that touch them are handed to serve whole. */
typedef struct mb_block {
    int (*touches)(const uint8_t *pdu, size_t n);
    size_t (*serve)(void *arg, const uint8_t *pdu, size_t n, uint8_t *rsp, int *exc);
    int (*flush)(void *arg);       /* 1 while it has work pending */
    void *arg;
} mb_block;

#define MB_FRESH 4u                /* in mid: the middle snapshot is newer */

typedef struct mb_shared {
    pthread_mutex_t serve;         /* between the server threads only */
    mb_item *items;
    size_t nitems;
    mb_block block;                /* touches NULL: none */
    /* image out: the scan owns snap[back], the server snap[front] (its
    ** view, into which it also writes), mid holds the third */
    mb_snap snap[3];
    _Atomic unsigned mid;
    unsigned back, front;
    /* writes in: the server fills *fill; *given is the batch handed over
    ** last, ready while the scan has not landed it */
    mb_batch batch[2];
    mb_batch *fill, *given;
    _Atomic int ready;
    uint64_t landed;               /* scan's: seq of the last batch landed */
    uint32_t img_idx[sizeof(plc_image)];   /* server's: image offset -> record + 1 in *fill */
    uint32_t *item_idx;                    /* item -> record + 1 */
    _Atomic uint64_t requests, exceptions, clients, refused, evicted, dropped;
    _Atomic uint64_t rtu_served, rtu_bad;  /* the RTU server's (mbrtu.h) */
    _Atomic uint64_t exchange_max_ns;      /* scan's longest mb_apply + mb_publish */
} mb_shared;

/* Allocate; items from the config's symbol map resolved against the
** program's variables (call after the program's init). NULL with a
** message ("FILE:LINE: ...") in err. */
mb_shared *mb_new(const plc_config *c, const plc_program *p, char *err, size_t errlen);
void mb_free(mb_shared *m);

/* Serve one request PDU (function code first); writes the reply PDU into
** rsp (MB_PDU_MAX bytes) and returns its length. Server thread. */
size_t mb_process(mb_shared *m, const uint8_t *pdu, size_t n, uint8_t *rsp);
/* A request PDU's shape (function code first): 1 when its length, counts
** and byte count fit the function, 0 when not (exception 03), -1 for a
** function this map does not serve (exception 01). */
int mb_pdu_shape(const uint8_t *pdu, size_t n);
/* Take the newest snapshot and hand the pending writes to the scan if it
** took the last batch in. Server thread; 1 while writes remain pending (call
** again within a period), else 0. mb_process calls it too. */
int mb_flush(mb_shared *m);

/* Scan thread: land the batch handed over (start of a cycle); publish the
** image, the symbols and diag (end of a cycle; diag may be NULL). */
void mb_apply(mb_shared *m, plc_image *img);
void mb_publish(mb_shared *m, const plc_image *img, const uint16_t *diag);
/* Main thread, once the scan and the server stopped: land every write
** acknowledged to a client (the batch handed over and the one filling). */
void mb_drain(mb_shared *m, plc_image *img);

#endif
