#!/usr/bin/env bash
# Build and run the CIA402DRIVE test programs: each is compiled together
# with the library, the check recorder of the EPICPOS tests
# (tests/epicpos/tsupport.st) and the standard's state machine as a drive
# model (tdrive.st), linked with the EPICPOS harness and run tick by tick.
#   tests/cia402/run.sh OUTDIR LIBRARY.st prog.st...
# Environment: STC (compiler command), STC_INC (its header folder), CC, CFLAGS.
set -u
here=$(cd "$(dirname "$0")" && pwd)
top=$(cd "$here/../.." && pwd)
. "$here/../common/st_build.sh"
out=$1 lib=$2; shift 2
status=0
for st in "$@"; do
    d="$out/$(basename "$st" .st)"
    rm -rf "$d" && mkdir -p "$d"
    cat "$lib" "$top/tests/epicpos/tsupport.st" "$here/tdrive.st" "$st" > "$d/all.st"
    st_check_run cia402 "$st" "$d" || status=1
done
exit $status
