/*
 * Runs one ISG bench program tick by tick (1 ms) until it sets %QX0.0, then
 * prints its figures: each "(* FIG n: text *)" comment of the program names
 * the REAL at %QDn, printed as "text: value".
 *
 *   report program.st maxticks
 */
#include <stdlib.h>
#include <string.h>

#include "plc_harness.h"

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: %s program.st maxticks\n", argv[0]);
        return 2;
    }
    long maxticks = atol(argv[2]);
    uint8_t *done = located("%QX0.0", NULL);
    if (!done) {
        fprintf(stderr, "no %%QX0.0 (done) in the program\n");
        return 1;
    }
    config_init__();
    long tick;
    for (tick = 0; tick < maxticks && !*done; tick++) {
        config_run__((unsigned long)tick);
        tick_clock();
    }
    if (!*done) {
        fprintf(stderr, "not finished after %ld ticks\n", maxticks);
        return 1;
    }
    FILE *f = fopen(argv[1], "r");
    if (!f) return 1;
    char line[512];
    while (fgets(line, sizeof line, f)) {
        int n, off = 0;
        char *p = strstr(line, "(* FIG ");
        if (!p || sscanf(p, "(* FIG %d: %n", &n, &off) != 1 || off == 0) continue;
        char *text = p + off, *end = strstr(text, " *)");
        if (end) *end = 0;
        char a[16];
        snprintf(a, sizeof a, "%%QD%d", n);
        float *v = located(a, NULL);
        if (v) printf("%s: %g\n", text, *v);
    }
    fclose(f);
    return 0;
}
