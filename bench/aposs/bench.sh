#!/usr/bin/env bash
# APOSS axis benchmark: the cost of one 1 ms scan with 256 APOSSAXIS
# instances in limited-jerk motion (RAMPTYPE 2), each on its own simulated
# plant, beside the same program with one axis; whether 256 axes fit a 1 ms
# scan on one core, and the cost per axis.  The program's axes re-plan
# (POSA) at different scans, as their moves differ in length.  The program is built as plcrt
# builds a program (the compiler's output, CFLAGS) and timed scan by scan:
# median and p99 over SCANS scans, each the median of ROUNDS rounds.
#   bench/aposs/bench.sh OUTDIR LIBRARY.st [SCANS [ROUNDS [PLCRT]]]
# PLCRT: examples/aposs's plcrt, to run the tuning tool whose gains are
# compared with hand tunings (without it, the gains docs/aposs.md gives).
# Environment: STC, STC_INC, CC, CFLAGS.
set -u
here=$(cd "$(dirname "$0")" && pwd)
top=$(cd "$here/../.." && pwd)
. "$top/tests/common/st_build.sh"
out=$1 lib=$2 scans=${3:-3000} rounds=${4:-5} plcrt=${5:-}
. "$top/bench/common/scan_rounds.sh"
for n in 1 256; do
    d="$out/axes$n"
    rm -rf "$d" && mkdir -p "$d"
    sed "s/@N@/$n/g" "$here/axes.st.in" > "$d/axes.st"
    cat "$lib" "$top/c_blocks/sim_axis.st" "$d/axes.st" > "$d/all.st"
    scan_rounds "bench-aposs/axes$n" "$d" "$d/all.st" "$here/driver.c" "$scans" "$rounds" \
        -I "$top/c_blocks" "$top/c_blocks/plant.c" || exit 1
    eval "med$n=$med p99$n=$p99 max$n=$max"
    printf 'bench-aposs: %3d axes: %8.0f ns per scan median, %8.0f ns p99, %8.0f ns max (%s scans; median of %s rounds, max of the quietest); %s POSA per round, %s axes in error\n' \
        "$n" "$med" "$p99" "$max" "$scans" "$rounds" "$moves" "$bad"
    [ "$bad" = 0 ] || { echo "bench-aposs: FAIL: axes in error: the figures do not show moving axes"; exit 1; }
done
# shellcheck disable=SC2154
awk -v m1="$med1" -v m="$med256" -v p="$p99256" -v x="$max256" 'BEGIN {
    printf "bench-aposs: per axis: %.0f ns with 256 axes (%.0f ns for a program of one axis)\n", m / 256, m1
    printf "bench-aposs: 256 APOSS axes in a 1 ms scan on one core: median %.1f %%, p99 %.1f %%, max %.1f %% of the scan: %s\n",
        m / 1e4, p / 1e4, x / 1e4, (p <= 1e6 ? "FIT" : "DO NOT FIT")
    printf "bench-aposs: axes that fit 1 ms at the p99 cost per axis: %d\n", int(1e6 / (p / 256))
}'

# The tuning tool run on examples/aposs under plcrt (as make test does),
# then its final gains beside hand tunings of the same plant
# (bench/aposs/gains.st.in): the peak following error of the tool's standard
# move, POSA 50000 qc at VEL 100, ACC 100, the mean over 32 starting positions.
d="$out/gains"
rm -rf "$d" && mkdir -p "$d"
if [ -n "$plcrt" ]; then
    ST_LIB="$lib" python3 "$top/tests/apossaxis/test_tune.py" "$plcrt" "$top/examples/aposs/aposs.ini" "$d/tune" > "$d/tune.log" 2>&1
    trc=$?
    gl=$(sed -n 's/^gains: //p' "$d/tune/tune.out" 2>/dev/null)
    [ -n "$gl" ] || { echo "bench-aposs: FAIL: the tuning run gave no gains:"; tail -5 "$d/tune.log"; exit 1; }
    echo "bench-aposs: tuning tool on examples/aposs: $gl"
    sed -n 's/^\(step [0-9]*: .*\|[0-9]* test runs, .*\)$/bench-aposs:   \1/p' "$d/tune/tune.out"
    # the test's own measures: the onset, and the standard move beside the hand tune's
    sed -n 's/^\(standard move.*\|oscillation onset .*\|the loop.s linear .*\|second tuning.*\)$/bench-aposs: \1/p' "$d/tune.log"
    grep -c '^PASS' "$d/tune.log" | sed 's/^/bench-aposs: tuning test checks passed: /'
    grep '^FAIL' "$d/tune.log" | sed 's/^/bench-aposs: /'
    [ "$trc" = 0 ] || echo "bench-aposs: FAIL: the tuning test ended with status $trc: $(tail -1 "$d/tune.log")"
