#!/usr/bin/env python3
"""aposs_tune: seed 001's "ten steps for optimum control", automated, on a
running plcrt with an APOSSAXIS (st/devices/apossaxis.st) whose parameters,
commands and outputs are on the Modbus symbols of examples/aposs/aposs.ini.
Every test run is the axis's TESTRUN (a POSR framed by motor off) recorded
cycle by cycle with plcrt's trace (docs/trace.md); every measure comes from that record, in the program's
time (one task interval per cycle executed), never from the wall clock, and
every wait is a count of PLC cycles: the same plant gives the same gains
whatever the host's load.  The steps (docs/aposs.md, "Tuning"):

  2  POSERR very high (--poserr, default 1000000)
  3  FFVEL: KPROP = KDER = KINT = FFACC = 0, FFVEL 100; the plateau's actual
     speed over the commanded gives the next FFVEL, until they agree
  4  FFACC: from 10, the speed lost on the ramp (the following error the
     ramp adds, over its peak speed: a lag in ms) brought to 0 by the secant
  5  KPROP: the onset of oscillation at standstill after a move (the
     following error's swing 0.3-0.4 s after the move's end, RMS about its
     mean, above --osc qc: more than the encoder's one-count chatter) bracketed around
     what the plant measured in steps 3-4 predicts, then bisected to 2 %;
     KPROP = 70 % of the onset
  6  KDER: 200, then 1.5 times more per run until the oscillation (RMS of
     the following error about its mean, move and standstill) rises, more
     than 10 % above the lowest so far; of the values before whose
     oscillation is within 10 % of the lowest (a bottom flat to the
     encoder), the middle one is kept
  7  KINT: only if a static following error (above 1 qc) remains
  9  BANDWIDTH: from 1.25 times what the PID used, lowered by 20 % per run
     while the following error (its RMS and its peak) stays within 10 % of
     its best, not below what the PID used
 10  POSERR back; a last run of the standard move (--dist) shows the result

Each step's run is the shortest move that shows what it measures: one that
just reaches VEL for the ramps (step 4) and the oscillation after a move
(step 5), one with 0.1 s at VEL for the constant speed (step 3) and for the
following error all along a move (steps 6-9).  Each run is the axis's own
TESTRUN: motor off, 200 ms at rest, MOTORON, POSR, the hold, motor off, each
in a cycle the block chooses; so a run starts at rest where the last one
left the axis, whenever the tool's writes land, and the tool's measures
depend on the plant alone.  The moves alternate towards the start
position, so the axis stays within the software limits.  Written to --out: aposs-tune-report.txt (every run,
its gains and measures), aposs-tune-stepN.png per step (set-point and
actual position, speed and following error of the step's last run, as the
seed's Tune Oscilloscope shows them), aposs-tune-runN.csv (each capture),
and aposs-gains.txt, the gains found, which --load writes into an axis.

  tools/aposs_tune.py [--host H] [--port P] [--out DIR] [--vel %] [--acc %]
  tools/aposs_tune.py --load aposs-gains.txt [--host H] [--port P]

Exit status: 0 tuned (or loaded), 1 a run failed (an error on the axis, no
capture), 2 bad usage."""
import argparse
import math
import os
import struct
import sys
import time

from pymodbus.client import ModbusTcpClient

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "plc_runtime"))
import importlib.machinery  # noqa: E402
import importlib.util  # noqa: E402

_spec = importlib.util.spec_from_loader(
    "plctrace", importlib.machinery.SourceFileLoader("plctrace", os.path.join(HERE, "..", "plc_runtime", "plctrace")))
plctrace = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(plctrace)

# the symbol map of examples/aposs/aposs.ini
PARAMS = ("KPROP KDER KINT FFVEL FFACC BANDWIDTH POSERR KILIM POS VEL ACC DEC POSLIMIT NEGLIMIT "
          "SWPOSLIMACT SWNEGLIMACT VELMAX ENCODER RAMPMIN TESTWIN TESTTIM TESTVAL RAMPTYPE JERKMIN "
          "ERRCOND HOME_TYPE HOME_VEL HOME_RAMP HOME_OFFSET HOME_FORCE TESTRUN_REST TESTRUN_HOLD").split()
