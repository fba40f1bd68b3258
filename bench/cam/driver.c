/*
 * Time the scans of one CAM benchmark program (bench/cam/bench_NAME.st).
 *
 *   driver program.st scans
 *
 * The program does its work in every scan after the first (which sets the
 * curve or the cams up) and says in %QD0 how many calls of the block under
 * test one scan makes.  Prints the median over `scans` scans of the cost
 * per call, in ns, on one line: "ns_per_call N".  Only the generated code's
 * contract is used (entry points, located variables), as the test harness.
 */
#include <stdlib.h>
#include <time.h>

#include "plc_harness.h"
#include "../common/bench_clock.h"


int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: %s program.st scans\n", argv[0]);
        return 2;
    }
    long n = atol(argv[2]);
    uint32_t *calls = located("%QD0", NULL);
    if (n < 1 || !calls) {
        fprintf(stderr, "%s: no scans or no %%QD0\n", argv[0]);
        return 2;
    }
    long long *t = malloc(sizeof *t * (size_t)n);
    if (!t)
        return 1;
    config_init__();
    config_run__(0);
    tick_clock();
    for (long i = 0; i < n; i++) {
        long long t0 = now_ns();
        config_run__((unsigned long)i + 1);
        t[i] = now_ns() - t0;
        tick_clock();
    }
    qsort(t, (size_t)n, sizeof *t, cmp_ll);
    printf("ns_per_call %.1f\n", (double)t[n / 2] / (double)(*calls ? *calls : 1));
    free(t);
    return 0;
}
