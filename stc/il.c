/* Instruction List (IL): a POU body written in IL, lowered into the same
** statement tree as Structured Text, so the type checker and the code
** generator treat both alike.
**
** The current result (CR, the accumulator) is kept as an expression: LD a,
** ADD b, ST c becomes c := a + b. After ST x the CR is x again (re-read, so
** a function call is not evaluated twice). Where the CR decides something
** (S, R, JMPC, CALC, RETC and their N forms) it is BOOL and is first stored
** in a hidden BOOL temporary, so later instructions read the value it had
** then. A parenthesis AND( ... ) saves the operator and the CR and applies
** them at ')'. Jumps and labels become S_GOTO / S_LABEL (a C goto).
**
** IL is line-oriented: an operand belongs to its instruction when it is on
** the same line. After a label or a jump the CR is undefined (as the
** standard leaves it): the next instruction must load it.
*/
#include "stc.h"

#include <string.h>

typedef struct {
    Token *t;
    int n, i;
    Pou *pou;
    Unit *u;
    Node *cr;          /* current result, NULL when undefined */
    Token *crtok;      /* the instruction that loaded it */
    const char *why;   /* why the CR is undefined */
    bool in_part;      /* an SFC action or transition: no RET */
    Vec *out;          /* statements of the current level */
    bool has_tmp;
    Vec labels;        /* Node* S_LABEL */
    Vec gotos;         /* Node* S_GOTO */
} IL;

#define IL_TMP "__IL_CR"

static const char *const il_all_ops[] = {
    "LD", "LDN", "ST", "STN", "S", "R", "S1", "R1", "CLK", "CU", "CD", "PV", "IN", "PT",
    "AND", "ANDN", "OR", "ORN", "XOR", "XORN", "NOT", "ADD", "SUB", "MUL", "DIV", "MOD",
    "GT", "GE", "EQ", "NE", "LE", "LT", "JMP", "JMPC", "JMPCN", "CAL", "CALC", "CALCN",
    "RET", "RETC", "RETCN", NULL};

static bool one_of(const char *up, const char *const *names) {
    for (; *names; names++)
        if (!strcmp(up, *names)) return true;
    return false;
}

static Token *cur(IL *il) { return &il->t[il->i]; }
static bool is_p(Token *t, const char *s) { return t->kind == TK_PUNCT && !strcmp(t->up, s); }
static bool same_line(Token *a, Token *b) { return b->kind != TK_EOF && a->loc.line == b->loc.line; }

bool il_body_starts(Token *toks, int n, int i) {
    Token *t = &toks[i], *nx = &toks[i + 1 < n ? i + 1 : n - 1];
    if (t->kind != TK_IDENT) return false;
    if (!strncmp(t->up, "END_", 4)) return false;
    if (is_p(nx, ":"))          /* a label, then an instruction (not an ST statement) */
        return !is_reserved(t->up) && i + 2 < n && il_body_starts(toks, n, i + 2);
    if (!one_of(t->up, il_all_ops)) return false;
    /* ST statements that start with such a name: S := 1; R(...); S.x := ... */
    return !(is_p(nx, ":=") || is_p(nx, ".") || is_p(nx, "[") || is_p(nx, "(") || is_p(nx, "=>"));
}

static Node *node(NodeKind k, Token *t) {
    Node *n = xalloc(sizeof *n);
    n->kind = k;
    n->loc = n->start = t->loc;
    return n;
}

/* a fresh copy: every use of the CR is a tree of its own for the type checker */
static Node *clone(Node *n) {
    if (!n) return NULL;
    Node *c = xalloc(sizeof *c);
    *c = *n;
    c->lhs = clone(n->lhs);
    c->rhs = clone(n->rhs);
    c->third = clone(n->third);
    c->fourth = clone(n->fourth);
    c->list = (Vec){0};
    for (int i = 0; i < n->list.n; i++) vec_push(&c->list, clone(n->list.v[i]));
    return c;
}

static Node *ident_node(Token *t, const char *name) {
    Node *n = node(N_IDENT, t);
    n->name = xstrdup(name);
    n->uname = upcase(name);
    return n;
}

static Node *unary_node(Token *t, const char *op, Node *e) {
    Node *n = node(N_UNARY, t);
    n->op = op;
    n->lhs = e;
    n->start = e->start;
    n->depth = e->depth + 1;
    return n;
}

