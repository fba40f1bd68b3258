#!/usr/bin/env bash
# Build and run the CAM test programs: the ones gen_curve.py writes (expected
# values from scipy) and the hand-written ones given, each compiled together
# with the library and the check recorder of the EPICPOS tests
# (tests/epicpos/tsupport.st), linked with the EPICPOS harness, and run.
#   tests/cam/run.sh OUTDIR LIBRARY.st prog.st...
# Environment: STC (compiler command), STC_INC (its header folder), CC, CFLAGS.
# A program's "(* MAXTICKS n *)" comment bounds its run (1 tick = 1 ms).
set -u
here=$(cd "$(dirname "$0")" && pwd)
top=$(cd "$here/../.." && pwd)
. "$here/../common/st_build.sh"
out=$1 lib=$2; shift 2
status=0
mkdir -p "$out/gen"
if ! python3 "$here/gen_curve.py" "$out/gen"; then
    echo "FAIL: cam/gen_curve: the generator failed"
    status=1
fi
for st in "$out"/gen/t_*.st "$@"; do
    [ -f "$st" ] || continue
    d="$out/$(basename "$st" .st)"
    rm -rf "$d" && mkdir -p "$d"
    cat "$lib" "$top/tests/epicpos/tsupport.st" "$st" > "$d/all.st"
    # the generated programs are long straight-line code: gcc's optimiser
    # takes a minute on them and buys nothing, so they are built with -O0
    opt=()
    case $st in "$out"/gen/*) opt=(-O0) ;; esac
    st_check_run cam "$st" "$d" "${opt[@]}" || status=1
done
exit $status
