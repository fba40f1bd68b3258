#!/usr/bin/env python3
"""aposs_tune: the "ten steps for optimum control" of seed 001, automated, on
a running plcrt with an APOSSAXIS (st/devices/apossaxis.st) whose parameters,
commands and outputs are on Modbus symbols (examples/aposs/aposs.ini shows
the map).  Each test run is a POSA recorded cycle by cycle with the trace
(plc_runtime/plctrace, docs/trace.md); the steps:

  2  POSERR set very high (the test value, default 1000000)
  3  KPROP = KDER = KINT = FFACC = 0, FFVEL from 100 up (or down) until the
     actual speed's plateau equals the commanded one
  4  FFACC from 10 until the speed ramps coincide
  5  KPROP raised until the axis oscillates at standstill after the move,
     then set to 70 % of that value
  6  KDER from 200 raised by half while the oscillation (the peak following
     error of the move plus the oscillation at standstill, the median of
     --repeat runs) falls; the search stops where it grows by a quarter and half a count, and
     keeps the value that is best together with its neighbours on the
     ladder (if 200 is already worse than none, the same search downwards:
     100, 50, ...)
  7  KINT only if a static following error remains
  9  BANDWIDTH lowered to twice what the PID needs in the test move (more
     if the move then follows worse than unclamped)
 10  POSERR back to its value before tuning

Test moves go back and forth between two positions inside the software
limits (POSLIMIT / NEGLIMIT when active, else --travel around the start),
at VEL --vel and ACC --acc; the motor is switched off and on before each
run so that a run starts from the axis's position, whatever the previous one
left.  The gains found are printed and left in the axis (written to its
parameters); each run's capture is kept as aposs-tune-runN.csv, and PNG
plots of a run before and after tuning are written, all in --out.

  tools/aposs_tune.py [--host H] [--port P] [--out DIR] [--dist QC] [--vel %] [--acc %]

Exit status: 0 tuned, 1 a run failed (an error on the axis, no capture)."""
import argparse
import csv
import importlib.machinery
import importlib.util
import math
import os
import statistics
import struct
import sys
import threading
import time

from pymodbus.client import ModbusTcpClient

HERE = os.path.dirname(os.path.abspath(__file__))
_spec = importlib.util.spec_from_loader(
    "plctrace", importlib.machinery.SourceFileLoader(
        "plctrace", os.path.join(HERE, "..", "plc_runtime", "plctrace")))
plctrace = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(plctrace)

# the symbol map of examples/aposs/aposs.ini
PARAMS = ("KPROP KDER KINT FFVEL FFACC BANDWIDTH POSERR KILIM POS VEL ACC DEC POSLIMIT NEGLIMIT "
          "SWPOSLIMACT SWNEGLIMACT VELMAX ENCODER RAMPMIN TESTWIN TESTTIM TESTVAL RAMPTYPE JERKMIN "
          "ERRCOND HOME_TYPE HOME_VEL HOME_RAMP HOME_OFFSET HOME_FORCE").split()
HOLD = {p: 8192 + 2 * i for i, p in enumerate(PARAMS)}
COILS = {c: 8192 + i for i, c in enumerate("MOTOROFF MOTORON ERRCLR STOP HOME POSA POSR CVEL".split())}
INPUTS = {"APOS": (1152, "i"), "ERRNUM": (1154, "h"), "MODE": (1155, "h")}
DISCRETE = {d: 8192 + i for i, d in enumerate("MOTOR BUSY INPOS HOMED ERROR".split())}
INST = "CONFIG0.RES0.INST0"
CHANS = [INST + ".COUNTER", INST + ".AX.CPOS", INST + ".AX.CVELQ", INST + ".AX.CACCQ",
         INST + ".AX.FE", INST + ".AX.CTL.PIDPART", INST + ".AX.BUSY"]


