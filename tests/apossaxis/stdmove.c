/*
 * Run the standard-move comparison (tests/apossaxis/stdmove.st.in) for a
 * number of 1 ms ticks and print its figures, "name value" pairs, peaks in
 * 1/1000 qc:  tool_mean tool_worst hand_mean hand_worst bad
 *   stdmove ticks
 */
#include <stdlib.h>

#include "plc_harness.h"

int main(int argc, char **argv)
{
    long n = argc == 2 ? atol(argv[1]) : 0;
    static const char *const label[5] = { "tool_mean", "tool_worst", "hand_mean", "hand_worst", "bad" };
    int32_t *q[5];
    for (int i = 0; i < 5; i++) {
        char name[8];
        snprintf(name, sizeof name, "%%QD%d", i);
        q[i] = located(name, NULL);
        if (!q[i])
            n = 0;
    }
    if (n < 1) {
        fprintf(stderr, "usage: %s ticks (program with %%QD0..%%QD4)\n", argv[0]);
        return 2;
    }
    config_init__();
    for (long i = 0; i < n; i++) {
        config_run__((unsigned long)i);
        tick_clock();
    }
    for (int i = 0; i < 5; i++)
        printf("%s%s %ld", i ? " " : "", label[i], (long)*q[i]);
    printf("\n");
    return 0;
}
