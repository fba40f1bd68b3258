/* Lexer: source text to tokens. Keywords and identifiers are case-insensitive:
** every identifier token carries its upper-cased spelling. */
#include "stc.h"

#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* INTERVAL, PRIORITY and SINGLE are not here: they name task parameters
** only, and a block may use them as variable names (matiec does too). */
static const char *reserved[] = {
    "ACTION", "AND", "ANY", "ARRAY", "AT", "BOOL", "BY", "BYTE", "CASE", "CONFIGURATION",
    "CONSTANT", "DATE", "DATE_AND_TIME", "DINT", "DO", "DT", "DWORD", "ELSE", "ELSIF",
    "END_ACTION", "END_CASE", "END_CONFIGURATION", "END_FOR", "END_FUNCTION",
    "END_FUNCTION_BLOCK", "END_IF", "END_PROGRAM", "END_REPEAT", "END_RESOURCE",
    "END_STRUCT", "END_TYPE", "END_VAR", "END_WHILE", "EXIT", "FALSE", "FOR", "FUNCTION",
    "FUNCTION_BLOCK", "IF", "INT", "LINT", "LREAL", "LWORD", "MOD", "NOT", "OF",
    "ON", "OR", "PROGRAM", "READ_ONLY", "READ_WRITE", "REAL", "REPEAT", "RESOURCE",
    "RETAIN", "NON_RETAIN", "RETURN", "SINT", "STEP", "END_STEP", "INITIAL_STEP", "TRANSITION", "END_TRANSITION", "FROM",
    "R_EDGE", "F_EDGE", "STRING", "STRUCT", "TASK", "THEN",
    "TIME", "TIME_OF_DAY", "TO", "TOD", "TRUE", "TYPE", "UDINT", "UINT", "ULINT", "UNTIL",
    "USINT", "VAR", "VAR_ACCESS", "VAR_CONFIG", "VAR_EXTERNAL", "VAR_GLOBAL", "VAR_INPUT",
    "VAR_IN_OUT", "VAR_OUTPUT", "VAR_TEMP", "WHILE", "WITH", "WORD", "WSTRING", "XOR",
    NULL,
};

static int cmp_word(const void *a, const void *b) { return strcmp(*(const char *const *)a, *(const char *const *)b); }

/* Called for every identifier the parser looks at: a binary search in the
** list, sorted on first use. */
bool is_reserved(const char *up) {
    static const char *sorted[sizeof reserved / sizeof reserved[0]];
    static size_t n;
    if (!n) {
        for (const char **r = reserved; *r; r++) sorted[n++] = *r;
        qsort(sorted, n, sizeof sorted[0], cmp_word);
    }
    return bsearch(&up, sorted, n, sizeof sorted[0], cmp_word) != NULL;
}

typedef struct {
    const Source *src;
    const char *p, *end;
    int line;
    const char *line_start;
    Vec toks;
} Lexer;

static Loc here(Lexer *L, const char *at) {
    return (Loc){L->src, L->line, (int)(at - L->line_start) + 1};
}

static Token *add(Lexer *L, TokKind k, const char *s, const char *e) {
    Token *t = xalloc(sizeof *t);
    t->kind = k;
    t->loc = here(L, s);
    t->text = xstrndup(s, (size_t)(e - s));
    t->up = upcase(t->text);
    t->pos = (size_t)(s - L->src->text);
    t->end = (size_t)(e - L->src->text);
    vec_push(&L->toks, t);
    return t;
}

/* Skip over text that may contain newlines, keeping line numbers. */
static void advance_to(Lexer *L, const char *to) {
    for (; L->p < to; L->p++)
        if (*L->p == '\n') { L->line++; L->line_start = L->p + 1; }
}

static bool ident_start(int c) { return isalpha(c) || c == '_'; }
static bool ident_char(int c) { return isalnum(c) || c == '_'; }