class Axis:
    """The axis's symbols over one pymodbus connection."""

    def __init__(self, host, port):
        self.host, self.port = host, port
        self.c = ModbusTcpClient(host, port=port, timeout=3)
        if not self.c.connect():
            raise SystemExit(f"aposs_tune: cannot connect to {host}:{port}")

    def _ok(self, r, what):
        if r.isError():
            raise SystemExit(f"aposs_tune: {what}: {r}")
        return r

    def get(self, name):
        r = self._ok(self.c.read_holding_registers(HOLD[name], 2, slave=1), name).registers
        return struct.unpack(">i", struct.pack(">HH", *r))[0]

    def set(self, name, value):
        hi, lo = struct.unpack(">HH", struct.pack(">i", int(value)))
        self._ok(self.c.write_registers(HOLD[name], [hi, lo], slave=1), name)

    def out(self, name):
        addr, fmt = INPUTS[name]
        n = 2 if fmt == "i" else 1
        r = self._ok(self.c.read_input_registers(addr, n, slave=1), name).registers
        return struct.unpack(">" + fmt, struct.pack(f">{n}H", *r))[0]

    def flag(self, name):
        return self._ok(self.c.read_discrete_inputs(DISCRETE[name], 1, slave=1), name).bits[0]

    def pulse(self, cmd):
        """A command: coil on for a few cycles, then off (the block acts on the edge)."""
        self._ok(self.c.write_coil(COILS[cmd], True, slave=1), cmd)
        time.sleep(0.01)
        self._ok(self.c.write_coil(COILS[cmd], False, slave=1), cmd)
        time.sleep(0.01)

    def close(self):
        self.c.close()


def record_move(axis, target, samples, csvpath):
    """A test move recorded by plctrace's own record (in a thread, triggered
    by the POSA edge): once the trace is armed, command the move; return the
    columns of the capture by the variables' last names, T in s."""
    a = argparse.Namespace(host=axis.host, port=axis.port, chan=CHANS, trigger=INST + ".AX.POSA:rise",
                           pre=20, samples=samples, every=1, timeout=10, output=csvpath, png=None,
                           no_plot=True, rows=None, title=None)
    out = {}

    def rec():
        try:
            plctrace.record(a)
        except BaseException as e:      # reported by the caller
            out["error"] = e

    th = threading.Thread(target=rec)
    th.start()
    watch = plctrace.Plc(axis.host, axis.port)
    try:
        t0 = time.monotonic()
        while watch.status()["state"] != 1 and th.is_alive() and time.monotonic() - t0 < 5:
            time.sleep(0.005)
    finally:
        watch.close()
    time.sleep(0.05)    # the trigger is looked for once the pre-trigger samples (20 ms) are in
    axis.set("POS", target)
    axis.pulse("POSA")
    th.join()
    if "error" in out:
        raise SystemExit(f"aposs_tune: trace: {out['error']}")
    with open(csvpath) as f:
        rows = list(csv.reader(f))
    cols = {}
    for k, name in enumerate(rows[0]):
        cols[name.split(".")[-1].upper()] = [float(r[k]) for r in rows[1:]]
    cols["T"] = [x / 1000.0 for x in cols["TIME_MS"]]
    return cols


