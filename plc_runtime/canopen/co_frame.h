/* CANopen core: the frame record every protocol module takes and produces.
 * No socket in here: the protocol code is stepped by frames and a time. */
#ifndef CO_FRAME_H
#define CO_FRAME_H

#include <stdint.h>

typedef uint64_t co_time;           /* monotonic time, ns */
#define CO_MS ((co_time)1000000)

#define CO_ERR_FLAG 0x20000000u     /* id flag of a controller error frame */

typedef struct co_frame {
    uint32_t id;                    /* 11-bit COB-ID, or CO_ERR_FLAG|class */
    uint8_t len;                    /* 0..8 */
    uint8_t rtr;
    uint8_t data[8];
} co_frame;

/* function codes (COB-ID base) of the predefined connection set */
enum {
    CO_FC_NMT = 0x000, CO_FC_SYNC = 0x080, CO_FC_EMCY = 0x080,
    CO_FC_TPDO1 = 0x180, CO_FC_RPDO1 = 0x200,
    CO_FC_SDO_TX = 0x580, CO_FC_SDO_RX = 0x600, CO_FC_HB = 0x700
};

static inline uint16_t co_get16(const uint8_t *p) { return (uint16_t)(p[0] | p[1] << 8); }
static inline uint32_t co_get32(const uint8_t *p)
{ return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24; }
static inline void co_put16(uint8_t *p, uint16_t v) { p[0] = (uint8_t)v; p[1] = (uint8_t)(v >> 8); }
static inline void co_put32(uint8_t *p, uint32_t v)
{ p[0] = (uint8_t)v; p[1] = (uint8_t)(v >> 8); p[2] = (uint8_t)(v >> 16); p[3] = (uint8_t)(v >> 24); }

#endif
