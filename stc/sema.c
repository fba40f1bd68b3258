/* Semantic analysis: resolves names and types, checks the IEC typing rules
** (as strict as matiec's: no implicit conversion between elementary types;
** untyped literals take the type their context asks for) and annotates the
** tree for the code generator. Errors are reported and checking goes on with
** the next statement; compilation stops before code generation. */
#include "stc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

Type *ty_prim[T__COUNT];

static const struct { TypeKind k; const char *name, *cname; } prims[] = {
    {T_BOOL, "BOOL", "BOOL"}, {T_SINT, "SINT", "SINT"}, {T_INT, "INT", "INT"},
    {T_DINT, "DINT", "DINT"}, {T_LINT, "LINT", "LINT"}, {T_USINT, "USINT", "USINT"},
    {T_UINT, "UINT", "UINT"}, {T_UDINT, "UDINT", "UDINT"}, {T_ULINT, "ULINT", "ULINT"},
    {T_BYTE, "BYTE", "BYTE"}, {T_WORD, "WORD", "WORD"}, {T_DWORD, "DWORD", "DWORD"},
    {T_LWORD, "LWORD", "LWORD"}, {T_REAL, "REAL", "REAL"}, {T_LREAL, "LREAL", "LREAL"},
    {T_TIME, "TIME", "TIME"}, {T_DATE, "DATE", "DATE"}, {T_TOD, "TOD", "TOD"},
    {T_DT, "DT", "DT"}, {T_STRING, "STRING", "STRING"},
    {T_LITINT, "ANY_INT", "LINT"}, {T_LITREAL, "ANY_REAL", "LREAL"},
    {T_VOID, "VOID", "void"}, {T_ERROR, "<error>", "int"},
};

Type *canon(Type *t) {
    while (t && t->alias) t = t->alias;
    if (t && t->subrange) t = t->base;
    return t;
}

bool is_int(const Type *t) {
    t = canon((Type *)t);
    return t && ((t->kind >= T_SINT && t->kind <= T_ULINT) || t->kind == T_LITINT);
}
bool is_signed_int(const Type *t) {
    t = canon((Type *)t);
    return t && ((t->kind >= T_SINT && t->kind <= T_LINT) || t->kind == T_LITINT);
}
bool is_real(const Type *t) {
    t = canon((Type *)t);
    return t && (t->kind == T_REAL || t->kind == T_LREAL || t->kind == T_LITREAL);
}
bool is_bit(const Type *t) {
    t = canon((Type *)t);
    return t && t->kind >= T_BYTE && t->kind <= T_LWORD;
}
bool is_num(const Type *t) { return is_int(t) || is_real(t); }
static bool is_lit(const Type *t) { return t && (t->kind == T_LITINT || t->kind == T_LITREAL); }
static bool is_timeish(const Type *t) {
    t = canon((Type *)t);
    return t && t->kind >= T_TIME && t->kind <= T_DT;
}
static bool is_elementary(const Type *t) {
    t = canon((Type *)t);
    return t && t->kind <= T_STRING;
}

int type_bits(const Type *t) {
    switch (canon((Type *)t)->kind) {
    case T_BOOL: return 1;
    case T_SINT: case T_USINT: case T_BYTE: return 8;
    case T_INT: case T_UINT: case T_WORD: return 16;
    case T_DINT: case T_UDINT: case T_DWORD: case T_REAL: return 32;
    case T_LINT: case T_ULINT: case T_LWORD: case T_LREAL: return 64;
    default: return 0;
    }
}

const char *type_name(const Type *t) { return t ? t->name : "?"; }

static void int_range(const Type *t, int64_t *lo, uint64_t *hi) {
    t = t->alias ? canon((Type *)t) : t;
    if (t->subrange) { *lo = t->lo; *hi = (uint64_t)t->hi; return; }
    int b = type_bits(t);
    if (t->kind == T_BOOL) { *lo = 0; *hi = 1; return; }
    if (is_signed_int(t)) { *lo = b == 64 ? INT64_MIN : -(INT64_C(1) << (b - 1)); *hi = (UINT64_C(1) << (b - 1)) - 1; }
    else { *lo = 0; *hi = b == 64 ? UINT64_MAX : (UINT64_C(1) << b) - 1; }
}

/* ---- context and symbol tables ---- */
typedef struct Ctx {
    Unit *u;
    Vec types;      /* Sym (SK_TYPE) */
    Vec pous;       /* Sym (SK_POU) */
    Vec enumvals;   /* Sym (SK_ENUMVAL) */
    Vec arrays;     /* anonymous array types, shared by structure */
    Pou *pou;
    Vec *scope;     /* Sym of the current POU */
    Vec *gscope[2]; /* resource, configuration globals (for VAR_EXTERNAL) */
    int loops;
    Vec forvars;
} Ctx;

static Sym *find(Vec *v, const char *uname) {
    if (!v) return NULL;
    for (int i = 0; i < v->n; i++) {
        Sym *s = v->v[i];
        if (!strcmp(s->uname, uname)) return s;
    }
    return NULL;
}

/* ---- "did you mean": the declared name nearest to a misspelt one ---- */
typedef struct { const char *want; const char *best; int dist; } Near;

static int edit_distance(const char *a, const char *b) {   /* upper-case names */
    size_t n = strlen(a), m = strlen(b);
    if (n > 63 || m > 63) return 99;
    int row[64], prev[64];
    for (size_t j = 0; j <= m; j++) prev[j] = (int)j;
    for (size_t i = 1; i <= n; i++) {
        row[0] = (int)i;
        for (size_t j = 1; j <= m; j++) {
            int sub = prev[j - 1] + (a[i - 1] != b[j - 1]);
            int del = prev[j] + 1, ins = row[j - 1] + 1;
            row[j] = sub < del ? (sub < ins ? sub : ins) : (del < ins ? del : ins);
        }
        memcpy(prev, row, sizeof(int) * (m + 1));
    }
    return prev[m];
}

static void near_name(Near *nr, const char *name) {
    char *up = upcase(name);
    if (!strcmp(up, nr->want)) return;
    int d = edit_distance(nr->want, up);
    size_t len = strlen(nr->want);
    int limit = len <= 2 ? 0 : len <= 4 ? 1 : len <= 7 ? 2 : 3;   /* one- and two-letter names: no guess */
    if (d > 0 && d <= limit && (!nr->best || d < nr->dist)) { nr->best = name; nr->dist = d; }
}

static void near_syms(Near *nr, Vec *v) {
    for (int i = 0; v && i < v->n; i++) near_name(nr, ((Sym *)v->v[i])->name);
}

/* "; did you mean 'x'?" or "" */
static const char *near_hint(Near *nr) { return nr->best ? fmt("; did you mean '%s'?", nr->best) : ""; }

static Sym *new_sym(SymKind k, char *name, char *uname, Loc loc) {
    Sym *s = xalloc(sizeof *s);
    s->kind = k;
    s->name = name;
    s->uname = uname;
    s->loc = loc;
    return s;
}

static Type *new_type(TypeKind k, const char *name, const char *cname) {
    Type *t = xalloc(sizeof *t);
    t->kind = k;
    t->name = (char *)name;
    t->cname = (char *)cname;
    return t;
}

static Type *err_type(void) { return ty_prim[T_ERROR]; }
static bool is_err(Type *t) { return !t || t->kind == T_ERROR; }

/* ---- constant expressions ---- */
static bool const_int(Ctx *c, Node *n, int64_t *v) {
    int64_t a, b;
    switch (n->kind) {
    case N_INT:
        if (n->ival > (uint64_t)INT64_MAX + (n->neg ? 1u : 0u)) return false;
        *v = n->neg ? (int64_t)(0 - n->ival) : (int64_t)n->ival;
        return true;
    case N_TYPED:
        return n->lhs && n->lhs->kind == N_INT && const_int(c, n->lhs, v);
    case N_IDENT: {
        Sym *s = find(c->scope, n->uname);
        if (!s && c->gscope[0]) s = find(c->gscope[0], n->uname);
        if (!s && c->gscope[1]) s = find(c->gscope[1], n->uname);
        if (s && s->kind == SK_VAR && s->constant && s->decl && s->decl->init)
            return const_int(c, s->decl->init, v);
        if (!s) {
            Sym *e = find(&c->enumvals, n->uname);
            if (e) { *v = e->enum_index; return true; }
        }
        return false;
    }
    case N_UNARY:
        if (strcmp(n->op, "-") || !const_int(c, n->lhs, &a)) return false;
        *v = (int64_t)(0 - (uint64_t)a);
        return true;
    case N_BINARY:
        if (!const_int(c, n->lhs, &a) || !const_int(c, n->rhs, &b)) return false;
        if (!strcmp(n->op, "+")) *v = (int64_t)((uint64_t)a + (uint64_t)b);
        else if (!strcmp(n->op, "-")) *v = (int64_t)((uint64_t)a - (uint64_t)b);
        else if (!strcmp(n->op, "*")) *v = (int64_t)((uint64_t)a * (uint64_t)b);
        else if (!strcmp(n->op, "/")) { if (!b || (a == INT64_MIN && b == -1)) return false; *v = a / b; }
        else if (!strcmp(n->op, "MOD")) { if (!b || (a == INT64_MIN && b == -1)) return false; *v = a % b; }
        else return false;
        return true;
    default:
        return false;
    }
}

static int64_t need_const(Ctx *c, Node *n, const char *what) {
    int64_t v;
    if (!const_int(c, n, &v)) {
        error_at(n->start, "%s must be a constant integer expression", what);
        return 0;
    }
    return v;
}

/* ---- type resolution ---- */
static Type *resolve(Ctx *c, TypeSpec *s, const char *declname);
static void check_init(Ctx *c, Type *t, Node *init);

static Sym *type_sym(Ctx *c, const char *uname) { return find(&c->types, uname); }

static Type *named_type(Ctx *c, const char *uname, Loc loc, const char *spelled) {
    for (int k = 0; k <= T_STRING; k++)
        if (!strcmp(ty_prim[k]->name, uname)) return ty_prim[k];
    if (!strcmp(uname, "TIME_OF_DAY")) return ty_prim[T_TOD];
    if (!strcmp(uname, "DATE_AND_TIME")) return ty_prim[T_DT];
    Sym *s = type_sym(c, uname);
    if (s) {
        if (!s->type) {
            TypeDecl *d = (TypeDecl *)s->decl;
            if (s->pou) { error_at(d->loc, "type '%s' is defined in terms of itself", d->name); return err_type(); }
            s->pou = (Pou *)1;      /* resolving: cycle guard */
            Type *t = resolve(c, d->spec, d->uname);
            if (d->spec->kind == TS_NAME) {   /* alias: a distinct name for the same type */
                Type *a = new_type(t->kind, d->uname, d->uname);
                a->alias = t;
                t = a;
            }
            t->init = d->init;
            s->type = t;
        }
        return s->type;
    }
    Sym *p = find(&c->pous, uname);
    if (p && p->pou->kind != POU_FUNCTION) { p->pou->used = true; return p->pou->type; }
    if (p) { error_at(loc, "'%s' is a function, not a type", spelled); return err_type(); }
    Near nr = {uname, NULL, 0};
    for (int k = 0; k <= T_STRING; k++) near_name(&nr, ty_prim[k]->name);
    near_syms(&nr, &c->types);
    for (int i = 0; i < c->pous.n; i++)
        if (((Sym *)c->pous.v[i])->pou->kind == POU_FB) near_name(&nr, ((Sym *)c->pous.v[i])->name);
    error_at(loc, "unknown type '%s'%s", spelled, near_hint(&nr));
    return err_type();
}

static Type *array_type(Ctx *c, Type *elem, Dim *dims, int nd, const char *declname) {
    if (!declname) {
        for (int i = 0; i < c->arrays.n; i++) {
            Type *a = c->arrays.v[i];
            if (a->elem != elem || a->ndims != nd) continue;
            bool same = true;
            for (int k = 0; k < nd; k++)
                if (a->dims[k].lo != dims[k].lo || a->dims[k].hi != dims[k].hi) same = false;
            if (same) return a;
        }
    }
    Buf b = {0};
    buf_printf(&b, "__ARRAY_OF_%s", elem->cname);
    int64_t count = 1;
    for (int k = 0; k < nd; k++) {
        int64_t n = dims[k].hi - dims[k].lo + 1;
        if (dims[k].lo == 0) buf_printf(&b, "_%lld", (long long)n);
        else buf_printf(&b, "_%s%lld_%s%lld", dims[k].lo < 0 ? "m" : "", (long long)llabs(dims[k].lo),
                        dims[k].hi < 0 ? "m" : "", (long long)llabs(dims[k].hi));
        if (n > 0 && count <= (INT64_C(1) << 40) / n) count *= n;
        else count = INT64_C(1) << 41;
    }
    Type *t = new_type(T_ARRAY, declname ? (char *)declname : fmt("ARRAY OF %s", elem->name),
                       declname ? (char *)declname : b.s);
    t->elem = elem;
    t->ndims = nd;
    memcpy(t->dims, dims, sizeof(Dim) * (size_t)nd);
    t->count = count;
    if (!declname) vec_push(&c->arrays, t);
    return t;
}

