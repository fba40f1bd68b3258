/* Retain files: round trip, missing, truncated, flipped byte, previous
** generation, and kill -9 in a tight save loop. */
#include <check.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include "retain.h"
#include "../common/check_run.h"

static char dir[256], file[300];

static int32_t a;
static double b;
static uint8_t blob[3000];
static retain_var v[3];

static void vars(void)
{
    v[0] = (retain_var){ "CONFIG0.RES0.I.A", "DINT", &a, sizeof a };
    v[1] = (retain_var){ "CONFIG0.RES0.I.B", "LREAL", &b, sizeof b };
    v[2] = (retain_var){ "CONFIG0.RES0.I.BLOB", "ARR", blob, sizeof blob };
}

/* generation g's values */
static void fill(uint64_t g)
{
    a = (int32_t)g * 3 + 1;
    b = (double)g * 0.5;
    memset(blob, (int)(g & 0xFF), sizeof blob);
}

static int consistent(uint64_t g)
{
    if (a != (int32_t)g * 3 + 1 || b != (double)g * 0.5) return 0;
    for (size_t i = 0; i < sizeof blob; i++) if (blob[i] != (uint8_t)g) return 0;
    return 1;
}

static void setup(void)
{
    snprintf(dir, sizeof dir, "%s/retain-XXXXXX", getenv("TMPDIR") ? getenv("TMPDIR") : P_tmpdir);
    ck_assert_ptr_nonnull(mkdtemp(dir));
    snprintf(file, sizeof file, "%s/plc.retain", dir);
    vars();
}

static void teardown(void)
{
    char cmd[400];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd)) {}
}

static long file_size(const char *f) { struct stat st; return stat(f, &st) ? -1 : st.st_size; }

static void save(uint64_t g)
{
    char err[600];
    fill(g);
    ck_assert_msg(!retain_save(file, v, 3, g, err, sizeof err), "%s", err);
}

START_TEST(round_trip)
{
    char err[600];
    uint64_t g = 0;
    save(7);
    fill(0);
    ck_assert_int_eq(retain_load_file(file, v, 3, &g, err, sizeof err), 0);
    ck_assert_uint_eq(g, 7);
    ck_assert(consistent(7));
}
END_TEST

START_TEST(missing)
{
    char err[600];
    uint64_t g = 99;
    fill(5);
    ck_assert_int_eq(retain_load_file(file, v, 3, &g, err, sizeof err), 1);
    ck_assert_int_eq(retain_load(file, v, 3, &g), 1);
    ck_assert(consistent(5));                  /* initial values kept */
}
END_TEST

START_TEST(truncated)
{
    char err[600];
    save(3);
    long n = file_size(file);
    ck_assert_int_gt(n, 3000);
    int fd = open(file, O_RDONLY);
    static uint8_t whole[8192];
    ck_assert_int_eq(read(fd, whole, sizeof whole), n);
    close(fd);
    for (long cut = 0; cut < n; cut += (cut < 64 || cut > n - 64) ? 1 : 97) {
        FILE *f = fopen(file, "wb");
        fwrite(whole, 1, (size_t)cut, f);
        fclose(f);
        fill(1000);
        uint64_t g = 0;
        ck_assert_msg(retain_load_file(file, v, 3, &g, err, sizeof err) == -1, "a file cut at %ld loaded", cut);
        ck_assert(consistent(1000));           /* nothing half-loaded */
    }
    ck_assert(strstr(err, "damaged") || strstr(err, "bad header"));
}
END_TEST

START_TEST(flipped_byte)
{
    char err[600];
    save(4);
    long n = file_size(file);
    static uint8_t whole[8192];
    int fd = open(file, O_RDONLY);
    ck_assert_int_eq(read(fd, whole, sizeof whole), n);
    close(fd);
    for (long i = 0; i < n; i += (i < 128 || i > n - 64) ? 1 : 53) {
        whole[i] ^= 0x10;
        FILE *f = fopen(file, "wb");
        fwrite(whole, 1, (size_t)n, f);
        fclose(f);
        whole[i] ^= 0x10;
        fill(1000);
        uint64_t g = 0;
        ck_assert_msg(retain_load_file(file, v, 3, &g, err, sizeof err) == -1, "byte %ld flipped: loaded", i);
        ck_assert(consistent(1000));
    }
}
END_TEST

START_TEST(previous_generation)
{
    uint64_t g = 0;
    save(1);
    save(2);
    /* damage the newest: the one before is used */
    FILE *f = fopen(file, "r+b");
    fseek(f, 40, SEEK_SET);
    fputc(0x55 ^ fgetc(f), f);
    fclose(f);
    fill(1000);
    ck_assert_int_eq(retain_load(file, v, 3, &g), 0);
    ck_assert_uint_eq(g, 1);
    ck_assert(consistent(1));
    /* the damaged one was set aside; a new save keeps generation 1 as previous */
    char bad[400], prev[400];
    snprintf(bad, sizeof bad, "%s.bad", file);
    snprintf(prev, sizeof prev, "%s.prev", file);
    ck_assert_int_ge(file_size(bad), 0);
    save(3);
    char err[600];
    fill(1000);
    ck_assert_int_eq(retain_load_file(prev, v, 3, &g, err, sizeof err), 0);
    ck_assert_uint_eq(g, 1);
    ck_assert(consistent(1));
}
END_TEST

START_TEST(type_changed)
{
    uint64_t g;
    save(6);
    v[0].type = "UDINT";          /* the program now declares A as UDINT */
    fill(1000);
    ck_assert_int_eq(retain_load(file, v, 3, &g), 0);
    ck_assert_int_eq(a, 1000 * 3 + 1);   /* kept its initial value */
    ck_assert(b == 3.0);                 /* the others loaded */
}
END_TEST

