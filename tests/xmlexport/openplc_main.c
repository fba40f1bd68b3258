/* The runtime's side of the contract, kept to what compiles both as C and
 * as C++: OpenPLC v3 compiles the compiler's output (Res0.c, which includes
 * POUS.c, and Config0.c) with g++, so this file and the generated code are
 * built once with gcc and once with g++, and both linked against plant.c
 * compiled as C. It runs the program for 1000 cycles of 1 ms and prints the
 * axis counter read from %QD0. */
#include <stdio.h>
#include "iec_std_lib.h"

IEC_TIME __CURRENT_TIME;
BOOL __DEBUG;
static DINT qd0;
DINT *__QD0 = &qd0;
void config_init__(void);
void config_run__(unsigned long tick);

int main(void)
{
    config_init__();
    for (unsigned long tick = 0; tick < 1000; tick++)
        config_run__(tick);
    printf("%ld\n", (long)qd0);
    return 0;
}
