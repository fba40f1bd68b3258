#!/bin/sh
# A located variable outside the process image stops the build, naming it.
#   located_outside.sh STC STC_INC OUTDIR CC CFLAGS...
set -u
stc=$1 inc=$2 out=$3 cc=$4; shift 4
rm -rf "$out" && mkdir -p "$out/gen"
if ! "$stc" -T "$out/gen" tests/runtime/st/outside.st > "$out/stc.log" 2>&1; then
    echo "FAIL: located-outside: the compiler rejected the program"; cat "$out/stc.log"; exit 1
fi
plc_runtime/gen_program.sh "$out/gen" "$out/program.c" || { echo "FAIL: located-outside: gen_program.sh"; exit 1; }
if "$cc" "$@" -I "$inc" -I "$out/gen" -I plc_runtime -c "$out/program.c" -o "$out/program.o" > "$out/cc.log" 2>&1; then
    echo "FAIL: located-outside: %QW1024 was accepted"; exit 1
fi
if grep -q '__QW1024 lies outside the process image' "$out/cc.log"; then
    echo "PASS: located-outside: build stopped naming __QW1024"
else
    echo "FAIL: located-outside: no message naming __QW1024:"; cat "$out/cc.log"; exit 1
fi
