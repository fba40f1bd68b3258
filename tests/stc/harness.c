/*
 * Test harness playing the PLC runtime for one ST program compiled by stc.
 *
 * Built together with the program's generated <Config>.c and <Resource>.c,
 * with the output folder on the include path (for LOCATED_VARIABLES.h).
 * It owns the located variables, defines __CURRENT_TIME and __DEBUG, runs
 * config_init__() and then config_run__(tick) for each tick, advancing the
 * clock by common_ticktime__, and checks the script in the program's first
 * comment (format: README.md next to this file).
 *
 *   harness [-q] program.st
 *
 * Prints one "PASS: ..." or "FAIL: ..." line per EXPECT (-q: nothing; the
 * exit status tells). Exit status 0 when everything passed, 1 otherwise.
 * Only the contract of the generated code is used: type names and widths,
 * the __LOCATED_VAR lines and the entry points; no compiler header.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "plc_harness.h"

/* ---- values ---- */

enum kind { K_BOOL, K_SIGNED, K_UNSIGNED, K_REAL, K_LREAL, K_TIME, K_NONE };
struct tinfo { const char *name; enum kind kind; int bytes; };
static const struct tinfo tinfos[] = {
    {"BOOL", K_BOOL, 1}, {"BYTE", K_UNSIGNED, 1}, {"USINT", K_UNSIGNED, 1},
    {"SINT", K_SIGNED, 1}, {"INT", K_SIGNED, 2}, {"UINT", K_UNSIGNED, 2},
    {"WORD", K_UNSIGNED, 2}, {"DINT", K_SIGNED, 4}, {"UDINT", K_UNSIGNED, 4},
    {"DWORD", K_UNSIGNED, 4}, {"LINT", K_SIGNED, 8}, {"ULINT", K_UNSIGNED, 8},
    {"LWORD", K_UNSIGNED, 8}, {"REAL", K_REAL, 4}, {"LREAL", K_LREAL, 8},
    {"TIME", K_TIME, 0}, {"DATE", K_TIME, 0}, {"TOD", K_TIME, 0},
    {"DT", K_TIME, 0}, {NULL, K_NONE, 0}
};

/* A located variable resolved from its IEC address, e.g. "%QW3". */
struct var { char iec[32]; const struct tinfo *t; void *p; };

/* A value: integers exact on 64 bits (neg + magnitude), reals as double. */
struct value { int neg; uint64_t mag; double real; int is_real; };

static int parse_value(const char *s, struct value *v)
{
    memset(v, 0, sizeof *v);
    if (!strcmp(s, "TRUE") || !strcmp(s, "true")) { v->mag = 1; v->real = 1; return 0; }
    if (!strcmp(s, "FALSE") || !strcmp(s, "false")) return 0;
    char buf[128];
    size_t n = 0;
    for (const char *c = s; *c; c++)             /* drop '_' separators */
        if (*c != '_') { if (n + 1 >= sizeof buf) return -1; buf[n++] = *c; }
    buf[n] = 0;
    const char *b = buf;
    if (*b == '-' || *b == '+') { v->neg = *b == '-'; b++; }
    const char *hash = strchr(b, '#');
    int base = 10;
    if (hash) {
        base = atoi(b);
        if (base != 2 && base != 8 && base != 16) return -1;
        b = hash + 1;
    }
    if (!*b) return -1;
    char *end;
    errno = 0;
    if (base == 10 && strpbrk(b, ".eE")) {
        v->is_real = 1;
        v->real = strtod(b, &end);
    } else {
        v->mag = strtoull(b, &end, base);
        v->real = (double)v->mag;
    }
    if (*end || errno) return -1;
    if (v->neg) v->real = -v->real;
    return 0;
}

/* Read a variable into a value; time kinds in milliseconds. */
static void read_var(const struct var *x, struct value *v)
{
    memset(v, 0, sizeof *v);
    int64_t i = 0; uint64_t u = 0;
    switch (x->t->kind) {
    case K_BOOL: u = *(uint8_t *)x->p; break;
    case K_UNSIGNED:
        switch (x->t->bytes) {
        case 1: u = *(uint8_t *)x->p; break;
        case 2: u = *(uint16_t *)x->p; break;
        case 4: u = *(uint32_t *)x->p; break;
        default: u = *(uint64_t *)x->p; break;
        }
        break;
    case K_SIGNED:
        switch (x->t->bytes) {
        case 1: i = *(int8_t *)x->p; break;
        case 2: i = *(int16_t *)x->p; break;
        case 4: i = *(int32_t *)x->p; break;
        default: i = *(int64_t *)x->p; break;
        }
        v->neg = i < 0;
        u = v->neg ? (uint64_t)0 - (uint64_t)i : (uint64_t)i;
        break;
    case K_TIME: {
        const ht_time *t = x->p;
        i = (int64_t)t->tv_sec * 1000 + t->tv_nsec / 1000000;
        v->neg = i < 0;
        u = v->neg ? (uint64_t)0 - (uint64_t)i : (uint64_t)i;
        break;
    }
    case K_REAL: v->is_real = 1; v->real = *(float *)x->p; return;
    case K_LREAL: v->is_real = 1; v->real = *(double *)x->p; return;
    case K_NONE: return;
    }
    v->mag = u;
    v->real = v->neg ? -(double)u : (double)u;
}

