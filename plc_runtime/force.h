/*
** force.h: forcing program variables from a running plcrt (commissioning,
** tuning). A forced input (%I) is overwritten after the inputs are read, a
** forced output (%Q) before the outputs are written, any other variable
** before and after the program. Forcing exists only when the configuration
** allows it ([debug] allow_force), lives in memory only (a restart starts
** with nothing forced) and is cleared whole by one command.
**
** The idea: the server thread edits its own list and publishes it into one
** of two tables with an atomic index; the scan takes the published index at
** the start of each cycle and says so (ack). The server writes a table only
** once the scan moved to the other one, so the scan never sees a table
** being written, never waits and never locks. A change waits (pending) at
** most a cycle or two for the scan to move.
**
** Threads: force_begin and force_apply belong to the scan; force_set,
** force_clear, force_flush to the server thread; force_count and
** force_is_forced to anyone.
*/
#ifndef FORCE_H
#define FORCE_H

#include <stdatomic.h>
#include <stdint.h>
#include "program.h"

#define FORCE_MAX 64

enum { FORCE_INTERNAL, FORCE_INPUT, FORCE_OUTPUT };
/* force_apply's moments */
enum { FORCE_AFTER_INPUTS, FORCE_AFTER_PROGRAM };

typedef struct force_entry {
    void *addr;
    uint32_t var;                  /* index in the program's variable table */
    uint8_t size, area;
    uint64_t raw;                  /* the value's bytes, zero-extended */
} force_entry;

typedef struct force_table {
    force_entry e[FORCE_MAX];
    int n;
} force_table;

typedef struct forcing {
    int allowed;
    const plc_program *prog;
    force_table tab[2];
    _Atomic int pub, ack;
    int cur;                       /* the scan's table this cycle */
    force_table list;              /* the server's */
    int pending;                   /* list not published yet */
    _Atomic int count;
    _Atomic unsigned char *flag;   /* per variable: forced */
} forcing;

forcing *force_new(const plc_program *p, int allowed);
void force_free(forcing *f);

/* Where a variable lives: FORCE_INPUT (%I), FORCE_OUTPUT (%Q), else internal. */
int force_area(const plc_var *v);

/* Scan: take the published table (start of a cycle); apply it. */
void force_begin(forcing *f);
void force_apply(forcing *f, int moment);

/* Server: force variable var to raw (its bytes), release one, release all.
** 0, or -1 (no such variable, not elementary, the table full). */
int force_set(forcing *f, uint32_t var, uint64_t raw);
void force_clear(forcing *f, uint32_t var);
void force_clear_all(forcing *f);
/* Publish a change the scan could not take yet; 1 while one waits. */
int force_flush(forcing *f);

int force_count(const forcing *f);
int force_is_forced(const forcing *f, uint32_t var);

#endif
