/* Memory, strings and diagnostics shared by all stages. */
#include "stc.h"

#include <ctype.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int error_count;
jmp_buf *stc_error_jmp;

/* Every allocation of a compilation comes from chunks chained here and
** freed at its end: small ones are carved from 256 KiB chunks (fresh
** zeroed pages from the system), large ones get a chunk of their own. Under
** AddressSanitizer every allocation gets its own, so that it can catch an
** overrun of any of them. */
typedef struct Chunk { struct Chunk *next; max_align_t data[]; } Chunk;
static Chunk *chunks;
static char *arena_at, *arena_end;
#if defined(__SANITIZE_ADDRESS__)
#define STC_NO_ARENA 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define STC_NO_ARENA 1
#endif
#endif
#ifdef STC_NO_ARENA
enum { ARENA = 0 };
#else
enum { ARENA = 256 * 1024 };
#endif

static void *new_chunk(size_t n) {
    Chunk *c = calloc(1, sizeof(Chunk) + n);
    if (!c) { fputs("stc: out of memory\n", stderr); exit(1); }
    c->next = chunks;
    chunks = c;
    return c->data;
}

void *xalloc(size_t n) {
    size_t a = sizeof(max_align_t);
    n = n ? (n + a - 1) / a * a : a;
    if (n > ARENA / 8) return new_chunk(n);
    if ((size_t)(arena_end - arena_at) < n) {
        arena_at = new_chunk(ARENA);
        arena_end = arena_at + ARENA;
    }
    void *p = arena_at;
    arena_at += n;
    return p;
}

void xfree_all(void) {
    while (chunks) {
        Chunk *n = chunks->next;
        free(chunks);
        chunks = n;
    }
    arena_at = arena_end = NULL;
}

char *xstrndup(const char *s, size_t n) {
    char *p = xalloc(n + 1);
    memcpy(p, s, n);
    return p;
}

char *xstrdup(const char *s) { return xstrndup(s, strlen(s)); }

char *fmt(const char *f, ...) {
    va_list ap;
    va_start(ap, f);
    int n = vsnprintf(NULL, 0, f, ap);
    va_end(ap);
    char *p = xalloc((size_t)n + 1);
    va_start(ap, f);
    vsnprintf(p, (size_t)n + 1, f, ap);
    va_end(ap);
    return p;
}

char *upcase(const char *s) {
    char *p = xstrdup(s);
    for (char *q = p; *q; q++) *q = (char)toupper((unsigned char)*q);
    return p;
}

void vec_push(Vec *v, void *p) {
    if (v->n == v->cap) {
        v->cap = v->cap ? v->cap * 2 : 8;
        void **nv = xalloc(sizeof(void *) * (size_t)v->cap);
        if (v->n) memcpy(nv, v->v, sizeof(void *) * (size_t)v->n);
        v->v = nv;
    }
    v->v[v->n++] = p;
}

void vec_remove(Vec *v, int i) {
    memmove(v->v + i, v->v + i + 1, sizeof(void *) * (size_t)(v->n - i - 1));
    v->n--;
}

static void buf_grow(Buf *b, size_t add) {
    if (b->n + add + 1 <= b->cap) return;
    size_t cap = b->cap ? b->cap : 256;
    while (cap < b->n + add + 1) cap *= 2;
    char *s = xalloc(cap);
    if (b->n) memcpy(s, b->s, b->n + 1);
    b->s = s;
    b->cap = cap;
}

void buf_put(Buf *b, const char *s) {
    size_t n = strlen(s);
    buf_grow(b, n);
    memcpy(b->s + b->n, s, n + 1);
    b->n += n;
}

void buf_printf(Buf *b, const char *f, ...) {
    va_list ap;
    va_start(ap, f);
    int n = vsnprintf(NULL, 0, f, ap);
    va_end(ap);
    buf_grow(b, (size_t)n);
    va_start(ap, f);
    vsnprintf(b->s + b->n, (size_t)n + 1, f, ap);
    va_end(ap);
    b->n += (size_t)n;
}

/* The source line holding loc, without its newline; *len gets its length. */
static const char *line_of(Loc loc, int *len) {
    const char *t = loc.src->text, *end = t + loc.src->len;
    for (int l = 1; l < loc.line && t < end; t++)
        if (*t == '\n') l++;
    const char *e = t;
    while (e < end && *e != '\n') e++;
    if (e > t && e[-1] == '\r') e--;
    *len = (int)(e - t);
    return t;
}

static void vdiag(Loc loc, const char *kind, const char *f, va_list ap) {
    if (!loc.src) {
        fprintf(stderr, "stc: %s: ", kind);
        vfprintf(stderr, f, ap);
        fputc('\n', stderr);
        return;
    }
    fprintf(stderr, "%s:%d:%d: %s: ", loc.src->name, loc.line, loc.col, kind);
    vfprintf(stderr, f, ap);
    fputc('\n', stderr);
    int len;
    const char *s = line_of(loc, &len);
    int col = loc.col - 1;
    if (len > 160) {            /* a long line: show 160 columns around the spot */
        int from = col > 80 ? col - 80 : 0;
        if (from > len) from = len;
        s += from;
        len -= from;
        col -= from;
        if (len > 160) len = 160;
    }
    fputs("  ", stderr);
    for (int i = 0; i < len; i++) {
        unsigned char ch = (unsigned char)s[i];
        fputc(ch == '\t' || ch >= 0x20 ? ch : ' ', stderr);
    }
    fputs("\n  ", stderr);
    for (int i = 0; i < col && i < len; i++) fputc(s[i] == '\t' ? '\t' : ' ', stderr);
    fputs("^\n", stderr);
}

static void verror(Loc loc, const char *f, va_list ap) {
    error_count++;
    vdiag(loc, "error", f, ap);
    if (error_count >= MAX_ERRORS) {
        fprintf(stderr, "stc: too many errors, stopping\n");
        if (stc_error_jmp) longjmp(*stc_error_jmp, 1);
        exit(1);
    }
}

void warning_at(Loc loc, const char *f, ...) {
    va_list ap;
    va_start(ap, f);
    vdiag(loc, "warning", f, ap);
    va_end(ap);
}

void error_at(Loc loc, const char *f, ...) {
    va_list ap;
    va_start(ap, f);
    verror(loc, f, ap);
    va_end(ap);
}

void fatal_at(Loc loc, const char *f, ...) {
    va_list ap;
    va_start(ap, f);
    verror(loc, f, ap);
    va_end(ap);
    if (stc_error_jmp) longjmp(*stc_error_jmp, 1);
    exit(1);
}
