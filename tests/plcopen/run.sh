#!/usr/bin/env bash
# Build and run the PLCopen test programs with the APOSSCTL suite's runner
# (library + simulated plant block + check recorder, linked with the EPICPOS
# harness and the plant's C body, run tick by tick, 1 tick = 1 ms), each
# program preceded by this folder's rig (psupport.st, which uses the plant
# block and so comes after it: matiec wants a block declared before use).
#   tests/plcopen/run.sh OUTDIR LIBRARY.st prog.st...
# Environment: STC (compiler command), STC_INC (its header folder), CC, CFLAGS.
set -u
here=$(cd "$(dirname "$0")" && pwd)
out=$1 lib=$2; shift 2
mkdir -p "$out/src"
progs=()
for st in "$@"; do
    p="$out/src/$(basename "$st")"
    cat "$here/psupport.st" "$st" > "$p"
    progs+=("$p")
done
"$here/../apossctl/run.sh" "$out" "$lib" "${progs[@]}" | sed 's#^\(PASS\|FAIL\): apossctl/#\1: plcopen/#'
exit "${PIPESTATUS[0]}"
