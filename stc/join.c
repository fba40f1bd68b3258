/* A project is the library's files (stc -L) and the user's own. Two things
** a user meets when the editor exported the program:
**  - the OpenPLC editor and Beremiz write one generated_plc.st holding the
**    program and every library block it uses: a POU or type of the user's
**    that the library declares too replaces the library's (replace_library),
**    silently when both read the same token for token (comments and layout
**    aside), else with a warning naming both places;
**  - iec2c reads one file, top to bottom, and wants every declaration before
**    its first use: stc_join_files writes the kept declarations in such an
**    order, with a line map so that its diagnostics can be led back to the
**    user's files.
** The order is found from the names each declaration's tokens mention: a
** declaration comes after those it names (a loop keeps the input order). */
#include "stc.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

/* ---- names -> items: a small open-addressing table ---- */
typedef struct { const char **key; Item **val; int cap; } Names;

static unsigned hash(const char *s) {
    unsigned h = 2166136261u;
    for (; *s; s++) h = (h ^ (unsigned char)*s) * 16777619u;
    return h;
}

static Item **slot(Names *t, const char *key) {
    unsigned i = hash(key) & (unsigned)(t->cap - 1);
    while (t->key[i] && strcmp(t->key[i], key)) i = (i + 1) & (unsigned)(t->cap - 1);
    t->key[i] = key;
    return &t->val[i];
}

static Item *lookup(Names *t, const char *key) {
    unsigned i = hash(key) & (unsigned)(t->cap - 1);
    while (t->key[i]) {
        if (!strcmp(t->key[i], key)) return t->val[i];
        i = (i + 1) & (unsigned)(t->cap - 1);
    }
    return NULL;
}

static Names names_new(int n) {
    Names t;
    t.cap = 16;
    while (t.cap < 4 * n + 16) t.cap *= 2;
    t.key = xalloc(sizeof *t.key * (size_t)t.cap);
    t.val = xalloc(sizeof *t.val * (size_t)t.cap);
    return t;
}

/* ---- the library gives way ---- */
static bool same_token(const Token *a, const Token *b) {
    if (a->kind != b->kind) return false;
    switch (a->kind) {
    case TK_INT: return a->ival == b->ival;
    case TK_REAL: return a->rval == b->rval;
    case TK_STRING: return a->slen == b->slen && !memcmp(a->sval, b->sval, (size_t)a->slen);
    case TK_TIME: return a->tval == b->tval && a->tkind == b->tkind;
    case TK_PRAGMA: return a->ival == b->ival && !strcmp(a->sval, b->sval);
    default: return !strcmp(a->up, b->up);
    }
}

/* An item's tokens as a list, with `a, b : T := v;` read as `a : T := v;
** b : T := v;` (variables and structure fields): editors write one
** declaration per name. */
static bool is_word(const Token *t, const char *w) { return t->kind == TK_IDENT && !strcmp(t->up, w); }
static bool is_punct(const Token *t, const char *w) { return t->kind == TK_PUNCT && !strcmp(t->up, w); }
static bool is_var_kw(const Token *t) {
    return t->kind == TK_IDENT && is_reserved(t->up) && (!strcmp(t->up, "VAR") || !strncmp(t->up, "VAR_", 4));
}

static Vec canonical(const Item *it) {
    Vec v = {0};
    int depth = 0;       /* inside VAR..END_VAR or STRUCT..END_STRUCT */
    bool at_start = false;   /* a declaration may start at the next token */
    for (Token *t = it->first; t <= it->last; t++) {
        if (depth > 0 && at_start && t->kind == TK_IDENT) {
            /* names: IDENT (, IDENT)+ then ':' */
            Token *e = t;
            while (e + 2 <= it->last && e[1].kind == TK_PUNCT && is_punct(&e[1], ",") && e[2].kind == TK_IDENT) e += 2;
            if (e > t && e + 1 <= it->last && is_punct(&e[1], ":")) {
                Token *end = e + 1;
                while (end < it->last && !is_punct(end, ";")) end++;
                for (Token *n = t; n <= e; n += 2) {
                    vec_push(&v, n);
                    for (Token *r = e + 1; r <= end; r++) vec_push(&v, r);
                }
                t = end;
                continue;   /* at_start stays: after ';' */
            }
        }
        if (is_var_kw(t) || is_word(t, "STRUCT")) depth++;
        if (is_word(t, "END_VAR") || is_word(t, "END_STRUCT")) depth--;
        at_start = is_punct(t, ";") || is_word(t, "STRUCT") || is_word(t, "RETAIN") || is_word(t, "NON_RETAIN") ||
                   is_word(t, "CONSTANT") || is_var_kw(t);
        vec_push(&v, t);
    }
    return v;
}

/* NULL when both declarations read the same, else the first token of a
** where they part (*at_b: b's). */
static const Token *first_difference(const Item *a, const Item *b, const Token **at_b) {
    Vec x = canonical(a), y = canonical(b);
    int i = 0;
    for (; i < x.n && i < y.n; i++)
        if (!same_token(x.v[i], y.v[i])) { *at_b = y.v[i]; return x.v[i]; }
    if (x.n == y.n) return NULL;
    *at_b = i < y.n ? y.v[i] : y.v[y.n - 1];
    return i < x.n ? x.v[i] : x.v[x.n - 1];
}

static void drop_decl(Vec *v, void *decl) {
    for (int i = 0; i < v->n; i++)
        if (v->v[i] == decl) { vec_remove(v, i); return; }
}

