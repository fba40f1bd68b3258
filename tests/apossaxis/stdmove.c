/*
 * Run the standard-move comparison (tests/apossaxis/stdmove.st.in) for a
 * number of 1 ms ticks and print its figures, "name value" pairs, peaks in
 * 1/1000 qc:  tool_mean tool_worst hand_mean hand_worst bad
 *   stdmove ticks
 */
#include "plc_harness.h"

int main(int argc, char **argv)
{
    static const char *const label[5] = { "tool_mean", "tool_worst", "hand_mean", "hand_worst", "bad" };
    return run_print_qd(argc, argv, label, 5);
}
