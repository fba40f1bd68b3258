#!/usr/bin/env python3
"""The trace and forcing of plcrt (docs/trace.md) with real clients:
pymodbus on the register block, and plctrace as a user runs it.

The program (tests/runtime/st/trace.st) makes every value a function of
the cycle: after its n-th run count = n, toggle = (n MOD 100 >= 50),
saw = n MOD 100, pair_a = 3n, pair_b = -3n, axis.posit = n MOD 1000. A
sample carries the number of cycles run before it (c), so n = c + 1 and
every expected value below comes from the program's text, not from plcrt.

usage: test_trace.py PLCRT WORKDIR"""
import csv
import os
import struct
import subprocess
import sys
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from peer import Plcrt, Report, free_port, wait_for  # noqa: E402
from pymodbus.client import ModbusTcpClient  # noqa: E402

PLCRT, WORK = sys.argv[1], sys.argv[2]
PLCTRACE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "plc_runtime", "plctrace")
report = Report("runtime-trace")
os.makedirs(WORK, exist_ok=True)
PORT = free_port()
BASE, CMD, SEL, WIN = 60000, 60100, 60300, 60304
CLAIM, RELEASE, CHANNELS, SETUP, ARM, TRIGGER, STOP, NEXT = range(1, 9)
LOOKUP, FORCE, UNFORCE, UNFORCE_ALL = 16, 17, 18, 19
MANUAL, RISE, FALL, UP, DOWN = range(5)
P = "CONFIG0.RES0.INST0."


def ini(allow_force, extra=""):
    path = os.path.join(WORK, "trace.ini")
    with open(path, "w") as f:
        f.write(f"""[io]
backend = none
[modbus]
port = {PORT}
idle_timeout = 0
[retain]
file =
[plc]
status_interval = 1
status_vars = {P}GAIN
[debug]
allow_force = {'yes' if allow_force else 'no'}
[modbus.symbols]
{P}SCALED = holding 9000
{P}ECHO = holding 9001
{P}GAIN = holding 9002 rw
{extra}""")
    return path


def client():
    c = ModbusTcpClient("127.0.0.1", port=PORT, timeout=3)
    assert c.connect()
    return c


def u32(r, i=0):
    return r[i] << 16 | r[i + 1]


def a32(x):
    return [(x >> 16) & 0xFFFF, x & 0xFFFF]


def text(s):
    b = s.encode() + b"\0" * (2 - len(s) % 2)
    return [b[i] << 8 | b[i + 1] for i in range(0, len(b), 2)]


def exc_of(r):
    """The exception code of a reply, or 0 when it is not one."""
    return getattr(r, "exception_code", -1) if r.isError() else 0


def cmd(c, token, code, args=()):
    return exc_of(c.write_registers(CMD, [token, code] + list(args), slave=1))


def lookup(c, path):
    r = c.readwrite_registers(read_address=BASE + 24, read_count=2, write_address=CMD,
                              values=[0, LOOKUP] + text(path), slave=1)
    assert not r.isError(), (path, r)
    return u32(r.registers)


def status(c):
    return c.read_holding_registers(BASE, 32, slave=1).registers


def window(c, what, first, n):
    r = c.readwrite_registers(read_address=WIN, read_count=n, write_address=SEL,
                              values=[what, first >> 16, first & 0xFFFF], slave=1)
    assert not r.isError(), (what, first, r)
    return r.registers


def signed(v, bits):
    return v - (1 << bits) if v >> (bits - 1) else v


def series(c, what, n, width):
    out, per = [], 125 // width
    for first in range(0, n, per):
        k = min(per, n - first)
        r = window(c, what, first, k * width)
        for i in range(k):
            v = 0
            for w in r[i * width:(i + 1) * width]:
                v = v << 16 | w
            out.append(v)
    return out


def setup_args(samples, pre, trig=MANUAL, tvar=0xFFFFFFFF, level=0.0, decim=1, repeat=0):
    return [decim] + a32(samples) + a32(pre) + [trig] + a32(tvar) + list(struct.unpack(">4H", struct.pack(">d", level))) + [repeat]