static Type *resolve(Ctx *c, TypeSpec *s, const char *declname) {
    if (s->resolved) return s->resolved;
    Type *t = err_type();
    switch (s->kind) {
    case TS_NAME:
        t = named_type(c, s->name, s->loc, s->name);
        break;
    case TS_STRING:
        if (s->strlen_) {
            int64_t n = need_const(c, s->strlen_, "string length");
            if (n < 1 || n > 126) error_at(s->strlen_->start, "string length must be 1 to 126");
        }
        t = ty_prim[T_STRING];
        break;
    case TS_ARRAY: {
        Dim dims[8];
        int nd = s->dims.n;
        if (nd > 8) { error_at(s->loc, "arrays have at most 8 dimensions"); nd = 8; }
        bool ok = true;
        for (int k = 0; k < nd; k++) {
            Node *r = s->dims.v[k];
            dims[k].lo = need_const(c, r->lhs, "array bound");
            dims[k].hi = need_const(c, r->rhs, "array bound");
            if (dims[k].hi < dims[k].lo) { error_at(r->start, "array upper bound below lower bound"); ok = false; }
        }
        Type *e = resolve(c, s->elem, NULL);
        if (!ok || is_err(e)) break;
        t = array_type(c, e, dims, nd, declname);
        if (t->count > 16 * 1024 * 1024) { error_at(s->loc, "array too large"); t = err_type(); }
        break;
    }
    case TS_STRUCT: {
        if (!declname) { error_at(s->loc, "STRUCT is only allowed in a TYPE declaration"); break; }
        t = new_type(T_STRUCT, (char *)declname, (char *)declname);
        for (int i = 0; i < s->fields.n; i++) {
            VarDecl *d = s->fields.v[i];
            for (int j = 0; j < t->fields.n; j++)
                if (!strcmp(((Field *)t->fields.v[j])->uname, d->uname))
                    error_at(d->loc, "duplicate declaration of '%s'", d->name);
            if (d->location) error_at(d->locloc, "a structure member cannot have a location");
            Field *f = xalloc(sizeof *f);
            f->name = d->name;
            f->uname = d->uname;
            f->loc = d->loc;
            f->type = resolve(c, d->spec, NULL);
            f->init = d->init;
            if (f->init) check_init(c, f->type, f->init);
            if (f->type->kind == T_FB) error_at(d->loc, "a structure member cannot be a function block instance");
            vec_push(&t->fields, f);
        }
        break;
    }
    case TS_ENUM: {
        static int anon;
        char *name = declname ? (char *)declname : fmt("__ENUM_%d", ++anon);
        t = new_type(T_ENUM, name, name);
        for (int i = 0; i < s->values.n; i++) {
            Token *v = s->values.v[i];
            for (int j = 0; j < t->fields.n; j++)
                if (!strcmp(t->fields.v[j], v->up)) error_at(v->loc, "duplicate declaration of '%s'", v->text);
            vec_push(&t->fields, v->up);
            Sym *e = new_sym(SK_ENUMVAL, v->text, v->up, v->loc);
            e->type = t;
            e->enum_index = i;
            vec_push(&c->enumvals, e);
        }
        break;
    }
    case TS_SUBRANGE: {
        Type *b = named_type(c, s->name, s->loc, s->name);
        if (is_err(b)) break;
        if (!is_int(b)) { error_at(s->loc, "a subrange needs an integer base type, not %s", b->name); break; }
        int64_t lo = need_const(c, s->lo, "subrange bound"), hi = need_const(c, s->hi, "subrange bound");
        int64_t blo;
        uint64_t bhi;
        int_range(canon(b), &blo, &bhi);
        if (hi < lo) error_at(s->lo->start, "subrange upper bound below lower bound");
        if (lo < blo || (hi > 0 && (uint64_t)hi > bhi)) error_at(s->lo->start, "subrange does not fit in %s", b->name);
        t = new_type(canon(b)->kind, declname ? (char *)declname : canon(b)->name,
                     declname ? (char *)declname : canon(b)->cname);
        t->subrange = true;
        t->base = canon(b);
        t->lo = lo;
        t->hi = hi;
        break;
    }
    }
    s->resolved = t;
    return t;
}

/* ---- assignability ---- */
static bool same_type(Type *a, Type *b) {
    a = canon(a);
    b = canon(b);
    return a == b;
}

/* Check literal n (or a tree of literals) can take type t; set it. */
static bool lit_fits(Node *n, Type *t, bool report);

static bool coerce(Node *n, Type *t, bool report) {
    if (!is_lit(n->ty)) return true;
    Type *ct = canon(t);
    if (n->ty->kind == T_LITINT && !(is_int(ct) || is_bit(ct) || ct->kind == T_BOOL || is_real(ct)))
        return false;
    if (n->ty->kind == T_LITREAL && !is_real(ct)) return false;
    if (n->ty->kind == T_LITINT && is_real(ct)) return false;   /* matiec: 1 is not a REAL */
    return lit_fits(n, t, report);
}

static bool lit_fits(Node *n, Type *t, bool report) {
    switch (n->kind) {
    case N_INT: {
        int64_t lo;
        uint64_t hi;
        Type *rt = t->alias ? canon(t) : t;
        if (canon(t)->kind == T_BOOL) {
            if (n->neg || n->ival > 1) {
                if (report) error_at(n->start, "value %s%llu out of range for BOOL", n->neg ? "-" : "", (unsigned long long)n->ival);
                return false;
            }
        } else {
            int_range(rt, &lo, &hi);
            bool ok = n->neg ? (n->ival == 0 || (lo < 0 && n->ival <= (uint64_t)0 - (uint64_t)lo))
                             : n->ival <= hi && (lo <= 0 || n->ival >= (uint64_t)lo);
            if (!ok) {
                if (report) error_at(n->start, "value %s%llu out of range for %s", n->neg ? "-" : "",
                                     (unsigned long long)n->ival, t->name);
                return false;
            }
        }
        n->ty = t;
        return true;
    }
    case N_REAL:
        if (canon(t)->kind == T_REAL && fabs(n->rval) > 3.4028234663852886e38) {
            if (report) error_at(n->start, "value %g out of range for REAL", n->rval);
            return false;
        }
        n->ty = t;
        return true;
    case N_UNARY:
        if (!lit_fits(n->lhs, t, report)) return false;
        n->ty = t;
        return true;
    case N_BINARY: {
        bool cmp = n->ty && canon(n->ty)->kind == T_BOOL;
        if (cmp) return true;
        if (!lit_fits(n->lhs, t, report) || !lit_fits(n->rhs, t, report)) return false;
        n->ty = t;
        return true;
    }
    case N_CALL:
        if (n->opx) {
            if (!lit_fits(n->opx, t, report)) return false;
            n->ty = t;
            return true;
        }
        for (int i = 0; i < n->list.n; i++) {
            Node *a = n->list.v[i];
            if (a->lhs && is_lit(a->lhs->ty) && !lit_fits(a->lhs, t, report)) return false;
        }
        n->ty = t;
        return true;
    default:
        n->ty = t;
        return true;
    }
}

/* Give untyped literals their default type: DINT / LINT / LREAL. */
static void default_lit(Node *n) {
    if (!is_lit(n->ty)) return;
    if (n->ty->kind == T_LITREAL) { coerce(n, ty_prim[T_LREAL], true); return; }
    int64_t v;
    bool small = n->kind == N_INT && !n->neg && n->ival <= INT32_MAX;
    small = small || (n->kind == N_INT && n->neg && n->ival <= (uint64_t)INT32_MAX + 1);
    (void)v;
    Type *t = small ? ty_prim[T_DINT] : ty_prim[T_LINT];
    if (n->kind == N_INT && !n->neg && n->ival > (uint64_t)INT64_MAX) t = ty_prim[T_ULINT];
    if (n->kind != N_INT) t = ty_prim[T_LINT];
    coerce(n, t, true);
}


/* Check an assignment-like transfer; reports at src. */
static void check_transfer(Type *dst, Node *src, const char *ctx_fmt, const char *a, const char *b) {
    if (is_err(dst) || is_err(src->ty)) return;
    if (is_lit(src->ty)) {
        Type *ct = canon(dst);
        bool kind_ok = (src->ty->kind == T_LITINT && (is_int(ct) || is_bit(ct) || ct->kind == T_BOOL)) ||
                       (src->ty->kind == T_LITREAL && is_real(ct));
        if (kind_ok) { coerce(src, dst, true); return; }
    } else if (same_type(dst, src->ty)) {
        /* a subrange destination with a constant source: check the value */
        Type *d = dst;
        while (d->alias) d = d->alias;
        int64_t v;
        (void)v;
        return;
    }
    if (ctx_fmt) error_at(src->start, ctx_fmt, a, b, type_name(src->ty), type_name(dst));
    else error_at(src->start, "type mismatch: cannot assign %s to %s", type_name(src->ty), type_name(dst));
}

/* ---- expressions ---- */
static Type *check(Ctx *c, Node *n, Type *want);
static void check_call_args(Ctx *c, Node *call, Pou *p, bool is_fb);
static Type *check_builtin(Ctx *c, Node *n, Type *want);

/* EN and ENO of a function or function block (IEC 61131-3 2.5.1.2): every one
   has them, so they appear when a call or the body first names them, as a
   BOOL input EN (initially TRUE) and a BOOL output ENO. */
static bool is_en_eno(const char *uname) { return !strcmp(uname, "EN") || !strcmp(uname, "ENO"); }

static Sym *implicit_flag(Pou *p, char *name, VarClass cls) {
    Sym *s = new_sym(SK_VAR, name, name, p->loc);
    VarDecl *d = xalloc(sizeof *d);
    d->name = d->uname = name;
    d->loc = p->loc;
    d->cls = cls;
    if (cls == V_INPUT) {
        Node *t = xalloc(sizeof *t);
        t->kind = N_BOOL;
        t->ival = 1;
        t->ty = ty_prim[T_BOOL];
        t->loc = t->start = p->loc;
        d->init = t;
    }
    s->decl = d;
    s->cls = cls;
    s->type = ty_prim[T_BOOL];
    s->pou = p;
    s->in_function = p->kind == POU_FUNCTION;
    s->implicit = true;
    vec_push(&p->syms, s);
    return s;
}

static void need_en_eno(Pou *p) {
    if (p->kind == POU_PROGRAM) return;
    if (!p->en) p->en = implicit_flag(p, "EN", V_INPUT);
    if (!p->eno) p->eno = implicit_flag(p, "ENO", V_OUTPUT);
}

static Sym *lookup_var(Ctx *c, const char *uname) {
    Sym *s = find(c->scope, uname);
    if (s) return s;
    if (c->pou && c->pou->kind != POU_PROGRAM && is_en_eno(uname)) {
        need_en_eno(c->pou);
        return find(c->scope, uname);
    }
    if (!c->pou) {
        if ((s = find(c->gscope[0], uname))) return s;
        if ((s = find(c->gscope[1], uname))) return s;
    }
    return NULL;
}

static Sym *lookup_enum(Ctx *c, const char *uname, Type *want, Loc loc) {
    Sym *first = NULL;
    int n = 0;
    for (int i = 0; i < c->enumvals.n; i++) {
        Sym *e = c->enumvals.v[i];
        if (strcmp(e->uname, uname)) continue;
        if (want && canon(want) == e->type) return e;
        if (!first) first = e;
        n++;
    }
    if (n > 1) error_at(loc, "'%s' is a value of several enumerations: write Type#%s", uname, uname);
    return first;
}

static Type *check_ident(Ctx *c, Node *n, Type *want) {
    Sym *s = lookup_var(c, n->uname);
    if (s) {
        n->sym = s;
        return s->type;
    }
    Sym *e = lookup_enum(c, n->uname, want, n->loc);
    if (e) {
        n->sym = e;
        return e->type;
    }
    Sym *p = find(&c->pous, n->uname);
    if (p) {
        error_at(n->loc, "'%s' is a %s, not a variable", n->name,
                 p->pou->kind == POU_FUNCTION ? "function" : p->pou->kind == POU_FB ? "function block" : "program");
        return err_type();
    }
    if (type_sym(c, n->uname)) { error_at(n->loc, "'%s' is a type, not a variable", n->name); return err_type(); }
    Near nr = {n->uname, NULL, 0};
    near_syms(&nr, c->scope);
    if (!c->pou) { near_syms(&nr, c->gscope[0]); near_syms(&nr, c->gscope[1]); }
    near_syms(&nr, &c->enumvals);
    error_at(n->loc, "undeclared identifier '%s'%s", n->name, near_hint(&nr));
    return err_type();
}

static Type *check_typed(Ctx *c, Node *n, Type *want) {
    (void)want;
    Type *t = named_type(c, n->tname, n->start, n->name);
    if (is_err(t)) return t;
    if (canon(t)->kind == T_ENUM) {
        if (!n->uname) { error_at(n->start, "expected a value of enumeration %s after '#'", t->name); return err_type(); }
        Type *et = canon(t);
        for (int i = 0; i < et->fields.n; i++)
            if (!strcmp(et->fields.v[i], n->uname)) {
                for (int k = 0; k < c->enumvals.n; k++) {
                    Sym *e = c->enumvals.v[k];
                    if (e->type == et && !strcmp(e->uname, n->uname)) n->sym = e;
                }
                return t;
            }
        error_at(n->loc, "'%s' is not a value of %s", n->uname, t->name);
        return err_type();
    }
    if (!n->lhs || !is_elementary(t)) { error_at(n->start, "'%s#' needs a literal", n->name); return err_type(); }
    Node *l = n->lhs;
    Type *ct = canon(t);
    if (l->kind == N_INT) {
        l->ty = ty_prim[T_LITINT];
        if (is_real(ct)) { error_at(n->start, "malformed %s literal: write %s#%s%llu.0", t->name, n->name, l->neg ? "-" : "", (unsigned long long)l->ival); return err_type(); }
        if (!(is_int(ct) || is_bit(ct) || ct->kind == T_BOOL)) {
            error_at(n->start, "malformed %s literal", t->name);
            return err_type();
        }
        lit_fits(l, t, true);
        return t;
    }
    if (l->kind == N_REAL && is_real(ct)) { l->ty = t; return t; }
    if (l->kind == N_BOOL && ct->kind == T_BOOL) { l->ty = t; return t; }
    if (l->kind == N_STRING && ct->kind == T_STRING) { l->ty = t; return t; }
    error_at(n->start, "malformed %s literal", t->name);
    return err_type();
}

