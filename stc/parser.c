/* Parser: tokens to syntax tree, by recursive descent. Syntax errors stop the
** compilation at once; a missing END_xxx is reported at the construct it
** should close. */
#include "stc.h"

#include <string.h>

#define MAX_DEPTH 400

typedef struct {
    Token *t;
    int n, i;
    int depth;
    Unit *u;
    bool lib;
} P;

static Token *cur(P *p) { return &p->t[p->i]; }
static Token *peek(P *p, int k) { int j = p->i + k; return &p->t[j < p->n ? j : p->n - 1]; }
static Token *next(P *p) { Token *t = cur(p); if (t->kind != TK_EOF) p->i++; return t; }

static bool is_kw(Token *t, const char *kw) { return t->kind == TK_IDENT && !strcmp(t->up, kw); }
static bool is_p(Token *t, const char *s) { return t->kind == TK_PUNCT && !strcmp(t->up, s); }
/* A keyword beginning with prefix (END_..., VAR_...): a name that merely
   starts the same way, like var_out or end_x, is an identifier. */
static bool kw_prefix(Token *t, const char *prefix) {
    return t->kind == TK_IDENT && !strncmp(t->up, prefix, strlen(prefix)) && is_reserved(t->up);
}

static const char *desc(Token *t) {
    if (t->kind == TK_EOF) return "end of file";
    return t->text;
}

_Noreturn static void expected(P *p, const char *what) {
    Token *t = cur(p);
    if (t->kind == TK_EOF) fatal_at(t->loc, "unexpected end of file: expected %s", what);
    fatal_at(t->loc, "expected %s, found '%s'", what, desc(t));
}

static bool accept_kw(P *p, const char *kw) { if (is_kw(cur(p), kw)) { next(p); return true; } return false; }
static bool accept_p(P *p, const char *s) { if (is_p(cur(p), s)) { next(p); return true; } return false; }

static Token *expect_p(P *p, const char *s) {
    if (!is_p(cur(p), s)) expected(p, fmt("'%s'", s));
    return next(p);
}

static Token *expect_kw(P *p, const char *kw) {
    if (!is_kw(cur(p), kw)) expected(p, fmt("'%s'", kw));
    return next(p);
}

/* Closing keyword of a construct opened at `open`. */
static void expect_end(P *p, Token *open, const char *what, const char *end) {
    if (accept_kw(p, end)) return;
    Token *t = cur(p);
    if (t->kind == TK_EOF || (t->kind == TK_IDENT && (kw_prefix(t, "END_") ||
        !strcmp(t->up, "FUNCTION") || !strcmp(t->up, "FUNCTION_BLOCK") || !strcmp(t->up, "PROGRAM") ||
        !strcmp(t->up, "CONFIGURATION") || !strcmp(t->up, "TYPE") || !strcmp(t->up, "ELSE") ||
        !strcmp(t->up, "ELSIF") || !strcmp(t->up, "UNTIL") || !strcmp(t->up, "VAR") ||
        kw_prefix(t, "VAR_") || !strcmp(t->up, "RESOURCE"))))
        fatal_at(open->loc, "%s without %s", what, end);
    expected(p, fmt("'%s'", end));
}

static Token *ident(P *p, const char *what) {
    Token *t = cur(p);
    if (t->kind != TK_IDENT) expected(p, what);
    if (is_reserved(t->up)) fatal_at(t->loc, "expected %s, found keyword '%s'", what, t->text);
    return next(p);
}

/* Constructs stc does not compile, named in the diagnostic. */
static bool is_one_of(Token *t, const char *const *names) {
    if (t->kind != TK_IDENT) return false;
    for (; *names; names++) if (!strcmp(t->up, *names)) return true;
    return false;
}
static const char *const oop_words[] = {"CLASS", "INTERFACE", "NAMESPACE", "METHOD", "PROPERTY", "EXTENDS", "IMPLEMENTS", NULL};
static const char *const sfc_words[] = {"INITIAL_STEP", "STEP", "TRANSITION", "ACTION", NULL};
static const char *const il_ops[] = {"LD", "LDN", "ST", "STN", "S", "R", "ANDN", "ORN", "XORN", "CAL", "CALC", "CALCN",
                                    "JMPC", "JMPCN", "RET", "RETC", "RETCN", NULL};
static const char *const unsupported_types[] = {"WSTRING", "CHAR", "WCHAR", "LTIME", "LDATE", "LTOD", "LDT",
                                               "LTIME_OF_DAY", "LDATE_AND_TIME", NULL};

static void unsupported_oop(Token *t) {
    if (t->kind == TK_IDENT && is_one_of(t, oop_words))
        fatal_at(t->loc, "object-oriented ST (%s) is not supported by stc", t->up);
}

static Node *new_node(NodeKind k, Token *t) {
    Node *n = xalloc(sizeof *n);
    n->kind = k;
    n->loc = n->start = t->loc;
    return n;
}

static void enter(P *p) {
    if (++p->depth > MAX_DEPTH) fatal_at(cur(p)->loc, "nesting too deep (more than %d levels)", MAX_DEPTH);
}
static void leave(P *p) { p->depth--; }

/* ---- expressions ---- */
static Node *expr(P *p);

