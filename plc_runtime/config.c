/*
** config.c: INI file -> plc_config, via libinih.
**
** The file is read whole into memory and handed to libinih one physical
** line per reader call, so libinih's line numbers are the file's. libinih
** reads into a fixed buffer (INI_MAX_LINE, 200 bytes in Debian's build): a
** longer line (up to CFG_MAX_LINE) is read here with libinih's own rules
** and handed over as a short line of the same shape whose section, key or
** value is a placeholder; the handler puts the real text back. Placeholders
** are control characters, which a configuration file may not contain.
** Lines are handed over without their indent: an indented line is a line
** like any other, never the continuation of the value above (libinih's
** multi-line values).
*/
#include <arpa/inet.h>
#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <ifaddrs.h>
#include <ini.h>
#include <libgen.h>
#include <limits.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sched.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>
#include "config.h"
#include "log.h"

#define PH_NAME "\x01"          /* placeholder: section or key of a long line */
#define PH_VALUE "\x02"         /* placeholder: value of a long line */

typedef struct parse {
    plc_config *c;
    const char *name;
    const char *pos;        /* next line of the text */
    int line;               /* line being parsed (counted by the reader) */
    int err_line;           /* first error (smallest line), 0 = none */
    char msg[700];
    int pass;               /* 1: only [io] backend; 2: everything */
    /* the last long line, taken apart (see the header comment) */
    char long_section[CFG_MAX_LINE + 1];
    char long_key[CFG_MAX_LINE + 1];
    char long_value[CFG_MAX_LINE + 1];
    char section[64];                   /* the last [section] read, for messages */
    /* the backend's keys read so far, for "given twice" */
    struct { char section[64], key[64]; int line; } seen[256];
    int nseen;
} parse;

/* ---- the runtime's own keys ---------------------------------------------- */

enum kind { K_INT, K_BOOL, K_STR, K_LOG, K_STATUS, K_BACKEND, K_BIND, K_PARITY };
#define F(x) offsetof(plc_config, x), sizeof ((plc_config *)0)->x
static const struct key {
    const char *section, *key;
    enum kind kind;
    long lo, hi;
    size_t off, size;
} keys[] = {
    { "plc", "log_level", K_LOG, 0, 0, F(log_level) },
    { "plc", "status_interval", K_INT, 0, 3600, F(status_interval) },
    { "plc", "status_vars", K_STATUS, 0, 0, F(status_vars) },
    { "scan", "priority", K_INT, 0, 99, F(priority) },
    { "scan", "cpu", K_INT, -1, 1023, F(cpu) },
    { "scan", "lock_memory", K_BOOL, 0, 0, F(lock_memory) },
    { "scan", "overrun_log_interval", K_INT, 1, 3600, F(overrun_log_interval) },
    { "scan", "watchdog_ms", K_INT, 0, 3600000, F(watchdog_ms) },
    { "io", "backend", K_BACKEND, 0, 0, F(backend) },
    { "modbus", "enabled", K_BOOL, 0, 0, F(mb_enabled) },
    { "modbus", "bind", K_BIND, 0, 0, F(mb_bind) },
    { "modbus", "port", K_INT, 1, 65535, F(mb_port) },
    { "modbus", "max_clients", K_INT, 1, 1000, F(mb_max_clients) },
    { "modbus", "idle_timeout", K_INT, 0, 86400, F(mb_idle_timeout) },
    { "modbus_rtu", "device", K_STR, 0, 0, F(rtu_device) },
    { "modbus_rtu", "baud", K_INT, 50, 4000000, F(rtu_baud) },
    { "modbus_rtu", "parity", K_PARITY, 0, 0, F(rtu_parity) },
    { "modbus_rtu", "data_bits", K_INT, 7, 8, F(rtu_data_bits) },
    { "modbus_rtu", "stop_bits", K_INT, 1, 2, F(rtu_stop_bits) },
    { "modbus_rtu", "slave", K_INT, 1, 247, F(rtu_slave) },
    { "retain", "file", K_STR, 0, 0, F(retain_file) },
    { "retain", "period", K_INT, 0, 86400, F(retain_period) },
    { "trace", "samples", K_INT, 16384, 1048576, F(trace_samples) },
    { "debug", "allow_force", K_BOOL, 0, 0, F(allow_force) },
};
_Static_assert(sizeof keys / sizeof keys[0] == CFG_NKEYS, "CFG_NKEYS counts keys[]");

