#!/usr/bin/env bash
# The output contract of stc (DESIGN.md section 2), checked on
# contract/cell.st: command line, file names, LOCATED_VARIABLES.h,
# VARIABLES.csv, and a runtime-like C file built against the output.
#   tests/stc/contract.sh OUTDIR
# Environment: STC, STC_INC, CC, CFLAGS. Prints PASS:/FAIL: lines.
set -u
here=$(cd "$(dirname "$0")" && pwd)
out=$1
st=$here/contract/cell.st
status=0
pass() { echo "PASS: contract: $1"; }
fail() { echo "FAIL: contract: $1"; shift; for l in "$@"; do printf '    %s\n' "$l"; done; status=1; }

if v=$($STC --version 2>&1) && [ -n "$v" ]; then pass "--version prints '$v'"; else fail "--version"; fi
d=$($STC --include-dir 2>&1)
if [ -d "$d" ] && [ "$(cd "$d" && pwd -P)" = "$(cd "$STC_INC" && pwd -P)" ]; then
    pass "--include-dir names the header folder"
else
    fail "--include-dir printed '$d', not the folder $STC_INC"
fi

rm -rf "$out" && mkdir -p "$out/c"
if ! $STC -T "$out/c" "$st" > "$out/stc.log" 2>&1; then
    fail "stc rejected cell.st" "$(head -5 "$out/stc.log")"
    exit 1
fi
c=$out/c
for f in POUS.c POUS.h Cell.c Cell.h Plc1.c LOCATED_VARIABLES.h VARIABLES.csv; do
    if [ -f "$c/$f" ]; then pass "writes $f"; else fail "writes $f" "$(ls "$c")"; fi
done
if grep -q '^#include "POUS.c"' "$c/Plc1.c" 2>/dev/null; then pass "Plc1.c includes POUS.c"; else fail "Plc1.c includes POUS.c"; fi

want_located='__LOCATED_VAR(BOOL,__IX0_0,I,X,0,0)
__LOCATED_VAR(BOOL,__IX1_2_3,I,X,1,2,3)
__LOCATED_VAR(BYTE,__QB5,Q,B,5)
__LOCATED_VAR(INT,__QW3,Q,W,3)
__LOCATED_VAR(LINT,__IL4,I,L,4)
__LOCATED_VAR(REAL,__MD2,M,D,2)'
got_located=$(grep -v '^[[:space:]]*$' "$c/LOCATED_VARIABLES.h" 2>/dev/null | LC_ALL=C sort)
if [ "$got_located" = "$(printf '%s\n' "$want_located" | LC_ALL=C sort)" ]; then
    pass "LOCATED_VARIABLES.h lists the six located variables"
else
    fail "LOCATED_VARIABLES.h" "$got_located"
fi

csv=$c/VARIABLES.csv
sections=$(grep '^// ' "$csv" 2>/dev/null | tr '\n' '|')
if [ "$sections" = "// Programs|// Variables|// Ticktime|" ]; then pass "VARIABLES.csv sections"; else fail "VARIABLES.csv sections: $sections"; fi
if grep -qx '0;CELL.PLC1.INST0;MAIN;' "$csv"; then pass "VARIABLES.csv program row"; else fail "VARIABLES.csv program row" "$(sed -n '1,3p' "$csv")"; fi
tick=$(sed -n '/^\/\/ Ticktime/{n;p;}' "$csv")
if [ "$tick" = 5000000 ]; then pass "VARIABLES.csv ticktime 5000000 ns"; else fail "VARIABLES.csv ticktime: '$tick'"; fi
# rows: num;kind;IEC_path;C_path;type;derived;retain;
rows='VAR;CELL.G;CELL.G;DINT;DINT;0;
VAR;CELL.GR;CELL.GR;INT;INT;1;
FB;CELL.PLC1.INST0;CELL.PLC1.INST0;MAIN;;0;
VAR;CELL.PLC1.INST0.PIN;CELL.PLC1.INST0.PIN;INT;INT;0;
VAR;CELL.PLC1.INST0.POUT;CELL.PLC1.INST0.POUT;INT;INT;0;
EXT;CELL.PLC1.INST0.G;CELL.PLC1.INST0.G;DINT;DINT;0;
IN;CELL.PLC1.INST0.X;CELL.PLC1.INST0.X;BOOL;BOOL;0;
OUT;CELL.PLC1.INST0.Y;CELL.PLC1.INST0.Y;INT;INT;0;
MEM;CELL.PLC1.INST0.M;CELL.PLC1.INST0.M;REAL;REAL;0;
IN;CELL.PLC1.INST0.L;CELL.PLC1.INST0.L;LINT;LINT;0;
OUT;CELL.PLC1.INST0.B;CELL.PLC1.INST0.B;BYTE;BYTE;0;
IN;CELL.PLC1.INST0.Z;CELL.PLC1.INST0.Z;BOOL;BOOL;0;
VAR;CELL.PLC1.INST0.CNT;CELL.PLC1.INST0.CNT;INT;INT;0;
FB;CELL.PLC1.INST0.AC;CELL.PLC1.INST0.AC;ACC;;0;
VAR;CELL.PLC1.INST0.AC.X;CELL.PLC1.INST0.AC.X;INT;INT;0;
VAR;CELL.PLC1.INST0.AC.TOTAL;CELL.PLC1.INST0.AC.TOTAL;DINT;DINT;0;
VAR;CELL.PLC1.INST0.AC.IO;CELL.PLC1.INST0.AC.IO;INT;INT;0;
FB;CELL.PLC1.INST0.TM;CELL.PLC1.INST0.TM;TON;;0;
VAR;CELL.PLC1.INST0.TM.IN;CELL.PLC1.INST0.TM.IN;BOOL;BOOL;0;
VAR;CELL.PLC1.INST0.TM.PT;CELL.PLC1.INST0.TM.PT;TIME;TIME;0;
VAR;CELL.PLC1.INST0.TM.Q;CELL.PLC1.INST0.TM.Q;BOOL;BOOL;0;
VAR;CELL.PLC1.INST0.TM.ET;CELL.PLC1.INST0.TM.ET;TIME;TIME;0;
VAR;CELL.PLC1.INST0.KEPT;CELL.PLC1.INST0.KEPT;UDINT;UDINT;1;'
missing=$(printf '%s\n' "$rows" | while IFS= read -r r; do
    grep -q "^[0-9][0-9]*;$r\$" "$csv" || echo "$r"; done)
if [ -z "$missing" ]; then pass "VARIABLES.csv rows of every declared variable"; else fail "VARIABLES.csv rows missing:" $missing; fi
nums=$(sed -n '/^\/\/ Variables/,/^\/\/ Ticktime/p' "$csv" | grep -o '^[0-9]*;' | tr -d ';' | tr '\n' ' ')
if [ "$nums" = "$(seq -s ' ' 0 $(( $(echo $nums | wc -w) - 1 ))) " ]; then pass "VARIABLES.csv rows numbered from 0"; else fail "VARIABLES.csv numbering: $nums"; fi

srcs=()
for f in "$c"/*.c; do [ "$(basename "$f")" = POUS.c ] || srcs+=("$f"); done
# shellcheck disable=SC2086
if $CC $CFLAGS -I "$STC_INC" -I "$c" "${srcs[@]}" "$here/contract/contract.c" -o "$out/contract" -lm > "$out/cc.log" 2>&1; then
    timeout 20 "$out/contract" || status=1
else
    fail "a runtime-like C file builds against the output" "$(head -20 "$out/cc.log")"
fi
exit $status
