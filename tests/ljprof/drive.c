/*
 * Harness running LJDRIVE (drive.st, one LJPROF) for a list of moves read
 * from standard input, one per line:
 *
 *   p0 v0 a0 target VEL ACC DEC ACCMAX JERKMIN JERKMIN2 JERKMIN3 JERKMIN4 PROFTIME
 *
 * Each move: SETPOS to (p0, v0, a0), POSA to target, then samples until done
 * (at most 10^7, or the first argument).  Prints one line per move:
 *
 *   ptime samples final_pos vmax_ratio amax_ratio overshoot snaperr err iters jerk_ok
 *
 * vmax_ratio is max |v| / VEL, amax_ratio max |a| / (ACC while speeding up,
 * DEC while slowing down), overshoot the farthest the set-point went past the
 * target in the direction of travel at the end (0 if never), jerk_ok 1 when
 * every sample's jerk was 0 or one of the four jerks ACCMAX/JERKMINx.
 * Only the generated code's contract is used (docs/stc.md).
 */
#include <math.h>
#include <stdlib.h>

#include "plc_harness.h"

static double *L(const char *n)
{
    double *p = located(n, NULL);
    if (!p) { fprintf(stderr, "no %s\n", n); exit(2); }
    return p;
}

int main(int argc, char **argv)
{
    long maxs = argc > 1 ? atol(argv[1]) : 10000000;
    int16_t *cmd = located("%IW0", NULL);
    double *tpos = L("%IL1"), *vset = L("%IL2"), *aset = L("%IL3"), *vl = L("%IL4"),
           *ac = L("%IL5"), *dc = L("%IL6"), *am = L("%IL7"), *jm[4] = {L("%IL8"), L("%IL9"),
           L("%IL10"), L("%IL11")}, *ptm = L("%IL12");
    double *pos = L("%QL0"), *vel = L("%QL1"), *acc = L("%QL2"), *jerk = L("%QL3"),
           *ptime = L("%QL4"), *snap = L("%QL5");
    uint8_t *done = located("%QX0.1", NULL);
    int16_t *err = located("%QW1", NULL), *iters = located("%QW2", NULL);
    config_init__();
    unsigned long tick = 0;
    double in[13];
    while (1) {
        int n = 0;
        for (; n < 13; n++)
            if (scanf("%lf", &in[n]) != 1) break;
        if (n < 13) break;
        *vl = in[4]; *ac = in[5]; *dc = in[6]; *am = in[7];
        for (int i = 0; i < 4; i++) *jm[i] = in[8 + i];
        *ptm = in[12];
        *cmd = 4; *tpos = in[0]; *vset = in[1]; *aset = in[2];
        config_run__(tick++);
        *cmd = 1; *tpos = in[3];
        double tgt = in[3], dir = 0;
        double js[4];
        for (int i = 0; i < 4; i++) {
            double t = in[8 + i] > 0 ? in[8 + i] : in[8];
            js[i] = in[7] / (fmax(t, 1e-6) / 1000.0);
        }
        double vmax = 0, amax = 0, over = 0;
        int jok = 1;
        long s;
        for (s = 1; s <= maxs; s++) {
            config_run__(tick++);
            *cmd = 0;
            if (s == 1) {
                if (*err) break;
                dir = tgt > *pos ? 1 : tgt < *pos ? -1 : 0;
            }
            double v = *vel, a = *acc, j = *jerk;
            if (fabs(v) / in[4] > vmax) vmax = fabs(v) / in[4];
            double lim = v * a > 0 ? in[5] : v * a < 0 ? in[6] : fmin(in[5], in[6]);
            if (fabs(a) / lim > amax) amax = fabs(a) / lim;
            if (j != 0) {
                int ok = 0;
                for (int i = 0; i < 4; i++)
                    if (fabs(fabs(j) - js[i]) <= 1e-12 * js[i]) ok = 1;
                if (!ok) jok = 0;
            }
            if (dir != 0 && (*pos - tgt) * dir > over) over = (*pos - tgt) * dir;
            if (*done) break;
        }
        printf("%.17g %ld %.17g %.17g %.17g %.17g %.17g %d %d %d\n", *ptime, s, *pos, vmax,
               amax, over, *snap, *err, *iters, jok);
        fflush(stdout);
    }
    return 0;
}
