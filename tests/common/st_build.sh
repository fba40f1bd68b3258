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