def capture(c, token, chans, samples, pre, trig=MANUAL, tpath=None, level=0.0, decim=1, timeout=20):
    """Arm, wait, read back: {'cycle': [...], 'tick': [...], path: [...]} (DINT/BOOL/REAL by size)."""
    ids = [lookup(c, p) for p in chans]
    tvar = lookup(c, tpath) if tpath else 0xFFFFFFFF
    assert cmd(c, token, CHANNELS, [x for i in ids for x in a32(i)]) == 0
    assert cmd(c, token, SETUP, setup_args(samples, pre, trig, tvar, level, decim)) == 0
    before = u32(status(c), 8)
    assert cmd(c, token, ARM) == 0
    if trig == MANUAL:
        assert cmd(c, token, TRIGGER) == 0
    st = wait_for(lambda: (lambda s: s if s[3] and u32(s, 10) > before else None)(status(c)), timeout, 0.02)
    assert st, "no capture"
    out = {"cycle": series(c, 0x100, samples, 2), "tick": series(c, 0x101, samples, 2), "status": st}
    for k, p in enumerate(chans):
        size = window(c, 0x400, k, 4)[3]
        vals = series(c, k, samples, 1 if size <= 2 else size // 2)
        out[p] = [signed(v, 8 * size) if size in (2, 4) else v for v in vals]
    return out


def consecutive(cycles, step=1):
    return all(b - a == step for a, b in zip(cycles, cycles[1:]))


def n_of(t, i):
    return t["cycle"][i] + 1


plc = None
try:
    plc = Plcrt(PLCRT, ini(True), WORK, "trace")
    c = client()
    st = status(c)
    report("the block answers: magic, capacity of at least 16384 samples",
           st[0] == 0x5452 and u32(st, 6) >= 16384, f"capacity {u32(st, 6)}")
    T = 0x1234
    report("claim", cmd(c, T, CLAIM) == 0)

    # ---- triggers, pre-trigger counts exact to the sample ----
    t = capture(c, T, ["count", "toggle"], 300, 37, RISE, "toggle")
    ok = (t["toggle"][37] == 1 and t["toggle"][36] == 0 and n_of(t, 37) % 100 == 50
          and len(t["cycle"]) == 300 and consecutive(t["cycle"]))
    report("rise of a BOOL: the trigger sample is sample 37 of 300 after 37 pre-trigger samples", ok,
           f"n at sample 37: {n_of(t, 37)}, toggle {t['toggle'][35:39]}")
    report("each sample holds the cycle's values: count = cycle + 1, toggle = (n MOD 100 >= 50)",
           all(t["count"][i] == n_of(t, i) and t["toggle"][i] == int(n_of(t, i) % 100 >= 50) for i in range(300)))
    t = capture(c, T, ["toggle", "count"], 120, 0, FALL, "toggle")
    report("fall of a BOOL, no pre-trigger: sample 0 is the falling one (n MOD 100 = 0)",
           t["toggle"][0] == 0 and n_of(t, 0) % 100 == 0 and t["count"][0] == n_of(t, 0), f"n {n_of(t, 0)}")
    t = capture(c, T, ["saw", "count"], 100, 5, UP, "saw", 30.5)
    saw = [struct.unpack(">f", struct.pack(">I", v & 0xFFFFFFFF))[0] for v in t["saw"]]
    report("a REAL crossing 30.5 upwards, 5 before: sample 5 has saw = 31, sample 4 has 30",
           saw[5] == 31.0 and saw[4] == 30.0 and n_of(t, 5) % 100 == 31, f"saw {saw[3:7]}")
    t = capture(c, T, ["axis.posit"], 400, 200, DOWN, "axis.posit", 100)
    report("a DINT of a function-block instance crossing 100 downwards, 200 before: sample 200 is posit 0",
           t["axis.posit"][200] == 0 and t["axis.posit"][199] == 999
           and all(t["axis.posit"][i] == n_of(t, i) % 1000 for i in range(400)),
           f"posit {t['axis.posit'][198:202]}")
    t = capture(c, T, ["count"], 50, 10, MANUAL)
    report("manual trigger: 50 samples, 10 before the trigger, consecutive cycles",
           len(t["count"]) == 50 and consecutive(t["cycle"]) and t["count"][0] == n_of(t, 0))

    # ---- no sample missing or torn, while other clients read ----
    stop = threading.Event()
    reads = [0]

    def hammer():
        h = client()
        while not stop.is_set():
            h.read_holding_registers(BASE, 32, slave=1)
            h.read_holding_registers(9000, 3, slave=1)
            reads[0] += 1
        h.close()
    th = [threading.Thread(target=hammer) for _ in range(2)]
    for x in th:
        x.start()
    t = capture(c, T, ["count", "pair_a", "pair_b"], 2000, 0, MANUAL)
    stop.set()
    for x in th:
        x.join()
    report("2000 samples under 2 reading clients: consecutive cycle numbers, none missing",
           consecutive(t["cycle"]), f"{reads[0]} reads beside")
    report("pair_a and pair_b (written together) never seen apart: pair_b = -pair_a = -3n in every sample",
           all(t["pair_b"][i] == -t["pair_a"][i] == -3 * n_of(t, i) for i in range(2000)))
    report("PLC ticks advance with the cycles (no overrun here) or more (one skipped periods)",
           all(b - a >= 1 for a, b in zip(t["tick"], t["tick"][1:])))

    # ---- decimation ----
    t = capture(c, T, ["count"], 150, 3, MANUAL, decim=7)
    report("every 7th cycle: cycle numbers 7 apart, count = cycle + 1",
           consecutive(t["cycle"], 7) and all(t["count"][i] == n_of(t, i) for i in range(150)),
           f"cycles {t['cycle'][:3]}")
    st = status(c)
    report("the capture's status: samples, pre, decimation, channels",
           (u32(st, 12), u32(st, 14), st[16], st[17]) == (150, 3, 7, 1), str(st[10:18]))

    # ---- repeated captures ----
    tv = lookup(c, "toggle")
    assert cmd(c, T, CHANNELS, a32(lookup(c, "count"))) == 0
    assert cmd(c, T, SETUP, setup_args(20, 4, RISE, tv, repeat=1)) == 0
    assert cmd(c, T, ARM) == 0
    trig_n = []
    for k in range(3):
        s0 = wait_for(lambda: (lambda s: s if s[3] else None)(status(c)), 20, 0.01)
        vals = series(c, 0, 20, 2)
        trig_n.append(vals[4])
        cmd(c, T, NEXT)
        wait_for(lambda: not status(c)[3] or u32(status(c), 10) != u32(s0, 10), 20, 0.005)
    cmd(c, T, STOP)
    report("repeat: each capture triggered at a rise (n MOD 100 = 50), 100 cycles apart or a multiple",
           all(n % 100 == 50 for n in trig_n) and all((b - a) % 100 == 0 and b > a for a, b in zip(trig_n, trig_n[1:])),
           f"trigger counts {trig_n}")
    wait_for(lambda: status(c)[2] == 0, 20)

    # ---- bad requests: exceptions, nothing changed ----
    cnt = lookup(c, "count")
    bad = [
        ("unknown command", cmd(c, T, 99), 1),
        ("a channel index beyond the table", cmd(c, T, CHANNELS, a32(100000)), 2),
        ("33 channels", cmd(c, T, CHANNELS, a32(cnt) * 33), 3),
        ("pre-trigger not below the samples", cmd(c, T, SETUP, setup_args(100, 100)), 3),
        ("more samples than the buffer", cmd(c, T, SETUP, setup_args(u32(status(c), 6) + 1, 0)), 3),
        ("decimation 0", cmd(c, T, SETUP, setup_args(100, 0, decim=0)), 3),
        ("rise of a DINT", cmd(c, T, SETUP, setup_args(100, 0, RISE, cnt)), 3),
        ("trigger kind 9", cmd(c, T, SETUP, setup_args(100, 0, 9, cnt)), 3),
        ("writing the status registers", exc_of(c.write_register(BASE + 2, 1, slave=1)), 2),
        ("a read across the block's start", exc_of(c.read_holding_registers(BASE - 1, 3, slave=1)), 2),
        ("a read in the gap after the status", exc_of(c.read_holding_registers(BASE + 40, 2, slave=1)), 2),
        ("an unknown path", exc_of(c.write_registers(CMD, [0, LOOKUP] + text("no.such.var"), slave=1)), 2),
        ("a tail several paths end with (axis.posit, axis2.posit)",
         exc_of(c.write_registers(CMD, [0, LOOKUP] + text("posit"), slave=1)), 3),
        ("a window on channel 5 of a 1-channel capture",
         exc_of(c.readwrite_registers(read_address=WIN, read_count=2, write_address=SEL, values=[5, 0, 0], slave=1)), 2),
        ("a command of one register", exc_of(c.write_register(CMD, T, slave=1)), 3),
    ]
    for name, got, want in bad:
        report(f"bad request: {name}: exception {want}", got == want, f"got {got}")
    report("FC 16 into the trace block and beyond it in one request: exception 02",
           exc_of(c.write_registers(SEL + 1, [0] * 4, slave=1)) == 2)

    # ---- a second client cannot corrupt a running trace ----
    assert cmd(c, T, CHANNELS, a32(cnt) + a32(lookup(c, "pair_a"))) == 0
    assert cmd(c, T, SETUP, setup_args(1500, 100, MANUAL)) == 0
    before = u32(status(c), 8)
    assert cmd(c, T, ARM) == 0
    b = client()
    other = [cmd(b, 0x4321, CLAIM), cmd(b, 0x4321, STOP), cmd(b, 0x4321, CHANNELS, a32(cnt)),
             cmd(b, 0x4321, SETUP, setup_args(10, 0)), cmd(b, 0x4321, ARM), cmd(b, 0x4321, RELEASE),
             cmd(b, 0, STOP), cmd(b, T + 1, TRIGGER)]
    report("a second client's claim, stop, channels, setup, arm, release, trigger: exception 06 each",
           other == [6] * 8, str(other))
    report("the owner's own setup change while armed: exception 06 (frozen)", cmd(c, T, SETUP, setup_args(10, 0)) == 6)
    assert cmd(c, T, TRIGGER) == 0
    st = wait_for(lambda: (lambda s: s if s[3] and u32(s, 10) > before else None)(status(c)), 30, 0.02)
    cyc = series(c, 0x100, 1500, 2)
    pa = [signed(v, 32) for v in series(c, 1, 1500, 2)]
    report("the owner's capture is whole: 1500 samples, 2 channels, consecutive, pair_a = 3n",
           st and u32(st, 12) == 1500 and st[17] == 2 and consecutive(cyc)
           and all(pa[i] == 3 * (cyc[i] + 1) for i in range(1500)))
    report("released, the trace can be claimed by another client",
           cmd(c, T, RELEASE) == 0 and cmd(b, 0x4321, CLAIM) == 0 and cmd(b, 0x4321, RELEASE) == 0)

    # ---- forcing: inputs, outputs, internals ----
    def hreg(a):
        r = c.read_holding_registers(a, 1, slave=1)
        return None if r.isError() else signed(r.registers[0], 16)

    def force(path, value):
        return cmd(c, 0, FORCE, a32(lookup(c, path)) + [(value >> s) & 0xFFFF for s in (48, 32, 16, 0)])

    def diag_forced():
        r = c.read_input_registers(1024 + 48, 2, slave=1).registers
        return u32(r)

    report("program values before forcing: scaled = 10 gain = 20, out_w = in_w + 1 = 1",
           wait_for(lambda: hreg(9000) == 20 and hreg(0) == 1, 20), f"scaled {hreg(9000)} out_w {hreg(0)}")
    report("force an input: in_w = 7 -> the program sees it: echo 7, out_w 8",
           force("in_w", 7) == 0 and wait_for(lambda: hreg(9001) == 7 and hreg(0) == 8, 20),
           f"echo {hreg(9001)} out_w {hreg(0)}")
    report("force an internal read by the program: gain = 5 -> scaled = 50",
           force("gain", 5) == 0 and wait_for(lambda: hreg(9000) == 50, 20), f"scaled {hreg(9000)}")
    c.write_register(9002, 4, slave=1)
    # two cycles after the write (counted, not slept for: a loaded host may
    # run none in 50 ms, and the check could not fail) the write had its chance
    n0 = u32(c.read_input_registers(1024, 2, slave=1).registers)
    wait_for(lambda: u32(c.read_input_registers(1024, 2, slave=1).registers) >= n0 + 2, 20)
    report("a Modbus write to a forced variable does not win over the force: scaled stays 50",
           all(hreg(9000) == 50 for _ in range(10)), f"scaled {hreg(9000)}")
    report("force an internal the program writes every cycle: scaled = -3 holds",
           force("scaled", (-3) & 0xFFFF) == 0 and wait_for(lambda: hreg(9000) == -3, 20)
           and all(hreg(9000) == -3 for _ in range(20)), f"scaled {hreg(9000)}")
    report("force an output the program writes every cycle: out_w = 1234 on %QW0",
           force("out_w", 1234) == 0 and wait_for(lambda: hreg(0) == 1234, 20)
           and all(hreg(0) == 1234 for _ in range(20)), f"out_w {hreg(0)}")
    report("the diagnostics count 4 forced variables (input register 1072)", diag_forced() == 4, str(diag_forced()))
    report("the status line says FORCED and marks the forced status variable",
           wait_for(lambda: "FORCED 4" in plc.output() and "GAIN 5 (forced)" in plc.output(), 20))
    listed = subprocess.run([PLCTRACE, "--port", str(PORT), "forced"], capture_output=True, text=True)
    report("plctrace forced lists them with their values",
           all(x in listed.stdout for x in (f"{P}IN_W = 7 (input)", f"{P}GAIN = 5", f"{P}SCALED = -3",
                                            f"{P}OUT_W = 1234 (output)")), listed.stdout + listed.stderr)
    r = subprocess.run([PLCTRACE, "--port", str(PORT), "unforce", "gain"], capture_output=True, text=True)
    report("plctrace unforce gain, then scaled: gain keeps 5 until written, scaled follows the program: 50",
           r.returncode == 0 and cmd(c, 0, UNFORCE, a32(lookup(c, "scaled"))) == 0
           and wait_for(lambda: hreg(9000) == 50, 20), f"scaled {hreg(9000)}")
    c.write_register(9002, 2, slave=1)
    report("released, gain takes a Modbus write again: 2 -> scaled 20", wait_for(lambda: hreg(9000) == 20, 20),
           f"scaled {hreg(9000)}")
    r = subprocess.run([PLCTRACE, "--port", str(PORT), "force", "gain", "3"], capture_output=True, text=True)
    report("plctrace force gain 3 -> scaled 30", r.returncode == 0 and wait_for(lambda: hreg(9000) == 30, 20),
           r.stderr)
    r = subprocess.run([PLCTRACE, "--port", str(PORT), "unforce", "--all"], capture_output=True, text=True)
    # separate reads, polled until the relations hold: in_w and gain are
    # static once released (nothing writes them), so out_w and scaled are too
    report("plctrace unforce --all: one command clears every force, the program's values return",
           r.returncode == 0 and wait_for(lambda: diag_forced() == 0 and hreg(0) == hreg(9001) + 1
                                          and hreg(9000) == 10 * hreg(9002), 20),
           f"out_w {hreg(0)} echo {hreg(9001)} scaled {hreg(9000)} gain {hreg(9002)}")
    report("forcing a variable beyond the table: exception 02; a FORCE of 3 registers: 03",
           cmd(c, 0, FORCE, a32(100000) + [0] * 4) == 2 and cmd(c, 0, FORCE, a32(0) + [0]) == 3)

    # ---- careless values: refused, saying why and what fits, nothing forced ----
    def pt(*args):
        return subprocess.run([PLCTRACE, "--port", str(PORT)] + list(args), capture_output=True, text=True,
                              timeout=60)

    for path, value, want in (("saw", "nan", "'nan' is not a finite number"),
                              ("saw", "1e40", "'1e40' does not fit a REAL"),
                              ("gain", "1.5", "'1.5' is not an integer (INT: -32768..32767"),
                              ("gain", "70000", "'70000' does not fit an INT (-32768..32767)")):
        r = pt("force", path, value)
        report(f"plctrace force {path} {value}: refused with a message, no traceback",
               r.returncode == 1 and want in r.stderr and "Traceback" not in r.stderr, r.stderr[-300:])
    # the same through the register block: a REAL nan, a BOOL of 2
    report("FORCE of a REAL nan or a BOOL of 2 through the block: exception 03, nothing forced",
           cmd(c, 0, FORCE, a32(lookup(c, "saw")) + [0, 0, 0x7FC0, 0]) == 3
           and cmd(c, 0, FORCE, a32(lookup(c, "toggle")) + [0, 0, 0, 2]) == 3 and diag_forced() == 0,
           f"forced {diag_forced()}")
    r = pt("force", "gain", "010")
    report("plctrace force gain 010: ten, as everywhere in plcrt (not octal 8): scaled 100",
           r.returncode == 0 and wait_for(lambda: hreg(9000) == 100, 20), f"{r.stderr} scaled {hreg(9000)}")
    pt("unforce", "--all")
    # the forcing table full (64): plctrace said "busy: another client owns
    # the trace"; now it says how many are forced and what to do
    full = [cmd(c, 0, FORCE, a32(lookup(c, f"spare[{k}]")) + [0, 0, 0, k]) for k in range(1, 65)]
    r = pt("force", "gain", "3")
    report("plctrace force with 64 variables forced: says the table is full and how to release one",
           full == [0] * 64 and r.returncode == 1 and "64 variables are forced, the most plcrt forces at once" in r.stderr
           and "plctrace unforce PATH" in r.stderr, f"{full.count(0)} forced; {r.stderr[-300:]}")
    pt("unforce", "--all")
    missing = os.path.join(WORK, "no-such-folder", "rec.csv")
    r = pt("record", "--chan", "count", "--samples", "100", "--no-plot", "-o", missing)
    report("plctrace record -o into a missing folder: refused before the capture (not lost after it)",
           r.returncode == 1 and "no folder" in r.stderr and "Traceback" not in r.stderr and status(c)[4] == 0,
           r.stderr[-300:])
    r = pt("record", "--chan", "count", "--trigger", "count:rise", "--no-plot", "-o", os.path.join(WORK, "x.csv"))
    report("plctrace record --trigger count:rise (a DINT): says rise takes a BOOL and what to use instead",
           r.returncode == 1 and "rise and fall take a BOOL" in r.stderr and "count:up:LEVEL" in r.stderr,
           r.stderr[-300:])
    r = pt("record", "--chan", "count", "--samples", "999999999", "--no-plot", "-o", os.path.join(WORK, "x.csv"))
    report("plctrace record --samples beyond the buffer: names the limit and the key that sets it",
           r.returncode == 1 and f"at most {status(c)[6] << 16 | status(c)[7]} samples" in r.stderr
           and "[trace] samples" in r.stderr, r.stderr[-300:])

    # ---- plctrace record: CSV with the expected columns, and a PNG ----
    csvp = os.path.join(WORK, "rec.csv")
    for f in (csvp, csvp[:-4] + ".png"):
        if os.path.exists(f):
            os.unlink(f)
    r = subprocess.run([PLCTRACE, "--port", str(PORT), "record", "--chan", "count", "--chan", "toggle",
                        "--trigger", "toggle:rise", "--pre", "10", "--samples", "200", "-o", csvp],
                       capture_output=True, text=True, timeout=60)
    rows = list(csv.reader(open(csvp))) if os.path.exists(csvp) else [[]]
    report("plctrace record writes CSV: time_ms, cycle, one column per channel",
           r.returncode == 0 and rows[0] == ["time_ms", "cycle", f"{P}COUNT", f"{P}TOGGLE"], r.stderr + str(rows[0]))
    if len(rows) == 201:
        d = rows[1:]
        # one sample a cycle: consecutive cycle numbers; PLC time 1 ms apart,
        # or a whole number of periods where the machine made plcrt skip one
        steps = [float(d[i + 1][0]) - float(d[i][0]) for i in range(199)]
        report("its rows: 200 samples of consecutive cycles, time 0 ms at the trigger (sample 10, a rise), "
               "1 ms apart (whole periods across a skipped one)",
               float(d[10][0]) == 0 and d[10][3] == "1" and d[9][3] == "0"
               and all(int(d[i + 1][1]) == int(d[i][1]) + 1 for i in range(199))
               and all(st >= 1 - 1e-9 and abs(st - round(st)) < 1e-9 for st in steps)
               and all(int(x[2]) == int(x[1]) + 1 for x in d),
               f"{str(d[8:12])}; steps other than 1 ms: {[s for s in steps if abs(s - 1) > 1e-9][:5]}")
    else:
        report("its rows: 200 samples", False, f"{len(rows) - 1} rows")
    png = csvp[:-4] + ".png"
    report("and a PNG plot", os.path.exists(png) and open(png, "rb").read(8) == b"\x89PNG\r\n\x1a\n")

    # ---- restart: nothing forced; forcing refused when not allowed ----
    force("gain", 9)
    plc.stop()
    c.close()
    b.close()
    plc = Plcrt(PLCRT, ini(True), WORK, "trace")
    c = client()
    report("after a restart nothing is forced: count 0, gain its initial 2, scaled = 20",
           diag_forced() == 0 and wait_for(lambda: hreg(9000) == 20, 20) and status(c)[23] == 0)
    plc.stop()
    c.close()
    plc = Plcrt(PLCRT, ini(False), WORK, "trace")
    c = client()
    report("[debug] allow_force = no: force, unforce, unforce all refused with exception 01",
           (force("gain", 9), cmd(c, 0, UNFORCE, a32(lookup(c, "gain"))), cmd(c, 0, UNFORCE_ALL)) == (1, 1, 1)
           and wait_for(lambda: hreg(9000) == 20, 20) and status(c)[22] == 0)
    r = subprocess.run([PLCTRACE, "--port", str(PORT), "force", "gain", "9"], capture_output=True, text=True)
    report("plctrace force says so and fails", r.returncode == 1 and "allow_force" in r.stderr, r.stderr)
    report("no capture after a restart: a window on samples is exception 02",
           exc_of(c.readwrite_registers(read_address=WIN, read_count=2, write_address=SEL, values=[0, 0, 0], slave=1)) == 2)
    plc.stop()
    c.close()
    # a symbol map reaching into the block is refused at the start
    bad = ini(False, f"{P}COUNT = holding 59999\n")
    r = subprocess.run([PLCRT, "-c", bad, "--check-config"], capture_output=True, text=True)
    report("a symbol overlapping the trace block: refused, status 2",
           r.returncode == 2 and "trace block" in r.stderr, r.stderr)
    plc = None
finally:
    if plc:
        plc.stop()
    Plcrt.kill_all()
sys.exit(0 if report.all_passed() else 1)
