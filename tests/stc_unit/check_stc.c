/* Unit tests of the compiler's stages: lexer, parser, type checker. */
#include <check.h>
#include <string.h>

#include "../../stc/stc.h"
#include "../common/check_run.h"

static Source src_of(const char *text) {
    Source s = {"test.st", text, strlen(text)};
    return s;
}

static Token *lex_text(const char *text, int *n) {
    static Source s;
    s = src_of(text);
    return lex(&s, n);
}

/* ---- lexer ---- */
START_TEST(lex_keywords_case_insensitive) {
    int n;
    Token *t = lex_text("if If iF myVar", &n);
    ck_assert_int_eq(n, 5);
    ck_assert_str_eq(t[0].up, "IF");
    ck_assert_str_eq(t[1].up, "IF");
    ck_assert_str_eq(t[2].up, "IF");
    ck_assert_str_eq(t[3].up, "MYVAR");
    ck_assert_str_eq(t[3].text, "myVar");
    ck_assert_int_eq(t[4].kind, TK_EOF);
}
END_TEST

START_TEST(lex_comments_and_positions) {
    int n;
    Token *t = lex_text("(* one\n two *) x\n  y", &n);
    ck_assert_int_eq(n, 3);
    ck_assert_int_eq(t[0].loc.line, 2);
    ck_assert_int_eq(t[0].loc.col, 9);
    ck_assert_int_eq(t[1].loc.line, 3);
    ck_assert_int_eq(t[1].loc.col, 3);
}
END_TEST

START_TEST(lex_integers) {
    int n;
    Token *t = lex_text("1_000 2#1010 8#17 16#FF 16#ff_ff 18446744073709551615", &n);
    ck_assert_uint_eq(t[0].ival, 1000);
    ck_assert_uint_eq(t[1].ival, 10);
    ck_assert_uint_eq(t[2].ival, 15);
    ck_assert_uint_eq(t[3].ival, 255);
    ck_assert_uint_eq(t[4].ival, 65535);
    ck_assert_uint_eq(t[5].ival, UINT64_MAX);
    for (int i = 0; i < 6; i++) ck_assert_int_eq(t[i].kind, TK_INT);
}
END_TEST

START_TEST(lex_reals) {
    int n;
    Token *t = lex_text("1.5 1.5e3 2.0E-2 1_0.2_5 1..5", &n);
    ck_assert_double_eq(t[0].rval, 1.5);
    ck_assert_double_eq(t[1].rval, 1500.0);
    ck_assert_double_eq_tol(t[2].rval, 0.02, 1e-15);
    ck_assert_double_eq(t[3].rval, 10.25);
    ck_assert_int_eq(t[4].kind, TK_INT);          /* 1..5 is a range, not a real */
    ck_assert_str_eq(t[5].up, "..");
    ck_assert_int_eq(t[6].kind, TK_INT);
}
END_TEST

START_TEST(lex_time_literals) {
    int n;
    Token *t = lex_text("T#1h2m3s4ms TIME#-5s t#1.5s T#2d_3h T#100us TOD#12:30:15.5 D#1970-01-02 DT#1970-01-01-00:00:01", &n);
    ck_assert_int_eq(t[0].kind, TK_TIME);
    ck_assert_int_eq(t[0].tval, ((1 * 3600 + 2 * 60 + 3) * 1000LL + 4) * 1000000LL);
    ck_assert_int_eq(t[1].tval, -5000000000LL);
    ck_assert_int_eq(t[2].tval, 1500000000LL);
    ck_assert_int_eq(t[3].tval, (2 * 86400LL + 3 * 3600LL) * 1000000000LL);
    ck_assert_int_eq(t[4].tval, 100000LL);
    ck_assert_int_eq(t[5].tkind, TIMEK_TOD);
    ck_assert_int_eq(t[5].tval, (12 * 3600LL + 30 * 60 + 15) * 1000000000LL + 500000000LL);
    ck_assert_int_eq(t[6].tval, 86400LL * 1000000000LL);
    ck_assert_int_eq(t[7].tval, 1000000000LL);
}
END_TEST