static Type *check_member(Ctx *c, Node *n) {
    Type *bt = check(c, n->lhs, NULL);
    if (is_err(bt)) return bt;
    Type *t = canon(bt);
    if (t->kind == T_STRUCT) {
        for (int i = 0; i < t->fields.n; i++) {
            Field *f = t->fields.v[i];
            if (!strcmp(f->uname, n->uname)) return f->type;
        }
    } else if (t->kind == T_FB) {
        Sym *m = find(&t->pou->syms, n->uname);
        if (!m && is_en_eno(n->uname) && t->pou->kind == POU_FB) {
            need_en_eno(t->pou);
            m = find(&t->pou->syms, n->uname);
        }
        /* an in-out reads the variable the last call connected */
        if (m && (m->cls == V_INPUT || m->cls == V_OUTPUT || m->cls == V_IN_OUT)) { n->sym = m; return m->type; }
        /* matiec lets a POU read and write a block's plain internal
        ** variable (inst.busy := TRUE), and editors' exported projects do
        ** it: accepted with a warning, once a variable. Its internal
        ** instances, located and temporary variables stay out of reach. */
        if (m && m->cls == V_LOCAL && !m->pointer && canon(m->type)->kind != T_FB) {
            if (!m->warned_outside)
                warning_at(n->loc, "'%s' is an internal variable of '%s': IEC 61131-3 does not let other POUs use it (accepted, as matiec does)",
                           n->name, t->pou->name);
            m->warned_outside = true;
            n->sym = m;
            return m->type;
        }
        if (m) {
            error_at(n->loc, "'%s' is an internal variable of '%s', not accessible from outside", n->name, t->pou->name);
            return err_type();
        }
    } else {
        error_at(n->loc, "no member '%s' in '%s': it is not a structure or function block instance", n->name,
                 t->name);
        return err_type();
    }
    Near nr = {n->uname, NULL, 0};
    if (t->kind == T_STRUCT)
        for (int i = 0; i < t->fields.n; i++) near_name(&nr, ((Field *)t->fields.v[i])->name);
    else
        for (int i = 0; i < t->pou->syms.n; i++) {
            Sym *m = t->pou->syms.v[i];
            if (m->cls == V_INPUT || m->cls == V_OUTPUT || m->cls == V_IN_OUT) near_name(&nr, m->name);
        }
    error_at(n->loc, "no member '%s' in '%s'%s", n->name, t->name, near_hint(&nr));
    return err_type();
}

static Type *check_index(Ctx *c, Node *n) {
    Type *bt = check(c, n->lhs, NULL);
    if (is_err(bt)) {
        for (int i = 0; i < n->list.n; i++) check(c, n->list.v[i], NULL);
        return bt;
    }
    Type *t = canon(bt);
    if (t->kind != T_ARRAY) {
        error_at(n->loc, "'%s' is not an array", t->name);
        return err_type();
    }
    if (n->list.n != t->ndims) {
        error_at(n->loc, "array of %d dimension%s indexed with %d", t->ndims, t->ndims > 1 ? "s" : "", n->list.n);
        return err_type();
    }
    for (int i = 0; i < n->list.n; i++) {
        Node *x = n->list.v[i];
        Type *xt = check(c, x, NULL);
        if (is_err(xt)) continue;
        if (is_lit(xt)) default_lit(x);
        if (!is_int(x->ty)) { error_at(x->start, "array index must be an integer, not %s", type_name(x->ty)); continue; }
        int64_t v;
        if (const_int(c, x, &v)) {
            x->is_const = true;
            x->cval = v;
            if (v < t->dims[i].lo || v > t->dims[i].hi)
                error_at(x->start, "array index out of range: %lld not in %lld..%lld", (long long)v,
                         (long long)t->dims[i].lo, (long long)t->dims[i].hi);
        }
    }
    return t->elem;
}

typedef enum { OP_ARITH, OP_MOD, OP_POW, OP_CMP, OP_EQ, OP_LOGIC } OpClass;

static OpClass op_class(const char *op) {
    if (!strcmp(op, "+") || !strcmp(op, "-") || !strcmp(op, "*") || !strcmp(op, "/")) return OP_ARITH;
    if (!strcmp(op, "MOD")) return OP_MOD;
    if (!strcmp(op, "**")) return OP_POW;
    if (!strcmp(op, "=") || !strcmp(op, "<>")) return OP_EQ;
    if (!strcmp(op, "AND") || !strcmp(op, "OR") || !strcmp(op, "XOR")) return OP_LOGIC;
    return OP_CMP;
}

/* the operator as the user wrote it: '+' or ADD */
static const char *opname(Node *n) { return n->name ? n->name : n->op; }

static Type *mismatch(Node *n, Type *a, Type *b) {
    error_at(n->loc, "type mismatch: %s and %s in '%s'", type_name(a), type_name(b), opname(n));
    return err_type();
}

/* Unify the operand types of n: literals take the other side's type. */
static Type *unify(Node *n, Type *lt, Type *rt) {
    if (is_lit(lt) && !is_lit(rt)) {
        if (!coerce(n->lhs, rt, false)) return mismatch(n, lt, rt);
        coerce(n->lhs, rt, true);
        return rt;
    }
    if (is_lit(rt) && !is_lit(lt)) {
        if (!coerce(n->rhs, lt, false)) return mismatch(n, lt, rt);
        coerce(n->rhs, lt, true);
        return lt;
    }
    if (is_lit(lt) && is_lit(rt)) {
        if (lt->kind != rt->kind) return mismatch(n, lt, rt);
        return lt;
    }
    if (!same_type(lt, rt)) return mismatch(n, lt, rt);
    return lt;
}

static Type *check_binary(Ctx *c, Node *n, Type *want) {
    OpClass k = op_class(n->op);
    Type *wop = NULL;
    if (want && !is_err(want)) {
        Type *cw = canon(want);
        if ((k == OP_ARITH || k == OP_POW) && (is_num(cw) || is_timeish(cw))) wop = want;
        else if (k == OP_MOD && is_int(cw)) wop = want;
        else if (k == OP_LOGIC && (cw->kind == T_BOOL || is_bit(cw))) wop = want;
    }
    bool time_scale = (!strcmp(n->op, "*") || !strcmp(n->op, "/")) && wop && is_timeish(wop);
    Type *lt = check(c, n->lhs, wop);
    Type *rwant = k == OP_POW ? NULL : time_scale ? NULL : wop;
    if (!rwant && !is_lit(lt) && !is_err(lt) && k != OP_POW && !time_scale) rwant = lt;
    if (!strcmp(n->op, "*") && lt && is_timeish(lt)) rwant = NULL;
    if (!strcmp(n->op, "/") && lt && is_timeish(lt)) rwant = NULL;
    Type *rt = check(c, n->rhs, rwant);
    if (is_err(lt) || is_err(rt)) return err_type();
    Type *cl = canon(lt), *cr = canon(rt);

    if (k == OP_POW) {
        if (is_lit(lt)) {
            if (lt->kind != T_LITREAL) return mismatch(n, lt, rt);
            coerce(n->lhs, wop && is_real(wop) ? wop : ty_prim[T_LREAL], true);
            lt = n->lhs->ty;
        }
        if (!is_real(lt) || !is_num(rt)) return mismatch(n, lt, rt);
        if (is_lit(rt)) default_lit(n->rhs);
        return lt;
    }
    /* TIME and date arithmetic */
    if (k == OP_ARITH && (is_timeish(cl) || is_timeish(cr))) {
        const char *op = n->op;
        if ((*op == '*' || *op == '/') && cl->kind == T_TIME && is_num(cr)) {
            if (is_lit(rt)) default_lit(n->rhs);
            return lt;
        }
        if (*op == '*' && cr->kind == T_TIME && is_num(cl)) {
            if (is_lit(lt)) default_lit(n->lhs);
            return rt;
        }
        if (is_lit(lt) || is_lit(rt)) return mismatch(n, lt, rt);
        if (*op == '+') {
            if (cl->kind == T_TIME && cr->kind == T_TIME) return lt;
            if ((cl->kind == T_TOD || cl->kind == T_DT) && cr->kind == T_TIME) return lt;
            if (cl->kind == T_TIME && (cr->kind == T_TOD || cr->kind == T_DT)) return rt;
        } else if (*op == '-') {
            if (cr->kind == T_TIME && (cl->kind == T_TIME || cl->kind == T_TOD || cl->kind == T_DT)) return lt;
            if (cl == cr && (cl->kind == T_TOD || cl->kind == T_DT || cl->kind == T_DATE)) return ty_prim[T_TIME];
        }
        return mismatch(n, lt, rt);
    }
    Type *t = unify(n, lt, rt);
    if (is_err(t)) return t;
    Type *ct = canon(t);
    switch (k) {
    case OP_ARITH:
        if (!is_num(ct)) { error_at(n->loc, "'%s' is not defined for %s", opname(n), t->name); return err_type(); }
        return t;
    case OP_MOD:
        if (!is_int(ct)) { error_at(n->loc, "'MOD' needs integers, not %s", t->name); return err_type(); }
        return t;
    case OP_LOGIC:
        if (ct->kind != T_BOOL && !is_bit(ct)) {
            if (is_lit(ct) && wop == NULL) { default_lit(n->lhs); default_lit(n->rhs); }
            error_at(n->loc, "'%s' needs BOOL or bit strings, not %s", opname(n), t->name);
            return err_type();
        }
        return t;
    case OP_CMP:
        if (is_lit(ct)) { default_lit(n->lhs); default_lit(n->rhs); ct = canon(n->lhs->ty); }
        if (!is_num(ct) && !is_bit(ct) && !is_timeish(ct) && ct->kind != T_STRING && ct->kind != T_BOOL) {
            error_at(n->loc, "'%s' cannot compare %s", opname(n), t->name);
            return err_type();
        }
        return ty_prim[T_BOOL];
    case OP_EQ:
        if (is_lit(ct)) { default_lit(n->lhs); default_lit(n->rhs); ct = canon(n->lhs->ty); }
        if (!is_elementary(ct) && ct->kind != T_ENUM) {
            error_at(n->loc, "'%s' cannot compare %s", opname(n), t->name);
            return err_type();
        }
        return ty_prim[T_BOOL];
    default:
        return err_type();
    }
}

static Type *check_unary(Ctx *c, Node *n, Type *want) {
    Type *t = check(c, n->lhs, want);
    if (is_err(t)) return t;
    Type *ct = canon(t);
    if (!strcmp(n->op, "NOT")) {
        if (ct->kind == T_BOOL || is_bit(ct)) return t;
        if (ct->kind == T_LITINT) return t;
        error_at(n->loc, "'NOT' needs BOOL or a bit string, not %s", t->name);
        return err_type();
    }
    if (is_lit(ct) || (is_num(ct) && (is_signed_int(ct) || is_real(ct))) || ct->kind == T_TIME) return t;
    error_at(n->loc, "unary '-' is not defined for %s", t->name);
    return err_type();
}

static bool is_lvalue(Node *n) {
    return n->kind == N_IDENT || n->kind == N_MEMBER || n->kind == N_INDEX;
}

static Sym *root_sym(Node *n) {
    while (n->kind == N_MEMBER || n->kind == N_INDEX) n = n->lhs;
    return n->kind == N_IDENT ? n->sym : NULL;
}

/* Report writing to n when that is not allowed. */
static void check_writable(Ctx *c, Node *n) {
    if (!is_lvalue(n)) { error_at(n->start, "cannot assign to an expression"); return; }
    if (n->kind == N_IDENT && n->sym && n->sym->kind == SK_ENUMVAL) {
        error_at(n->start, "cannot assign to enumeration value '%s'", n->name);
        return;
    }
    Sym *r = root_sym(n);
    if (!r || r->kind != SK_VAR) return;
    if (r->constant) { error_at(n->start, "cannot assign to constant '%s'", r->name); return; }
    if (r->loop_locked) { error_at(n->start, "cannot assign to FOR variable '%s' inside its loop", r->name); return; }
    /* writing an instance's member from outside: inputs only */
    for (Node *m = n; m->kind == N_MEMBER || m->kind == N_INDEX; m = m->lhs) {
        if (m->kind == N_MEMBER && m->sym && m->sym->kind == SK_VAR && m->sym->cls == V_IN_OUT) {
            Node *inst = m->lhs;
            error_at(n->start, "cannot assign to in-out '%s' of instance '%s': connect it in a call", m->name,
                     inst->kind == N_IDENT ? inst->name : "instance");
            return;
        }
        if (m->kind == N_MEMBER && m->sym && m->sym->kind == SK_VAR && m->sym->cls == V_OUTPUT) {
            Node *inst = m->lhs;
            const char *iname = inst->kind == N_IDENT ? inst->name : "instance";
            error_at(n->start, "cannot assign to output '%s' of instance '%s'", m->name, iname);
            return;
        }
    }
    if (c->pou && c->pou->kind == POU_FUNCTION && r->cls == V_INPUT && n->kind == N_IDENT) return;
}

