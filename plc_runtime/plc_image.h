/*
** plc_image.h: the process image, the only state the PLC program, the I/O
** backend and the Modbus server share.
**
** One area per IEC prefix and size. Bit areas (%IX/%QX/%MX) keep one byte
** per bit, as matiec binds a BOOL located variable to a BOOL (a byte), so
** %QX3.5 is qx[3*8+5]. Byte, word, double and long areas are separate (no
** overlay: %IB0 is not %IX0.0-7), as in OpenPLC. Wider areas are raw bytes
** in host order; use the accessors below, never pointer casts.
*/
#ifndef PLC_IMAGE_H
#define PLC_IMAGE_H

#include <stdint.h>
#include <string.h>

#define PLC_IMG_X   1024        /* bytes of %IX/%QX/%MX (8 bits each) */
#define PLC_IMG_B   1024        /* %IB/%QB/%MB */
#define PLC_IMG_W   1024        /* %IW/%QW/%MW */
#define PLC_IMG_D   1024        /* %ID/%QD/%MD */
#define PLC_IMG_L   1024        /* %IL/%QL/%ML */

typedef struct plc_image {
    uint8_t ix[PLC_IMG_X * 8], qx[PLC_IMG_X * 8], mx[PLC_IMG_X * 8];
    uint8_t ib[PLC_IMG_B], qb[PLC_IMG_B], mb[PLC_IMG_B];
    _Alignas(8) uint8_t iw[PLC_IMG_W * 2], qw[PLC_IMG_W * 2], mw[PLC_IMG_W * 2];
    _Alignas(8) uint8_t id[PLC_IMG_D * 4], qd[PLC_IMG_D * 4], md[PLC_IMG_D * 4];
    _Alignas(8) uint8_t il[PLC_IMG_L * 8], ql[PLC_IMG_L * 8], ml[PLC_IMG_L * 8];
} plc_image;

/* The one process image of this process (plc_image.c). */
extern plc_image plc_img;

static inline int16_t img_get16(const uint8_t *a, unsigned i)
{ int16_t v; memcpy(&v, a + 2 * i, 2); return v; }
static inline void img_set16(uint8_t *a, unsigned i, int16_t v)
{ memcpy(a + 2 * i, &v, 2); }
static inline int32_t img_get32(const uint8_t *a, unsigned i)
{ int32_t v; memcpy(&v, a + 4 * i, 4); return v; }
static inline void img_set32(uint8_t *a, unsigned i, int32_t v)
{ memcpy(a + 4 * i, &v, 4); }
static inline int64_t img_get64(const uint8_t *a, unsigned i)
{ int64_t v; memcpy(&v, a + 8 * i, 8); return v; }
static inline void img_set64(uint8_t *a, unsigned i, int64_t v)
{ memcpy(a + 8 * i, &v, 8); }

/* The value of 1, 2, 4 or 8 bytes at p (any alignment), zero-extended. */
static inline uint64_t plc_load(const void *p, unsigned size)
{
    uint8_t b; uint16_t h; uint32_t w; uint64_t l;
    switch (size) {
    case 1: memcpy(&b, p, 1); return b;
    case 2: memcpy(&h, p, 2); return h;
    case 4: memcpy(&w, p, 4); return w;
    default: memcpy(&l, p, 8); return l;
    }
}

/* A located address parsed from text such as "%QW3" or "%IX0.1". */
typedef struct plc_loc {
    char area;      /* 'I', 'Q', 'M' */
    char size;      /* 'X', 'B', 'W', 'D', 'L' */
    unsigned index; /* byte for X, element otherwise */
    unsigned bit;   /* X only */
} plc_loc;

/* Parse "%QW3" / "%IX1.7" (case-insensitive); 0 on success, -1 when the
** text is malformed or the address lies outside the image. */
int plc_loc_parse(const char *s, plc_loc *out);

/* Address of a location's storage in img and its width in bytes. */
uint8_t *plc_loc_ptr(plc_image *img, const plc_loc *l);
unsigned plc_loc_width(const plc_loc *l);

#endif
