/* Code generator: the checked tree to C, in matiec's file layout (POUS.h,
** POUS.c, <Config>.c/.h, <Resource>.c, LOCATED_VARIABLES.h, VARIABLES.csv).
** Variables are plain struct fields (no accessor indirection); integer
** arithmetic wraps on the declared width without C undefined behaviour;
** integer division by zero yields 0; array indexes are kept in bounds. */
#include "stc.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    Unit *u;
    Buf h, c;          /* POUS.h, POUS.c */
    Pou *pou;          /* POU being emitted */
    int tmp;           /* counter for unique C temporaries */
    Vec located;       /* VarDecl* of located variables, for LOCATED_VARIABLES.h */
    Vec externs;       /* names of globals used through VAR_EXTERNAL (char*) */
} G;

static void expr(G *g, Buf *b, Node *n);
static void stmts(G *g, Buf *b, Vec *body, int ind);

static void indent(Buf *b, int n) { for (int i = 0; i < n; i++) buf_put(b, "  "); }

static Type *ct(Type *t) { return canon(t); }

/* C name of a type */
static const char *cty(Type *t) {
    if (t->alias) return t->cname;
    return t->cname;
}

/* ---- types ---- */
static void emit_type(G *g, Type *t);

static void emit_fb_struct(G *g, Type *t) {
    Pou *p = t->pou;
    for (int i = 0; i < p->syms.n; i++) {
        Sym *s = p->syms.v[i];
        if (!s->pointer) emit_type(g, s->type);
        else if (ct(s->type)->kind != T_FB) emit_type(g, s->type);
    }
    buf_printf(&g->h, "/* %s %s */\ntypedef struct %s {\n", p->kind == POU_FB ? "FUNCTION_BLOCK" : "PROGRAM", p->name, t->cname);
    int n = 0;
    for (int i = 0; i < p->syms.n; i++) {
        Sym *s = p->syms.v[i];
        if (s->cls == V_TEMP) continue;
        if (s->pointer && ct(s->type)->kind == T_FB) buf_printf(&g->h, "  struct %s *%s;\n", cty(s->type), s->uname);
        else buf_printf(&g->h, "  %s %s%s;\n", cty(s->type), s->pointer ? "*" : "", s->uname);
        n++;
    }
    if (!n) buf_put(&g->h, "  char __empty;\n");
    buf_printf(&g->h, "} %s;\n", t->cname);
    buf_printf(&g->h, "void %s_init__(%s *data__, BOOL retain);\nvoid %s_body__(%s *data__);\n\n", t->cname, t->cname,
               t->cname, t->cname);
}

static void emit_type(G *g, Type *t) {
    if (t->emitted) return;
    if (t->kind <= T_STRING && !t->alias && !t->subrange) return;
    if (t->subrange && !strcmp(t->cname, t->base->cname)) return;
    t->emitted = true;
    if (t->alias) {
        emit_type(g, t->alias);
        if (ct(t)->kind == T_FB) return;
        buf_printf(&g->h, "typedef %s %s;\n", cty(t->alias), t->cname);
        return;
    }
    if (t->subrange) { buf_printf(&g->h, "typedef %s %s;\n", t->base->cname, t->cname); return; }
    switch (t->kind) {
    case T_ENUM:
        buf_printf(&g->h, "typedef enum {\n");
        for (int i = 0; i < t->fields.n; i++)
            buf_printf(&g->h, "  %s__%s%s\n", t->cname, (char *)t->fields.v[i], i + 1 < t->fields.n ? "," : "");
        buf_printf(&g->h, "} %s;\n", t->cname);
        break;
    case T_STRUCT:
        for (int i = 0; i < t->fields.n; i++) emit_type(g, ((Field *)t->fields.v[i])->type);
        buf_printf(&g->h, "typedef struct {\n");
        for (int i = 0; i < t->fields.n; i++) {
            Field *f = t->fields.v[i];
            buf_printf(&g->h, "  %s %s;\n", cty(f->type), f->uname);
        }
        buf_printf(&g->h, "} %s;\n", t->cname);
        break;
    case T_ARRAY:
        emit_type(g, t->elem);
        buf_printf(&g->h, "typedef struct { %s table[%lld]; } %s;\n", cty(t->elem), (long long)t->count, t->cname);
        break;
    case T_FB:
        emit_fb_struct(g, t);
        break;
    default:
        break;
    }
}

/* ---- literals ---- */
static void int_lit(Buf *b, Type *t, uint64_t v, bool neg) {
    const char *c = cty(t);
    if (ct(t)->kind == T_BOOL) { buf_put(b, v ? "1" : "0"); return; }
    if (ct(t)->kind == T_ENUM) { buf_printf(b, "((%s)%llu)", c, (unsigned long long)v); return; }
    if (neg) {
        if (v == (uint64_t)INT64_MAX + 1) buf_printf(b, "((%s)(-9223372036854775807LL - 1))", c);
        else buf_printf(b, "((%s)-%lluLL)", c, (unsigned long long)v);
    } else if (v > (uint64_t)INT64_MAX) {
        buf_printf(b, "((%s)%lluULL)", c, (unsigned long long)v);
    } else if (v > INT32_MAX) {
        buf_printf(b, "((%s)%lluLL)", c, (unsigned long long)v);
    } else {
        buf_printf(b, "((%s)%llu)", c, (unsigned long long)v);
    }
}

static void real_lit(Buf *b, Type *t, double v) {
    char s[64];
    snprintf(s, sizeof s, "%.17g", v);
    if (!strpbrk(s, ".eEni")) strcat(s, ".0");
    buf_printf(b, "((%s)%s)", cty(t), s);
}

static void time_lit(Buf *b, Type *t, int64_t ns) {
    int64_t sec = ns / 1000000000, nsec = ns % 1000000000;
    if (nsec < 0) { nsec += 1000000000; sec--; }
    buf_printf(b, "((%s){%lldL, %lldL})", cty(t), (long long)sec, (long long)nsec);
}

static void string_lit(Buf *b, const char *s, int len) {
    buf_printf(b, "((STRING){%d, \"", len);
    for (int i = 0; i < len; i++) {
        unsigned char ch = (unsigned char)s[i];
        if (ch == '"' || ch == '\\') buf_printf(b, "\\%c", ch);
        else if (ch >= 0x20 && ch < 0x7f && ch != '?') buf_printf(b, "%c", ch);
        else buf_printf(b, "\\%03o", ch);
    }
    buf_put(b, "\"})");
}

/* ---- variables ---- */
static void var_ref(G *g, Buf *b, Sym *s) {
    (void)g;
    if (s->kind == SK_ENUMVAL) { buf_printf(b, "%s__%s", s->type->cname, s->uname); return; }
    if (s->is_global) {
        if (s->pointer) buf_printf(b, "(*%s)", s->gcname);
        else buf_put(b, s->gcname);
        return;
    }
    if (s->in_function) {
        if (s->is_result) buf_put(b, "__res");
        else if (s->cls == V_OUTPUT || s->cls == V_IN_OUT) buf_printf(b, "(*%s)", s->uname);
        else buf_put(b, s->uname);
        return;
    }
    if (s->cls == V_TEMP) { buf_put(b, s->uname); return; }
    if (s->pointer) buf_printf(b, "(*data__->%s)", s->uname);
    else buf_printf(b, "data__->%s", s->uname);
}

/* ---- expressions ---- */
static const char *wide_u(Type *t) { return type_bits(t) == 64 ? "ULINT" : "UDINT"; }

static void index_expr(G *g, Buf *b, Node *n) {
    Type *at = ct(n->lhs->ty);
    expr(g, b, n->lhs);
    buf_put(b, ".table[");
    int64_t stride = 1;
    int64_t strides[8];
    for (int k = at->ndims - 1; k >= 0; k--) {
        strides[k] = stride;
        stride *= at->dims[k].hi - at->dims[k].lo + 1;
    }
    for (int k = 0; k < at->ndims; k++) {
        Node *x = n->list.v[k];
        int64_t size = at->dims[k].hi - at->dims[k].lo + 1;
        if (k) buf_put(b, " + ");
        if (x->is_const) {
            buf_printf(b, "%lld", (long long)((x->cval - at->dims[k].lo) * strides[k]));
            continue;
        }
        buf_put(b, "__IDX((LINT)(");
        expr(g, b, x);
        buf_printf(b, ") - (%lldLL), %lldLL)", (long long)at->dims[k].lo, (long long)size);
        if (strides[k] != 1) buf_printf(b, " * %lld", (long long)strides[k]);
    }
    buf_put(b, "]");
}

