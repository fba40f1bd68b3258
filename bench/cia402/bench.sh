#!/usr/bin/env bash
# CiA 402 drive benchmark: the scan's cost per drive (CIA402DRIVE in CSP
# with LJPROF planning, 1 and 64 drives, timed scan by scan with
# bench/aposs/driver.c) and the bus load: drives per 1 Mbit/s bus at a 1 ms
# and a 4 ms SYNC period against the frame-time bound (busload.py).
#   bench/cia402/bench.sh OUTDIR LIBRARY.st [SCANS [ROUNDS]]
# Environment: STC, STC_INC, CC, CFLAGS.
set -u
here=$(cd "$(dirname "$0")" && pwd)
top=$(cd "$here/../.." && pwd)
. "$top/tests/common/st_build.sh"
out=$1 lib=$2 scans=${3:-3000} rounds=${4:-5}
. "$top/bench/common/scan_rounds.sh"
for n in 1 64; do
    d="$out/drives$n"
    rm -rf "$d" && mkdir -p "$d"
    sed "s/@N@/$n/g" "$here/axes.st.in" > "$d/axes.st"
    cat "$lib" "$d/axes.st" > "$d/all.st"
    scan_rounds "bench-cia402/drives$n" "$d" "$d/all.st" "$top/bench/aposs/driver.c" "$scans" "$rounds" || exit 1
    eval "med$n=$med p99$n=$p99"
    printf 'bench-cia402: %2d drives: %8.0f ns per scan median, %8.0f ns p99 (%s scans, median of %s rounds); %s POSA per round, %s drives in error\n' \
        "$n" "$med" "$p99" "$scans" "$rounds" "$moves" "$bad"
    [ "$bad" = 0 ] || { echo "bench-cia402: FAIL: drives in error: the figures do not show moving drives"; exit 1; }
done
# shellcheck disable=SC2154
awk -v m="$med64" -v p="$p9964" 'BEGIN {
    printf "bench-cia402: scan cost per drive: %.0f ns median, %.0f ns p99 (64 drives)\n", m / 64, p / 64 }'
python3 "$here/busload.py" "$top/examples/cia402/drive402.eds"