START_TEST(lex_strings) {
    int n;
    Token *t = lex_text("'a$'b$N$$$41' ''", &n);
    ck_assert_int_eq(t[0].kind, TK_STRING);
    ck_assert_int_eq(t[0].slen, 6);
    ck_assert_mem_eq(t[0].sval, "a'b\n$A", 6);
    ck_assert_int_eq(t[1].slen, 0);
}
END_TEST

START_TEST(lex_locations_and_typed) {
    int n;
    Token *t = lex_text("%IX0.1 %QW3 %MD10 INT#5 :=", &n);
    ck_assert_int_eq(t[0].kind, TK_LOCATION);
    ck_assert_str_eq(t[0].up, "%IX0.1");
    ck_assert_str_eq(t[2].up, "%MD10");
    ck_assert_str_eq(t[3].up, "INT");
    ck_assert_str_eq(t[4].up, "#");
    ck_assert_uint_eq(t[5].ival, 5);
    ck_assert_str_eq(t[6].up, ":=");
}
END_TEST

START_TEST(lex_unterminated_comment_exits) { int n; lex_text("x (* never closed", &n); }
END_TEST
START_TEST(lex_bad_digit_exits) { int n; lex_text("2#102", &n); }
END_TEST
START_TEST(lex_unterminated_string_exits) { int n; lex_text("'abc\n'", &n); }
END_TEST
START_TEST(lex_bad_time_exits) { int n; lex_text("T#5q", &n); }
END_TEST

/* ---- parser ---- */
static Unit parse_text(const char *text) {
    static Source s;
    s = src_of(text);
    Unit u = {0};
    parse_unit(&u, &s, false);
    return u;
}

static Node *first_rhs(Unit *u) {
    Pou *p = u->pous.v[0];
    Node *s = p->body.v[0];
    return s->rhs;
}

START_TEST(parse_precedence) {
    Unit u = parse_text("PROGRAM P x := a + b * c; END_PROGRAM");
    Node *e = first_rhs(&u);
    ck_assert_int_eq(e->kind, N_BINARY);
    ck_assert_str_eq(e->op, "+");
    ck_assert_str_eq(e->rhs->op, "*");
    u = parse_text("PROGRAM P x := a OR b AND c XOR d; END_PROGRAM");
    e = first_rhs(&u);
    ck_assert_str_eq(e->op, "OR");
    ck_assert_str_eq(e->rhs->op, "XOR");
    ck_assert_str_eq(e->rhs->lhs->op, "AND");
    u = parse_text("PROGRAM P x := NOT a AND b; END_PROGRAM");
    e = first_rhs(&u);
    ck_assert_str_eq(e->op, "AND");
    ck_assert_str_eq(e->lhs->op, "NOT");
    u = parse_text("PROGRAM P x := a < b = c > d; END_PROGRAM");
    e = first_rhs(&u);
    ck_assert_str_eq(e->op, "=");
    ck_assert_str_eq(e->lhs->op, "<");
    u = parse_text("PROGRAM P x := 2.0 ** 3.0 * 4.0; END_PROGRAM");
    e = first_rhs(&u);
    ck_assert_str_eq(e->op, "*");
    ck_assert_str_eq(e->lhs->op, "**");
    u = parse_text("PROGRAM P x := a - b - c; END_PROGRAM");   /* left associative */
    e = first_rhs(&u);
    ck_assert_int_eq(e->lhs->kind, N_BINARY);
    ck_assert_int_eq(e->rhs->kind, N_IDENT);
}
END_TEST

START_TEST(parse_signed_literal) {
    Unit u = parse_text("PROGRAM P x := -5; y := a - 5; END_PROGRAM");
    Node *e = first_rhs(&u);
    ck_assert_int_eq(e->kind, N_INT);
    ck_assert(e->neg);
    Node *s = ((Pou *)u.pous.v[0])->body.v[1];
    ck_assert_int_eq(s->rhs->kind, N_BINARY);
}
END_TEST