static int key_index(const char *s, const char *k)
{
    for (int i = 0; i < CFG_NKEYS; i++)
        if (!strcmp(keys[i].section, s) && !strcmp(keys[i].key, k)) return i;
    return -1;
}

static int is_own_section(const char *s)
{
    for (int i = 0; i < CFG_NKEYS; i++)
        if (!strcmp(keys[i].section, s)) return 1;
    return !strcmp(s, "modbus.symbols");
}

/* ---- messages -------------------------------------------------------------- */

/* Record an error at line; the one on the smallest line is kept. Returns 0
** (libinih's "error", it goes on reading). */
static int fail_at(parse *p, int line, const char *section, const char *key, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));
static int fail_at(parse *p, int line, const char *section, const char *key, const char *fmt, ...)
{
    if (p->err_line && p->err_line <= line) return 0;
    char m[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(m, sizeof m, fmt, ap);
    va_end(ap);
    int r;
    if (section) r = snprintf(p->msg, sizeof p->msg, "[%.60s] %.80s: %s", section, key, m);
    else r = snprintf(p->msg, sizeof p->msg, "%s", m);
    if (r < 0) p->msg[0] = 0;
    p->err_line = line;
    return 0;
}
#define fail(p, s, k, ...) fail_at(p, (p)->line, s, k, __VA_ARGS__)

int config_line(const plc_config *c, const char *section, const char *key)
{
    int i = key_index(section, key);
    return i < 0 ? 0 : c->key_line[i];
}

void config_msg(const plc_config *c, const char *section, const char *key,
                char *out, size_t n, const char *fmt, ...)
{
    char m[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(m, sizeof m, fmt, ap);
    va_end(ap);
    const char *file = c->file[0] ? c->file : "(defaults)";
    int line = config_line(c, section, key), r;
    if (line) r = snprintf(out, n, "%s:%d: [%s] %s: %s", file, line, section, key, m);
    else r = snprintf(out, n, "%s: [%s] %s (default): %s", file, section, key, m);
    if (r < 0 && n) out[0] = 0;
}

/* ---- values ---------------------------------------------------------------- */

/* Decimal only: a leading zero does not make an octal number. */
static int get_int(const char *v, long lo, long hi, int *out)
{
    const char *d = v + (*v == '-' || *v == '+');
    if (!isdigit((unsigned char)*d)) return -1;
    char *end;
    errno = 0;
    long x = strtol(v, &end, 10);
    if (errno || *end || x < lo || x > hi) return -1;
    *out = (int)x;
    return 0;
}

static int get_bool(const char *v, int *out)
{
    if (!strcasecmp(v, "yes") || !strcasecmp(v, "true") || !strcmp(v, "1") || !strcasecmp(v, "on")) *out = 1;
    else if (!strcasecmp(v, "no") || !strcasecmp(v, "false") || !strcmp(v, "0") || !strcasecmp(v, "off")) *out = 0;
    else return -1;
    return 0;
}

static int get_str(const char *v, char *dst, size_t n)
{
    if (strlen(v) >= n) return -1;
    strcpy(dst, v);
    return 0;
}

static int only(const char *v, const char *set)
{
    return v[strspn(v, set)] == 0;
}

/* [modbus] bind -> a dotted IPv4 address in out (the server listens on
** IPv4 only); a host name is resolved here, once. */
static int bind_addr(const char *v, char *out, size_t n, char *why, size_t wn)
{
    struct in_addr a;
    struct in6_addr a6;
    if (!*v) { snprintf(why, wn, "empty (127.0.0.1 = this host only, 0.0.0.0 = every interface)"); return -1; }
    if (inet_pton(AF_INET6, v, &a6) == 1) {
        snprintf(why, wn, "'%.60s' is an IPv6 address: the Modbus server listens on IPv4 only "
                 "(give an IPv4 address or a host name with one; 0.0.0.0 = every interface)", v);
        return -1;
    }
    if (strchr(v, ':')) {
        snprintf(why, wn, "'%.60s' is not an address (the port is the key port)", v);
        return -1;
    }
    if (only(v, "0123456789.")) {
        if (inet_pton(AF_INET, v, &a) != 1) {
            snprintf(why, wn, "'%.60s' is not an IPv4 address (four decimal numbers 0..255 "
                     "without leading zeros, e.g. 192.168.1.10)", v);
            return -1;
        }
    } else {
        struct addrinfo hints = { .ai_family = AF_INET, .ai_socktype = SOCK_STREAM }, *res;
        int r = getaddrinfo(v, NULL, &hints, &res);
        if (r) {
            snprintf(why, wn, "cannot resolve '%.60s' to an IPv4 address: %s", v,
                     r == EAI_SYSTEM ? strerror(errno) : gai_strerror(r));
            return -1;
        }
        a = ((struct sockaddr_in *)res->ai_addr)->sin_addr;
        freeaddrinfo(res);
    }
    uint32_t h = ntohl(a.s_addr);
    /* libmodbus listens on every interface for any address written with a
    ** leading 0; and a broadcast or multicast address takes no connection */
    if ((h >> 24) == 0 && h != 0) {
        snprintf(why, wn, "'%.60s' is not an address of a host (0.0.0.0 = every interface)", v);
        return -1;
    }
    if (h == 0xFFFFFFFFu || (h >> 28) == 0xE) {
        snprintf(why, wn, "'%.60s' is a %s address: a TCP server cannot listen on it", v,
                 h == 0xFFFFFFFFu ? "broadcast" : "multicast");
        return -1;
    }
    if (!inet_ntop(AF_INET, &a, out, (socklen_t)n)) { snprintf(why, wn, "address too long"); return -1; }
    return 0;
}

static int status_vars(parse *p, const char *s, const char *key, const char *v)
{
    plc_config *c = p->c;
    char buf[CFG_MAX_LINE + 1];
    if (get_str(v, buf, sizeof buf)) return fail(p, s, key, "too long");
    c->nstatus = 0;
    for (char *save, *t = strtok_r(buf, ", \t", &save); t; t = strtok_r(NULL, ", \t", &save)) {
        if (c->nstatus == CFG_MAX_STATUS) return fail(p, s, key, "more than %d variables", CFG_MAX_STATUS);
        if (get_str(t, c->status_vars[c->nstatus++], sizeof c->status_vars[0]))
            return fail(p, s, key, "path '%.40s...' is longer than %zu characters", t,
                        sizeof c->status_vars[0] - 1);
    }
    return 1;
}

static int own_key(parse *p, const char *s, const char *key, const char *v)
{
    plc_config *c = p->c;
    int i = key_index(s, key);
    if (i < 0) return fail(p, s, key, "unknown key");
    const struct key *k = &keys[i];
    if (p->pass == 1 && k->kind != K_BACKEND) return 1;
    if (p->pass == 2 && k->kind == K_BACKEND) return 1;      /* read in pass 1 */
    if (c->key_line[i] && c->key_line[i] != p->line)
        return fail(p, s, key, "given twice (first on line %d)", c->key_line[i]);
    c->key_line[i] = p->line;
    void *f = (char *)c + k->off;
    char why[300];
    switch (k->kind) {
    case K_INT:
        if (get_int(v, k->lo, k->hi, f))
            return fail(p, s, key, "'%.60s' is not a decimal integer in %ld..%ld", v, k->lo, k->hi);
        return 1;
    case K_BOOL:
        if (get_bool(v, f)) return fail(p, s, key, "'%.60s' is not yes or no", v);
        return 1;
    case K_STR:
        if (get_str(v, f, k->size))
            return fail(p, s, key, "'%.40s...' is longer than %zu characters", v, k->size - 1);
        return 1;
    case K_PARITY:
        if (!strcasecmp(v, "none")) c->rtu_parity = 'N';
        else if (!strcasecmp(v, "even")) c->rtu_parity = 'E';
        else if (!strcasecmp(v, "odd")) c->rtu_parity = 'O';
        else return fail(p, s, key, "'%.60s' is not none, even or odd", v);
        return 1;
    case K_LOG:
        if ((c->log_level = plc_log_parse_level(v)) < 0)
            return fail(p, s, key, "'%.60s' is not error, warning, info or debug", v);
        return 1;
    case K_STATUS:
        return status_vars(p, s, key, v);
    case K_BIND:
        if (bind_addr(v, f, k->size, why, sizeof why)) return fail(p, s, key, "%s", why);
        c->mb_bind_name[0] = 0;
        if (!only(v, "0123456789.") && get_str(v, c->mb_bind_name, sizeof c->mb_bind_name))
            return fail(p, s, key, "host name longer than %zu characters", sizeof c->mb_bind_name - 1);
        return 1;
    case K_BACKEND: {
        /* one name or several, separated by commas: "sim, modbus_io" */
        char list[256] = "", one[64];
        const char *q = v;
        int count = 0;
        while (*q) {
            size_t l = strcspn(q, ",");
            const char *a = q, *b = q + l;
            while (a < b && isspace((unsigned char)*a)) a++;
            while (b > a && isspace((unsigned char)b[-1])) b--;
            if (b == a) return fail(p, s, key, "'%.60s': an empty name in the list (NAME or NAME, NAME, ...)", v);
            snprintf(one, sizeof one, "%.*s", (int)(b - a < 63 ? b - a : 63), a);
            const io_backend_ops *o = io_backend_find(one);
            if (!o) {
                char names[200] = "";
                for (int j = 0; io_backends[j]; j++)
                    snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s",
                             j ? ", " : "", io_backends[j]->name);
                return fail(p, s, key, "unknown backend '%.40s' (known: %s)", one, names);
            }
            for (const char *w = list; *w; w += strcspn(w, ",") , w += *w ? 2 : 0)
                if (!strncmp(w, one, strlen(one)) && (w[strlen(one)] == ',' || !w[strlen(one)]))
                    return fail(p, s, key, "backend %s listed twice", one);
            if (++count > IO_MULTI_MAX) return fail(p, s, key, "more than %d backends", IO_MULTI_MAX);
            snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", list[0] ? ", " : "", one);
            q += l;
            if (*q == ',') {
                q++;
                if (!*q) return fail(p, s, key, "'%.60s': a list may not end with a comma", v);
            }
        }
        if (!count) return fail(p, s, key, "empty: name a backend (none, sim, ...)");
        if (get_str(list, f, k->size)) return fail(p, s, key, "list too long");
        return 1;
    }
    }
    return fail(p, s, key, "unknown key");
}

static int symbol(parse *p, const char *s, const char *key, const char *v)
{
    plc_config *c = p->c;
    if (c->nsymbols >= CFG_MAX_SYMBOLS) return fail(p, s, key, "more than %d symbols", CFG_MAX_SYMBOLS);
    cfg_symbol *y = &c->symbols[c->nsymbols];
    memset(y, 0, sizeof *y);
    if (get_str(key, y->path, sizeof y->path))
        return fail(p, s, key, "path longer than %zu characters", sizeof y->path - 1);
    char tab[16] = "", rw[8] = "", extra[2] = "", addr[16] = "";
    int n = sscanf(v, "%15s %15s %7s %1s", tab, addr, rw, extra);
    if (n < 2 || n > 3)
        return fail(p, s, key, "'%.60s': expected TABLE ADDRESS [rw]", v);
    static const char *tabs[] = { "coil", "discrete", "input", "holding" };
    y->table = -1;
    for (int i = 0; i < 4; i++) if (!strcasecmp(tab, tabs[i])) y->table = i;
    if (y->table < 0) return fail(p, s, key, "table '%s' is not coil, discrete, input or holding", tab);
    int a;
    if (get_int(addr, 0, 65535, &a) || addr[0] == '-' || addr[0] == '+')
        return fail(p, s, key, "address '%s' is not a decimal number in 0..65535", addr);
    y->addr = (unsigned)a;
    if (n == 3) {
        if (strcasecmp(rw, "rw")) return fail(p, s, key, "'%s': the only flag is rw", rw);
        if (y->table == MB_DISCRETE || y->table == MB_INPUT)
            return fail(p, s, key, "'%.60s': discrete inputs and input registers are read-only", v);
        y->writable = 1;
    }
    y->line = p->line;
    c->nsymbols++;
    return 1;
}

/* Which backend a section belongs to, or NULL. */
static const io_backend_ops *owner(const char *s)
{
    for (int i = 0; io_backends[i]; i++) {
        size_t n = strlen(io_backends[i]->name);
        if (!strncmp(s, io_backends[i]->name, n) && (s[n] == 0 || s[n] == '.'))
            return io_backends[i];
    }
    return NULL;
}

/* A backend's key given twice in a section (or in two sections of the same
** name) would silently replace the first: refused, naming the first line,
** as for the runtime's own keys. `bind` ([canopen.NODE]) and `read`,
** `write` ([modbus_io.NAME]) are the keys meant to repeat. 1 when refused. */
static int backend_twice(parse *p, const char *s, const char *key)
{
    if (!strcmp(key, "bind") || !strcmp(key, "read") || !strcmp(key, "write")) return 0;
    for (int i = 0; i < p->nseen; i++)
        if (!strncmp(p->seen[i].section, s, sizeof p->seen[i].section - 1)
            && !strncmp(p->seen[i].key, key, sizeof p->seen[i].key - 1)) {
            fail(p, s, key, "given twice (first on line %d)", p->seen[i].line);
            return 1;
        }
    if (p->nseen < (int)(sizeof p->seen / sizeof p->seen[0])) {
        snprintf(p->seen[p->nseen].section, sizeof p->seen[0].section, "%.63s", s);
        snprintf(p->seen[p->nseen].key, sizeof p->seen[0].key, "%.63s", key);
        p->seen[p->nseen++].line = p->line;
    }
    return 0;
}

static int handler(void *user, const char *s, const char *key, const char *v)
{
    parse *p = user;
    plc_config *c = p->c;
    /* a long line's text back in place of its placeholders */
    if (!strcmp(s, PH_NAME)) s = p->long_section;
    if (!strcmp(key, PH_NAME)) key = p->long_key;
    if (!strcmp(v, PH_VALUE)) v = p->long_value;

    if (!strcmp(s, "modbus.symbols")) return p->pass == 1 ? 1 : symbol(p, s, key, v);
    if (is_own_section(s)) return own_key(p, s, key, v);
    if (p->pass == 1) return 1;
    const io_backend_ops *o = owner(s);
    if (!o) return fail(p, s, key, "unknown section");
    if (!io_multi_state(c->io_state, o)) return 1;   /* a backend not listed: ignored */
    if (backend_twice(p, s, key)) return 0;
    char e[300] = "";
    if (o->config(io_multi_state(c->io_state, o), s, key, v, e, sizeof e))
        return fail(p, s, key, "%s", e[0] ? e : "rejected");
    return 1;
}

/* ---- lines ------------------------------------------------------------------- */

/* libinih's search: the first of chars, or an inline comment (';' after a
** space), or the end. */
static char *find_or_comment(char *s, const char *chars)
{
    int was_space = 0;
    while (*s && (!chars || !strchr(chars, *s)) && !(was_space && *s == ';')) {
        was_space = isspace((unsigned char)*s);
        s++;
    }
    return s;
}

static char *rstrip(char *s)
{
    char *e = s + strlen(s);
    while (e > s && isspace((unsigned char)e[-1])) *--e = 0;
    return s;
}

static char *lskip(char *s)
{
    while (*s && isspace((unsigned char)*s)) s++;
    return s;
}

/* A line longer than libinih's buffer: taken apart here, handed on as a
** short line of the same shape. */
static void long_line(parse *p, const char *text, size_t len, char *buf)
{
    char ln[CFG_MAX_LINE + 1];
    memcpy(ln, text, len);
    ln[len] = 0;
    char *start = rstrip(ln);
    if (*start == ';' || *start == '#') {
        strcpy(buf, ";\n");
    } else if (*start == '[') {
        char *end = find_or_comment(start + 1, "]");
        if (*end == ']') {
            *end = 0;
            snprintf(p->long_section, sizeof p->long_section, "%s", start + 1);
            strcpy(buf, "[" PH_NAME "]\n");
        } else {
            strcpy(buf, "[\n");                            /* libinih: syntax error */
        }
    } else {
        char *end = find_or_comment(start, "=:");
        if (*end == '=' || *end == ':') {
            *end = 0;
            snprintf(p->long_key, sizeof p->long_key, "%s", rstrip(start));
            char *v = end + 1;
            *find_or_comment(v, NULL) = 0;
            snprintf(p->long_value, sizeof p->long_value, "%s", rstrip(lskip(v)));
            strcpy(buf, PH_NAME "=" PH_VALUE "\n");
        } else {
            strcpy(buf, PH_NAME "\n");                     /* libinih: syntax error */
        }
    }
}

/* The key of a line the reader refuses (the text before '='), for the
** message; "" if none. */
static void place(const char *s, size_t len, char *key, size_t kn)
{
    char ln[80];
    size_t n = len < sizeof ln - 1 ? len : sizeof ln - 1;
    memcpy(ln, s, n);
    ln[n] = 0;
    char *start = lskip(ln), *end = find_or_comment(start, "=:");
    key[0] = 0;
    if (*end == '=' || *end == ':') {
        *end = 0;
        snprintf(key, kn, "%s", rstrip(start));
    }
}

/* One physical line per call: libinih's line numbers are the file's. */
static char *reader(char *buf, int n, void *stream)
{
    parse *p = stream;
    if (!*p->pos || n < 8) return NULL;              /* n: never that small */
    const char *s = p->pos, *e = strchr(s, '\n');
    if (!e) e = s + strlen(s);
    p->pos = *e ? e + 1 : e;
    p->line++;
    size_t len = (size_t)(e - s);
    if (len && s[len - 1] == '\r') len--;
    char key[80];
    for (size_t i = 0; i < len; i++)
        if ((unsigned char)s[i] < 0x20 && s[i] != '\t') {
            place(s, len, key, sizeof key);
            fail_at(p, p->line, key[0] ? p->section : NULL, key, "control character 0x%02x in column %zu",
                    (unsigned char)s[i], i + 1);
            strcpy(buf, ";\n");
            return buf;
        }
    if (len > CFG_MAX_LINE) {
        place(s, len, key, sizeof key);
        fail_at(p, p->line, key[0] ? p->section : NULL, key, "line of %zu characters; at most %d are read",
                len, CFG_MAX_LINE);
        strcpy(buf, ";\n");
        return buf;
    }
    size_t lead = strspn(s, " \t");                  /* no indent: see the top */
    if (lead > len) lead = len;
    s += lead;
    len -= lead;
    if (*s == '[') {                                 /* section, for messages */
        size_t k = strcspn(s + 1, "]\n");
        snprintf(p->section, sizeof p->section, "%.*s", (int)(k < sizeof p->section ? k : sizeof p->section - 1), s + 1);
    }
    if (len + 2 <= (size_t)n) {
        memcpy(buf, s, len);
        buf[len] = '\n';
        buf[len + 1] = 0;
    } else {
        long_line(p, s, len, buf);
    }
    return buf;
}

/* The backends of c->backend (a checked list), created anew. 0, or -1 on
** out of memory. */
static int make_set(plc_config *c)
{
    if (c->io_state) c->io->close(c->io_state);
    c->io = &io_multi;
    c->io_list[0] = 0;
    if (!(c->io_state = io_multi_new())) return -1;
    char one[64];
    for (const char *q = c->backend; *q;) {
        size_t l = strcspn(q, ",");
        snprintf(one, sizeof one, "%.*s", (int)(l < 63 ? l : 63), q);
        if (!io_multi_add(c->io_state, io_backend_find(one))) return -1;
        q += l;
        while (*q == ',' || *q == ' ') q++;
    }
    snprintf(c->io_list, sizeof c->io_list, "%s", c->backend);
    return 0;
}

static int run(plc_config *c, const char *name, const char *text, char *err, size_t errlen)
{
    if (!strncmp(text, "\xEF\xBB\xBF", 3)) text += 3;     /* UTF-8 byte order mark */
    memset(c->key_line, 0, sizeof c->key_line);
    parse p;
    int first_line = 0;
    char first[sizeof p.msg] = "";
    for (int pass = 1; pass <= 2; pass++) {
        memset(&p, 0, sizeof p);
        p.c = c; p.name = name; p.pass = pass; p.pos = text;
        if (pass == 2 && strcmp(c->backend, c->io_list) && make_set(c)) {
            snprintf(err, errlen, "%s: backend %s: out of memory", name, c->backend);
            return -1;
        }
        int r = ini_parse_stream(reader, &p, handler, &p);
        if (r < 0) { snprintf(err, errlen, "%s: cannot read", name); return -1; }
        if (r > 0 && (!p.err_line || r < p.err_line)) {
            p.err_line = r;
            snprintf(p.msg, sizeof p.msg, "syntax error (expected [section] or key = value)");
        }
        if (p.err_line && (!first_line || p.err_line < first_line)) {
            first_line = p.err_line;
            memcpy(first, p.msg, sizeof first);
        }
    }
    if (first_line) {
        if (snprintf(err, errlen, "%s:%d: %s", name, first_line, first) < 0) err[0] = 0;
        return -1;
    }
    return 0;
}

int config_defaults(plc_config *c, char *err, size_t errlen)
{
    memset(c, 0, sizeof *c);
    c->log_level = LOG_INFO;
    c->priority = 80;
    c->cpu = -1;
    c->lock_memory = 1;
    c->overrun_log_interval = 1;
    c->watchdog_ms = 500;
    strcpy(c->backend, "sim");
    c->mb_enabled = 1;
    strcpy(c->mb_bind, "127.0.0.1");
    c->mb_port = 1502;
    c->mb_max_clients = 16;
    c->mb_idle_timeout = 10;
    c->rtu_baud = 19200;
    c->rtu_parity = 'E';
    c->rtu_data_bits = 8;
    c->rtu_stop_bits = 1;
    c->rtu_slave = 1;
    strcpy(c->retain_file, "plcrt.retain");
    c->retain_period = 10;
    c->trace_samples = 16384;
    if (make_set(c)) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    return 0;
}

/* The whole file, NUL-terminated; a folder or an oversized file refused. */
static char *slurp(const char *path, char *err, size_t errlen)
{
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) { snprintf(err, errlen, "%s: %s", path, strerror(errno)); return NULL; }
    struct stat st;
    if (fstat(fd, &st) == 0 && S_ISDIR(st.st_mode)) {
        snprintf(err, errlen, "%s: is a folder, not a configuration file", path);
        close(fd);
        return NULL;
    }
    size_t n = 0, cap = 4096;
    char *b = malloc(cap + 1);
    for (;;) {
        if (!b) { snprintf(err, errlen, "%s: out of memory", path); close(fd); return NULL; }
        if (n == cap) {
            if (cap > CFG_MAX_FILE) {
                snprintf(err, errlen, "%s: larger than %d bytes: not a configuration file", path, CFG_MAX_FILE);
                free(b); close(fd); return NULL;
            }
            char *nb = realloc(b, 2 * cap + 1);
            if (!nb) { free(b); b = NULL; continue; }
            b = nb;
            cap *= 2;
        }
        ssize_t r = read(fd, b + n, cap - n);
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) {
            snprintf(err, errlen, "%s: %s", path, strerror(errno));
            free(b); close(fd); return NULL;
        }
        if (r == 0) break;
        n += (size_t)r;
    }
    close(fd);
    if (n > CFG_MAX_FILE) {
        snprintf(err, errlen, "%s: larger than %d bytes: not a configuration file", path, CFG_MAX_FILE);
        free(b);
        return NULL;
    }
    b[n] = 0;
    char *z = memchr(b, 0, n);
    if (z) {                                  /* a NUL would end the text early */
        int line = 1;
        for (char *q = b; q < z; q++) line += *q == '\n';
        snprintf(err, errlen, "%s:%d: control character 0x00", path, line);
        free(b);
        return NULL;
    }
    return b;
}