/* An operand of a comparison. gcc's -Wsign-compare takes a computed
** narrow unsigned value for a promoted bitwise complement (BYTE#255 - B
** folds to ~B) and warns on a comparison with it, as in OSCAT's BAND_B:
** such an operand goes through a compound literal, which gcc does not see
** through. */
static void cmp_operand(G *g, Buf *b, Node *n, const char *cop) {
    Type *t = ct(n->ty);
    bool narrow = t && (t->kind == T_BYTE || t->kind == T_USINT || t->kind == T_WORD || t->kind == T_UINT);
    bool cmp = !strcmp(cop, "==") || !strcmp(cop, "!=") || !strcmp(cop, "<") || !strcmp(cop, ">") ||
               !strcmp(cop, "<=") || !strcmp(cop, ">=");
    if (!narrow || !cmp || n->kind == N_IDENT || n->kind == N_INT || n->kind == N_TYPED) {
        expr(g, b, n);
        return;
    }
    buf_printf(b, "((%s){", cty(n->ty));
    expr(g, b, n);
    buf_put(b, "})");
}

static void binary(G *g, Buf *b, Node *n) {
    Type *lt = ct(n->lhs->ty), *rt = ct(n->rhs->ty), *t = ct(n->ty);
    const char *op = n->op;
    bool time_l = lt->kind >= T_TIME && lt->kind <= T_DT, time_r = rt->kind >= T_TIME && rt->kind <= T_DT;
    if (!strcmp(op, "**")) {
        buf_printf(b, "__EXPT_%s(", cty(lt));
        expr(g, b, n->lhs);
        buf_put(b, ", (LREAL)(");
        expr(g, b, n->rhs);
        buf_put(b, "))");
        return;
    }
    if (time_l || time_r) {
        const char *f = NULL;
        if (!strcmp(op, "+")) f = "__time_add";
        else if (!strcmp(op, "-")) f = "__time_sub";
        if (f) {
            buf_printf(b, "%s(", f);
            expr(g, b, n->lhs);
            buf_put(b, ", ");
            expr(g, b, n->rhs);
            buf_put(b, ")");
            return;
        }
        if (!strcmp(op, "*") || !strcmp(op, "/")) {
            Node *tn = time_l ? n->lhs : n->rhs, *k = time_l ? n->rhs : n->lhs;
            buf_printf(b, "__time_%s_%s(", *op == '*' ? "mul" : "div", is_real(k->ty) ? "real" : "int");
            expr(g, b, tn);
            buf_printf(b, ", (%s)(", is_real(k->ty) ? "LREAL" : "LINT");
            expr(g, b, k);
            buf_put(b, "))");
            return;
        }
        /* comparison */
        buf_put(b, "(__time_cmp(");
        expr(g, b, n->lhs);
        buf_put(b, ", ");
        expr(g, b, n->rhs);
        buf_printf(b, ") %s 0)", !strcmp(op, "=") ? "==" : !strcmp(op, "<>") ? "!=" : op);
        return;
    }
    if (lt->kind == T_STRING) {
        buf_put(b, "(__str_cmp(");
        expr(g, b, n->lhs);
        buf_put(b, ", ");
        expr(g, b, n->rhs);
        buf_printf(b, ") %s 0)", !strcmp(op, "=") ? "==" : !strcmp(op, "<>") ? "!=" : op);
        return;
    }
    const char *cop = op;
    if (!strcmp(op, "=")) cop = "==";
    else if (!strcmp(op, "<>")) cop = "!=";
    if (!strcmp(op, "AND") || !strcmp(op, "OR") || !strcmp(op, "XOR")) {
        bool boolean = t->kind == T_BOOL;
        cop = !strcmp(op, "AND") ? (boolean ? "&&" : "&") : !strcmp(op, "OR") ? (boolean ? "||" : "|") : "^";
        if (boolean) {
            buf_put(b, "(");
            expr(g, b, n->lhs);
            buf_printf(b, " %s ", cop);
            expr(g, b, n->rhs);
            buf_put(b, ")");
        } else {
            buf_printf(b, "((%s)(", cty(n->ty));
            expr(g, b, n->lhs);
            buf_printf(b, " %s ", cop);
            expr(g, b, n->rhs);
            buf_put(b, "))");
        }
        return;
    }
    if (is_int(t) && (!strcmp(op, "/") || !strcmp(op, "MOD"))) {
        buf_printf(b, "__%s_%s(", *op == '/' ? "DIV" : "MOD", t->cname);
        expr(g, b, n->lhs);
        buf_put(b, ", ");
        expr(g, b, n->rhs);
        buf_put(b, ")");
        return;
    }
    if (is_int(t) && (!strcmp(op, "+") || !strcmp(op, "-") || !strcmp(op, "*"))) {
        const char *w = wide_u(t);
        buf_printf(b, "((%s)((%s)(", cty(n->ty), w);
        expr(g, b, n->lhs);
        buf_printf(b, ") %s (%s)(", op, w);
        expr(g, b, n->rhs);
        buf_put(b, ")))");
        return;
    }
    buf_put(b, "(");
    cmp_operand(g, b, n->lhs, cop);
    buf_printf(b, " %s ", cop);
    cmp_operand(g, b, n->rhs, cop);
    buf_put(b, ")");
}

static const char *math_fn(int id) {
    switch (id) {
    case B_SQRT: return "sqrt"; case B_LN: return "log"; case B_LOG: return "log10"; case B_EXP: return "exp";
    case B_SIN: return "sin"; case B_COS: return "cos"; case B_TAN: return "tan"; case B_ASIN: return "asin";
    case B_ACOS: return "acos"; case B_ATAN: return "atan";
    default: return "?";
    }
}

static Node *arg(Node *n, int i) { return ((Node *)n->list.v[i])->lhs; }

/* The C helper of <from>_TO_STRING (matiec's formats). */
static const char *to_string_fn(const Type *from) {
    switch (from->kind) {
    case T_BOOL: return "__bool_to_str";
    case T_BYTE: case T_WORD: case T_DWORD: case T_LWORD: return "__bits_to_str";
    case T_SINT: case T_INT: case T_DINT: case T_LINT: return "__sint_to_str";
    case T_REAL: case T_LREAL: return "__real_to_str";
    case T_TIME: return "__time_to_str";
    case T_DATE: return "__date_to_str";
    case T_TOD: return "__tod_to_str";
    case T_DT: return "__dt_to_str";
    default: return "__uint_to_str";
    }
}

static void conversion(G *g, Buf *b, Node *n) {
    Type *from = ct(n->conv_from), *to = ct(n->ty);
    Node *a = arg(n, 0);
    if (to->kind == T_STRING) { buf_printf(b, "%s(", to_string_fn(from)); expr(g, b, a); buf_put(b, ")"); return; }
    if (from->kind == T_STRING) {
        if (to->kind >= T_TIME && to->kind <= T_DT) buf_put(b, "__str_to_time(");
        else if (to->kind == T_BOOL) buf_put(b, "__str_to_bool(");
        else if (is_real(to)) buf_printf(b, "((%s)__str_to_real(", cty(n->ty));
        else buf_printf(b, "((%s)__str_to_int(", cty(n->ty));
        expr(g, b, a);
        buf_put(b, to->kind >= T_TIME && to->kind <= T_DT ? ")" : to->kind == T_BOOL ? ")" : "))");
        return;
    }
    bool tf = from->kind >= T_TIME && from->kind <= T_DT, tt = to->kind >= T_TIME && to->kind <= T_DT;
    if (tf && tt) {
        const char *f = from->kind == T_DT && to->kind == T_TOD ? "__dt_to_tod" : from->kind == T_DT && to->kind == T_DATE ? "__dt_to_date" : "";
        buf_printf(b, "%s(", f);
        expr(g, b, a);
        buf_put(b, ")");
        return;
    }
    if (tf) {
        if (is_real(to)) { buf_printf(b, "((%s)__time_to_real(", cty(n->ty)); expr(g, b, a); buf_put(b, "))"); }
        else if (to->kind == T_BOOL) { buf_put(b, "(__time_to_int("); expr(g, b, a); buf_put(b, ") != 0)"); }
        else { buf_printf(b, "((%s)__time_to_int(", cty(n->ty)); expr(g, b, a); buf_put(b, "))"); }
        return;
    }
    if (tt) {
        if (is_real(from)) { buf_printf(b, "__real_to_time(("); expr(g, b, a); buf_put(b, "))"); }
        else { buf_printf(b, "__int_to_time((LINT)("); expr(g, b, a); buf_put(b, "))"); }
        return;
    }
    if (to->kind == T_BOOL) { buf_put(b, "(("); expr(g, b, a); buf_put(b, ") != 0)"); return; }
    if (is_real(from) && !is_real(to)) {
        buf_printf(b, "__real_to_%s(", to->cname);
        expr(g, b, a);
        buf_put(b, ")");
        return;
    }
    buf_printf(b, "((%s)(", cty(n->ty));
    expr(g, b, a);
    buf_put(b, "))");
}