/* Digits of `base` with single '_' separators; returns end, sets *ok. */
static const char *scan_digits(const char *p, const char *end, int base, uint64_t *val, bool *ok, bool *ovf) {
    uint64_t v = 0;
    bool any = false, last_us = false;
    *ovf = false;
    for (; p < end; p++) {
        int c = (unsigned char)*p, d;
        if (c == '_') {
            if (!any || last_us) { *ok = false; }
            last_us = true;
            continue;
        }
        if (isdigit(c)) d = c - '0';
        else if (isalpha(c)) d = toupper(c) - 'A' + 10;
        else break;
        if (d >= base) {
            if (base == 10 && isalpha(c)) break;   /* '1e5', '5s' handled by caller */
            *ok = false;
            continue;
        }
        if (v > (UINT64_MAX - (uint64_t)d) / (uint64_t)base) *ovf = true;
        v = v * (uint64_t)base + (uint64_t)d;
        any = true;
        last_us = false;
    }
    if (!any || last_us) *ok = false;
    *val = v;
    return p;
}

static void lex_number(Lexer *L) {
    const char *s = L->p, *end = L->end;
    uint64_t v;
    bool ok = true, ovf;
    const char *p = scan_digits(s, end, 10, &v, &ok, &ovf);
    if (p < end && *p == '#') {               /* based integer 2#, 8#, 16# */
        if (ok && (v == 2 || v == 8 || v == 16)) {
            int base = (int)v;
            const char *q = p + 1;
            while (q < end && ident_char((unsigned char)*q)) q++;
            bool ok2 = true, ovf2;
            const char *r = scan_digits(p + 1, q, base, &v, &ok2, &ovf2);
            if (!ok2 || r != q)
                fatal_at(here(L, s), "malformed integer literal '%.*s': bad digit for base %d",
                         (int)(q - s), s, base);
            if (ovf2) fatal_at(here(L, s), "malformed integer literal '%.*s': too large", (int)(q - s), s);
            Token *t = add(L, TK_INT, s, q);
            t->ival = v;
            L->p = q;
            return;
        }
        fatal_at(here(L, s), "malformed integer literal '%.*s#': base must be 2, 8 or 16", (int)(p - s), s);
    }
    bool is_real = false;
    if (p + 1 < end && *p == '.' && isdigit((unsigned char)p[1])) {
        is_real = true;
        uint64_t f;
        bool ovf2;
        p = scan_digits(p + 1, end, 10, &f, &ok, &ovf2);
    } else if (p < end && *p == '.' && !(p + 1 < end && p[1] == '.')) {
        const char *q = p + 1;
        while (q < end && ident_char((unsigned char)*q)) q++;
        fatal_at(here(L, s), "malformed real literal '%.*s': digits expected after '.'", (int)(q - s), s);
    }
    if (p < end && (*p == 'e' || *p == 'E')) {
        const char *q = p + 1;
        if (q < end && (*q == '+' || *q == '-')) q++;
        if (q >= end || !isdigit((unsigned char)*q)) {
            while (q < end && ident_char((unsigned char)*q)) q++;
            fatal_at(here(L, s), "malformed real literal '%.*s': exponent digits expected", (int)(q - s), s);
        }
        while (q < end && isdigit((unsigned char)*q)) q++;
        is_real = true;
        p = q;
    }
    if (p < end && ident_char((unsigned char)*p)) {
        const char *q = p;
        while (q < end && ident_char((unsigned char)*q)) q++;
        fatal_at(here(L, s), "malformed %s literal '%.*s'", is_real ? "real" : "integer", (int)(q - s), s);
    }
    if (!ok)
        fatal_at(here(L, s), "malformed %s literal '%.*s': misplaced '_'", is_real ? "real" : "integer",
                 (int)(p - s), s);
    if (is_real) {
        char *txt = xstrndup(s, (size_t)(p - s)), *w = txt;
        for (char *r = txt; *r; r++)
            if (*r != '_') *w++ = *r;
        *w = 0;
        Token *t = add(L, TK_REAL, s, p);
        t->rval = strtod(txt, NULL);
        if (!isfinite(t->rval)) fatal_at(t->loc, "malformed real literal '%s': out of range", t->text);
    } else {
        if (ovf) fatal_at(here(L, s), "malformed integer literal '%.*s': too large", (int)(p - s), s);
        Token *t = add(L, TK_INT, s, p);
        t->ival = v;
    }
    L->p = p;
}

