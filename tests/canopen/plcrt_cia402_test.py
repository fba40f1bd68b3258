"""plcrt driving two simulated CiA 402 drives (drive402.Drive402, nodes 5
and 6) with CIA402DRIVE in cyclic synchronous position mode, on vcan0
inside a kernel with CAN (tests/canopen/bus_run.sh): the example
examples/cia402 with its configuration (on port PORT).  What a user sees:
both drives powered through transitions 2, 3, 4; homing in mode 6; an
absolute move whose length in cycles is the closed-form D/v + v/a; a
velocity move at v; a stop v^2/(2a) further; a drive fault (its load
blocked: following error, EMCY 0x8611) -> the axis in error with the
drive's code, the other axis still moving, and a reset that powers it
again.  Motion is measured on the recorded RPDO frames (one per cycle), not
on this script's clock.

    $PY tests/canopen/plcrt_cia402_test.py PLCRT OUT_DIR
"""
import os
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from drive402 import Drive402  # noqa: E402
from slave401 import CanDump, connect  # noqa: E402
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from peer import Report, wait_for  # noqa: E402
from pymodbus.client import ModbusTcpClient  # noqa: E402

plcrt, out = sys.argv[1], sys.argv[2]
PORT = 15034
HERE = os.path.dirname(os.path.abspath(__file__))
report = Report("canopen_cia402")
SCALE = 100            # counts per mm (examples/cia402/cia402.st)

cfg = os.path.join(out, "cia402.ini")
with open(os.path.join(HERE, "..", "..", "examples", "cia402", "cia402.ini")) as f:
    # the example's configuration; a heartbeat consumer time that rides out
    # the stalls of a loaded host (the guest may not run for a second)
    text = f.read().replace("port = 1502", f"port = {PORT}").replace(
        "heartbeat_consumer_ms = 250", "heartbeat_consumer_ms = 5000")
with open(cfg, "w") as f:
    f.write(text)

trace = CanDump(os.path.join(out, "candump.log"))
net = connect("vcan0")
d5 = Drive402(net, 5, home_at=0)
d6 = Drive402(net, 6, home_at=25000)
log = open(os.path.join(out, "plcrt.log"), "w")
plc = subprocess.Popen([plcrt, "-c", cfg], stdout=log, stderr=subprocess.STDOUT)
mb = ModbusTcpClient("127.0.0.1", port=PORT)
ok = wait_for(lambda: mb.connect(), 30) and wait_for(lambda: d5.state == 5 and d6.state == 5, 30)
report("startup_both_nodes_operational", ok, f"NMT states {d5.state} {d6.state}")
seqs = [0, 0]


def mw(addr, n=1):
    rr = mb.read_holding_registers(1024 + addr, n, slave=1)
    return None if rr.isError() else rr.registers


def md(addr):
    rr = mb.read_holding_registers(2048 + 2 * addr, 2, slave=1)
    if rr.isError():
        return None
    v = rr.registers[0] << 16 | rr.registers[1]
    return v - (1 << 32) if v & 0x80000000 else v


def status(k):
    r = mw(20 * k + 2, 6)
    return dict(zip(("state", "bits", "errid", "errtrans", "errcode", "refused"), r)) if r else {}


def cycles():
    rr = mb.read_input_registers(1024, 2, slave=1)
    return 0 if rr.isError() else rr.registers[0] << 16 | rr.registers[1]


def bit(k, b):
    return (status(k).get("bits", 0) >> b) & 1


def fault_status(k):
    """axis k's status once its error has its code: the drive's 0x603F
    travels in another TPDO than the statusword and may come a SYNC or two
    later (the axis takes it then); 20 cycles at most"""
    c0 = cycles()
    wait_for(lambda: status(k).get("errcode") or cycles() >= c0 + 20, 30)
    return status(k)


def dwords(v):
    v &= 0xFFFFFFFF
    return [v >> 16, v & 0xFFFF]