START_TEST(parse_statements) {
    Unit u = parse_text(
        "PROGRAM P\n"
        "IF a THEN x := 1; ELSIF b THEN x := 2; ELSIF c THEN x := 3; ELSE x := 4; END_IF;\n"
        "CASE k OF 1, 2: x := 1; 3..5: x := 2; ELSE x := 3; END_CASE;\n"
        "FOR i := 10 TO 0 BY -2 DO x := i; END_FOR;\n"
        "WHILE a DO EXIT; END_WHILE;\n"
        "REPEAT x := x + 1; UNTIL x > 3 END_REPEAT;\n"
        "t(IN := a, PT := T#1s, Q => b);\n"
        "RETURN;\n"
        "END_PROGRAM");
    Vec *b = &((Pou *)u.pous.v[0])->body;
    ck_assert_int_eq(b->n, 7);
    Node *s = b->v[0];
    ck_assert_int_eq(s->kind, S_IF);
    ck_assert_int_eq(s->list.n, 3);
    ck_assert_ptr_nonnull(s->els);
    s = b->v[1];
    ck_assert_int_eq(s->kind, S_CASE);
    ck_assert_int_eq(s->list2.n, 2);
    ck_assert_int_eq(((Node *)s->list2.v[0])->list.n, 2);
    ck_assert_int_eq(((Node *)((Node *)s->list2.v[1])->list.v[0])->kind, N_RANGE);
    s = b->v[2];
    ck_assert_int_eq(s->kind, S_FOR);
    ck_assert(s->fourth->neg);
    ck_assert_int_eq(((Node *)b->v[3])->kind, S_WHILE);
    ck_assert_int_eq(((Node *)b->v[4])->kind, S_REPEAT);
    s = b->v[5];
    ck_assert_int_eq(s->kind, S_CALL);
    ck_assert_int_eq(s->lhs->list.n, 3);
    ck_assert(((Node *)s->lhs->list.v[2])->is_out);
    ck_assert_int_eq(((Node *)b->v[6])->kind, S_RETURN);
}
END_TEST

START_TEST(parse_declarations) {
    Unit u = parse_text(
        "TYPE C : (Red, Green); S : STRUCT a : INT; b : REAL := 1.0; END_STRUCT; A : ARRAY[1..3, 0..1] OF INT; R : INT(0..9); END_TYPE\n"
        "FUNCTION_BLOCK F VAR_INPUT i : INT := 3; END_VAR VAR_OUTPUT o : BOOL; END_VAR VAR_IN_OUT x : DINT; END_VAR END_FUNCTION_BLOCK\n"
        "PROGRAM P VAR q AT %QW2 : INT; END_VAR VAR RETAIN r : DINT; END_VAR VAR CONSTANT k : INT := 1; END_VAR END_PROGRAM\n"
        "CONFIGURATION C1 VAR_GLOBAL g : INT; END_VAR RESOURCE R1 ON PLC TASK t(INTERVAL := T#10ms, PRIORITY := 1); PROGRAM p1 WITH t : P; END_RESOURCE END_CONFIGURATION");
    ck_assert_int_eq(u.types.n, 4);
    ck_assert_int_eq(((TypeDecl *)u.types.v[0])->spec->kind, TS_ENUM);
    ck_assert_int_eq(((TypeDecl *)u.types.v[1])->spec->kind, TS_STRUCT);
    ck_assert_int_eq(((TypeDecl *)u.types.v[2])->spec->dims.n, 2);
    ck_assert_int_eq(((TypeDecl *)u.types.v[3])->spec->kind, TS_SUBRANGE);
    Pou *f = u.pous.v[0];
    ck_assert_int_eq(f->vars.n, 3);
    ck_assert_int_eq(((VarDecl *)f->vars.v[2])->cls, V_IN_OUT);
    Pou *p = u.pous.v[1];
    ck_assert_str_eq(((VarDecl *)p->vars.v[0])->location, "%QW2");
    ck_assert(((VarDecl *)p->vars.v[1])->retain);
    ck_assert(((VarDecl *)p->vars.v[2])->constant);
    Config *c = u.configs.v[0];
    Resource *r = c->resources.v[0];
    ck_assert_int_eq(r->tasks.n, 1);
    ck_assert_int_eq(r->progs.n, 1);
}
END_TEST

START_TEST(parse_missing_end_if_exits) { parse_text("PROGRAM P IF a THEN x := 1; END_PROGRAM"); }
END_TEST
START_TEST(parse_garbage_exits) { parse_text("PROGRAM P x := ; END_PROGRAM"); }
END_TEST