/* "fn(a0, a1, ...)" from the first nargs arguments of call n; cast1, if
   not NULL, converts the second one: "fn(a0, (cast1)(a1))". */
static void call_fn(G *g, Buf *b, const char *fn, Node *n, int nargs, const char *cast1) {
    buf_printf(b, "%s(", fn);
    for (int i = 0; i < nargs; i++) {
        if (i) buf_put(b, ", ");
        if (i == 1 && cast1) buf_printf(b, "(%s)(", cast1);
        expr(g, b, arg(n, i));
        if (i == 1 && cast1) buf_put(b, ")");
    }
    buf_put(b, ")");
}

static void builtin(G *g, Buf *b, Node *n) {
    Type *t = ct(n->ty);
    int id = n->builtin;
    char fn[64];
    switch (id) {
    case B_CONV: conversion(g, b, n); return;
    case B_TRUNC:
        snprintf(fn, sizeof fn, "__trunc_to_%s", t->cname);
        call_fn(g, b, fn, n, 1, NULL);
        return;
    case B_ABS:
        if (is_real(t)) snprintf(fn, sizeof fn, "%s", t->kind == T_REAL ? "fabsf" : "fabs");
        else snprintf(fn, sizeof fn, "__ABS_%s", t->cname);
        call_fn(g, b, fn, n, 1, NULL);
        return;
    case B_SQRT: case B_LN: case B_LOG: case B_EXP: case B_SIN: case B_COS: case B_TAN:
    case B_ASIN: case B_ACOS: case B_ATAN:   /* in double, rounded once to REAL (matiec) */
        if (t->kind == T_REAL) buf_put(b, "((REAL)");
        call_fn(g, b, math_fn(id), n, 1, NULL);
        if (t->kind == T_REAL) buf_put(b, ")");
        return;
    case B_EXPT:
        snprintf(fn, sizeof fn, "__EXPT_%s", t->cname);
        call_fn(g, b, fn, n, 2, "LREAL");
        return;
    case B_MOVE: expr(g, b, arg(n, 0)); return;
    case B_SEL:
        buf_put(b, "(");
        expr(g, b, arg(n, 0));
        buf_put(b, " ? ");
        expr(g, b, arg(n, 2));
        buf_put(b, " : ");
        expr(g, b, arg(n, 1));
        buf_put(b, ")");
        return;
    case B_MAX: case B_MIN: {
        int k = n->list.n;
        for (int i = 0; i < k - 1; i++) buf_printf(b, "__%s_%s(", id == B_MAX ? "MAX" : "MIN", t->cname);
        expr(g, b, arg(n, 0));
        for (int i = 1; i < k; i++) { buf_put(b, ", "); expr(g, b, arg(n, i)); buf_put(b, ")"); }
        return;
    }
    case B_LIMIT:
        snprintf(fn, sizeof fn, "__LIMIT_%s", t->cname);
        call_fn(g, b, fn, n, 3, NULL);
        return;
    case B_MUX:   /* matiec's MUX: K out of range gives the initial value, ENO = FALSE */
        buf_printf(b, "__MUX_%s((LINT)(", t->cname);
        expr(g, b, arg(n, 0));
        buf_printf(b, "), %d, (%s[]){", n->list.n - 1, t->cname);
        for (int i = 1; i < n->list.n; i++) { if (i > 1) buf_put(b, ", "); expr(g, b, arg(n, i)); }
        if (n->eno && n->eno->lhs) { buf_put(b, "}, &("); expr(g, b, n->eno->lhs); buf_put(b, "))"); }
        else buf_put(b, "}, NULL)");
        return;
    case B_SHL: case B_SHR: case B_ROL: case B_ROR:
        snprintf(fn, sizeof fn, "__%s_%s", id == B_SHL ? "SHL" : id == B_SHR ? "SHR" : id == B_ROL ? "ROL" : "ROR", t->cname);
        call_fn(g, b, fn, n, 2, "LINT");
        return;
    case B_OP: expr(g, b, n->opx); return;
    case B_CONCAT: {
        int k = n->list.n;
        for (int i = 0; i < k - 1; i++) buf_put(b, "__str_concat(");
        expr(g, b, arg(n, 0));
        for (int i = 1; i < k; i++) { buf_put(b, ", "); expr(g, b, arg(n, i)); buf_put(b, ")"); }
        return;
    }
    case B_DIV:   /* matiec's DIV: a zero divisor gives 0 and ENO = FALSE */
        buf_printf(b, "__DIVF_%s(", t->cname);
        expr(g, b, arg(n, 0));
        buf_put(b, ", ");
        expr(g, b, arg(n, 1));
        if (n->eno && n->eno->lhs) { buf_put(b, ", &("); expr(g, b, n->eno->lhs); buf_put(b, "))"); }
        else buf_put(b, ", NULL)");
        return;
    case B_LIB: {   /* FIND's LINT result cast to the type the context took */
        bool scalar = t->kind != T_STRING && !(t->kind >= T_TIME && t->kind <= T_DT);
        if (scalar) buf_printf(b, "((%s)", cty(n->ty));
        buf_printf(b, "%s(", n->libfn);
        for (int i = 0; i < n->list.n; i++) {
            Type *at = ct(arg(n, i)->ty);
            if (i) buf_put(b, ", ");
            const char *cast = is_real(at) ? "LREAL" : is_int(at) ? "LINT" : NULL;
            if (cast) buf_printf(b, "(%s)(", cast);
            expr(g, b, arg(n, i));
            if (cast) buf_put(b, ")");
        }
        if (n->libfn[2] >= 'A' && n->libfn[2] <= 'Z') {   /* __LEFT, ...: ENO's address */
            if (n->eno && n->eno->lhs) { buf_put(b, ", &("); expr(g, b, n->eno->lhs); buf_put(b, ")"); }
            else buf_put(b, ", NULL");
        }
        buf_put(b, scalar ? "))" : ")");
        return;
    }
    case B_TO_BCD:
        buf_printf(b, "((%s)__uint_to_bcd((ULINT)(", cty(n->ty));
        expr(g, b, arg(n, 0));
        buf_put(b, ")))");
        return;
    case B_FROM_BCD:   /* an invalid digit: 0 and ENO = FALSE */
        buf_printf(b, "((%s)__bcd_to_uint((ULINT)(", cty(n->ty));
        expr(g, b, arg(n, 0));
        if (n->eno && n->eno->lhs) { buf_put(b, "), &("); expr(g, b, n->eno->lhs); buf_put(b, ")))"); }
        else buf_put(b, "), NULL))");
        return;
    case B_LEN:
        buf_put(b, "((INT)(");
        expr(g, b, arg(n, 0));
        buf_put(b, ").len)");
        return;
    }
}

