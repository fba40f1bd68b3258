#!/usr/bin/env bash
# C-bodied blocks from C++ (OpenPLC v3 builds the PLC program with g++):
#   cxx_link.sh OUTDIR
# 1. cxx_plant.cpp (g++) calls plant.h's functions, linked with plant.c
#    compiled as C;
# 2. the SIM_AXIS block (c_blocks/sim_axis.st) in a program compiled by $STC,
#    its Res0.c/Config0.c built with g++ -std=gnu++11 as OpenPLC v3's
#    compile_program.sh does, linked with plant.c compiled as C; it must run
#    and give the same counter as the same program built as C, and the
#    counter a first-order lag predicts.
# Environment: STC, STC_INC, CC, CFLAGS, CXX.
set -u
out=$1
here=$(dirname "$0")
CXX=${CXX:-g++}
mkdir -p "$out"
rc=0

# plant.c as C, always
if ! $CC $CFLAGS -c c_blocks/plant.c -o "$out/plant.o"; then
    echo "FAIL: cxx-plant-c-object (plant.c does not compile as C)"; exit 1
fi

# 1. a C++ translation unit over plant.h
if $CXX -std=gnu++11 -Wall -Wextra -Werror -Ic_blocks -c "$here/cxx_plant.cpp" -o "$out/cxx_plant.o" &&
   $CXX "$out/cxx_plant.o" "$out/plant.o" -lm -o "$out/cxx_plant"; then
    echo "PASS: cxx-plant-links (a C++ caller of plant.h links against plant.c built as C)"
    "$out/cxx_plant" || rc=1
else
    echo "FAIL: cxx-plant-links (a C++ caller of plant.h does not link against plant.c built as C)"
    rc=1
fi

# 2. the ST block with its C body, compiler output built as C++ and as C
gen="$out/gen"
rm -rf "$gen" && mkdir -p "$gen"
cat c_blocks/sim_axis.st "$here/openplc_prog.st" > "$gen/prog.st"
if ! $STC -T "$gen" "$gen/prog.st"; then
    echo "FAIL: cxx-sim-axis-compiles (the ST compiler refused the program)"; exit 1
fi
cxxok=1
for f in Res0 Config0; do
    $CXX -std=gnu++11 -I "$STC_INC" -I "$gen" -c "$gen/$f.c" -o "$gen/$f.cxx.o" || cxxok=0
done
$CXX -std=gnu++11 -x c++ -I "$STC_INC" -c "$here/openplc_main.c" -o "$gen/main.cxx.o" || cxxok=0
if [ $cxxok = 1 ] && $CXX "$gen/Res0.cxx.o" "$gen/Config0.cxx.o" "$gen/main.cxx.o" "$out/plant.o" \
        -lm -o "$gen/prog_cxx"; then
    echo "PASS: cxx-sim-axis-links (SIM_AXIS's C body built as C++ links against plant.c built as C)"
else
    echo "FAIL: cxx-sim-axis-links (SIM_AXIS's C body built as C++ does not link against plant.c built as C)"
    exit 1
fi
for f in Res0 Config0; do
    $CC $CFLAGS -I "$STC_INC" -I "$gen" -c "$gen/$f.c" -o "$gen/$f.o" || exit 1
done
$CC $CFLAGS -I "$STC_INC" -c "$here/openplc_main.c" -o "$gen/main.o" || exit 1
$CC "$gen/Res0.o" "$gen/Config0.o" "$gen/main.o" "$out/plant.o" -lm -o "$gen/prog_c" || exit 1

cxx=$("$gen/prog_cxx"); c=$("$gen/prog_c")
# 1000 cycles of 1 ms at DAC 3277: speed 100000 * 3277 / 32767 counts/s
# through a 5 ms lag: x = v * (t - 0.005 * (1 - exp(-t / 0.005)))
expect=$(awk 'BEGIN { v = 100000 * 3277 / 32767; printf "%.0f", v * (1 - 0.005 * (1 - exp(-200))) }')
if [ "$cxx" = "$c" ]; then
    echo "PASS: cxx-sim-axis-same-as-c (counter $cxx built as C++ and as C)"
else
    echo "FAIL: cxx-sim-axis-same-as-c (counter $cxx built as C++, $c built as C)"; rc=1
fi
if awk -v g="$cxx" -v e="$expect" 'BEGIN { d = g - e; if (d < 0) d = -d; exit !(d <= 0.01 * e) }'; then
    echo "PASS: cxx-sim-axis-moves (counter $cxx after 1 s at 1 V, expected $expect +-1%)"
else
    echo "FAIL: cxx-sim-axis-moves (counter $cxx after 1 s at 1 V, expected $expect +-1%)"; rc=1
fi
exit $rc
