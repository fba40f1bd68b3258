"""Seed 000's DRIVETYPE 91 on a real bus (vcan0 inside a kernel with CAN,
tests/canopen/bus_run.sh): plcrt runs st/canopen_aposs.st, an APOSSAXIS
whose speed reference goes to analog output 1 of CiA 401 node 4
(slave401.Axis, which integrates it into the encoder count it sends back).
The node answers node guarding (RTR on 0x704, toggle bit); then it stops
answering during a move: error 88, the loop open and every reference on the
bus 0 from the first cycle past guard time x life factor (counted in RPDOs
from the last answer on the recorded frames, their kernel timestamps
shown); ERRCLR while it is silent raises 88 again; a negative DRIVETYPE
lets ERRCLR stand (the seed's way out); answering again, the node is
restarted and the axis moves.

    $PY tests/canopen/plcrt_drivetype_test.py PLCRT OUT_DIR
"""
import os
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from apossmb import AxisMb  # noqa: E402
from slave401 import Axis, CanDump, connect, reference_zero_after  # noqa: E402
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from peer import Report, wait_for  # noqa: E402

plcrt, out = sys.argv[1], sys.argv[2]
PORT = 15035
# a life time of 1 s: a loaded host can hold the kernel the node runs in
# for a few hundred ms, which must not count as the node's silence
GUARD, LIFE, CYCLE = 0.200, 5, 0.010
report = Report("canopen_drivetype")

cfg = os.path.join(out, "drivetype.ini")
with open(cfg, "w") as f:
    f.write(f"""[plc]
log_level = info
[io]
backend = canopen
[modbus]
port = {PORT}
[canopen]
interface = vcan0
cansynctimer_ms = 10
[canopen.module4]
id = 4
device_type = 0x191
drivetype = 91
guard_time_ms = {round(GUARD * 1000)}
life_factor = {LIFE}
rpdo1 = 0x6411:01:16 0x6411:02:16 0x6411:03:16 0x6411:04:16
tpdo1 = 0x2000:00:32
bind = 0x6411:01 %QW0
bind = 0x6411:02 %QW1
bind = 0x6411:03 %QW2
bind = 0x6411:04 %QW3
bind = 0x2000:00 %ID0
status = %IW30
""")

trace = CanDump(os.path.join(out, "candump.log"))
net = connect("vcan0")
axis = Axis(net, 4, maxvel=40000.0)
log = open(os.path.join(out, "plcrt.log"), "w")
plc = subprocess.Popen([plcrt, "-c", cfg], stdout=log, stderr=subprocess.STDOUT)
mb = AxisMb(PORT)
ok = wait_for(lambda: mb.connect(), 10) and wait_for(lambda: axis.state == 5, 5)
mw, md, put_md, command, bits, errnum = mb.mw, mb.md, mb.put_md, mb.command, mb.bits, mb.errnum


MOTOR, BUSY, INPOS, ERROR, BUSERR = 1, 2, 4, 8, 16
rtr0 = axis.guard_rtrs
ok = wait_for(lambda: axis.guard_rtrs - rtr0 >= 3, 10) and ok
report("guarded_not_heartbeat", ok and axis.get(0x100C) == round(GUARD * 1000) and axis.get(0x100D) == LIFE
       and axis.get(0x1017) == 0,
       f"0x100C {axis.get(0x100C)} ms, 0x100D {axis.get(0x100D)}, {axis.guard_rtrs - rtr0} RTRs")
command(1)
wait_for(lambda: bits() & MOTOR, 5)
command(4, 20000)
ok = wait_for(lambda: bits() & INPOS and not bits() & BUSY, 15)
count = axis.get(0x2000)
report("moves_by_analog_output_1", ok and abs(count - 20000) <= 50 and errnum() == 0,
       f"encoder {count}, ERRNUM {errnum()}")

# a long move, and the node falls silent in the middle of it
command(4, -200000)
wait_for(lambda: abs(axis.get(0x6411, 1)) > 3000, 5)
axis.guard_answer = False
ok = wait_for(lambda: errnum() == 88, 5)
b = bits()
report("silent_node_error_88_loop_open", ok and not b & MOTOR and b & BUSERR, f"ERRNUM {errnum()}, bits {b}")
n88 = md(3)
command(3)                                          # ERRCLR while still silent
ok = wait_for(lambda: md(3) == n88 + 1, 5)
report("errclr_while_silent_raises_88_again", ok and errnum() == 88, f"errors 88: {n88} -> {md(3)}")
put_md(0, -91)                                      # the seed's way out: no guarding
command(3)
time.sleep(0.3)
report("negative_drivetype_errclr_stands", errnum() == 0 and not bits() & ERROR, f"ERRNUM {errnum()}")
put_md(0, 91)
time.sleep(0.1)
report("positive_again_88_again", wait_for(lambda: errnum() == 88, 5), f"ERRNUM {errnum()}")

axis.guard_answer = True
ok = wait_for(lambda: not bits() & BUSERR, 10)
command(3)
ok = ok and wait_for(lambda: errnum() == 0, 5)
time.sleep(0.2)
report("answers_again_errclr_clears", ok and errnum() == 0, f"ERRNUM {errnum()}, bits {bits()}")
command(1)
wait_for(lambda: bits() & MOTOR, 5)
here = axis.get(0x2000)
command(4, here + 10000)
ok = wait_for(lambda: bits() & INPOS and not bits() & BUSY, 15)
report("moves_again", ok and abs(axis.get(0x2000) - (here + 10000)) <= 50, f"encoder {axis.get(0x2000)}")
plc.send_signal(signal.SIGTERM)
report("plcrt_exits_0", plc.wait(10) == 0)

# ---- on the bus: the last good answer, then the RPDOs ----
answers = [t for t, d in trace.frames(0x704) if d and d[0] & 0x7F == 0x05]
rpdo = trace.frames(0x204)
# the first silence: the last answer before the first gap longer than the life time
t_last = next((a for a, b in zip(answers, answers[1:]) if b - a > GUARD * LIFE), None)
if t_last is None:
    report("reference_zero_past_life_time", False, "no gap in the guarding answers recorded")
else:
    nxt = min([a for a in answers if a > t_last], default=float("inf"))
    report("reference_zero_past_life_time", *reference_zero_after(rpdo, t_last, nxt, GUARD * LIFE, CYCLE))
    others = [d for t, d in rpdo if any(d[2:8])]
    report("outputs_2_to_4_stay_0", rpdo and not others, f"{len(others)} RPDOs with outputs 2..4 not 0")
trace.close(keep=not report.all_passed())
sys.exit(0 if report.all_passed() else 1)