/* ---- type checker ---- */
static int compile_errors(const char *text) {
    static Source s;
    s = src_of(text);
    return stc_compile(&s, NULL) ? error_count : 0;
}

START_TEST(sema_accepts_valid) {
    ck_assert_int_eq(compile_errors(
        "TYPE Mode : (Idle, Run); END_TYPE\n"
        "FUNCTION F : INT VAR_INPUT a : INT; END_VAR F := a * 2; END_FUNCTION\n"
        "PROGRAM P VAR i : INT; d : DINT; r : REAL; m : Mode; t : TON; w : WORD; END_VAR\n"
        "i := F(3) + 1; d := INT_TO_DINT(i); r := DINT_TO_REAL(d) * 1.5; m := Run;\n"
        "IF m = Mode#Idle THEN i := 0; END_IF; t(IN := TRUE, PT := T#1s); w := w AND 16#FF;\n"
        "END_PROGRAM"), 0);
}
END_TEST

START_TEST(sema_strict_types) {
    ck_assert_int_gt(compile_errors("PROGRAM P VAR i : INT; d : DINT; END_VAR d := i; END_PROGRAM"), 0);
    ck_assert_int_gt(compile_errors("PROGRAM P VAR i : INT; d : DINT; END_VAR i := d; END_PROGRAM"), 0);
    ck_assert_int_gt(compile_errors("PROGRAM P VAR r : REAL; END_VAR r := 1; END_PROGRAM"), 0);
    ck_assert_int_gt(compile_errors("PROGRAM P VAR i : INT; r : REAL; END_VAR i := i + r; END_PROGRAM"), 0);
    ck_assert_int_gt(compile_errors("PROGRAM P VAR w : WORD; END_VAR w := w + 1; END_PROGRAM"), 0);
    ck_assert_int_gt(compile_errors("PROGRAM P VAR s : SINT; END_VAR s := 128; END_PROGRAM"), 0);
    ck_assert_int_eq(compile_errors("PROGRAM P VAR s : SINT; END_VAR s := -128; END_PROGRAM"), 0);
    ck_assert_int_eq(compile_errors("PROGRAM P VAR b : BOOL; END_VAR b := 1; END_PROGRAM"), 0);
    ck_assert_int_gt(compile_errors("PROGRAM P VAR b : BOOL; END_VAR b := 2; END_PROGRAM"), 0);
}
END_TEST

START_TEST(sema_literal_takes_context_type) {
    static Source s;
    s = src_of("PROGRAM P VAR u : UDINT; END_VAR u := 4000000000 + 1; END_PROGRAM");
    ck_assert_int_eq(stc_compile(&s, NULL), 0);
}
END_TEST

START_TEST(sema_rules) {
    ck_assert_int_gt(compile_errors("PROGRAM P VAR CONSTANT k : INT := 1; END_VAR k := 2; END_PROGRAM"), 0);
    ck_assert_int_gt(compile_errors("PROGRAM P VAR t : TON; END_VAR t.Q := TRUE; END_PROGRAM"), 0);
    ck_assert_int_eq(compile_errors("PROGRAM P VAR t : TON; END_VAR t.IN := TRUE; END_PROGRAM"), 0);
    ck_assert_int_gt(compile_errors("PROGRAM P VAR i : INT; END_VAR FOR i := 1 TO 2 DO i := 3; END_FOR; END_PROGRAM"), 0);
    ck_assert_int_gt(compile_errors("PROGRAM P VAR i : INT; END_VAR WHILE i DO END_WHILE; END_PROGRAM"), 0);
    ck_assert_int_gt(compile_errors("FUNCTION_BLOCK F VAR x AT %QW0 : INT; END_VAR END_FUNCTION_BLOCK"), 0);
    ck_assert_int_gt(compile_errors("PROGRAM P VAR t : TON; END_VAR t(IN := TRUE, Q := TRUE); END_PROGRAM"), 0);
    ck_assert_int_gt(compile_errors("PROGRAM P VAR t : TON; END_VAR t(FOO := TRUE); END_PROGRAM"), 0);
    ck_assert_int_gt(compile_errors("PROGRAM P VAR a : ARRAY[1..2] OF INT; END_VAR a[3] := 1; END_PROGRAM"), 0);
    ck_assert_int_gt(compile_errors("PROGRAM P VAR x : INT; x : INT; END_VAR END_PROGRAM"), 0);
    ck_assert_int_gt(compile_errors("PROGRAM P EXIT; END_PROGRAM"), 0);
    ck_assert_int_gt(compile_errors("PROGRAM P VAR x AT %QD0 : INT; END_VAR END_PROGRAM"), 0);
}
END_TEST