static Node *literal_from(Token *t) {
    Node *n;
    switch (t->kind) {
    case TK_INT: n = new_node(N_INT, t); n->ival = t->ival; return n;
    case TK_REAL: n = new_node(N_REAL, t); n->rval = t->rval; return n;
    case TK_STRING: n = new_node(N_STRING, t); n->sval = t->sval; n->slen = t->slen; return n;
    case TK_TIME: n = new_node(N_TIME, t); n->tval = t->tval; n->tkind = t->tkind; return n;
    default: return NULL;
    }
}

static Node *call_args(P *p, Node *call) {
    /* after '(' */
    if (accept_p(p, ")")) return call;
    do {
        Token *t = cur(p);
        Node *a = new_node(N_ARG, t);
        if (is_kw(t, "NOT") && peek(p, 1)->kind == TK_IDENT && is_p(peek(p, 2), "=>")) {
            next(p);
            a->negated = true;
            t = cur(p);
        }
        if (t->kind == TK_IDENT && (is_p(peek(p, 1), ":=") || is_p(peek(p, 1), "=>"))) {
            next(p);
            a->name = t->text;
            a->uname = t->up;
            a->loc = t->loc;
            a->is_out = is_p(cur(p), "=>");
            next(p);
            if (a->is_out && is_p(cur(p), ",")) { a->lhs = NULL; vec_push(&call->list, a); continue; }
            if (a->is_out && is_p(cur(p), ")")) { a->lhs = NULL; vec_push(&call->list, a); break; }
        }
        a->lhs = expr(p);
        if (!a->name) a->loc = a->lhs->start;
        vec_push(&call->list, a);
    } while (accept_p(p, ","));
    expect_p(p, ")");
    return call;
}

static Node *postfix(P *p, Node *n) {
    for (;;) {
        Token *t = cur(p);
        if (is_p(t, ".")) {
            next(p);
            Token *m = cur(p);
            if (m->kind == TK_INT) {  /* bit access x.3: not supported */
                fatal_at(m->loc, "bit access '.%s' is not supported", m->text);
            }
            m = ident(p, "member name");
            Node *x = new_node(N_MEMBER, m);
            x->start = n->start;
            x->lhs = n;
            x->name = m->text;
            x->uname = m->up;
            n = x;
        } else if (is_p(t, "[")) {
            next(p);
            Node *x = new_node(N_INDEX, t);
            x->start = n->start;
            x->lhs = n;
            do vec_push(&x->list, expr(p)); while (accept_p(p, ","));
            expect_p(p, "]");
            n = x;
        } else {
            return n;
        }
    }
}

static Node *primary(P *p) {
    Token *t = cur(p);
    Node *n = literal_from(t);
    if (n) { next(p); return n; }
    if (is_p(t, "(")) {
        next(p);
        enter(p);
        n = expr(p);
        leave(p);
        Token *close = cur(p);
        (void)close;
        expect_p(p, ")");
        n->start = t->loc;
        return postfix(p, n);
    }
    if (t->kind == TK_IDENT) {
        if (is_kw(t, "TRUE") || is_kw(t, "FALSE")) {
            next(p);
            n = new_node(N_BOOL, t);
            n->ival = is_kw(t, "TRUE");
            return n;
        }
        if (is_p(peek(p, 1), "#")) {           /* TYPE#literal or Enum#Value */
            next(p);
            next(p);
            n = new_node(N_TYPED, t);
            n->tname = t->up;
            n->name = t->text;
            Token *v = cur(p);
            bool neg = false;
            if (is_p(v, "-")) { neg = true; next(p); v = cur(p); }
            Node *lit = literal_from(v);
            if (lit) {
                next(p);
                if (neg) {
                    if (lit->kind == N_INT) lit->neg = true;
                    else if (lit->kind == N_REAL) lit->rval = -lit->rval;
                    else fatal_at(v->loc, "unexpected '-'");
                }
                n->lhs = lit;
            } else if (v->kind == TK_IDENT && (is_kw(v, "TRUE") || is_kw(v, "FALSE"))) {
                next(p);
                n->lhs = new_node(N_BOOL, v);
                n->lhs->ival = is_kw(v, "TRUE");
            } else if (v->kind == TK_IDENT && !neg) {
                next(p);
                n->uname = v->up;   /* Enum#Value */
                n->loc = v->loc;
            } else {
                expected(p, "a literal after '#'");
            }
            return n;
        }
        bool opfn = (is_kw(t, "AND") || is_kw(t, "OR") || is_kw(t, "XOR") || is_kw(t, "NOT") || is_kw(t, "MOD")) &&
                    is_p(peek(p, 1), "(");   /* the operator functions AND(a, b), ... */
        if (is_kw(t, "TIME") && is_p(peek(p, 1), "("))
            fatal_at(t->loc, "TIME() is CODESYS's clock, not a standard function: stc does not support it");
        if (is_reserved(t->up) && !opfn) {
            /* type-named conversion calls like INT_TO_REAL are not reserved; these are */
            fatal_at(t->loc, "expected expression, found keyword '%s'", t->text);
        }
        next(p);
        if (is_p(cur(p), "(")) {
            next(p);
            n = new_node(N_CALL, t);
            n->name = t->text;
            n->uname = t->up;
            enter(p);
            call_args(p, n);
            leave(p);
            return postfix(p, n);
        }
        n = new_node(N_IDENT, t);
        n->name = t->text;
        n->uname = t->up;
        return postfix(p, n);
    }
    if (t->kind == TK_EOF) expected(p, "expression");
    fatal_at(t->loc, "expected expression, found '%s'", desc(t));
}