static void write_var(const struct var *x, const struct value *v)
{
    uint64_t u = v->neg ? (uint64_t)0 - v->mag : v->mag;
    switch (x->t->kind) {
    case K_BOOL: *(uint8_t *)x->p = u != 0; break;
    case K_SIGNED: case K_UNSIGNED:
        switch (x->t->bytes) {
        case 1: *(uint8_t *)x->p = (uint8_t)u; break;
        case 2: *(uint16_t *)x->p = (uint16_t)u; break;
        case 4: *(uint32_t *)x->p = (uint32_t)u; break;
        default: *(uint64_t *)x->p = u; break;
        }
        break;
    case K_REAL: *(float *)x->p = (float)v->real; break;
    case K_LREAL: *(double *)x->p = v->real; break;
    case K_TIME: {
        ht_time *t = x->p;
        int64_t ms = v->neg ? -(int64_t)v->mag : (int64_t)v->mag;
        t->tv_sec = (long)(ms / 1000);
        t->tv_nsec = (long)(ms % 1000) * 1000000;
        break;
    }
    case K_NONE: break;
    }
}

static void format_value(const struct var *x, const struct value *v, char *buf, size_t n)
{
    if (x->t->kind == K_REAL) snprintf(buf, n, "%.9g", v->real);
    else if (x->t->kind == K_LREAL) snprintf(buf, n, "%.17g", v->real);
    else if (x->t->kind == K_TIME) snprintf(buf, n, "%s%llu ms", v->neg ? "-" : "", (unsigned long long)v->mag);
    else snprintf(buf, n, "%s%llu", v->neg && v->mag ? "-" : "", (unsigned long long)v->mag);
}

/* Exact comparison in the variable's own type. */
static int equal(const struct var *x, const struct value *want, const struct value *got)
{
    if (x->t->kind == K_REAL) return (float)want->real == (float)got->real;
    if (x->t->kind == K_LREAL) return want->real == got->real;
    if (want->is_real) return 0;
    if (want->mag == 0 && got->mag == 0) return 1;
    return want->neg == got->neg && want->mag == got->mag;
}

/* ---- the script ---- */

enum op { OP_SET, OP_EXPECT, OP_EXPECT_REAL };
struct step {
    enum op op;
    int line;                 /* line in the .st file */
    long from, to;            /* ticks */
    char text[160];           /* the directive as written, for messages */
    struct var var;
    struct value val;
    double tol;
    int failed;               /* first failing tick reported */
    long fail_tick;
    struct value fail_got;
};

static const char *prog;      /* the .st path, as given */
static int quiet;
static int nfail;