/* Default value of type t, as a C expression (elementary and enumerations). */
static void default_value(G *g, Buf *b, Type *t) {
    for (Type *a = t; a; a = a->alias) {
        if (a->init && a->init->kind != N_ARRINIT && a->init->kind != N_STRUCTINIT) { expr(g, b, a->init); return; }
        if (!a->alias) break;
    }
    Type *c = ct(t);
    if (t->subrange || (t->alias && canon(t) != t && ct(t)->subrange)) {
        Type *s = t;
        while (s->alias) s = s->alias;
        if (s->subrange && (s->lo > 0 || s->hi < 0)) { buf_printf(b, "((%s)%lldLL)", s->cname, (long long)s->lo); return; }
    }
    if (c->kind >= T_TIME && c->kind <= T_DT) { buf_printf(b, "((%s){0, 0})", c->cname); return; }
    if (c->kind == T_STRING) { buf_put(b, "((STRING){0, \"\"})"); return; }
    if (c->kind == T_ENUM) { buf_printf(b, "%s__%s", c->cname, (char *)c->fields.v[0]); return; }
    if (is_real(c)) { buf_printf(b, "((%s)0.0)", c->cname); return; }
    buf_printf(b, "((%s)0)", cty(t));
}

/* A standard function called with EN := or ENO =>: EN = FALSE skips it, gives
   the type's initial value and ENO = FALSE (matiec's TEST_EN). */
static void builtin_en_eno(G *g, Buf *b, Node *n) {
    Node *eno = n->eno && n->eno->lhs ? n->eno->lhs : NULL;
    if (!n->en && !eno) { builtin(g, b, n); return; }
    buf_put(b, "(");
    if (n->en) { buf_put(b, "("); expr(g, b, n->en); buf_put(b, ") ? "); }
    Type *t = ct(n->ty);   /* both branches in the value's C type; structures need no cast */
    bool scalar = t->kind != T_STRING && !(t->kind >= T_TIME && t->kind <= T_DT) && t->kind != T_ARRAY && t->kind != T_STRUCT;
    if (scalar) buf_printf(b, "(%s)", cty(n->ty));
    buf_put(b, "(");
    if (eno && n->builtin != B_DIV && n->builtin != B_MUX) { buf_put(b, "("); expr(g, b, eno); buf_put(b, ") = 1, "); }
    builtin(g, b, n);
    buf_put(b, ")");
    if (n->en) {
        buf_put(b, " : ");
        if (eno) { buf_put(b, "(("); expr(g, b, eno); buf_put(b, ") = 0, "); }
        default_value(g, b, n->ty);
        if (eno) buf_put(b, ")");
    }
    buf_put(b, ")");
}

static void call_user_function(G *g, Buf *b, Node *n) {
    Pou *p = n->callee;
    buf_printf(b, "%s(", p->uname);
    bool first = true;
    for (int i = 0; i < p->syms.n; i++) {
        Sym *s = p->syms.v[i];
        if (s->cls != V_INPUT && s->cls != V_OUTPUT && s->cls != V_IN_OUT) continue;
        if (!first) buf_put(b, ", ");
        first = false;
        Node *a = NULL;
        for (int k = 0; k < n->list.n; k++)
            if (((Node *)n->list.v[k])->sym == s) a = n->list.v[k];
        if (s->cls == V_INPUT) {
            if (a) expr(g, b, a->lhs);
            else if (s->decl->init) expr(g, b, s->decl->init);
            else default_value(g, b, s->type);
        } else if (a && a->lhs) {
            buf_put(b, "&(");
            expr(g, b, a->lhs);
            buf_put(b, ")");
        } else {
            buf_printf(b, "&(%s){0}", cty(s->type));
        }
    }
    buf_put(b, ")");
}

static void expr(G *g, Buf *b, Node *n) {
    switch (n->kind) {
    case N_INT:
        if (is_real(n->ty)) real_lit(b, n->ty, n->neg ? -(double)n->ival : (double)n->ival);
        else int_lit(b, n->ty, n->ival, n->neg);
        return;
    case N_REAL: real_lit(b, n->ty, n->rval); return;
    case N_BOOL: buf_put(b, n->ival ? "1" : "0"); return;
    case N_STRING: string_lit(b, n->sval, n->slen); return;
    case N_TIME: time_lit(b, n->ty, n->tval); return;
    case N_TYPED:
        if (n->sym) { var_ref(g, b, n->sym); return; }
        expr(g, b, n->lhs);
        return;
    case N_IDENT: var_ref(g, b, n->sym); return;
    case N_MEMBER:
        if (n->sym && n->sym->kind == SK_VAR && n->sym->cls == V_IN_OUT) {
            /* an instance's in-out from outside: what its last call connected;
               before any call, a zero of the type */
            buf_put(b, "(*(");
            expr(g, b, n->lhs);
            buf_printf(b, ".%s ? ", n->uname);
            expr(g, b, n->lhs);
            buf_printf(b, ".%s : &(%s){0}))", n->uname, cty(n->sym->type));
            return;
        }
        expr(g, b, n->lhs);
        buf_printf(b, ".%s", n->uname);
        return;
    case N_INDEX: index_expr(g, b, n); return;
    case N_CALL:
        if (n->builtin) builtin_en_eno(g, b, n);
        else call_user_function(g, b, n);
        return;
    case N_UNARY: {
        Type *t = ct(n->ty);
        if (!strcmp(n->op, "NOT")) {
            if (t->kind == T_BOOL) { buf_put(b, "(!"); expr(g, b, n->lhs); buf_put(b, ")"); }
            else { buf_printf(b, "((%s)~", cty(n->ty)); expr(g, b, n->lhs); buf_put(b, ")"); }
        } else if (t->kind == T_TIME) {
            buf_put(b, "__time_neg(");
            expr(g, b, n->lhs);
            buf_put(b, ")");
        } else if (is_int(t)) {
            buf_printf(b, "((%s)(0 - (%s)(", cty(n->ty), wide_u(t));
            expr(g, b, n->lhs);
            buf_put(b, ")))");
        } else {
            buf_put(b, "(-");
            expr(g, b, n->lhs);
            buf_put(b, ")");
        }
        return;
    }
    case N_BINARY: binary(g, b, n); return;
    default:
        buf_put(b, "0");
        return;
    }
}

/* ---- initial values ---- */
static void init_value(G *g, Buf *b, const char *lv, Type *t, Node *init, int ind);

static void init_elements(G *g, Buf *b, const char *lv, Type *at, Node *init, int ind) {
    int64_t k = 0;
    if (init) {
        for (int i = 0; i < init->list.n; i++) {
            Node *it = init->list.v[i];
            if (it->kind == N_REPEAT) {
                int64_t cnt = (int64_t)it->ival;
                if (cnt > at->count - k) cnt = at->count - k;
                if (cnt <= 0) continue;
                int id = ++g->tmp;
                indent(b, ind);
                buf_printf(b, "for (LINT __stc_k%d = %lld; __stc_k%d < %lld; __stc_k%d++) {\n", id, (long long)k, id,
                           (long long)(k + cnt), id);
                init_value(g, b, fmt("%s.table[__stc_k%d]", lv, id), at->elem, it->lhs, ind + 1);
                indent(b, ind);
                buf_put(b, "}\n");
                k += cnt;
            } else {
                init_value(g, b, fmt("%s.table[%lld]", lv, (long long)k), at->elem, it, ind);
                k++;
            }
        }
    }
    if (k < at->count) {
        int id = ++g->tmp;
        indent(b, ind);
        buf_printf(b, "for (LINT __stc_k%d = %lld; __stc_k%d < %lld; __stc_k%d++) {\n", id, (long long)k, id, (long long)at->count, id);
        init_value(g, b, fmt("%s.table[__stc_k%d]", lv, id), at->elem, NULL, ind + 1);
        indent(b, ind);
        buf_put(b, "}\n");
    }
}

static Node *named_init(Type *t) {
    for (Type *a = t; a; a = a->alias)
        if (a->init) return a->init;
    return NULL;
}