HOLD = {p: 8192 + 2 * i for i, p in enumerate(PARAMS)}
COILS = {c: 8192 + i for i, c in enumerate("MOTOROFF MOTORON ERRCLR STOP HOME POSA POSR CVEL TESTRUN".split())}
INPUTS = {"APOS": (1152, "i"), "ERRNUM": (1154, "h"), "MODE": (1155, "h"), "REFCODE": (1158, "h")}
DISCRETE = {d: 8192 + i for i, d in enumerate("MOTOR BUSY INPOS HOMED ERROR LIMPOS LIMNEG BRAKE TESTING".split())}
REST_MS = 200              # a test run's rest, motor off, before its MOTORON: the drive's lag died out
CYCLES_REG = 1024           # plcrt's diagnostics: cycles executed (docs/modbus.md)
GAINS = ("FFVEL", "FFACC", "KPROP", "KDER", "KINT", "BANDWIDTH")
# trace channels, below the instance path (--instance)
CHANS = ("AP", "CPOS", "CVELQ", "CACCQ", "FE", "CTL.PIDPART", "BUSY")


class Axis:
    """The axis's symbols over one pymodbus connection; commands and waits
    counted in PLC cycles (plcrt's cycle counter), never in seconds."""

    def __init__(self, host, port):
        self.host, self.port = host, port
        self.c = ModbusTcpClient(host, port=port, timeout=5)
        if not self.c.connect():
            raise SystemExit(f"aposs_tune: cannot connect to {host}:{port} (is plcrt running?)")

    def _ok(self, r, what):
        if r.isError():
            raise SystemExit(f"aposs_tune: {what}: {r} (is the symbol map of examples/aposs/aposs.ini "
                             "in the configuration?)")
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

    def cycles(self):
        r = self._ok(self.c.read_input_registers(CYCLES_REG, 2, slave=1), "cycle counter").registers
        return r[0] << 16 | r[1]

    def wait_cycles(self, n, limit_s=60):
        """Until n more PLC cycles have run (the wall-clock limit only
        catches a stopped plcrt)."""
        c0, t0 = self.cycles(), time.monotonic()
        while (self.cycles() - c0) & 0xFFFFFFFF < n:
            if time.monotonic() - t0 > limit_s:
                raise SystemExit(f"aposs_tune: plcrt ran fewer than {n} cycles in {limit_s} s")
            time.sleep(0.002)

    def pulse(self, cmd):
        """A command: the coil on until the scan has seen it, then off (the
        block acts on the rising edge; on and off landing in one cycle would
        be no edge at all)."""
        self._ok(self.c.write_coil(COILS[cmd], True, slave=1), cmd)
        self.wait_cycles(3)
        self._ok(self.c.write_coil(COILS[cmd], False, slave=1), cmd)
        self.wait_cycles(3)

    def close(self):
        self.c.close()


