/* SDO client (COB-IDs 0x600/0x580 + node): expedited and segmented upload
 * and download, aborts both ways, timeouts. A state machine stepped by the
 * server's frames and by the time; every frame to send comes out in *out. */
#ifndef CO_SDO_H
#define CO_SDO_H

#include <stddef.h>
#include "co_frame.h"

enum co_sdo_status { CO_SDO_IDLE, CO_SDO_BUSY, CO_SDO_DONE, CO_SDO_FAILED };

#define CO_SDO_ABORT_TOGGLE   0x05030000u
#define CO_SDO_ABORT_TIMEOUT  0x05040000u
#define CO_SDO_ABORT_CMD      0x05040001u
#define CO_SDO_ABORT_NOMEM    0x05040005u
#define CO_SDO_ABORT_LEN      0x06070010u
#define CO_SDO_ABORT_GENERAL  0x08000000u

typedef struct co_sdo {
    uint8_t node;
    uint8_t status;             /* enum co_sdo_status */
    uint8_t upload;             /* 1 = reading from the server */
    uint8_t toggle;
    uint8_t step;               /* internal: 0 initiate, 1 segments */
    uint8_t by_server;          /* on failure: 1 if the server aborted */
    uint16_t index;
    uint8_t sub;
    uint8_t *buf;               /* download: data; upload: destination */
    size_t cap;                 /* upload capacity / download length */
    size_t len;                 /* bytes transferred so far */
    size_t size;                /* upload: size announced by the server */
    uint32_t abort_code;        /* on failure */
    co_time timeout;            /* per exchange, ns */
    co_time deadline;
} co_sdo;

void co_sdo_init(co_sdo *s, uint8_t node, co_time timeout);
/* Start a transfer; the request is put in *out. data/buf must stay valid
 * until the transfer ends. Returns 0, -1 if a transfer is still running. */
int co_sdo_download(co_sdo *s, uint16_t index, uint8_t sub, const void *data,
                    size_t len, co_time now, co_frame *out);
int co_sdo_upload(co_sdo *s, uint16_t index, uint8_t sub, void *buf, size_t cap,
                  co_time now, co_frame *out);
/* Feed a frame received on 0x580+node. Returns 1 if *out holds a frame to
 * send (next request or an abort), else 0. Other ids are ignored. */
int co_sdo_rx(co_sdo *s, const co_frame *in, co_time now, co_frame *out);
/* Check the deadline: on timeout the transfer fails with 0x05040000 and an
 * abort for the server is put in *out (returns 1). */
int co_sdo_tick(co_sdo *s, co_time now, co_frame *out);

/* The CiA 301 text of an abort code ("unknown abort code" otherwise). */
const char *co_sdo_abort_text(uint32_t code);

#endif
