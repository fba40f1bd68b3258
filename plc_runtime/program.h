/*
** program.h: what the runtime knows of the linked PLC program. The build
** generates plc_program_linked from the compiler's output (gen_program.sh):
** entry points, the PLC clock, and a table of every variable listed in
** VARIABLES.csv with its address.
*/
#ifndef PLC_PROGRAM_H
#define PLC_PROGRAM_H

#include <stddef.h>
#include <stdint.h>

/* IEC_TIME's layout under both compilers. */
typedef struct { long tv_sec, tv_nsec; } plc_timespec;

typedef struct plc_var {
    const char *path;     /* IEC path, e.g. CONFIG0.RES0.INST0.POS */
    const char *type;     /* IEC type name as in VARIABLES.csv */
    unsigned char retain; /* declared RETAIN */
    unsigned char indirect; /* addr holds a pointer to the value (located) */
    unsigned short size;  /* bytes of the value */
    void *addr;
} plc_var;

typedef struct plc_program {
    const char *name;             /* configuration name */
    void (*init)(void);           /* config_init__ */
    void (*run)(unsigned long);   /* config_run__ */
    const unsigned long long *ticktime;   /* common_ticktime__, ns */
    plc_timespec *now;            /* __CURRENT_TIME */
    const plc_var *vars;
    size_t nvars;
} plc_program;

extern const plc_program plc_program_linked;

/* Address of a variable's value (follows indirect ones; valid after init). */
static inline void *plc_var_addr(const plc_var *v)
{
    return v->indirect ? *(void **)v->addr : v->addr;
}

/* The variable with this IEC path (case-insensitive), or NULL. */
const plc_var *plc_var_find(const plc_program *p, const char *path);

#endif