/* A call naming EN or ENO gives the callee both. */
static void uses_en_eno(Node *call, Pou *p) {
    for (int i = 0; i < call->list.n; i++) {
        Node *a = call->list.v[i];
        if (a->uname && is_en_eno(a->uname)) need_en_eno(p);
    }
}

static void near_builtins(Near *nr);

static Type *prim_named(const char *s, size_t len);

static Type *check_call(Ctx *c, Node *n, Type *want, bool stmt) {
    if (n->lhs) {      /* a[i](...): the instance is an expression */
        Type *it = check(c, n->lhs, NULL);
        if (is_err(it)) return it;
        if (canon(it)->kind != T_FB) { error_at(n->lhs->start, "this is not a function block instance, it is %s", type_name(it)); return err_type(); }
        n->callee = canon(it)->pou;
        n->name = n->callee->name;
        uses_en_eno(n, n->callee);
        check_call_args(c, n, n->callee, true);
        return ty_prim[T_VOID];
    }
    Sym *v = lookup_var(c, n->uname);
    if (v && v->kind == SK_VAR) {
        Type *t = canon(v->type);
        if (t->kind != T_FB) {
            error_at(n->loc, "'%s' is not a function block instance", n->name);
            return err_type();
        }
        if (!stmt) {
            error_at(n->loc, "function block instance '%s' cannot be called inside an expression", n->name);
            return err_type();
        }
        n->sym = v;
        n->callee = t->pou;
        uses_en_eno(n, t->pou);
        check_call_args(c, n, t->pou, true);
        return ty_prim[T_VOID];
    }
    Sym *p = find(&c->pous, n->uname);
    if (p) {
        if (p->pou->kind != POU_FUNCTION) {
            error_at(n->loc, "'%s' is a %s type: declare an instance and call that", n->name,
                     p->pou->kind == POU_FB ? "function block" : "program");
            return err_type();
        }
        p->pou->used = true;
        n->callee = p->pou;
        if (c->pou) vec_push(&c->pou->calls, p->pou);
        uses_en_eno(n, p->pou);
        check_call_args(c, n, p->pou, false);
        return p->pou->rettype;
    }
    Type *b = check_builtin(c, n, want);
    if (b) return b;
    const char *us = strstr(n->uname, "_TO_");
    if (!v && us && prim_named(n->uname, (size_t)(us - n->uname)) && prim_named(us + 4, strlen(us + 4))) {
        error_at(n->loc, "'%s' is not a standard function (matiec has no such conversion): declare it as a FUNCTION", n->name);
        return err_type();
    }
    if (v) { error_at(n->loc, "'%s' is not a function", n->name); return err_type(); }
    Near nr = {n->uname, NULL, 0};
    for (int i = 0; i < c->pous.n; i++)
        if (((Sym *)c->pous.v[i])->pou->kind == POU_FUNCTION) near_name(&nr, ((Sym *)c->pous.v[i])->name);
    near_builtins(&nr);
    near_syms(&nr, c->scope);
    error_at(n->loc, "'%s' is not a function%s", n->name, near_hint(&nr));
    return err_type();
}

/* Arguments of a user function or function-block call. */
static void check_call_args(Ctx *c, Node *call, Pou *p, bool is_fb) {
    Vec params = {0};
    for (int i = 0; i < p->syms.n; i++) {
        Sym *s = p->syms.v[i];
        if (s->cls == V_INPUT || s->cls == V_OUTPUT || s->cls == V_IN_OUT) vec_push(&params, s);
    }
    int formal = -1;
    bool *given = xalloc(sizeof(bool) * (size_t)(params.n + 1));
    int ninputs = 0;
    for (int i = 0; i < params.n; i++)
        if (((Sym *)params.v[i])->cls != V_OUTPUT && !((Sym *)params.v[i])->implicit) ninputs++;
    for (int i = 0; i < call->list.n; i++) {
        Node *a = call->list.v[i];
        bool f = a->name != NULL;
        if (formal < 0) formal = f;
        else if (formal != f) { error_at(a->loc, "cannot mix formal (name := value) and positional arguments"); return; }
    }
    if (formal == 0) {
        /* positional: inputs and in-outs in declaration order */
        int k = 0;
        if (call->list.n > ninputs) {
            error_at(call->loc, "'%s' expects %d argument%s, got %d", p->name, ninputs, ninputs == 1 ? "" : "s",
                     call->list.n);
            for (int i = 0; i < call->list.n; i++) check(c, ((Node *)call->list.v[i])->lhs, NULL);
            return;
        }
        for (int i = 0; i < params.n && k < call->list.n; i++) {
            Sym *s = params.v[i];
            if (s->cls == V_OUTPUT || s->implicit) continue;
            Node *a = call->list.v[k++];
            a->sym = s;
            a->name = s->name;
            a->uname = s->uname;
            given[i] = true;
        }
    }
    for (int i = 0; i < call->list.n; i++) {
        Node *a = call->list.v[i];
        int pi = -1;
        for (int j = 0; j < params.n; j++)
            if (!strcmp(((Sym *)params.v[j])->uname, a->uname)) pi = j;
        if (pi < 0) {
            Near nr = {a->uname, NULL, 0};
            near_syms(&nr, &params);
            error_at(a->loc, "unknown parameter '%s' for '%s'%s", a->name, p->name, near_hint(&nr));
            if (a->lhs) check(c, a->lhs, NULL);
            continue;
        }
        Sym *s = params.v[pi];
        if (formal && given[pi]) { error_at(a->loc, "parameter '%s' given twice", a->name); continue; }
        given[pi] = true;
        a->sym = s;
        if (s->cls == V_OUTPUT) {
            if (!a->is_out) { error_at(a->loc, "cannot connect output '%s' with ':=': use '=>'", a->name); continue; }
            if (a->negated) { error_at(a->loc, "negated output connections are not supported"); continue; }
            if (!a->lhs) continue;
            Type *t = check(c, a->lhs, s->type);
            if (is_err(t)) continue;
            check_writable(c, a->lhs);
            if (!same_type(t, s->type))
                error_at(a->lhs->start, "type mismatch: output '%s' of '%s' is %s, its target %s", a->name, p->name,
                         type_name(s->type), type_name(t));
            continue;
        }
        if (a->is_out) { error_at(a->loc, "'%s' is not an output of '%s'", a->name, p->name); continue; }
        Type *t = check(c, a->lhs, s->type);
        if (s->cls == V_IN_OUT) {
            if (!is_lvalue(a->lhs)) { error_at(a->lhs->start, "in-out parameter '%s' needs a variable", a->name); continue; }
            if (is_err(t)) continue;
            check_writable(c, a->lhs);
            if (!same_type(t, s->type))
                error_at(a->lhs->start, "type mismatch: parameter '%s' of '%s' expects %s, got %s", a->name, p->name,
                         type_name(s->type), type_name(t));
            continue;
        }
        check_transfer(s->type, a->lhs, "type mismatch: parameter '%s' of '%s' expects %4$s, got %3$s", a->name, p->name);
    }
    int missing = 0;
    for (int i = 0; i < params.n; i++) {
        Sym *s = params.v[i];
        /* a formal call may leave inputs out: they take their initial value */
        bool needed = s->cls == V_IN_OUT || (formal == 0 && !is_fb && s->cls == V_INPUT && !s->decl->init && !s->implicit);
        if (!needed || given[i]) continue;
        if (formal == 0 && !missing++)
            error_at(call->loc, "'%s' expects %d argument%s, got %d", p->name, ninputs, ninputs == 1 ? "" : "s",
                     call->list.n);
        else if (formal != 0)
            error_at(call->loc, "missing parameter '%s' for '%s'", s->name, p->name);
    }
}

/* ---- builtin functions ---- */
/* nargs < 0: extensible, at least -nargs inputs IN1, IN2, ... (MUX: K, IN0, ...);
   the operator functions' operators are in opfns */
static const struct { const char *name; int id; int nargs; const char *pnames[3]; } builtins[] = {
    {"TRUNC", B_TRUNC, 1, {"IN"}}, {"ABS", B_ABS, 1, {"IN"}}, {"SQRT", B_SQRT, 1, {"IN"}},
    {"LN", B_LN, 1, {"IN"}}, {"LOG", B_LOG, 1, {"IN"}}, {"EXP", B_EXP, 1, {"IN"}},
    {"SIN", B_SIN, 1, {"IN"}}, {"COS", B_COS, 1, {"IN"}}, {"TAN", B_TAN, 1, {"IN"}},
    {"ASIN", B_ASIN, 1, {"IN"}}, {"ACOS", B_ACOS, 1, {"IN"}}, {"ATAN", B_ATAN, 1, {"IN"}},
    {"EXPT", B_EXPT, 2, {"IN1", "IN2"}}, {"SEL", B_SEL, 3, {"G", "IN0", "IN1"}},
    {"MAX", B_MAX, -2, {0}}, {"MIN", B_MIN, -2, {0}}, {"LIMIT", B_LIMIT, 3, {"MN", "IN", "MX"}},
    {"MUX", B_MUX, -3, {0}}, {"MOVE", B_MOVE, 1, {"IN"}}, {"SHL", B_SHL, 2, {"IN", "N"}},
    {"SHR", B_SHR, 2, {"IN", "N"}}, {"ROL", B_ROL, 2, {"IN", "N"}}, {"ROR", B_ROR, 2, {"IN", "N"}},
    {"LEN", B_LEN, 1, {"IN"}},
    /* IEC 61131-3 tables 24, 26, 28: the operators as functions (opfns) */
    {"ADD", B_OP, -2, {0}}, {"MUL", B_OP, -2, {0}}, {"SUB", B_OP, 2, {"IN1", "IN2"}},
    {"DIV", B_DIV, 2, {"IN1", "IN2"}}, {"MOD", B_OP, 2, {"IN1", "IN2"}},
    {"AND", B_OP, -2, {0}}, {"OR", B_OP, -2, {0}}, {"XOR", B_OP, -2, {0}}, {"NOT", B_OP, 1, {"IN"}},
    {"GT", B_OP, -2, {0}}, {"GE", B_OP, -2, {0}}, {"EQ", B_OP, -2, {0}},
    {"LE", B_OP, -2, {0}}, {"LT", B_OP, -2, {0}}, {"NE", B_OP, 2, {"IN1", "IN2"}},
    {"CONCAT", B_CONCAT, -2, {0}},
    {NULL, 0, 0, {0}},
};

static const char *const opfns[][2] = {
    {"ADD", "+"}, {"MUL", "*"}, {"SUB", "-"}, {"DIV", "/"}, {"MOD", "MOD"}, {"AND", "AND"}, {"OR", "OR"},
    {"XOR", "XOR"}, {"NOT", "NOT"}, {"GT", ">"}, {"GE", ">="}, {"EQ", "="}, {"LE", "<="}, {"LT", "<"}, {"NE", "<>"},
};

/* Standard functions of fixed signature (matiec's time and string
   functions): each input an elementary type, or A_INT (any integer, passed
   as LINT) or A_NUM (any number, passed as LREAL); FIND's result takes the
   integer type the context wants (INT otherwise). A helper in upper case
   takes ENO's address last (NULL when not connected) and clears it when it
   refuses its inputs. */
enum { A_INT = -1, A_NUM = -2 };
static const struct LibFn { const char *name, *cfn; int ret, nargs; const char *pnames[4]; int ptypes[4]; } libfns[] = {
    {"ADD_TIME", "__time_add", T_TIME, 2, {"IN1", "IN2"}, {T_TIME, T_TIME}},
    {"SUB_TIME", "__time_sub", T_TIME, 2, {"IN1", "IN2"}, {T_TIME, T_TIME}},
    {"ADD_TOD_TIME", "__time_add", T_TOD, 2, {"IN1", "IN2"}, {T_TOD, T_TIME}},
    {"ADD_DT_TIME", "__time_add", T_DT, 2, {"IN1", "IN2"}, {T_DT, T_TIME}},
    {"SUB_TOD_TIME", "__time_sub", T_TOD, 2, {"IN1", "IN2"}, {T_TOD, T_TIME}},
    {"SUB_DT_TIME", "__time_sub", T_DT, 2, {"IN1", "IN2"}, {T_DT, T_TIME}},
    {"SUB_DATE_DATE", "__time_sub", T_TIME, 2, {"IN1", "IN2"}, {T_DATE, T_DATE}},
    {"SUB_TOD_TOD", "__time_sub", T_TIME, 2, {"IN1", "IN2"}, {T_TOD, T_TOD}},
    {"SUB_DT_DT", "__time_sub", T_TIME, 2, {"IN1", "IN2"}, {T_DT, T_DT}},
    {"CONCAT_DATE_TOD", "__time_add", T_DT, 2, {"IN1", "IN2"}, {T_DATE, T_TOD}},
    {"MULTIME", "__time_mul_real", T_TIME, 2, {"IN1", "IN2"}, {T_TIME, A_NUM}},
    {"DIVTIME", "__time_div_real", T_TIME, 2, {"IN1", "IN2"}, {T_TIME, A_NUM}},
    {"LEFT", "__LEFT", T_STRING, 2, {"IN", "L"}, {T_STRING, A_INT}},
    {"RIGHT", "__RIGHT", T_STRING, 2, {"IN", "L"}, {T_STRING, A_INT}},
    {"MID", "__MID", T_STRING, 3, {"IN", "L", "P"}, {T_STRING, A_INT, A_INT}},
    {"INSERT", "__INSERT", T_STRING, 3, {"IN1", "IN2", "P"}, {T_STRING, T_STRING, A_INT}},
    {"DELETE", "__DELETE", T_STRING, 3, {"IN", "L", "P"}, {T_STRING, A_INT, A_INT}},
    {"REPLACE", "__REPLACE", T_STRING, 4, {"IN1", "IN2", "L", "P"}, {T_STRING, T_STRING, A_INT, A_INT}},
    {"FIND", "__str_find", A_INT, 2, {"IN1", "IN2"}, {T_STRING, T_STRING}},
    {NULL, NULL, 0, 0, {0}, {0}},
};