/* Duration: [-] { number [. digits] unit } with units d h m s ms us ns. */
static bool parse_duration(const char *p, const char *end, const char **stop, int64_t *ns) {
    bool neg = false, any = false;
    long double total = 0;
    if (p < end && *p == '-') { neg = true; p++; }
    if (p < end && *p == '+') p++;
    while (p < end && (isdigit((unsigned char)*p))) {
        long double num = 0;
        while (p < end && (isdigit((unsigned char)*p) || *p == '_')) {
            if (*p != '_') num = num * 10 + (*p - '0');
            p++;
        }
        if (p < end && *p == '.') {
            p++;
            long double scale = 0.1L;
            if (p >= end || !isdigit((unsigned char)*p)) return false;
            while (p < end && isdigit((unsigned char)*p)) { num += (*p - '0') * scale; scale /= 10; p++; }
        }
        long double unit;
        char c0 = (char)tolower((unsigned char)(p < end ? *p : 0));
        char c1 = (char)tolower((unsigned char)(p + 1 < end ? p[1] : 0));
        if (c0 == 'm' && c1 == 's') { unit = 1e6L; p += 2; }
        else if (c0 == 'u' && c1 == 's') { unit = 1e3L; p += 2; }
        else if (c0 == 'n' && c1 == 's') { unit = 1; p += 2; }
        else if (c0 == 'd') { unit = 86400e9L; p++; }
        else if (c0 == 'h') { unit = 3600e9L; p++; }
        else if (c0 == 'm') { unit = 60e9L; p++; }
        else if (c0 == 's') { unit = 1e9L; p++; }
        else return false;
        total += num * unit;
        any = true;
        if (p < end && *p == '_') p++;
    }
    if (!any || (p < end && ident_char((unsigned char)*p))) return false;
    if (total > 9.2e18L) return false;
    *ns = (int64_t)llroundl(neg ? -total : total);
    *stop = p;
    return true;
}

static bool parse_fixed(const char **pp, const char *end, int n, long *v) {
    const char *p = *pp;
    long x = 0;
    int k = 0;
    while (p < end && isdigit((unsigned char)*p) && k < n + 2) { x = x * 10 + (*p - '0'); p++; k++; }
    if (k == 0) return false;
    *v = x;
    *pp = p;
    return true;
}

static bool parse_tod(const char **pp, const char *end, int64_t *ns) {
    long h, m;
    const char *p = *pp;
    if (!parse_fixed(&p, end, 2, &h) || p >= end || *p++ != ':') return false;
    if (!parse_fixed(&p, end, 2, &m) || p >= end || *p++ != ':') return false;
    long sec;
    if (!parse_fixed(&p, end, 2, &sec)) return false;
    long double frac = 0;
    if (p < end && *p == '.') {
        p++;
        long double sc = 0.1L;
        if (p >= end || !isdigit((unsigned char)*p)) return false;
        while (p < end && isdigit((unsigned char)*p)) { frac += (*p - '0') * sc; sc /= 10; p++; }
    }
    if (h > 23 || m > 59 || sec > 59) return false;
    *ns = (int64_t)((h * 3600 + m * 60 + sec) * 1000000000LL) + (int64_t)llroundl(frac * 1e9L);
    *pp = p;
    return true;
}

static bool parse_date(const char **pp, const char *end, int64_t *ns) {
    long y, mo, d;
    const char *p = *pp;
    if (!parse_fixed(&p, end, 4, &y) || p >= end || *p++ != '-') return false;
    if (!parse_fixed(&p, end, 2, &mo) || p >= end || *p++ != '-') return false;
    if (!parse_fixed(&p, end, 2, &d)) return false;
    if (y < 1970 || y > 2200 || mo < 1 || mo > 12 || d < 1 || d > 31) return false;
    /* days since 1970-01-01 (proleptic Gregorian) */
    long yy = y - (mo <= 2), era = yy / 400, yoe = yy - era * 400;
    long doy = (153 * (mo + (mo > 2 ? -3 : 9)) + 2) / 5 + d - 1;
    long doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    long days = era * 146097 + doe - 719468;
    *ns = (int64_t)days * 86400LL * 1000000000LL;
    *pp = p;
    return true;
}

