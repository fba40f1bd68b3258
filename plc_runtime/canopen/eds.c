#include <ctype.h>
#include <errno.h>
#include <ini.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "eds.h"

/* one sub-object as the file describes it */
typedef struct obj {
    uint16_t index;
    uint8_t sub;
    uint16_t type;
    char access[8];
    char defval[64], parval[64];
    int has_def, has_par, has_type;
} obj;

#define MAX_OBJS 2048

typedef struct rd {
    const char *path;
    uint8_t node;
    obj *o;
    int n;
    char err[256];
} rd;

/* "[1600sub2]" or "[1000]": 0 with index and sub, -1 for other sections */
static int section_obj(const char *s, uint16_t *index, uint8_t *sub)
{
    char *end;
    if (strlen(s) < 4 || !isxdigit((unsigned char)s[0]))
        return -1;
    unsigned long i = strtoul(s, &end, 16);
    if (end != s + 4 || i > 0xFFFF)
        return -1;
    *index = (uint16_t)i;
    *sub = 0;
    if (!*end)
        return 0;
    if (strncasecmp(end, "sub", 3))
        return -1;
    unsigned long k = strtoul(end + 3, &end, 16);
    if (*end || k > 0xFF)
        return -1;
    *sub = (uint8_t)k;
    return 0;
}

#define FAIL(...) do { if (!r->err[0]) snprintf(r->err, sizeof r->err, __VA_ARGS__); return 0; } while (0)

static int handler(void *user, const char *section, const char *key, const char *value)
{
    rd *r = user;
    uint16_t index;
    uint8_t sub;
    if (section_obj(section, &index, &sub))
        return 1;                   /* [FileInfo], [DeviceInfo], [Comments] ...: not ours */
    obj *o = r->n ? &r->o[r->n - 1] : NULL;
    if (!o || o->index != index || o->sub != sub) {
        if (r->n >= MAX_OBJS)
            FAIL("more than %d objects", MAX_OBJS);
        o = &r->o[r->n++];
        memset(o, 0, sizeof *o);
        o->index = index;
        o->sub = sub;
    }
    if (!strcasecmp(key, "DefaultValue")) {
        snprintf(o->defval, sizeof o->defval, "%s", value);
        o->has_def = 1;
    } else if (!strcasecmp(key, "ParameterValue")) {
        snprintf(o->parval, sizeof o->parval, "%s", value);
        o->has_par = 1;
    } else if (!strcasecmp(key, "DataType")) {
        char *end;
        unsigned long t = strtoul(value, &end, 0);
        if (end == value || *end || t > 0xFFFF)
            FAIL("[%s] DataType '%s' is not a number (e.g. 0x0007)", section, value);
        o->type = (uint16_t)t;
        o->has_type = 1;
    } else if (!strcasecmp(key, "AccessType")) {
        snprintf(o->access, sizeof o->access, "%s", value);
    }
    return 1;
}

/* a value: number (0x hex, decimal, negative) with an optional $NODEID term */
static int value_of(const char *v, uint8_t node, long long *out)
{
    char buf[64];
    size_t k = 0;
    long long add = 0;
    for (const char *p = v; *p && k + 1 < sizeof buf; p++) {
        if (!strncasecmp(p, "$NODEID", 7)) {
            add += node;
            p += 6;
            continue;
        }
        if (*p != ' ' && *p != '\t')
            buf[k++] = *p;
    }
    buf[k] = 0;
    char *s = buf;
    /* "$NODEID+0x180" leaves "+0x180"; "0x180+$NODEID" leaves "0x180+" */
    if (*s == '+')
        s++;
    if (k && buf[k - 1] == '+')
        buf[--k] = 0;
    if (!*s)
        return add ? (*out = add, 0) : -1;
    char *end;
    errno = 0;
    long long x = strtoll(s, &end, 0);
    if (errno || *end)
        return -1;
    *out = x + add;
    return 0;
}

static const obj *find(const rd *r, uint16_t index, uint8_t sub)
{
    for (int i = 0; i < r->n; i++)
        if (r->o[i].index == index && r->o[i].sub == sub)
            return &r->o[i];
    return NULL;
}

