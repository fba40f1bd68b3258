/* PDOs: fields of 1 to 64 bits at any bit offset of a little-endian
 * payload (CiA 301 bit order: bit 0 = LSB of byte 0), PDO mappings, and the
 * SDO writes that install a mapping in a node. */
#ifndef CO_PDO_H
#define CO_PDO_H

#include <stddef.h>
#include "co_frame.h"

/* Read / write `len` bits (1..64) at bit offset `off` of buf. */
uint64_t co_bits_get(const uint8_t *buf, unsigned off, unsigned len);
void co_bits_put(uint8_t *buf, unsigned off, unsigned len, uint64_t v);
/* Sign-extend a len-bit value. */
int64_t co_bits_sext(uint64_t v, unsigned len);

#define CO_PDO_MAX_ENTRIES 8
#define CO_PDO_PER_NODE 4

typedef struct co_map_entry {
    uint16_t index;
    uint8_t sub;
    uint8_t bits;               /* 1..64 */
} co_map_entry;

typedef struct co_pdo_map {
    uint8_t n;                  /* entries in use; 0 = PDO disabled */
    uint8_t trans;              /* transmission type: 1..240 synchronous, 254/255 event */
    co_map_entry e[CO_PDO_MAX_ENTRIES];
} co_pdo_map;

/* Bit offset of entry i; total bits of the map. */
unsigned co_pdo_offset(const co_pdo_map *m, unsigned i);
unsigned co_pdo_bits(const co_pdo_map *m);
/* 0 if the map fits a CAN frame (1..64 bits per entry, <= 64 total),
 * else -1 with a message in err. */
int co_pdo_check(const co_pdo_map *m, char *err, size_t errlen);

/* One SDO write of up to 4 bytes. */
typedef struct co_sdo_write {
    uint16_t index;
    uint8_t sub;
    uint8_t size;               /* 1, 2 or 4 */
    uint32_t value;
} co_sdo_write;

/* The CiA 301 sequence installing map m as RPDO (tx=0) or TPDO (tx=1)
 * number num (0..3) of node `node` with its default COB-ID: invalidate the
 * COB-ID, set the transmission type, clear the mapping, write the entries,
 * set their count, validate the COB-ID (or leave it invalid when m->n is 0).
 * Returns the number of writes put in out (at most max), -1 if max is short. */
int co_pdo_config(int tx, unsigned num, uint8_t node, const co_pdo_map *m,
                  co_sdo_write *out, int max);
/* Default COB-ID of PDO num (0..3) of a node. */
uint32_t co_pdo_cobid(int tx, unsigned num, uint8_t node);

/* CiA 401 default mappings: TPDO1 8 digital input bytes (0x6000),
 * RPDO1 8 digital output bytes (0x6200), TPDO2 4 analog inputs (0x6401),
 * RPDO2 4 analog outputs (0x6411), all 16-bit; transmission type 1. */
void co_pdo_cia401_default(int tx, unsigned num, co_pdo_map *m);

#endif
