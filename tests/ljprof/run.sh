#!/usr/bin/env bash
# Build and run the LJPROF test programs: each is compiled with the
# library, the check block of the EPICPOS tests (tests/epicpos/tsupport.st)
# and ljsupport.st, linked with the EPICPOS harness (which prints a
# PASS:/FAIL: line per "(* CHECK n: ... *)" comment) and run.
#   tests/ljprof/run.sh OUTDIR LIBRARY.st prog.st...
# Environment: STC (compiler command), STC_INC (its header folder), CC, CFLAGS.
set -u
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../common/st_build.sh"
out=$1 lib=$2; shift 2
status=0
for st in "$@"; do
    name=$(basename "$st" .st)
    d="$out/$name"
    rm -rf "$d" && mkdir -p "$d"
    cat "$lib" "$here/../epicpos/tsupport.st" "$here/ljsupport.st" "$st" > "$d/all.st"
    st_compile "$d/all.st" "$d" "ljprof/$name" || { status=1; continue; }
    st_link "$d" "$here/../epicpos/harness.c" "$d/prog" "ljprof/$name" || { status=1; continue; }
    ticks=$(sed -n 's/.*(\* MAXTICKS \([0-9]*\) \*).*/\1/p' "$st" | head -1)
    timeout 300 "$d/prog" "$st" "${ticks:-100}" > "$d/out.txt"
    rc=$?
    sed 's#^\(PASS\|FAIL\): epicpos/#\1: ljprof/#' "$d/out.txt"
    [ $rc -eq 0 ] || status=1
done
exit $status