def command(k, cmd, pos=0, vel=0, acc=0):
    """one write: the arguments, then command and sequence"""
    mb.write_registers(2048 + 20 * k, dwords(pos) + dwords(vel) + dwords(acc), slave=1)
    seqs[k] += 1
    mb.write_registers(1024 + 20 * k, [cmd, seqs[k]], slave=1)


POWERED, BUSY, INPOS, HOMED, ERROR, ATVEL = 0, 1, 2, 3, 4, 5
wait_for(lambda: status(0).get("state") == 3 and status(1).get("state") == 3, 30)
d5.trans, d6.trans = [], []
command(0, 1)
command(1, 1)
ok = wait_for(lambda: bit(0, POWERED) and bit(1, POWERED), 30)
report("dcf_written_at_startup", d5.get(0x6065) == 2000 and d6.get(0x6065) == 2000
       and d5._mapping(0x1600, 0) == [(0x6040, 0, 16), (0x6060, 0, 8), (0x607A, 0, 32)]
       and d6._mapping(0x1A00, 1) == [(0x606C, 0, 32), (0x603F, 0, 16)],
       f"0x6065 {d5.get(0x6065)} {d6.get(0x6065)}, RPDO1 {d5._mapping(0x1600, 0)}")
report("power_on_both", ok and d5.trans == [3, 4] and d6.trans == [3, 4] and d5.st == 5 and d6.st == 5,
       f"transitions {d5.trans} {d6.trans}, states {status(0)} {status(1)}")

command(1, 3)                                   # home node 6: it says 250 mm
ok = wait_for(lambda: bit(1, HOMED) and not bit(1, BUSY), 30) and wait_for(lambda: d6.get(0x6061) == 8, 20)
# APOS and CPOS read apart: fair, the axis rests (homed, not busy) and each
# is held against the drive's 250 mm alone
report("home_mode_6", ok and md(13) == 250000 and md(14) == 250000 and d6.get(0x6061) == 8,
       f"APOS {md(13)} µm, CPOS {md(14)} µm, mode display {d6.get(0x6061)}")

# axis 0: 0 -> 100 mm at 50 mm/s, 500 mm/s2: T = 100/50 + 50/500 = 2.1 s = 210 cycles
command(0, 4, pos=100000, vel=50000, acc=500000)
ok = wait_for(lambda: bit(0, INPOS) and not bit(0, BUSY), 45) and wait_for(lambda: md(3) == 100000, 20)
report("move_absolute_in_position", ok and d5.get(0x6064) == 10000 and md(3) == 100000,
       f"drive position {d5.get(0x6064)} counts, APOS {md(3)} µm")
# axis 1 from 250 mm: run at -20 mm/s, then stop (a = 500 mm/s2: 0.4 mm further)
command(1, 5, vel=-20000, acc=500000)
ok = wait_for(lambda: bit(1, ATVEL), 30)
# 30 cycles at speed, counted by plcrt (input registers 1024-1025), not
# 0.3 s slept: velocity_move_at_v below wants 20 of them on the bus
c_at = cycles()
wait_for(lambda: cycles() >= c_at + 30, 30)
command(1, 6, acc=500000)
ok2 = wait_for(lambda: bit(1, INPOS) and not bit(1, BUSY), 30)

# ---- the load of drive 5 blocked during a move: the drive's following
# error (window 0x6065 = 2000 counts from its DCF) is a fault, EMCY 0x8611 ----
d5.stuck = True
d5.trans = []
command(0, 4, pos=0, vel=50000, acc=500000)
ok3 = wait_for(lambda: bit(0, ERROR), 30)
st0 = fault_status(0)
report("following_error_fault", ok3 and st0.get("errid") == 1 and st0.get("errcode") == 0x8611
       and d5.trans == [13, 14], f"status {st0}, drive {d5.state_name}, transitions {d5.trans}")