/* the value of index:sub (ParameterValue over DefaultValue); 1 if absent */
static int get(const rd *r, uint16_t index, uint8_t sub, long long *v, char *err, size_t n)
{
    const obj *o = find(r, index, sub);
    if (!o || (!o->has_par && !o->has_def))
        return 1;
    const char *s = o->has_par ? o->parval : o->defval;
    if (value_of(s, r->node, v)) {
        snprintf(err, n, "%s: object 0x%04X:%02X: %s '%s' is not a number", r->path, index, sub,
                 o->has_par ? "ParameterValue" : "DefaultValue", s);
        return -1;
    }
    return 0;
}

static int type_size(uint16_t t)
{
    switch (t) {
    case 0x0001: case 0x0002: case 0x0005: return 1;   /* BOOLEAN, INTEGER8, UNSIGNED8 */
    case 0x0003: case 0x0006: return 2;                /* INTEGER16, UNSIGNED16 */
    case 0x0004: case 0x0007: case 0x0008: return 4;   /* INTEGER32, UNSIGNED32, REAL32 */
    default: return 0;
    }
}

static int pdos(const rd *r, eds_info *e, char *err, size_t n)
{
    for (int tx = 0; tx < 2; tx++)
        for (unsigned k = 0; k < CO_PDO_PER_NODE; k++) {
            uint16_t comm = (uint16_t)((tx ? 0x1800 : 0x1400) + k), map = (uint16_t)((tx ? 0x1A00 : 0x1600) + k);
            co_pdo_map *m = tx ? &e->tpdo[k] : &e->rpdo[k];
            long long cob, cnt, ent, tt;
            int rc = get(r, comm, 1, &cob, err, n);
            if (rc < 0)
                return -1;
            int rm = get(r, map, 0, &cnt, err, n);
            if (rm < 0)
                return -1;
            if (rc == 0 || rm == 0)
                e->has_pdo = 1;
            memset(m, 0, sizeof *m);
            if (rm || cnt == 0 || (rc == 0 && (cob & 0x80000000ll)))
                continue;                   /* not used */
            uint32_t pre = co_pdo_cobid(tx, k, r->node);
            if (rc == 0 && (uint32_t)(cob & 0x7FF) != pre) {
                snprintf(err, n, "%s: object 0x%04X:01: %cPDO%u COB-ID 0x%03llX is not the predefined 0x%03X "
                         "(0x%03X + node id %u); this master uses the predefined COB-IDs only", r->path, comm,
                         tx ? 'T' : 'R', k + 1, cob & 0x7FF, pre, pre - r->node, r->node);
                return -1;
            }
            if (cnt < 0 || cnt > CO_PDO_MAX_ENTRIES) {
                snprintf(err, n, "%s: object 0x%04X:00: %lld mapped objects, at most %d", r->path, map, cnt,
                         CO_PDO_MAX_ENTRIES);
                return -1;
            }
            for (int s = 1; s <= cnt; s++) {
                int g = get(r, map, (uint8_t)s, &ent, err, n);
                if (g < 0)
                    return -1;
                if (g || ent <= 0 || ent > 0xFFFFFFFFll || (ent & 0xFF) == 0 || (ent & 0xFF) > 64) {
                    snprintf(err, n, "%s: object 0x%04X:%02X: %s (expected INDEX << 16 | SUB << 8 | BITS, "
                             "e.g. 0x60410010 for the statusword)", r->path, map, s,
                             g ? "missing: sub 0 counts more entries than the file gives" : "not a mapping entry");
                    return -1;
                }
                m->e[m->n++] = (co_map_entry){ (uint16_t)(ent >> 16), (uint8_t)(ent >> 8), (uint8_t)ent };
            }
            if (get(r, comm, 2, &tt, err, n) == 0 && tt >= 1 && tt <= 240)
                m->trans = (uint8_t)tt;
            char e2[160];
            if (co_pdo_check(m, e2, sizeof e2)) {
                snprintf(err, n, "%s: object 0x%04X: %s", r->path, map, e2);
                return -1;
            }
        }
    return 0;
}

