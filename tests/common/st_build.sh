# Shell functions for the test scripts that compile an ST program with stc
# and link the generated C with a harness (source this file).
# Environment: STC (compiler command), STC_INC (its header folder), CC, CFLAGS.
common_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

# st_compile ST DIR LABEL [MORE.st...]: stc's output of ST (after the files
# MORE, when given: one program, in that order) into DIR/c. On failure prints
# "FAIL: LABEL: ..." with the compiler's messages and returns 1.
st_compile() {
    local st=$1 d=$2 label=$3
    shift 3
    mkdir -p "$d/c"
    if ! $STC -T "$d/c" "$@" "$st" > "$d/stc.log" 2>&1; then
        echo "FAIL: $label: the compiler rejected it:"
        sed 's/^/    /' "$d/stc.log" | head -20
        return 1
    fi
}

# st_link DIR HARNESS EXE LABEL [CC flags...]: the generated C in DIR/c
# (POUS.c is included by the others) linked with HARNESS into EXE. On
# failure prints "FAIL: LABEL: ..." with the C compiler's messages, returns 1.
st_link() {
    local d=$1 harness=$2 exe=$3 label=$4 srcs=() f
    shift 4
    for f in "$d"/c/*.c; do
        [ "$(basename "$f")" = POUS.c ] || srcs+=("$f")
    done
    # shellcheck disable=SC2086
    if ! $CC $CFLAGS "$@" -I "$STC_INC" -I "$d/c" -I "$common_dir" "${srcs[@]}" "$harness" \
            -o "$exe" -lm > "$exe.cc.log" 2>&1; then
        echo "FAIL: $label: the generated C does not build:"
        sed 's/^/    /' "$exe.cc.log" | head -30
        return 1
    fi
}

# st_check_run SUITE ST DIR [CC flags...]: build DIR/all.st (the program ST
# with what it needs, already put together by the caller) into DIR/prog with
# the EPICPOS check harness (tests/epicpos/harness.c), run it for the
# program's "(* MAXTICKS n *)" ticks and print its PASS/FAIL lines labelled
# SUITE/name.  A compiler warning is a failure.  Returns 1 on any failure.
st_check_run() {
    local suite=$1 st=$2 d=$3 name rc ticks
    shift 3
    name=$(basename "$st" .st)
    st_compile "$d/all.st" "$d" "$suite/$name" || return 1
    if [ -s "$d/stc.log" ]; then
        echo "FAIL: $suite/$name: the compiler warns:"
        sed 's/^/    /' "$d/stc.log" | head -20
        return 1
    fi
    st_link "$d" "$common_dir/../epicpos/harness.c" "$d/prog" "$suite/$name" "$@" || return 1
    ticks=$(sed -n 's/.*(\* MAXTICKS \([0-9]*\) \*).*/\1/p' "$st" | head -1)
    # the harness labels its lines for the EPICPOS suite: relabel them
    timeout 300 "$d/prog" "$st" "${ticks:-100000}" > "$d/out.txt"
    rc=$?
    sed "s#^\(PASS\|FAIL\): epicpos/#\1: $suite/#" "$d/out.txt"
    return $rc
}
