/*
 * Cost of one LJPROF call in stc's generated C, with the LJDRIVE program of
 * tests/ljprof (drive.st: one LJPROF with located inputs and outputs).
 *
 *   replan [cases]
 *
 * For each random case (speed, acceleration and jerk limits over four
 * decades each, distances over six, half from rest and half from a moving
 * set-point within the limits, jerk times all different) the set-point is
 * taken over (SETPOS), then one call carrying POSA is timed: the whole
 * re-plan plus the first sample.  Then 100 plain sample calls of the same
 * move are timed.  Prints p50, p99 and the maximum of each, in ns, and the
 * root-search steps.  Calls are timed one by one with CLOCK_MONOTONIC
 * (the clock's own cost, some 20 ns, is included).
 */
#include <stdlib.h>
#include <time.h>

#include "plc_harness.h"

static uint64_t rng = 88172645463325252ull;
static double urand(void)
{
    rng ^= rng << 13; rng ^= rng >> 7; rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}
static double uni(double a, double b) { return a + (b - a) * urand(); }
static double logu(double a, double b) { return __builtin_pow(10.0, uni(a, b)); }

static double *L(const char *n)
{
    double *p = located(n, NULL);
    if (!p) { fprintf(stderr, "no %s\n", n); exit(2); }
    return p;
}

static long long now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (long long)t.tv_sec * 1000000000ll + t.tv_nsec;
}

static int cmpll(const void *a, const void *b)
{
    long long x = *(const long long *)a, y = *(const long long *)b;
    return (x > y) - (x < y);
}

static void report(const char *what, long long *v, long n, const char *unit)
{
    qsort(v, (size_t)n, sizeof *v, cmpll);
    printf("%s: n %ld  p50 %lld%s  p99 %lld%s  max %lld%s\n", what, n, v[n / 2], unit,
           v[(long)(n * 0.99)], unit, v[n - 1], unit);
}

int main(int argc, char **argv)
{
    long cases = argc > 1 ? atol(argv[1]) : 20000;
    int16_t *cmd = located("%IW0", NULL), *iters = located("%QW2", NULL), *err = located("%QW1", NULL);
    double *tpos = L("%IL1"), *vset = L("%IL2"), *aset = L("%IL3"), *vl = L("%IL4"),
           *ac = L("%IL5"), *dc = L("%IL6"), *am = L("%IL7"), *jm[4] = {L("%IL8"), L("%IL9"),
           L("%IL10"), L("%IL11")}, *ptm = L("%IL12");
    long long *tre = malloc(sizeof *tre * (size_t)cases);
    long long *tsa = malloc(sizeof *tsa * (size_t)cases * 100);
    long long *it = malloc(sizeof *it * (size_t)cases);
    if (!tre || !tsa || !it) return 2;
    config_init__();
    unsigned long tick = 0;
    long ns = 0, bad = 0;
    for (long c = 0; c < cases; c++) {
        double vel = logu(-1, 3), acc = logu(-1, 3), dec = acc * logu(-0.5, 0.5);
        *vl = vel; *ac = acc; *dc = dec; *am = acc; *ptm = 1.0;
        for (int i = 0; i < 4; i++) *jm[i] = logu(0, 3);
        double v0 = 0, a0 = 0;
        if (c % 2) {
            double amin = acc < dec ? acc : dec;
            v0 = uni(-0.9, 0.9) * vel;
            a0 = uni(-0.9, 0.9) * amin;
            /* keep the speed limit reachable: the jerk is at least amin/1 s */
            double j = *am / (1000.0 / 1000.0);
            if (v0 + a0 * (a0 < 0 ? -a0 : a0) / (2 * j) > vel || v0 + a0 * (a0 < 0 ? -a0 : a0) / (2 * j) < -vel)
                a0 = 0;
        }
        *cmd = 4; *tpos = 0; *vset = v0; *aset = a0;
        config_run__(tick++);
        *cmd = 1; *tpos = (urand() < 0.5 ? -1 : 1) * logu(-3, 3);
        long long t0 = now();
        config_run__(tick++);
        long long t1 = now();
        tre[c] = t1 - t0;
        it[c] = *iters;
        if (*err) bad++;
        *cmd = 0;
        for (int k = 0; k < 100; k++) {
            t0 = now();
            config_run__(tick++);
            t1 = now();
            tsa[ns++] = t1 - t0;
        }
    }
    report("replan call (POSA)", tre, cases, " ns");
    report("sample call", tsa, ns, " ns");
    report("root-search steps", it, cases, "");
    if (bad) printf("refused: %ld\n", bad);
    return bad != 0;
}