static void report(int pass, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void report(int pass, const char *fmt, ...)
{
    if (!pass) nfail++;
    if (quiet) return;
    va_list ap;
    va_start(ap, fmt);
    printf("%s: %s:", pass ? "PASS" : "FAIL", prog);
    vprintf(fmt, ap);
    putchar('\n');
    va_end(ap);
}

static int resolve(const char *iec, struct var *x)
{
    const char *type;
    void *p = located(iec, &type);
    if (!p) return -1;
    for (const struct tinfo *t = tinfos; t->name; t++)
        if (!strcmp(t->name, type)) {
            snprintf(x->iec, sizeof x->iec, "%s", iec);
            x->t = t; x->p = p;
            return 0;
        }
    return -2;
}

static int parse_ticks(const char *s, long *from, long *to)
{
    char *end;
    *from = strtol(s, &end, 10);
    if (end == s || *from < 0) return -1;
    if (!*end) { *to = *from; return 0; }
    if (strncmp(end, "..", 2)) return -1;
    s = end + 2;
    *to = strtol(s, &end, 10);
    return (end == s || *end || *to < *from) ? -1 : 0;
}

#define MAXSTEPS 4096
static struct step steps[MAXSTEPS];
static int nsteps;
static long nticks = -1;

/* Parse the first comment of the file; 0 on success. */
static int load_script(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f) { report(0, " cannot open: %s", strerror(errno)); return -1; }
    static char src[1 << 20];
    size_t n = fread(src, 1, sizeof src - 1, f);
    fclose(f);
    src[n] = 0;
    char *p = src;
    int line = 1;
    while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n') { if (*p == '\n') line++; p++; }
    if (strncmp(p, "(*", 2)) { report(0, " no script: the file must start with a (* ... *) comment"); return -1; }
    p += 2;
    char *end = strstr(p, "*)");
    if (!end) { report(0, " script comment not closed"); return -1; }
    *end = 0;
    int bad = 0;
    for (char *ln = p; ln; line++) {
        char *nl = strchr(ln, '\n');
        if (nl) *nl = 0;
        char *rem = strstr(ln, "--");   /* remark to the end of the line */
        if (rem) *rem = 0;
        char *tok[8];
        int nt = 0;
        for (char *t = strtok(ln, " \t\r"); t && nt < 8; t = strtok(NULL, " \t\r")) tok[nt++] = t;
        ln = nl ? nl + 1 : NULL;
        if (nt == 0) continue;
        if (!strcmp(tok[0], "TICKS") && nt == 2) {
            nticks = strtol(tok[1], NULL, 10);
            if (nticks <= 0) { report(0, "%d: bad TICKS", line); bad = 1; }
            continue;
        }
        if (!strcmp(tok[0], "FILES") && nt >= 2) continue;   /* run.sh compiles them */
        struct step *s = &steps[nsteps];
        memset(s, 0, sizeof *s);
        s->line = line;
        int want;
        if (!strcmp(tok[0], "SET")) { s->op = OP_SET; want = 4; }
        else if (!strcmp(tok[0], "EXPECT")) { s->op = OP_EXPECT; want = 4; }
        else if (!strcmp(tok[0], "EXPECT_REAL")) { s->op = OP_EXPECT_REAL; want = 5; }
        else { report(0, "%d: unknown directive '%s'", line, tok[0]); bad = 1; continue; }
        if (nt != want) { report(0, "%d: %s takes %d arguments", line, tok[0], want - 1); bad = 1; continue; }
        if (nsteps + 1 >= MAXSTEPS) { report(0, "%d: too many directives", line); return -1; }
        snprintf(s->text, sizeof s->text, "tick %s %s", tok[1], tok[2]);
        if (parse_ticks(tok[1], &s->from, &s->to) || (s->op == OP_SET && s->from != s->to)) {
            report(0, "%d: bad tick '%s'", line, tok[1]); bad = 1; continue;
        }
        int r = resolve(tok[2], &s->var);
        if (r) {
            report(0, "%d: %s %s", line, tok[2], r == -1 ? "is not a located variable of the program"
                                                     : "has a type the harness does not know");
            bad = 1; continue;
        }
        if (parse_value(tok[3], &s->val)) { report(0, "%d: bad value '%s'", line, tok[3]); bad = 1; continue; }
        if (s->op == OP_EXPECT_REAL) {
            char *e;
            s->tol = strtod(tok[4], &e);
            if (*e || s->tol < 0) { report(0, "%d: bad tolerance '%s'", line, tok[4]); bad = 1; continue; }
        }
        nsteps++;
    }
    if (nticks < 0) { report(0, " script has no TICKS line"); return -1; }
    int nexpect = 0;
    for (int i = 0; i < nsteps; i++) nexpect += steps[i].op != OP_SET;
    if (!nexpect && !bad) { report(0, " script has no EXPECT line"); return -1; }
    for (int i = 0; i < nsteps; i++)
        if (steps[i].to >= nticks) { report(0, "%d: tick beyond TICKS %ld", steps[i].line, nticks); bad = 1; }
    return bad ? -1 : 0;
}

static void check(struct step *s, long tick)
{
    struct value got;
    read_var(&s->var, &got);
    int ok = s->op == OP_EXPECT_REAL ? fabs(got.real - s->val.real) <= s->tol
                                     : equal(&s->var, &s->val, &got);
    if (!ok && !s->failed) { s->failed = 1; s->fail_tick = tick; s->fail_got = got; }
}

int main(int argc, char **argv)
{
    int a = 1;
    if (a < argc && !strcmp(argv[a], "-q")) { quiet = 1; a++; }
    if (a + 1 != argc) { fprintf(stderr, "usage: %s [-q] program.st\n", argv[0]); return 2; }
    prog = argv[a];
    if (load_script(prog)) return 1;
    __CURRENT_TIME.tv_sec = 0;
    __CURRENT_TIME.tv_nsec = 0;
    config_init__();
    for (long tick = 0; tick < nticks; tick++) {
        for (int i = 0; i < nsteps; i++)
            if (steps[i].op == OP_SET && steps[i].from == tick) write_var(&steps[i].var, &steps[i].val);
        config_run__((unsigned long)tick);
        tick_clock();
        for (int i = 0; i < nsteps; i++)
            if (steps[i].op != OP_SET && steps[i].from <= tick && tick <= steps[i].to) check(&steps[i], tick);
    }
    for (int i = 0; i < nsteps; i++) {
        struct step *s = &steps[i];
        if (s->op == OP_SET) continue;
        char want[64], got[64];
        format_value(&s->var, &s->val, want, sizeof want);
        if (!s->failed) {
            report(1, "%d: %s = %s", s->line, s->text, want);
        } else {
            format_value(&s->var, &s->fail_got, got, sizeof got);
            if (s->op == OP_EXPECT_REAL)
                report(0, "%d: %s: tick %ld expected %s +- %g, got %s", s->line, s->text, s->fail_tick, want, s->tol, got);
            else
                report(0, "%d: %s: tick %ld expected %s, got %s", s->line, s->text, s->fail_tick, want, got);
        }
    }
    return nfail ? 1 : 0;
}
