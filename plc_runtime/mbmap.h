/*
** mbmap.h: the Modbus address map (docs/modbus.md) and the exchange
** between the Modbus threads and the scan.
**
** Clients see a shadow of the image. A read copies from the shadow; a
** write is checked whole (every address mapped and writable, values and
** counts valid) before any of it lands, then goes to the shadow at once
** (so a client reads back what it wrote) and into a log of pending
** writes. At the start of each cycle the scan applies the log to the image
** and to the program's variables (mb_apply); after the program ran it
** copies the image into the shadow and replays writes logged meanwhile
** (mb_publish). Both hold the lock for a copy only; a request holds it
** while it is served, never across I/O.
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
#define MB_LOG_MAX     16384   /* pending writes: more than the writable cells */
#define MB_PDU_MAX     253

/* Diagnostics: input register offsets from MB_DIAG_BASE; 32-bit values,
** two registers, high word first. Times in microseconds. */
enum {
    MBD_CYCLES = 0, MBD_OVERRUNS = 2, MBD_MISSED = 4,
    MBD_EXEC_MIN = 6, MBD_EXEC_MEAN = 8, MBD_EXEC_MAX = 10, MBD_EXEC_P99 = 12,
    MBD_LAT_MIN = 14, MBD_LAT_MEAN = 16, MBD_LAT_MAX = 18, MBD_LAT_P99 = 20,
    MBD_TICK_US = 22, MBD_CLIENTS = 24, MBD_REFUSED = 26, MBD_REQUESTS = 28,
    MBD_EXCEPTIONS = 30, MBD_RETAIN_SAVES = 32, MBD_RETAIN_ERRORS = 34,
    MBD_IO_ERRORS = 36, MBD_UPTIME_S = 38, MBD_OVERRUNS_EXEC = 40,
    MBD_BACKEND = 64               /* 64 registers of the I/O backend */
};

typedef struct mb_item {           /* a program variable from the symbol map */
    const char *path;
    int table, writable;
    unsigned addr, nregs, size;
    int is_bool;
    void *var;                     /* the value in the program */
    uint8_t shadow[8];
} mb_item;

typedef struct mb_rec {
    uint32_t target;               /* offset in plc_image, or MB_REC_ITEM|i */
    uint8_t len;
    uint8_t data[8];
} mb_rec;
#define MB_REC_ITEM 0x80000000u

typedef struct mb_shared {
    pthread_mutex_t lock;
    plc_image shadow;
    uint16_t diag[MB_DIAG_N];
    mb_item *items;
    size_t nitems;
    /* pending writes, one record per element written since the last
    ** cycle (a later write to the same element replaces the value) */
    mb_rec log[MB_LOG_MAX];
    size_t nlog;
    uint32_t img_idx[sizeof(plc_image)];   /* image offset -> record + 1 */
    uint32_t *item_idx;                    /* item -> record + 1 */
    _Atomic uint64_t requests, exceptions, clients, refused;
} mb_shared;

/* Allocate; items from the config's symbol map resolved against the
** program's variables (call after the program's init). NULL with a
** message ("FILE:LINE: ...") in err. */
mb_shared *mb_new(const plc_config *c, const plc_program *p, char *err, size_t errlen);
void mb_free(mb_shared *m);

/* Serve one request PDU (function code first); writes the reply PDU into
** rsp (MB_PDU_MAX bytes) and returns its length. */
size_t mb_process(mb_shared *m, const uint8_t *pdu, size_t n, uint8_t *rsp);

void mb_apply(mb_shared *m, plc_image *img);
void mb_publish(mb_shared *m, const plc_image *img, const uint16_t *diag);

#endif
