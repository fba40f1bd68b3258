#!/usr/bin/env bash
# Build and run EPICPOS test programs: each is compiled together with the
# library and the test support blocks, linked with harness.c and run.
#   tests/epicpos/run.sh OUTDIR LIBRARY.st prog.st...
# Environment: STC (compiler command), STC_INC (its header folder), CC, CFLAGS.
# A program's "(* MAXTICKS n *)" comment bounds its run (1 tick = 1 ms).
set -u
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../common/st_build.sh"
out=$1 lib=$2; shift 2
status=0
for st in "$@"; do
    name=$(basename "$st" .st)
    d="$out/$name"
    rm -rf "$d" && mkdir -p "$d"
    cat "$lib" "$here/tsupport.st" "$st" > "$d/all.st"
    st_compile "$d/all.st" "$d" "epicpos/$name" || { status=1; continue; }
    st_link "$d" "$here/harness.c" "$d/prog" "epicpos/$name" || { status=1; continue; }
    ticks=$(sed -n 's/.*(\* MAXTICKS \([0-9]*\) \*).*/\1/p' "$st" | head -1)
    timeout 300 "$d/prog" "$st" "${ticks:-100000}" || status=1
done
exit $status
