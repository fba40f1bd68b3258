#!/usr/bin/env bash
# Build and run the PLCopen test programs: each is compiled together with the
# library, the simulated plant block (c_blocks/sim_axis.st), the check
# recorder of the EPICPOS tests (tests/epicpos/tsupport.st) and the rig of
# this folder (psupport.st), linked with the EPICPOS harness and the plant's
# C body, and run tick by tick (1 tick = 1 ms).
#   tests/plcopen/run.sh OUTDIR LIBRARY.st prog.st...
# Environment: STC (compiler command), STC_INC (its header folder), CC, CFLAGS.
# A program's "(* MAXTICKS n *)" comment bounds its run.
set -u
here=$(cd "$(dirname "$0")" && pwd)
top=$(cd "$here/../.." && pwd)
. "$here/../common/st_build.sh"
out=$1 lib=$2; shift 2
status=0
for st in "$@"; do
    name=$(basename "$st" .st)
    d="$out/$name"
    rm -rf "$d" && mkdir -p "$d"
    cat "$lib" "$top/c_blocks/sim_axis.st" "$top/tests/epicpos/tsupport.st" \
        "$here/psupport.st" "$st" > "$d/all.st"
    st_compile "$d/all.st" "$d" "plcopen/$name" || { status=1; continue; }
    if [ -s "$d/stc.log" ]; then
        echo "FAIL: plcopen/$name: the compiler warns:"
        sed 's/^/    /' "$d/stc.log" | head -20
        status=1
    fi
    st_link "$d" "$here/../epicpos/harness.c" "$d/prog" "plcopen/$name" \
        -I "$top/c_blocks" "$top/c_blocks/plant.c" || { status=1; continue; }
    ticks=$(sed -n 's/.*(\* MAXTICKS \([0-9]*\) \*).*/\1/p' "$st" | head -1)
    # the harness labels its lines for the EPICPOS suite: relabel them
    timeout 300 "$d/prog" "$st" "${ticks:-100000}" > "$d/out.txt"
    rc=$?
    sed 's#^\(PASS\|FAIL\): epicpos/#\1: plcopen/#' "$d/out.txt"
    [ $rc -eq 0 ] || status=1
done
exit $status
