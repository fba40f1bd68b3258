#!/usr/bin/env bash
# Build and run the LJPROF test programs with the EPICPOS test runner
# (tests/epicpos/run.sh: the library, its check block TCHECK and harness,
# one PASS:/FAIL: line per "(* CHECK n: ... *)" comment), the library being
# followed by ljsupport.st; the results are labelled ljprof/.
#   tests/ljprof/run.sh OUTDIR LIBRARY.st prog.st...
# Environment: STC (compiler command), STC_INC (its header folder), CC, CFLAGS.
set -u -o pipefail
here=$(cd "$(dirname "$0")" && pwd)
out=$1 lib=$2; shift 2
mkdir -p "$out"
cat "$lib" "$here/ljsupport.st" > "$out/lib.st"
"$here/../epicpos/run.sh" "$out" "$out/lib.st" "$@" | sed 's#^\(PASS\|FAIL\): epicpos/#\1: ljprof/#'