static Node *unary(P *p) {
    Token *t = cur(p);
    if (is_p(t, "-") || is_p(t, "+")) {
        Token *v = peek(p, 1);
        if (v->kind == TK_INT || v->kind == TK_REAL) {   /* signed literal */
            next(p);
            Node *n = primary(p);
            n->start = t->loc;
            if (is_p(t, "-")) {
                if (n->kind == N_INT) n->neg = true;
                else if (n->kind == N_REAL) n->rval = -n->rval;
                else {          /* -5.x member etc: fall back to negation */
                    Node *u = new_node(N_UNARY, t);
                    u->op = "-";
                    u->lhs = n;
                    return u;
                }
            }
            return n;
        }
        next(p);
        enter(p);
        Node *n = new_node(N_UNARY, t);
        n->op = t->up;
        n->lhs = unary(p);
        leave(p);
        if (!strcmp(n->op, "+")) { n->lhs->start = t->loc; return n->lhs; }
        return n;
    }
    /* NOT(IN := x) is the function; NOT (x) the operator, with the same meaning */
    if (is_kw(t, "NOT") && !(is_p(peek(p, 1), "(") && peek(p, 2)->kind == TK_IDENT && is_p(peek(p, 3), ":="))) {
        next(p);
        enter(p);
        Node *n = new_node(N_UNARY, t);
        n->op = "NOT";
        n->lhs = unary(p);
        leave(p);
        return n;
    }
    return primary(p);
}

static Node *binary(P *p, Token *op, Node *l, Node *r) {
    Node *n = new_node(N_BINARY, op);
    /* a long chain a+b+c+... nests as deeply as parentheses would */
    n->depth = (l->depth > r->depth ? l->depth : r->depth) + 1;
    if (n->depth + p->depth > MAX_DEPTH * 4)
        fatal_at(op->loc, "expression too long (more than %d operators deep)", MAX_DEPTH * 4);
    n->op = op->up;
    if (!strcmp(n->op, "&")) n->op = "AND";
    n->lhs = l;
    n->rhs = r;
    n->start = l->start;
    return n;
}

static Node *power(P *p) {
    Node *n = unary(p);
    while (is_p(cur(p), "**")) { Token *op = next(p); n = binary(p, op, n, unary(p)); }
    return n;
}

static Node *term(P *p) {
    Node *n = power(p);
    for (;;) {
        Token *t = cur(p);
        if (is_p(t, "*") || is_p(t, "/") || is_kw(t, "MOD")) { next(p); n = binary(p, t, n, power(p)); }
        else return n;
    }
}

static Node *additive(P *p) {
    Node *n = term(p);
    for (;;) {
        Token *t = cur(p);
        if (is_p(t, "+") || is_p(t, "-")) { next(p); n = binary(p, t, n, term(p)); }
        else return n;
    }
}

static Node *relational(P *p) {
    Node *n = additive(p);
    for (;;) {
        Token *t = cur(p);
        if (is_p(t, "<") || is_p(t, ">") || is_p(t, "<=") || is_p(t, ">=")) { next(p); n = binary(p, t, n, additive(p)); }
        else return n;
    }
}

static Node *equality(P *p) {
    Node *n = relational(p);
    for (;;) {
        Token *t = cur(p);
        if (is_p(t, "=") || is_p(t, "<>")) { next(p); n = binary(p, t, n, relational(p)); }
        else return n;
    }
}

static Node *and_expr(P *p) {
    Node *n = equality(p);
    for (;;) {
        Token *t = cur(p);
        if (is_kw(t, "AND") || is_p(t, "&")) { next(p); n = binary(p, t, n, equality(p)); }
        else return n;
    }
}

static Node *xor_expr(P *p) {
    Node *n = and_expr(p);
    while (is_kw(cur(p), "XOR")) { Token *t = next(p); n = binary(p, t, n, and_expr(p)); }
    return n;
}

static Node *expr(P *p) {
    enter(p);
    Node *n = xor_expr(p);
    while (is_kw(cur(p), "OR")) { Token *t = next(p); n = binary(p, t, n, xor_expr(p)); }
    leave(p);
    return n;
}

/* ---- initial values ---- */
static Node *init_value(P *p);

static Node *array_init(P *p) {
    Token *t = expect_p(p, "[");
    Node *n = new_node(N_ARRINIT, t);
    enter(p);
    do {
        Token *c = cur(p);
        if (c->kind == TK_INT && is_p(peek(p, 1), "(")) {
            next(p);
            next(p);
            Node *r = new_node(N_REPEAT, c);
            r->ival = c->ival;
            if (!is_p(cur(p), ")")) r->lhs = init_value(p);
            expect_p(p, ")");
            vec_push(&n->list, r);
        } else {
            vec_push(&n->list, init_value(p));
        }
    } while (accept_p(p, ","));
    leave(p);
    expect_p(p, "]");
    return n;
}