static void init_value(G *g, Buf *b, const char *lv, Type *t, Node *init, int ind) {
    Type *c = ct(t);
    if (!init) init = named_init(t);
    switch (c->kind) {
    case T_FB:
        indent(b, ind);
        buf_printf(b, "%s_init__(&%s, retain);\n", c->cname, lv);
        if (init && init->kind == N_STRUCTINIT)
            for (int i = 0; i < init->list.n; i++) {
                Node *a = init->list.v[i];
                init_value(g, b, fmt("%s.%s", lv, a->sym->uname), a->sym->type, a->lhs, ind);
            }
        return;
    case T_STRUCT:
        for (int i = 0; i < c->fields.n; i++) {
            Field *f = c->fields.v[i];
            Node *fi = f->init;
            if (init && init->kind == N_STRUCTINIT)
                for (int k = 0; k < init->list.n; k++) {
                    Node *a = init->list.v[k];
                    if (!strcmp(a->uname, f->uname)) fi = a->lhs;
                }
            init_value(g, b, fmt("%s.%s", lv, f->uname), f->type, fi, ind);
        }
        return;
    case T_ARRAY:
        init_elements(g, b, lv, c, init && init->kind == N_ARRINIT ? init : NULL, ind);
        return;
    default:
        indent(b, ind);
        buf_printf(b, "%s = ", lv);
        if (init) expr(g, b, init);
        else default_value(g, b, t);
        buf_put(b, ";\n");
    }
}

/* ---- statements ---- */
static void fb_call(G *g, Buf *b, Node *call, int ind) {
    Pou *p = call->callee;
    Sym *inst = call->sym;
    int id = ++g->tmp;
    indent(b, ind);
    buf_printf(b, "{ %s *__stc_fb%d = &", p->type->cname, id);
    if (call->lhs) { buf_put(b, "("); expr(g, b, call->lhs); buf_put(b, ")"); }
    else var_ref(g, b, inst);
    buf_put(b, ";\n");
    for (int i = 0; i < call->list.n; i++) {
        Node *a = call->list.v[i];
        if (a->sym->cls == V_OUTPUT) continue;
        indent(b, ind + 1);
        if (a->sym->cls == V_IN_OUT) {
            buf_printf(b, "__stc_fb%d->%s = &(", id, a->sym->uname);
            expr(g, b, a->lhs);
            buf_put(b, ");\n");
        } else {
            buf_printf(b, "__stc_fb%d->%s = ", id, a->sym->uname);
            expr(g, b, a->lhs);
            buf_put(b, ";\n");
        }
    }
    indent(b, ind + 1);
    buf_printf(b, "%s_body__(__stc_fb%d);\n", p->type->cname, id);
    for (int i = 0; i < call->list.n; i++) {
        Node *a = call->list.v[i];
        if (a->sym->cls != V_OUTPUT || !a->lhs) continue;
        indent(b, ind + 1);
        expr(g, b, a->lhs);
        buf_printf(b, " = __stc_fb%d->%s;\n", id, a->sym->uname);
    }
    indent(b, ind);
    buf_put(b, "}\n");
}

static void cond(G *g, Buf *b, Node *e) { expr(g, b, e); }

static void stmt(G *g, Buf *b, Node *s, int ind) {
    switch (s->kind) {
    case S_ASSIGN:
        indent(b, ind);
        expr(g, b, s->lhs);
        buf_put(b, " = ");
        expr(g, b, s->rhs);
        buf_put(b, ";\n");
        return;
    case S_CALL:
        if ((s->lhs->sym || s->lhs->lhs) && !s->lhs->builtin && s->lhs->callee && s->lhs->callee->kind != POU_FUNCTION) {
            fb_call(g, b, s->lhs, ind);
            return;
        }
        indent(b, ind);
        buf_put(b, "(void)");
        expr(g, b, s->lhs);
        buf_put(b, ";\n");
        return;
    case S_IF:
        for (int i = 0; i < s->list.n; i++) {
            indent(b, ind);
            buf_put(b, i ? "} else if (" : "if (");
            cond(g, b, s->list.v[i]);
            buf_put(b, ") {\n");
            stmts(g, b, s->list2.v[i], ind + 1);
        }
        if (s->els) {
            indent(b, ind);
            buf_put(b, "} else {\n");
            stmts(g, b, &s->els->list, ind + 1);
        }
        indent(b, ind);
        buf_put(b, "}\n");
        return;
    case S_CASE: {
        int id = ++g->tmp;
        Type *t = s->lhs->ty;
        indent(b, ind);
        buf_printf(b, "{ %s __stc_sel%d = ", cty(t), id);
        expr(g, b, s->lhs);
        buf_put(b, ";\n");
        for (int i = 0; i < s->list2.n; i++) {
            Node *item = s->list2.v[i];
            indent(b, ind + 1);
            buf_put(b, i ? "} else if (" : "if (");
            for (int k = 0; k < item->list.n; k++) {
                Node *l = item->list.v[k];
                if (k) buf_put(b, " || ");
                if (l->kind == N_RANGE) {
                    buf_printf(b, "(__stc_sel%d >= ", id);
                    expr(g, b, l->lhs);
                    buf_printf(b, " && __stc_sel%d <= ", id);
                    expr(g, b, l->rhs);
                    buf_put(b, ")");
                } else {
                    buf_printf(b, "__stc_sel%d == ", id);
                    expr(g, b, l);
                }
            }
            buf_put(b, ") {\n");
            stmts(g, b, &item->list2, ind + 2);
        }
        if (s->els) {
            indent(b, ind + 1);
            buf_put(b, s->list2.n ? "} else {\n" : "{\n");
            stmts(g, b, &s->els->list, ind + 2);
        }
        if (s->list2.n || s->els) { indent(b, ind + 1); buf_put(b, "}\n"); }
        if (!s->list2.n && !s->els) { indent(b, ind + 1); buf_printf(b, "(void)__stc_sel%d;\n", id); }
        indent(b, ind);
        buf_put(b, "}\n");
        return;
    }
    case S_FOR: {
        int id = ++g->tmp;
        Type *t = s->lhs->ty;
        bool wide = type_bits(t) == 64;
        const char *ctr = wide ? cty(t) : "LINT";
        int64_t step = 1;
        bool const_step = !s->fourth || (s->fourth->kind == N_INT);
        if (s->fourth && s->fourth->kind == N_INT) step = s->fourth->neg ? -(int64_t)s->fourth->ival : (int64_t)s->fourth->ival;
        indent(b, ind);
        buf_printf(b, "{ %s __stc_to%d = (%s)(", ctr, id, ctr);
        expr(g, b, s->third);
        buf_printf(b, "); %s __stc_by%d = (%s)(", ctr, id, ctr);
        if (s->fourth) expr(g, b, s->fourth);
        else buf_put(b, "1");
        buf_put(b, ");\n");
        indent(b, ind + 1);
        buf_printf(b, "for (%s __stc_i%d = (%s)(", ctr, id, ctr);
        expr(g, b, s->rhs);
        if (const_step)
            buf_printf(b, "); __stc_i%d %s __stc_to%d; __stc_i%d += __stc_by%d) {\n", id, step > 0 ? "<=" : ">=", id, id, id);
        else
            buf_printf(b, "); __stc_by%d > 0 ? __stc_i%d <= __stc_to%d : (__stc_by%d < 0 && __stc_i%d >= __stc_to%d); __stc_i%d += __stc_by%d) {\n",
                       id, id, id, id, id, id, id, id);
        indent(b, ind + 2);
        expr(g, b, s->lhs);
        buf_printf(b, " = (%s)__stc_i%d;\n", cty(t), id);
        if (wide) {   /* stop before the counter wraps */
            stmts(g, b, &s->list, ind + 2);
            indent(b, ind + 2);
            buf_printf(b, "if (__stc_by%d > 0 ? __stc_i%d > __stc_to%d - __stc_by%d : __stc_i%d < __stc_to%d - __stc_by%d) break;\n", id, id, id,
                       id, id, id, id);
        } else {
            stmts(g, b, &s->list, ind + 2);
        }
        indent(b, ind + 1);
        buf_put(b, "}\n");
        indent(b, ind);
        buf_put(b, "}\n");
        return;
    }
    case S_WHILE:
        indent(b, ind);
        buf_put(b, "while (");
        cond(g, b, s->lhs);
        buf_put(b, ") {\n");
        stmts(g, b, &s->list, ind + 1);
        indent(b, ind);
        buf_put(b, "}\n");
        return;
    case S_REPEAT:
        indent(b, ind);
        buf_put(b, "do {\n");
        stmts(g, b, &s->list, ind + 1);
        indent(b, ind);
        buf_put(b, "} while (!(");
        cond(g, b, s->lhs);
        buf_put(b, "));\n");
        return;
    case S_EXIT:
        indent(b, ind);
        buf_put(b, "break;\n");
        return;
    case S_LABEL:   /* IL */
        if (s->ival) buf_printf(b, "__il_%s:;\n", s->uname);
        return;
    case S_GOTO:
        indent(b, ind);
        buf_printf(b, "goto __il_%s;\n", s->uname);
        return;
    case S_RETURN:
        indent(b, ind);
        buf_put(b, g->pou && g->pou->kind == POU_FUNCTION ? "return __res;\n" : "return;\n");
        return;
    case S_PRAGMA:
        if (g->pou && g->pou->kind == POU_FUNCTION) {
            /* in matiec's C a function's result is a local named like the
               function: C written for matiec assigns it under that name */
            buf_printf(b, "  /* embedded C */\n#define %s __res\n%s\n;\n#undef %s\n", g->pou->uname, s->sval, g->pou->uname);
            return;
        }
        /* the ';' after the text, as matiec writes it: C whose last
           statement lacks one (OSCAT's T_PLC_MS for OpenPLC) still builds */
        buf_printf(b, "  /* embedded C */\n%s\n;\n", s->sval);
        return;
    default:
        return;
    }
}

