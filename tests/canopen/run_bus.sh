#!/usr/bin/env bash
# The real-bus suite: first what the host itself can show (a kernel without
# CAN gives one clear error naming the interface and status 2), then the
# tests on vcan0 inside a kernel with CAN ($BUS_RUN, tests/canopen/bus_run.sh).
#   tests/canopen/run_bus.sh BUILD_DIR
set -u
build=$1
bin=$build/co_testmaster
msg=$("$bin" -i vcan0 -n 2 -t 0.1 2>&1); st=$?
if echo "$msg" | grep -q "no CAN support"; then
    [ $st -eq 2 ] && echo "$msg" | grep -q "CAN interface vcan0" \
        && echo "PASS: canopen_host/no_can_in_kernel" \
        || echo "FAIL: canopen_host/no_can_in_kernel: status $st: $msg"
else   # this kernel has CAN: a missing interface must be named instead
    msg=$("$bin" -i nocan42 -n 2 -t 0.1 2>&1); st=$?
    [ $st -eq 2 ] && echo "$msg" | grep -q "CAN interface nocan42: no such interface" \
        && echo "PASS: canopen_host/no_such_interface" \
        || echo "FAIL: canopen_host/no_such_interface: status $st: $msg"
fi
exec ${BUS_RUN:-tests/canopen/bus_run.sh} "$build/uml" @PY@ tests/canopen/bus_test.py "$build" "$build/uml"
