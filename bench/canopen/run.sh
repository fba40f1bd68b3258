#!/bin/sh
# make bench: the CANopen figures, measured on vcan0 inside User-Mode Linux.
b=$1
"$b/co_core_bench"
exec tests/canopen/uml_run.sh "$b/bench_uml" sh bench/canopen/bench_bus.sh "$b" 3