/* After "T#", "TOD#", "D#", "DT#" (and long forms): a time or date literal. */
static void lex_time(Lexer *L, const char *s, const char *hash, TimeKind k) {
    const char *p = hash + 1, *stop, *end = L->end;
    /* blanks after the '#' (T# 30000ms, as an OpenPLC project has it):
       matiec accepts them */
    while (p < end && (*p == ' ' || *p == '\t')) p++;
    stop = p;
    int64_t ns = 0, tod;
    bool ok;
    switch (k) {
    case TIMEK_TIME: ok = parse_duration(p, end, &stop, &ns); break;
    case TIMEK_TOD: stop = p; ok = parse_tod(&stop, end, &ns); break;
    case TIMEK_DATE: stop = p; ok = parse_date(&stop, end, &ns); break;
    default:
        stop = p;
        ok = parse_date(&stop, end, &ns) && stop < end && *stop++ == '-' && parse_tod(&stop, end, &tod);
        if (ok) ns += tod;
        break;
    }
    if (ok && stop < end && ident_char((unsigned char)*stop)) ok = false;
    if (!ok) {
        const char *q = p;
        while (q < end && (ident_char((unsigned char)*q) || strchr(".:-", *q))) q++;
        static const char *what[] = {"TIME", "DATE", "TIME_OF_DAY", "DATE_AND_TIME"};
        fatal_at(here(L, s), "malformed %s literal '%.*s'", what[k], (int)(q - s), s);
    }
    Token *t = add(L, TK_TIME, s, stop);
    t->tval = ns;
    t->tkind = k;
    L->p = stop;
}

static void lex_string(Lexer *L) {
    const char *s = L->p, *p = s + 1, *end = L->end;
    Buf b = {0};
    buf_put(&b, "");
    for (;;) {
        if (p >= end || *p == '\n') fatal_at(here(L, s), "unterminated string");
        if (*p == '\'') break;
        char c = *p++;
        if (c == '$') {
            if (p >= end) fatal_at(here(L, s), "unterminated string");
            char e = *p++;
            switch (toupper((unsigned char)e)) {
            case '$': c = '$'; break;
            case '\'': c = '\''; break;
            case 'L': case 'N': c = '\n'; break;
            case 'P': c = '\f'; break;
            case 'R': c = '\r'; break;
            case 'T': c = '\t'; break;
            default:
                if (isxdigit((unsigned char)e) && p < end && isxdigit((unsigned char)*p)) {
                    char hx[3] = {e, *p++, 0};
                    c = (char)strtol(hx, NULL, 16);
                } else {
                    fatal_at(here(L, p - 2), "invalid escape '$%c' in string", e);
                }
            }
        }
        char one[2] = {c, 0};
        if (c == 0) { buf_put(&b, " "); b.s[b.n - 1] = 0; continue; }   /* $00: a NUL byte in the string */
        buf_put(&b, one);
    }
    Token *t = add(L, TK_STRING, s, p + 1);
    t->sval = b.s;
    t->slen = (int)b.n;
    if (t->slen > 126) fatal_at(t->loc, "string literal longer than 126 characters");
    L->p = p + 1;
}

static void lex_location(Lexer *L) {
    const char *s = L->p, *p = s + 1, *end = L->end;
    bool ok = p < end && strchr("IQMiqm", *p);
    if (ok) p++;
    if (ok && p < end && strchr("XBWDLxbwdl", *p)) p++;
    if (ok && !(p < end && isdigit((unsigned char)*p))) ok = false;
    while (ok && p < end && isdigit((unsigned char)*p)) {
        while (p < end && isdigit((unsigned char)*p)) p++;
        if (p + 1 < end && *p == '.' && isdigit((unsigned char)p[1])) p++;
        else break;
    }
    if (p < end && *p == '*')
        fatal_at(here(L, s), "partly specified locations like '%.*s*' are not supported by stc: give the full address",
                 (int)(p - s), s);
    if (!ok || (p < end && ident_char((unsigned char)*p))) {
        while (p < end && (ident_char((unsigned char)*p) || *p == '.')) p++;
        fatal_at(here(L, s), "malformed location '%.*s'", (int)(p - s), s);
    }
    add(L, TK_LOCATION, s, p);
    L->p = p;
}

static const char *puncts[] = {
    ":=", "=>", "<=", ">=", "<>", "**", "..", "(", ")", "[", "]", ",", ";", ":", ".",
    "+", "-", "*", "/", "<", ">", "=", "&", "#", NULL,
};