else
    echo "bench-aposs: no plcrt given: the tuning tool's gains of docs/aposs.md are used"
    gl="FFVEL 875 FFACC 24 KPROP 475 KDER 675 KINT 0 BANDWIDTH 38"
fi
gain() { echo "$gl" | awk -v k="$1" '{ for (i = 1; i < NF; i += 2) if ($i == k) print $(i + 1) }'; }
sed -e "s/@FFVEL@/$(gain FFVEL)/; s/@FFACC@/$(gain FFACC)/; s/@KPROP@/$(gain KPROP)/" \
    -e "s/@KDER@/$(gain KDER)/; s/@KINT@/$(gain KINT)/; s/@BANDWIDTH@/$(gain BANDWIDTH)/" \
    "$here/gains.st.in" > "$d/gains.st"
cat "$lib" "$top/c_blocks/sim_axis.st" "$d/gains.st" > "$d/all.st"
st_compile "$d/all.st" "$d" "bench-aposs/gains" || exit 1
st_link "$d" "$here/gains.c" "$d/prog" "bench-aposs/gains" -I "$top/c_blocks" "$top/c_blocks/plant.c" || exit 1
"$d/prog" 1200 > "$d/out.txt" || exit 1
read -r _ tm _ tw _ mm _ gm _ gkp _ gkd _ gff _ ltm _ lmm _ lgm _ lkp _ lkd _ lff _ bad < "$d/out.txt"
[ "$bad" = 0 ] || { echo "bench-aposs: FAIL: $bad axes in error in the gains comparison"; exit 1; }
awk -v tm="$tm" -v tw="$tw" -v mm="$mm" -v gm="$gm" -v gkp="$gkp" -v gkd="$gkd" -v gff="$gff" \
    -v ltm="$ltm" -v lmm="$lmm" -v lgm="$lgm" -v lkp="$lkp" -v lkd="$lkd" -v lff="$lff" 'BEGIN {
    printf "bench-aposs: peak following error of the standard move (POSA 50000 qc), mean of 32 starts, encoder (load):\n"
    printf "bench-aposs:   tool gains                                     %.3f (%.3f) qc, worst start %.2f qc\n", tm / 1000, ltm / 1000, tw / 1000
    printf "bench-aposs:   hand tune (FFACC 24, KPROP 361, KDER 361)      %.3f (%.3f) qc\n", mm / 1000, lmm / 1000
    printf "bench-aposs:   best of 70 trials on the encoder figure (FFACC %d, KPROP %d, KDER %d) %.3f qc; on the load figure (FFACC %d, KPROP %d, KDER %d) %.3f qc\n", gff, gkp, gkd, gm / 1000, lff, lkp, lkd, lgm / 1000
    printf "bench-aposs: the tool'"'"'s peak following error no larger than the hand tune'"'"'s: encoder %s (ratio %.3f, %+.3f qc), load %s (ratio %.3f, %+.3f qc)\n", (tm <= mm ? "yes" : "NO"), tm / mm, (tm - mm) / 1000, (ltm <= lmm ? "yes" : "NO"), ltm / lmm, (ltm - lmm) / 1000
    printf "bench-aposs: ... than the best of 70 trials: encoder %s (ratio %.3f, %+.3f qc), load %s (ratio %.3f, %+.3f qc); one count is 1 qc\n", (tm <= gm ? "yes" : "NO"), tm / gm, (tm - gm) / 1000, (ltm <= lgm ? "yes" : "NO"), ltm / lgm, (ltm - lgm) / 1000
}'
