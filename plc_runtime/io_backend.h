/*
** io_backend.h: the interface between the scan and an I/O backend.
**
** A backend moves data between the process image and the outside world
** (a simulated plant, CANopen nodes, Modbus remote I/O, ...). The
** configuration file selects one or several with `[io] backend = NAME, ...`;
** several run side by side as one (io_multi below), each with its own
** sections, diagnostics and image locations. Life of a backend, all calls
** from the runtime's threads as noted:
**
**   create()            main thread, before the config file is read
**   config() per key    main thread, for every key of a section named
**                       NAME or NAME.anything (e.g. [canopen.node3])
**   open()              main thread, after the whole file was read and
**                       before the first cycle: validate, open devices
**   inputs()            main thread, after open(): the image locations the
**                       backend writes, so that two backends writing one
**                       input are refused at the start
**   read_inputs()       scan thread, at the start of each cycle
**   write_outputs()     scan thread, at the end of each cycle
**   safe_state()        main thread, once, after the scan has stopped, with
**                       the image's %Q areas already zeroed: bring every
**                       physical output to its safe state (0 V, off)
**   close()             main thread, last; frees the state
**
** Rules: read_inputs/write_outputs run in the real-time scan, so they never
** block, allocate or log at length (use the rate-limited plc_log). They
** only touch the image passed in. Errors found while running are reported
** through diag() (and may make read_inputs return -1 once per occurrence,
** which the runtime counts and logs); they never stop the scan. A backend
** whose devices are slow (a network, a serial line) talks to them in
** threads of its own and trades whole buffers with read_inputs and
** write_outputs through atomic swaps (io_modbus.c does so).
**
** To add a backend: implement an io_backend_ops, and list it in
** io_backends.c.
*/
#ifndef IO_BACKEND_H
#define IO_BACKEND_H

#include <stddef.h>
#include <stdint.h>
#include "plc_image.h"

/* One input a backend writes into the image, for io_inputs_apart: where,
** how many bytes, and its name for a message ("[sim.axis0] counter"). */
typedef struct io_input_use {
    const uint8_t *p;
    unsigned w;
    char who[96];
} io_input_use;

typedef struct io_backend_ops {
    const char *name;
    /* Allocate and default the backend's state; NULL on out of memory. */
    void *(*create)(void);
    /* One key of one of the backend's sections. Return 0 if accepted;
    ** otherwise -1 with a message in err (the runtime adds file, line,
    ** section and key). */
    int (*config)(void *st, const char *section, const char *key,
                  const char *value, char *err, size_t errlen);
    /* Check the configuration as a whole and acquire the devices.
    ** ticktime_ns is the scan period. 0, or -1 with a message in err. */
    int (*open)(void *st, plc_image *img, uint64_t ticktime_ns,
                char *err, size_t errlen);
    /* Fill the %I areas. now_ns: PLC time of this cycle (monotonic, starts
    ** at 0, advances by whole periods). 0, or -1 on an I/O error. */
    int (*read_inputs)(void *st, plc_image *img, uint64_t now_ns);
    /* Send the %Q areas out. 0, or -1 on an I/O error. */
    int (*write_outputs)(void *st, const plc_image *img);
    /* Outputs to their safe state (see above). */
    void (*safe_state)(void *st, plc_image *img);
    void (*close)(void *st);
    /* Copy up to max (IO_DIAG_BLOCK) diagnostic registers (16-bit) into
    ** regs; return how many. Called from the scan thread once per cycle.
    ** The first listed backend's first 64 are also served at input
    ** registers 1088-1151 (docs/modbus.md). May be NULL. */
    size_t (*diag)(void *st, uint16_t *regs, size_t max);
    /* After open(): up to max inputs the backend writes (io_input_use
    ** above) into out; return how many. May be NULL (writes no input). */
    int (*inputs)(void *st, plc_image *img, io_input_use *out, int max);
} io_backend_ops;

/* For a backend's open(): 0 when no two of the n inputs share a byte of
** the image, else -1 with "A and B write the same input: give each its own
** address" in err (two bindings copied and not edited would leave the
** program one of them only, without a word). */
int io_inputs_apart(const io_input_use *in, int n, char *err, size_t errlen);

/* Several backends as one (io_multi.c): the runtime always runs this one,
** over the backends `[io] backend` lists. config() hands a key to the
** backend owning its section; open() opens them in the list's order (on a
** failure the ones opened are put in their safe state), then refuses two
** of them writing one input; read_inputs/write_outputs/safe_state call each
** in turn; diag() gives backend k the IO_DIAG_BLOCK registers from
** k * IO_DIAG_BLOCK (docs/modbus.md). */
#define IO_MULTI_MAX 4
#define IO_DIAG_BLOCK 1000
extern const io_backend_ops io_multi;
/* An empty set, or NULL on out of memory. */
void *io_multi_new(void);
/* Add a backend (created here); its state, or NULL on out of memory. */
void *io_multi_add(void *set, const io_backend_ops *o);
/* The state of backend o in the set, or NULL when it is not listed. */
void *io_multi_state(void *set, const io_backend_ops *o);
int io_multi_count(void *set);

/* The backend named name, or NULL. */
const io_backend_ops *io_backend_find(const char *name);
/* NULL-terminated list of all backends (for section ownership and help). */
extern const io_backend_ops *const io_backends[];

#endif
