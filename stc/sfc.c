/* Sequential Function Chart (SFC) in its textual form: a PROGRAM or
** FUNCTION_BLOCK body of INITIAL_STEP/STEP, TRANSITION and ACTION blocks,
** lowered into Structured Text statements that do, each scan, what
** matiec's generated C does:
**
**   1. every active step's T grows by the time since the last scan, and
**      its X of the previous scan is kept (to see activations);
**   2. every transition whose source steps are all active tests its
**      condition; the fired ones deactivate their sources, then activate
**      their targets (T restarts at 0): one evolution per scan;
**   3. the associations of each step: N while the step is active, S and R
**      store and clear the action, P on the scan the step became active;
**   4. an ACTION block runs on a scan its state is TRUE; an association
**      naming a BOOL variable instead sets it (N, P: to the state; S, R:
**      TRUE and FALSE).
**
** Steps are variables of the structure __SFC_STEP (X, T, and P, the X of
** the previous scan), so step.X and step.T read as members. The glue is
** written as ST text and parsed; the user's conditions and action bodies are
** spliced in as parsed from the source, so their diagnostics point there.
*/
#include "stc.h"

#include <string.h>

typedef struct { char *uname, *name; Loc loc; bool initial; Vec assoc; } Step;
typedef struct { char *action; char qual; Loc loc; Node *time; } Assoc;
typedef struct { Vec from, to; Node *cond; Vec pre; Loc loc; } Trans;
typedef struct { char *uname, *name; Loc loc; Vec body; bool block; bool has_sr; } Action;

typedef struct {
    Token *t;
    int n, i;
    Vec steps, trans, actions;
    Pou *pou;
    Unit *u;
} SFC;

static Token *cur(SFC *s) { return &s->t[s->i]; }
static bool is_kw(Token *t, const char *kw) { return t->kind == TK_IDENT && !strcmp(t->up, kw); }
static bool is_p(Token *t, const char *p) { return t->kind == TK_PUNCT && !strcmp(t->up, p); }

bool sfc_body_starts(Token *toks, int n, int i) {
    (void)n;
    Token *t = &toks[i];
    return is_kw(t, "INITIAL_STEP") || is_kw(t, "STEP") || is_kw(t, "TRANSITION") || is_kw(t, "ACTION");
}

static Token *expect_p(SFC *s, const char *p) {
    Token *t = cur(s);
    if (!is_p(t, p)) fatal_at(t->loc, "expected '%s', found '%s'", p, t->kind == TK_EOF ? "end of file" : t->text);
    s->i++;
    return t;
}
static Token *expect_kw(SFC *s, const char *kw) {
    Token *t = cur(s);
    if (!is_kw(t, kw)) fatal_at(t->loc, "expected %s, found '%s'", kw, t->kind == TK_EOF ? "end of file" : t->text);
    s->i++;
    return t;
}
static Token *name(SFC *s, const char *what) {
    Token *t = cur(s);
    if (t->kind != TK_IDENT || is_reserved(t->up))
        fatal_at(t->loc, "expected %s, found '%s'", what, t->kind == TK_EOF ? "end of file" : t->text);
    s->i++;
    return t;
}

static Step *find_step(SFC *s, const char *up) {
    for (int k = 0; k < s->steps.n; k++) {
        Step *st = s->steps.v[k];
        if (!strcmp(st->uname, up)) return st;
    }
    return NULL;
}
static Action *find_action(SFC *s, const char *up) {
    for (int k = 0; k < s->actions.n; k++) {
        Action *a = s->actions.v[k];
        if (!strcmp(a->uname, up)) return a;
    }
    return NULL;
}
static Action *action(SFC *s, Token *t) {
    Action *a = find_action(s, t->up);
    if (!a) {
        a = xalloc(sizeof *a);
        a->uname = t->up;
        a->name = t->text;
        a->loc = t->loc;
        vec_push(&s->actions, a);
    }
    return a;
}

