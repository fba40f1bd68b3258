/*
 * Run the gains comparison program (bench/aposs/gains.st.in) for a number
 * of 1 ms ticks and print its figures (%QD0..%QD13, named in the program's
 * header comment) on one line, "name value" pairs, peaks in 1/1000 qc.
 *   gains ticks
 */
#include <stdlib.h>

#include "plc_harness.h"

int main(int argc, char **argv)
{
    long n = argc == 2 ? atol(argv[1]) : 0;
    int32_t *q[14];
    for (int i = 0; i < 14; i++) {
        char name[8];
        snprintf(name, sizeof name, "%%QD%d", i);
        q[i] = located(name, NULL);
        if (!q[i])
            n = 0;
    }
    if (n < 1) {
        fprintf(stderr, "usage: %s ticks (program with %%QD0..%%QD13)\n", argv[0]);
        return 2;
    }
    config_init__();
    for (long i = 0; i < n; i++) {
        config_run__((unsigned long)i);
        tick_clock();
    }
    static const char *const label[14] = {
        "tool", "tool_worst", "model", "grid", "grid_kprop", "grid_kder", "grid_ffacc",
        "load_tool", "load_model", "load_grid", "load_grid_kprop", "load_grid_kder", "load_grid_ffacc", "bad" };
    for (int i = 0; i < 14; i++)
        printf("%s%s %ld", i ? " " : "", label[i], (long)*q[i]);
    printf("\n");
    return 0;
}
