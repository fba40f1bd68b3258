#!/bin/sh
# The before/after plots of docs/isg.md ("Both stages"): runs the seed's
# two-mode axis of tests/isg/t_seedcase.st without damping and with both
# stages, and a setpoint step at a gain the damping makes stable
# (docs/isg_plots.st), dumps every sample (tests/isg/dump.c) and
# plots them with matplotlib (docs/isg_plots.py); the plots land in
# docs/img/isg-*.png.
# Run from the top of the repository: sh docs/isg_plots.sh
set -eu
make -s build/stc/stc build/st/epicpos.st
d=build/isg_plots
rm -rf "$d" && mkdir -p "$d"
{ cat build/st/epicpos.st c_blocks/sim_axis.st
  sed -n '/^FUNCTION_BLOCK TSEED/,/^FUNCTION_BLOCK TGAIN/p' tests/isg/t_seedcase.st | sed '$d'
  cat docs/isg_plots.st; } > "$d/all.st"
build/stc/stc -T "$d/c" "$d/all.st"
srcs=$(ls "$d"/c/*.c | grep -v '/POUS\.c$')
gcc -std=c11 -O2 -D_DEFAULT_SOURCE -D_GNU_SOURCE -I stc/include -I "$d/c" -I tests/common -I c_blocks \
    $srcs tests/isg/dump.c c_blocks/plant.c -o "$d/dump" -lm
"$d/dump" 10000 > "$d/rows.txt"
python3 docs/isg_plots.py "$d/rows.txt" docs/img
