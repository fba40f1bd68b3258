/*
** bind_located.h: included before LOCATED_VARIABLES.h in the generated
** program file. Each __LOCATED_VAR(TYPE, NAME, AREA, SIZE, ADDR...) line
** becomes `TYPE *NAME` pointing into the process image. An address outside
** the image, a wrong number of address parts or a type whose width does not
** match the size letter stops the build with the variable's name.
*/
#ifndef BIND_LOCATED_H
#define BIND_LOCATED_H

#include "plc_image.h"

#define PLC_AREA_IX plc_img.ix
#define PLC_AREA_QX plc_img.qx
#define PLC_AREA_MX plc_img.mx
#define PLC_AREA_IB plc_img.ib
#define PLC_AREA_QB plc_img.qb
#define PLC_AREA_MB plc_img.mb
#define PLC_AREA_IW plc_img.iw
#define PLC_AREA_QW plc_img.qw
#define PLC_AREA_MW plc_img.mw
#define PLC_AREA_ID plc_img.id
#define PLC_AREA_QD plc_img.qd
#define PLC_AREA_MD plc_img.md
#define PLC_AREA_IL plc_img.il
#define PLC_AREA_QL plc_img.ql
#define PLC_AREA_ML plc_img.ml

/* a, b, c: the address parts padded with -1; c must stay -1. */
#define PLC_OK_X(a, b, c, ...) ((a) >= 0 && (a) < PLC_IMG_X && (b) >= 0 && (b) < 8 && (c) == -1)
#define PLC_OK_B(a, b, ...) ((a) >= 0 && (a) < PLC_IMG_B && (b) == -1)
#define PLC_OK_W(a, b, ...) ((a) >= 0 && (a) < PLC_IMG_W && (b) == -1)
#define PLC_OK_D(a, b, ...) ((a) >= 0 && (a) < PLC_IMG_D && (b) == -1)
#define PLC_OK_L(a, b, ...) ((a) >= 0 && (a) < PLC_IMG_L && (b) == -1)
#define PLC_OFF_X(a, b, ...) ((a) * 8 + (b))
#define PLC_OFF_B(a, ...) (a)
#define PLC_OFF_W(a, ...) ((a) * 2)
#define PLC_OFF_D(a, ...) ((a) * 4)
#define PLC_OFF_L(a, ...) ((a) * 8)
#define PLC_WIDTH_X 1
#define PLC_WIDTH_B 1
#define PLC_WIDTH_W 2
#define PLC_WIDTH_D 4
#define PLC_WIDTH_L 8

#define PLC_FIRST(a, ...) a
#define PLC_OK(s, ...) PLC_OK_##s(__VA_ARGS__)
#define PLC_OFF(s, ...) PLC_OFF_##s(__VA_ARGS__)

#define __LOCATED_VAR(type, name, area, size, ...)                          \
    _Static_assert(PLC_OK(size, __VA_ARGS__, -1, -1),                        \
        "located variable " #name " lies outside the process image");       \
    _Static_assert(sizeof(type) == PLC_WIDTH_##size,                         \
        "located variable " #name ": type " #type " does not fit size " #size); \
    type *name = (type *)(PLC_AREA_##area##size + PLC_OFF(size, __VA_ARGS__, -1, -1));

#endif
