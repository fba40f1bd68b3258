#!/bin/sh
# The commands of docs/cam.md "Walk-through: the stamping example with
# plctrace": run examples/cam_stamping, record two master cycles of the
# master position, the set-point and the roller's counter; the plot lands
# in docs/img/cam_stamping.png.
# Run from the top of the repository: sh docs/cam_stamping.sh
# (PORT=n to use another Modbus port than the example's 1502, IMG=dir for
# another folder of plots: the tests run it so)
set -eu
PORT=${PORT:-1502}
IMG=${IMG:-docs/img}
make -s build/plc/cam_stamping/plcrt
mkdir -p "$IMG"

# 1. the example's configuration without its retain file (every run starts
#    as the seed's program does: a box at the processing point, DEFMCPOS 1000)
sed "s|^file = .*|file =|; s|^port = .*|port = $PORT|" \
    examples/cam_stamping/cam_stamping.ini > build/cam_stamping-doc.ini
build/plc/cam_stamping/plcrt -c build/cam_stamping-doc.ini > build/cam_stamping-doc.log 2>&1 &
PLC=$!
trap 'kill $PLC' EXIT
# serving Modbus (plcrt's cycle counter answers); the cam engages at once
# (SYNCCSTART 0): STATE 3 within the first cycle
end=$(($(date +%s) + 60))
until mbpoll -m tcp -p "$PORT" -0 -1 -t 3 -r 1024 127.0.0.1 > /dev/null 2>&1; do
    [ "$(date +%s)" -lt "$end" ] || { echo "cam_stamping.sh: plcrt does not answer on port $PORT" >&2; exit 1; }
    sleep 0.1
done

# 2. two master cycles of 4000 MU (1 s each at 60 boxes a minute), every
#    cycle of 1 ms, from 100 ms before the master position wraps to 0
plc_runtime/plctrace --port "$PORT" record \
    --chan stamping.sync.mcpos --chan stamping.sync.sp \
    --chan stamping.sync.spqc --chan stamping.scnt --chan stamping.slave.folerr \
    --rows 1,2,3,3,4 --trigger stamping.sync.mcpos:down:2000 --pre 100 --samples 2100 \
    -o build/cam_stamping.csv --png "$IMG/cam_stamping.png" \
    --title "CAM stamping: master MCPOS (MU), set-point SP (UU), SPQC and roller counter (qc), following error (qc)"

# 3. the late wakes of the scan while recording (they show in the following error)
tail -n 1 build/cam_stamping-doc.log; echo
