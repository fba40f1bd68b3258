/*
 * Run the gains comparison program (bench/aposs/gains.st) for a number of
 * 1 ms ticks and print its figures on one line:
 * "tool_peak_mqc T hand_peak_mqc H hand_kprop P hand_kder D bad B
 * samefb_peak_mqc S" (%QD0..%QD5).
 *   gains ticks
 */
#include <stdlib.h>

#include "plc_harness.h"

int main(int argc, char **argv)
{
    long n = argc == 2 ? atol(argv[1]) : 0;
    int32_t *q[6];
    for (int i = 0; i < 6; i++) {
        char name[8];
        snprintf(name, sizeof name, "%%QD%d", i);
        q[i] = located(name, NULL);
        if (!q[i])
            n = 0;
    }
    if (n < 1) {
        fprintf(stderr, "usage: %s ticks (program with %%QD0..%%QD5)\n", argv[0]);
        return 2;
    }
    config_init__();
    for (long i = 0; i < n; i++) {
        config_run__((unsigned long)i);
        tick_clock();
    }
    printf("tool_peak_mqc %ld hand_peak_mqc %ld hand_kprop %ld hand_kder %ld bad %ld samefb_peak_mqc %ld\n",
           (long)*q[0], (long)*q[1], (long)*q[2], (long)*q[3], (long)*q[4], (long)*q[5]);
    return 0;
}
