#!/usr/bin/env bash
# What `make run` and `make test` install and build (mk/deps.sh, Makefile):
# make run's Debian packages are exactly the runtime's (the list the README
# gives), the Python list names each package once, a non-root user is told
# to install without recommended packages, and make run builds the demo's
# plcrt alone, in parallel, without a test binary.
#   tests/deps/check_deps.sh WORKDIR        Prints PASS:/FAIL: lines.
set -u
work=$1
mkdir -p "$work"
st=0
pass() { echo "PASS: deps/$1"; }
fail() { echo "FAIL: deps/$1: $2"; st=1; }

# the README's list of runtime packages: the line after "Debian packages of `make run`"
readme=$(sed -n '/^Debian packages of `make run`/,+2p' README.md | tr -s ' \n' ' ')
want=$(printf '%s\n' gcc make pkg-config libinih-dev libmodbus-dev python3 python3-matplotlib python3-pip | sort | tr '\n' ' ')
got=$(mk/deps.sh --list run | sed -n 's/^debian: //p' | tr ' ' '\n' | sort | tr '\n' ' ')
[ "$got" = "$want" ] && pass "make run installs the runtime's packages only" || fail "make run's packages" "got '$got', want '$want'"
miss=
for p in $want; do case " $readme " in *" $p "*) ;; *) miss="$miss $p" ;; esac; done
[ -z "$miss" ] && pass "the README lists them" || fail "README's list" "missing:$miss in '$readme'"

all=$(mk/deps.sh --list all | sed -n 's/^pip: //p' | tr ' ' '\n' | sed 's/[=<>!~].*//' | sed '/^$/d')
dups=$(printf '%s\n' "$all" | sort | uniq -d | tr '\n' ' ')
[ -z "$dups" ] && pass "the pip list names each package once ($(echo $all))" || fail "pip list" "twice: $dups"

# a non-root user with a package missing: a fake id and dpkg-query
fake=$work/fakebin
mkdir -p "$fake"
printf '#!/bin/sh\necho 1000\n' > "$fake/id"
printf '#!/bin/sh\necho "deinstall ok config-files"\n' > "$fake/dpkg-query"
chmod +x "$fake/id" "$fake/dpkg-query"
out=$(PATH="$fake:$PATH" mk/deps.sh run 2>&1); rc=$?
if [ $rc -ne 0 ] && printf '%s\n' "$out" | grep -q '^  apt-get update && apt-get install -y --no-install-recommends .*libmodbus-dev'; then
    pass "the non-root line installs without recommended packages"
else
    fail "non-root line" "status $rc: $out"
fi

# make run: the demo's plcrt alone, on every core (a dry run in an empty build folder)
# not for make run: sanitized or Check builds, test sources, other examples
notrun='-fsanitize|check_|(^| )tests/|/plc/(demo|multiaxis|preset|plcopen|aposs|cam_)'
dry=$(make -n --no-print-directory run BUILD="$work/build" JOBS=3 2>&1)
if printf '%s\n' "$dry" | grep -q -- "-o $work/build/plc/epicpos/plcrt " &&
   ! printf '%s\n' "$dry" | grep -qE -- "$notrun"; then
    pass "make run builds the demo's plcrt and nothing of the tests"
else
    fail "make run's build" "$(printf '%s\n' "$dry" | grep -E -- "$notrun" | head -5)"
fi
grep -q -- '-j$(JOBS) $(RUN_DEMO_BIN)' Makefile && pass "make run builds in parallel (-j, one job per core)" ||
    fail "make run" "not built with -j"
exit $st
