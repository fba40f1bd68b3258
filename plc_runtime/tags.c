/* tags.c: the tag list (tags.h). */
#include "tags.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "plc_image.h"

typedef struct tag {
    const char *name, *type;
    int table;                 /* MB_COILS .. MB_HOLDING */
    unsigned addr, nregs, size;
    int writable;
    char loc[48];              /* "%QW3", or "" for a symbol */
} tag;

static const char *const table_name[] = { "coil", "discrete", "input", "holding" };

/* Where a located variable's address falls in the fixed map, if it does. */
static int locate(const void *a, tag *t)
{
    static const struct area {
        const uint8_t *base; size_t len; unsigned width; int table; unsigned first, regs; const char *name;
    } areas[] = {
        { plc_img.ix, sizeof plc_img.ix, 1, MB_DISCRETE, 0, 1, "IX" },
        { plc_img.qx, sizeof plc_img.qx, 1, MB_COILS, 0, 1, "QX" },
        { plc_img.iw, sizeof plc_img.iw, 2, MB_INPUT, 0, 1, "IW" },
        { plc_img.qw, sizeof plc_img.qw, 2, MB_HOLDING, 0, 1, "QW" },
        { plc_img.mw, sizeof plc_img.mw, 2, MB_HOLDING, 1024, 1, "MW" },
        { plc_img.md, sizeof plc_img.md, 4, MB_HOLDING, 2048, 2, "MD" },
        { plc_img.ml, sizeof plc_img.ml, 8, MB_HOLDING, 4096, 4, "ML" },
    };
    const uint8_t *b = a;
    for (size_t i = 0; i < sizeof areas / sizeof areas[0]; i++) {
        const struct area *r = &areas[i];
        if (b < r->base || b >= r->base + r->len) continue;
        unsigned off = (unsigned)((size_t)(b - r->base) / r->width);   /* below 8192 */
        t->table = r->table;
        t->addr = r->first + off * r->regs;
        t->nregs = r->regs;
        t->writable = r->table == MB_COILS || r->table == MB_HOLDING;
        if (r->width == 1) snprintf(t->loc, sizeof t->loc, "%%%s%u.%u", r->name, off / 8, off % 8);
        else snprintf(t->loc, sizeof t->loc, "%%%s%u", r->name, off);
        return 1;
    }
    return 0;
}

/* how the value lies in its registers */
static const char *order(const tag *t)
{
    if (t->nregs > 1) return "high word first";
    if (t->size == 1 && t->table >= MB_INPUT && strcasecmp(t->type, "BOOL")) return "low byte";
    return "";
}

static int by_address(const void *x, const void *y)
{
    const tag *a = x, *b = y;
    if (a->table != b->table) return a->table - b->table;
    if (a->addr != b->addr) return a->addr < b->addr ? -1 : 1;
    return strcmp(a->name, b->name);
}

static void json_str(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        if (*s == '"' || *s == '\\') fputc('\\', f);
        if ((unsigned char)*s < 0x20) fprintf(f, "\\u%04x", *s);
        else fputc(*s, f);
    }
    fputc('"', f);
}

static FILE *open_in(const char *dir, const char *name, char *path, size_t n, char *err, size_t en)
{
    snprintf(path, n, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    if (!f) snprintf(err, en, "%s: %s", path, strerror(errno));
    return f;
}

int tags_write(const plc_program *p, const mb_shared *mb, const char *dir, char *err, size_t n)
{
    tag *t = calloc(p->nvars + (mb ? mb->nitems : 0) + 1, sizeof *t);
    if (!t) { snprintf(err, n, "out of memory"); return -1; }
    size_t k = 0;
    for (size_t i = 0; mb && i < p->nvars; i++) {
        const plc_var *v = &p->vars[i];
        if (!v->indirect || !locate(plc_var_addr(v), &t[k])) continue;
        t[k].name = v->path;
        t[k].size = v->size;
        t[k++].type = v->type;
    }
    for (size_t i = 0; mb && i < mb->nitems; i++) {
        const mb_item *it = &mb->items[i];
        const plc_var *v = plc_var_find(p, it->path);
        t[k] = (tag){ it->path, v ? v->type : "?", it->table, it->addr, it->nregs, it->size, it->writable, "" };
        k++;
    }
    qsort(t, k, sizeof *t, by_address);

    char path[4096];
    FILE *c = open_in(dir, "TAGS.csv", path, sizeof path, err, n);
    if (!c) { free(t); return -1; }
    fprintf(c, "name,table,address,registers,type,word_order,access,location\n");
    for (size_t i = 0; i < k; i++)
        fprintf(c, "%s,%s,%u,%u,%s,%s,%s,%s\n", t[i].name, table_name[t[i].table], t[i].addr, t[i].nregs, t[i].type,
                order(&t[i]), t[i].writable ? "read-write" : "read", t[i].loc);
    int bad = ferror(c);
    bad |= fclose(c) != 0;
    FILE *j = bad ? NULL : open_in(dir, "TAGS.json", path, sizeof path, err, n);
    if (!j) { free(t); if (bad) snprintf(err, n, "%s/TAGS.csv: write error", dir); return -1; }
    fprintf(j, "{\n  \"tags\": [");
    for (size_t i = 0; i < k; i++) {
        fprintf(j, "%s\n    {\"name\": ", i ? "," : "");
        json_str(j, t[i].name);
        fprintf(j, ", \"table\": \"%s\", \"address\": %u, \"registers\": %u, \"type\": ", table_name[t[i].table],
                t[i].addr, t[i].nregs);
        json_str(j, t[i].type);
        fprintf(j, ", \"word_order\": ");
        if (*order(&t[i])) json_str(j, order(&t[i])); else fputs("null", j);
        fprintf(j, ", \"access\": \"%s\", \"location\": ", t[i].writable ? "read-write" : "read");
        if (t[i].loc[0]) json_str(j, t[i].loc); else fputs("null", j);
        fputc('}', j);
    }
    fprintf(j, "\n  ]\n}\n");
    bad = ferror(j);
    bad |= fclose(j) != 0;
    free(t);
    if (bad) { snprintf(err, n, "%s: write error", path); return -1; }
    return 0;
}
