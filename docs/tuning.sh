#!/bin/sh
# The commands of docs/tuning.md, in order: tune the EPICPOS example's axis
# on the simulated plant with plctrace; the plots land in docs/img/.
# Run from the top of the repository: sh docs/tuning.sh
# (PORT=n for another Modbus port than the example's 1502, IMG=dir for
# another folder of plots: the tests run it so)
set -eu
PORT=${PORT:-1502}
IMG=${IMG:-docs/img}
make -s build/plc/epicpos/plcrt
mkdir -p "$IMG"

T="plc_runtime/plctrace --port $PORT"
M="mbpoll -m tcp -p $PORT -0 -1 127.0.0.1"

# until TIMEOUT WHAT CMD...: run CMD until it succeeds, at most TIMEOUT s
until_ok() {
    end=$(($(date +%s) + $1)); what=$2; shift 2
    until "$@"; do
        [ "$(date +%s)" -lt "$end" ] || { echo "tuning.sh: $what: not within $1 s" >&2; exit 1; }
        sleep 0.1
    done
}

# 1. the example's configuration, with forcing allowed and no retain file
#    (every run starts from the example's parameters)
sed "s|^file = .*|file =|; s|^port = .*|port = $PORT|" examples/epicpos/epicpos.ini > build/tune.ini
printf '[debug]\nallow_force = yes\n' >> build/tune.ini
build/plc/epicpos/plcrt -c build/tune.ini > build/tune.log 2>&1 &
PLC=$!
trap 'kill $PLC' EXIT
# coil N on?
coil() { $M -t 0 -r "$1" 2>/dev/null | grep -q "^\[$1\]:[[:space:]]*1$"; }
# the start-up sequence of 1.6 closes the loop: st_loopon (coil 47) on
until_ok 60 "the example's loop closed (st_loopon)" coil 47

# 2. one move: record from 100 ms before START, 3 s every 2nd cycle, while
#    the quota is set and the START input held on until the trace has
#    triggered (the example takes START only while the axis is still,
#    st_still: a short pulse can fall between two stills)
trace_fired() {            # plcrt's trace state (holding 60002): 2 triggered, 0 done
    $M -t 4 -r 60002 2>/dev/null | grep -q '^\[60002\]:[[:space:]]*[02]$'
}
move() {   # QUOTA NAME TITLE
    name=$2
    $T record --chan axis.setpt --chan res0.axis.posit --chan res0.axis.folterr --chan res0.axis.dacval \
        --rows 1,1,2,3 --trigger axis.START:rise --pre 50 --samples 1500 --every 2 \
        -o build/$2.csv --png "$IMG/$2.png" --title "$3" 2> build/$2.err &
    REC=$!
    until_ok 60 "plctrace armed for $name" armed
    $M -t 4:int -B -r 2048 "$1" > /dev/null   # slQuotaPos (Um)
    $M -t 0 -r 2 1 > /dev/null                # START input on ...
    until_ok 60 "START taken for $name" trace_fired
    $M -t 0 -r 2 0 > /dev/null                # ... and off once it was
    wait $REC || { cat build/$name.err >&2; exit 1; }
}
# armed: plctrace has said so; a plctrace that ended instead fails the script
armed() {
    grep -q '^armed' build/$name.err && return 0
    kill -0 $REC 2>/dev/null || { cat build/$name.err >&2; exit 1; }
    return 1
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