static Node *binary_node(Token *t, const char *op, Node *l, Node *r) {
    Node *n = node(N_BINARY, t);
    n->op = op;
    n->lhs = l;
    n->rhs = r;
    n->start = l->start;
    n->depth = (l->depth > r->depth ? l->depth : r->depth) + 1;
    if (n->depth > 1600) fatal_at(t->loc, "IL sequence too long for one expression: store the result with ST");
    return n;
}

static void emit(IL *il, Node *s) { vec_push(il->out, s); }

static Node *need_cr(IL *il, Token *t) {
    if (!il->cr)
        fatal_at(t->loc, "'%s' needs a current result: load one with LD first%s%s", t->text, il->why ? "; " : "",
                 il->why ? il->why : "");
    return clone(il->cr);
}

/* the BOOL CR kept in the hidden temporary; returns an expression reading it */
static Node *cr_bool(IL *il, Token *t) {
    Node *v = need_cr(il, t);
    if (v->kind == N_IDENT && !strcmp(v->uname, IL_TMP)) return v;
    for (int k = 0; k < il->pou->vars.n && !il->has_tmp; k++)
        il->has_tmp = !strcmp(((VarDecl *)il->pou->vars.v[k])->uname, IL_TMP);
    if (!il->has_tmp) {
        VarDecl *d = xalloc(sizeof *d);
        d->name = d->uname = IL_TMP;
        d->loc = t->loc;
        d->cls = V_TEMP;
        d->spec = xalloc(sizeof *d->spec);
        d->spec->kind = TS_NAME;
        d->spec->loc = t->loc;
        d->spec->name = "BOOL";
        vec_push(&il->pou->vars, d);
        il->has_tmp = true;
    }
    /* IF cr THEN tmp := TRUE; ELSE tmp := FALSE: a CR that is not BOOL is
       reported as a condition, at the instruction */
    v->start = t->loc;
    Node *n = node(S_IF, t);
    Vec *body = xalloc(sizeof(Vec));
    for (int k = 1; k >= 0; k--) {
        Node *a = node(S_ASSIGN, t);
        a->lhs = ident_node(t, IL_TMP);
        a->rhs = node(N_BOOL, t);
        a->rhs->ival = (uint64_t)k;
        if (k) vec_push(body, a);
        else { n->els = node(S_EMPTY, t); vec_push(&n->els->list, a); }
    }
    vec_push(&n->list, v);
    vec_push(&n->list2, body);
    emit(il, n);
    il->cr = ident_node(t, IL_TMP);
    return ident_node(t, IL_TMP);
}

static Node *if_node(Token *t, Node *cond, Node *then) {
    Node *n = node(S_IF, t);
    Vec *body = xalloc(sizeof(Vec));
    vec_push(body, then);
    vec_push(&n->list, cond);
    vec_push(&n->list2, body);
    return n;
}

static Node *operand(IL *il, Token *op) {
    if (!same_line(op, cur(il))) fatal_at(op->loc, "'%s' needs an operand on the same line", op->text);
    return parse_il_operand(il->t, il->n, &il->i);
}

/* is the operand (a plain name) declared as a function block instance? */
static bool is_fb_instance(IL *il, Node *e) {
    if (e->kind != N_IDENT) return false;
    for (int i = 0; i < il->pou->vars.n; i++) {
        VarDecl *d = il->pou->vars.v[i];
        if (strcmp(d->uname, e->uname)) continue;
        if (!d->spec || d->spec->kind != TS_NAME) return false;
        char *tn = upcase(d->spec->name);
        for (int k = 0; k < il->u->pous.n; k++) {
            Pou *p = il->u->pous.v[k];
            if (p->kind == POU_FB && !strcmp(p->uname, tn)) return true;
        }
        return false;
    }
    return false;
}

static Node *call_stmt(Token *t, Node *call) {
    Node *s = node(S_CALL, t);
    s->lhs = call;
    s->start = call->start;
    return s;
}

/* CAL inst, CAL inst(args), and the implicit calls S1 inst, CLK inst, ... */
static Node *fb_call(IL *il, Token *op, Node *inst, const char *param, Node *val) {
    Node *call = node(N_CALL, op);
    call->start = inst->start;
    call->loc = inst->start;
    if (inst->kind == N_CALL) return inst;
    if (inst->kind == N_IDENT) {
        call->name = inst->name;
        call->uname = inst->uname;
    } else {
        call->lhs = inst;
        call->name = "instance";
        call->uname = "";
    }
    if (param) {
        Node *a = node(N_ARG, op);
        a->name = xstrdup(param);
        a->uname = xstrdup(param);
        a->lhs = val;
        vec_push(&call->list, a);
    }
    (void)il;
    return call;
}

