"""The CODESYS-style PLCopen program (examples/plcopen/plcopen_cia402.st: the
program of examples/plcopen changed only in its device binding,
MC_AXIS_CIA402 instead of MC_AXIS_EPICPOS, and a 10 ms task) driving two
simulated CiA 402 drives (drive402.Drive402, nodes 5 = X and 6 = Y) on
vcan0 inside a kernel with CAN (tests/canopen/bus_run.sh), watched over
Modbus.  What a user sees: both drives powered (transitions 3, 4) and homed
by the drive (mode 6); MC_MoveAbsolute ends both set-points on their
targets, as the sim-plant run does (tests/examples/test_plcopen.py: the same
exact values); MC_GearIn: Y's set-point follows X's at 1:2 within one
cycle's travel of X times the ratio (X at 10000 Um/s, 10 ms: 50 Um), as in
the sim-plant run whose bound is the same expression at its 1 ms cycle; on
the bus, the target positions of the velocity move are X's 10000 Um/s x 10
ms = 10 counts per SYNC and Y's half of it (closed form, from the recorded
RPDO frames); MC_Stop held: Stopping; after MC_GearOut both at rest on
their set-points; a drive fault (EMCY 0x2310) -> X in ErrorStop, MC_Reset
(coil 7) -> the drive's fault reset (15) and power again (2, 3, 4), and the
sequence goes round again.

    $PY tests/canopen/plcrt_plcopen402_test.py PLCRT OUT_DIR
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
PORT = 15036
HERE = os.path.dirname(os.path.abspath(__file__))
report = Report("canopen_plcopen402")
RESET = 7                                   # coil of MC_Reset (both axes)
NAMES = ["statex", "statey", "setptx", "setpty", "posx", "posy", "gearx0", "geary0",
         "lasterr", "steps", "phase", "ingear"]     # %MD10..%MD21
CYCLE_S = 0.010
SCALE = 0.1                                 # counts per Um

cfg = os.path.join(out, "plcopen_cia402.ini")
with open(os.path.join(HERE, "..", "..", "examples", "plcopen", "plcopen_cia402.ini")) as f:
    # a heartbeat consumer time that rides out the stalls of a loaded host
    text = f.read().replace("port = 1502", f"port = {PORT}").replace(
        "heartbeat_consumer_ms = 250", "heartbeat_consumer_ms = 5000").replace(
        "file = build/plcopen_cia402.retain", "file = " + os.path.join(out, "plcopen_cia402.retain"))
for old in ("plcopen_cia402.retain", "plcopen_cia402.retain.prev"):     # the README's values, every run
    if os.path.exists(os.path.join(out, old)):
        os.remove(os.path.join(out, old))
with open(cfg, "w") as f:
    f.write(text)


class HomingDrive(Drive402):
    """Drive402 that counts the homings it completes (mode 6)."""

    def __init__(self, *a, **k):
        super().__init__(*a, **k)
        self.homings = 0
        self.on_sync = HomingDrive._step

    def _step(self):
        before = self.home_phase
        Drive402._step(self)
        if before == 1 and self.home_phase == 2:
            self.homings += 1


trace = CanDump(os.path.join(out, "candump.log"))
net = connect("vcan0")
dx = HomingDrive(net, 5)
dy = HomingDrive(net, 6)
log = open(os.path.join(out, "plcrt.log"), "w")
plc = subprocess.Popen([plcrt, "-c", cfg], stdout=log, stderr=subprocess.STDOUT)
mb = ModbusTcpClient("127.0.0.1", port=PORT, timeout=3)
ok = wait_for(lambda: mb.connect(), 10)
report("modbus_up", ok)


def s32(hi, lo):
    v = hi << 16 | lo
    return v - (1 << 32) if v & 0x80000000 else v


def md(n, count=1):
    rr = mb.read_holding_registers(2048 + 2 * n, 2 * count, slave=1)
    if rr.isError():
        return None
    return [s32(rr.registers[2 * i], rr.registers[2 * i + 1]) for i in range(count)]


def status():
    """one request: the values of one PLC cycle"""
    v = md(10, len(NAMES))
    return dict(zip(NAMES, v)) if v else {}


def skipped():
    rr = mb.read_input_registers(1024 + 4, 2, slave=1)
    return 0 if rr.isError() else (rr.registers[0] << 16 | rr.registers[1])


def at(cond, timeout):
    got = []
    wait_for(lambda: (lambda s: got.append(s) or True if s and cond(s) else False)(status()), timeout)
    return got[-1] if got else None


tx, ty, speed, rnum, rden = md(0, 5) or [None] * 5
ratio = rnum / rden if rden else 0
report("readme_setup", (tx, ty, speed, rnum, rden) == (50000, 20000, 20000, 1, 2), f"{(tx, ty, speed, rnum, rden)}")

s = at(lambda s: s["phase"] >= 1, 30)
report("power_on_and_home_mode_6", s is not None and s["lasterr"] == 0 and dx.homings >= 1 and dy.homings >= 1
       and dx.trans[-2:] == [3, 4] and dy.trans[-2:] == [3, 4],
       f"status {s or status()}, homings {dx.homings} {dy.homings}, transitions {dx.trans} {dy.trans}")

s = at(lambda s: s["phase"] == 4, 20)
t_vel = time.time()
report("reaches_velocity_move_geared", s is not None, f"{status()}")
samples = []
if s:
    report("move_absolute_on_targets_as_sim_run", (s["gearx0"], s["geary0"]) == (tx, ty),
           f"set-points at gear-in {(s['gearx0'], s['geary0'])}, targets {(tx, ty)}")
    sk0 = skipped()
    while True:
        s = status()
        if not s or s["phase"] != 4:
            break
        samples.append(s)
        time.sleep(0.02)
    sk = skipped() - sk0
    bound = speed / 2.0 * CYCLE_S * (1 + sk) * ratio + 1.0
    worst = max((abs((x["setpty"] - x["geary0"]) - (x["setptx"] - x["gearx0"]) * ratio) for x in samples),
                default=None)
    report("gear_follows_within_one_cycle_travel",
           len(samples) >= 20 and worst is not None and worst <= bound,
           f"worst {worst} Um over {len(samples)} samples, bound {bound:g} Um ({sk} periods skipped)")
    report("velocity_move_states_4_and_5", all(x["statex"] == 4 and x["statey"] == 5 and x["ingear"] == 1
                                               for x in samples),
           f"{sorted({(x['statex'], x['statey'], x['ingear']) for x in samples})}")
t_vel_end = time.time()
stopping = at(lambda s: s["phase"] == 5 and s["statex"] == 6, 5)
report("stop_held_stopping_y_geared", stopping is not None and stopping["statey"] == 5, f"{stopping or status()}")
# in the 1 s pause after MC_GearOut: both at rest on their set-points
s = at(lambda s: s["phase"] == 7 and s["statex"] == 1 and s["statey"] == 1 and s["ingear"] == 0
       and abs(s["posx"] - s["setptx"]) <= 5 and abs(s["posy"] - s["setpty"]) <= 5, 5)
report("gear_out_both_at_rest_on_set_points",
       s is not None and abs(dx.pos - s["setptx"] * SCALE) <= 0.5 and abs(dy.pos - s["setpty"] * SCALE) <= 0.5,
       f"{s or status()}, drives at {dx.pos} {dy.pos} counts")

# ---- a drive fault while X runs the velocity move ----
s = at(lambda s: s["phase"] == 4, 20)
dx.trans = []
dx.fault(0x2310)
# the sequence halts while X is not powered: the velocity move's ErrorID
# stays in lasterr, the axis's error 210 + the device's ERRID 1 (drive fault)
s = at(lambda s: s["statex"] == 7 and s["lasterr"] != 0, 5)
report("drive_fault_error_stop_211", s is not None and s["lasterr"] == 211 and dx.st == 8,
       f"{s or status()}, drive {dx.state_name}")
dx.trans = []
mb.write_coil(RESET, True, slave=1)
s = at(lambda s: s["statex"] not in (0, 7), 10)
mb.write_coil(RESET, False, slave=1)
report("mc_reset_fault_reset_on_drive", s is not None and dx.trans[:4] == [15, 2, 3, 4],
       f"{s or status()}, transitions {dx.trans}")
steps0 = status().get("steps", 0)
s = at(lambda s: s["steps"] >= steps0 + 5, 25)
report("sequence_goes_round_again", s is not None and s["statex"] != 7 and s["statey"] != 7, f"{s or status()}")

plc.send_signal(signal.SIGTERM)
report("plcrt_exits_0", plc.wait(10) == 0)

# ---- on the bus: the velocity move's target positions per SYNC ----
def steps_of(cob):
    tg = [int.from_bytes(d[3:7], "little", signed=True) for t, d in trace.frames(cob)
          if t_vel <= t <= t_vel_end and len(d) >= 7]
    return [b - a for a, b in zip(tg, tg[1:])]


stx, sty = steps_of(0x205), steps_of(0x206)
vx = round(speed / 2.0 * CYCLE_S * SCALE)        # counts per cycle: 10
report("bus_x_at_v_y_at_ratio", stx.count(-vx) >= 50 and sty.count(round(-vx * ratio)) >= 50,
       f"X {stx.count(-vx)} cycles at {-vx} counts, Y {sty.count(round(-vx * ratio))} at {round(-vx * ratio)}")
trace.close(keep=not report.all_passed())
sys.exit(0 if report.all_passed() else 1)
