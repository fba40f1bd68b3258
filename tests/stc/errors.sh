#!/usr/bin/env bash
# Error tests: each file's first line is
#   (* EXPECT-ERROR line:col message text *)
# stc must exit with status 1, and its first "error:" line must be
# "<file>:line:col: error: ..." containing the message text, followed by
# the source line and a caret under the column.
# A file whose first line is (* MUST-FAIL ... *) only has to be rejected
# with a file:line:col diagnostic, (* MAY-PASS ... *) may also be accepted;
# neither may crash stc or take more than 5 s.
# A file whose first line is (* EXPECT-WARNING line:col message text *) must
# compile (status 0) with exactly one "warning:" line, at line:col, with the text.
# A second line "(* FILES a.st b.st *)" (paths from the test's folder) puts
# those files before the test on stc's command line: one program. The
# expected spot may then name one of them: EXPECT-ERROR a.st:3:5 text.
# Then more such inputs, generated into OUTDIR.
#   tests/stc/errors.sh OUTDIR file.st...
# Environment: STC (compiler command). Prints PASS:/FAIL: lines.
set -u
out=$1; shift
mkdir -p "$out"
status=0
pass() { echo "PASS: $1"; }
fail() { echo "FAIL: $1"; shift; for l in "$@"; do printf '    %s\n' "$l"; done; status=1; }

# Run stc on the files; sets rc and log. Status 124 = killed by timeout.
compile() {
    rm -rf "$out/c" && mkdir -p "$out/c"
    log=$(timeout 5 $STC -T "$out/c" "$@" 2>&1 < /dev/null)
    rc=$?
}

# ---- robustness: no crash, no hang ----
# must_fail NAME FILE: exit status 1 with a file:line:col diagnostic.
# may_pass NAME FILE: as above, or exit status 0.
check_robust() {
    local mode=$1 name=$2 file=$3
    compile "$file"
    if [ $rc -eq 124 ]; then fail "robust $name: stc did not finish within 5 s"; return; fi
    if [ $rc -gt 128 ]; then fail "robust $name: stc killed by signal $((rc - 128))" "$(printf '%s\n' "$log" | tail -3)"; return; fi
    if [ $rc -eq 0 ] && [ "$mode" = may_pass ]; then pass "robust $name (accepted)"; return; fi
    if [ $rc -ne 1 ]; then fail "robust $name: exit status $rc, expected 1"; return; fi
    if printf '%s\n' "$log" | grep -q "^$file:[0-9]*:[0-9]*: error: "; then
        pass "robust $name"
    else
        fail "robust $name: no $file:line:col: error: line" "$(printf '%s\n' "$log" | head -c 300)"
    fi
}
check_warning() {
    local f=$1 L=$2 C=$3 msg=$4
    local name="$f: warning $L:$C $msg"
    compile "$f"
    if [ $rc -ne 0 ]; then fail "$name: exit status $rc, expected 0" "$(printf '%s\n' "$log" | head -5)"; return; fi
    local w; w=$(printf '%s\n' "$log" | grep ': warning: ')
    if [ "$(printf '%s\n' "$w" | grep -c .)" -ne 1 ]; then fail "$name: expected one warning" "$w"; return; fi
    if [[ $w != "$f:$L:$C: warning: "*"$msg"* ]]; then fail "$name: wrong warning" "$w"; return; fi
    pass "$name"
}
for f in "$@"; do
    head=$(head -n 1 "$f")
    if [[ $head =~ ^\(\*\ EXPECT-WARNING\ ([0-9]+):([0-9]+)\ (.*[^ ])\ *\*\)$ ]]; then
        check_warning "$f" "${BASH_REMATCH[1]}" "${BASH_REMATCH[2]}" "${BASH_REMATCH[3]}"; continue
    fi
    case $head in
    "(* MUST-FAIL "*) check_robust must_fail "$f" "$f"; continue ;;
    "(* MAY-PASS "*) check_robust may_pass "$f" "$f"; continue ;;
    esac
    if [[ ! $head =~ ^\(\*\ EXPECT-ERROR\ ([^ :]+:)?([0-9]+):([0-9]+)\ (.*[^ ])\ *\*\)$ ]]; then
        fail "$f: first line is not (* EXPECT-ERROR line:col message *)"; continue
    fi
    in=${BASH_REMATCH[1]} L=${BASH_REMATCH[2]} C=${BASH_REMATCH[3]} msg=${BASH_REMATCH[4]}
    name="$f: $in$L:$C $msg"
    before=()
    if [[ $(sed -n 2p "$f") =~ ^\(\*\ FILES\ (.*[^ ])\ *\*\)$ ]]; then
        for g in ${BASH_REMATCH[1]}; do before+=("$(dirname "$f")/$g"); done
    fi
    compile "${before[@]}" "$f"
    at=$f
    [ -z "$in" ] || at=$(dirname "$f")/${in%:}
    if [ $rc -ne 1 ]; then
        fail "$name: exit status $rc, expected 1" "$(printf '%s\n' "$log" | head -5)"; continue
    fi
    first=$(printf '%s\n' "$log" | grep -n -m1 ': error: ')
    if [ -z "$first" ]; then
        fail "$name: no error line" "$(printf '%s\n' "$log" | head -5)"; continue
    fi
    n=${first%%:*} diag=${first#*:}
    if [[ $diag != "$at:$L:$C: error: "* ]]; then
        fail "$name: first error is elsewhere" "$diag"; continue
    fi
    if [[ $diag != *"$msg"* ]]; then
        fail "$name: wrong message" "$diag"; continue
    fi
    # The source line must follow, then a caret under column C.
    src=$(sed -n "${L}p" "$at" | tr -d '\r')
    caret=$(printf '%s\n' "$log" | awk -v n="$n" -v src="$src" -v col="$C" '
        NR <= n { next }
        found { c = substr($0, p + col - 1, 1); print (c == "^" ? "ok" : "caret"); exit }
        src != "" && (p = index($0, src)) > 0 { found = 1; next }
        src == "" && NR == n + 1 { p = 1; found = 1; next }
        END { if (!found) print "source" }')
    case $caret in
    ok) pass "$name" ;;
    caret) fail "$name: caret not under column $C" "$(printf '%s\n' "$log" | sed -n "$n,$((n + 3))p")" ;;
    *) fail "$name: source line not shown" "$(printf '%s\n' "$log" | sed -n "$n,$((n + 3))p")" ;;
    esac