void replace_library(Unit *u) {
    Names lib = names_new(u->items.n);
    for (int i = 0; i < u->items.n; i++) {
        Item *it = u->items.v[i];
        if (it->library && it->uname && !lookup(&lib, it->uname)) *slot(&lib, it->uname) = it;
    }
    for (int i = 0; i < u->items.n; i++) {
        Item *mine = u->items.v[i], *theirs;
        if (mine->library || !mine->uname || mine->kind == IT_CONFIG) continue;
        if (!(theirs = lookup(&lib, mine->uname)) || theirs->dropped) continue;
        theirs->dropped = true;
        if (theirs->kind == IT_POU) drop_decl(&u->pous, theirs->decl);
        else if (theirs->kind == IT_TYPE) drop_decl(&u->types, theirs->decl);
        const Token *at_theirs = NULL, *at_mine = first_difference(mine, theirs, &at_theirs);
        if (at_mine)
            warning_at(mine->first->loc,
                       "'%s' replaces the library's own (%s:%d), which differs: this one is used "
                       "(they part at line %d, '%s', and %s:%d, '%s')",
                       mine->uname, theirs->first->loc.src->name, theirs->first->loc.line,
                       at_mine->loc.line, at_mine->text, at_theirs->loc.src->name, at_theirs->loc.line,
                       at_theirs->text);
    }
}

/* ---- one file in an order iec2c takes ---- */
static int lines_in(const char *s, size_t n) {
    int k = 0;
    for (size_t i = 0; i < n; i++) k += s[i] == '\n';
    return k;
}

/* Item i's text into out, where line *line is being written; its piece in map. */
static void emit(Buf *out, Buf *map, int *line, const Item *it) {
    const Source *src = it->first->loc.src;
    size_t from = it->first->pos, to = it->last->end;
    int col = it->first->loc.col - 1;
    if (it->kind == IT_TYPE) {
        buf_put(out, "TYPE ");
        col = col > 5 ? col - 5 : 0;
    }
    for (int k = 0; k < col; k++) buf_put(out, " ");
    char *text = xstrndup(src->text + from, to - from);
    buf_put(out, text);
    int n = lines_in(text, to - from);
    buf_printf(map, "%d %d %d %s\n", *line, *line + n, it->first->loc.line, src->name);
    buf_put(out, it->kind == IT_TYPE ? "\nEND_TYPE\n\n" : "\n\n");
    *line += n + (it->kind == IT_TYPE ? 3 : 2);
}

static bool write_text(const char *path, const Buf *b) {
    FILE *f = fopen(path, "w");
    if (!f || fwrite(b->s ? b->s : "", 1, b->n, f) != b->n || fclose(f) != 0) {
        fprintf(stderr, "stc: cannot write '%s': %s\n", path, strerror(errno));
        if (f) fclose(f);
        return false;
    }
    return true;
}

int stc_join_files(const Source *srcs, int nsrcs, int nlib, const char *out, const char *map) {
    jmp_buf jb;
    error_count = 0;
    stc_error_jmp = &jb;
    if (setjmp(jb)) { stc_error_jmp = NULL; xfree_all(); return 1; }
    Unit u = {0};
    for (int i = 0; i < nsrcs; i++) {
        u.library = i < nlib;
        parse_unit(&u, &srcs[i], false);
    }
    replace_library(&u);
    int rc = 1;
    if (!error_count) {
        /* the kept items, and who declares which name */
        int n = 0;
        Item **items = xalloc(sizeof *items * (size_t)(u.items.n + 1));
        for (int i = 0; i < u.items.n; i++)
            if (!((Item *)u.items.v[i])->dropped) items[n++] = u.items.v[i];
        Names decl = names_new(4 * n);
        for (int i = 0; i < n; i++) {
            if (items[i]->uname && !lookup(&decl, items[i]->uname)) *slot(&decl, items[i]->uname) = items[i];
            for (int k = 0; k < items[i]->names.n; k++)
                if (!lookup(&decl, items[i]->names.v[k])) *slot(&decl, items[i]->names.v[k]) = items[i];
        }
        /* what each needs first: the items its identifiers name, once each */
        for (int i = 0; i < n; i++) items[i]->index = i;
        Vec *needs = xalloc(sizeof *needs * (size_t)(n + 1));
        int *seen = xalloc(sizeof *seen * (size_t)(n + 1));
        for (int i = 0; i < n; i++)
            for (const Token *t = items[i]->first; t <= items[i]->last; t++) {
                /* not a name being declared (`x, y : T`) nor a member (`a.x`) */
                if (t->kind != TK_IDENT || (t < items[i]->last && (is_punct(t + 1, ":") || is_punct(t + 1, ","))) ||
                    (t > items[i]->first && is_punct(t - 1, ".")))
                    continue;
                Item *d = lookup(&decl, t->up);
                if (!d || d == items[i] || seen[d->index] == i + 1) continue;
                seen[d->index] = i + 1;
                vec_push(&needs[i], d);
            }
        /* the lowest-numbered item whose needs are all written goes next;
        ** when none is ready (a loop), the lowest-numbered left */
        bool *done = xalloc(sizeof *done * (size_t)(n + 1));
        Buf text = {0}, lines = {0};
        buf_put(&text, "");
        buf_put(&lines, "");
        int line = 1;
        for (int written = 0; written < n; written++) {
            int pick = -1, first_left = -1;
            for (int i = 0; i < n && pick < 0; i++) {
                if (done[i]) continue;
                if (first_left < 0) first_left = i;
                bool ready = true;
                for (int k = 0; k < needs[i].n && ready; k++) ready = done[((Item *)needs[i].v[k])->index];
                if (ready) pick = i;
            }
            if (pick < 0) pick = first_left;
            done[pick] = true;
            emit(&text, &lines, &line, items[pick]);
        }
        rc = write_text(out, &text) && (!map || write_text(map, &lines)) ? 0 : 1;
    }
    stc_error_jmp = NULL;
    xfree_all();
    return rc;
}