static const char *bin_op(const char *up) {
    static const char *const map[][2] = {
        {"AND", "AND"}, {"OR", "OR"}, {"XOR", "XOR"}, {"ADD", "+"}, {"SUB", "-"}, {"MUL", "*"},
        {"DIV", "/"}, {"MOD", "MOD"}, {"GT", ">"}, {"GE", ">="}, {"EQ", "="}, {"NE", "<>"},
        {"LE", "<="}, {"LT", "<"}, {"&", "AND"}};
    for (size_t k = 0; k < sizeof map / sizeof map[0]; k++)
        if (!strcmp(up, map[k][0])) return map[k][1];
    return NULL;
}

static void instructions(IL *il, int depth, Token *open);

/* does expression e read the variable or instance named up? */
static bool mentions(Node *e, const char *up) {
    if (!e) return false;
    if (e->kind == N_IDENT && !strcmp(e->uname, up)) return true;
    if (mentions(e->lhs, up) || mentions(e->rhs, up) || mentions(e->third, up) || mentions(e->fourth, up)) return true;
    for (int k = 0; k < e->list.n; k++)
        if (mentions(e->list.v[k], up)) return true;
    return false;
}

/* the root name of an instance operand: inst, inst.sub, arr[i] */
static const char *root_name(Node *e) {
    while (e && e->kind != N_IDENT && !(e->kind == N_CALL && !e->lhs)) e = e->lhs;
    return e && e->uname ? e->uname : "";
}

/* after a call of inst, a CR that reads inst is stale: make it undefined */
static void after_call(IL *il, Node *inst) {
    if (il->cr && mentions(il->cr, root_name(inst))) {
        il->cr = NULL;
        il->why = "the call before may have changed what it read";
    }
}

static Node *label_ref(IL *il, Token *op) {
    Token *l = cur(il);
    if (!same_line(op, l) || l->kind != TK_IDENT) fatal_at(op->loc, "'%s' needs a label on the same line", op->text);
    il->i++;
    Node *g = node(S_GOTO, l);
    g->name = l->text;
    g->uname = l->up;
    vec_push(&il->gotos, g);
    return g;
}