static Node *struct_init(P *p) {
    Token *t = expect_p(p, "(");
    Node *n = new_node(N_STRUCTINIT, t);
    enter(p);
    do {
        Token *f = ident(p, "structure member name");
        Node *a = new_node(N_ARG, f);
        a->name = f->text;
        a->uname = f->up;
        expect_p(p, ":=");
        a->lhs = init_value(p);
        vec_push(&n->list, a);
    } while (accept_p(p, ","));
    leave(p);
    expect_p(p, ")");
    return n;
}

static Node *init_value(P *p) {
    if (is_p(cur(p), "[")) return array_init(p);
    if (is_p(cur(p), "(") && peek(p, 1)->kind == TK_IDENT && is_p(peek(p, 2), ":=")) return struct_init(p);
    return expr(p);
}

/* ---- types ---- */
static TypeSpec *new_spec(TSKind k, Token *t) {
    TypeSpec *s = xalloc(sizeof *s);
    s->kind = k;
    s->loc = t->loc;
    return s;
}

static Node *range(P *p) {
    Token *t = cur(p);
    if (is_p(t, "*")) fatal_at(t->loc, "variable-length arrays (ARRAY[*]) are not supported by stc");
    Node *r = new_node(N_RANGE, t);
    r->lhs = expr(p);
    expect_p(p, "..");
    r->rhs = expr(p);
    return r;
}

static void var_decls(P *p, Vec *out, VarClass cls, bool constant, bool retain, Token *open, const char *end);

static TypeSpec *type_spec(P *p) {
    Token *t = cur(p);
    if (is_kw(t, "ARRAY")) {
        next(p);
        TypeSpec *s = new_spec(TS_ARRAY, t);
        expect_p(p, "[");
        do vec_push(&s->dims, range(p)); while (accept_p(p, ","));
        expect_p(p, "]");
        expect_kw(p, "OF");
        enter(p);
        s->elem = type_spec(p);
        leave(p);
        return s;
    }
    if (is_kw(t, "STRUCT")) {
        next(p);
        TypeSpec *s = new_spec(TS_STRUCT, t);
        var_decls(p, &s->fields, V_FIELD, false, false, t, "END_STRUCT");
        expect_end(p, t, "STRUCT", "END_STRUCT");
        return s;
    }
    if (is_p(t, "(")) {
        next(p);
        TypeSpec *s = new_spec(TS_ENUM, t);
        do vec_push(&s->values, ident(p, "enumeration value")); while (accept_p(p, ","));
        expect_p(p, ")");
        return s;
    }
    if (is_kw(t, "STRING")) {
        next(p);
        TypeSpec *s = new_spec(TS_STRING, t);
        s->name = "STRING";
        if (accept_p(p, "[")) { s->strlen_ = expr(p); expect_p(p, "]"); }
        else if (is_p(cur(p), "(") && peek(p, 1)->kind == TK_INT) { next(p); s->strlen_ = expr(p); expect_p(p, ")"); }
        return s;
    }
    if (t->kind != TK_IDENT) expected(p, "type name");
    if (is_one_of(t, unsupported_types)) fatal_at(t->loc, "type %s is not supported by stc", t->up);
    if (is_kw(t, "REF_TO") || is_kw(t, "POINTER") || is_kw(t, "REFERENCE"))
        fatal_at(t->loc, "pointers and references (%s) are not supported by stc", t->up);
    next(p);
    if (is_p(cur(p), "(")) {                 /* subrange: INT (lo..hi) */
        next(p);
        TypeSpec *s = new_spec(TS_SUBRANGE, t);
        s->name = t->up;
        Node *r = range(p);
        s->lo = r->lhs;
        s->hi = r->rhs;
        expect_p(p, ")");
        return s;
    }
    TypeSpec *s = new_spec(TS_NAME, t);
    s->name = t->up;
    return s;
}