/* MULTIME_<T> and DIVTIME_<T>: the typed forms, IN2 of the number type T. */
static const char *const numtypes[] = {"SINT", "INT", "DINT", "LINT", "USINT", "UINT", "UDINT", "ULINT", "REAL", "LREAL", NULL};

static const struct LibFn *find_libfn(const char *uname, int *typed) {
    *typed = -1;
    for (int i = 0; libfns[i].name; i++)
        if (!strcmp(libfns[i].name, uname)) return &libfns[i];
    for (int k = 0; k < 2; k++) {
        const char *pre = k ? "DIVTIME_" : "MULTIME_";
        if (strncmp(uname, pre, 8)) continue;
        for (int j = 0; numtypes[j]; j++)
            if (!strcmp(uname + 8, numtypes[j])) { *typed = j; return &libfns[k ? 11 : 10]; }
    }
    return NULL;
}

/* The conversions matiec has: CONV_PLAIN <T>_TO_<U> for elementary T, U
   (short names; of the long ones only DATE_AND_TIME_TO_DATE and
   DATE_AND_TIME_TO_TIME_OF_DAY), except between TIME, DATE, TOD and DT
   where only DT_TO_DATE, DT_TO_TOD and the identities exist, and no
   STRING_TO_STRING; CONV_TO_BCD
   <U>_TO_BCD[_<B>] and CONV_FROM_BCD [<B>_]BCD_TO_<U> for unsigned U and
   bit strings B. A name outside these is free for a user's FUNCTION
   (TIME_TO_TOD, for one). */
enum { CONV_NONE, CONV_PLAIN, CONV_TO_BCD, CONV_FROM_BCD };
static Type *prim_named(const char *s, size_t len);
static Type *short_prim(const char *s, size_t len) {
    Type *t = prim_named(s, len);
    return t && strlen(t->name) == len ? t : NULL;
}
static bool is_uint_kind(const Type *t) { return t && (t->kind == T_USINT || t->kind == T_UINT || t->kind == T_UDINT || t->kind == T_ULINT); }
static bool is_nbit_kind(const Type *t) { return t && (t->kind == T_BYTE || t->kind == T_WORD || t->kind == T_DWORD || t->kind == T_LWORD); }
static int conv_kind(const char *uname, Type **from, Type **to) {
    *from = *to = NULL;
    if (!strcmp(uname, "DATE_AND_TIME_TO_DATE")) { *from = ty_prim[T_DT]; *to = ty_prim[T_DATE]; return CONV_PLAIN; }
    if (!strcmp(uname, "DATE_AND_TIME_TO_TIME_OF_DAY")) { *from = ty_prim[T_DT]; *to = ty_prim[T_TOD]; return CONV_PLAIN; }
    const char *bcd = strstr(uname, "BCD_TO_");
    if (bcd && (bcd == uname || (bcd[-1] == '_' && (*from = short_prim(uname, (size_t)(bcd - 1 - uname))) && is_nbit_kind(*from)))) {
        *to = short_prim(bcd + 7, strlen(bcd + 7));
        return is_uint_kind(*to) ? CONV_FROM_BCD : CONV_NONE;
    }
    const char *us = strstr(uname, "_TO_BCD");
    if (us && (!us[7] || us[7] == '_')) {
        *from = short_prim(uname, (size_t)(us - uname));
        if (us[7]) { *to = short_prim(us + 8, strlen(us + 8)); if (!is_nbit_kind(*to)) return CONV_NONE; }
        return is_uint_kind(*from) ? CONV_TO_BCD : CONV_NONE;
    }
    us = strstr(uname, "_TO_");
    if (!us) return CONV_NONE;
    *from = short_prim(uname, (size_t)(us - uname));
    *to = short_prim(us + 4, strlen(us + 4));
    if (!*from || !*to) return CONV_NONE;
    int f = (*from)->kind, t = (*to)->kind;
    if (f == T_STRING && t == T_STRING) return CONV_NONE;
    if (f >= T_TIME && f <= T_DT && t >= T_TIME && t <= T_DT && f != t && !(f == T_DT && (t == T_DATE || t == T_TOD)))
        return CONV_NONE;
    return CONV_PLAIN;
}

static void near_builtins(Near *nr) {
    for (int i = 0; builtins[i].name; i++) near_name(nr, builtins[i].name);
    for (int i = 0; libfns[i].name; i++) near_name(nr, libfns[i].name);
}

static const char *opfn_op(const char *uname) {
    for (size_t i = 0; i < sizeof opfns / sizeof opfns[0]; i++)
        if (!strcmp(opfns[i][0], uname)) return opfns[i][1];
    return NULL;
}

/* The elementary type named by the first len chars of s, or NULL. */
static Type *prim_named(const char *s, size_t len) {
    for (int k = 0; k <= T_STRING; k++)
        if (strlen(ty_prim[k]->name) == len && !strncmp(ty_prim[k]->name, s, len)) return ty_prim[k];
    if (len == 11 && !strncmp(s, "TIME_OF_DAY", 11)) return ty_prim[T_TOD];
    if (len == 13 && !strncmp(s, "DATE_AND_TIME", 13)) return ty_prim[T_DT];
    return NULL;
}

/* Put formal builtin arguments in positional order. */
static bool order_builtin_args(Node *n, int id, int nb) {
    bool formal = n->list.n && ((Node *)n->list.v[0])->name;
    if (!formal) {
        for (int i = 0; i < n->list.n; i++)
            if (((Node *)n->list.v[i])->name) { error_at(((Node *)n->list.v[i])->loc, "cannot mix formal (name := value) and positional arguments"); return false; }
        return true;
    }
    int cnt = n->list.n;
    bool fixed = nb >= 0 && builtins[nb].nargs > 1 && builtins[nb].nargs >= cnt;
    if (fixed) cnt = builtins[nb].nargs;
    Node **ord = xalloc(sizeof(Node *) * (size_t)(cnt + 1));
    for (int i = 0; i < n->list.n; i++) {
        Node *a = n->list.v[i];
        if (!a->name || a->is_out) { error_at(a->loc, "cannot mix formal (name := value) and positional arguments"); return false; }
        int pos = -1;
        if (nb < 0 || builtins[nb].nargs == 1) pos = !strcmp(a->uname, "IN") ? 0 : -1;
        else if (nb >= 0 && builtins[nb].nargs > 0) {
            for (int k = 0; k < builtins[nb].nargs; k++)
                if (builtins[nb].pnames[k] && !strcmp(builtins[nb].pnames[k], a->uname)) pos = k;
        } else if (id == B_MUX) {
            if (!strcmp(a->uname, "K")) pos = 0;
            else if (!strncmp(a->uname, "IN", 2) && a->uname[2]) pos = atoi(a->uname + 2) + 1;
        } else if (!strncmp(a->uname, "IN", 2) && a->uname[2]) {
            pos = atoi(a->uname + 2) - 1;
        }
        if (pos < 0 || pos >= cnt || ord[pos]) {
            error_at(a->loc, "unknown parameter '%s' for '%s'", a->name, n->name);
            return false;
        }
        ord[pos] = a;
    }
    for (int i = 0; i < cnt; i++) {
        if (!ord[i]) {
            if (fixed) error_at(n->loc, "missing parameter '%s' for '%s'", builtins[nb].pnames[i], n->name);
            else error_at(n->loc, "missing parameter for '%s'", n->name);
            return false;
        }
    }
    for (int i = 0; i < cnt; i++) n->list.v[i] = ord[i];
    return true;
}

static Node *arg(Node *n, int i) { return ((Node *)n->list.v[i])->lhs; }

/* Check args as one generic type (MAX, MIN, LIMIT, MUX, SEL); returns it. */
static Type *generic_args(Ctx *c, Node *n, int from, Type *want) {
    Type *t = NULL;
    for (int i = from; i < n->list.n; i++) {
        Type *at = check(c, arg(n, i), want && !is_err(want) ? want : NULL);
        if (is_err(at)) return err_type();
        if (!is_lit(at) && !t) t = at;
    }
    if (!t) {
        t = want && !is_err(want) ? want : NULL;
        if (!t) {
            default_lit(arg(n, from));
            t = arg(n, from)->ty;
        }
    }
    for (int i = from; i < n->list.n; i++) {
        Node *a = arg(n, i);
        if (is_lit(a->ty)) {
            if (!coerce(a, t, false)) {
                error_at(a->start, "type mismatch: parameter %d of '%s' expects %s, got %s", i + 1, n->name,
                         type_name(t), type_name(a->ty));
                return err_type();
            }
            coerce(a, t, true);
        } else if (!same_type(a->ty, t)) {
            error_at(a->start, "type mismatch: parameter %d of '%s' expects %s, got %s", i + 1, n->name,
                     type_name(t), type_name(a->ty));
            return err_type();
        }
    }
    return t;
}

/* EN := and ENO => of a standard function call leave its argument list. */
static bool split_en_eno(Node *n) {
    int k = 0;
    for (int i = 0; i < n->list.n; i++) {
        Node *a = n->list.v[i];
        if (a->uname && !strcmp(a->uname, "EN")) {
            if (a->is_out) { error_at(a->loc, "'EN' is not an output of '%s'", n->name); return false; }
            n->en = a->lhs;
            continue;
        }
        if (a->uname && !strcmp(a->uname, "ENO")) {
            if (!a->is_out) { error_at(a->loc, "cannot connect output 'ENO' with ':=': use '=>'"); return false; }
            if (a->negated) { error_at(a->loc, "negated output connections are not supported"); return false; }
            n->eno = a;
            continue;
        }
        n->list.v[k++] = a;
    }
    n->list.n = k;
    for (int i = 0; (n->en || n->eno) && i < k; i++)   /* EN/ENO make a call formal (matiec too) */
        if (!((Node *)n->list.v[i])->name) {
            error_at(((Node *)n->list.v[i])->loc, "cannot mix formal (name := value) and positional arguments");
            return false;
        }
    return true;
}

static void check_en_eno(Ctx *c, Node *n) {
    if (n->en) {
        check(c, n->en, ty_prim[T_BOOL]);
        check_transfer(ty_prim[T_BOOL], n->en, "type mismatch: parameter '%s' of '%s' expects %4$s, got %3$s", "EN", n->name);
    }
    if (n->eno && n->eno->lhs) {
        Type *t = check(c, n->eno->lhs, ty_prim[T_BOOL]);
        if (is_err(t)) return;
        check_writable(c, n->eno->lhs);
        if (canon(t)->kind != T_BOOL)
            error_at(n->eno->lhs->start, "type mismatch: output 'ENO' of '%s' is BOOL, its target %s", n->name, type_name(t));
    }
}

static bool has_call(Node *n) {
    if (!n) return false;
    if (n->kind == N_CALL) return true;
    if (has_call(n->lhs) || has_call(n->rhs)) return true;
    for (int i = 0; i < n->list.n; i++) if (has_call(n->list.v[i])) return true;
    return false;
}

static Node *clone_expr(Node *n) {
    if (!n) return NULL;
    Node *x = xalloc(sizeof *x);
    *x = *n;
    x->lhs = clone_expr(n->lhs);
    x->rhs = clone_expr(n->rhs);
    x->list = (Vec){0};
    for (int i = 0; i < n->list.n; i++) vec_push(&x->list, clone_expr(n->list.v[i]));
    return x;
}

static Node *op_node(Node *call, const char *op, Node *l, Node *r) {
    Node *x = xalloc(sizeof *x);
    x->kind = r ? N_BINARY : N_UNARY;
    x->loc = call->loc;
    x->start = l->start;
    x->op = op;
    x->name = call->name;    /* diagnostics name the function, not the operator */
    x->lhs = l;
    x->rhs = r;
    return x;
}

/* ADD(a, b, c) is (a + b) + c; GT(a, b, c) is a > b AND b > c (IEC 61131-3
   tables 24 and 28); NOT(a) is NOT a. The call keeps the operator tree. */