START_TEST(sema_several_errors_reported) {
    ck_assert_int_eq(compile_errors("PROGRAM P VAR i : INT; END_VAR\n a := 1;\n b := 2;\n i := TRUE;\nEND_PROGRAM"), 3);
}
END_TEST

/* Several files are one program: a file may use what a later one declares,
   and a name declared in two files is an error. */
static int compile_files(const char *a, const char *b) {
    static Source s[2];
    s[0] = src_of(a);
    s[0].name = "a.st";
    s[1] = src_of(b);
    s[1].name = "b.st";
    return stc_compile_files(s, 2, NULL) ? error_count : 0;
}

START_TEST(sema_files_share_declarations) {
    ck_assert_int_eq(compile_files(
        "PROGRAM P VAR m : Mode; i : INT; END_VAR m := Mode#Run; i := Twice(3); END_PROGRAM",
        "TYPE Mode : (Idle, Run); END_TYPE\n"
        "FUNCTION Twice : INT VAR_INPUT x : INT; END_VAR Twice := x * 2; END_FUNCTION"), 0);
    ck_assert_int_eq(compile_files(
        "FUNCTION Twice : INT VAR_INPUT x : INT; END_VAR Twice := x * 2; END_FUNCTION",
        "FUNCTION Twice : INT VAR_INPUT x : INT; END_VAR Twice := x; END_FUNCTION"), 1);
    ck_assert_int_eq(compile_files(
        "FUNCTION TIME_TO_TOD : TOD VAR_INPUT IN : TIME; END_VAR TIME_TO_TOD := TOD#00:00:00; END_FUNCTION",
        "PROGRAM P VAR t : TOD; END_VAR t := TIME_TO_TOD(T#1s); END_PROGRAM"), 0);
}
END_TEST

static Suite *stc_suite(void) {
    Suite *s = suite_create("stc");
    TCase *lx = tcase_create("lexer");
    tcase_add_test(lx, lex_keywords_case_insensitive);
    tcase_add_test(lx, lex_comments_and_positions);
    tcase_add_test(lx, lex_integers);
    tcase_add_test(lx, lex_reals);
    tcase_add_test(lx, lex_time_literals);
    tcase_add_test(lx, lex_strings);
    tcase_add_test(lx, lex_locations_and_typed);
    tcase_add_exit_test(lx, lex_unterminated_comment_exits, 1);
    tcase_add_exit_test(lx, lex_bad_digit_exits, 1);
    tcase_add_exit_test(lx, lex_unterminated_string_exits, 1);
    tcase_add_exit_test(lx, lex_bad_time_exits, 1);
    suite_add_tcase(s, lx);
    TCase *ps = tcase_create("parser");
    tcase_add_test(ps, parse_precedence);
    tcase_add_test(ps, parse_signed_literal);
    tcase_add_test(ps, parse_statements);
    tcase_add_test(ps, parse_declarations);
    tcase_add_exit_test(ps, parse_missing_end_if_exits, 1);
    tcase_add_exit_test(ps, parse_garbage_exits, 1);
    suite_add_tcase(s, ps);
    TCase *sm = tcase_create("types");
    tcase_add_test(sm, sema_accepts_valid);
    tcase_add_test(sm, sema_strict_types);
    tcase_add_test(sm, sema_literal_takes_context_type);
    tcase_add_test(sm, sema_rules);
    tcase_add_test(sm, sema_several_errors_reported);
    tcase_add_test(sm, sema_files_share_declarations);
    suite_add_tcase(s, sm);
    return s;
}

int main(void) {
    return check_run(stc_suite());
}