class Tuner:
    def __init__(self, axis, a):
        self.ax, self.a = axis, a
        self.runs = 0
        os.makedirs(a.out, exist_ok=True)
        pl, nl = axis.get("POSLIMIT"), axis.get("NEGLIMIT")
        pa, na = axis.get("SWPOSLIMACT"), axis.get("SWNEGLIMACT")
        p0 = axis.out("APOS")
        hi = pl - a.margin if pa else p0 + a.dist
        lo = nl + a.margin if na else p0 - a.dist
        # the two ends of the test move, inside the travel
        if hi - lo < a.dist:
            raise SystemExit(f"aposs_tune: the travel {lo}..{hi} is shorter than the test move {a.dist} qc")
        self.lo = max(lo, min(p0, hi - a.dist))
        self.hi = self.lo + a.dist
        self.vmx = axis.get("VELMAX") * axis.get("ENCODER") * 4.0 / 60.0

    def run(self, **gains):
        """One test move with the given parameters (others as they are)."""
        for k, v in gains.items():
            self.ax.set(k, v)
        self.ax.pulse("MOTOROFF")
        self.ax.pulse("MOTORON")
        if self.ax.flag("ERROR"):
            raise SystemExit(f"aposs_tune: the axis has error {self.ax.out('ERRNUM')}")
        for attempt in range(self.a.retries + 1):
            p = self.ax.out("APOS")
            target = self.hi if abs(p - self.lo) < abs(p - self.hi) else self.lo
            c = record_move(self.ax, target, self.a.samples,
                            os.path.join(self.a.out, f"aposs-tune-run{self.runs + 1}.csv"))
            self.runs += 1
            if self.ax.flag("ERROR"):
                raise SystemExit(f"aposs_tune: error {self.ax.out('ERRNUM')} in a test run with {gains}")
            # a scan that came late (another program took the CPU) moves the
            # plant on by more than one cycle: the run says nothing of the
            # gains and is made again
            t = c["T"]
            cyc = sorted(t[i + 1] - t[i] for i in range(len(t) - 1))[len(t) // 2]
            gap = max(t[i + 1] - t[i] for i in range(len(t) - 1))
            if gap <= 1.5 * cyc:
                break
            self.log(f"run {self.runs}: a scan {1000 * gap:.1f} ms after the one before (cycle "
                     f"{1000 * cyc:.1f} ms): disturbed, made again")
            self.ax.pulse("MOTOROFF")
            self.ax.pulse("MOTORON")
        return c

    # ---- measures on a run ----
    @staticmethod
    def vact(c):
        """actual speed, qc/s, from the counter, per sample"""
        t, x = c["T"], c["COUNTER"]
        return [0.0] + [(x[i] - x[i - 1]) / (t[i] - t[i - 1]) for i in range(1, len(x))]

    @staticmethod
    def plateau(c, settle=0.03):
        """commanded and actual speed on the constant-speed part (after settle s)"""
        v = c["CVELQ"]
        vm = max(v, key=abs)
        idx = [i for i, x in enumerate(v) if abs(x - vm) <= 1e-9 * abs(vm)]
        t0 = c["T"][idx[0]] + settle
        idx = [i for i in idx if c["T"][i] >= t0]
        if len(idx) < 20:
            raise SystemExit("aposs_tune: no constant speed in the test move: lengthen --dist")
        i0, i1 = idx[0], idx[-1]
        va = (c["COUNTER"][i1] - c["COUNTER"][i0]) / (c["T"][i1] - c["T"][i0])
        return vm, va

    def ramp_error(self, c):
        """mean of (commanded - actual) speed while speeding up, relative to the peak"""
        va = self.vact(c)
        v, acc = c["CVELQ"], c["CACCQ"]
        vm = max(v, key=abs)
        sel = [i for i in range(len(v)) if acc[i] * vm > 0 and abs(v[i]) < abs(vm)]
        # the counter's speed is the mean over the sample: compare it with the set-point's mean
        e = [(v[i] + v[i - 1]) / 2 - va[i] for i in sel if i > 0]
        return math.copysign(1, vm) * sum(e) / max(len(e), 1) / abs(vm)

    @staticmethod
    def end_index(c):
        busy = c["BUSY"]
        for i in range(len(busy) - 1, 0, -1):
            if busy[i - 1] and not busy[i]:
                return i
        return len(busy) - 1

    def standstill(self, c, t_from=0.1, t_to=0.4):
        """following error after the set-point stopped: (mean, std) over t_from..t_to s"""
        i = self.end_index(c)
        te = c["T"][i]
        fe = [c["FE"][k] for k in range(i, len(c["T"])) if te + t_from <= c["T"][k] <= te + t_to]
        if not fe:
            raise SystemExit("aposs_tune: the capture ends too early after the move: raise --samples")
        m = sum(fe) / len(fe)
        return m, math.sqrt(sum((x - m) ** 2 for x in fe) / len(fe))

    @staticmethod
    def fe_peak(c):
        return max(abs(x) for x in c["FE"])

    @staticmethod
    def fe_rms(c):
        fe = c["FE"]
        return math.sqrt(sum(x * x for x in fe) / len(fe))

    # ---- the steps ----
    def tune(self):
        ax, a, log = self.ax, self.a, self.log
        orig = {k: ax.get(k) for k in ("KPROP", "KDER", "KINT", "FFVEL", "FFACC", "BANDWIDTH", "POSERR", "KILIM")}
        ax.set("VEL", a.vel)
        ax.set("ACC", a.acc)
        ax.set("DEC", 0)
        ax.pulse("ERRCLR")
        ax.set("POSERR", a.poserr)                                       # step 2
        self.before = self.run()
        log(f"before: KPROP {orig['KPROP']} KDER {orig['KDER']} KINT {orig['KINT']} FFVEL {orig['FFVEL']} "
            f"FFACC {orig['FFACC']}: following error RMS {self.fe_rms(self.before):.1f} qc")

        ffvel = 100                                                     # step 3
        for _ in range(6):
            c = self.run(KPROP=0, KDER=0, KINT=0, FFACC=0, FFVEL=ffvel, BANDWIDTH=1000)
            vc, va = self.plateau(c)
            log(f"FFVEL {ffvel}: plateau commanded {vc:.0f} qc/s, actual {va:.0f} qc/s")
            new = max(1, min(100000, round(ffvel * vc / va)))
            if new == ffvel:
                break
            ffvel = new
        self.ffvel = ffvel

        ffacc, prev = 10, None                                          # step 4
        for _ in range(6):
            c = self.run(FFACC=ffacc)
            e = self.ramp_error(c)
            log(f"FFACC {ffacc}: actual speed behind the ramp by {100 * e:.2f} % of the peak on average")
            if abs(e) < 0.002:
                break
            if prev is None or prev[1] == e:
                new = ffacc * 2 if e > 0 else ffacc // 2
            else:   # linear in FFACC: the secant
                new = ffacc - e * (ffacc - prev[0]) / (e - prev[1])
            new = max(0, min(100000, round(new)))
            if new == ffacc:
                break
            prev, ffacc = (ffacc, e), new
        self.ffacc = ffacc

        def oscillates(kp):                                             # step 5
            c = self.run(KPROP=kp, KDER=0, KINT=0)
            m, s = self.standstill(c)
            log(f"KPROP {kp}: at standstill following error {m:+.1f} qc, oscillating {s:.1f} qc RMS")
            return s > a.osc
        kp, stable = 10, 0
        while kp <= 65000 and not oscillates(kp):
            stable, kp = kp, kp * 2
        bad = min(kp, 65000)
        while bad - stable > max(2, 0.08 * bad):
            mid = (bad + stable) // 2
            if oscillates(mid):
                bad = mid
            else:
                stable = mid
        self.kosc = bad
        self.kprop = max(1, round(0.7 * bad))
        log(f"KPROP: mild oscillation from {bad}: 70 % = {self.kprop}")

        def oscillation(**gains):                                       # step 6
            # the oscillation of a run: the peak following error over the
            # move plus the oscillation left at standstill; the median of
            # --repeat runs (there and back), as one count of the encoder is
            # as large as the following error of a well tuned move, and a
            # scan a few tenths of a ms late (the plant moved on meanwhile)
            # adds tens of counts to one run at full speed
            ms = []
            for _ in range(a.repeat):
                c = self.run(**gains)
                ms.append(self.fe_peak(c) + self.standstill(c)[1])
                gains = {}
            return statistics.median(ms)
        bestm = oscillation(KPROP=self.kprop, KDER=0, KINT=0)
        log(f"KDER 0: peak following error + standstill oscillation {bestm:.2f} qc")
        tried = {0: bestm}
        kd, up = 200, True
        while 1 <= kd <= 65000 and len(tried) < 12:
            m = tried[kd] = oscillation(KDER=kd)
            log(f"KDER {kd}: peak following error + standstill oscillation {m:.2f} qc")
            if up and kd == 200 and m > tried[0]:
                # already worse at the seed's 200 (its scale is the machine's):
                # the same search downwards
                up, kd = False, 100
                continue
            # the oscillations begin to increase: clearly worse than the best,
            # by more than the encoder's rounding
            if m > 1.25 * min(tried.values()) + 0.5:
                break
            kd = round(kd * 1.5) if up else kd // 2
        # a run's peak moves by a count with where the encoder's edges fall:
        # the value kept is the middle of the best stretch, each value judged
        # with its neighbours on the ladder
        ks = sorted(tried)
        smooth = {k: sum(tried[j] for j in ks[max(0, i - 1):i + 2]) / len(ks[max(0, i - 1):i + 2])
                  for i, k in enumerate(ks)}
        self.kder = min(smooth, key=smooth.get)
        log(f"KDER {self.kder}: the least oscillation with its neighbours of {ks}")
        ax.set("KDER", self.kder)

        c = self.run()                                                  # step 7
        m, s = self.standstill(c)
        self.kint = 0
        if abs(m) > 1.0:
            self.kint = 1
            log(f"static following error {m:+.1f} qc: KINT 1")
        else:
            log(f"static following error {m:+.2f} qc: no KINT")
        ax.set("KINT", self.kint)

        c = self.run(BANDWIDTH=1000)                                    # step 9
        peak = max(abs(x) for x in c["PIDPART"])
        ref = oscillation()
        bw = max(1, min(1000, math.ceil(2 * 1000 * peak / 32767)))
        log(f"PID part at most {peak:.0f} DAC bits: BANDWIDTH {bw} to try")
        while bw < 1000:
            # the clamp must not cost accuracy: the move as good as unclamped
            m = oscillation(BANDWIDTH=bw)
            log(f"BANDWIDTH {bw}: peak following error + standstill oscillation {m:.2f} qc (unclamped {ref:.2f})")
            if m <= 1.1 * ref:
                break
            bw = min(1000, bw * 2)
        self.bandwidth = bw
        ax.set("BANDWIDTH", bw)

        ax.set("POSERR", orig["POSERR"])                                # step 10
        self.after = self.run()
        log(f"after: following error RMS {self.fe_rms(self.after):.2f} qc, POSERR {orig['POSERR']} not tripped")
        return {"FFVEL": self.ffvel, "FFACC": self.ffacc, "KPROP": self.kprop, "KDER": self.kder,
                "KINT": self.kint, "BANDWIDTH": self.bandwidth, "KPROP_OSC": self.kosc, "RUNS": self.runs}

    def log(self, s):
        print(s, flush=True)

    def plot(self, c, path, title):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        t = c["T"]
        va = self.vact(c)
        n = 5   # the counter's speed averaged over 5 samples for the eye
        vs = [sum(va[max(0, i - n + 1):i + 1]) / len(va[max(0, i - n + 1):i + 1]) for i in range(len(va))]
        fig, axs = plt.subplots(2, 1, sharex=True, figsize=(10, 6))
        axs[0].plot(t, c["CVELQ"], label="commanded speed (qc/s)")
        axs[0].plot(t, vs, label="actual speed (qc/s, 5 ms mean)")
        axs[1].plot(t, c["FE"], label="following error (qc)", color="C3")
        for x in axs:
            x.grid(True, alpha=0.3)
            x.legend(loc="best", fontsize="small")
        axs[0].set_title(title)
        axs[1].set_xlabel("PLC time from the POSA (s)")
        fig.tight_layout()
        fig.savefig(path, dpi=90)
        plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--host", default="127.0.0.1")
    ap.add_argument("--port", type=int, default=1502)
    ap.add_argument("--out", default=".", help="folder of the captures and plots (aposs-tune-runN.csv, -before.png, -after.png)")
    ap.add_argument("--dist", type=int, default=50000, help="length of the test move, qc")
    ap.add_argument("--margin", type=int, default=5000, help="distance kept from the software limits, qc")
    ap.add_argument("--vel", type=int, default=100, help="VEL of the test move (1/VELRES of VELMAX)")
    ap.add_argument("--acc", type=int, default=100, help="ACC of the test move (1/VELRES of VELMAX/RAMPMIN)")
    ap.add_argument("--poserr", type=int, default=1000000, help="POSERR while tuning (seed: e.g. 1000000)")
    ap.add_argument("--osc", type=float, default=3.0,
                    help="RMS following error at standstill (qc) that counts as oscillating")
    ap.add_argument("--retries", type=int, default=3,
                    help="times a run disturbed by a late scan is made again")
    ap.add_argument("--repeat", type=int, default=3,
                    help="test runs per KDER and BANDWIDTH value, their median judged")
    ap.add_argument("--samples", type=int, default=1200, help="trace samples per run (1 per cycle)")
    a = ap.parse_args(argv)
    ax = Axis(a.host, a.port)
    try:
        tn = Tuner(ax, a)
        g = tn.tune()
        os.makedirs(a.out, exist_ok=True)
        tn.plot(tn.before, os.path.join(a.out, "aposs-tune-before.png"), "before tuning")
        tn.plot(tn.after, os.path.join(a.out, "aposs-tune-after.png"),
                f"after: FFVEL {g['FFVEL']} FFACC {g['FFACC']} KPROP {g['KPROP']} KDER {g['KDER']} "
                f"KINT {g['KINT']} BANDWIDTH {g['BANDWIDTH']}")
        print("gains: " + " ".join(f"{k} {v}" for k, v in g.items()), flush=True)
    finally:
        ax.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