static void var_decls(P *p, Vec *out, VarClass cls, bool constant, bool retain, Token *open, const char *end) {
    for (;;) {
        Token *t = cur(p);
        if (t->kind == TK_PRAGMA && t->ival) { next(p); continue; }   /* { } hint in a declaration: dropped */
        if (t->kind != TK_IDENT || is_reserved(t->up)) {
            if (is_kw(t, end)) return;
            if (t->kind == TK_IDENT && (kw_prefix(t, "END_") || !strncmp(t->up, "VAR", 3) ||
                                        is_kw(t, "FUNCTION") || is_kw(t, "FUNCTION_BLOCK") ||
                                        is_kw(t, "PROGRAM")))
                return;   /* caller reports the missing END_VAR */
            if (t->kind == TK_EOF) return;
            if (t->kind == TK_IDENT) fatal_at(t->loc, "expected variable name, found keyword '%s'", t->text);
            expected(p, "variable name");
        }
        Vec names = {0};
        Token *n1 = peek(p, 1);
        if (is_p(n1, ":=") || is_p(n1, "(") || is_p(n1, "[") || is_p(n1, "."))   /* a statement: the block was never closed */
            fatal_at(open->loc, "%s without %s", open->up, end);
        do vec_push(&names, ident(p, "variable name")); while (accept_p(p, ","));
        char *location = NULL;
        Loc locloc = {0};
        if (accept_kw(p, "AT")) {
            Token *l = cur(p);
            if (l->kind != TK_LOCATION) expected(p, "a location like %QW0");
            next(p);
            location = l->up;
            locloc = l->loc;
        }
        if (!is_p(cur(p), ":")) {
            if (is_p(cur(p), ";") || cur(p)->kind == TK_IDENT) expected(p, "':' and a type");
            expected(p, "':'");
        }
        next(p);
        TypeSpec *spec = type_spec(p);
        if (is_kw(cur(p), "R_EDGE") || is_kw(cur(p), "F_EDGE"))
            fatal_at(cur(p)->loc, "edge-detecting inputs (%s) are not supported by stc: use an %s_TRIG", cur(p)->up,
                     cur(p)->up[0] == 'R' ? "R" : "F");
        Node *init = NULL;
        if (accept_p(p, ":=")) init = init_value(p);
        expect_p(p, ";");
        for (int i = 0; i < names.n; i++) {
            Token *nt = names.v[i];
            VarDecl *d = xalloc(sizeof *d);
            d->name = nt->text;
            d->uname = nt->up;
            d->loc = nt->loc;
            d->cls = cls;
            d->constant = constant;
            d->retain = retain;
            d->location = location;
            d->locloc = locloc;
            d->spec = spec;
            d->init = init;
            vec_push(out, d);
        }
    }
}

/* VAR... blocks; returns false when the current token starts none. */
static bool var_block(P *p, Vec *out, bool global_ok) {
    Token *t = cur(p);
    VarClass cls;
    if (is_kw(t, "VAR")) cls = V_LOCAL;
    else if (is_kw(t, "VAR_INPUT")) cls = V_INPUT;
    else if (is_kw(t, "VAR_OUTPUT")) cls = V_OUTPUT;
    else if (is_kw(t, "VAR_IN_OUT")) cls = V_IN_OUT;
    else if (is_kw(t, "VAR_TEMP")) cls = V_TEMP;
    else if (is_kw(t, "VAR_EXTERNAL")) cls = V_EXTERNAL;
    else if (is_kw(t, "VAR_GLOBAL")) cls = V_GLOBAL;
    else if (is_kw(t, "VAR_ACCESS") || is_kw(t, "VAR_CONFIG"))
        fatal_at(t->loc, "%s is not supported", t->text);
    else return false;
    if (cls == V_GLOBAL && !global_ok) fatal_at(t->loc, "VAR_GLOBAL is only allowed in a CONFIGURATION or RESOURCE");
    next(p);
    bool constant = false, retain = false, non_retain = false;
    for (;;) {
        if (accept_kw(p, "CONSTANT")) constant = true;
        else if (accept_kw(p, "RETAIN")) retain = true, non_retain = false;
        else if (accept_kw(p, "NON_RETAIN")) retain = false, non_retain = true;
        else break;
    }
    int first = out->n;
    var_decls(p, out, cls, constant, retain, t, "END_VAR");
    for (int i = first; i < out->n; i++) ((VarDecl *)out->v[i])->non_retain = non_retain;
    /* matiec wants located variables in VAR blocks of their own, except
    ** in VAR_GLOBAL (the OpenPLC editor writes PLC_CYCLE_COUNT AT %ML1025
    ** and unlocated globals in one block) */
    for (int i = first + 1; cls != V_GLOBAL && i < out->n; i++) {
        VarDecl *a = out->v[first], *d = out->v[i];
        if (!a->location != !d->location)
            fatal_at(d->loc, "'%s': located and unlocated variables cannot share a VAR block; give the %s ones a block of their own",
                     d->name, a->location ? "unlocated" : "located");
    }
    expect_end(p, t, "VAR", "END_VAR");
    return true;
}

/* ---- statements ---- */
static void stmt_list(P *p, Vec *out);
static void case_list(P *p, Vec *out);

static bool at_case_label(P *p) {
    Token *t = cur(p);
    if (t->kind == TK_INT || is_p(t, "-")) return true;
    if (t->kind == TK_IDENT && !is_reserved(t->up)) {
        Token *n = peek(p, 1);
        if (is_p(n, ":") || is_p(n, ",") || is_p(n, "..")) return true;
        if (is_p(n, "#")) return true;
    }
    return false;
}