static Type *operator_function(Ctx *c, Node *n, const char *op, Type *want) {
    Node *x;
    bool cmp = !strcmp(op, ">") || !strcmp(op, ">=") || !strcmp(op, "=") || !strcmp(op, "<=") || !strcmp(op, "<");
    if (!strcmp(op, "NOT")) {
        x = op_node(n, op, arg(n, 0), NULL);
    } else if (cmp && n->list.n > 2) {
        for (int i = 1; i + 1 < n->list.n; i++)
            if (has_call(arg(n, i))) {
                error_at(arg(n, i)->start, "'%s' with more than two inputs compares each middle input twice: "
                         "a function call there is not supported, give it a variable", n->name);
                return err_type();
            }
        x = NULL;
        for (int i = 0; i + 1 < n->list.n; i++) {
            Node *pair = op_node(n, op, i ? clone_expr(arg(n, i)) : arg(n, i), arg(n, i + 1));
            x = x ? op_node(n, "AND", x, pair) : pair;
        }
    } else {
        x = arg(n, 0);
        for (int i = 1; i < n->list.n; i++) x = op_node(n, op, x, arg(n, i));
    }
    n->opx = x;
    return check(c, x, want);
}

static Type *builtin_value(Ctx *c, Node *n, Type *want);

static Type *check_builtin(Ctx *c, Node *n, Type *want) {
    Type *t = builtin_value(c, n, want);
    if (t && !is_err(t)) check_en_eno(c, n);
    return t;
}

/* A call of a library function: its inputs checked against the signature. */
static Type *library_function(Ctx *c, Node *n, const struct LibFn *lf, int typed, Type *want) {
    n->builtin = B_LIB;
    n->libfn = lf->cfn;
    if (!split_en_eno(n)) return err_type();
    bool formal = n->list.n && ((Node *)n->list.v[0])->name;
    if (formal) {
        Node **ord = xalloc(sizeof(Node *) * (size_t)lf->nargs);
        for (int i = 0; i < n->list.n; i++) {
            Node *a = n->list.v[i];
            if (!a->name || a->is_out) { error_at(a->loc, "cannot mix formal (name := value) and positional arguments"); return err_type(); }
            int pos = -1;
            for (int k = 0; k < lf->nargs; k++)
                if (!strcmp(lf->pnames[k], a->uname)) pos = k;
            if (pos < 0 || ord[pos]) { error_at(a->loc, "unknown parameter '%s' for '%s'", a->name, n->name); return err_type(); }
            ord[pos] = a;
        }
        for (int k = 0; k < lf->nargs; k++)
            if (!ord[k]) { error_at(n->loc, "missing parameter '%s' for '%s'", lf->pnames[k], n->name); return err_type(); }
        n->list.n = 0;
        for (int k = 0; k < lf->nargs; k++) vec_push(&n->list, ord[k]);
    } else {
        for (int i = 0; i < n->list.n; i++)
            if (((Node *)n->list.v[i])->name) { error_at(((Node *)n->list.v[i])->loc, "cannot mix formal (name := value) and positional arguments"); return err_type(); }
        if (n->list.n != lf->nargs) {
            error_at(n->loc, "'%s' expects %d arguments, got %d", n->name, lf->nargs, n->list.n);
            return err_type();
        }
    }
    bool bad = false;
    for (int k = 0; k < lf->nargs; k++) {
        Node *a = arg(n, k);
        int pt = lf->ptypes[k];
        if (pt == A_NUM && typed >= 0) {
            Type *tt = NULL;
            for (int j = 0; j <= T_STRING; j++) if (!strcmp(ty_prim[j]->name, numtypes[typed])) tt = ty_prim[j];
            check(c, a, tt);
            check_transfer(tt, a, "type mismatch: parameter '%s' of '%s' expects %4$s, got %3$s", lf->pnames[k], n->name);
            continue;
        }
        if (pt >= 0) {
            check(c, a, ty_prim[pt]);
            check_transfer(ty_prim[pt], a, "type mismatch: parameter '%s' of '%s' expects %4$s, got %3$s", lf->pnames[k], n->name);
            continue;
        }
        Type *at = check(c, a, NULL);
        if (is_err(at)) { bad = true; continue; }
        if (is_lit(at)) { if (pt == A_INT && at->kind != T_LITINT) goto mismatch; default_lit(a); at = a->ty; }
        if (pt == A_INT ? is_int(at) : is_num(at)) continue;
    mismatch:
        error_at(a->start, "type mismatch: parameter '%s' of '%s' expects %s, got %s", lf->pnames[k], n->name,
                 pt == A_INT ? "ANY_INT" : "ANY_NUM", type_name(a->ty));
        bad = true;
    }
    if (bad || error_count >= MAX_ERRORS) return err_type();
    if (lf->ret == A_INT) return want && !is_err(want) && !is_lit(want) && is_int(want) ? want : ty_prim[T_INT];
    return ty_prim[lf->ret];
}

static Type *builtin_value(Ctx *c, Node *n, Type *want) {
    int id = 0, nb = -1, typed;
    Type *from = NULL, *to = NULL;
    int ck = conv_kind(n->uname, &from, &to);
    if (ck == CONV_PLAIN) id = B_CONV;
    else if (ck == CONV_TO_BCD) id = B_TO_BCD;
    else if (ck == CONV_FROM_BCD) id = B_FROM_BCD;
    const struct LibFn *lf = id ? NULL : find_libfn(n->uname, &typed);
    if (lf) return library_function(c, n, lf, typed, want);
    if (!id)
        for (int i = 0; builtins[i].name; i++)
            if (!strcmp(builtins[i].name, n->uname)) { id = builtins[i].id; nb = i; }
    if (!id) return NULL;
    n->builtin = id;
    if (!split_en_eno(n) || !order_builtin_args(n, id, nb)) return err_type();
    int want_n = nb < 0 ? 1 : builtins[nb].nargs;
    if ((want_n > 0 && n->list.n != want_n) || (want_n < 0 && n->list.n < -want_n)) {
        if (want_n > 0)
            error_at(n->loc, "'%s' expects %d argument%s, got %d", n->name, want_n, want_n == 1 ? "" : "s", n->list.n);
        else
            error_at(n->loc, "'%s' expects at least %d arguments, got %d", n->name, -want_n, n->list.n);
        return err_type();
    }
    Type *t;
    switch (id) {
    case B_TO_BCD: case B_FROM_BCD: {
        Node *a = arg(n, 0);
        if (from) {
            check(c, a, from);
            check_transfer(from, a, "type mismatch: parameter '%s' of '%s' expects %4$s, got %3$s", "IN", n->name);
        } else {      /* BCD_TO_<U>: any bit string */
            Type *at = check(c, a, NULL);
            if (is_err(at)) return at;
            if (is_lit(at)) { coerce(a, ty_prim[T_LWORD], true); at = a->ty; }
            if (!is_nbit_kind(canon(at))) {
                error_at(a->start, "type mismatch: parameter 'IN' of '%s' expects ANY_BIT, got %s", n->name, type_name(at));
                return err_type();
            }
            from = at;
        }
        if (!to) {    /* <U>_TO_BCD: the bit string the context wants, else of U's width */
            Type *cw = want && !is_err(want) ? canon(want) : NULL;
            if (is_nbit_kind(cw)) to = want;
            else to = ty_prim[from->kind == T_USINT ? T_BYTE : from->kind == T_UINT ? T_WORD : from->kind == T_UDINT ? T_DWORD : T_LWORD];
        }
        n->conv_from = from;
        return to;
    }
    case B_CONV: {
        Node *a = arg(n, 0);
        check(c, a, from);
        check_transfer(from, a, "type mismatch: parameter '%s' of '%s' expects %4$s, got %3$s", "IN", n->name);
        n->conv_from = from;
        return to;
    }
    case B_TRUNC: {
        Node *a = arg(n, 0);
        t = check(c, a, NULL);
        if (is_err(t)) return t;
        if (is_lit(t)) default_lit(a);
        if (!is_real(a->ty)) { error_at(a->start, "type mismatch: parameter 'IN' of 'TRUNC' expects ANY_REAL, got %s", type_name(a->ty)); return err_type(); }
        n->conv_from = a->ty;
        return want && is_int(want) && !is_lit(want) ? want : ty_prim[T_DINT];
    }
    case B_ABS: case B_SQRT: case B_LN: case B_LOG: case B_EXP: case B_SIN: case B_COS: case B_TAN:
    case B_ASIN: case B_ACOS: case B_ATAN: case B_MOVE: {
        Node *a = arg(n, 0);
        t = check(c, a, want);
        if (is_err(t)) return t;
        if (is_lit(t)) { if (want && !is_err(want)) coerce(a, want, true); if (is_lit(a->ty)) default_lit(a); t = a->ty; }
        if (id == B_MOVE) return t;
        if (id == B_ABS ? !is_num(t) : !is_real(t)) {
            error_at(a->start, "type mismatch: parameter 'IN' of '%s' expects %s, got %s", n->name,
                     id == B_ABS ? "ANY_NUM" : "ANY_REAL", type_name(t));
            return err_type();
        }
        return t;
    }
    case B_EXPT: {
        Node *a = arg(n, 0), *b = arg(n, 1);
        t = check(c, a, want);
        Type *e = check(c, b, NULL);
        if (is_err(t) || is_err(e)) return err_type();
        if (is_lit(t)) { if (t->kind != T_LITREAL) goto expt_bad; coerce(a, want && is_real(want) ? want : ty_prim[T_LREAL], true); t = a->ty; }
        if (is_lit(e)) default_lit(b);
        if (!is_real(t) || !is_num(b->ty)) {
        expt_bad:
            error_at(n->loc, "type mismatch: 'EXPT' needs ANY_REAL ** ANY_NUM, got %s and %s", type_name(a->ty), type_name(b->ty));
            return err_type();
        }
        return t;
    }
    case B_SEL: {
        Node *g = arg(n, 0);
        check(c, g, ty_prim[T_BOOL]);
        check_transfer(ty_prim[T_BOOL], g, "type mismatch: parameter '%s' of '%s' expects %4$s, got %3$s", "G", "SEL");
        return generic_args(c, n, 1, want);
    }
    case B_MUX: {
        Node *k = arg(n, 0);
        Type *kt = check(c, k, NULL);
        if (is_lit(kt)) default_lit(k);
        if (!is_err(kt) && !is_int(k->ty)) { error_at(k->start, "type mismatch: parameter 'K' of 'MUX' expects ANY_INT, got %s", type_name(k->ty)); return err_type(); }
        t = generic_args(c, n, 1, want);
        if (!is_err(t) && !is_elementary(t)) { error_at(n->loc, "'MUX' supports elementary types only"); return err_type(); }
        return t;
    }
    case B_CONCAT:
        t = generic_args(c, n, 0, want);
        if (!is_err(t) && canon(t)->kind != T_STRING) {
            error_at(n->loc, "'CONCAT' joins strings, not %s", type_name(t));
            return err_type();
        }
        return t;
    case B_MAX: case B_MIN: case B_LIMIT:
        t = generic_args(c, n, 0, want);
        if (!is_err(t) && !is_num(t) && !is_bit(t) && !is_timeish(t)) {
            error_at(n->loc, "'%s' needs numbers, bit strings or times, not %s", n->name, type_name(t));
            return err_type();
        }
        return t;
    case B_SHL: case B_SHR: case B_ROL: case B_ROR: {
        Node *a = arg(n, 0), *s = arg(n, 1);
        t = check(c, a, want);
        Type *st = check(c, s, NULL);
        if (is_err(t) || is_err(st)) return err_type();
        if (is_lit(t)) { if (want && is_bit(want)) coerce(a, want, true); else coerce(a, ty_prim[T_DWORD], true); t = a->ty; }
        if (is_lit(st)) default_lit(s);
        if (!is_bit(t)) { error_at(a->start, "type mismatch: parameter 'IN' of '%s' expects ANY_BIT, got %s", n->name, type_name(t)); return err_type(); }
        if (!is_int(s->ty)) { error_at(s->start, "type mismatch: parameter 'N' of '%s' expects ANY_INT, got %s", n->name, type_name(s->ty)); return err_type(); }
        return t;
    }
    case B_OP: case B_DIV:
        t = operator_function(c, n, opfn_op(n->uname), want);
        if (id == B_DIV && !is_err(t) && !is_num(t)) {
            error_at(n->loc, "'DIV' needs numbers, not %s", type_name(t));
            return err_type();
        }
        return t;
    case B_LEN: {
        Node *a = arg(n, 0);
        t = check(c, a, ty_prim[T_STRING]);
        if (!is_err(t) && canon(t)->kind != T_STRING) { error_at(a->start, "type mismatch: parameter 'IN' of 'LEN' expects STRING, got %s", type_name(t)); return err_type(); }
        return ty_prim[T_INT];
    }
    }
    return err_type();
}

static Type *check(Ctx *c, Node *n, Type *want) {
    Type *t = err_type();
    switch (n->kind) {
    case N_INT:
        t = ty_prim[T_LITINT];
        n->ty = t;
        if (want && !is_err(want) && !is_lit(want)) {
            Type *cw = canon(want);
            if (is_int(cw) || is_bit(cw) || cw->kind == T_BOOL) {
                if (!lit_fits(n, want, true)) n->ty = err_type();
                return n->ty;
            }
        }
        return t;
    case N_REAL:
        n->ty = ty_prim[T_LITREAL];
        if (want && is_real(want) && !is_lit(want)) {
            if (!lit_fits(n, want, true)) n->ty = err_type();
            return n->ty;
        }
        return n->ty;
    case N_BOOL: t = ty_prim[T_BOOL]; break;
    case N_STRING: t = ty_prim[T_STRING]; break;
    case N_TIME: t = ty_prim[n->tkind == TIMEK_TIME ? T_TIME : n->tkind == TIMEK_DATE ? T_DATE : n->tkind == TIMEK_TOD ? T_TOD : T_DT]; break;
    case N_TYPED: t = check_typed(c, n, want); break;
    case N_IDENT: t = check_ident(c, n, want); break;
    case N_MEMBER: t = check_member(c, n); break;
    case N_INDEX: t = check_index(c, n); break;
    case N_CALL: t = check_call(c, n, want, false); break;
    case N_UNARY: t = check_unary(c, n, want); break;
    case N_BINARY: t = check_binary(c, n, want); break;
    case N_ARRINIT: case N_STRUCTINIT:
        error_at(n->start, "an initializer list is only allowed as an initial value");
        break;
    default:
        error_at(n->start, "expression expected");
        break;
    }
    n->ty = t;
    return t;
}

