/*
 * What a test harness playing the PLC runtime needs, from the generated
 * code's contract only (docs/stc.md, "What the runtime provides"): the
 * elementary types' widths, storage for every located variable listed in
 * LOCATED_VARIABLES.h, the clock and debug flag the runtime defines, the
 * entry points, and a lookup of a located variable by its IEC name.
 *
 * Include it once, from the harness's only C file, with the compiler's
 * output folder on the include path. Works with stc's and matiec's output.
 */
#ifndef PLC_HARNESS_H
#define PLC_HARNESS_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Elementary types as the generated code declares them (same widths). */
typedef struct { long tv_sec; long tv_nsec; } ht_time;
typedef struct { uint8_t len; uint8_t body[126]; } ht_string;
#define HT_BOOL  uint8_t
#define HT_BYTE  uint8_t
#define HT_USINT uint8_t
#define HT_SINT  int8_t
#define HT_INT   int16_t
#define HT_UINT  uint16_t
#define HT_WORD  uint16_t
#define HT_DINT  int32_t
#define HT_UDINT uint32_t
#define HT_DWORD uint32_t
#define HT_LINT  int64_t
#define HT_ULINT uint64_t
#define HT_LWORD uint64_t
#define HT_REAL  float
#define HT_LREAL double
#define HT_TIME  ht_time
#define HT_DATE  ht_time
#define HT_TOD   ht_time
#define HT_DT    ht_time
#define HT_STRING ht_string

/* What the runtime provides to the generated code. */
ht_time __CURRENT_TIME;
uint8_t __DEBUG;
extern unsigned long long common_ticktime__;
void config_init__(void);
void config_run__(unsigned long tick);

/* Storage and pointer for every located variable. */
#define __LOCATED_VAR(type, name, ...) \
    static HT_##type name##_store; HT_##type *name = &name##_store;
#include "LOCATED_VARIABLES.h"
#undef __LOCATED_VAR

struct locvar { const char *type, *area, *size, *addr; void *p; };
static const struct locvar locvars[] = {
#define __LOCATED_VAR(type, name, area, size, ...) \
    { #type, #area, #size, #__VA_ARGS__, &name##_store },
#include "LOCATED_VARIABLES.h"
#undef __LOCATED_VAR
    { NULL, NULL, NULL, NULL, NULL }
};

/* The located variable "%QD3", "%IX0.1", ...: its storage, and its type's
   name in *type (if type is not NULL); NULL when the program has none. */
static inline void *located(const char *iec, const char **type)
{
    for (const struct locvar *l = locvars; l->type; l++) {
        char name[64];
        size_t n = (size_t)snprintf(name, sizeof name, "%%%s%s", l->area, l->size);
        for (const char *a = l->addr; *a && n + 1 < sizeof name; a++)
            if (*a != ' ') name[n++] = *a == ',' ? '.' : *a;
        name[n] = 0;
        if (!strcmp(name, iec)) {
            if (type) *type = l->type;
            return l->p;
        }
    }
    return NULL;
}

/* Advance the PLC clock by one task tick. */
static inline void tick_clock(void)
{
    unsigned long long ns = (unsigned long long)__CURRENT_TIME.tv_nsec + common_ticktime__;
    __CURRENT_TIME.tv_sec += (long)(ns / 1000000000ULL);
    __CURRENT_TIME.tv_nsec = (long)(ns % 1000000000ULL);
}

/* A figures program's whole main: run `prog ticks` ticks of the program,
   then print %QD0..%QD(n-1) on one line as "label value" pairs. Status 2
   with a usage line when ticks is missing or the program lacks one. */
static inline int run_print_qd(int argc, char **argv, const char *const *label, int n)
{
    long ticks = argc == 2 ? atol(argv[1]) : 0;
    int32_t *q[64];
    for (int i = 0; i < n && i < 64; i++) {
        char name[8];
        snprintf(name, sizeof name, "%%QD%d", i);
        q[i] = located(name, NULL);
        if (!q[i])
            ticks = 0;
    }
    if (ticks < 1 || n > 64) {
        fprintf(stderr, "usage: %s ticks (program with %%QD0..%%QD%d)\n", argv[0], n - 1);
        return 2;
    }
    config_init__();
    for (long i = 0; i < ticks; i++) {
        config_run__((unsigned long)i);
        tick_clock();
    }
    for (int i = 0; i < n; i++)
        printf("%s%s %ld", i ? " " : "", label[i], (long)*q[i]);
    printf("\n");
    return 0;
}

#endif