int config_load(plc_config *c, const char *path, char *err, size_t errlen)
{
    char *text = slurp(path, err, errlen);
    if (!text) return -1;
    snprintf(c->file, sizeof c->file, "%s", path);
    int r = run(c, path, text, err, errlen);
    free(text);
    return r;
}

int config_load_string(plc_config *c, const char *name, const char *text,
                       char *err, size_t errlen)
{
    snprintf(c->file, sizeof c->file, "%s", name);
    return run(c, name, text, err, errlen);
}

/* ---- this host ------------------------------------------------------------ */

static int check_bind(const plc_config *c, char *err, size_t errlen)
{
    struct in_addr a;
    if (inet_pton(AF_INET, c->mb_bind, &a) != 1) {
        config_msg(c, "modbus", "bind", err, errlen, "'%s' is not an IPv4 address", c->mb_bind);
        return -1;
    }
    uint32_t h = ntohl(a.s_addr);
    int local = h == 0 || (h >> 24) == 127;
    char list[200] = "";
    struct ifaddrs *ifs, *i;
    if (!local && getifaddrs(&ifs) == 0) {
        for (i = ifs; i; i = i->ifa_next) {
            if (!i->ifa_addr || i->ifa_addr->sa_family != AF_INET) continue;
            struct in_addr x = ((struct sockaddr_in *)i->ifa_addr)->sin_addr;
            char t[INET_ADDRSTRLEN];
            if (x.s_addr == a.s_addr) local = 1;
            if (inet_ntop(AF_INET, &x, t, sizeof t) && !strstr(list, t) && strlen(list) + strlen(t) + 3 < sizeof list)
                snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", list[0] ? ", " : "", t);
        }
        freeifaddrs(ifs);
        if (!local) {
            config_msg(c, "modbus", "bind", err, errlen, "%s%s%s%s is not an address of this host (its addresses: %s; "
                       "0.0.0.0 = every interface)", c->mb_bind_name, c->mb_bind_name[0] ? " (" : "", c->mb_bind,
                       c->mb_bind_name[0] ? ")" : "", list);
            return -1;
        }
    }
    /* the address and port as the server will take them; a port in use
    ** (by a plcrt running this very file, perhaps) is found at the start */
    int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0) return 0;
    int one = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    struct sockaddr_in sa = { .sin_family = AF_INET, .sin_port = htons((uint16_t)c->mb_port), .sin_addr = a };
    int r = bind(fd, (struct sockaddr *)&sa, sizeof sa), e = errno;
    close(fd);
    if (r == 0 || e == EADDRINUSE) return 0;
    if (e == EACCES)
        config_msg(c, "modbus", "port", err, errlen, "%d: ports below 1024 need root or CAP_NET_BIND_SERVICE", c->mb_port);
    else
        config_msg(c, "modbus", "bind", err, errlen, "cannot listen on %s:%d: %s", c->mb_bind, c->mb_port, strerror(e));
    return -1;
}

