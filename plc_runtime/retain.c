/* retain.c: see retain.h. */
#include <errno.h>
#include <fcntl.h>
#include <libgen.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "log.h"
#include "retain.h"

#define MAGIC "PLCRTRT1"
#define MAX_FILE (64u << 20)

uint32_t retain_crc32(const void *p, size_t n)
{
    const uint8_t *b = p;
    uint32_t c = 0xFFFFFFFFu;
    while (n--) {
        c ^= *b++;
        for (int k = 0; k < 8; k++) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1)));
    }
    return ~c;
}

typedef struct buf { uint8_t *p; size_t n, cap; int oom; } buf;

static void put(buf *b, const void *d, size_t n)
{
    if (b->oom) return;
    if (b->n + n > b->cap) {
        size_t cap = (b->cap ? b->cap * 2 : 4096) + n;
        uint8_t *p = realloc(b->p, cap);
        if (!p) { b->oom = 1; return; }
        b->p = p; b->cap = cap;
    }
    memcpy(b->p + b->n, d, n);
    b->n += n;
}

static void put32(buf *b, uint32_t x) { put(b, &x, 4); }

static int write_all(int fd, const uint8_t *p, size_t n)
{
    while (n) {
        ssize_t w = write(fd, p, n);
        if (w < 0) { if (errno == EINTR) continue; return -1; }
        p += w; n -= (size_t)w;
    }
    return 0;
}

int retain_save(const char *file, const retain_var *v, size_t n, uint64_t gen,
                char *err, size_t errlen)
{
    buf b = {0};
    put(&b, MAGIC, 8);
    put(&b, &gen, 8);
    put32(&b, (uint32_t)n);
    for (size_t i = 0; i < n; i++) {
        uint32_t pl = (uint32_t)strlen(v[i].path), tl = (uint32_t)strlen(v[i].type);
        put32(&b, pl); put(&b, v[i].path, pl);
        put32(&b, tl); put(&b, v[i].type, tl);
        put32(&b, (uint32_t)v[i].size); put(&b, v[i].data, v[i].size);
    }
    put32(&b, retain_crc32(b.p, b.n));
    if (b.oom) { free(b.p); snprintf(err, errlen, "%s: out of memory", file); return -1; }

    char tmp[4200], prev[4200], dir[4200];
    snprintf(tmp, sizeof tmp, "%s.tmp", file);
    snprintf(prev, sizeof prev, "%s.prev", file);
    snprintf(dir, sizeof dir, "%s", file);
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) { snprintf(err, errlen, "%s: %s", tmp, strerror(errno)); free(b.p); return -1; }
    if (write_all(fd, b.p, b.n) || fsync(fd)) {
        snprintf(err, errlen, "%s: %s", tmp, strerror(errno));
        close(fd); unlink(tmp); free(b.p);
        return -1;
    }
    free(b.p);
    close(fd);
    if (unlink(prev) && errno != ENOENT) { snprintf(err, errlen, "%s: %s", prev, strerror(errno)); return -1; }
    if (link(file, prev) && errno != ENOENT) { snprintf(err, errlen, "%s: %s", prev, strerror(errno)); return -1; }
    if (rename(tmp, file)) { snprintf(err, errlen, "%s: %s", file, strerror(errno)); return -1; }
    int dfd = open(dirname(dir), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) { fsync(dfd); close(dfd); }
    return 0;
}

typedef struct rd { const uint8_t *p; size_t n, at; } rd;

static int get(rd *r, void *d, size_t n)
{
    if (r->n - r->at < n) return -1;
    memcpy(d, r->p + r->at, n);
    r->at += n;
    return 0;
}

static int get_str(rd *r, char *d, size_t cap)
{
    uint32_t l;
    if (get(r, &l, 4) || l >= cap || get(r, d, l)) return -1;
    d[l] = 0;
    return 0;
}

