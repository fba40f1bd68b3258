#!/bin/sh
# The commands of docs/tuning.md, in order: tune the EPICPOS example's axis
# on the simulated plant with plctrace; the plots land in docs/img/.
# Run from the top of the repository: sh docs/tuning.sh
set -eu
make -s build/plc/epicpos/plcrt

# 1. the example's configuration, with forcing allowed and no retain file
#    (every run starts from the example's parameters)
sed 's|^file = .*|file =|' examples/epicpos/epicpos.ini > build/tune.ini
printf '[debug]\nallow_force = yes\n' >> build/tune.ini
build/plc/epicpos/plcrt -c build/tune.ini > build/tune.log 2>&1 &
PLC=$!
trap 'kill $PLC' EXIT
sleep 2                                # the start-up sequence of 1.6 closes the loop

T=plc_runtime/plctrace
M="mbpoll -m tcp -p 1502 -0 -1 127.0.0.1"

# 2. one move: record from 100 ms before START, 3 s every 2nd cycle, while
#    the quota is set and the START input pulsed
move() {   # QUOTA NAME TITLE
    $T record --chan axis.setpt --chan res0.axis.posit --chan res0.axis.folterr --chan res0.axis.dacval \
        --rows 1,1,2,3 --trigger axis.START:rise --pre 50 --samples 1500 --every 2 \
        -o build/$2.csv --png docs/img/$2.png --title "$3" &
    REC=$!
    sleep 1
    $M -t 4:int -B -r 2048 "$1" > /dev/null   # slQuotaPos (Um)
    $M -t 0 -r 2 1 > /dev/null                # START input on
    sleep 0.1
    $M -t 0 -r 2 0 > /dev/null                # and off
    wait $REC
}

move 1000 tune-1-default "pgain 10, feedfw 1000 (the example's tuning)"

# 3. the P loop alone: feed-forward forced off
$T force res0.axis.feedfw 0
move 0 tune-2-no-feedforward "pgain 10, feedfw 0: the following error is the loop's lag"

# 4. a stiffer loop without feed-forward
$T force res0.axis.pgain 40
move 1000 tune-3-pgain40 "pgain 40, feedfw 0"

# 5. back to full feed-forward with the stiffer gain
$T force res0.axis.feedfw 1000
move 0 tune-4-pgain40-feedfw "pgain 40, feedfw 1000"

$T forced
$T unforce --all
