/*
 * Harness playing the PLC runtime for one EPICPOS test program.
 *
 *   harness program.st maxticks
 *
 * Owns the located variables, runs config_init__() and config_run__(tick),
 * advancing __CURRENT_TIME by common_ticktime__ each tick, until the program
 * sets %QX0.0 (done) or maxticks have run.  The program records its checks
 * with the TCHECK block (tcheck.st): checks 1..128 as bits of %QD0..%QD3
 * (passed at least once) and %QD4..%QD7 (failed at least once); %QD8 is the
 * first failing check, %QD9 (REAL) the value it saw, %QD10/%QD11 two counts
 * reported as information.  Check names come from the program's comments:
 *   (* CHECK 12: name of the check *)
 * Prints one PASS:/FAIL: line per named check; a check never evaluated fails.
 * Only the generated code's contract is used (type widths, __LOCATED_VAR
 * lines, entry points), so it runs either compiler's output.
 */
#include <stdlib.h>

#include "plc_harness.h"

static uint32_t qd(int i)
{
    char a[16];
    snprintf(a, sizeof a, "%%QD%d", i);
    uint32_t *p = located(a, NULL);
    return p ? *p : 0;
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: %s program.st maxticks\n", argv[0]);
        return 2;
    }
    const char *prog = strrchr(argv[1], '/') ? strrchr(argv[1], '/') + 1 : argv[1];
    long maxticks = atol(argv[2]);
    uint8_t *done = located("%QX0.0", NULL);
    if (!done) {
        printf("FAIL: %s: no %%QX0.0 (done) in the program\n", prog);
        return 1;
    }
    config_init__();
    long tick;
    for (tick = 0; tick < maxticks && !*done; tick++) {
        config_run__((unsigned long)tick);
        tick_clock();
    }
    int failed = 0;
    if (!*done) {
        printf("FAIL: %s: not finished after %ld ticks\n", prog, maxticks);
        failed = 1;
    }
    uint32_t firstid = qd(8), v9 = qd(9);
    float firstval;
    memcpy(&firstval, &v9, sizeof firstval);
    printf("info: %s: %ld ticks, counts %u %u\n", prog, tick, qd(10), qd(11));

    FILE *f = fopen(argv[1], "r");
    if (!f) {
        printf("FAIL: %s: cannot read it for the check names\n", prog);
        return 1;
    }
    char line[512];
    int named = 0;
    while (fgets(line, sizeof line, f)) {
        char *s = strstr(line, "(* CHECK ");
        if (!s) continue;
        int id = atoi(s + 9);
        char *name = strchr(s + 9, ':');
        char *end = strstr(s, "*)");
        if (id < 1 || id > 128 || !name || !end) continue;
        name++;
        while (*name == ' ') name++;
        while (end > name && end[-1] == ' ') end--;
        *end = 0;
        named++;
        int w = (id - 1) / 32, b = (id - 1) % 32;
        int pass = (qd(w) >> b) & 1, fail = (qd(4 + w) >> b) & 1;
        if (fail) {
            failed = 1;
            if ((int)firstid == id)
                printf("FAIL: epicpos/%.*s/%s (value %g)\n", (int)(strlen(prog) - 3), prog, name, firstval);
            else
                printf("FAIL: epicpos/%.*s/%s\n", (int)(strlen(prog) - 3), prog, name);
        } else if (!pass) {
            failed = 1;
            printf("FAIL: epicpos/%.*s/%s (never evaluated)\n", (int)(strlen(prog) - 3), prog, name);
        } else {
            printf("PASS: epicpos/%.*s/%s\n", (int)(strlen(prog) - 3), prog, name);
        }
    }
    fclose(f);
    if (!named) {
        printf("FAIL: %s: no CHECK comments\n", prog);
        failed = 1;
    }
    return failed;
}