static int writes(const rd *r, eds_info *e, char *err, size_t n)
{
    for (int i = 0; i < r->n; i++) {
        const obj *o = &r->o[i];
        if (!o->has_par || (o->index >= 0x1400 && o->index < 0x1C00) || o->index == 0x1017
            || o->index == 0x100C || o->index == 0x100D || o->index == 0x1000)
            continue;
        const char *a = o->access;
        if (strcasecmp(a, "rw") && strcasecmp(a, "wo") && strcasecmp(a, "rww") && strcasecmp(a, "rwr"))
            continue;                       /* ro, const: a value to read, not to write */
        int size = type_size(o->type);
        if (!size) {
            snprintf(err, n, "%s: object 0x%04X:%02X: ParameterValue of DataType 0x%04X: only objects of 8, 16 "
                     "and 32 bits are written at start-up; remove its ParameterValue or write it from the "
                     "program", r->path, o->index, o->sub, o->type);
            return -1;
        }
        long long v;
        if (value_of(o->parval, r->node, &v)) {
            snprintf(err, n, "%s: object 0x%04X:%02X: ParameterValue '%s' is not a number", r->path, o->index,
                     o->sub, o->parval);
            return -1;
        }
        long long lo = (o->type <= 0x0004) ? -(1ll << (8 * size - 1)) : 0;
        long long hi = (o->type <= 0x0004 && o->type != 0x0001) ? (1ll << (8 * size - 1)) - 1 : (1ll << (8 * size)) - 1;
        if (o->type == 0x0008)
            lo = 0, hi = 0xFFFFFFFFll;      /* REAL32 given as its bit pattern */
        if (v < lo || v > hi) {
            snprintf(err, n, "%s: object 0x%04X:%02X: ParameterValue %lld out of range for its %d-bit DataType "
                     "0x%04X", r->path, o->index, o->sub, v, 8 * size, o->type);
            return -1;
        }
        if (e->nwrites >= EDS_MAX_WRITES) {
            snprintf(err, n, "%s: more than %d objects to write at start-up", r->path, EDS_MAX_WRITES);
            return -1;
        }
        e->w[e->nwrites++] = (co_sdo_write){ o->index, o->sub, (uint8_t)size,
                                             (uint32_t)((unsigned long long)v & (size == 4 ? 0xFFFFFFFFull
                                                        : (1ull << (8 * size)) - 1)) };
    }
    return 0;
}

int eds_load(const char *path, uint8_t node, eds_info *out, char *err, size_t n)
{
    memset(out, 0, sizeof *out);
    FILE *f = fopen(path, "r");
    if (!f) {
        snprintf(err, n, "%s: %s (the eds key names the node's EDS or DCF file, relative to the folder plcrt "
                 "was started in)", path, strerror(errno));
        return -1;
    }
    rd r = { .path = path, .node = node };
    r.o = calloc(MAX_OBJS, sizeof *r.o);
    if (!r.o) {
        fclose(f);
        snprintf(err, n, "%s: out of memory", path);
        return -1;
    }
    int line = ini_parse_file(f, handler, &r);
    fclose(f);
    int rc = -1;
    if (line > 0) {
        if (r.err[0])
            snprintf(err, n, "%s:%d: %s", path, line, r.err);
        else
            snprintf(err, n, "%s:%d: not an EDS/DCF line (expected [section] or Key=Value)", path, line);
    } else if (line < 0) {
        snprintf(err, n, "%s: cannot be read", path);
    } else if (!find(&r, 0x1000, 0)) {
        snprintf(err, n, "%s: no object 0x1000 (device type): not an EDS or DCF file", path);
    } else {
        long long dt;
        int g = get(&r, 0x1000, 0, &dt, err, n);
        if (g < 0)
            goto out;
        if (g == 0) {
            out->device_type = (uint32_t)dt;
            out->has_device_type = 1;
        }
        if (pdos(&r, out, err, n) || writes(&r, out, err, n))
            goto out;
        rc = 0;
    }
out:
    free(r.o);
    return rc;
}
