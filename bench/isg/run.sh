#!/usr/bin/env bash
# make bench-isg: ISGDAMP through EPICPOS on the simulated plant, the seed's
# procedure's figures (figures.st, with the TRUN scenario of
# tests/isg/t_epicpos.st), the seed's two-mode case, robustness and the
# position gain (seedcase.st, with the blocks of tests/isg/t_seedcase.st),
# the stability limits by analysis (gain_analysis.py, numpy/scipy)
# and the cost per stage per sample (cost.c).
#   bench/isg/run.sh OUTDIR LIBRARY.st
# Environment: STC, STC_INC, CC, CFLAGS.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
top=$(cd "$here/../.." && pwd)
. "$top/tests/common/st_build.sh"
out=$1 lib=$2
rm -rf "$out/figures" && mkdir -p "$out/figures"
d=$out/figures
{ cat "$lib" "$top/c_blocks/sim_axis.st" "$top/tests/epicpos/tsupport.st"
  sed -n '/^FUNCTION_BLOCK TRUN/,/^END_FUNCTION_BLOCK/p' "$top/tests/isg/t_epicpos.st"
  cat "$here/figures.st"; } > "$d/all.st"
st_compile "$d/all.st" "$d" isg/figures
st_link "$d" "$here/report.c" "$d/report" isg/figures -I "$top/c_blocks" "$top/c_blocks/plant.c"
echo "== ISGDAMP through EPICPOS: the seed's procedure on the 53 Hz plant"
"$d/report" "$here/figures.st" 20000
# the seed's two-mode case, the force step, fg_f0 off the mode, the position
# gain: the blocks of tests/isg/t_seedcase.st
d2=$out/seedcase
rm -rf "$d2" && mkdir -p "$d2"
{ cat "$lib" "$top/c_blocks/sim_axis.st" "$top/tests/epicpos/tsupport.st"
  sed -n '/^FUNCTION_BLOCK TSEED/,/^PROGRAM/p' "$top/tests/isg/t_seedcase.st" | sed '$d'
  cat "$here/seedcase.st"; } > "$d2/all.st"
st_compile "$d2/all.st" "$d2" isg/seedcase
st_link "$d2" "$here/report.c" "$d2/report" isg/seedcase -I "$top/c_blocks" "$top/c_blocks/plant.c"
echo "== ISGDAMP on the seed's two-mode plant (53 Hz DIRECT, 11 Hz INDIRECT), force step, detuning, position gain"
"$d2/report" "$here/seedcase.st" 10
echo "== the highest stable position gain by analysis (closed-loop eigenvalues, scipy; gain_analysis.py)"
python3 "$here/gain_analysis.py"
"$CC" $CFLAGS -I "$STC_INC" -I "$d/c" -I "$top/c_blocks" -o "$d/isg_cost" \
    "$here/cost.c" "$top/c_blocks/plant.c" -lm
echo "== ISGDAMP's cost per sample (DIRECT, order 2; EPICPOS does not call it while isg_enable is FALSE)"
"$d/isg_cost" 300000 | awk '{ print "  " ($2 == 0 ? "disabled" : $2 " stages") ": " $4 " ns per call"; ns[$2] = $4 }
    END { printf "  per stage (3 stages - 1 stage) / 2: %.1f ns per sample\n", (ns[3] - ns[1]) / 2 }'
# the same stage through APOSSAXIS (aposs.st, with the TRUN scenario of
# tests/apossaxis/t_isg.st)
d=$out/aposs
rm -rf "$d" && mkdir -p "$d"
{ cat "$lib" "$top/c_blocks/sim_axis.st" "$top/tests/epicpos/tsupport.st"
  sed -n '/^FUNCTION_BLOCK TRUN/,/^END_FUNCTION_BLOCK/p' "$top/tests/apossaxis/t_isg.st"
  cat "$here/aposs.st"; } > "$d/all.st"
st_compile "$d/all.st" "$d" isg/aposs
st_link "$d" "$here/report.c" "$d/report" isg/aposs -I "$top/c_blocks" "$top/c_blocks/plant.c"
echo "== ISGDAMP through APOSSAXIS: the seed's procedure on the 53 Hz plant"
"$d/report" "$here/aposs.st" 20000
