"""A CAN-driven simulated axis positioned by EPICPOS, on vcan0 inside a
kernel with CAN (tests/canopen/bus_run.sh): plcrt runs st/canopen_axis.st; node 4 (slave401.Axis) integrates
its analog output into an encoder count sent back in a TPDO. The move to
setpos must end within toll (checked on the node's own count and on posit);
then the node's heartbeat stops: the axis goes to emergency, as seed 000's
guarding error does, and from one cycle after the loss every speed
reference on the bus is 0 (checked on the recorded frames, whose kernel
timestamps do not depend on how fast this script runs).

    $PY tests/canopen/plcrt_axis_test.py PLCRT OUT_DIR
"""
import os
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from slave401 import Axis, CanDump, connect  # noqa: E402
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from peer import Report, wait_for  # noqa: E402
from pymodbus.client import ModbusTcpClient  # noqa: E402

plcrt, out = sys.argv[1], sys.argv[2]
PORT = 15032
SETPOS, TOLL, HB_CONS, CYCLE = 20000, 20, 0.250, 0.010
report = Report("canopen_axis")


cfg = os.path.join(out, "axis.ini")
with open(cfg, "w") as f:
    f.write(f"""[plc]
log_level = info
[io]
backend = canopen
[modbus]
port = {PORT}
[canopen]
interface = vcan0
[canopen.axis]
id = 4
device_type = 0x191
heartbeat_producer_ms = 100
heartbeat_consumer_ms = 250
rpdo1 = 0x6411:01:16
tpdo1 = 0x2000:00:32 0x6000:01:8
bind = 0x2000:00 %ID0
bind = 0x6000:01 %IB0
bind = 0x6411:01 %QW0
status = %IW30
""")

trace = CanDump(os.path.join(out, "candump.log"))
net = connect("vcan0")
axis = Axis(net, 4, maxvel=40000.0)
log = open(os.path.join(out, "plcrt.log"), "w")
plc = subprocess.Popen([plcrt, "-c", cfg], stdout=log, stderr=subprocess.STDOUT)
mb = ModbusTcpClient("127.0.0.1", port=PORT)
ok = wait_for(lambda: mb.connect(), 30) and wait_for(lambda: axis.state == 5, 20)
report("startup", ok, f"node state {axis.state}")


def hreg(addr, n=1):
    rr = mb.read_holding_registers(addr, n, slave=1)
    return None if rr.isError() else rr.registers


def cycles():
    rr = mb.read_input_registers(1024, 2, slave=1)
    return 0 if rr.isError() else rr.registers[0] << 16 | rr.registers[1]


def posit():
    r = hreg(2048, 2)
    if not r:
        return None
    v = r[0] << 16 | r[1]
    return v - (1 << 32) if v & 0x80000000 else v


# the program needs its first cycles to INIT and close the loop before a
# START; how long those take depends on the machine, so count them
report("program_running", wait_for(lambda: cycles() >= 5, 30), f"{cycles()} cycles")
mb.write_register(1024, 1, slave=1)                   # go
t0 = time.monotonic()
ok = wait_for(lambda: (hreg(1025) or [0])[0] & 1 == 1, 30)
# the drive's count and the program's posit are each held against SETPOS
# alone (the axis rests in its tolerance), never against each other: two
# reads at different times compare fairly
count = axis.get(0x2000)
report("positioned_within_toll", ok and abs(count - SETPOS) <= TOLL and abs((posit() or 0) - SETPOS) <= TOLL,
       f"st_toll after {time.monotonic() - t0:.2f} s, encoder {count}, posit {posit()}")
# it holds for 30 PLC cycles (counted, not slept for)
n = cycles()
wait_for(lambda: cycles() >= n + 30, 30)
count = axis.get(0x2000)
report("holds_position", abs(count - SETPOS) <= TOLL and abs(axis.get(0x6411, 1)) < 3000,
       f"encoder {count}, DAC {axis.get(0x6411, 1)}")

t_stop = time.monotonic()
axis.stop_heartbeat()
emrg = wait_for(lambda: (hreg(1025) or [0])[0] & 2 == 2, 30)
report("node_lost_axis_emergency", emrg,
       f"{(time.monotonic() - t_stop) * 1000:.0f} ms, state {hreg(1025)}")
# the emergency holds (no RESUME is sent) while the program keeps running
n = cycles()
wait_for(lambda: cycles() >= n + 20, 30)
report("emergency_holds", (hreg(1025) or [0])[0] & 2 == 2, f"state {hreg(1025)}")

# the scan's worst wake latency as plcrt measured it (input registers
# 1042-1043, us): the bound below is widened by it, not by a guess
rr = mb.read_input_registers(1042, 2, slave=1)
late = 0.0 if rr.isError() else (rr.registers[0] << 16 | rr.registers[1]) / 1e6
plc.send_signal(signal.SIGTERM)
plc.wait(30)

# On the bus: the node's last heartbeat, then the consumer time; plcrt
# notices the silence in its first cycle past it (its input is read once a
# cycle), and that cycle's RPDO carries DAC 0: every RPDO from three cycles
# past the timeout to the end is 0, and there is at least one.
hb = [t for t, d in trace.frames(0x704) if d == b"\x05"]
rpdo = trace.frames(0x204)
t_cut = hb[-1] + HB_CONS + 3 * CYCLE + late if hb else float("inf")
after = [(t, int.from_bytes(d[:2], "little", signed=True)) for t, d in rpdo if t >= t_cut]
moving = [v for t, v in rpdo if hb and t < hb[-1]]
bad = [(round((t - hb[-1]) * 1000), v) for t, v in after if v != 0]
report("dac_zero_within_a_cycle_of_emergency",
       after and not bad and any(v != 0 for v in moving),
       (f"{len(after)} RPDOs from {(t_cut - hb[-1]) * 1000:.0f} ms after the last heartbeat, "
        + (f"non-zero (ms, DAC): {bad[:5]}" if bad else "all 0") + f"; worst wake latency {late * 1000:.1f} ms")
       if hb else "no heartbeat recorded")