/* Check a value of a typed context (assignment, initial value). */
static void check_value(Ctx *c, Type *dst, Node *src) {
    check(c, src, dst);
    check_transfer(dst, src, NULL, NULL, NULL);
}

/* ---- initial values ---- */
static void check_init(Ctx *c, Type *t, Node *init);

/* matiec takes an integer literal as an element of a REAL or LREAL array
** initializer ([0, 4.228, 5.0], as OSCAT writes its tables), though
** nowhere else: the literal becomes a real one. */
static void int_lit_as_real(Type *elem, Node *n) {
    if (!n || !is_real(canon(elem))) return;
    if (n->kind == N_UNARY && n->op && !strcmp(n->op, "-")) n = n->lhs;
    if (n->kind != N_INT || n->ioverflow) return;
    n->kind = N_REAL;
    n->rval = n->neg ? -(double)n->ival : (double)n->ival;
}

static void check_array_init(Ctx *c, Type *t, Node *init) {
    int64_t count = 0;
    for (int i = 0; i < init->list.n; i++) {
        Node *it = init->list.v[i];
        int_lit_as_real(t->elem, it->kind == N_REPEAT ? it->lhs : it);
        if (it->kind == N_REPEAT) {
            if (it->lhs) check_init(c, t->elem, it->lhs);
            count += (int64_t)it->ival;
        } else {
            check_init(c, t->elem, it);
            count++;
        }
        if (count > t->count) {
            error_at(it->start, "too many initial values for %s (%lld elements)", t->name, (long long)t->count);
            return;
        }
    }
}

static void check_init(Ctx *c, Type *t, Node *init) {
    if (is_err(t) || !init) return;
    Type *ct = canon(t);
    if (init->kind == N_ARRINIT) {
        if (ct->kind != T_ARRAY) { error_at(init->start, "an array initializer for %s", t->name); return; }
        init->ty = t;
        check_array_init(c, ct, init);
        return;
    }
    if (init->kind == N_STRUCTINIT) {
        init->ty = t;
        if (ct->kind == T_STRUCT) {
            for (int i = 0; i < init->list.n; i++) {
                Node *a = init->list.v[i];
                Field *f = NULL;
                for (int k = 0; k < ct->fields.n; k++)
                    if (!strcmp(((Field *)ct->fields.v[k])->uname, a->uname)) f = ct->fields.v[k];
                if (!f) { error_at(a->loc, "no member '%s' in '%s'", a->name, t->name); continue; }
                check_init(c, f->type, a->lhs);
            }
            return;
        }
        if (ct->kind == T_FB) {     /* initial values of an instance's inputs */
            for (int i = 0; i < init->list.n; i++) {
                Node *a = init->list.v[i];
                Sym *m = find(&ct->pou->syms, a->uname);
                if (!m || (m->cls != V_INPUT && m->cls != V_OUTPUT && m->cls != V_LOCAL)) {
                    error_at(a->loc, "no member '%s' in '%s'", a->name, t->name);
                    continue;
                }
                a->sym = m;
                check_init(c, m->type, a->lhs);
            }
            return;
        }
        error_at(init->start, "a structure initializer for %s", t->name);
        return;
    }
    if (ct->kind == T_FB) { error_at(init->start, "a function block instance has no initial value"); return; }
    check_value(c, t, init);
    int64_t v;
    if (t->subrange && const_int(c, init, &v) && (v < t->lo || v > t->hi))
        error_at(init->start, "value %lld out of range for %s (%lld..%lld)", (long long)v, t->name,
                 (long long)t->lo, (long long)t->hi);
}

/* ---- statements ---- */
static void check_stmts(Ctx *c, Vec *body);

static void check_cond(Ctx *c, Node *e, const char *what) {
    Type *t = check(c, e, ty_prim[T_BOOL]);
    (void)what;
    if (is_err(t)) return;
    if (canon(t)->kind != T_BOOL) error_at(e->start, "condition must be BOOL, not %s", type_name(t));
}

static void check_stmt(Ctx *c, Node *s) {
    switch (s->kind) {
    case S_ASSIGN: {
        Type *lt = check(c, s->lhs, NULL);
        if (!is_err(lt)) check_writable(c, s->lhs);
        if (!is_err(lt) && canon(lt)->kind == T_FB) {
            error_at(s->lhs->start, "cannot assign to function block instance '%s'", s->lhs->name ? s->lhs->name : "");
            return;
        }
        Type *rt = check(c, s->rhs, is_err(lt) ? NULL : lt);
        if (is_err(lt) || is_err(rt)) return;
        check_transfer(lt, s->rhs, NULL, NULL, NULL);
        int64_t v;
        Type *d = lt;
        while (d->alias) d = d->alias;
        if (d->subrange && const_int(c, s->rhs, &v) && (v < d->lo || v > d->hi))
            error_at(s->rhs->start, "value %lld out of range for %s (%lld..%lld)", (long long)v, lt->name,
                     (long long)d->lo, (long long)d->hi);
        return;
    }
    case S_CALL: {
        Node *call = s->lhs;
        Type *t = check_call(c, call, NULL, true);
        call->ty = t;
        if (!is_err(t) && call->builtin) { /* builtin function as a statement: value dropped */ }
        return;
    }
    case S_IF:
        for (int i = 0; i < s->list.n; i++) {
            check_cond(c, s->list.v[i], "IF");
            check_stmts(c, s->list2.v[i]);
        }
        if (s->els) check_stmts(c, &s->els->list);
        return;
    case S_CASE: {
        Type *t = check(c, s->lhs, NULL);
        if (!is_err(t) && is_lit(t)) default_lit(s->lhs), t = s->lhs->ty;
        bool ok = !is_err(t) && (is_int(t) || canon(t)->kind == T_ENUM);
        if (!is_err(t) && !ok) error_at(s->lhs->start, "CASE selector must be an integer or enumeration, not %s", type_name(t));
        Vec seen = {0};
        for (int i = 0; i < s->list2.n; i++) {
            Node *item = s->list2.v[i];
            for (int k = 0; k < item->list.n; k++) {
                Node *l = item->list.v[k];
                Node *parts[2] = {l->kind == N_RANGE ? l->lhs : l, l->kind == N_RANGE ? l->rhs : NULL};
                int64_t vals[2] = {0, 0};
                for (int j = 0; j < 2 && parts[j]; j++) {
                    Type *lt = check(c, parts[j], ok ? t : NULL);
                    if (!ok || is_err(lt)) continue;
                    check_transfer(t, parts[j], "type mismatch: CASE label%.0s%.0s is %s, selector %s", "", "");
                    if (!const_int(c, parts[j], &vals[j]) && !(parts[j]->sym && parts[j]->sym->kind == SK_ENUMVAL))
                        error_at(parts[j]->start, "CASE label must be a constant");
                    if (parts[j]->sym && parts[j]->sym->kind == SK_ENUMVAL) vals[j] = parts[j]->sym->enum_index;
                }
                if (!parts[1]) vals[1] = vals[0];
                if (ok && vals[1] < vals[0]) error_at(l->start, "empty CASE range");
                for (int j = 0; ok && j < seen.n; j += 2) {
                    int64_t lo = (int64_t)(intptr_t)seen.v[j], hi = (int64_t)(intptr_t)seen.v[j + 1];
                    if (vals[0] <= hi && lo <= vals[1]) { error_at(l->start, "duplicate CASE label"); break; }
                }
                vec_push(&seen, (void *)(intptr_t)vals[0]);
                vec_push(&seen, (void *)(intptr_t)vals[1]);
            }
            check_stmts(c, &item->list2);
        }
        if (s->els) check_stmts(c, &s->els->list);
        return;
    }
    case S_FOR: {
        Type *vt = check(c, s->lhs, NULL);
        Sym *v = s->lhs->sym;
        if (!is_err(vt)) {
            if (!is_int(vt)) error_at(s->lhs->start, "FOR control variable must be an integer, not %s", type_name(vt));
            else check_writable(c, s->lhs);
        }
        Type *it = is_err(vt) || !is_int(vt) ? NULL : vt;
        check_value(c, it ? it : ty_prim[T_DINT], s->rhs);
        check_value(c, it ? it : ty_prim[T_DINT], s->third);
        if (s->fourth) {
            check_value(c, it ? it : ty_prim[T_DINT], s->fourth);
            int64_t st;
            if (const_int(c, s->fourth, &st) && st == 0) error_at(s->fourth->start, "FOR step BY 0 never ends");
        }
        bool was = v && v->kind == SK_VAR ? v->loop_locked : false;
        if (v && v->kind == SK_VAR) v->loop_locked = true;
        c->loops++;
        check_stmts(c, &s->list);
        c->loops--;
        if (v && v->kind == SK_VAR) v->loop_locked = was;
        return;
    }
    case S_WHILE:
        check_cond(c, s->lhs, "WHILE");
        c->loops++;
        check_stmts(c, &s->list);
        c->loops--;
        return;
    case S_REPEAT:
        c->loops++;
        check_stmts(c, &s->list);
        c->loops--;
        check_cond(c, s->lhs, "UNTIL");
        return;
    case S_EXIT:
        if (!c->loops) error_at(s->loc, "EXIT outside a loop");
        return;
    case S_RETURN:
        if (c->pou) c->pou->uses_return = true;
        return;
    default:
        return;
    }
}

static void check_stmts(Ctx *c, Vec *body) {
    for (int i = 0; i < body->n; i++) check_stmt(c, body->v[i]);
}

/* ---- declarations ---- */
static bool location_fits(Ctx *c, VarDecl *d, Type *t) {
    (void)c;
    char size = d->location[2];
    if (size >= '0' && size <= '9') size = 'X';
    int bits = type_bits(t);
    Type *ct = canon(t);
    if (!is_elementary(ct) || ct->kind == T_STRING || is_timeish(ct)) {
        error_at(d->locloc, "located variable '%s' must be of an elementary type of the location's size", d->name);
        return false;
    }
    int need = size == 'X' ? 1 : size == 'B' ? 8 : size == 'W' ? 16 : size == 'D' ? 32 : 64;
    if (bits != need) {
        error_at(d->locloc, "located variable '%s': %s does not fit %s (%d bit%s)", d->name, t->name, d->location,
                 need, need == 1 ? "" : "s");
        return false;
    }
    return true;
}

static Sym *declare_var(Ctx *c, Vec *scope, VarDecl *d, Pou *p) {
    Sym *old = find(scope, d->uname);
    if (old) { error_at(d->loc, "duplicate declaration of '%s'", d->name); return NULL; }
    if (p && !strcmp(d->uname, p->uname) && p->kind == POU_FUNCTION) {
        error_at(d->loc, "duplicate declaration of '%s': it is the function's own name", d->name);
        return NULL;
    }
    Sym *s = new_sym(SK_VAR, d->name, d->uname, d->loc);
    s->decl = d;
    s->cls = d->cls;
    s->constant = d->constant;
    s->retain = d->retain;
    s->type = resolve(c, d->spec, NULL);
    s->pou = p;
    s->in_function = p && p->kind == POU_FUNCTION;
    if (d->location) {
        if (p && p->kind != POU_PROGRAM) {
            error_at(d->loc, "located variable '%s' not allowed in a %s", d->name,
                     p->kind == POU_FB ? "function block" : "function");
        } else if (location_fits(c, d, s->type)) {
            s->pointer = true;
        }
    }
    if (d->cls == V_IN_OUT || d->cls == V_EXTERNAL) s->pointer = true;
    if (d->constant && d->cls != V_EXTERNAL && !d->init && d->cls != V_GLOBAL)
        /* matiec accepts it (OpenPLC examples have such constants) */
        warning_at(d->loc, "constant '%s' has no initial value: it is its type's initial value", d->name);
    if (d->cls == V_IN_OUT && p && p->kind == POU_FUNCTION) { /* passed by address */ }
    if (canon(s->type)->kind == T_FB && p && p->kind == POU_FUNCTION && d->cls != V_IN_OUT)
        error_at(d->loc, "a function cannot hold a function block instance");
    if (canon(s->type)->kind == T_FB && (d->cls == V_INPUT || d->cls == V_OUTPUT))
        error_at(d->loc, "function block instances as inputs or outputs are not supported");
    if (is_en_eno(d->uname)) {   /* declared out loud, as matiec allows: the same flag */
        bool en = !strcmp(d->uname, "EN");
        if (!p || p->kind == POU_PROGRAM || d->cls != (en ? V_INPUT : V_OUTPUT) || canon(s->type)->kind != T_BOOL) {
            error_at(d->loc, "'%s' is the %s of every function and function block: declare it only there, as %s %s : BOOL",
                     d->name, en ? "enable input" : "enable output", en ? "VAR_INPUT" : "VAR_OUTPUT", d->uname);
            return NULL;
        }
        if (en) p->en = s;
        else p->eno = s;
    }
    vec_push(scope, s);
    return s;
}

