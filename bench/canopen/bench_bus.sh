#!/bin/sh
# Runs inside User-Mode Linux (bench/canopen/run.sh): the stand-alone master
# at 1 ms with the echo program against 1, 8 and 32 simulated nodes.
#   bench_bus.sh BUILD_DIR SECONDS
b=$1; secs=${2:-3}
for n in 1 8 32; do
    ids=$(seq -s, 1 "$n")
    "$b/co_bench" -i vcan0 -n "$n" -t "$secs" -c 1000 > "$b/bench_$n.txt" 2>&1 &
    peer=$!
    sleep 0.2
    "$b/co_testmaster" -i vcan0 -n "$ids" -c 1000 -H 100:300 -p echo -t $((secs + 8)) > "$b/bench_master_$n.txt" 2>&1 &
    master=$!
    wait $peer
    kill $master 2>/dev/null; wait $master
    cat "$b/bench_$n.txt"
    grep -E 'error|dropped [1-9]' "$b/bench_master_$n.txt" | head -5
done