static void stmts(G *g, Buf *b, Vec *body, int ind) {
    for (int i = 0; i < body->n; i++) stmt(g, b, body->v[i], ind);
}

/* ---- POUs ---- */
static void emit_function(G *g, Pou *p) {
    Buf sig = {0};
    buf_printf(&sig, "%s %s(", cty(p->rettype), p->uname);
    bool first = true;
    for (int i = 0; i < p->syms.n; i++) {
        Sym *s = p->syms.v[i];
        if (s->cls != V_INPUT && s->cls != V_OUTPUT && s->cls != V_IN_OUT) continue;
        buf_printf(&sig, "%s%s %s%s", first ? "" : ", ", cty(s->type), s->cls == V_INPUT ? "" : "*", s->uname);
        first = false;
    }
    if (first) buf_put(&sig, "void");
    buf_put(&sig, ")");
    buf_printf(&g->h, "/* FUNCTION %s */\n%s;\n\n", p->name, sig.s);
    Buf *b = &g->c;
    buf_printf(b, "%s {\n", sig.s);
    g->pou = p;
    for (int i = 0; i < p->syms.n; i++) {
        Sym *s = p->syms.v[i];
        if (s->cls == V_LOCAL || s->cls == V_TEMP) {
            const char *name = s->is_result ? "__res" : s->uname;
            buf_printf(b, "  %s %s;\n", cty(s->type), name);
        }
    }
    buf_put(b, "  BOOL retain = 0;\n");
    for (int i = 0; i < p->syms.n; i++) {
        Sym *s = p->syms.v[i];
        const char *name = s->is_result ? "__res" : s->uname;
        if (s->cls == V_LOCAL || s->cls == V_TEMP) init_value(g, b, name, s->type, s->decl ? s->decl->init : NULL, 1);
        buf_printf(b, "  (void)%s;\n", name);
    }
    buf_put(b, "  (void)retain;\n");
    if (p->en) {   /* EN = FALSE: the result's initial value, ENO = FALSE */
        buf_printf(b, "  if (!EN) { %sreturn __res; }\n", p->eno ? "*ENO = 0; " : "");
        if (p->eno) buf_put(b, "  *ENO = 1;\n");
    }
    stmts(g, b, &p->body, 1);
    buf_put(b, "  return __res;\n}\n\n");
    g->pou = NULL;
}

static void emit_located_extern(G *g, Buf *b, VarDecl *d, Type *t) {
    (void)g;
    Buf name = {0};
    buf_put(&name, "__");
    const char *l = d->location + 1;
    buf_printf(&name, "%c", l[0]);
    l++;
    if (*l >= '0' && *l <= '9') buf_put(&name, "X");
    else { buf_printf(&name, "%c", *l); l++; }
    for (; *l; l++) buf_printf(&name, "%c", *l == '.' ? '_' : *l);
    buf_printf(b, "%s", name.s);
    (void)t;
}

static char *located_name(VarDecl *d) {
    Buf b = {0};
    emit_located_extern(NULL, &b, d, NULL);
    return b.s;
}

static void add_located(G *g, Sym *s) {
    for (int i = 0; i < g->located.n; i++) {
        Sym *o = g->located.v[i];
        if (!strcmp(located_name(o->decl), located_name(s->decl))) {
            if (!canon(o->type) || canon(o->type) != canon(s->type))
                error_at(s->decl->locloc, "location %s is already declared as %s (at line %d)", s->decl->location,
                         type_name(o->type), o->loc.line);
            return;
        }
    }
    vec_push(&g->located, s);
}

static void emit_fb(G *g, Pou *p) {
    Type *t = p->type;
    Buf *b = &g->c;
    g->pou = p;
    buf_printf(b, "void %s_init__(%s *data__, BOOL retain) {\n", t->cname, t->cname);
    for (int i = 0; i < p->syms.n; i++) {
        Sym *s = p->syms.v[i];
        if (s->cls == V_TEMP || s->cls == V_IN_OUT) continue;
        if (s->cls == V_EXTERNAL) {
            buf_printf(b, "  data__->%s = __GET_GLOBAL_%s();\n", s->uname, s->uname);
            bool have = false;
            for (int k = 0; k < g->externs.n; k++)
                if (!strcmp(((Sym *)g->externs.v[k])->uname, s->uname)) have = true;
            if (!have) vec_push(&g->externs, s);
            continue;
        }
        if (s->decl && s->decl->location) {
            char *ln = located_name(s->decl);
            buf_printf(b, "  data__->%s = %s;\n", s->uname, ln);
            if (s->decl->init) init_value(g, b, fmt("(*data__->%s)", s->uname), s->type, s->decl->init, 1);
            add_located(g, s);
            continue;
        }
        init_value(g, b, fmt("data__->%s", s->uname), s->type, s->decl ? s->decl->init : NULL, 1);
    }
    buf_put(b, "  (void)data__; (void)retain;\n}\n\n");
    buf_printf(b, "void %s_body__(%s *data__) {\n", t->cname, t->cname);
    for (int i = 0; i < p->syms.n; i++) {
        Sym *s = p->syms.v[i];
        if (s->cls != V_TEMP) continue;
        buf_printf(b, "  %s %s;\n", cty(s->type), s->uname);
    }
    bool temps = false;
    for (int i = 0; i < p->syms.n; i++) {
        Sym *s = p->syms.v[i];
        if (s->cls != V_TEMP) continue;
        if (!temps) buf_put(b, "  BOOL retain = 0; (void)retain;\n");
        temps = true;
        init_value(g, b, s->uname, s->type, s->decl->init, 1);
        buf_printf(b, "  (void)%s;\n", s->uname);
    }
    buf_put(b, "  (void)data__;\n");
    if (p->en) {   /* EN = FALSE: the body does not run, ENO = FALSE */
        buf_printf(b, "  if (!data__->EN) { %sreturn; }\n", p->eno ? "data__->ENO = 0; " : "");
        if (p->eno) buf_put(b, "  data__->ENO = 1;\n");
    }
    stmts(g, b, &p->body, 1);
    buf_put(b, "}\n\n");
    g->pou = NULL;
}

/* ---- files ---- */
static const char *g_outdir;

static void write_file(const char *name, Buf *b) {
    if (!g_outdir) return;
    char *path = fmt("%s/%s", g_outdir, name);
    FILE *f = fopen(path, "w");
    if (!f) { fprintf(stderr, "stc: cannot write %s: %s\n", path, strerror(errno)); exit(1); }
    if (b->n) fwrite(b->s, 1, b->n, f);
    if (fclose(f) != 0) { fprintf(stderr, "stc: cannot write %s: %s\n", path, strerror(errno)); exit(1); }
}

static const char *banner = "/* Generated by stc " STC_VERSION " from Structured Text: do not edit. */\n";

