/* Runs N scans of either the compiled ST program or the hand-written C:
**   scan_bench st|hand N */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "iec_std_lib.h"

IEC_TIME __CURRENT_TIME;
BOOL __DEBUG;
#define __LOCATED_VAR(type, name, ...) type __s##name; type *name = &__s##name;
#include "LOCATED_VARIABLES.h"
#undef __LOCATED_VAR

void config_init__(void);
void config_run__(unsigned long tick);
void hand_scan(void);
extern int32_t hand_out;

int main(int argc, char **argv) {
    if (argc != 3) { fprintf(stderr, "usage: scan_bench st|hand N\n"); return 2; }
    long n = atol(argv[2]);
    int st = !strcmp(argv[1], "st");
    if (st) config_init__();
    for (long t = 0; t < n; t++) {
        if (st) config_run__((unsigned long)t);
        else hand_scan();
    }
    printf("%s: out = %d\n", argv[1], st ? (int)*__QD0 : (int)hand_out);
    return 0;
}