done

# ---- generated inputs that must not crash or hang stc ----
g=$out/robust
mkdir -p "$g"
rep() { local i; for ((i = 0; i < $2; i++)); do printf '%s' "$1"; done; }
prologue='PROGRAM p
VAR x : DINT; END_VAR
'

# nothing to compile is accepted, as matiec accepts it: status 0, no error
accepted() {
    compile "$2"
    if [ $rc -eq 0 ] && ! printf '%s\n' "$log" | grep -q 'error:'; then pass "robust $1 (accepted, as by matiec)"
    else fail "robust $1: exit status $rc, expected 0 as matiec" "$(printf '%s\n' "$log" | head -3)"; fi
}
: > "$g/empty.st"
accepted "empty file" "$g/empty.st"

printf '   \n\n  (* only a comment *)\n' > "$g/blank.st"
accepted "only blanks and a comment" "$g/blank.st"

printf '(*' > "$g/lone-comment.st"
check_robust must_fail "lone (*" "$g/lone-comment.st"

# deterministic binary garbage, every byte value
LC_ALL=C awk 'BEGIN { srand(7); for (i = 0; i < 8192; i++) printf "%c", int(rand() * 256) }' > "$g/garbage.st"
check_robust must_fail "binary garbage" "$g/garbage.st"

{ printf '%s' "$prologue"; printf 'x := 1;\n'; printf '\0\0\0'; printf 'x := 2;\nEND_PROGRAM\n'; } > "$g/nul.st"
check_robust must_fail "NUL bytes in a body" "$g/nul.st"

{ printf '%sx := ' "$prologue"; rep '(' 100000; printf '1'; rep ')' 100000; printf ';\nEND_PROGRAM\n'; } > "$g/deep-parens.st"
check_robust may_pass "parentheses 100000 deep" "$g/deep-parens.st"

