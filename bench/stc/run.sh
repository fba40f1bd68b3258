#!/usr/bin/env bash
# stc benchmarks: compile time of the project's ST, and instructions per scan
# of a compiled program beside the same logic written by hand in C.
set -euo pipefail
stc=$1; inc=$2; out=$3
mkdir -p "$out"
cd "$(dirname "$0")/../.."

echo "== stc compile time (mean of 10 runs each)"
for f in $(ls st/*/*.st examples/*/*.st bench/stc/*.st 2>/dev/null); do
    start=$(date +%s%N)
    for _ in 1 2 3 4 5 6 7 8 9 10; do "$stc" -T "$out/ct" "$f" >/dev/null 2>&1 || true; done
    end=$(date +%s%N)
    printf '  %-40s %8.2f ms  (%d lines)\n' "$f" "$(echo "($end - $start) / 10000000" | bc -l)" "$(wc -l < "$f")"
done

echo "== instructions per scan (valgrind --tool=callgrind), scan.st vs the same logic by hand"
"$stc" -T "$out/gen" bench/stc/scan.st
cc -std=c11 -O2 -I "$inc" -I "$out/gen" -o "$out/scan_bench" bench/stc/scan_main.c bench/stc/scan_hand.c \
   "$out/gen/Config0.c" "$out/gen/Res0.c" -lm
"$out/scan_bench" st 1000; "$out/scan_bench" hand 1000
count() {   # instructions for N scans
    valgrind --tool=callgrind --callgrind-out-file=/dev/null "$out/scan_bench" "$1" "$2" 2>&1 |
        sed -n 's/.*Collected : *\([0-9]*\).*/\1/p'
}
for who in st hand; do
    a=$(count $who 1000); b=$(count $who 11000)
    eval "per_$who=$(( (b - a) / 10000 ))"
done
echo "  stc-compiled ST : $per_st instructions/scan"
echo "  hand-written C  : $per_hand instructions/scan"
echo "  ratio           : $(echo "scale=2; $per_st / $per_hand" | bc) (aim: within 1.5)"