d5.stuck = False
d5.trans = []
command(0, 7)
ok = wait_for(lambda: bit(0, POWERED) and not bit(0, ERROR), 30)
report("reset_after_following_error", ok and d5.trans == [15, 2, 3, 4], f"transitions {d5.trans}, status {status(0)}")

# ---- a drive fault during a move (EMCY 0x2310, overcurrent) ----
command(0, 4, pos=0, vel=50000, acc=500000)
wait_for(lambda: bit(0, BUSY), 20)
d5.fault(0x2310)
ok3 = wait_for(lambda: bit(0, ERROR), 30)
st0 = fault_status(0)
command(1, 5, vel=10000, acc=500000)            # the other axis keeps moving
p1 = md(13)
wait_for(lambda: (md(13) or 0) > (p1 or 0) + 500, 30)
p2 = md(13)
report("drive_fault_is_axis_error", ok3 and st0.get("errid") == 1 and st0.get("errcode") == 0x2310
       and d5.st == 8, f"status {st0}, drive state {d5.state_name}")
report("other_axis_keeps_moving", p1 is not None and p2 is not None and p2 > p1 and bit(1, POWERED),
       f"axis 1 APOS {p1} -> {p2} µm")
command(1, 6, acc=500000)
d5.trans = []
command(0, 7)
ok = wait_for(lambda: bit(0, POWERED) and not bit(0, ERROR), 30)
report("fault_reset_powers_again", ok and d5.trans == [15, 2, 3, 4], f"transitions {d5.trans}, status {status(0)}")
command(0, 4, pos=50000, vel=50000, acc=500000)
ok = wait_for(lambda: bit(0, INPOS) and not bit(0, BUSY), 45) and wait_for(lambda: d5.get(0x6064) == 5000, 20)
report("moves_after_reset", ok and d5.get(0x6064) == 5000, f"drive position {d5.get(0x6064)}")

# ---- drive 6 sends TPDOs cut short: its inputs are stale, the axis goes
# to error 5 (offline) and stops; drive 5 is not touched ----
command(1, 5, vel=10000, acc=500000)
wait_for(lambda: bit(1, ATVEL), 30)
t_short = time.time()
d6.trans = []
d6.short_tpdo = 3
ok = wait_for(lambda: bit(1, ERROR), 30)
st1 = status(1)
p1 = md(3)
report("short_tpdo_axis_error", ok and st1.get("errid") == 5 and bit(0, POWERED),
       f"status {st1}, axis 0 powered {bit(0, POWERED)}")
d6.short_tpdo = 0
# the drive's answer to the controlword 0 of the loss (9, or 11 then 12),
# as its own TPDOs report it: a drive lagging under load reports
# Operation enabled for a while after the good frames are back
ok = wait_for(lambda: status(1).get("state") in (2, 6), 30)
report("short_tpdo_drive_off_power", ok and d6.trans[:1] in ([9], [11]),
       f"status {status(1)}, drive transitions {d6.trans}")
command(1, 7)
ok = wait_for(lambda: bit(1, POWERED) and not bit(1, ERROR), 30)
report("short_tpdo_reset_after_good_frames", ok, f"status {status(1)}")

d5.trans, d6.trans = [], []
command(0, 2)
command(1, 2)
ok = wait_for(lambda: d5.st == 3 and d6.st == 3, 20)
report("power_off_both", ok and d5.trans == [8] and d6.trans == [8], f"{d5.trans} {d6.trans}")
plc.send_signal(signal.SIGTERM)
report("plcrt_exits_0", plc.wait(10) == 0)
with open(os.path.join(out, "plcrt.log")) as f:
    named = [ln.strip() for ln in f if "node 6: TPDO" in ln and "of 3 byte(s), its mapping needs" in ln]
report("short_tpdo_named", named, f"{named[:1]}")
with open(os.path.join(out, "plcrt.log")) as f:
    lost = [ln.strip() for ln in f if "lost" in ln or "unexpected boot-up" in ln]