{ printf '%sx := ' "$prologue"; rep '(' 100000; printf '\nEND_PROGRAM\n'; } > "$g/open-parens.st"
check_robust must_fail "100000 unclosed parentheses" "$g/open-parens.st"

{ printf '%sx := ' "$prologue"; rep '-' 100000; printf '1;\nEND_PROGRAM\n'; } > "$g/deep-minus.st"
check_robust may_pass "unary minus 100000 deep" "$g/deep-minus.st"

{ printf '%s' "$prologue"; rep 'IF TRUE THEN ' 20000; printf 'x := 1;'; rep ' END_IF;' 20000; printf '\nEND_PROGRAM\n'; } > "$g/deep-if.st"
check_robust may_pass "IF nested 20000 deep" "$g/deep-if.st"

{ printf '%s' "$prologue"; rep 'IF TRUE THEN ' 20000; printf '\nEND_PROGRAM\n'; } > "$g/open-if.st"
check_robust must_fail "20000 unclosed IF" "$g/open-if.st"

{ printf '%sLD x\n' "$prologue"; rep 'ADD( x\n' 100000; rep ')\n' 100000; printf 'ST x\nEND_PROGRAM\n'; } > "$g/il-deep-parens.st"
check_robust must_fail "IL deferred operations 100000 deep" "$g/il-deep-parens.st"

{ printf '%sLD x\n' "$prologue"; rep 'ADD x\n' 100000; printf 'ST x\nEND_PROGRAM\n'; } > "$g/il-long.st"
check_robust may_pass "IL sequence of 100000 operators" "$g/il-long.st"

{ printf '%s' "$prologue"; printf 'INITIAL_STEP s0:\nEND_STEP\n'; for ((i = 1; i < 2000; i++)); do printf 'STEP s%d:\nEND_STEP\nTRANSITION FROM s%d TO s%d\n := TRUE;\nEND_TRANSITION\n' $i $((i - 1)) $i; done; printf 'END_PROGRAM\n'; } > "$g/sfc-long.st"
check_robust may_pass "SFC chain of 2000 steps" "$g/sfc-long.st"

{ printf '%sx := 1' "$prologue"; rep '0' 100000; printf ';\nEND_PROGRAM\n'; } > "$g/huge-literal.st"
check_robust must_fail "integer literal of 100001 digits" "$g/huge-literal.st"

{ printf '%sx := 16#' "$prologue"; rep 'F' 50000; printf ';\nEND_PROGRAM\n'; } > "$g/huge-hex.st"
check_robust must_fail "hex literal of 50000 digits" "$g/huge-hex.st"

{ printf 'PROGRAM p\nVAR r : LREAL; END_VAR\nr := 1.0E'; rep '9' 1000; printf ';\nEND_PROGRAM\n'; } > "$g/huge-exponent.st"
check_robust must_fail "real literal with a 1000-digit exponent" "$g/huge-exponent.st"

{ printf '%sx := ' "$prologue"; rep 'a' 100000; printf ';\nEND_PROGRAM\n'; } > "$g/long-ident.st"
check_robust must_fail "undeclared identifier of 100000 characters" "$g/long-ident.st"

{ printf "PROGRAM p\nVAR s : STRING; END_VAR\ns := '"; rep 'x' 100000; printf "';\nEND_PROGRAM\n"; } > "$g/long-string.st"
check_robust may_pass "string literal of 100000 characters" "$g/long-string.st"

{ printf '%s' "$prologue"; rep 'x := x + 1; ' 50000; printf '\nEND_PROGRAM\n'; } > "$g/long-line.st"
check_robust may_pass "50000 statements on one line" "$g/long-line.st"

{ printf 'PROGRAM p\nVAR x : DINT; END_VAR\nx := '; rep '1 + ' 100000; printf '1;\nEND_PROGRAM\n'; } > "$g/long-sum.st"
check_robust may_pass "sum of 100001 terms" "$g/long-sum.st"

printf 'PROGRAM p\nVAR x : DINT; END_VAR\nx := 1;\n{{ x = 2;' > "$g/open-pragma.st"
check_robust must_fail "unterminated {{ pragma" "$g/open-pragma.st"

exit $status
