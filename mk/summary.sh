#!/usr/bin/env bash
# Sum up the suites' result files: every "PASS: x" / "FAIL: x" line counts.
# A suite that wrote no result file at all (it crashed before reporting) fails.
set -u
dir=$1
pass=0; fail=0
for f in "$dir"/*.log; do
    [ -e "$f" ] || continue
    p=$(grep -c '^PASS: ' "$f"); x=$(grep -c '^FAIL: ' "$f")
    pass=$((pass + p)); fail=$((fail + x))
    [ "$x" -gt 0 ] && grep '^FAIL: ' "$f" | sed "s|^|  $(basename "$f" .log): |"
    if ! grep -q '^SUITE-END' "$f"; then
        echo "  $(basename "$f" .log): suite did not finish"; fail=$((fail + 1))
    fi
done
echo
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ] && [ "$pass" -gt 0 ]
