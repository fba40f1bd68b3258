/*
 * Harness for the ISG filter dump (coef.st): runs the program tick by tick
 * until it sets %QX0.0 (done) and, after every tick in which it set %QX0.1
 * (a row), prints "ROW" and the LREALs %ML0..%ML15, exactly (%.17g), for
 * test_filters.py to evaluate with scipy.
 *
 *   dump maxticks
 */
#include <stdlib.h>

#include "plc_harness.h"

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: %s maxticks\n", argv[0]);
        return 2;
    }
    long maxticks = atol(argv[1]);
    uint8_t *done = located("%QX0.0", NULL), *row = located("%QX0.1", NULL);
    double *ml[16];
    for (int i = 0; i < 16; i++) {
        char a[16];
        snprintf(a, sizeof a, "%%ML%d", i);
        ml[i] = located(a, NULL);
    }
    if (!done || !row) {
        fprintf(stderr, "no %%QX0.0 (done) or %%QX0.1 (row) in the program\n");
        return 2;
    }
    config_init__();
    for (long tick = 0; tick < maxticks && !*done; tick++) {
        *row = 0;
        config_run__((unsigned long)tick);
        tick_clock();
        if (!*row) continue;
        printf("ROW");
        for (int i = 0; i < 16; i++) printf(" %.17g", ml[i] ? *ml[i] : 0.0);
        printf("\n");
    }
    if (!*done) {
        fprintf(stderr, "not finished after %ld ticks\n", maxticks);
        return 1;
    }
    return 0;
}
