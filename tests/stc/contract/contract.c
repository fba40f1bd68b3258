/*
 * A runtime's view of cell.st compiled by stc: it includes the generated
 * POUS.h, owns the located variables, and reads program, block and global
 * variables through accessor.h (&__GET_VAR(RES__INST.PATH)) and
 * __GET_GLOBAL_<NAME>(), as DESIGN.md section 2 promises.
 * Prints PASS:/FAIL: lines.
 */
#include <stdio.h>
#include "POUS.h"

#define __LOCATED_VAR(type, name, ...) static type name##_store; type *name = &name##_store;
#include "LOCATED_VARIABLES.h"
#undef __LOCATED_VAR

IEC_TIME __CURRENT_TIME;
BOOL __DEBUG;
extern MAIN PLC1__INST0;
extern unsigned long long common_ticktime__;
extern DINT *__GET_GLOBAL_G(void);
void config_init__(void);
void config_run__(unsigned long tick);

static int fails;

static void check(const char *what, long long got, long long want)
{
    if (got == want) {
        printf("PASS: contract: %s = %lld\n", what, want);
    } else {
        printf("FAIL: contract: %s: expected %lld, got %lld\n", what, want, got);
        fails++;
    }
}

static void run(unsigned long from, unsigned long to)
{
    for (unsigned long tick = from; tick < to; tick++) {
        config_run__(tick);
        unsigned long long ns = (unsigned long long)__CURRENT_TIME.tv_nsec + common_ticktime__;
        __CURRENT_TIME.tv_sec += (long)(ns / 1000000000ULL);
        __CURRENT_TIME.tv_nsec = (long)(ns % 1000000000ULL);
    }
}

int main(void)
{
    INT *cnt = &__GET_VAR(PLC1__INST0.CNT);
    DINT *total = &__GET_VAR(PLC1__INST0.AC.TOTAL);
    BOOL *q = &__GET_VAR(PLC1__INST0.TM.Q);
    UDINT *kept = &__GET_VAR(PLC1__INST0.KEPT);

    config_init__();
    check("common_ticktime__ (ns), gcd of 10 ms and 25 ms", (long long)common_ticktime__, 5000000);
    check("initial value of a RETAIN variable", *kept, 5);
    check("initial value of a global", *__GET_GLOBAL_G(), 100);
    /* the 10 ms task runs every second 5 ms tick: ticks 0 and 2 */
    run(0, 3);
    check("program variable after ticks 0..2", *cnt, 2);
    check("TON.Q after 10 ms of a 20 ms PT", *q, 0);
    run(3, 10);
    check("program variable after ticks 0..9", *cnt, 5);
    check("function block output", *total, 10);
    check("TON.Q after 40 ms of a 20 ms PT", *q, 1);
    check("global written through VAR_EXTERNAL", *__GET_GLOBAL_G(), 150);
    check("located output %QW3", *__QW3, 5);
    return fails != 0;
}
