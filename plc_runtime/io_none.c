/* io_none.c: no I/O at all; the image's inputs stay as the program and
** Modbus leave them. */
#include <stdlib.h>
#include "io_backend.h"

static void *create(void) { return malloc(1); }
static int config(void *st, const char *s, const char *k, const char *v, char *e, size_t n)
{ (void)st; (void)s; (void)k; (void)v; (void)e; (void)n; return -1; }
static int open_(void *st, plc_image *img, uint64_t tick, char *e, size_t n)
{ (void)st; (void)img; (void)tick; (void)e; (void)n; return 0; }
static int rd(void *st, plc_image *img, uint64_t now) { (void)st; (void)img; (void)now; return 0; }
static int wr(void *st, const plc_image *img) { (void)st; (void)img; return 0; }
static void safe(void *st, plc_image *img) { (void)st; (void)img; }
static void close_(void *st) { free(st); }

const io_backend_ops io_none = {
    "none", create, config, open_, rd, wr, safe, close_, NULL, NULL
};