static Node *statement(P *p) {
    Token *t = cur(p);
    Node *n;
    if (t->kind == TK_PRAGMA) {
        next(p);
        n = new_node(S_PRAGMA, t);
        n->sval = t->sval;
        return n;
    }
    if (is_p(t, ";")) { next(p); return new_node(S_EMPTY, t); }
    if (is_kw(t, "IF")) {
        next(p);
        n = new_node(S_IF, t);
        Node *c = expr(p);
        expect_kw(p, "THEN");
        Vec *body = xalloc(sizeof(Vec));
        stmt_list(p, body);
        vec_push(&n->list, c);
        vec_push(&n->list2, body);
        while (is_kw(cur(p), "ELSIF")) {
            next(p);
            c = expr(p);
            expect_kw(p, "THEN");
            body = xalloc(sizeof(Vec));
            stmt_list(p, body);
            vec_push(&n->list, c);
            vec_push(&n->list2, body);
        }
        if (is_kw(cur(p), "ELSE")) {
            next(p);
            n->els = new_node(S_EMPTY, t);
            stmt_list(p, &n->els->list);
        }
        expect_end(p, t, "IF", "END_IF");
        accept_p(p, ";");
        return n;
    }
    if (is_kw(t, "CASE")) {
        next(p);
        n = new_node(S_CASE, t);
        n->lhs = expr(p);
        expect_kw(p, "OF");
        while (at_case_label(p)) {
            Node *item = new_node(S_CASEITEM, cur(p));
            do {
                Token *lt = cur(p);
                Node *lo = expr(p);
                if (accept_p(p, "..")) {
                    Node *r = new_node(N_RANGE, lt);
                    r->lhs = lo;
                    r->rhs = expr(p);
                    vec_push(&item->list, r);
                } else {
                    vec_push(&item->list, lo);
                }
            } while (accept_p(p, ","));
            expect_p(p, ":");
            case_list(p, &item->list2);
            vec_push(&n->list2, item);
        }
        if (is_kw(cur(p), "ELSE")) {
            next(p);
            n->els = new_node(S_EMPTY, t);
            stmt_list(p, &n->els->list);
        }
        expect_end(p, t, "CASE", "END_CASE");
        accept_p(p, ";");
        return n;
    }
    if (is_kw(t, "FOR")) {
        next(p);
        n = new_node(S_FOR, t);
        Token *v = ident(p, "FOR control variable");
        n->lhs = new_node(N_IDENT, v);
        n->lhs->name = v->text;
        n->lhs->uname = v->up;
        expect_p(p, ":=");
        n->rhs = expr(p);
        expect_kw(p, "TO");
        n->third = expr(p);
        if (accept_kw(p, "BY")) n->fourth = expr(p);
        expect_kw(p, "DO");
        stmt_list(p, &n->list);
        expect_end(p, t, "FOR", "END_FOR");
        accept_p(p, ";");
        return n;
    }
    if (is_kw(t, "WHILE")) {
        next(p);
        n = new_node(S_WHILE, t);
        n->lhs = expr(p);
        expect_kw(p, "DO");
        stmt_list(p, &n->list);
        expect_end(p, t, "WHILE", "END_WHILE");
        accept_p(p, ";");
        return n;
    }
    if (is_kw(t, "REPEAT")) {
        next(p);
        n = new_node(S_REPEAT, t);
        stmt_list(p, &n->list);
        if (!is_kw(cur(p), "UNTIL")) expect_end(p, t, "REPEAT", "END_REPEAT");
        next(p);
        n->lhs = expr(p);
        expect_end(p, t, "REPEAT", "END_REPEAT");
        accept_p(p, ";");
        return n;
    }
    if (is_kw(t, "ACTION")) fatal_at(t->loc, "actions (ACTION ... END_ACTION) are not supported by stc");
    if (is_one_of(t, sfc_words))
        fatal_at(t->loc, "an SFC element (%s) in a Structured Text body: a body is all SFC or all ST", t->up);
    unsupported_oop(t);
    if (is_kw(t, "CONTINUE") && is_p(peek(p, 1), ";"))
        fatal_at(t->loc, "CONTINUE is not supported by stc (nor by matiec): put the rest of the loop body under an IF");
    if (is_kw(t, "JMP") || (t->kind == TK_IDENT && !is_reserved(t->up) && is_p(peek(p, 1), ":") && !is_p(peek(p, 2), "=")))
        fatal_at(t->loc, "jumps and labels are not supported by stc");
    if (is_one_of(t, il_ops) && (peek(p, 1)->kind == TK_IDENT || peek(p, 1)->kind == TK_INT || peek(p, 1)->kind == TK_LOCATION))
        fatal_at(t->loc, "an IL instruction in a Structured Text body: a body is all IL or all ST");
    if (is_kw(t, "EXIT")) { next(p); expect_p(p, ";"); return new_node(S_EXIT, t); }
    if (is_kw(t, "RETURN")) { next(p); expect_p(p, ";"); return new_node(S_RETURN, t); }
    if (t->kind == TK_IDENT && !is_reserved(t->up)) {
        Node *target = primary(p);
        if (is_p(cur(p), ":=")) {
            Token *a = next(p);
            n = new_node(S_ASSIGN, a);
            n->start = target->start;
            n->lhs = target;
            n->rhs = expr(p);
            expect_p(p, ";");
            return n;
        }
        if ((target->kind == N_INDEX || target->kind == N_MEMBER) && is_p(cur(p), "(")) {
            /* an instance reached through an array or a member: a[i](...) */
            Token *open = next(p);
            Node *call = new_node(N_CALL, open);
            call->start = target->start;
            call->loc = target->start;
            call->lhs = target;
            call->name = "instance";
            call->uname = "";
            call_args(p, call);
            target = call;
        }
        if (target->kind == N_CALL) {
            n = new_node(S_CALL, t);
            n->lhs = target;
            expect_p(p, ";");
            return n;
        }
        expected(p, "':='");
    }
    if (t->kind == TK_EOF) expected(p, "statement");
    fatal_at(t->loc, "expected statement, found '%s'", desc(t));
}

