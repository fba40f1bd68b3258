/*
** Cost of one EPICPOS call: one axis on its plant (SIM_AXIS), 1 ms cycles.
**
**   epicpos_call still|move CALLS [timed]
**
** Brings the axis up as the seed's example does (1.6: INIT, CNTUNLOCK,
** CNTDIR, REGON, RESUME, LOOPON), then runs until CALLS calls were made in
** the chosen state: "still" (loop closed, regulating on a still setpoint) or
** "move" (positioned back and forth: profile and PID; the calls made while
** still between two moves are not counted).  The counted calls go through
** call_counted(), never inlined, so that callgrind --toggle-collect counts
** them alone; with "timed" each is timed with clock_gettime and the mean
** and median printed, less the mean cost of reading the clock (the clock
** ticks in steps of 10 ns or more here: the median is that coarse).  Built with the
** compiler's output of a program holding EPICPOS and SIM_AXIS (the
** configuration and resource files are included: one translation unit, as
** plcrt builds a program).
*/
#include "Config0.c"
#include "Res0.c"
#include "accessor.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

IEC_TIME __CURRENT_TIME;
BOOL __DEBUG;
#define __LOCATED_VAR(type, name, ...) type __s##name; type *name = &__s##name;
#include "LOCATED_VARIABLES.h"
#undef __LOCATED_VAR

#define V(x) __GET_VAR(x)

static EPICPOS ax;
static SIM_AXIS pl;

__attribute__((noinline)) static void call_counted(EPICPOS *a) { EPICPOS_body__(a); }
__attribute__((noinline)) static void call_other(EPICPOS *a) { EPICPOS_body__(a); }

static long long now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1000000000LL + t.tv_nsec;
}

/* one 1 ms cycle up to the EPICPOS call: PLC time, plant, inputs */
static void cycle(void)
{
    __CURRENT_TIME.tv_nsec += 1000000;
    if (__CURRENT_TIME.tv_nsec >= 1000000000) {
        __CURRENT_TIME.tv_nsec -= 1000000000;
        __CURRENT_TIME.tv_sec++;
    }
    V(pl.DAC) = V(ax.DAC);
    V(pl.TS) = (IEC_TIME){0, 1000000};
    SIM_AXIS_body__(&pl);
    V(ax.CNT) = V(pl.COUNTER);
    V(ax.CAM) = V(pl.CAM);
}

/* one cycle with a command raised for it */
static void command(BOOL *c)
{
    cycle();
    *c = 1;
    call_other(&ax);
    *c = 0;
}

static int cmp_ll(const void *a, const void *b)
{
    long long x = *(const long long *)a, y = *(const long long *)b;
    return (x > y) - (x < y);
}

static long long median(long long *v, long n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_ll);
    return v[n / 2];
}

int main(int argc, char **argv)
{
    if (argc < 3 || (strcmp(argv[1], "still") && strcmp(argv[1], "move"))) {
        fprintf(stderr, "usage: epicpos_call still|move CALLS [timed]\n");
        return 2;
    }
    int move = !strcmp(argv[1], "move");
    long calls = atol(argv[2]);
    int timed = argc > 3 && !strcmp(argv[3], "timed");
    long long *dt = timed ? calloc((size_t)calls, sizeof *dt) : NULL;
    if (calls < 1 || (timed && !dt)) return 2;

    EPICPOS_init__(&ax, 0);
    SIM_AXIS_init__(&pl, 0);
    V(ax.CNRATIO) = 100000;     /* 1 count = 1 Um */
    V(ax.UNITVEL) = 1;          /* Um/s: maxvel 100000 = the plant's 10 V speed */
    V(ax.MAXVEL) = 100000;
    V(ax.TACCDEC) = 20;
    V(ax.PGAIN) = 30;
    V(ax.TOLL) = 5;
    V(ax.TCAMP) = 1;            /* regulate in every 1 ms call */
    V(ax.SETVEL) = 40000;

    command(&V(ax.INIT));
    command(&V(ax.CNTUNLOCK));
    command(&V(ax.CNTDIR));
    if (V(ax.ST_REGOFF)) command(&V(ax.REGON));
    if (V(ax.ST_EMRG)) command(&V(ax.RESUME));
    command(&V(ax.LOOPON));
    if (!V(ax.ST_INIT) || !V(ax.ST_LOOPON) || V(ax.ST_REGOFF) || V(ax.ST_EMRG)) {
        fprintf(stderr, "epicpos_call: the axis did not start up\n");
        return 1;
    }
    for (int i = 0; i < 100; i++) { cycle(); call_other(&ax); }

    long n = 0, moves = 0, quiet = 0;
    int away = 0;
    DINT maxerr = 0;
    while (n < calls) {
        cycle();
        if (move && V(ax.ST_STILL)) {
            if (++quiet >= 20) {        /* the next move, 20 ms after a stop */
                V(ax.SETPOS) = away ? 0 : 10000;
                away = !away;
                V(ax.START) = 1;
                moves++;
                quiet = 0;
            }
            call_other(&ax);
            V(ax.START) = 0;
            continue;
        }
        quiet = 0;
        if (timed) {
            long long t0 = now_ns();
            call_counted(&ax);
            dt[n] = now_ns() - t0;
        } else {
            call_counted(&ax);
        }
        n++;
        DINT e = V(ax.FOLTERR) < 0 ? -V(ax.FOLTERR) : V(ax.FOLTERR);
        if (e > maxerr) maxerr = e;
    }
    if (V(ax.ST_EMRG) || V(ax.REFCNT) || !V(ax.ST_LOOPON) || (move && moves < 2) ||
        (!move && !V(ax.ST_STILL))) {
        fprintf(stderr, "epicpos_call: the axis left the measured state (emrg %d, refused %d, moves %ld)\n",
                V(ax.ST_EMRG), (int)V(ax.REFCNT), moves);
        return 1;
    }
    printf("calls %ld moves %ld maxfolterr %d", n, moves, (int)maxerr);
    if (timed) {
        double c = 0, sum = 0;
        for (int i = 0; i < 100000; i++) { long long t0 = now_ns(); c += (double)(now_ns() - t0); }
        c /= 100000;
        for (long i = 0; i < n; i++) sum += (double)dt[i];
        printf(" mean_ns %.1f median_ns %.0f clock_ns %.1f", sum / (double)n - c, (double)median(dt, n) - c, c);
    }
    printf("\n");
    return 0;
}