static void step(SFC *s) {
    Token *kw = cur(s);
    s->i++;
    Token *nm = name(s, "step name");
    if (find_step(s, nm->up)) fatal_at(nm->loc, "duplicate step '%s'", nm->text);
    Step *st = xalloc(sizeof *st);
    st->uname = nm->up;
    st->name = nm->text;
    st->loc = nm->loc;
    st->initial = is_kw(kw, "INITIAL_STEP");
    vec_push(&s->steps, st);
    expect_p(s, ":");
    while (!is_kw(cur(s), "END_STEP")) {
        Token *an = name(s, "action name or END_STEP");
        Assoc *as = xalloc(sizeof *as);
        as->action = an->up;
        as->loc = an->loc;
        as->qual = 'N';
        if (is_p(cur(s), "(")) {
            s->i++;
            Token *q = name(s, "action qualifier");
            if (strcmp(q->up, "N") && strcmp(q->up, "S") && strcmp(q->up, "R") && strcmp(q->up, "P") &&
                strcmp(q->up, "L") && strcmp(q->up, "D"))
                fatal_at(q->loc, "action qualifier %s is not supported by stc (N, S, R, P, L and D are)", q->up);
            as->qual = q->up[0];
            if (as->qual == 'L' || as->qual == 'D') {
                if (!is_p(cur(s), ",")) fatal_at(cur(s)->loc, "qualifier %s needs a time: %s(%s, T#1s)", q->up, an->text, q->up);
                s->i++;
                as->time = parse_expr_at(s->t, s->n, &s->i);
            }
            expect_p(s, ")");
        }
        Action *a = action(s, an);
        if (as->qual == 'S' || as->qual == 'R') a->has_sr = true;
        vec_push(&st->assoc, as);
        expect_p(s, ";");
    }
    s->i++;
    if (is_p(cur(s), ";")) s->i++;
}

static void step_list(SFC *s, Vec *out) {
    if (is_p(cur(s), "(")) {
        s->i++;
        do vec_push(out, name(s, "step name")); while (is_p(cur(s), ",") && ++s->i);
        expect_p(s, ")");
    } else {
        vec_push(out, name(s, "step name"));
    }
}

static void transition(SFC *s) {
    Token *kw = cur(s);
    s->i++;
    Trans *tr = xalloc(sizeof *tr);
    tr->loc = kw->loc;
    if (!is_kw(cur(s), "FROM") && !is_p(cur(s), "(")) name(s, "transition name");
    if (is_p(cur(s), "(")) {      /* (PRIORITY := n): matiec ignores it too */
        while (!is_p(cur(s), ")") && cur(s)->kind != TK_EOF) s->i++;
        expect_p(s, ")");
    }
    expect_kw(s, "FROM");
    step_list(s, &tr->from);
    expect_kw(s, "TO");
    step_list(s, &tr->to);
    if (is_p(cur(s), ":") && il_body_starts(s->t, s->n, s->i + 1)) {   /* the condition in IL: the last CR */
        s->i++;
        s->i = il_lower(s->t, s->n, s->i, s->pou, s->u, &tr->pre, fmt("__TR%d", s->trans.n), &tr->cond);
    } else {
        if (!is_p(cur(s), ":="))
            fatal_at(cur(s)->loc, "expected ':=' and the transition's condition, or ':' and IL");
        s->i++;
        tr->cond = parse_expr_at(s->t, s->n, &s->i);
        expect_p(s, ";");
    }
    expect_kw(s, "END_TRANSITION");
    if (is_p(cur(s), ";")) s->i++;
    vec_push(&s->trans, tr);
}

static void action_block(SFC *s) {
    s->i++;
    Token *nm = name(s, "action name");
    Action *a = find_action(s, nm->up);
    if (a && a->block) fatal_at(nm->loc, "duplicate action '%s'", nm->text);
    if (!a) a = action(s, nm);
    a->block = true;
    a->loc = nm->loc;
    expect_p(s, ":");
    if (il_body_starts(s->t, s->n, s->i)) s->i = il_lower(s->t, s->n, s->i, s->pou, s->u, &a->body, fmt("__A_%s", a->uname), NULL);
    else parse_stmts_at(s->t, s->n, &s->i, &a->body);
    expect_kw(s, "END_ACTION");
    if (is_p(cur(s), ";")) s->i++;
}

