#!/usr/bin/env bash
# Run one test suite and record its results for mk/summary.sh.
#   mk/suite.sh RESULTS_DIR NAME command [args...]
# The command prints "PASS: x" / "FAIL: x" lines; Check's verbose lines
# (file:line:P|F|E:suite:test:...) are translated to the same. A command that
# exits non-zero without reporting a failure counts as one failure.
set -u
dir=$1; name=$2; shift 2
mkdir -p "$dir"
log="$dir/$name.log"
: > "$log"
echo "== $name"
export CK_VERBOSITY=verbose CK_FORK=yes
start=$(date +%s)
"$@" 2>&1 | while IFS= read -r line; do
    printf '%s\n' "$line"
    if [[ $line =~ ^[^:]+:[0-9]+:([PFE]):([^:]+):([^:]+):[0-9]+:\ ?(.*)$ ]]; then
        if [ "${BASH_REMATCH[1]}" = P ]; then echo "PASS: ${BASH_REMATCH[2]}/${BASH_REMATCH[3]}" >> "$log"
        else echo "FAIL: ${BASH_REMATCH[2]}/${BASH_REMATCH[3]}: ${BASH_REMATCH[4]}" >> "$log"; fi
    elif [[ $line =~ ^(PASS|FAIL):\  ]]; then
        printf '%s\n' "$line" >> "$log"
    fi
done
status=${PIPESTATUS[0]}
if [ "$status" -ne 0 ] && ! grep -q '^FAIL: ' "$log"; then
    echo "FAIL: $name (exit status $status)" | tee -a "$log"
fi
echo "SUITE-TIME: $(($(date +%s) - start))" >> "$log"
echo SUITE-END >> "$log"
exit "$status"