/* one instruction at cur(il) */
static void instruction(IL *il, int depth) {
    Token *t = cur(il);
    il->i++;
    char *up = t->up;
    if (t->kind == TK_IDENT && is_p(cur(il), ":") && !one_of(up, il_all_ops)) {   /* label */
        il->i++;
        for (int k = 0; k < il->labels.n; k++) {
            Node *o = il->labels.v[k];
            if (!strcmp(o->uname, up)) fatal_at(t->loc, "duplicate label '%s'", t->text);
        }
        if (depth) fatal_at(t->loc, "a label cannot be inside ( )");
        Node *l = node(S_LABEL, t);
        l->name = t->text;
        l->uname = up;
        vec_push(&il->labels, l);
        emit(il, l);
        il->cr = NULL;
        il->why = "a label leaves it undefined";
        return;
    }
    if (t->kind != TK_IDENT) fatal_at(t->loc, "expected an IL instruction, found '%s'", t->text);
    if (depth && (!strncmp(up, "ST", 2) || !strcmp(up, "S") || !strcmp(up, "R") || !strncmp(up, "CAL", 3) ||
                  !strcmp(up, "S1") || !strcmp(up, "R1") || !strcmp(up, "CLK") || !strcmp(up, "CU") ||
                  !strcmp(up, "CD") || !strcmp(up, "PV") || !strcmp(up, "IN") || !strcmp(up, "PT")))
        fatal_at(t->loc, "'%s' cannot be inside ( ): store or call after the ')'", t->text);
    if (!strcmp(up, "LD") || !strcmp(up, "LDN")) {
        Node *v = operand(il, t);
        il->cr = up[2] ? unary_node(t, "NOT", v) : v;
        il->crtok = t;
        return;
    }
    if (!strcmp(up, "ST") || !strcmp(up, "STN")) {
        Node *cr = need_cr(il, t);
        Node *dst = operand(il, t);
        Node *a = node(S_ASSIGN, t);
        a->lhs = dst;
        a->start = dst->start;
        a->rhs = up[2] ? unary_node(t, "NOT", cr) : cr;
        a->rhs->start = t->loc;   /* a type mismatch is reported at the ST */
        emit(il, a);
        il->cr = up[2] ? unary_node(t, "NOT", clone(dst)) : clone(dst);
        return;
    }
    if (!strcmp(up, "S1") || !strcmp(up, "R1") || !strcmp(up, "CLK") || !strcmp(up, "CU") || !strcmp(up, "CD") ||
        !strcmp(up, "PV") || !strcmp(up, "IN") || !strcmp(up, "PT")) {
        Node *cr = need_cr(il, t);
        Node *inst = operand(il, t);
        emit(il, call_stmt(t, fb_call(il, t, inst, up, cr)));
        after_call(il, inst);
        return;
    }
    if (!strcmp(up, "S") || !strcmp(up, "R")) {
        if (!same_line(t, cur(il))) fatal_at(t->loc, "'%s' needs an operand on the same line", t->text);
        int save = il->i;
        Node *dst = operand(il, t);
        if (is_fb_instance(il, dst)) {
            il->i = save;
            Node *cr = need_cr(il, t);
            dst = operand(il, t);
            emit(il, call_stmt(t, fb_call(il, t, dst, up, cr)));
            after_call(il, dst);
            return;
        }
        Node *c = cr_bool(il, t);
        Node *a = node(S_ASSIGN, t);
        a->lhs = dst;
        a->start = dst->start;
        a->rhs = node(N_BOOL, t);
        a->rhs->ival = up[0] == 'S';
        emit(il, if_node(t, c, a));
        return;
    }
    if ((!strcmp(up, "NOT") || !strncmp(up, "RET", 3)) && same_line(t, cur(il)) && !is_p(cur(il), ";") &&
        !is_p(cur(il), ")"))
        fatal_at(cur(il)->loc, "'%s' takes no operand", t->text);
    if (!strcmp(up, "NOT")) {
        il->cr = unary_node(t, "NOT", need_cr(il, t));
        return;
    }
    if (!strcmp(up, "JMP") || !strcmp(up, "JMPC") || !strcmp(up, "JMPCN")) {
        if (depth) fatal_at(t->loc, "a jump cannot be inside ( )");
        Node *c = up[3] ? cr_bool(il, t) : NULL;
        Node *g = label_ref(il, t);
        if (!c) { emit(il, g); il->cr = NULL; il->why = "a JMP leaves it undefined"; return; }
        emit(il, if_node(t, up[4] ? unary_node(t, "NOT", c) : c, g));
        return;
    }
    if (!strcmp(up, "RET") || !strcmp(up, "RETC") || !strcmp(up, "RETCN")) {
        if (depth) fatal_at(t->loc, "RET cannot be inside ( )");
        if (il->in_part) fatal_at(t->loc, "RET cannot end an SFC action or transition");
        Node *c = up[3] ? cr_bool(il, t) : NULL;
        Node *r = node(S_RETURN, t);
        if (!c) { emit(il, r); il->cr = NULL; il->why = "RET leaves it undefined"; return; }
        emit(il, if_node(t, up[4] ? unary_node(t, "NOT", c) : c, r));
        return;
    }
    if (!strcmp(up, "CAL") || !strcmp(up, "CALC") || !strcmp(up, "CALCN")) {
        Node *c = up[3] ? cr_bool(il, t) : NULL;
        if (!same_line(t, cur(il))) fatal_at(t->loc, "'%s' needs a function block instance on the same line", t->text);
        Node *inst = parse_il_operand(il->t, il->n, &il->i);
        if (inst->kind != N_CALL) inst = fb_call(il, t, inst, NULL, NULL);
        Node *s = call_stmt(t, inst);
        emit(il, c ? if_node(t, up[4] ? unary_node(t, "NOT", c) : c, s) : s);
        after_call(il, inst->kind == N_CALL && inst->lhs ? inst->lhs : inst);
        return;
    }
    /* operators with an optional N and an optional deferred '(' */
    char base[16] = "";
    bool neg = false;
    size_t len = strlen(up);
    if (len < sizeof base) strcpy(base, up);
    if (!bin_op(base) && len > 1 && len < sizeof base && up[len - 1] == 'N') {
        base[len - 1] = 0;
        neg = bin_op(base) && (!strcmp(base, "AND") || !strcmp(base, "OR") || !strcmp(base, "XOR"));
        if (!neg) strcpy(base, up);
    }
    const char *op = bin_op(base);
    if (op) {
        Node *left = need_cr(il, t);
        Node *right;
        if (is_p(cur(il), "(") && same_line(t, cur(il))) {      /* deferred: OP( ... ) */
            Token *open = cur(il);
            if (depth >= 400) fatal_at(open->loc, "nesting too deep (more than 400 levels)");
            il->i++;
            Node *saved = il->cr;
            Token *savedtok = il->crtok;
            il->cr = NULL;
            if (same_line(open, cur(il)) && !is_p(cur(il), ")")) {   /* AND( x  is AND( LD x */
                il->cr = parse_il_operand(il->t, il->n, &il->i);
                il->crtok = open;
            }
            instructions(il, depth + 1, open);
            Token *close = cur(il);
            il->i++;                                                  /* the ')' */
            right = need_cr(il, close);
            il->cr = saved;
            il->crtok = savedtok;
        } else {
            right = operand(il, t);
        }
        if (neg) right = unary_node(t, "NOT", right);
        il->cr = binary_node(t, op, left, right);
        return;
    }
    if (one_of(up, il_all_ops) || is_reserved(up))
        fatal_at(t->loc, "'%s' cannot start an IL instruction here", t->text);
    /* a function call: the CR is its first input, the operands the others */
    Node *call = node(N_CALL, t);
    call->name = t->text;
    call->uname = up;
    if (is_p(cur(il), "(") && same_line(t, cur(il))) {        /* formal call: F(IN1 := ..., ...) */
        il->i++;
        parse_il_call_args(il->t, il->n, &il->i, call);
    } else {
        Node *a = node(N_ARG, t);
        a->lhs = need_cr(il, t);
        vec_push(&call->list, a);
        while (same_line(t, cur(il))) {
            Node *arg = node(N_ARG, cur(il));
            arg->lhs = parse_il_operand(il->t, il->n, &il->i);
            arg->loc = arg->lhs->start;
            vec_push(&call->list, arg);
            if (!(is_p(cur(il), ",") && same_line(t, cur(il)))) break;
            il->i++;
            if (!same_line(t, cur(il))) fatal_at(cur(il)->loc, "expected an operand after ','");
        }
    }
    il->cr = call;
    il->crtok = t;
}