Token *lex(const Source *src, int *count) {
    Lexer L = {src, src->text, src->text + src->len, 1, src->text, {0}};
    bool warned_single = false;   /* the target-C warning, once per file */
    while (L.p < L.end) {
        const char *p = L.p;
        unsigned char c = (unsigned char)*p;
        if (c == '\n') { advance_to(&L, p + 1); continue; }
        if (isspace(c)) { L.p++; continue; }
        if (c == '(' && p + 1 < L.end && p[1] == '*') {
            const char *e = p + 2;
            while (e + 1 < L.end && !(e[0] == '*' && e[1] == ')')) e++;
            if (e + 1 >= L.end) fatal_at(here(&L, p), "unterminated comment");
            advance_to(&L, e + 2);
            continue;
        }
        if (c == '/' && p + 1 < L.end && p[1] == '/')
            fatal_at(here(&L, p), "'//' comments are not IEC 61131-3 (2nd edition): use (* ... *)");
        if (c == '{') {
            bool twin = p + 1 < L.end && p[1] == '{';
            const char *e = p + (twin ? 2 : 1);
            if (twin) while (e + 1 < L.end && !(e[0] == '}' && e[1] == '}')) e++;
            else while (e < L.end && *e != '}') e++;
            if (e >= L.end || (twin && e + 1 >= L.end)) fatal_at(here(&L, p), "unterminated pragma");
            if (twin) {
                Token *t = add(&L, TK_PRAGMA, p, p + 2);
                t->sval = xstrndup(p + 2, (size_t)(e - p - 2));
                t->end = (size_t)(e + 2 - src->text);
                advance_to(&L, e + 2);
                continue;
            }
            /* { ... }: matiec copies it into the C as it does {{ ... }}, except
               its own {enable/disable code generation}, which stc ignores */
            char *text = xstrndup(p + 1, (size_t)(e - p - 1));
            if (!strncmp(text, "#include", 8)) fatal_at(here(&L, p), "{#include ...} pragmas are not supported by stc");
            if (strcmp(text, "enable code generation") && strcmp(text, "disable code generation")) {
                Token *t = add(&L, TK_PRAGMA, p, p + 1);
                t->sval = text;
                t->ival = 1;
                t->end = (size_t)(e + 1 - src->text);
                if (!warned_single) {
                    warning_at(t->loc, "'{ ... }' pragma copied into the generated C, as matiec does: its text must be C for the target");
                    warned_single = true;
                }
            }
            advance_to(&L, e + 1);
            continue;
        }
        if (isdigit(c)) { lex_number(&L); continue; }
        if (c == '\'') { lex_string(&L); continue; }
        if (c == '"') fatal_at(here(&L, p), "WSTRING literals (\"...\") are not supported");
        if (c == '%') { lex_location(&L); continue; }
        if (ident_start(c)) {
            const char *e = p;
            while (e < L.end && ident_char((unsigned char)*e)) e++;
            if (e < L.end && *e == '#') {
                char *up = upcase(xstrndup(p, (size_t)(e - p)));
                int k = -1;
                if (!strcmp(up, "T") || !strcmp(up, "TIME")) k = TIMEK_TIME;
                else if (!strcmp(up, "TOD") || !strcmp(up, "TIME_OF_DAY")) k = TIMEK_TOD;
                else if (!strcmp(up, "D") || !strcmp(up, "DATE")) k = TIMEK_DATE;
                else if (!strcmp(up, "DT") || !strcmp(up, "DATE_AND_TIME")) k = TIMEK_DT;
                if (k >= 0) { lex_time(&L, p, e, (TimeKind)k); continue; }
            }
            add(&L, TK_IDENT, p, e);
            L.p = e;
            continue;
        }
        bool matched = false;
        for (const char **q = puncts; *q; q++) {
            size_t n = strlen(*q);
            if ((size_t)(L.end - p) >= n && !strncmp(p, *q, n)) {
                add(&L, TK_PUNCT, p, p + n);
                L.p = p + n;
                matched = true;
                break;
            }
        }
        if (!matched) {
            if (c == '^') fatal_at(here(&L, p), "pointer dereference '^' is not supported by stc");
            if (c == '?' && p + 1 < L.end && p[1] == '=') fatal_at(here(&L, p), "assignment attempt '?=' is not supported by stc");
            if (c >= 0x20 && c < 0x7f) fatal_at(here(&L, p), "unexpected character '%c'", c);
            fatal_at(here(&L, p), "unexpected byte 0x%02X", c);
        }
    }
    Token *t = add(&L, TK_EOF, L.p, L.p);
    (void)t;
    *count = L.toks.n;
    Token *arr = xalloc(sizeof(Token) * (size_t)L.toks.n);
    for (int i = 0; i < L.toks.n; i++) arr[i] = *(Token *)L.toks.v[i];
    return arr;
}