static bool stmt_stop(P *p) {
    Token *t = cur(p);
    if (t->kind == TK_EOF) return true;
    if (t->kind != TK_IDENT) return false;
    return kw_prefix(t, "END_") || is_kw(t, "ELSE") || is_kw(t, "ELSIF") || is_kw(t, "UNTIL") ||
           is_kw(t, "FUNCTION") || is_kw(t, "FUNCTION_BLOCK") || is_kw(t, "PROGRAM") ||
           is_kw(t, "CONFIGURATION") || is_kw(t, "TYPE") || is_kw(t, "VAR") || kw_prefix(t, "VAR_");
}

static void stmts(P *p, Vec *out, bool in_case) {
    enter(p);
    while (!stmt_stop(p) && !(in_case && at_case_label(p))) vec_push(out, statement(p));
    leave(p);
}

static void stmt_list(P *p, Vec *out) { stmts(p, out, false); }
/* inside CASE, the next label ends the current list */
static void case_list(P *p, Vec *out) { stmts(p, out, true); }

/* ---- program organisation units ---- */
static void pou(P *p) {
    Token *t = next(p);
    Pou *u = xalloc(sizeof *u);
    u->kind = is_kw(t, "FUNCTION") ? POU_FUNCTION : is_kw(t, "FUNCTION_BLOCK") ? POU_FB : POU_PROGRAM;
    const char *what = u->kind == POU_FUNCTION ? "FUNCTION" : u->kind == POU_FB ? "FUNCTION_BLOCK" : "PROGRAM";
    const char *end = u->kind == POU_FUNCTION ? "END_FUNCTION" : u->kind == POU_FB ? "END_FUNCTION_BLOCK" : "END_PROGRAM";
    Token *name = ident(p, fmt("%s name", what));
    u->name = name->text;
    u->uname = name->up;
    u->loc = name->loc;
    u->from_lib = p->lib;
    unsupported_oop(cur(p));
    if (u->kind == POU_FUNCTION) {
        expect_p(p, ":");
        u->ret = type_spec(p);
    }
    for (;;) {   /* a { } pragma between VAR blocks is a declaration hint: dropped */
        if (cur(p)->kind == TK_PRAGMA && cur(p)->ival && peek(p, 1)->kind == TK_IDENT &&
            (is_kw(peek(p, 1), "VAR") || kw_prefix(peek(p, 1), "VAR_"))) { next(p); continue; }
        if (!var_block(p, &u->vars, false)) break;
    }
    if (il_body_starts(p->t, p->n, p->i)) p->i = il_body(p->t, p->n, p->i, u, p->u);
    else if (sfc_body_starts(p->t, p->n, p->i)) p->i = sfc_body(p->t, p->n, p->i, u, p->u);
    else stmt_list(p, &u->body);
    expect_end(p, t, what, end);
    vec_push(&p->u->pous, u);
}

/* the top-level declaration whose tokens are first..the one before cur */
static Item *add_item(P *p, ItemKind kind, void *decl, const char *uname, int first) {
    Item *it = xalloc(sizeof *it);
    it->kind = kind;
    it->decl = decl;
    it->uname = uname;
    it->first = &p->t[first];
    it->last = &p->t[p->i - 1];
    it->library = p->u->library;
    vec_push(&p->u->items, it);
    return it;
}

static void type_block(P *p) {
    Token *t = next(p);
    while (cur(p)->kind == TK_IDENT && !is_reserved(cur(p)->up)) {
        int first = p->i;
        Token *name = next(p);
        expect_p(p, ":");
        TypeDecl *d = xalloc(sizeof *d);
        d->name = name->text;
        d->uname = name->up;
        d->loc = name->loc;
        d->spec = type_spec(p);
        if (accept_p(p, ":=")) d->init = init_value(p);
        expect_p(p, ";");
        vec_push(&p->u->types, d);
        Item *it = add_item(p, IT_TYPE, d, d->uname, first);
        if (d->spec->kind == TS_ENUM)
            for (int i = 0; i < d->spec->values.n; i++) vec_push(&it->names, ((Token *)d->spec->values.v[i])->up);
    }
    expect_end(p, t, "TYPE", "END_TYPE");
}

static Node *task_param(P *p, Task *k) {
    Token *t = cur(p);
    (void)k;
    if (t->kind != TK_IDENT) expected(p, "task parameter");
    next(p);
    expect_p(p, ":=");
    Node *v = expr(p);
    v->name = t->up;
    return v;
}

