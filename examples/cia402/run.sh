#!/usr/bin/env bash
# make run-cia402: two simulated CiA 402 drives (nodes 5 and 6,
# tests/canopen/drive402.py) on vcan0 and plcrt moving them with the example
# program; Ctrl-C stops plcrt (drives disabled, outputs 0), then the drives.
# PYTHON names the interpreter that has python-canopen (default python3).
#   examples/cia402/run.sh PLCRT [INI]
set -u
plcrt=$1
ini=${2:-examples/cia402/cia402.ini}
iface=$(sed -n 's/^interface *= *\([^ ;]*\).*/\1/p' "$ini" | head -1)
iface=${iface:-can0}
if ! ip link show "$iface" >/dev/null 2>&1; then
    echo "run-cia402: no CAN interface $iface on this host. With a kernel that has vcan:"
    echo "    sudo modprobe vcan && sudo ip link add dev $iface type vcan && sudo ip link set $iface up"
    echo "(docs/drives.md; the bus tests run the same example inside User-Mode Linux: make canopen_cia402)"
    exit 2
fi
"${PYTHON:-python3}" tests/canopen/drive402.py --interface "$iface" 5 6 &
sim=$!
trap 'kill "$sim" 2>/dev/null; wait "$sim" 2>/dev/null' EXIT
sleep 1             # the drives listen before plcrt resets them
mk/run_fg.sh "$plcrt" -c "$ini"
