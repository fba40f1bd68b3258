#!/usr/bin/env bash
# Compile each ST test program with stc, build the generated C with the
# harness (once with CFLAGS, once more with the sanitizers) and run its script.
#   tests/stc/run.sh OUTDIR prog.st...
# Environment: STC (compiler command), STC_INC (its header folder), CC,
# CFLAGS, SAN (sanitizer flags; empty skips that build), JOBS.
# Prints PASS:/FAIL: lines; exit status 1 when anything failed.
set -u
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../common/st_build.sh"

one() {  # one program; output goes to stdout
    local st=$1 out=$2
    local name; name=$(basename "$st" .st)
    local d="$out/$name"
    rm -rf "$d"
    # A script line "FILES a.st b.st" (paths from the test's folder): the
    # program is those files, then this one.
    local more=() f
    for f in $(sed -n '1,/\*)/s/^ *FILES //p' "$st" | sed 's/--.*//'); do
        more+=("$(dirname "$st")/$f")
    done
    st_compile "$st" "$d" "$st" "${more[@]}" || return
    st_link "$d" "$here/harness.c" "$d/prog" "$st" || return
    timeout 20 "$d/prog" "$st" > "$d/run.log" 2>&1
    local rc=$?
    cat "$d/run.log"
    if [ $rc -gt 1 ]; then
        echo "FAIL: $st: harness exit status $rc"
    fi
    [ -n "${SAN:-}" ] || return
    # shellcheck disable=SC2086
    st_link "$d" "$here/harness.c" "$d/prog-san" "$st: sanitizer build" $SAN || return
    ASAN_OPTIONS=exitcode=86:detect_leaks=0 UBSAN_OPTIONS=exitcode=86:print_stacktrace=1 \
        timeout 60 "$d/prog-san" -q "$st" > "$d/run-san.log" 2>&1
    local src=$?
    if [ $src -eq $rc ] && ! grep -q 'runtime error:\|Sanitizer' "$d/run-san.log"; then
        echo "PASS: $st: sanitizers (address, undefined)"
    else
        echo "FAIL: $st: sanitizers (address, undefined): exit status $src (plain build: $rc)"
        sed 's/^/    /' "$d/run-san.log" | head -30
    fi
}

if [ "${1:-}" = --one ]; then
    one "$2" "$3"
    exit 0
fi

out=$1; shift
mkdir -p "$out"
printf '%s\0' "$@" | xargs -0 -P "${JOBS:-$(nproc)}" -I{} \
    sh -c '"$0" --one "$1" "$2" > "$2/$(basename "$1" .st).result" 2>&1' "$0" {} "$out"
status=0
for st in "$@"; do
    r="$out/$(basename "$st" .st).result"
    if [ -f "$r" ]; then cat "$r"; else echo "FAIL: $st: not run"; fi
    grep -q '^FAIL: ' "$r" 2>/dev/null && status=1
done
exit $status
