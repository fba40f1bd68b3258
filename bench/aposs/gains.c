/*
 * Run the gains comparison program (bench/aposs/gains.st.in) for a number
 * of 1 ms ticks and print its figures (%QD0..%QD13, named in the program's
 * header comment) on one line, "name value" pairs, peaks in 1/1000 qc.
 *   gains ticks
 */
#include "plc_harness.h"

int main(int argc, char **argv)
{
    static const char *const label[14] = {
        "tool", "tool_worst", "model", "grid", "grid_kprop", "grid_kder", "grid_ffacc",
        "load_tool", "load_model", "load_grid", "load_grid_kprop", "load_grid_kder", "load_grid_ffacc", "bad" };
    return run_print_qd(argc, argv, label, 14);
}
