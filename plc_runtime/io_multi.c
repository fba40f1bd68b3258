/*
** io_multi.c: several I/O backends run as one (io_backend.h): the
** simulator beside remote I/O beside CANopen, each reading its own
** sections and writing its own image locations. The scan sees one
** backend; this one calls each listed backend in the list's order.
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "io_backend.h"

typedef struct io_set {
    int n;
    const io_backend_ops *ops[IO_MULTI_MAX];
    void *st[IO_MULTI_MAX];
    int opened;                 /* how many were opened */
} io_set;

void *io_multi_new(void) { return calloc(1, sizeof(io_set)); }

void *io_multi_add(void *vs, const io_backend_ops *o)
{
    io_set *s = vs;
    if (s->n >= IO_MULTI_MAX) return NULL;
    void *st = o->create();
    if (!st) return NULL;
    s->ops[s->n] = o;
    s->st[s->n++] = st;
    return st;
}

void *io_multi_state(void *vs, const io_backend_ops *o)
{
    io_set *s = vs;
    for (int i = 0; i < s->n; i++)
        if (s->ops[i] == o) return s->st[i];
    return NULL;
}

int io_multi_count(void *vs) { return ((io_set *)vs)->n; }

static void *create(void) { return io_multi_new(); }

/* the backend owning section sec: [NAME] or [NAME.anything] */
static int owner(io_set *s, const char *sec)
{
    for (int i = 0; i < s->n; i++) {
        size_t n = strlen(s->ops[i]->name);
        if (!strncmp(sec, s->ops[i]->name, n) && (sec[n] == 0 || sec[n] == '.')) return i;
    }
    return -1;
}

static int config(void *vs, const char *sec, const char *k, const char *v, char *err, size_t n)
{
    io_set *s = vs;
    int i = owner(s, sec);
    if (i < 0) { snprintf(err, n, "no backend listed in [io] backend reads this section"); return -1; }
    return s->ops[i]->config(s->st[i], sec, k, v, err, n);
}

static void safe(void *vs, plc_image *img)
{
    io_set *s = vs;
    for (int i = 0; i < s->opened; i++) s->ops[i]->safe_state(s->st[i], img);
}

/* two backends writing one input: refused, naming both */
static int apart(io_set *s, plc_image *img, char *err, size_t n)
{
    enum { MAX = 8192 };
    io_input_use *in = malloc(MAX * sizeof *in);
    int *by = malloc(MAX * sizeof *by);
    int k = 0, r = 0;
    if (!in || !by) { snprintf(err, n, "out of memory"); r = -1; }
    for (int i = 0; i < s->n && !r; i++) {
        if (!s->ops[i]->inputs) continue;
        int first = k;
        k += s->ops[i]->inputs(s->st[i], img, in + k, MAX - k);
        for (int a = first; a < k; a++) by[a] = i;
        /* within one backend, the backend's own open() checked already */
        for (int a = first; a < k && !r; a++)
            for (int b = 0; b < first && !r; b++)
                if (in[a].p < in[b].p + in[b].w && in[b].p < in[a].p + in[a].w) {
                    snprintf(err, n, "%s (backend %s) and %s (backend %s) write the same input: "
                             "give each its own address", in[b].who, s->ops[by[b]]->name, in[a].who, s->ops[i]->name);
                    r = -1;
                }
    }
    free(in);
    free(by);
    return r;
}

static int open_(void *vs, plc_image *img, uint64_t tick, char *err, size_t n)
{
    io_set *s = vs;
    char e[600];
    for (int i = 0; i < s->n; i++) {
        e[0] = 0;
        if (s->ops[i]->open(s->st[i], img, tick, e, sizeof e)) {
            snprintf(err, n, "backend %s: %s", s->ops[i]->name, e);
            safe(s, img);
            return -1;
        }
        s->opened = i + 1;
    }
    if (s->n > 1 && apart(s, img, err, n)) { safe(s, img); return -1; }
    return 0;
}

static int rd(void *vs, plc_image *img, uint64_t now)
{
    io_set *s = vs;
    int r = 0;
    for (int i = 0; i < s->n; i++) r |= s->ops[i]->read_inputs(s->st[i], img, now);
    return r ? -1 : 0;
}

static int wr(void *vs, const plc_image *img)
{
    io_set *s = vs;
    int r = 0;
    for (int i = 0; i < s->n; i++) r |= s->ops[i]->write_outputs(s->st[i], img);
    return r ? -1 : 0;
}

static void close_(void *vs)
{
    io_set *s = vs;
    for (int i = 0; i < s->n; i++) s->ops[i]->close(s->st[i]);
    free(s);
}

static size_t diag(void *vs, uint16_t *r, size_t max)
{
    io_set *s = vs;
    size_t k = 0;
    for (int i = 0; i < s->n && (size_t)i * IO_DIAG_BLOCK < max; i++) {
        k = (size_t)i * IO_DIAG_BLOCK;
        size_t room = max - k < IO_DIAG_BLOCK ? max - k : IO_DIAG_BLOCK;
        if (s->ops[i]->diag) k += s->ops[i]->diag(s->st[i], r + k, room);
    }
    return k;
}

static int inputs(void *vs, plc_image *img, io_input_use *out, int max)
{
    io_set *s = vs;
    int k = 0;
    for (int i = 0; i < s->n; i++)
        if (s->ops[i]->inputs) k += s->ops[i]->inputs(s->st[i], img, out + k, max - k);
    return k;
}

const io_backend_ops io_multi = {
    "multi", create, config, open_, rd, wr, safe, close_, diag, inputs
};