static int64_t gcd64(int64_t a, int64_t b) { while (b) { int64_t t = a % b; a = b; b = t; } return a; }

/* VARIABLES.csv rows: one per variable, an FB instance followed by its own. */
static void csv_vars(Buf *b, int *num, Pou *p, const char *path, bool retain);

/* a resource's variables' path prefix: CONFIG.RES, or CONFIG for the single
** resource of a configuration without RESOURCE (as matiec writes it) */
static const char *res_path(const Config *cf, const Resource *res) {
    return res->single ? cf->uname : fmt("%s.%s", cf->uname, res->uname);
}

/* The elementary parts of an array or a structure, one row each: the IEC
** path with the indexes as written (TAB[2,3], CFG.LIMITS.MAX), the C path
** to the element (TAB.table[k]). Arrays of function blocks are left out;
** at most CSV_MAX_PARTS rows per variable. */
enum { CSV_MAX_PARTS = 65536 };

static void csv_parts(Buf *b, int *num, Type *t, const char *iec, const char *cp, bool r, int *budget) {
    Type *c = ct(t);
    if (*budget <= 0) return;
    if (c->kind == T_ARRAY) {
        for (int64_t k = 0; k < c->count && *budget > 0; k++) {
            Buf ix = {0};
            int64_t rest = k, size = c->count;
            for (int d = 0; d < c->ndims; d++) {
                int64_t n = c->dims[d].hi - c->dims[d].lo + 1;
                size /= n;
                buf_printf(&ix, "%s%lld", d ? "," : "", (long long)(c->dims[d].lo + rest / size));
                rest %= size;
            }
            csv_parts(b, num, c->elem, fmt("%s[%s]", iec, ix.s), fmt("%s.table[%lld]", cp, (long long)k), r, budget);
        }
        return;
    }
    if (c->kind == T_STRUCT) {
        for (int i = 0; i < c->fields.n && *budget > 0; i++) {
            Field *f = c->fields.v[i];
            csv_parts(b, num, f->type, fmt("%s.%s", iec, f->uname), fmt("%s.%s", cp, f->uname), r, budget);
        }
        return;
    }
    if (c->kind == T_FB) return;
    (*budget)--;
    buf_printf(b, "%d;VAR;%s;%s;%s;%s;%d;\n", (*num)++, iec, cp, t->name, t->name, r);
}

static void csv_var(Buf *b, int *num, Sym *s, const char *vp, bool r) {
    Type *c = ct(s->type);
    if (c->kind == T_FB && !s->pointer) {
        buf_printf(b, "%d;FB;%s;%s;%s;;%d;\n", (*num)++, vp, vp, c->cname, r);
        csv_vars(b, num, c->pou, vp, r);
        return;
    }
    if (c->kind == T_FB) return;
    if (c->kind == T_ARRAY || c->kind == T_STRUCT) {
        /* matiec lists no arrays or structures; stc lists their elementary
        ** parts, so that they can be retained and mapped to Modbus */
        int budget = CSV_MAX_PARTS;
        if (!s->pointer) csv_parts(b, num, s->type, vp, vp, r, &budget);
        return;
    }
    const char *kind = "VAR";
    if (s->cls == V_EXTERNAL) kind = "EXT";
    else if (s->decl && s->decl->location)
        kind = s->decl->location[1] == 'I' ? "IN" : s->decl->location[1] == 'Q' ? "OUT" : "MEM";
    buf_printf(b, "%d;%s;%s;%s;%s;%s;%d;\n", (*num)++, kind, vp, vp, s->type->name, s->type->name, r);
}

static void csv_vars(Buf *b, int *num, Pou *p, const char *path, bool retain) {
    for (int i = 0; i < p->syms.n; i++) {
        Sym *s = p->syms.v[i];
        if (s->cls == V_TEMP) continue;
        /* NON_RETAIN members stay volatile inside a RETAIN instance */
        bool r = (retain || s->retain) && !(s->decl && s->decl->non_retain);
        csv_var(b, num, s, fmt("%s.%s", path, s->uname), r);
    }
}

static void globals_code(Buf *b, Vec *gsyms) {
    for (int i = 0; i < gsyms->n; i++) {
        Sym *s = gsyms->v[i];
        if (s->pointer) buf_printf(b, "%s *%s;\n", cty(s->type), s->gcname);
        else buf_printf(b, "%s %s;\n", cty(s->type), s->gcname);
        buf_printf(b, "%s *__GET_GLOBAL_%s(void) { return %s%s; }\n", cty(s->type), s->uname, s->pointer ? "" : "&",
                   s->gcname);
    }
}

static void globals_init(G *g, Buf *b, Vec *gsyms) {
    for (int i = 0; i < gsyms->n; i++) {
        Sym *s = gsyms->v[i];
        if (s->decl->location) {
            buf_printf(b, "  %s = %s;\n", s->gcname, located_name(s->decl));
            if (s->decl->init) init_value(g, b, fmt("(*%s)", s->gcname), s->type, s->decl->init, 1);
            add_located(g, s);
        } else {
            init_value(g, b, s->gcname, s->type, s->decl->init, 1);
        }
    }
}