static void declare_pou_vars(Ctx *c, Pou *p) {
    c->pou = p;
    c->scope = &p->syms;
    if (p->kind == POU_FUNCTION) {
        p->rettype = resolve(c, p->ret, NULL);
        if (canon(p->rettype)->kind == T_FB) error_at(p->ret->loc, "a function cannot return a function block");
        Sym *r = new_sym(SK_VAR, p->name, p->uname, p->loc);
        r->type = p->rettype;
        r->cls = V_LOCAL;
        r->in_function = true;
        r->is_result = true;
        r->pou = p;
        vec_push(&p->syms, r);
    }
    for (int i = 0; i < p->vars.n; i++) {
        VarDecl *d = p->vars.v[i];
        if (d->cls == V_EXTERNAL && p->kind == POU_FUNCTION)
            error_at(d->loc, "VAR_EXTERNAL is not allowed in a function");
        if (d->cls == V_TEMP && p->kind == POU_FUNCTION) d->cls = V_LOCAL;
        declare_var(c, &p->syms, d, p);
    }
    c->pou = NULL;
    c->scope = NULL;
}

static void check_pou_inits(Ctx *c, Pou *p) {
    c->pou = p;
    c->scope = &p->syms;
    for (int i = 0; i < p->syms.n; i++) {
        Sym *s = p->syms.v[i];
        if (s->decl && s->decl->init) {
            if (s->cls == V_IN_OUT || s->cls == V_EXTERNAL) { error_at(s->decl->init->start, "'%s' cannot have an initial value", s->name); continue; }
            check_init(c, s->type, s->decl->init);
        }
    }
    c->pou = NULL;
}

/* A function block must not contain itself. */
static bool fb_contains(Pou *outer, Pou *target, int depth) {
    if (depth > 64) return true;
    for (int i = 0; i < outer->syms.n; i++) {
        Sym *s = outer->syms.v[i];
        if (s->pointer) continue;
        Type *t = canon(s->type);
        while (t && t->kind == T_ARRAY) t = canon(t->elem);
        if (t && t->kind == T_FB && (t->pou == target || fb_contains(t->pou, target, depth + 1))) return true;
    }
    return false;
}

static void check_config(Ctx *c, Config *cf) {
    c->pou = NULL;
    c->scope = &cf->gsyms;
    for (int i = 0; i < cf->globals.n; i++) {
        Sym *s = declare_var(c, &cf->gsyms, cf->globals.v[i], NULL);
        if (s) { s->is_global = true; s->gcname = fmt("%s__%s", cf->uname, s->uname); }
    }
    for (int i = 0; i < cf->gsyms.n; i++) {
        Sym *s = cf->gsyms.v[i];
        if (s->decl->init) check_init(c, s->type, s->decl->init);
    }
    for (int r = 0; r < cf->resources.n; r++) {
        Resource *res = cf->resources.v[r];
        c->scope = &res->gsyms;
        c->gscope[1] = &cf->gsyms;
        for (int i = 0; i < res->globals.n; i++) {
            VarDecl *d = res->globals.v[i];
            if (find(&cf->gsyms, d->uname)) { error_at(d->loc, "duplicate declaration of '%s'", d->name); continue; }
            Sym *s = declare_var(c, &res->gsyms, d, NULL);
            if (s) { s->is_global = true; s->gcname = fmt("%s__%s", res->uname, s->uname); }
        }
        for (int i = 0; i < res->gsyms.n; i++) {
            Sym *s = res->gsyms.v[i];
            if (s->decl->init) check_init(c, s->type, s->decl->init);
        }
        c->gscope[1] = NULL;
        for (int i = 0; i < res->tasks.n; i++) {
            Task *t = res->tasks.v[i];
            for (int j = 0; j < i; j++)
                if (!strcmp(((Task *)res->tasks.v[j])->uname, t->uname)) error_at(t->loc, "duplicate declaration of '%s'", t->name);
            if (t->single) {   /* runs on the rising edge of a global BOOL (matiec: an R_TRIG per task) */
                c->gscope[1] = &cf->gsyms;
                Type *st = t->single->kind == N_IDENT ? check(c, t->single, ty_prim[T_BOOL]) : NULL;
                c->gscope[1] = NULL;
                if (t->single->kind != N_IDENT || (!is_err(st) && (!t->single->sym || !t->single->sym->is_global)))
                    error_at(t->single->start, "task SINGLE must name a global BOOL variable");
                else if (!is_err(st) && canon(st)->kind != T_BOOL)
                    error_at(t->single->start, "task SINGLE must be BOOL, not %s", type_name(st));
                t->interval_ns = 0;   /* SINGLE wins over INTERVAL, as in matiec */
                continue;
            }
            if (!t->interval) { error_at(t->loc, "task '%s' needs an INTERVAL", t->name); continue; }
            Type *it = check(c, t->interval, ty_prim[T_TIME]);
            if (is_err(it)) continue;
            if (t->interval->kind != N_TIME || t->interval->tkind != TIMEK_TIME) {
                error_at(t->interval->start, "task INTERVAL must be a TIME literal");
                continue;
            }
            t->interval_ns = t->interval->tval;
            if (t->interval_ns <= 0) error_at(t->interval->start, "task INTERVAL must be positive");
            if (t->priority) {
                check(c, t->priority, ty_prim[T_UINT]);
                if (!is_err(t->priority->ty) && !is_int(t->priority->ty)) error_at(t->priority->start, "task PRIORITY must be an integer");
            }
        }
        for (int i = 0; i < res->progs.n; i++) {
            ProgInst *pi = res->progs.v[i];
            for (int j = 0; j < i; j++)
                if (!strcmp(((ProgInst *)res->progs.v[j])->uname, pi->uname)) error_at(pi->loc, "duplicate declaration of '%s'", pi->name);
            if (find(&res->gsyms, pi->uname) || find(&cf->gsyms, pi->uname))
                error_at(pi->loc, "duplicate declaration of '%s'", pi->name);
            if (pi->task) {
                for (int j = 0; j < res->tasks.n; j++)
                    if (!strcmp(((Task *)res->tasks.v[j])->uname, pi->task)) pi->t = res->tasks.v[j];
                if (!pi->t) {
                    Near nr = {pi->task, NULL, 0};
                    for (int j = 0; j < res->tasks.n; j++) near_name(&nr, ((Task *)res->tasks.v[j])->name);
                    error_at(pi->taskloc, "undeclared task '%s'%s", pi->task, near_hint(&nr));
                }
            }
            Sym *ps = find(&c->pous, pi->pou);
            if (!ps || ps->pou->kind != POU_PROGRAM) {
                Near nr = {pi->pou, NULL, 0};
                for (int j = 0; !ps && j < c->pous.n; j++)
                    if (((Sym *)c->pous.v[j])->pou->kind == POU_PROGRAM) near_name(&nr, ((Sym *)c->pous.v[j])->name);
                error_at(pi->pouloc, ps ? "'%s' is not a PROGRAM%s" : "unknown program '%s'%s", pi->pou, near_hint(&nr));
                continue;
            }
            pi->p = ps->pou;
            pi->p->used = true;
            /* resolve its VAR_EXTERNALs against the globals */
            for (int k = 0; k < pi->p->syms.n; k++) {
                Sym *e = pi->p->syms.v[k];
                if (e->cls != V_EXTERNAL) continue;
                Sym *g = find(&res->gsyms, e->uname);
                if (!g) g = find(&cf->gsyms, e->uname);
                if (!g) error_at(pi->loc, "program '%s' needs global '%s' (VAR_EXTERNAL), which is not declared", pi->p->name, e->name);
                else if (!same_type(g->type, e->type))
                    error_at(g->loc, "global '%s' is %s but program '%s' declares it %s", g->name, type_name(g->type), pi->p->name, type_name(e->type));
                else if (g->constant && !e->constant)
                    error_at(e->loc, "VAR_EXTERNAL '%s' must be CONSTANT: the global is", e->name);
            }
        }
    }
    c->scope = NULL;
}

static bool calls_reach(Pou *from, Pou *target, int depth) {
    if (depth > 64) return false;
    for (int i = 0; i < from->calls.n; i++) {
        Pou *q = from->calls.v[i];
        if (q == target || calls_reach(q, target, depth + 1)) return true;
    }
    return false;
}

/* Standard FBs are only compiled when used; mark what used ones use. */
static void mark_used(Ctx *c, Pou *p) {
    for (int i = 0; i < p->syms.n; i++) {
        Type *t = canon(((Sym *)p->syms.v[i])->type);
        while (t && t->kind == T_ARRAY) t = canon(t->elem);
        if (t && t->kind == T_FB && !t->pou->used) { t->pou->used = true; mark_used(c, t->pou); }
    }
}

/* " (first declared in FILE:LINE)" when an earlier declaration of a name is
** in another input file the user wrote, " (first declared at line N)" in the
** same file, else "". */
static const char *declared_elsewhere(const Sym *old, Loc here) {
    if (!old || !old->loc.src || old->loc.src->name[0] == '<') return "";
    if (old->loc.src == here.src) return fmt(" (first declared at line %d)", old->loc.line);
    return fmt(" (first declared in %s:%d)", old->loc.src->name, old->loc.line);
}

void sema(Unit *u) {
    for (size_t i = 0; i < sizeof prims / sizeof prims[0]; i++)
        ty_prim[prims[i].k] = new_type(prims[i].k, prims[i].name, prims[i].cname);
    Ctx c = {u, {0}, {0}, {0}, {0}, NULL, NULL, {NULL, NULL}, 0, {0}};
    /* names: types and POUs share one namespace */
    for (int i = 0; i < u->types.n; i++) {
        TypeDecl *d = u->types.v[i];
        if (prim_named(d->uname, strlen(d->uname)) || find(&c.types, d->uname)) {
            error_at(d->loc, "duplicate declaration of '%s'%s", d->name, declared_elsewhere(find(&c.types, d->uname), d->loc));
            continue;
        }
        Sym *s = new_sym(SK_TYPE, d->name, d->uname, d->loc);
        s->decl = (VarDecl *)d;
        vec_push(&c.types, s);
    }
    for (int i = 0; i < u->pous.n; i++) {
        Pou *p = u->pous.v[i];
        if (find(&c.pous, p->uname) || find(&c.types, p->uname) || prim_named(p->uname, strlen(p->uname))) {
            Sym *old = find(&c.pous, p->uname);
            error_at(p->loc, "duplicate declaration of '%s'%s", p->name, declared_elsewhere(old ? old : find(&c.types, p->uname), p->loc));
            continue;
        }
        Type *cf, *cto;
        int typed;
        bool standard = conv_kind(p->uname, &cf, &cto) != CONV_NONE || find_libfn(p->uname, &typed);
        for (int k = 0; !standard && builtins[k].name; k++) standard = !strcmp(builtins[k].name, p->uname);
        if (standard && p->kind == POU_FUNCTION) {
            /* A program's own SEL, MAX or MIN (OpenPLC examples carry
            ** them): matiec accepts the declaration and calls keep going
            ** to its standard function. So here: the declaration is
            ** dropped, with a warning. */
            warning_at(p->loc, "'%s' is a standard function: calls use the standard one and this declaration is ignored, as in matiec",
                       p->name);
            vec_remove(&u->pous, i--);
            continue;
        }
        if (standard) {
            error_at(p->loc, "duplicate declaration of '%s': it is a standard function", p->name);
            continue;
        }
        {
            Sym *s = new_sym(SK_POU, p->name, p->uname, p->loc);
            s->pou = p;
            vec_push(&c.pous, s);
            if (p->kind != POU_FUNCTION) {
                p->type = new_type(T_FB, p->uname, p->uname);
                p->type->pou = p;
            }
            if (!p->from_lib) p->used = true;
        }
    }
    for (int i = 0; i < c.types.n; i++) {
        Sym *s = c.types.v[i];
        named_type(&c, s->uname, s->loc, s->name);
        TypeDecl *d = (TypeDecl *)s->decl;
        if (d->init && s->type) check_init(&c, s->type, d->init);
    }
    for (int i = 0; i < c.pous.n; i++) declare_pou_vars(&c, ((Sym *)c.pous.v[i])->pou);
    for (int i = 0; i < c.pous.n; i++) {
        Pou *p = ((Sym *)c.pous.v[i])->pou;
        if (p->kind == POU_FB && fb_contains(p, p, 0))
            error_at(p->loc, "function block '%s' contains an instance of itself", p->name);
    }
    for (int i = 0; i < c.pous.n; i++) {
        Pou *p = ((Sym *)c.pous.v[i])->pou;
        check_pou_inits(&c, p);
        c.pou = p;
        c.scope = &p->syms;
        check_stmts(&c, &p->body);
        c.pou = NULL;
        c.scope = NULL;
    }
    for (int i = 0; i < c.pous.n; i++) {
        Pou *p = ((Sym *)c.pous.v[i])->pou;
        if (p->kind == POU_FUNCTION && calls_reach(p, p, 0))
            error_at(p->loc, "function '%s' calls itself (directly or through others): IEC 61131-3 forbids recursion", p->name);
    }
    for (int i = 0; i < u->configs.n; i++) check_config(&c, u->configs.v[i]);
    for (int i = 0; i < c.pous.n; i++) {
        Pou *p = ((Sym *)c.pous.v[i])->pou;
        if (p->used) mark_used(&c, p);
    }
}
