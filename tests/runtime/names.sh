#!/bin/sh
# plcrt built from a program whose instances are named p, axis and res0
# (tests/runtime/st/names.st) runs, and each instance counts for itself:
# after n cycles p shows n, axis 2n, res0 3n (read over Modbus with mbpoll).
#   names.sh PLCRT OUTDIR
set -u
plcrt=$1 out=$2
rm -rf "$out" && mkdir -p "$out"
port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
printf '[plc]\nstatus_interval = 0\n[modbus]\nport = %s\n' "$port" > "$out/names.ini"
"$plcrt" -c "$out/names.ini" > "$out/plcrt.log" 2>&1 &
pid=$!
ok=0
for _ in $(seq 300); do      # a generous deadline (30 s): a loaded host starts slowly
    sleep 0.1
    # holding registers 1024..1026 are %MW0..2
    v=$(mbpoll -m tcp -p "$port" -0 -1 -r 1024 -c 3 -t 4 127.0.0.1 2>/dev/null | sed -n 's/^\[102[4-6]\]:[[:space:]]*//p' | tr '\n' ' ')
    set -- $v
    if [ $# -eq 3 ] && [ "$1" -gt 5 ]; then ok=1; break; fi
done
kill "$pid"; wait "$pid"
if [ $ok -ne 1 ]; then
    echo "FAIL: runtime-names/instances_p_axis_res0_run: no counts over Modbus ($v); log:"; cat "$out/plcrt.log"; exit 1
fi
echo "PASS: runtime-names/instances_p_axis_res0_run"
# within one read the three counters come from one cycle: n, 2n, 3n
a=$1 b=$2 c=$3
if [ "$b" -eq $((2 * a)) ] && [ "$c" -eq $((3 * a)) ]; then
    echo "PASS: runtime-names/each_instance_counts_for_itself ($a $b $c)"
else
    echo "FAIL: runtime-names/each_instance_counts_for_itself: p $a, axis $b, res0 $c (want n, 2n, 3n)"; exit 1
fi