static int check_cpu(const plc_config *c, char *err, size_t errlen)
{
    cpu_set_t set;
    if (c->cpu < 0 || sched_getaffinity(0, sizeof set, &set)) return 0;
    if (c->cpu < CPU_SETSIZE && CPU_ISSET(c->cpu, &set)) return 0;
    char list[200] = "";
    for (int i = 0; i < CPU_SETSIZE && strlen(list) < sizeof list - 16; i++)
        if (CPU_ISSET(i, &set)) snprintf(list + strlen(list), sizeof list - strlen(list), "%s%d", list[0] ? " " : "", i);
    config_msg(c, "scan", "cpu", err, errlen, "CPU %d is not one this process may run on (these are: %s)", c->cpu, list);
    return -1;
}

static int check_retain(const plc_config *c, size_t nretained, char *err, size_t errlen)
{
    if (!c->retain_file[0] || (!nretained && !config_line(c, "retain", "file"))) return 0;
    struct stat st;
    if (stat(c->retain_file, &st) == 0 && !S_ISREG(st.st_mode)) {
        config_msg(c, "retain", "file", err, errlen, "%s is not a regular file", c->retain_file);
        return -1;
    }
    char d[sizeof c->retain_file];
    snprintf(d, sizeof d, "%s", c->retain_file);
    const char *dir = dirname(d);
    if (stat(dir, &st)) {
        config_msg(c, "retain", "file", err, errlen, "folder %s: %s", dir, strerror(errno));
        return -1;
    }
    if (!S_ISDIR(st.st_mode)) {
        config_msg(c, "retain", "file", err, errlen, "%s is not a folder", dir);
        return -1;
    }
    if (access(dir, W_OK | X_OK)) {
        config_msg(c, "retain", "file", err, errlen, "folder %s is not writable (%s): the file is saved "
                   "there as a temporary file, then renamed", dir, strerror(errno));
        return -1;
    }
    return 0;
}

int config_check_host(const plc_config *c, size_t nretained, char *err, size_t errlen)
{
    if (c->mb_enabled && check_bind(c, err, errlen)) return -1;
    if (check_cpu(c, err, errlen)) return -1;
    return check_retain(c, nretained, err, errlen);
}

void config_free(plc_config *c)
{
    if (c->io && c->io_state) c->io->close(c->io_state);
    c->io_state = NULL;
}