/* ---- lowering ---- */
static Vec glue(const char *text) {
    if (!text) return (Vec){0};
    Source *src = xalloc(sizeof *src);
    src->name = "<SFC>";
    src->text = text;
    src->len = strlen(text);
    int n;
    Token *toks = lex(src, &n);
    Vec out = {0};
    int i = 0;
    parse_stmts_at(toks, n, &i, &out);
    return out;
}

static void append(Vec *body, const char *text) {
    Vec v = glue(text);
    for (int k = 0; k < v.n; k++) vec_push(body, v.v[k]);
}

static void add_var(Pou *p, const char *nm, const char *type, Loc loc) {
    VarDecl *d = xalloc(sizeof *d);
    d->name = xstrdup(nm);
    d->uname = upcase(nm);
    d->loc = loc;
    d->cls = V_LOCAL;
    d->spec = xalloc(sizeof *d->spec);
    d->spec->kind = TS_NAME;
    d->spec->loc = loc;
    d->spec->name = xstrdup(type);
    vec_push(&p->vars, d);
}

static void lower(SFC *s, Pou *p, Unit *u) {
    bool have_type = false;
    for (int k = 0; k < u->types.n; k++) {
        TypeDecl *d = u->types.v[k];
        if (!strcmp(d->uname, "__SFC_STEP")) have_type = true;
    }
    if (!have_type) {
        static Source src = {"<SFC>", "TYPE __SFC_STEP : STRUCT X : BOOL; T : TIME; P : BOOL; END_STRUCT; END_TYPE\n", 0};
        src.len = strlen(src.text);
        parse_unit(u, &src, true);
    }
    Vec *b = &p->body;
    Buf g = {0};
    add_var(p, "__SFC_INIT", "BOOL", p->loc);
    add_var(p, "__SFC_NOW", "TIME", p->loc);
    add_var(p, "__SFC_LAST", "TIME", p->loc);
    add_var(p, "__SFC_EL", "TIME", p->loc);
    bool any_initial = false;
    for (int k = 0; k < s->steps.n; k++) {
        Step *st = s->steps.v[k];
        add_var(p, st->name, "__SFC_STEP", st->loc);
        any_initial |= st->initial;
    }
    if (!any_initial) fatal_at(p->loc, "the SFC of '%s' has no INITIAL_STEP", p->name);
    for (int k = 0; k < s->trans.n; k++) add_var(p, fmt("__SFC_TR%d", k), "BOOL", p->loc);
    for (int k = 0; k < s->actions.n; k++) {
        add_var(p, fmt("__SFC_A%d_Q", k), "BOOL", p->loc);
        add_var(p, fmt("__SFC_A%d_STORED", k), "BOOL", p->loc);
        add_var(p, fmt("__SFC_A%d_SET", k), "BOOL", p->loc);
        add_var(p, fmt("__SFC_A%d_RESET", k), "BOOL", p->loc);
    }
    /* the initial steps are active from the start (before the first scan) */
    buf_put(&g, "IF NOT __SFC_INIT THEN __SFC_INIT := TRUE;");
    for (int k = 0; k < s->steps.n; k++) {
        Step *st = s->steps.v[k];
        if (st->initial) buf_printf(&g, " %s.X := TRUE;", st->name);
    }
    buf_put(&g, " END_IF;\n");
    append(b, g.s);
    Node *now = xalloc(sizeof *now);
    now->kind = S_PRAGMA;
    now->loc = now->start = p->loc;
    now->sval = "SetFbVar(__SFC_NOW, __CURRENT_TIME);";
    vec_push(b, now);
    g = (Buf){0};
    buf_put(&g, "__SFC_EL := __SFC_NOW - __SFC_LAST; __SFC_LAST := __SFC_NOW;\n");
    for (int k = 0; k < s->steps.n; k++) {
        Step *st = s->steps.v[k];
        buf_printf(&g, "%s.P := %s.X; IF %s.X THEN %s.T := %s.T + __SFC_EL; END_IF;\n", st->name, st->name, st->name,
                   st->name, st->name);
    }
    for (int k = 0; k < s->actions.n; k++)
        buf_printf(&g, "__SFC_A%d_Q := FALSE; __SFC_A%d_SET := FALSE; __SFC_A%d_RESET := FALSE;\n", k, k, k);
    append(b, g.s);
    /* transitions: test all, then reset the sources, then set the targets */
    for (int k = 0; k < s->trans.n; k++) {
        Trans *tr = s->trans.v[k];
        g = (Buf){0};
        buf_put(&g, "IF ");
        for (int j = 0; j < tr->from.n; j++) {
            Token *f = tr->from.v[j];
            if (!find_step(s, f->up)) fatal_at(f->loc, "unknown step '%s'", f->text);
            buf_printf(&g, "%s%s.X", j ? " AND " : "", f->text);
        }
        buf_printf(&g, " THEN IF TRUE THEN __SFC_TR%d := TRUE; ELSE __SFC_TR%d := FALSE; END_IF; ELSE __SFC_TR%d := FALSE; END_IF;\n",
                   k, k, k);
        Vec v = glue(g.s);
        Node *ifn = v.v[0];
        Vec *then = ifn->list2.v[0];
        Node *inner = then->v[0];
        inner->list.v[0] = tr->cond;   /* a condition that is not BOOL is reported as one */
        if (tr->pre.n) {               /* the IL before the condition, in the same branch */
            Vec all = {0};
            for (int j = 0; j < tr->pre.n; j++) vec_push(&all, tr->pre.v[j]);
            vec_push(&all, inner);
            *then = all;
        }
        vec_push(b, ifn);
    }
    g = (Buf){0};
    for (int k = 0; k < s->trans.n; k++) {
        Trans *tr = s->trans.v[k];
        buf_printf(&g, "IF __SFC_TR%d THEN", k);
        for (int j = 0; j < tr->from.n; j++) buf_printf(&g, " %s.X := FALSE;", ((Token *)tr->from.v[j])->text);
        buf_put(&g, " END_IF;\n");
    }
    for (int k = 0; k < s->trans.n; k++) {
        Trans *tr = s->trans.v[k];
        buf_printf(&g, "IF __SFC_TR%d THEN", k);
        for (int j = 0; j < tr->to.n; j++) {
            Token *t = tr->to.v[j];
            if (!find_step(s, t->up)) fatal_at(t->loc, "unknown step '%s'", t->text);
            buf_printf(&g, " %s.X := TRUE; %s.T := T#0s;", t->text, t->text);
        }
        buf_put(&g, " END_IF;\n");
    }
    /* associations: an ACTION's state, or directly the BOOL variable named */
    int ntimed = 0;
    for (int k = 0; k < s->steps.n; k++) {
        Step *st = s->steps.v[k];
        const char *x = st->name;
        for (int j = 0; j < st->assoc.n; j++) {
            Assoc *as = st->assoc.v[j];
            int a = -1;
            for (int m = 0; m < s->actions.n && a < 0; m++)
                if (!strcmp(((Action *)s->actions.v[m])->uname, as->action)) a = m;
            Action *ac = s->actions.v[a];
            const char *q = ac->block ? fmt("__SFC_A%d_Q", a) : ac->name;
            const char *dt = "";
            if (as->time) {   /* the time goes through a TIME variable set from the user's expression */
                dt = fmt("__SFC_DT%d", ntimed++);
                add_var(p, dt, "TIME", as->loc);
                Node *asg = xalloc(sizeof *asg);
                asg->kind = S_ASSIGN;
                asg->loc = asg->start = as->loc;
                asg->lhs = xalloc(sizeof *asg->lhs);
                asg->lhs->kind = N_IDENT;
                asg->lhs->loc = asg->lhs->start = as->loc;
                asg->lhs->name = asg->lhs->uname = (char *)dt;
                asg->rhs = as->time;
                Vec v = glue(g.s);
                for (int m = 0; m < v.n; m++) vec_push(b, v.v[m]);
                g = (Buf){0};
                vec_push(b, asg);
            }
            switch (as->qual) {
            case 'N':
                buf_printf(&g, "IF %s.X THEN %s := TRUE; ELSIF %s.P THEN %s := FALSE; END_IF;\n", x, q, x, q);
                break;
            case 'S': buf_printf(&g, "IF %s.X THEN __SFC_A%d_SET := TRUE; END_IF;\n", x, a); break;
            case 'R': buf_printf(&g, "IF %s.X THEN __SFC_A%d_RESET := TRUE; END_IF;\n", x, a); break;
            case 'L':   /* limited: active for the time given, no longer */
                buf_printf(&g, "IF %s.X AND %s.T < %s THEN %s := TRUE; ELSIF %s.X OR %s.P THEN %s := FALSE; END_IF;\n", x, x,
                           dt, q, x, x, q);
                break;
            case 'D':   /* delayed: active once the step has lasted the time given */
                buf_printf(&g, "IF %s.X AND %s.T >= %s THEN %s := TRUE; ELSIF NOT %s.X AND %s.P THEN %s := FALSE; END_IF;\n",
                           x, x, dt, q, x, x, q);
                break;
            default:
                buf_printf(&g, "%s := %s.X AND NOT %s.P;\n", q, x, x);
                break;
            }
        }
    }
    for (int k = 0; k < s->actions.n; k++)
        buf_printf(&g,
                   "IF __SFC_A%d_SET THEN __SFC_A%d_STORED := TRUE; END_IF; IF __SFC_A%d_RESET THEN __SFC_A%d_STORED := FALSE; "
                   "END_IF; __SFC_A%d_Q := __SFC_A%d_Q OR __SFC_A%d_STORED;\n",
                   k, k, k, k, k, k, k);
    /* BOOL variables stored (S) and cleared (R) */
    for (int k = 0; k < s->actions.n; k++) {
        Action *a = s->actions.v[k];
        if (a->block || !a->has_sr) continue;
        buf_printf(&g, "IF __SFC_A%d_RESET THEN %s := FALSE; ELSIF __SFC_A%d_SET THEN %s := TRUE; END_IF;\n", k, a->name, k,
                   a->name);
    }
    Vec v = glue(g.s);
    for (int k = 0; k < v.n; k++) vec_push(b, v.v[k]);
    for (int k = 0; k < s->actions.n; k++) {
        Action *a = s->actions.v[k];
        if (!a->block) continue;
        Vec w = glue(fmt("IF __SFC_A%d_Q THEN END_IF;\n", k));
        Node *ifn = w.v[0];
        Vec *body = ifn->list2.v[0];
        for (int j = 0; j < a->body.n; j++) vec_push(body, a->body.v[j]);
        vec_push(b, ifn);
    }
}

int sfc_body(Token *toks, int n, int i, Pou *pou, Unit *u) {
    SFC s = {.t = toks, .n = n, .i = i, .pou = pou, .u = u};
    if (pou->kind == POU_FUNCTION) fatal_at(toks[i].loc, "a FUNCTION cannot be written in SFC (it keeps no state)");
    for (;;) {
        Token *t = cur(&s);
        if (is_kw(t, "INITIAL_STEP") || is_kw(t, "STEP")) step(&s);
        else if (is_kw(t, "TRANSITION")) transition(&s);
        else if (is_kw(t, "ACTION")) action_block(&s);
        else break;
    }
    for (int k = 0; k < s.actions.n; k++) {   /* a name that is no ACTION must be a variable */
        Action *a = s.actions.v[k];
        if (a->block) continue;
        bool var = false;
        for (int j = 0; j < pou->vars.n && !var; j++) var = !strcmp(((VarDecl *)pou->vars.v[j])->uname, a->uname);
        if (!var) fatal_at(a->loc, "unknown action '%s' (neither an ACTION nor a BOOL variable of '%s')", a->name, pou->name);
    }
    lower(&s, pou, u);
    return s.i;
}