static void resource_body(P *p, Resource *r) {
    for (;;) {
        Token *t = cur(p);
        if (is_kw(t, "VAR_GLOBAL")) { var_block(p, &r->globals, true); continue; }
        if (is_kw(t, "TASK")) {
            next(p);
            Task *k = xalloc(sizeof *k);
            Token *n = ident(p, "task name");
            k->name = n->text;
            k->uname = n->up;
            k->loc = n->loc;
            expect_p(p, "(");
            if (!is_p(cur(p), ")")) do {
                Token *pt = cur(p);
                Node *v = task_param(p, k);
                if (!strcmp(v->name, "INTERVAL")) k->interval = v;
                else if (!strcmp(v->name, "PRIORITY")) k->priority = v;
                else if (!strcmp(v->name, "SINGLE")) k->single = v;
                else fatal_at(pt->loc, "unknown task parameter '%s'", pt->text);
            } while (accept_p(p, ","));
            expect_p(p, ")");
            expect_p(p, ";");
            vec_push(&r->tasks, k);
            continue;
        }
        if (is_kw(t, "PROGRAM")) {
            next(p);
            ProgInst *pi = xalloc(sizeof *pi);
            if (accept_kw(p, "RETAIN")) pi->retain = true;
            else accept_kw(p, "NON_RETAIN");
            Token *n = ident(p, "program instance name");
            pi->name = n->text;
            pi->uname = n->up;
            pi->loc = n->loc;
            if (accept_kw(p, "WITH")) {
                Token *tk = ident(p, "task name");
                pi->task = tk->up;
                pi->taskloc = tk->loc;
            }
            expect_p(p, ":");
            Token *pn = ident(p, "program type name");
            pi->pou = pn->up;
            pi->pouloc = pn->loc;
            if (is_p(cur(p), "(")) fatal_at(cur(p)->loc, "program instance parameters are not supported");
            expect_p(p, ";");
            vec_push(&r->progs, pi);
            continue;
        }
        return;
    }
}

static void configuration(P *p) {
    Token *t = next(p);
    Config *c = xalloc(sizeof *c);
    Token *n = ident(p, "configuration name");
    c->name = n->text;
    c->uname = n->up;
    c->loc = n->loc;
    while (is_kw(cur(p), "VAR_GLOBAL")) var_block(p, &c->globals, true);
    if (!is_kw(cur(p), "RESOURCE")) {
        if (is_kw(cur(p), "TASK") || is_kw(cur(p), "PROGRAM")) {
            /* IEC 61131-3's single resource: tasks and program instances
            ** right in the configuration. As matiec: one resource named
            ** RESOURCE in C, none in the variables' paths (CONFIG.INST.X). */
            Resource *r = xalloc(sizeof *r);
            r->name = r->uname = "RESOURCE";
            r->loc = cur(p)->loc;
            r->single = true;
            resource_body(p, r);
            vec_push(&c->resources, r);
        }
        expect_end(p, t, "CONFIGURATION", "END_CONFIGURATION");
        vec_push(&p->u->configs, c);
        return;
    }
    while (is_kw(cur(p), "RESOURCE")) {
        Token *rt = next(p);
        Resource *r = xalloc(sizeof *r);
        Token *rn = ident(p, "resource name");
        r->name = rn->text;
        r->uname = rn->up;
        r->loc = rn->loc;
        expect_kw(p, "ON");
        ident(p, "processor type name");
        resource_body(p, r);
        expect_end(p, rt, "RESOURCE", "END_RESOURCE");
        accept_p(p, ";");
        vec_push(&c->resources, r);
    }
    expect_end(p, t, "CONFIGURATION", "END_CONFIGURATION");
    vec_push(&p->u->configs, c);
}

Node *parse_il_operand(Token *toks, int n, int *i) {
    P p = {toks, n, *i, 0, NULL, false};
    Node *e = unary(&p);
    *i = p.i;
    return e;
}

void parse_il_call_args(Token *toks, int n, int *i, Node *call) {
    P p = {toks, n, *i, 0, NULL, false};
    call_args(&p, call);
    *i = p.i;
}

Node *parse_expr_at(Token *toks, int n, int *i) {
    P p = {toks, n, *i, 0, NULL, false};
    Node *e = expr(&p);
    *i = p.i;
    return e;
}

void parse_stmts_at(Token *toks, int n, int *i, Vec *out) {
    P p = {toks, n, *i, 0, NULL, false};
    stmt_list(&p, out);
    *i = p.i;
}

void parse_unit(Unit *u, const Source *src, bool from_lib) {
    int n;
    Token *toks = lex(src, &n);
    P p = {toks, n, 0, 0, u, from_lib};
    for (;;) {
        Token *t = cur(&p);
        int first = p.i;
        if (t->kind == TK_EOF) break;
        if (t->kind == TK_PRAGMA) {
            next(&p);
            vec_push(&u->pragmas, t);
            add_item(&p, IT_PRAGMA, t, NULL, first);
            continue;
        }
        if (is_kw(t, "FUNCTION") || is_kw(t, "FUNCTION_BLOCK") || is_kw(t, "PROGRAM")) {
            pou(&p);
            Pou *d = u->pous.v[u->pous.n - 1];
            add_item(&p, IT_POU, d, d->uname, first);
        } else if (is_kw(t, "TYPE")) type_block(&p);
        else if (is_kw(t, "CONFIGURATION")) {
            configuration(&p);
            Config *d = u->configs.v[u->configs.n - 1];
            add_item(&p, IT_CONFIG, d, d->uname, first);
        } else if (is_p(t, ";")) next(&p);
        else {
            unsupported_oop(t);
            if (is_one_of(t, sfc_words)) fatal_at(t->loc, "Sequential Function Chart (%s) is not supported by stc", t->up);
            expected(&p, "FUNCTION, FUNCTION_BLOCK, PROGRAM, TYPE or CONFIGURATION");
        }
    }
}