static bool at_end(IL *il) {
    Token *t = cur(il);
    return t->kind == TK_EOF || (t->kind == TK_IDENT && !strncmp(t->up, "END_", 4));
}

static void instructions(IL *il, int depth, Token *open) {
    while (!at_end(il)) {
        if (is_p(cur(il), ")")) {
            if (!depth) fatal_at(cur(il)->loc, "')' without a deferred operation '('");
            return;
        }
        if (cur(il)->kind == TK_PRAGMA) {
            Node *s = node(S_PRAGMA, cur(il));
            s->sval = cur(il)->sval;
            emit(il, s);
            il->i++;
            continue;
        }
        instruction(il, depth);
        if (is_p(cur(il), ";")) il->i++;   /* tolerated, as in matiec's ST-like layouts */
    }
    if (depth) fatal_at(open->loc, "'(' is never closed by ')'");
}

int il_lower(Token *toks, int n, int i, Pou *pou, Unit *u, Vec *out, const char *prefix, Node **cr) {
    IL il = {.t = toks, .n = n, .i = i, .pou = pou, .u = u, .out = out, .in_part = prefix != NULL};
    instructions(&il, 0, NULL);
    for (int k = 0; k < il.gotos.n; k++) {
        Node *g = il.gotos.v[k];
        Node *to = NULL;
        for (int j = 0; j < il.labels.n && !to; j++) {
            Node *l = il.labels.v[j];
            if (!strcmp(l->uname, g->uname)) to = l;
        }
        if (!to) fatal_at(g->loc, "unknown label '%s'", g->name);
        to->ival = 1;   /* jumped to: the C label is emitted */
    }
    if (prefix) {   /* C labels are per function: those of an action or a transition get its name */
        for (int k = 0; k < il.gotos.n; k++) {
            Node *g = il.gotos.v[k];
            g->uname = fmt("%s_%s", prefix, g->uname);
        }
        for (int k = 0; k < il.labels.n; k++) {
            Node *l = il.labels.v[k];
            l->uname = fmt("%s_%s", prefix, l->uname);
        }
    }
    if (cr) *cr = need_cr(&il, cur(&il));
    return il.i;
}

int il_body(Token *toks, int n, int i, Pou *pou, Unit *u) {
    return il_lower(toks, n, i, pou, u, &pou->body, NULL, NULL);
}
