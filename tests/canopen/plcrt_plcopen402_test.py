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

The two runs compared over time.  Before the bus run, on the host, the same
sequence in examples/plcopen/plcopen.st on the sim plant at its own 1 ms cycle
(EPICPOS axes, the program tests/examples/test_plcopen.py runs): both
programs are traced by plcrt (plctrace, every cycle, armed before the
first MC_MoveAbsolute: the sim's homing takes seconds, the drives' homing
is held until the trace is armed) and compared from the trace rows, never
from separate reads.  Homing is not compared: EPICPOS searches the cam and
the zero pulse with its own set-point, the drive homes by itself (mode 6)
while the PLC's set-point follows it; both end on 0.

Time base.  Each command is compared from its start: bus row ib, the cycle
MC_MoveAbsolute's (MC_MoveVelocity's, MC_Stop's) Busy rises, and the sim's
first call after its own Busy rise (EPICPOS starts its profile at that
call's PLC time).  The bus program's planner (LJPROF in CIA402DRIVE) steps
CYCLE = 10 ms per call whatever the clock, so bus row ib + n holds the
profile at n x 10 ms; EPICPOS plans in PLC time, so the sim is read at
its start + n x 10 ms (its row there, or the line between the rows around
a time an overrun skipped, off the profile by 2A dt^2 / 8 at most, dt the
gap: allowed for; a gap over 20 ms is not compared, half of the 10 ms
points at least are).  Overruns of either run thus move neither side of
a comparison.  The bus start is the call before the axis' set-point first
moves (Y geared: X's; the move after the homing waits for each drive to
show CSP, checked against its mode display in the same trace).

Bound, closed form.  Both runs plan the same moves: speed v, and speed
changes dv whose duration is dv / A with A = 500000 Um/s2 (the bus
program's DFLTACC; the EPICPOS example's taccdec 0.2 s from 0 to maxvel
100000 Um/s), each covering dv / A x (v0 + v1) / 2.  The bus ramp is a
trapezoid (constant A), the sim's an epicycloid v0 + dv (tau - sin(2 pi
tau) / 2 pi) of the same duration T: the two positions differ by
dv T (1 - cos 2 pi tau) / 4 pi^2, at most dv^2 / (2 pi^2 A), and agree
again after the ramp.  The starts differ by less than one cycle of the
coarser task.  So per sample

    |x_bus - x_sim| <= v T + dv^2 / (2 pi^2 A) + 1 Um (the DINT's rounding)

with T = 10 ms: MC_MoveAbsolute at 20000 Um/s: 200 + 40.5 + 1 = 241.5 Um;
MC_MoveVelocity and MC_Stop at 10000 Um/s: 100 + 10.1 + 1 = 111.1 Um; Y
geared at 1:2: half of X's bound and half of X's travel in one 10 ms
cycle (Y's device takes the set-point the block computed from X in the
cycle before; in the sim, from its previous call, a gap an overrun
lengthened beyond 10 ms allowed for): 105.6 Um.  MC_Stop from 10000 Um/s
is compared as the travel from the stop's start (the 2 s of the velocity
move are PLC time, and the 10 ms run reaches them a few cycles later).
Between the ramps (dv / A + one cycle after a start, before an end) both
are on p0 + v (t - v / 2A): there the start difference alone counts, and
it is within the sim's first call: v x 1 ms + 1 Um (21 Um, 11 Um), a
bound that an acceleration different from the sim's (dv / 2A shifts the
line) or a late start exceeds.  The gear law in each run's own rows: Y
within ratio x X's travel since the previous row + 1 Um.  The drives show
a new mode of operation MODE_LAG SYNCs late, as real drives do: a move
given when MC_Home is Done waits for CSP to show, it is not refused.

    $PY tests/canopen/plcrt_plcopen402_test.py --sim SIM_PLCRT OUT_DIR   (on the host, first)
    $PY tests/canopen/plcrt_plcopen402_test.py PLCRT OUT_DIR             (in the kernel with CAN)
