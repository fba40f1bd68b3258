#!/bin/sh
# make bench: the CANopen figures, measured on vcan0 inside a kernel with CAN
# (tests/canopen/bus_run.sh: User-Mode Linux, or QEMU where UML cannot run).
b=$1
"$b/co_core_bench"
BUS_BUILD=$(cd "$b" && pwd) exec tests/canopen/bus_run.sh "$b/bench_uml" sh bench/canopen/bench_bus.sh "$b" 3