int retain_load_file(const char *file, retain_var *v, size_t n, uint64_t *gen,
                     char *err, size_t errlen)
{
    int fd = open(file, O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
        if (errno == ENOENT) return 1;
        snprintf(err, errlen, "%s: %s", file, strerror(errno));
        return -1;
    }
    struct stat st;
    if (fstat(fd, &st) || st.st_size > MAX_FILE) {
        snprintf(err, errlen, "%s: too large or unreadable", file);
        close(fd);
        return -1;
    }
    size_t len = (size_t)st.st_size;
    uint8_t *p = malloc(len ? len : 1);
    size_t got = 0;
    while (p && got < len) {
        ssize_t r = read(fd, p + got, len - got);
        if (r <= 0) { if (r < 0 && errno == EINTR) continue; break; }
        got += (size_t)r;
    }
    close(fd);
    if (!p || got != len) { free(p); snprintf(err, errlen, "%s: read error", file); return -1; }

    int bad = 0;
    uint32_t crc;
    if (len < 24 || memcmp(p, MAGIC, 8)) { snprintf(err, errlen, "%s: not a retain file (bad header)", file); bad = 1; }
    else if (memcpy(&crc, p + len - 4, 4), crc != retain_crc32(p, len - 4)) {
        snprintf(err, errlen, "%s: damaged (checksum mismatch)", file); bad = 1;
    }
    /* parse twice: check everything (and whether the file is this
    ** program's at all), then copy */
    uint32_t cnt = 0, known = 0, gone = 0;
    char first_gone[1024] = "";
    for (int pass = 0; !bad && pass < 2; pass++) {
        rd r = { p, len - 4, 8 };
        if (get(&r, gen, 8) || get(&r, &cnt, 4)) { bad = 1; break; }
        for (uint32_t i = 0; i < cnt && !bad; i++) {
            char path[1024], type[64];
            uint32_t size;
            if (get_str(&r, path, sizeof path) || get_str(&r, type, sizeof type)
                || get(&r, &size, 4) || r.n - r.at < size) { bad = 1; break; }
            int found = 0;
            for (size_t k = 0; k < n; k++) {
                if (strcmp(v[k].path, path)) continue;
                found = 1;
                if (pass == 0) continue;
                if (strcmp(v[k].type, type) || v[k].size != size)
                    plc_log(LOG_WARN, "%s: %s was %s, is now %s: keeps its initial value",
                            file, path, type, v[k].type);
                else memcpy(v[k].data, r.p + r.at, size);
            }
            if (pass == 0 && found) known++;
            if (pass == 0 && !found && !gone++) snprintf(first_gone, sizeof first_gone, "%s", path);
            r.at += size;
        }
        if (!bad && r.at != r.n) bad = 1;
        if (bad) snprintf(err, errlen, "%s: damaged (inconsistent records)", file);
        /* another program's file: nothing of it would be loaded, and the
        ** next saves would overwrite it and its previous generation */
        if (!bad && pass == 0 && cnt && !known && n) {
            snprintf(err, errlen, "%s holds %u retained values, none of a variable of this program "
                     "(the first: %s): another program's file?", file, cnt, first_gone);
            free(p);
            return 2;
        }
    }
    if (!bad && gone)
        plc_log(LOG_WARN, "%s: %u retained value(s) belong to no retained variable of the program any more "
                "(the first: %s): dropped at the next save", file, gone, first_gone);
    free(p);
    return bad ? -1 : 0;
}

/* An intact file of another program: renamed FILE.foreign (a numbered name
** if that is taken), never loaded nor overwritten. */
static void set_aside(const char *file, const char *why)
{
    char to[4300];
    snprintf(to, sizeof to, "%s.foreign", file);
    for (int i = 1; i < 100 && access(to, F_OK) == 0; i++) snprintf(to, sizeof to, "%s.foreign%d", file, i);
    if (rename(file, to)) {
        plc_log(LOG_ERROR, "retain: %s; not loaded, and it cannot be moved to %s (%s): move it away before "
                "the next save overwrites it", why, to, strerror(errno));
        return;
    }
    plc_log(LOG_ERROR, "retain: %s; not loaded, kept as %s (give that program its own [retain] file)", why, to);
}

int retain_load(const char *file, retain_var *v, size_t n, uint64_t *gen)
{
    char prev[4200], err[512];
    snprintf(prev, sizeof prev, "%s.prev", file);
    int r = retain_load_file(file, v, n, gen, err, sizeof err);
    if (r == 0) { plc_log(LOG_INFO, "retain: loaded %s (generation %llu)", file, (unsigned long long)*gen); return 0; }
    int foreign = r == 2;
    if (r == 2) {
        /* kept out of the way of the saves, whole, for whoever owns it */
        set_aside(file, err);
        r = 1;
    }
    if (r < 0) {
        /* set the damaged file aside, so that the next save cannot make it
        ** the previous generation */
        char bad[4200];
        snprintf(bad, sizeof bad, "%s.bad", file);
        plc_log(LOG_ERROR, "retain: %s; not loaded, moved to %s", err, bad);
        rename(file, bad);
    }
    int q = retain_load_file(prev, v, n, gen, err, sizeof err);
    if (q == 2) {
        set_aside(prev, err);
        foreign = 1;
        q = 1;
    }
    if (q == 0) {
        plc_log(LOG_WARN, "retain: loaded the previous generation %s (generation %llu)", prev, (unsigned long long)*gen);
        if ((r < 0 || foreign) && link(prev, file)) plc_log(LOG_WARN, "retain: cannot restore %s: %s", file, strerror(errno));
        return 0;
    }
    if (q < 0) plc_log(LOG_ERROR, "retain: %s; not loaded", err);
    if (r == 1 && q == 1 && !foreign) plc_log(LOG_INFO, "retain: no file %s yet: initial values", file);
    else plc_log(LOG_WARN, "retain: no usable retain file: retained variables keep their initial values");
    return 1;
}