tests/canopen/plcopen402.sh runs both.
"""
import bisect
import csv
import math
import os
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from drive402 import Drive402  # noqa: E402
from slave401 import CanDump, connect  # noqa: E402
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from peer import Report, free_port, wait_for  # noqa: E402
from onecycle import Recording  # noqa: E402
from pymodbus.client import ModbusTcpClient  # noqa: E402

if sys.argv[1] == "--sim":                  # the sim-plant run, on the host
    plcrt, sim_plcrt, out = None, sys.argv[2], sys.argv[3]
else:                                       # the bus run, in the kernel with CAN
    plcrt, out, sim_plcrt = sys.argv[1], sys.argv[2], None
PORT = 15036                                # inside the kernel with CAN: its own network
SIM_PORT = free_port() if sim_plcrt else 0  # on the host: a free one
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


# ---- the trace channels, the same in both programs ----
CHANS = ["STEPS", "SETPTX", "SETPTY", "POSX", "POSY", "MABX.BUSY", "MVX.BUSY", "SPX.BUSY", "GIN.INGEAR", "PHASE",
         "MABY.BUSY"]
C = {n: i for i, n in enumerate(CHANS)}
TRIGGER = "CONFIG0.RES0.MC.MABX.BUSY:rise"      # the first MC_MoveAbsolute, after the homing
SIM_CYCLE_S = 0.001
SIM_SAMPLES = 5300                              # >= the cycles from there to the stop's end at 1 ms
BUS_SAMPLES = 1500                              # at 10 ms: the drives' python may lag on a loaded host


C["MDX"], C["MDY"] = len(CHANS), len(CHANS) + 1  # the bus run's only: the mode displays (0x6061)


def record(port, samples, name, extra=()):
    return Recording(port, ["CONFIG0.RES0.MC." + c for c in CHANS + list(extra)], TRIGGER, samples,
                     os.path.join(out, name), pre=2, timeout=90)


def sim_run():
    """examples/plcopen/plcopen.st on the sim plant at its 1 ms cycle,
    traced from its first MC_MoveAbsolute: [(cycle, PLC ms, values)].  On
    the host: inside the kernel with CAN a loaded host starves a 1 ms task
    for hundreds of ms, and the sim plant's closed loop does not survive
    that (the bus program's 10 ms task and its drives do)."""
    ini = os.path.join(out, "plcopen_sim.ini")
    with open(os.path.join(HERE, "..", "..", "examples", "plcopen", "plcopen.ini")) as f:
        text = f.read().replace("port = 1502", f"port = {SIM_PORT}").replace(
            "file = build/plcopen.retain", "file = " + os.path.join(out, "plcopen_sim.retain"))
    for old in ("plcopen_sim.retain", "plcopen_sim.retain.prev"):
        if os.path.exists(os.path.join(out, old)):
            os.remove(os.path.join(out, old))
    with open(ini, "w") as f:
        f.write(text)
    with open(os.path.join(out, "plcrt_sim.log"), "w") as slog:
        p = subprocess.Popen([sim_plcrt, "-c", ini], stdout=slog, stderr=subprocess.STDOUT)
        try:
            c = ModbusTcpClient("127.0.0.1", port=SIM_PORT, timeout=3)
            up = wait_for(lambda: c.connect(), 10)
            c.close()
            rows = record(SIM_PORT, SIM_SAMPLES, "sim_trace.csv").rows() if up else []
        except RuntimeError as e:
            print(f"sim run: {e}")
            rows = []
        finally:
            p.send_signal(signal.SIGTERM)
            p.wait(10)
    return rows


SIM_CSV = os.path.join(out, "sim_trace.csv")
if plcrt is None:
    if os.path.exists(SIM_CSV):
        os.remove(SIM_CSV)
    sim_rows = sim_run()
    if sim_rows and sim_rows[2][2][C["STEPS"]] != 1:
        sim_rows = sim_run()        # armed after the homing on a loaded host: once more
    report("sim_run_traced_from_first_move", len(sim_rows) == SIM_SAMPLES and sim_rows[2][2][C["STEPS"]] == 1,
           f"{len(sim_rows)} samples, steps at the trigger {sim_rows[2][2][C['STEPS']] if sim_rows else None}")
    sys.exit(0 if report.all_passed() else 1)
# the bus run: the sim run's trace, written on the host just before
sim_rows = []
if os.path.exists(SIM_CSV):
    with open(SIM_CSV) as f:
        sim_rows = [(int(r[1]), float(r[0]), [float(x) for x in r[2:]]) for r in list(csv.reader(f))[1:]]


MODE_LAG = 5                                # SYNCs a drive takes to show a new mode


class HomingDrive(Drive402):
    """Drive402 that counts the homings it completes (mode 6), whose
    homing stays in progress while hold is set (a home switch not yet
    reached: the trace is armed meanwhile), and which shows a new mode of
    operation in its mode display (0x6061) MODE_LAG SYNCs after it was
    asked for, as drives do (the standard sets no time)."""

    def __init__(self, *a, **k):
        super().__init__(*a, **k)
        self.homings = 0
        self.hold = True
        self.lagged = 0
        self.on_sync = HomingDrive._step

    def _step(self):
        before, shown = self.home_phase, self.mode_disp
        if self.hold and self.home_phase == 1:
            self.home_left = 3
        Drive402._step(self)
        if before == 1 and self.home_phase == 2:
            self.homings += 1
        if self.mode_disp != shown and self.lagged < MODE_LAG:
            self.lagged += 1
            with self.lock:
                self.mode_disp = shown
                self._publish()
        elif self.mode_disp != shown:
            self.lagged = 0


trace = CanDump(os.path.join(out, "candump.log"))
net = connect("vcan0")
dx = HomingDrive(net, 5)
dy = HomingDrive(net, 6)
log = open(os.path.join(out, "plcrt.log"), "w")
plc = subprocess.Popen([plcrt, "-c", cfg], stdout=log, stderr=subprocess.STDOUT)
mb = ModbusTcpClient("127.0.0.1", port=PORT, timeout=3)
ok = wait_for(lambda: mb.connect(), 10)
report("modbus_up", ok)
# armed before the homing ends (the drives home for a second and more)
try:
    bus_rec = record(PORT, BUS_SAMPLES, "bus_trace.csv", ["MDX", "MDY"])
except RuntimeError as e:
    print(f"bus run: {e}")
    bus_rec = None
dx.hold = dy.hold = False


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
    wait_for(lambda: (lambda s: got.append(s) or True if s and cond(s) else False)(status()), timeout, 0.02)
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
    report("move_absolute_on_targets_as_sim_run", (s["gearx0"], s["geary0"]) == (tx, ty) and s["lasterr"] == 0,
           f"set-points at gear-in {(s['gearx0'], s['geary0'])}, targets {(tx, ty)}, "
           f"last ErrorID {s['lasterr']} (0: no block in Error so far)")
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

try:
    bus_rows = bus_rec.rows() if bus_rec else []
except RuntimeError as e:
    print(f"bus run: {e}")
    bus_rows = []
plc.send_signal(signal.SIGTERM)
report("plcrt_exits_0", plc.wait(10) == 0)

# ---- the bus run against the sim-plant run, cycle by cycle ----
A = 500000.0                    # Um/s2: DFLTACC of the bus program, the mean acceleration of the sim's ramp


def col(rows, i, chan):
    return rows[i][2][C[chan]]


def rise(rows, chan, start=1):
    return next((i for i in range(max(start, 1), len(rows))
                 if col(rows, i, chan) and not col(rows, i - 1, chan)), None)


def fall(rows, chan, start):
    return next((i for i in range(start, len(rows)) if not col(rows, i, chan)), None)


def planner_start(what, ib, axis="X"):
    """the bus row before the axis' set-point first moves after row ib:
    the call before its planner's first (which already holds its first
    10 ms).  Checked: that is row ib, or, while the drive did not show CSP
    (8) at ib, the first row it does (the request waits for it, then goes
    to the device in the next call)"""
    sp, md = "SETPT" + axis, "MD" + axis
    k = next((k for k in range(ib + 1, len(bus_rows)) if col(bus_rows, k, sp) != col(bus_rows, ib, sp)), None)
    csp = next((r for r in range(ib, len(bus_rows)) if col(bus_rows, r, md) == 8), None)
    report(what, k is not None and csp is not None and k - 1 == max(ib, csp),
           f"the planner started {k - 1 - ib if k else None} cycles of 10 ms after the Busy rise, "
           f"the drive showed CSP {csp - ib if csp is not None else None} cycles after it")
    return (k - 1) if k else ib


def sim_cycles(js, es):
    """the sim's PLC time from row js + 1 to row es in bus cycles"""
    return int((sim_rows[es][1] - sim_rows[js + 1][1]) / (CYCLE_S * 1000.0))


def bound(v, dv):
    """Um: one bus cycle's travel at v, plus the epicycloid's most from
    the trapezoid of the same speed change dv, plus the DINT's rounding"""
    return v * CYCLE_S + dv * dv / (2 * math.pi ** 2 * A) + 1.0


def sim_value(t, chan):
    """the sim's value at PLC time t (ms): its row, or, where an overrun
    skipped t, the line between the rows either side, which is off the
    profile by at most 2A dt^2 / 8 (the epicycloid's peak acceleration
    is 2A); None where the gap is above 20 ms.  With the value: that
    allowance, and the PLC time in s from the row before (one sim cycle,
    or more after an overrun)"""
    k = bisect.bisect_left(sim_t, t)
    if k < len(sim_t) and sim_t[k] == t:
        return col(sim_rows, k, chan), 0.0, (t - sim_t[k - 1]) / 1000.0 if k else SIM_CYCLE_S
    if k == 0 or k >= len(sim_t) or sim_t[k] - sim_t[k - 1] > 20.0:
        return None, 0.0, 0.0
    t1, t2 = sim_t[k - 1], sim_t[k]
    v1, v2 = col(sim_rows, k - 1, chan), col(sim_rows, k, chan)
    dt = (t2 - t1) / 1000.0
    return v1 + (v2 - v1) * (t - t1) / (t2 - t1), 2 * A * dt * dt / 8, dt


def compare(what, chan, ib, js, n_end, bnd, rel, least, lag=0.0):
    """bus row ib + n (the busy rise's row, then n calls of its planner:
    the position planned n x 10 ms after its start) against the sim at PLC
    time n x 10 ms after its call js + 1 (the first after the busy rise:
    EPICPOS plans in PLC time from the call that starts it), n = 0..n_end
    (at least least cycles, half of them compared at least).  lag: the speed
    (Um/s) of a set-point the sim takes from its previous call (the gear's
    slave): what an overrun's gap beyond 10 ms adds to the bound"""
    worst, at, count, diffs = None, None, 0, []
    t0 = sim_rows[js + 1][1]
    b0 = col(bus_rows, ib, chan) if rel else 0.0
    s0 = col(sim_rows, js + 1, chan) if rel else 0.0
    for n in range(n_end + 1):
        sv, extra, gap = sim_value(t0 + n * CYCLE_S * 1000.0, chan)
        if ib + n >= len(bus_rows) or sv is None:
            continue
        extra += lag * max(0.0, gap - CYCLE_S)
        d = abs((col(bus_rows, ib + n, chan) - b0) - (sv - s0)) - extra
        count += 1
        diffs.append((n, d))
        if worst is None or d > worst:
            worst, at = d, n
    report(what, n_end >= least and 2 * count >= n_end + 1 and worst is not None and worst <= bnd,
           f"worst {worst:.1f} Um (less the sim's overrun allowances) at {at} cycles of 10 ms from the "
           f"command's start, bound {bnd:.1f} Um, "
           f"{count} samples of {n_end + 1} cycles (at least {least} cycles)" if worst is not None
           else f"nothing to compare ({n_end + 1} cycles)")
    return diffs


def cruise(what, diffs, v, n_end, end_ramp):
    """between the ramps (each v / A long, a cycle more) both runs are on
    the line p0 + v (t - v / 2A) from their starts (the sim's start is
    exact to its cycle): v x 1 ms + rounding"""
    nr = math.ceil(v / A / CYCLE_S) + 1
    last = n_end - nr - 1 if end_ramp else n_end - 1
    ds = [d for n, d in diffs if nr <= n <= last]
    bnd = v * SIM_CYCLE_S + 1.0
    report(what, 2 * len(ds) >= last - nr + 1 and len(ds) >= 10 and max(ds) <= bnd,
           f"worst {max(ds, default=0):.1f} Um over {len(ds)} samples from cycle {nr} to {last}, bound {bnd:g} Um")


sim_t = [t for _, t, _ in sim_rows]
report("traces_whole_and_consecutive",
       len(bus_rows) == BUS_SAMPLES and len(sim_rows) == SIM_SAMPLES
       and all(b[0] == a[0] + 1 for rows in (bus_rows, sim_rows) for a, b in zip(rows, rows[1:]))
       and col(bus_rows, 2, "STEPS") == 1,
       f"bus {len(bus_rows)} samples, sim {len(sim_rows)}, "
       f"steps at the bus trigger {col(bus_rows, 2, 'STEPS') if bus_rows else None}")
if len(bus_rows) == BUS_SAMPLES and len(sim_rows) == SIM_SAMPLES:
    vx = speed / 2.0                    # MC_MoveVelocity's speed, Um/s
    # MC_MoveAbsolute: both runs from 0 (homed), X and Y at speed to their targets
    # after the homing the drives show CSP MODE_LAG SYNCs late: each move
    # waits for its drive (they need not show it in the same cycle)
    js = 2
    for ch in ("SETPTX", "SETPTY"):
        ib = planner_start(f"move_absolute_{ch[-1].lower()}_starts_when_the_drive_shows_csp", 2, ch[-1])
        eb = fall(bus_rows, "MABX.BUSY" if ch == "SETPTX" else "MABY.BUSY", ib)
        es = fall(sim_rows, "MABX.BUSY" if ch == "SETPTX" else "MABY.BUSY", js)
        n_end = min(eb - ib, sim_cycles(js, es)) if eb and es else 0
        d = compare(f"move_absolute_{ch[-1].lower()}_as_sim_run_cycle_by_cycle", ch, ib, js, n_end,
                    bound(speed, speed), False, 200 if ch == "SETPTX" else 90)
        # the move ends distance / v + v / A after its start (X 2.54 s, Y 1.04 s)
        dist = abs((tx if ch == "SETPTX" else ty) - col(bus_rows, ib, ch))
        end = round((dist / speed + speed / A) / CYCLE_S)
        cruise(f"move_absolute_{ch[-1].lower()}_cruise_as_sim_run", d, speed, min(n_end, end), True)
    # MC_MoveVelocity of X (Y geared): both from the targets
    ib, js = rise(bus_rows, "MVX.BUSY"), rise(sim_rows, "MVX.BUSY")
    ib = planner_start("velocity_move_starts_at_once", ib) if ib else None
    eb = fall(bus_rows, "MVX.BUSY", ib) if ib else None
    es = fall(sim_rows, "MVX.BUSY", js) if js else None
    n_end = min(eb - ib, sim_cycles(js, es)) if eb and es else 0
    d = compare("velocity_move_x_as_sim_run_cycle_by_cycle", "SETPTX", ib or 0, js or 0, n_end,
                bound(vx, vx), False, 100)
    cruise("velocity_move_x_cruise_as_sim_run", d, vx, n_end, False)
    # Y by the gear: ratio x X's bound, and a cycle of X's travel for the
    # cycle Y's device takes its set-point later
    compare("gear_y_as_sim_run_cycle_by_cycle", "SETPTY", ib or 0, js or 0, n_end,
            ratio * (bound(vx, vx) + vx * CYCLE_S), False, 100, ratio * vx)
    # the gear law within each run, from one trace row each: Y within X's
    # travel since the previous row x ratio (Y's device takes the set-point
    # the block computed a cycle later), one cycle of its run, or the
    # periods an overrun skipped as well
    for rows, cyc, name in ((bus_rows, CYCLE_S, "bus"), (sim_rows, SIM_CYCLE_S, "sim")):
        g = rise(rows, "GIN.INGEAR")
        e = fall(rows, "MVX.BUSY", rise(rows, "MVX.BUSY") or len(rows)) if g else None
        if g and e:
            x0, y0 = col(rows, g, "SETPTX"), col(rows, g, "SETPTY")
            over = [(abs((col(rows, i, "SETPTY") - y0) - (col(rows, i, "SETPTX") - x0) * ratio),
                     vx * (rows[i][1] - rows[i - 1][1]) / 1000.0 * ratio + 1.0) for i in range(g, e)]
            worst = max(d - b for d, b in over)
            report(f"gear_law_in_{name}_trace", worst <= 0 and e - g >= 100,
                   f"worst {max(d for d, _ in over)} Um over {e - g} cycles, "
                   f"{worst:+g} Um from its row's bound (one cycle: {vx * cyc * ratio + 1:g} Um)")
        else:
            report(f"gear_law_in_{name}_trace", False, f"no gearing with a velocity move in the trace ({g}, {e})")
    # MC_Stop of X at 10000 Um/s (Y geared): from where each run stopped
    # (the 2 s of the velocity move are PLC time: the 10 ms run's steps
    # start it a few cycles later), both to rest within 20 ms
    ib, js = rise(bus_rows, "SPX.BUSY"), rise(sim_rows, "SPX.BUSY")
    ib = planner_start("stop_starts_at_once", ib) if ib else None
    compare("stop_x_as_sim_run_cycle_by_cycle", "SETPTX", ib or 0, js or 0, 10,
            bound(vx, vx), True, 10 if ib and js else 10 ** 9)
    compare("stop_y_geared_as_sim_run_cycle_by_cycle", "SETPTY", ib or 0, js or 0, 10,
            ratio * (bound(vx, vx) + vx * CYCLE_S), True, 10 if ib and js else 10 ** 9, ratio * vx)

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