class Tuner:
    def __init__(self, axis, a):
        self.ax, self.a = axis, a
        self.runs, self.lines, self.steps = 0, [], {}
        os.makedirs(a.out, exist_ok=True)
        self.tr = plctrace.Plc(a.host, a.port)
        st = self.tr.status()
        self.period = st["period_ns"] * 1e-9
        self.cap = st["cap"]
        self.chans = [self.tr.lookup(f"{a.instance}.{c}") for c in CHANS]
        self.trig = self.tr.lookup(f"{a.instance}.TESTMOVE")[0]
        self.p0 = axis.out("APOS")
        vmx = axis.get("VELMAX") * axis.get("ENCODER") * 4 / 60.0
        self.v = vmx * a.vel / 100.0                        # qc/s, VELRES 100
        self.acc = vmx / (axis.get("RAMPMIN") / 1000.0) * a.acc / 100.0
        self.cyc0 = axis.cycles()
        self.plc_s = 0.0
        self.sign = 1

    # ---- one test run ----
    def capture(self, dist, post_s):
        """One TESTRUN by dist qc (the axis: motor off, REST ms at rest,
        MOTORON, POSR, post_s and a little more, motor off; made by the
        block cycle by cycle) recorded from 20 cycles before its POSR to
        post_s after the set-point's end; columns by name, t in s of
        program time (cycles executed x the task interval)."""
        ax, tr = self.ax, self.tr
        tmove = (dist / self.v + self.v / self.acc) if dist >= self.v ** 2 / self.acc \
            else 2 * math.sqrt(dist / self.acc)
        pre = 20
        n = pre + int((tmove + post_s) / self.period) + 30
        if n > self.cap:
            raise SystemExit(f"aposs_tune: a run needs {n} trace samples, plcrt keeps {self.cap} "
                             "([trace] samples, docs/config.md)")
        tr.command(plctrace.CLAIM, what="claim the trace")
        try:
            tr.command(plctrace.CHANNELS, [x for c in self.chans for x in plctrace.args32(c[0])], "channels")
            tr.command(plctrace.SETUP, [1] + plctrace.args32(n) + plctrace.args32(pre) + [plctrace.TRIGGERS["rise"]]
                       + plctrace.args32(self.trig) + [0, 0, 0, 0] + [0], "setup")
            st0 = tr.status()
            tr.command(plctrace.ARM, what="arm")
            ax.wait_cycles(pre + 2)                  # the pre-trigger samples are in
            ax.set("POS", self.sign * dist)
            ax.set("TESTRUN_REST", REST_MS)
            ax.set("TESTRUN_HOLD", round(1000 * post_s) + 30 * round(1000 * self.period) + 20)
            ax.pulse("TESTRUN")
            c0 = ax.cycles()
            while True:
                st = tr.status()
                if st["readable"] and st["seq"] > st0["captures"]:
                    break
                if (ax.cycles() - c0) & 0xFFFFFFFF > 4 * n + 5000:
                    tr.command(plctrace.STOP, what="stop")
                    raise SystemExit("aposs_tune: the trace did not trigger on the test run's POSR (TESTRUN "
                                     f"refused: refcode {ax.out('REFCODE')}, error {ax.out('ERRNUM')})")
                tr.command(plctrace.CLAIM, what="keep the trace")
                ax.wait_cycles(20)
            rows = plctrace.download(tr, st)
        finally:
            tr.command(plctrace.RELEASE, what="release")
        c0 = ax.cycles()
        while ax.flag("TESTING"):                   # its hold, then motor off
            if (ax.cycles() - c0) & 0xFFFFFFFF > n + 5000:
                raise SystemExit("aposs_tune: the test run did not end")
            ax.wait_cycles(10)
        cols = {}
        for (path, vals), name in zip(rows["cols"], CHANS):
            cols[name.split(".")[-1]] = [float(v) for v in vals]
        cyc = rows["cycle"]
        cols["T"] = [((c - cyc[pre]) & 0xFFFFFFFF if c >= cyc[pre] else -((cyc[pre] - c) & 0xFFFFFFFF)) * self.period
                     for c in cyc]
        ticks = [t / 1000.0 for t in rows["time_ms"]]
        cols["missed"] = sum(1 for i in range(1, len(ticks)) if ticks[i] - ticks[i - 1] > 1.5 * self.period)
        return cols

    def run(self, step, dist, post_s=0.3, back=False, **gains):
        """One test run of step with the given parameters (the others as
        they are); back: there and back, as the seed's Testrun, the return
        move recorded as c["back"] (where within a count each move starts
        differs: the measures take the mean of both)."""
        ax = self.ax
        for k, v in gains.items():
            ax.set(k, v)
        if ax.flag("ERROR"):
            raise SystemExit(f"aposs_tune: the axis has error {ax.out('ERRNUM')} (parameters: {gains})")
        self.sign = 1 if ax.out("APOS") <= self.p0 else -1
        c = self.capture(dist, post_s)
        self.plc_s += c["T"][-1] - c["T"][0]
        if back:
            self.sign = -self.sign
            c["back"] = self.capture(dist, post_s)
            self.plc_s += c["back"]["T"][-1] - c["back"]["T"][0]
            c["missed"] += c["back"]["missed"]
        self.runs += 1
        if ax.flag("ERROR"):
            raise SystemExit(f"aposs_tune: error {ax.out('ERRNUM')} in run {self.runs} ({step}, {gains})")
        with open(os.path.join(self.a.out, f"aposs-tune-run{self.runs}.csv"), "w") as f:
            keys = ["T"] + [n.split(".")[-1] for n in CHANS]
            f.write(",".join(keys) + "\n")
            for i in range(len(c["T"])):
                f.write(",".join(f"{c[k][i]:.6g}" for k in keys) + "\n")
        cur = {k: ax.get(k) for k in GAINS}
        c["gains"], c["step"], c["run"], c["dist"] = cur, step, self.runs, dist
        self.steps[step] = c
        if c["missed"]:
            self.log(f"  run {self.runs}: {c['missed']} scan(s) came late (cycles skipped): on a real axis "
                     "the plant moved on meanwhile")
        return c

    # ---- measures on a run (program time) ----
    @staticmethod
    def phases(c):
        """indices of the set-point's phases: acceleration [a0, a1), constant
        speed [a1, d0), deceleration [d0, d1); d1 the end of the set-point"""
        v, acc = c["CVELQ"], c["CACCQ"]
        idx = [i for i in range(len(v)) if v[i] != 0.0]
        if not idx:
            raise SystemExit("aposs_tune: the set-point did not move (POSR refused?)")
        s = math.copysign(1, v[idx[0]])
        a0 = idx[0]
        a1 = next(i for i in range(a0, len(v)) if acc[i] * s <= 0)
        d0 = next((i for i in range(a1, len(v)) if acc[i] * s < 0), a1)
        d1 = idx[-1] + 1
        return a0, a1, d0, d1, s

    def plateau(self, c, settle=0.03):
        """commanded and actual mean speed over the constant speed (after
        settle s): the following error's change over it gives the difference"""
        a0, a1, d0, d1, s = self.phases(c)
        i0 = a1 + int(settle / self.period)
        if d0 - i0 < 20:
            raise SystemExit("aposs_tune: no constant speed in the FFVEL run")
        dt = c["T"][d0] - c["T"][i0]
        vc = (c["CPOS"][d0] - c["CPOS"][i0]) / dt
        va = vc - (c["FE"][d0] - c["FE"][i0]) / dt
        return vc, va

    def ramp_lag(self, c):
        """the speed lost on the ramps, as a lag in s: the following error
        each ramp adds over the peak speed (accelerating minus decelerating,
        halved: a speed offset on the way cancels)"""
        a0, a1, d0, d1, s = self.phases(c)
        fe = c["FE"]
        vp = abs(max(c["CVELQ"], key=abs))
        return s * ((fe[a1] - fe[a0]) - (fe[d1] - fe[d0])) / 2 / vp

    def swing(self, c, i0, i1):
        fe = c["FE"][i0:i1]
        m = sum(fe) / len(fe)
        return math.sqrt(sum((x - m) ** 2 for x in fe) / len(fe))

    def standstill(self, c):
        """swing (RMS about the mean) of the following error at standstill:
        the first and the last 0.1 s of the capture after the set-point's end,
        and the mean of the last 0.1 s (the static error)"""
        d1 = self.phases(c)[3]
        w = int(0.1 / self.period)
        n = len(c["FE"])
        if n - d1 < 2 * w:
            raise SystemExit("aposs_tune: the capture ends too early after the move")
        last = c["FE"][n - w:]
        return self.swing(c, d1, d1 + w), self.swing(c, n - w, n), sum(last) / w

    def oscillation(self, c):
        """RMS of the following error about its mean, from the move's start
        to 0.2 s after its end (the mean of there and back)"""
        def one(c):
            a0, _, _, d1, _ = self.phases(c)
            return self.swing(c, a0, min(len(c["FE"]), d1 + int(0.2 / self.period)))
        return sum(one(x) for x in both(c)) / len(both(c))

    @staticmethod
    def fe_peak(c):
        """peak |following error| (the mean of there and back)"""
        return sum(max(abs(x) for x in y["FE"]) for y in both(c)) / len(both(c))

    # ---- the steps ----
    def tune(self):
        ax, a, log = self.ax, self.a, self.log
        orig = {k: ax.get(k) for k in GAINS + ("POSERR",)}
        ax.set("VEL", a.vel)
        ax.set("ACC", a.acc)
        ax.set("DEC", 0)
        ax.pulse("ERRCLR")
        d_ramp = math.ceil(self.v ** 2 / self.acc)              # reaches VEL, no constant speed
        d_plat = math.ceil(self.v ** 2 / self.acc + 0.1 * self.v)   # and 0.1 s of it
        log(f"test moves: VEL {a.vel} = {self.v:.0f} qc/s, ACC {a.acc} = {self.acc:.0f} qc/s2; "
            f"{d_ramp} qc (just reaching VEL) for FFACC and KPROP, {d_plat} qc (and 0.1 s at VEL) for the others")
        log(f"before: " + " ".join(f"{k} {orig[k]}" for k in GAINS))
        ax.set("POSERR", a.poserr)                                          # step 2
        log(f"step 2: POSERR {a.poserr} (was {orig['POSERR']})")

        ffvel = 100                                                         # step 3
        for _ in range(5):
            c = self.run("3", d_plat, 0.1, KPROP=0, KDER=0, KINT=0, FFACC=0, FFVEL=ffvel, BANDWIDTH=1000)
            vc, va = self.plateau(c)
            new = max(1, min(100000, round(ffvel * vc / va)))
            log(f"step 3 run {self.runs}: FFVEL {ffvel}: plateau commanded {vc:.0f} qc/s, actual {va:.0f} qc/s "
                f"-> FFVEL {new}")
            done = abs(new - ffvel) <= max(1, 0.003 * ffvel)
            ffvel = new
            if done:
                break
        self.ffvel = ffvel
        ax.set("FFVEL", ffvel)
        self.drive = va / (ffvel / 1000 * 32767 * vc / (ax.get("VELMAX") * ax.get("ENCODER") * 4 / 60.0))

        pts = []                                                            # step 4
        ffacc = 10
        for _ in range(5):
            c = self.run("4", d_ramp, 0.1, FFACC=ffacc)
            lag = self.ramp_lag(c)
            pts.append((ffacc, lag))
            if len(pts) == 1:
                # the drive's speed per DAC bit (step 3) gives the slope
                vmx = ax.get("VELMAX") * ax.get("ENCODER") * 4 / 60.0
                amx = vmx / (ax.get("RAMPMIN") / 1000.0)
                slope = -32.767 * self.drive / amx
            else:
                (f0, l0), (f1, l1) = pts[-2], pts[-1]
                slope = (l1 - l0) / (f1 - f0) if f1 != f0 and l1 != l0 else slope
            new = max(0, min(100000, round(ffacc - lag / slope)))
            log(f"step 4 run {self.runs}: FFACC {ffacc}: the ramps lose {1000 * lag:+.3f} ms of speed -> FFACC {new}")
            if new == ffacc:
                break
            ffacc = new
        self.ffacc = ffacc
        ax.set("FFACC", ffacc)
        # the plant as steps 3 and 4 measured it: speed per DAC bit and lag
        self.tau = max(0.0, ffacc * 32.767 * self.drive / (ax.get("VELMAX") * ax.get("ENCODER") * 4 / 60.0
                                                           / (ax.get("RAMPMIN") / 1000.0)) - self.period / 2)
        log(f"the plant: {self.drive:.4f} qc/s per DAC bit, a lag of {1000 * self.tau:.2f} ms")

        def oscillates(kp):                                                 # step 5
            c = self.run("5", d_ramp, 0.4, True, KPROP=kp, KDER=0, KINT=0)
            sw = [self.standstill(x)[:2] for x in both(c)]
            s0, s1 = (sum(x[0] for x in sw) / 2, sum(x[1] for x in sw) / 2)
            osc = s1 > a.osc
            log(f"step 5 run {self.runs}: KPROP {kp}: following error swing at standstill {s0:.2f} qc, "
                f"0.3 s later {s1:.2f} qc: {'oscillating' if osc else 'steady'}")
            return osc
        guess = predicted_onset(self.drive, self.tau, self.period)
        log(f"step 5: the plant measured predicts oscillation from KPROP {guess:.0f}")
        lo, hi = max(1, math.floor(0.9 * guess)), min(65000, math.ceil(1.2 * guess))
        while lo > 1 and oscillates(lo):
            hi, lo = lo, max(1, math.floor(lo / 1.3))
        while not oscillates(hi):
            if hi >= 65000:
                raise SystemExit("aposs_tune: no oscillation up to KPROP 65000")
            lo, hi = hi, min(65000, math.ceil(hi * 1.3))
        while hi - lo > 0.02 * hi:
            mid = (lo + hi) // 2
            if oscillates(mid):
                hi = mid
            else:
                lo = mid
        self.kosc = hi
        self.kprop = max(1, round(0.7 * hi))
        log(f"step 5: oscillation from KPROP {hi} (steady at {lo}): KPROP = 70 % = {self.kprop}")

        c = self.run("6", d_plat, 0.3, True, KPROP=self.kprop, KDER=0, KINT=0)     # step 6
        best = (self.oscillation(c), 0, c)
        log(f"step 6 run {self.runs}: KDER 0: oscillation {best[0]:.3f} qc")
        tried = [best]
        kd, lowest = 200, best[0]
        while kd <= 65000:
            c = self.run("6", d_plat, 0.3, True, KDER=kd)
            m = self.oscillation(c)
            # a change within 10 % is the encoder's rounding (where within a
            # count the run started), not the gain's: the oscillations rise
            # when they exceed the lowest so far by more
            rise = m > 1.1 * lowest
            log(f"step 6 run {self.runs}: KDER {kd}: oscillation {m:.3f} qc"
                + (f" (more than 10 % above the lowest, {lowest:.3f}: they rise)" if rise else ""))
            if rise:
                break
            tried.append((m, kd, c))
            lowest = min(lowest, m)
            kd = round(kd * 1.5)
        # the values before the rise whose oscillation is within 10 % of the
        # lowest are one flat bottom to the encoder: the middle one is kept,
        # as far from too little damping as from a KDER that multiplies the
        # encoder's counts
        bottom = [t for t in tried if t[0] <= 1.1 * lowest]
        best = bottom[len(bottom) // 2]
        log(f"step 6: KDER {', '.join(str(t[1]) for t in bottom)} within 10 % of the lowest: the middle one")
        self.kder = best[1]
        self.steps["6"] = best[2]
        ax.set("KDER", self.kder)
        log(f"step 6: KDER {self.kder}")

        _, _, static = self.standstill(best[2])                              # step 7
        self.kint = 0
        while abs(static) > 1.0 and self.kint < 64:
            self.kint = max(1, self.kint * 2)
            c = self.run("7", d_plat, 0.3, True, KINT=self.kint)
            _, _, static = self.standstill(c)
            log(f"step 7 run {self.runs}: KINT {self.kint}: static following error {static:+.2f} qc")
        if self.kint == 0:
            log(f"step 7: static following error {static:+.2f} qc, within a count: no KINT (step 8 has no KILIM to lower)")
        ax.set("KINT", self.kint)

        ref = self.steps.get("7", best[2])
        fe_best, pk_best = self.oscillation(ref), self.fe_peak(ref)
        peak = max(abs(x) for r in both(ref) for x in r["PIDPART"])
        # the floor: what the PID used there and back; below it the clamp
        # cuts the corrections of the runs measured, and those of other
        # starts more (the seed expects 60..120 with a good feed-forward)
        floor = max(1, min(1000, math.ceil(1000 * peak / 32767)))
        bw = max(1, min(1000, math.ceil(1.25 * 1000 * peak / 32767)))
        log(f"step 9: the PID used at most {peak:.0f} DAC bits ({1000 * peak / 32767:.1f} / 1000): "
            f"BANDWIDTH {bw} clamps nothing, {floor} is the floor; following error {fe_best:.3f} qc RMS, "
            f"{pk_best:.3f} qc peak")
        good = bw
        while bw > floor:
            bw = max(floor, math.floor(bw * 0.8))
            c = self.run("9", d_plat, 0.3, True, BANDWIDTH=bw)
            m, pk = self.oscillation(c), self.fe_peak(c)
            # the following error, its RMS and its peak, within 10 % of the best
            ok = m <= 1.1 * fe_best and pk <= 1.1 * pk_best
            log(f"step 9 run {self.runs}: BANDWIDTH {bw}: following error {m:.3f} qc RMS, {pk:.3f} qc peak "
                f"({'within' if ok else 'beyond'} 10 % of the best, {fe_best:.3f} and {pk_best:.3f})")
            fe_best, pk_best = min(fe_best, m), min(pk_best, pk)
            if not ok:
                break
            good = bw
        self.bandwidth = good
        ax.set("BANDWIDTH", good)

        ax.set("POSERR", orig["POSERR"])                                    # step 10
        c = self.run("10", a.dist, 0.3)
        self.final_peak = self.fe_peak(c)
        log(f"step 10: POSERR {orig['POSERR']}; the standard move ({a.dist} qc): peak following error "
            f"{self.final_peak:.3f} qc, not tripped")
        self.plc_total = ((ax.cycles() - self.cyc0) & 0xFFFFFFFF) * self.period
        return {"FFVEL": self.ffvel, "FFACC": self.ffacc, "KPROP": self.kprop, "KDER": self.kder,
                "KINT": self.kint, "BANDWIDTH": self.bandwidth, "KPROP_OSC": self.kosc, "RUNS": self.runs}

    def log(self, s):
        self.lines.append(s)
        print(s, flush=True)

    def plot(self, step, c, path):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        t = [1000 * x for x in c["T"]]
        ap = c["AP"]
        va = [0.0] + [(ap[i] - ap[i - 1]) / self.period for i in range(1, len(ap))]
        fig, axs = plt.subplots(3, 1, sharex=True, figsize=(10, 7))
        axs[0].plot(t, c["CPOS"], label="set-point position (qc)")
        axs[0].plot(t, ap, label="actual position (qc)", drawstyle="steps-post")
        axs[1].plot(t, c["CVELQ"], label="set-point speed (qc/s)")
        axs[1].plot(t, va, label="actual speed (qc/s, per cycle)", linewidth=0.8)
        axs[2].plot(t, c["FE"], label="following error (qc)", color="C3", drawstyle="steps-post")
        for x in axs:
            x.grid(True, alpha=0.3)
            x.legend(loc="best", fontsize="small")
        g = c["gains"]
        axs[0].set_title(f"step {step}, run {c['run']}: " + " ".join(f"{k} {g[k]}" for k in GAINS))
        axs[2].set_xlabel("PLC time from the command (ms)")
        fig.tight_layout()
        fig.savefig(path, dpi=80)
        plt.close(fig)


def both(c):
    """a run's captures: there, and back if it went back"""
    return [c, c["back"]] if "back" in c else [c]


def predicted_onset(kd, tau, T):
    """The KPROP at which the sampled loop (P on the counter, DAC held over a
    cycle, a drive of kd qc/s per bit with a first-order lag tau) loses its
    stability: the largest eigenvalue's modulus reaches 1 (bisection)."""
    a = math.exp(-T / tau) if tau > 0 else 0.0
    b1 = kd * (T - tau * (1 - a))
    b2 = (1 - a) * kd
    tv = tau * (1 - a)

    def stable(k):
        # x+ = x + tv v - b1 k x ; v+ = a v - b2 k x: characteristic z^2 - tr z + det
        m11, m12, m21, m22 = 1 - b1 * k, tv, -b2 * k, a
        tr, det = m11 + m22, m11 * m22 - m12 * m21
        disc = tr * tr - 4 * det
        if disc < 0:
            return det < 1
        r = math.sqrt(disc)
        return max(abs((tr + r) / 2), abs((tr - r) / 2)) < 1
    lo, hi = 0.0, 1.0
    while stable(hi) and hi < 1e6:
        lo, hi = hi, hi * 2
    for _ in range(50):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if stable(mid) else (lo, mid)
    return lo


def load(ax, path):
    """Write the gains of a file written by a tuning (NAME VALUE lines) into the axis."""
    try:
        with open(path) as f:
            text = f.read()
    except OSError as e:
        raise SystemExit(f"aposs_tune: --load {path}: {e.strerror}")
    vals = {}
    for n, line in enumerate(text.splitlines(), 1):
        line = line.split("#")[0].strip()
        if not line:
            continue
        it = line.split()
        if len(it) != 2 or it[0] not in GAINS or not it[1].lstrip("-").isdigit():
            print(f"aposs_tune: {path}:{n}: '{line}': expected NAME VALUE, NAME one of {' '.join(GAINS)}",
                  file=sys.stderr)
            sys.exit(2)
        vals[it[0]] = int(it[1])
    for k, v in vals.items():
        ax.set(k, v)
    print("loaded: " + " ".join(f"{k} {v}" for k, v in vals.items()))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--host", default="127.0.0.1")
    ap.add_argument("--port", type=int, default=1502)
    ap.add_argument("--out", default=".", help="folder of the report, plots, captures and aposs-gains.txt")
    ap.add_argument("--instance", default="CONFIG0.RES0.INST0.AX", help="IEC path of the APOSSAXIS instance")
    ap.add_argument("--dist", type=int, default=50000, help="the standard move of the last run, qc")
    ap.add_argument("--vel", type=int, default=100, help="VEL of the test moves (1/VELRES of VELMAX)")
    ap.add_argument("--acc", type=int, default=100, help="ACC of the test moves (1/VELRES of VELMAX/RAMPMIN)")
    ap.add_argument("--poserr", type=int, default=1000000, help="POSERR while tuning (seed: e.g. 1000000)")
    ap.add_argument("--osc", type=float, default=1.2,
                    help="swing of the following error (RMS about its mean, qc) 0.3 to 0.4 s after the move "
                         "that counts as oscillating: above the encoder's one-count chatter")
    ap.add_argument("--load", metavar="FILE", help="write the gains of FILE (aposs-gains.txt) into the axis")
    a = ap.parse_args(argv)
    for k in ("vel", "acc"):
        if not 1 <= getattr(a, k) <= 100:
            ap.error(f"--{k} {getattr(a, k)}: 1..100")
    if a.dist <= 0 or a.poserr <= 0 or not a.osc > 0:
        ap.error("--dist, --poserr and --osc must be above 0")
    ax = Axis(a.host, a.port)
    try:
        if a.load:
            load(ax, a.load)
            return 0
        tn = Tuner(ax, a)
        g = tn.tune()
        tn.log(f"{tn.runs} test runs, {tn.plc_s:.1f} s of PLC time recorded, {tn.plc_total:.1f} s of PLC time "
               "from start to end")
        for step in sorted(tn.steps, key=int):
            tn.plot(step, tn.steps[step], os.path.join(a.out, f"aposs-tune-step{step}.png"))
        with open(os.path.join(a.out, "aposs-gains.txt"), "w") as f:
            f.write("# APOSSAXIS gains found by tools/aposs_tune.py; load them with\n"
                    "#   tools/aposs_tune.py --load aposs-gains.txt [--host H --port P]\n")
            for k in GAINS:
                f.write(f"{k} {g[k]}\n")
        with open(os.path.join(a.out, "aposs-tune-report.txt"), "w") as f:
            f.write("\n".join(tn.lines) + "\n")
            f.write("gains: " + " ".join(f"{k} {g[k]}" for k in GAINS) + "\n")
        print("gains: " + " ".join(f"{k} {v}" for k, v in g.items()) + f" PEAK {tn.final_peak:.3f}", flush=True)
    finally:
        ax.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
