#!/usr/bin/env bash
# Build and run EPICPOS test programs: each is compiled together with the
# library and the test support blocks, linked with harness.c and run.
#   tests/epicpos/run.sh OUTDIR LIBRARY.st prog.st...
# Environment: STC (compiler command), STC_INC (its header folder), CC, CFLAGS.
# A program's "(* MAXTICKS n *)" comment bounds its run (1 tick = 1 ms).
set -u
here=$(cd "$(dirname "$0")" && pwd)
out=$1 lib=$2; shift 2
status=0
for st in "$@"; do
    name=$(basename "$st" .st)
    d="$out/$name"
    rm -rf "$d" && mkdir -p "$d/c"
    cat "$lib" "$here/tsupport.st" "$st" > "$d/all.st"
    if ! $STC -T "$d/c" "$d/all.st" > "$d/stc.log" 2>&1; then
        echo "FAIL: epicpos/$name: the compiler rejected it:"
        sed 's/^/    /' "$d/stc.log" | head -20
        status=1; continue
    fi
    srcs=()
    for f in "$d"/c/*.c; do
        [ "$(basename "$f")" = POUS.c ] || srcs+=("$f")
    done
    # shellcheck disable=SC2086
    if ! $CC $CFLAGS -I "$STC_INC" -I "$d/c" "${srcs[@]}" "$here/harness.c" -I "$here/../common" -o "$d/prog" -lm > "$d/cc.log" 2>&1; then
        echo "FAIL: epicpos/$name: the generated C does not build:"
        sed 's/^/    /' "$d/cc.log" | head -20
        status=1; continue
    fi
    ticks=$(sed -n 's/.*(\* MAXTICKS \([0-9]*\) \*).*/\1/p' "$st" | head -1)
    timeout 300 "$d/prog" "$st" "${ticks:-100000}" || status=1
done
exit $status
