/* config.c: INI file -> plc_config, via libinih. */
#include <errno.h>
#include <ini.h>
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "config.h"
#include "log.h"

typedef struct parse {
    plc_config *c;
    const char *name;
    int line;               /* line being parsed (counted by the reader) */
    int err_line;           /* first handler error, 0 = none */
    char msg[700];
    int pass;               /* 1: only [io] backend; 2: everything */
    /* reader state */
    FILE *f;
    const char *text;
} parse;

/* Record the first error; always returns 0 (inih's "stop"). */
static int fail(parse *p, const char *section, const char *key, const char *fmt, ...)
{
    if (p->err_line) return 0;
    char m[300];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(m, sizeof m, fmt, ap);
    va_end(ap);
    if (snprintf(p->msg, sizeof p->msg, "[%s] %s: %s", section, key, m) < 0) p->msg[0] = 0;
    p->err_line = p->line;
    return 0;
}

static int get_int(const char *v, long lo, long hi, int *out)
{
    char *end;
    errno = 0;
    long x = strtol(v, &end, 0);
    if (errno || end == v || *end || x < lo || x > hi) return -1;
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

#define INT_KEY(k, lo, hi, field)                                              \
    if (!strcmp(key, k)) {                                                     \
        if (get_int(v, lo, hi, &c->field))                                     \
            return fail(p, s, key, "'%s' is not an integer in " #lo ".." #hi, v); \
        return 1;                                                              \
    }
#define BOOL_KEY(k, field)                                                     \
    if (!strcmp(key, k)) {                                                     \
        if (get_bool(v, &c->field))                                            \
            return fail(p, s, key, "'%s' is not yes or no", v);                \
        return 1;                                                              \
    }
#define STR_KEY(k, field)                                                      \
    if (!strcmp(key, k)) {                                                     \
        if (get_str(v, c->field, sizeof c->field))                             \
            return fail(p, s, key, "'%.40s...' is too long", v);               \
        return 1;                                                              \
    }

static int symbol(parse *p, const char *s, const char *key, const char *v)
{
    plc_config *c = p->c;
    if (c->nsymbols >= CFG_MAX_SYMBOLS) return fail(p, s, key, "more than %s symbols", "256");
    cfg_symbol *y = &c->symbols[c->nsymbols];
    memset(y, 0, sizeof *y);
    if (get_str(key, y->path, sizeof y->path)) return fail(p, s, key, "path too long%s", "");
    char tab[16] = "", rw[8] = "", extra[2] = "";
    unsigned addr;
    int n = sscanf(v, "%15s %u %7s %1s", tab, &addr, rw, extra);
    if (n < 2 || n > 3)
        return fail(p, s, key, "'%s': expected TABLE ADDRESS [rw]", v);
    static const char *tabs[] = { "coil", "discrete", "input", "holding" };
    y->table = -1;
    for (int i = 0; i < 4; i++) if (!strcasecmp(tab, tabs[i])) y->table = i;
    if (y->table < 0) return fail(p, s, key, "table '%s' is not coil, discrete, input or holding", tab);
    if (addr > 65535) return fail(p, s, key, "address '%s' is not in 0..65535", v);
    y->addr = addr;
    if (n == 3) {
        if (strcasecmp(rw, "rw")) return fail(p, s, key, "'%s': the only flag is rw", rw);
        if (y->table == MB_DISCRETE || y->table == MB_INPUT)
            return fail(p, s, key, "'%s': discrete inputs and input registers are read-only", v);
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

static int handler(void *user, const char *s, const char *key, const char *v)
{
    parse *p = user;
    plc_config *c = p->c;
    if (p->pass == 1) {
        if (!strcmp(s, "io") && !strcmp(key, "backend")) {
            if (!io_backend_find(v)) {
                char names[200] = "";
                for (int i = 0; io_backends[i]; i++)
                    snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s",
                             i ? ", " : "", io_backends[i]->name);
                return fail(p, s, key, "unknown backend '%.40s' (known: %s)", v, names);
            }
            snprintf(c->backend, sizeof c->backend, "%s", v);
        }
        return 1;
    }
    if (!strcmp(s, "plc")) {
        if (!strcmp(key, "log_level")) {
            if ((c->log_level = plc_log_parse_level(v)) < 0)
                return fail(p, s, key, "'%s' is not error, warning, info or debug", v);
            return 1;
        }
        INT_KEY("status_interval", 0, 3600, status_interval)
        if (!strcmp(key, "status_vars")) {
            char buf[1024];
            if (get_str(v, buf, sizeof buf)) return fail(p, s, key, "too long%s", "");
            c->nstatus = 0;
            for (char *t = strtok(buf, ", \t"); t; t = strtok(NULL, ", \t")) {
                if (c->nstatus == CFG_MAX_STATUS) return fail(p, s, key, "more than %s variables", "8");
                if (get_str(t, c->status_vars[c->nstatus++], sizeof c->status_vars[0]))
                    return fail(p, s, key, "path '%.40s...' too long", t);
            }
            return 1;
        }
    } else if (!strcmp(s, "scan")) {
        INT_KEY("priority", 0, 99, priority)
        INT_KEY("cpu", -1, 1023, cpu)
        BOOL_KEY("lock_memory", lock_memory)
        INT_KEY("overrun_log_interval", 1, 3600, overrun_log_interval)
    } else if (!strcmp(s, "io")) {
        if (!strcmp(key, "backend")) return 1;     /* read in pass 1 */
    } else if (!strcmp(s, "modbus")) {
        BOOL_KEY("enabled", mb_enabled)
        STR_KEY("bind", mb_bind)
        INT_KEY("port", 1, 65535, mb_port)
        INT_KEY("max_clients", 1, 1000, mb_max_clients)
        INT_KEY("idle_timeout", 0, 86400, mb_idle_timeout)
    } else if (!strcmp(s, "modbus.symbols")) {
        return symbol(p, s, key, v);
    } else if (!strcmp(s, "retain")) {
        STR_KEY("file", retain_file)
        INT_KEY("period", 0, 86400, retain_period)
    } else {
        const io_backend_ops *o = owner(s);
        if (!o) return fail(p, s, key, "unknown section%s", "");
        if (o != c->io) return 1;                  /* another backend's: ignored */
        char e[200] = "";
        if (o->config(c->io_state, s, key, v, e, sizeof e))
            return fail(p, s, key, "%s", e[0] ? e : "rejected");
        return 1;
    }
    return fail(p, s, key, "unknown key%s", "");
}

static char *reader(char *buf, int n, void *stream)
{
    parse *p = stream;
    p->line++;
    if (p->f) return fgets(buf, n, p->f);
    if (!*p->text) return NULL;
    int i = 0;
    while (i < n - 1 && p->text[0]) {
        buf[i++] = *p->text;
        if (*p->text++ == '\n') break;
    }
    buf[i] = 0;
    return buf;
}

static int run(plc_config *c, const char *name, FILE *f, const char *text,
               char *err, size_t errlen)
{
    for (int pass = 1; pass <= 2; pass++) {
        parse p = { .c = c, .name = name, .pass = pass, .f = f, .text = text };
        if (f) rewind(f);
        if (pass == 2) {
            const io_backend_ops *io = io_backend_find(c->backend);
            if (io != c->io) {
                if (c->io) c->io->close(c->io_state);
                c->io = io;
                if (!(c->io_state = io->create())) {
                    snprintf(err, errlen, "%s: backend %s: out of memory", name, io->name);
                    return -1;
                }
            }
        }
        int r = ini_parse_stream(reader, &p, handler, &p);
        if (r < 0) { snprintf(err, errlen, "%s: cannot read", name); return -1; }
        if (r > 0 && (!p.err_line || r < p.err_line)) {
            (void)!snprintf(err, errlen, "%s:%d: syntax error (expected [section] or key = value)", name, r);
            return -1;
        }
        if (p.err_line) {
            if (snprintf(err, errlen, "%s:%d: %s", name, p.err_line, p.msg) < 0) err[0] = 0;
            return -1;
        }
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
    strcpy(c->backend, "sim");
    c->mb_enabled = 1;
    strcpy(c->mb_bind, "127.0.0.1");
    c->mb_port = 1502;
    c->mb_max_clients = 16;
    c->mb_idle_timeout = 10;
    strcpy(c->retain_file, "plcrt.retain");
    c->retain_period = 10;
    c->io = io_backend_find(c->backend);
    if (!(c->io_state = c->io->create())) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    return 0;
}

int config_load(plc_config *c, const char *path, char *err, size_t errlen)
{
    FILE *f = fopen(path, "r");
    if (!f) { snprintf(err, errlen, "%s: %s", path, strerror(errno)); return -1; }
    snprintf(c->file, sizeof c->file, "%s", path);
    int r = run(c, path, f, NULL, err, errlen);
    fclose(f);
    return r;
}

int config_load_string(plc_config *c, const char *name, const char *text,
                       char *err, size_t errlen)
{
    snprintf(c->file, sizeof c->file, "%s", name);
    return run(c, name, NULL, text, err, errlen);
}

void config_free(plc_config *c)
{
    if (c->io && c->io_state) c->io->close(c->io_state);
    c->io_state = NULL;
}