if lost:       # a stall of the host longer than the consumer time: say so
    print("  (plcrt saw: " + "; ".join(lost[:4]) + ")")

# ---- bad configuration: one clear message naming the node and the file, exit 2 ----
def bad_run(name, edit, expect):
    path = os.path.join(out, f"{name}.ini")
    with open(path, "w") as f:
        f.write(edit(text))
    r = subprocess.run([plcrt, "-c", path], capture_output=True, text=True, timeout=20)
    msg = (r.stdout + r.stderr).strip().splitlines()
    hit = [m for m in msg if all(e in m for e in expect)]
    report(f"bad_config_{name}", r.returncode == 2 and hit, f"status {r.returncode}: {hit or msg[-3:]}")


garbled = os.path.join(out, "garbled.eds")
with open(garbled, "w") as f:
    f.write("[FileInfo]\nFileName=garbled.eds\n[1000]\nDefaultValue=0x20192\n[1600sub0]\nParameterValue=1\n"
            "[1600sub1]\nParameterValue=0x60400000\n")
bad_run("missing_eds", lambda t: t.replace("examples/cia402/drive402.eds", "examples/cia402/nosuch.eds", 1),
        ["[canopen.drive5] eds (node 5)", "nosuch.eds: No such file"])
bad_run("garbled_eds", lambda t: t.replace("examples/cia402/drive402.eds", garbled, 1),
        ["[canopen.drive5] eds (node 5)", "object 0x1600:01", "not a mapping entry"])
bad_run("node_id_clash", lambda t: t.replace("id = 6", "id = 5"), ["[canopen.drive5] and [canopen.drive6] both have id 5"])

# ---- on the bus: the RPDO1 of node 5 carries the target position (bytes 3..6) ----
frames = trace.frames(0x205)
tgt = [int.from_bytes(d[3:7], "little", signed=True) for t, d in frames if len(d) >= 7]
# the first move: from the first cycle whose target leaves 0 to the first at 10000
try:
    i0 = next(i for i, v in enumerate(tgt) if v != 0)
    i1 = next(i for i in range(i0, len(tgt)) if tgt[i] == 10000)
    n = i1 - i0 + 1
except StopIteration:
    n = None
steps = [abs(b - a) for a, b in zip(tgt[i0:i1 + 1], tgt[i0 + 1:i1 + 1])] if n else []
report("move_lasts_D_over_v_plus_v_over_a", n is not None and abs(n - 210) <= 1,
       f"{n} cycles of 10 ms, closed form 210")
report("move_speed_limit", steps and max(steps) <= 50 + 1, f"largest step {max(steps) if steps else None} counts "
       f"per cycle, v x cycle = 50")
frames6 = [(t, d) for t, d in trace.frames(0x206) if t < t_short]
tgt6 = [int.from_bytes(d[3:7], "little", signed=True) for t, d in frames6 if len(d) >= 7]
st6 = [b - a for a, b in zip(tgt6, tgt6[1:])]
report("velocity_move_at_v", st6.count(-20) >= 20, f"{st6.count(-20)} cycles at -20 counts (20 mm/s x 10 ms)")
# the stop: from the last cycle at full speed to standstill, v^2/(2a) = 0.4 mm = 40 counts
try:
    k = max(i for i, v in enumerate(st6) if v == -20)
    j = next(i for i in range(k + 1, len(st6)) if st6[i] == 0)
    dstop = tgt6[k + 1] - tgt6[j]
except (ValueError, StopIteration):
    dstop = None
report("stop_v2_over_2a", ok2 and dstop is not None and abs(dstop - 40) <= 20,
       f"{dstop} counts from the last cycle at speed, closed form 40 (one cycle's travel: 20)")
trace.close(keep=not report.all_passed())
sys.exit(0 if report.all_passed() else 1)