static void slurp(const char *f, char *out, size_t cap, size_t *n)
{
    FILE *fp = fopen(f, "rb");
    ck_assert_msg(fp != NULL, "%s missing", f);
    *n = fread(out, 1, cap, fp);
    fclose(fp);
}

/* Another program's file given to this one (a copied configuration): it
** used to be "loaded" (nothing of it matched) and the next two saves wiped
** it and its previous generation. Now it is reported, kept whole as
** FILE.foreign, and the saves that follow leave it alone. */
START_TEST(foreign_file)
{
    static int32_t x;
    static double y;
    retain_var other[2] = { { "CONFIG0.RES0.PRESS.X", "DINT", &x, sizeof x },
                            { "CONFIG0.RES0.PRESS.Y", "LREAL", &y, sizeof y } };
    char err[600], foreign[400], want[4096], got[4096];
    size_t nwant, ngot;
    uint64_t g = 0;
    x = 77; y = 2.5;
    ck_assert(!retain_save(file, other, 2, 9, err, sizeof err));
    slurp(file, want, sizeof want, &nwant);
    fill(1000);
    ck_assert_int_eq(retain_load_file(file, v, 3, &g, err, sizeof err), 2);
    ck_assert_msg(strstr(err, "holds 2 retained values, none of a variable of this program (the first: "
                              "CONFIG0.RES0.PRESS.X): another program's file?"), "%s", err);
    ck_assert(consistent(1000));
    ck_assert_int_eq(retain_load(file, v, 3, &g), 1);
    ck_assert(consistent(1000));                     /* initial values */
    snprintf(foreign, sizeof foreign, "%s.foreign", file);
    ck_assert_int_lt(file_size(file), 0);            /* out of the way */
    save(1);
    save(2);
    save(3);
    slurp(foreign, got, sizeof got, &ngot);
    ck_assert_uint_eq(ngot, nwant);
    ck_assert(!memcmp(got, want, nwant));            /* whole, after three saves */
    x = 0; y = 0;
    ck_assert_int_eq(retain_load_file(foreign, other, 2, &g, err, sizeof err), 0);
    ck_assert(x == 77 && y == 2.5 && g == 9);        /* its program can have it back */

    /* a file of this program with a variable since removed: still loaded */
    retain_var more[4] = { v[0], v[1], v[2], { "CONFIG0.RES0.I.OLD", "INT", &x, 2 } };
    fill(5);
    ck_assert(!retain_save(file, more, 4, 5, err, sizeof err));
    fill(1000);
    ck_assert_int_eq(retain_load_file(file, v, 3, &g, err, sizeof err), 0);
    ck_assert(consistent(5));
}
END_TEST

/* The child saves generation after generation and reports each completed
** one on a pipe; it is killed at a random moment. The file must then hold
** the last reported generation or the one being written (complete), and
** the previous file the one before: never anything else. */
START_TEST(kill9_loop)
{
    char err[600], prev[400];
    snprintf(prev, sizeof prev, "%s.prev", file);
    srand(12345);
    uint64_t gen = 0;
    int no_progress = 0;
    for (int round = 0; round < 200; round++) {
        int p[2];
        ck_assert_int_eq(pipe(p), 0);
        pid_t pid = fork();
        if (pid == 0) {
            close(p[0]);
            for (uint64_t g = gen + 1;; g++) {
                fill(g);
                if (retain_save(file, v, 3, g, err, sizeof err)) _exit(3);
                if (write(p[1], &g, sizeof g) != sizeof g) _exit(4);
            }
        }
        close(p[1]);
        /* every other round the kill comes after a first save completed, so
        ** that rounds with progress do not depend on how soon a loaded host
        ** runs the child; the others may kill it before any save */
        uint64_t g, last = gen;
        if (round % 2 && read(p[0], &g, sizeof g) == sizeof g) last = g;
        struct timespec d = { 0, (rand() % 4000) * 1000L };
        nanosleep(&d, NULL);
        kill(pid, SIGKILL);
        int st;
        waitpid(pid, &st, 0);
        ck_assert(WIFSIGNALED(st));
        while (read(p[0], &g, sizeof g) == sizeof g) last = g;
        close(p[0]);
        fill(1000000);
        uint64_t got = 0;
        int r = retain_load_file(file, v, 3, &got, err, sizeof err);
        if (r == 1) {                      /* nothing ever completed */
            ck_assert_uint_eq(last, 0);
            no_progress++;
            continue;
        }
        ck_assert_msg(r == 0, "round %d: %s", round, err);
        ck_assert_msg(got == last || got == last + 1, "round %d: generation %llu, last reported %llu",
                      round, (unsigned long long)got, (unsigned long long)last);
        ck_assert(consistent(got));
        uint64_t pg = 0;
        fill(1000000);
        if (retain_load_file(prev, v, 3, &pg, err, sizeof err) == 0) {
            ck_assert_msg(pg == got - 1 || pg == got, "round %d: previous %llu, newest %llu",
                          round, (unsigned long long)pg, (unsigned long long)got);
            ck_assert(consistent(pg));
        }
        gen = got;
    }
    ck_assert_int_le(no_progress, 100);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("retain");
    TCase *t = tcase_create("file");
    tcase_add_checked_fixture(t, setup, teardown);
    tcase_set_timeout(t, 120);
    tcase_add_test(t, round_trip);
    tcase_add_test(t, missing);
    tcase_add_test(t, truncated);
    tcase_add_test(t, flipped_byte);
    tcase_add_test(t, previous_generation);
    tcase_add_test(t, type_changed);
    tcase_add_test(t, foreign_file);
    tcase_add_test(t, kill9_loop);
    suite_add_tcase(s, t);
    return check_run(s);
}
