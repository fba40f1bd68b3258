/* force.c: see force.h and docs/trace.md. */
#include <stdlib.h>
#include <string.h>
#include "force.h"
#include "plc_image.h"
#include "trace.h"

forcing *force_new(const plc_program *p, int allowed)
{
    forcing *f = calloc(1, sizeof *f);
    if (!f) return NULL;
    f->allowed = allowed;
    f->prog = p;
    f->flag = calloc(p->nvars ? p->nvars : 1, sizeof *f->flag);
    if (!f->flag) { free(f); return NULL; }
    return f;
}

void force_free(forcing *f)
{
    if (!f) return;
    free((void *)f->flag);
    free(f);
}

static int within(const void *p, const uint8_t *a, size_t n)
{
    const uint8_t *q = p;
    return q >= a && q < a + n;
}

int force_area(const plc_var *v)
{
    const void *a = plc_var_addr(v);
    plc_image *i = &plc_img;
    if (within(a, i->ix, sizeof i->ix) || within(a, i->ib, sizeof i->ib) || within(a, i->iw, sizeof i->iw)
        || within(a, i->id, sizeof i->id) || within(a, i->il, sizeof i->il))
        return FORCE_INPUT;
    if (within(a, i->qx, sizeof i->qx) || within(a, i->qb, sizeof i->qb) || within(a, i->qw, sizeof i->qw)
        || within(a, i->qd, sizeof i->qd) || within(a, i->ql, sizeof i->ql))
        return FORCE_OUTPUT;
    return FORCE_INTERNAL;
}

/* ---- the scan's side ------------------------------------------------------ */

void force_begin(forcing *f)
{
    f->cur = atomic_load_explicit(&f->pub, memory_order_acquire);
    atomic_store_explicit(&f->ack, f->cur, memory_order_release);
}

void force_apply(forcing *f, int moment)
{
    const force_table *t = &f->tab[f->cur];
    int skip = moment == FORCE_AFTER_INPUTS ? FORCE_OUTPUT : FORCE_INPUT;
    for (int i = 0; i < t->n; i++)
        if (t->e[i].area != skip) memcpy(t->e[i].addr, &t->e[i].raw, t->e[i].size);
}

/* ---- the server's side ---------------------------------------------------- */

int force_flush(forcing *f)
{
    if (!f->pending) return 0;
    int pub = atomic_load_explicit(&f->pub, memory_order_relaxed);
    if (atomic_load_explicit(&f->ack, memory_order_acquire) != pub) return 1;
    f->tab[!pub] = f->list;
    atomic_store_explicit(&f->pub, !pub, memory_order_release);
    f->pending = 0;
    return 0;
}

static void changed(forcing *f)
{
    f->pending = 1;
    atomic_store(&f->count, f->list.n);
    force_flush(f);
}

int force_set(forcing *f, uint32_t var, uint64_t raw)
{
    if (var >= f->prog->nvars) return -1;
    const plc_var *v = &f->prog->vars[var];
    if (trace_type(v) == TT_NONE) return -1;
    force_table *l = &f->list;
    int i = 0;
    while (i < l->n && l->e[i].var != var) i++;
    if (i == l->n) {
        if (l->n == FORCE_MAX) return -1;
        l->n++;
    }
    /* host order: the value's low bytes first */
    l->e[i] = (force_entry){ plc_var_addr(v), var, (uint8_t)v->size, (uint8_t)force_area(v), 0 };
    uint8_t b[8];
    for (int k = 0; k < 8; k++) b[k] = (uint8_t)(raw >> (8 * k));
    memcpy(&l->e[i].raw, b, 8);
    atomic_store(&f->flag[var], 1);
    changed(f);
    return 0;
}

void force_clear(forcing *f, uint32_t var)
{
    force_table *l = &f->list;
    for (int i = 0; i < l->n; i++)
        if (l->e[i].var == var) {
            l->e[i] = l->e[--l->n];
            atomic_store(&f->flag[var], 0);
            changed(f);
            return;
        }
}

void force_clear_all(forcing *f)
{
    for (int i = 0; i < f->list.n; i++) atomic_store(&f->flag[f->list.e[i].var], 0);
    f->list.n = 0;
    changed(f);
}

int force_count(const forcing *f)
{
    return atomic_load((_Atomic int *)&f->count);
}

int force_is_forced(const forcing *f, uint32_t var)
{
    return var < f->prog->nvars && atomic_load(&f->flag[var]);
}