int codegen(Unit *u, const char *outdir) {
    G g = {0};
    g.u = u;
    g_outdir = outdir;
    buf_put(&g.h, banner);
    buf_put(&g.h, "#ifndef __POUS_H\n#define __POUS_H\n\n#include \"iec_std_lib.h\"\n\n");
    buf_put(&g.c, banner);
    buf_put(&g.c, "#include \"POUS.h\"\n\n");
    /* ST may compare a variable with itself (x = x is FALSE for a NaN) or an
       unsigned one with 0: legal, and not worth a warning in generated code */
    buf_put(&g.c, "#pragma GCC diagnostic ignored \"-Wtautological-compare\"\n");
    buf_put(&g.c, "#pragma GCC diagnostic ignored \"-Wtype-limits\"\n\n");
    for (int i = 0; i < u->pragmas.n; i++) buf_printf(&g.c, "%s\n", ((Token *)u->pragmas.v[i])->sval);
    /* types in dependency order */
    for (int i = 0; i < u->types.n; i++) {
        TypeDecl *d = u->types.v[i];
        if (d->spec->resolved) emit_type(&g, d->spec->resolved);
    }
    Buf body = {0};
    Buf saved = g.c;
    g.c = body;
    for (int i = 0; i < u->pous.n; i++) {
        Pou *p = u->pous.v[i];
        if (!p->used) continue;
        for (int k = 0; k < p->syms.n; k++) emit_type(&g, ((Sym *)p->syms.v[k])->type);
        if (p->kind == POU_FUNCTION) { emit_type(&g, p->rettype); emit_function(&g, p); }
        else { emit_type(&g, p->type); emit_fb(&g, p); }
    }
    body = g.c;
    g.c = saved;
    /* configuration globals reached through VAR_EXTERNAL */
    for (int i = 0; i < g.externs.n; i++) {
        Sym *s = g.externs.v[i];
        buf_printf(&g.h, "%s *__GET_GLOBAL_%s(void);\n", cty(s->type), s->uname);
    }
    /* located variables of programs are bound by the runtime */
    Buf cfgs = {0};
    Config *cf = u->configs.n ? u->configs.v[0] : NULL;
    if (u->configs.n > 1) error_at(((Config *)u->configs.v[1])->loc, "only one CONFIGURATION per file is supported");
    Buf csv = {0};
    buf_put(&csv, "// Programs\n");
    int num = 0;
    if (cf) {
        for (int r = 0; r < cf->resources.n; r++) {
            Resource *res = cf->resources.v[r];
            for (int i = 0; i < res->progs.n; i++) {
                ProgInst *pi = res->progs.v[i];
                buf_printf(&csv, "%d;%s.%s;%s;\n", num++, res_path(cf, res), pi->uname, pi->p ? pi->p->uname : "?");
            }
        }
    }
    buf_put(&csv, "\n// Variables\n");
    num = 0;
    int64_t tick = 0;
    if (cf) {
        Buf ch = {0}, cc = {0};
        buf_put(&ch, banner);
        buf_printf(&ch, "#ifndef __%s_H\n#define __%s_H\n\n#include \"POUS.h\"\n\n", cf->uname, cf->uname);
        buf_put(&cc, banner);
        buf_printf(&cc, "#include \"iec_std_lib.h\"\n#include \"POUS.h\"\n#include \"%s.h\"\n\n", cf->name);
        Buf cinit = {0};
        globals_code(&cc, &cf->gsyms);
        globals_init(&g, &cinit, &cf->gsyms);
        for (int i = 0; i < cf->gsyms.n; i++) {
            Sym *s = cf->gsyms.v[i];
            buf_printf(&ch, "extern %s %s%s;\n", cty(s->type), s->pointer ? "*" : "", s->gcname);
            csv_var(&csv, &num, s, fmt("%s.%s", cf->uname, s->uname), s->retain);
        }
        /* tick: gcd of the task intervals */
        for (int r = 0; r < cf->resources.n; r++) {
            Resource *res = cf->resources.v[r];
            for (int i = 0; i < res->tasks.n; i++) {
                Task *t = res->tasks.v[i];
                if (t->interval_ns > 0) tick = tick ? gcd64(tick, t->interval_ns) : t->interval_ns;
            }
        }
        if (!tick) tick = 20000000;   /* no task: run every 20 ms */
        uint64_t lcm = 1;
        for (int r = 0; r < cf->resources.n; r++) {
            Resource *res = cf->resources.v[r];
            Buf rc = {0};
            buf_put(&rc, banner);
            buf_printf(&rc, "#include \"iec_std_lib.h\"\n#include \"POUS.h\"\n#include \"%s.h\"\n", cf->name);
            if (r == 0) buf_put(&rc, "#include \"POUS.c\"\n");
            buf_put(&rc, "\n");
            Buf rinit = {0};
            for (int i = 0; i < res->gsyms.n; i++) {
                Sym *s = res->gsyms.v[i];
                csv_var(&csv, &num, s, fmt("%s.%s", res_path(cf, res), s->uname), s->retain);
            }
            globals_code(&rc, &res->gsyms);
            globals_init(&g, &rinit, &res->gsyms);
            for (int i = 0; i < res->progs.n; i++) {
                ProgInst *pi = res->progs.v[i];
                if (!pi->p) continue;
                buf_printf(&rc, "%s %s__%s;\n", pi->p->type->cname, res->uname, pi->uname);
                buf_printf(&rinit, "  %s_init__(&%s__%s, retain);\n", pi->p->type->cname, res->uname, pi->uname);
                char *vp = fmt("%s.%s", res_path(cf, res), pi->uname);
                buf_printf(&csv, "%d;FB;%s;%s;%s;;%d;\n", num++, vp, vp, pi->p->type->cname, pi->retain);
                csv_vars(&csv, &num, pi->p, vp, pi->retain);
            }
            /* SINGLE tasks: the trigger's value at the last tick, for its rising edge */
            for (int i = 0; i < res->tasks.n; i++) {
                Task *t = res->tasks.v[i];
                if (!t->single) continue;
                buf_printf(&rc, "static BOOL __stc_single_%s;\n", t->uname);
                buf_printf(&rinit, "  __stc_single_%s = 0;\n", t->uname);
            }
            buf_printf(&rc, "\nvoid %s_init__(void) {\n  BOOL retain = 0;\n%s  (void)retain;\n}\n\n", res->uname,
                       rinit.s ? rinit.s : "");
            buf_printf(&rc, "void %s_run__(unsigned long tick) {\n", res->uname);
            for (int i = 0; i < res->tasks.n; i++) {
                Task *t = res->tasks.v[i];
                if (!t->single || !t->single->sym) continue;
                buf_printf(&rc, "  BOOL __stc_now_%s = ", t->uname);
                expr(&g, &rc, t->single);
                buf_printf(&rc, ";\n  BOOL __stc_run_%s = __stc_now_%s && !__stc_single_%s;\n", t->uname, t->uname, t->uname);
                buf_printf(&rc, "  __stc_single_%s = __stc_now_%s;\n", t->uname, t->uname);
            }
            bool used_tick = false;
            for (int i = 0; i < res->progs.n; i++) {
                ProgInst *pi = res->progs.v[i];
                if (!pi->p) continue;
                if (pi->t && pi->t->single) {
                    buf_printf(&rc, "  if (__stc_run_%s) ", pi->t->uname);
                } else if (pi->t && pi->t->interval_ns > 0) {
                    int64_t k = pi->t->interval_ns / tick;
                    uint64_t gg = (uint64_t)gcd64((int64_t)lcm, k);
                    lcm = lcm / gg * (uint64_t)k;
                    if (lcm > 0xFFFFFFFFull) lcm = 0xFFFFFFFFull;
                    if (k > 1) {
                        buf_printf(&rc, "  if (tick %% %lldUL == 0) ", (long long)k);
                        used_tick = true;
                    } else {
                        buf_put(&rc, "  ");
                    }
                } else {
                    buf_put(&rc, "  ");
                }
                buf_printf(&rc, "%s_body__(&%s__%s);\n", pi->p->type->cname, res->uname, pi->uname);
            }
            if (!used_tick) buf_put(&rc, "  (void)tick;\n");
            buf_put(&rc, "}\n");
            buf_printf(&ch, "void %s_init__(void);\nvoid %s_run__(unsigned long tick);\n", res->uname, res->uname);
            write_file(fmt("%s.c", res->name), &rc);
        }
        uint64_t greatest = lcm > 1 ? (0xFFFFFFFFull / lcm) * lcm : 0;
        buf_printf(&cc, "\nvoid config_init__(void) {\n  BOOL retain = 0;\n%s", cinit.s ? cinit.s : "");
        for (int r = 0; r < cf->resources.n; r++) buf_printf(&cc, "  %s_init__();\n", ((Resource *)cf->resources.v[r])->uname);
        buf_put(&cc, "  (void)retain;\n}\n\nvoid config_run__(unsigned long tick) {\n");
        for (int r = 0; r < cf->resources.n; r++) buf_printf(&cc, "  %s_run__(tick);\n", ((Resource *)cf->resources.v[r])->uname);
        if (!cf->resources.n) buf_put(&cc, "  (void)tick;\n");
        buf_printf(&cc, "}\n\nunsigned long long common_ticktime__ = %lldULL; /* ns */\n", (long long)tick);
        buf_printf(&cc, "unsigned long greatest_tick_count__ = %lluUL; /* ticks */\n", (unsigned long long)greatest);
        buf_put(&ch, "\nextern unsigned long long common_ticktime__;\nextern unsigned long greatest_tick_count__;\n#endif\n");
        write_file(fmt("%s.h", cf->name), &ch);
        write_file(fmt("%s.c", cf->name), &cc);
    }
    buf_printf(&csv, "\n\n// Ticktime\n%lld\n", (long long)tick);
    /* extern declarations of located storage, before the bodies */
    for (int i = 0; i < g.located.n; i++) {
        Sym *s = g.located.v[i];
        buf_printf(&g.h, "extern %s *%s;\n", ct(s->type)->cname, located_name(s->decl));
    }
    buf_put(&g.h, "\n#endif\n");
    if (body.s) buf_put(&g.c, body.s);
    Buf loc = {0};
    for (int i = 0; i < g.located.n; i++) {
        Sym *s = g.located.v[i];
        const char *l = s->decl->location + 1;
        char area = l[0], size = 'X';
        l++;
        if (*l < '0' || *l > '9') { size = *l; l++; }
        buf_printf(&loc, "__LOCATED_VAR(%s,%s,%c,%c", ct(s->type)->cname, located_name(s->decl), area, size);
        for (const char *q = l; *q;) {
            const char *e = strchr(q, '.');
            size_t n = e ? (size_t)(e - q) : strlen(q);
            buf_printf(&loc, ",%.*s", (int)n, q);
            q += n;
            if (*q == '.') q++;
        }
        buf_put(&loc, ")\n");
    }
    if (error_count) return 1;
    write_file("POUS.h", &g.h);
    write_file("POUS.c", &g.c);
    write_file("LOCATED_VARIABLES.h", &loc);
    write_file("VARIABLES.csv", &csv);
    (void)cfgs;
    return 0;
}
