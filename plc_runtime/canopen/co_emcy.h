/* EMCY consumer (COB-ID 0x080 + node): error code, error register,
 * manufacturer-specific bytes. */
#ifndef CO_EMCY_H
#define CO_EMCY_H

#include <stddef.h>
#include "co_frame.h"

typedef struct co_emcy {
    uint8_t node;
    uint16_t code;          /* 0x0000 = error reset / no error */
    uint8_t reg;            /* error register (object 0x1001) */
    uint8_t msef[5];        /* manufacturer-specific error field */
} co_emcy;

/* 0 and *e filled if f is an EMCY (ids 0x081..0x0FF, 8 data bytes; shorter
 * frames are taken with missing bytes as 0), else -1 (SYNC, other ids). */
int co_emcy_decode(const co_frame *f, co_emcy *e);
/* The CiA 301 class of an error code, e.g. "voltage", "communication". */
const char *co_emcy_class(uint16_t code);
/* "generic current temperature..." for the bits set in an error register,
 * written to buf. */
const char *co_emcy_reg_text(uint8_t reg, char *buf, size_t len);

#endif
