#!/usr/bin/env bash
# CAM benchmarks: CAMCURVE's cost per evaluation at 1000 fix points (the
# target is 2 us), CAMBOX's cost per scan with 32 cams and CAMSYNC's per
# scan, each beside the 1 ms task interval.  The programs are built as plcrt builds a program
# (the compiler's output, -O2) and timed scan by scan; the median is shown.
#   bench/cam/bench.sh OUTDIR LIBRARY.st
# Environment: STC, STC_INC, CC, CFLAGS.
set -u
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../../tests/common/st_build.sh"
out=$1 lib=$2
status=0
for name in bench_curve bench_box bench_sync; do
    d="$out/$name"
    rm -rf "$d" && mkdir -p "$d"
    cat "$lib" "$here/$name.st" > "$d/all.st"
    st_compile "$d/all.st" "$d" "bench-cam/$name" || { status=1; continue; }
    st_link "$d" "$here/driver.c" "$d/prog" "bench-cam/$name" || { status=1; continue; }
    ns=$("$d/prog" "$here/$name.st" 2001 | sed -n 's/^ns_per_call //p')
    case $name in
    bench_curve)
        awk -v ns="$ns" 'BEGIN { printf "bench-cam: CAMCURVE, 1000 fix points: %.0f ns per evaluation (target <= 2000 ns: %s); %.4f %% of a 1 ms scan\n", ns, (ns <= 2000 ? "met" : "MISSED"), ns / 1e4 }' ;;
    bench_box)
        awk -v ns="$ns" 'BEGIN { printf "bench-cam: CAMBOX, 32 cams on 16 tracks, modulo axis: %.0f ns per scan; %.4f %% of a 1 ms scan\n", ns, ns / 1e4 }' ;;
    bench_sync)
        awk -v ns="$ns" 'BEGIN { printf "bench-cam: CAMSYNC, 1000-point curve, marker correction on: %.0f ns per scan; %.4f %% of a 1 ms scan\n", ns, ns / 1e4 }' ;;
    esac
done
exit $status
