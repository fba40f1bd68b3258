/* plc_image.c: the process image and located addresses. */
#include <ctype.h>
#include <stdlib.h>
#include "plc_image.h"

plc_image plc_img;

static unsigned area_count(char size)
{
    switch (size) {
    case 'X': return PLC_IMG_X;
    case 'B': return PLC_IMG_B;
    case 'W': return PLC_IMG_W;
    case 'D': return PLC_IMG_D;
    case 'L': return PLC_IMG_L;
    }
    return 0;
}

static int number(const char **s, unsigned *out)
{
    char *end;
    if (!isdigit((unsigned char)**s)) return -1;
    unsigned long v = strtoul(*s, &end, 10);
    if (v > 1000000) return -1;
    *out = (unsigned)v;
    *s = end;
    return 0;
}

int plc_loc_parse(const char *s, plc_loc *l)
{
    if (*s++ != '%') return -1;
    l->area = (char)toupper((unsigned char)*s++);
    if (l->area != 'I' && l->area != 'Q' && l->area != 'M') return -1;
    l->size = (char)toupper((unsigned char)*s);
    if (isdigit((unsigned char)l->size)) l->size = 'X';   /* %I0.1 */
    else s++;
    if (!area_count(l->size) || number(&s, &l->index)) return -1;
    l->bit = 0;
    if (l->size == 'X') {
        if (*s++ != '.' || number(&s, &l->bit) || l->bit > 7) return -1;
    }
    if (*s) return -1;
    return l->index < area_count(l->size) ? 0 : -1;
}

uint8_t *plc_loc_ptr(plc_image *img, const plc_loc *l)
{
    int a = l->area == 'I' ? 0 : l->area == 'Q' ? 1 : 2;
    switch (l->size) {
    case 'X': return (a == 0 ? img->ix : a == 1 ? img->qx : img->mx) + l->index * 8 + l->bit;
    case 'B': return (a == 0 ? img->ib : a == 1 ? img->qb : img->mb) + l->index;
    case 'W': return (a == 0 ? img->iw : a == 1 ? img->qw : img->mw) + l->index * 2;
    case 'D': return (a == 0 ? img->id : a == 1 ? img->qd : img->md) + l->index * 4;
    default:  return (a == 0 ? img->il : a == 1 ? img->ql : img->ml) + l->index * 8;
    }
}

unsigned plc_loc_width(const plc_loc *l)
{
    switch (l->size) {
    case 'W': return 2;
    case 'D': return 4;
    case 'L': return 8;
    }
    return 1;
}
