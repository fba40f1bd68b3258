#!/usr/bin/env bash
# Build and run the PLCopen test programs with the APOSSCTL suite's runner
# (library + simulated plant block + check recorder, linked with the EPICPOS
# harness and the plant's C body, run tick by tick, 1 tick = 1 ms), the
# library extended by this folder's rig (psupport.st).
#   tests/plcopen/run.sh OUTDIR LIBRARY.st prog.st...
# Environment: STC (compiler command), STC_INC (its header folder), CC, CFLAGS.
set -u
here=$(cd "$(dirname "$0")" && pwd)
out=$1 lib=$2; shift 2
mkdir -p "$out"
cat "$lib" "$here/psupport.st" > "$out/lib.st"
"$here/../apossctl/run.sh" "$out" "$out/lib.st" "$@" | sed 's#^\(PASS\|FAIL\): apossctl/#\1: plcopen/#'
exit "${PIPESTATUS[0]}"
