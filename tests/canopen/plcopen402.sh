#!/usr/bin/env bash
# The canopen_plcopen402 suite: the PLCopen program on the sim plant first,
# on the host (its 1 ms task would be starved inside the kernel with CAN on
# a loaded host), traced; then the same program on two CiA 402 drives in
# the kernel with CAN ($BUS_RUN, tests/canopen/bus_run.sh), traced and
# compared with the sim run's trace (tests/canopen/plcrt_plcopen402_test.py).
#   tests/canopen/plcopen402.sh PLCRT SIM_PLCRT OUTDIR
set -u
plcrt=$1 sim=$2 out=$3
mkdir -p "$out"
status=0
python3 tests/canopen/plcrt_plcopen402_test.py --sim "$sim" "$out" || status=1
${BUS_RUN:-tests/canopen/bus_run.sh} "$out" @PY@ tests/canopen/plcrt_plcopen402_test.py "$plcrt" "$out" || status=1
exit $status
