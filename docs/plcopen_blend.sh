#!/bin/sh
# The plot of docs/plcopen.md ("Buffer modes and blending"): the three
# moves of tests/plcopen/t_blend.st on three EPICPOS axes of the PLCopen
# test rig (tests/plcopen/psupport.st) with mcBuffered, mcBlendingLow and
# mcBlendingHigh (docs/plcopen_blend.st), every sample dumped by
# tests/isg/dump.c and plotted with matplotlib (docs/plcopen_blend.py);
# the plot lands in docs/img/plcopen-blend.png.
# Run from the top of the repository: sh docs/plcopen_blend.sh
set -eu
make -s build/stc/stc build/st/epicpos.st
d=build/plcopen_blend
rm -rf "$d" && mkdir -p "$d"
cat build/st/epicpos.st c_blocks/sim_axis.st tests/epicpos/tsupport.st tests/plcopen/psupport.st \
    docs/plcopen_blend.st > "$d/all.st"
build/stc/stc -T "$d/c" "$d/all.st"
srcs=$(ls "$d"/c/*.c | grep -v '/POUS\.c$')
gcc -std=c11 -O2 -D_DEFAULT_SOURCE -D_GNU_SOURCE -I stc/include -I "$d/c" -I tests/common -I c_blocks \
    $srcs tests/isg/dump.c c_blocks/plant.c -o "$d/dump" -lm
"$d/dump" 20000 > "$d/rows.txt"
python3 docs/plcopen_blend.py "$d/rows.txt" docs/img/plcopen-blend.png
