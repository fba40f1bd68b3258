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
# make -k went on past a suite that failed to build: it wrote no log, so
# count it here unless a suite already reported the failure
if [ -e "$dir/.make-failed" ] && [ "$fail" -eq 0 ]; then
    echo "  a test suite failed to build or run (see the make errors above)"; fail=$((fail + 1))
fi
# the slowest suites (wall seconds), to keep `make test` short
slow=$(grep -H '^SUITE-TIME: ' "$dir"/*.log 2>/dev/null | sed 's|.*/\(.*\)\.log:SUITE-TIME: \(.*\)|\2 \1|' \
       | sort -rn | head -n 6 | awk '{printf "%s%s %ss", (NR > 1 ? ", " : ""), $2, $1}')
[ -n "$slow" ] && echo "slowest suites: $slow"
echo
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ] && [ "$pass" -gt 0 ]
