#!/usr/bin/env python3
"""Write the CAMCURVE test programs: ST programs whose expected values come
from scipy.interpolate.CubicSpline (the clamped and natural cubic spline
computed independently of the block under test) and from closed forms
(straight T segments, seed 001's worked examples).

    gen_curve.py OUTDIR      writes OUTDIR/t_curve_*.st

Each program sets a curve, evaluates it in its first scan and records its
checks with TCHECK (tests/epicpos/tsupport.st); the EPICPOS harness prints one
PASS/FAIL line per "(* CHECK n: ... *)" comment.  The random curves come from
a seeded generator, so a failure can be reproduced.
"""
import os
import sys

import numpy as np
from scipy.interpolate import CubicSpline

ENDTYPES = {0: "averaged", 1: "start slope", 2: "zero"}


def lit(x):
    """An LREAL literal holding x exactly (17 significant digits)."""
    return "%.17e" % float(x)


class Prog:
    def __init__(self, name, doc):
        self.name = name
        self.doc = doc
        self.checks = {}
        self.body = []
        self.fbs = []

    def check(self, cid, title):
        self.checks[cid] = title

    def line(self, s):
        self.body.append("    " + s)

    def near(self, cid, expr, want, tol):
        self.line("chk(id := %d, ok := NEAR(%s, %s, %s), val := %s - %s);"
                  % (cid, expr, lit(want), lit(tol), expr, lit(want)))

    def ok(self, cid, cond, val="0.0"):
        self.line("chk(id := %d, ok := %s, val := %s);" % (cid, cond, val))

    def set_curve(self, cv, m, s, t=None, endtype=0, intervals=0):
        self.line("%s.NFIX := %d; %s.ENDTYPE := %d; %s.INTERVALS := %d;"
                  % (cv, len(m), cv, endtype, cv, intervals))
        for i in range(len(m)):
            tt = t is not None and t[i]
            self.line("%s.FIX[%d].MASTER := %s; %s.FIX[%d].SLAVE := %s; %s.FIX[%d].TANGENT := %s;"
                      % (cv, i, lit(m[i]), cv, i, lit(s[i]), cv, i, "TRUE" if tt else "FALSE"))

    def write(self, path):
        out = ["(* MAXTICKS 5 *)", "(* " + self.doc + " *)"]
        for cid in sorted(self.checks):
            out.append("(* CHECK %d: %s *)" % (cid, self.checks[cid]))
        out += ["FUNCTION NEAR : BOOL",
                "  VAR_INPUT a, b, tol : LREAL; END_VAR",
                "  NEAR := ABS(a - b) <= tol;",
                "END_FUNCTION", "",
                "PROGRAM %s" % self.name.upper().replace("_", ""),
                "  VAR",
                "    done AT %QX0.0 : BOOL;",
                "  END_VAR"]
        for k in range(4):
            out += ["  VAR", "    q%d AT %%QD%d : DWORD;" % (k, k), "  END_VAR"]
        for k in range(4):
            out += ["  VAR", "    f%d AT %%QD%d : DWORD;" % (k, k + 4), "  END_VAR"]
        out += ["  VAR", "    fid AT %QD8 : DINT;", "  END_VAR",
                "  VAR", "    fval AT %QD9 : REAL;", "  END_VAR",
                "  VAR", "    chk : TCHECK;"]
        for decl in self.fbs:
            out.append("    " + decl)
        out += ["    started : BOOL;", "  END_VAR",
                "  IF NOT started THEN", "    started := TRUE;"]
        out += self.body
        out += ["  END_IF;",
                "  q0 := chk.pass0; q1 := chk.pass1; q2 := chk.pass2; q3 := chk.pass3;",
                "  f0 := chk.fail0; f1 := chk.fail1; f2 := chk.fail2; f3 := chk.fail3;",
                "  fid := chk.firstid; fval := chk.firstval;",
                "  done := TRUE;",
                "END_PROGRAM", "",
                "CONFIGURATION Config0",
                "  RESOURCE Res0 ON PLC",
                "    TASK Main(INTERVAL := T#1ms, PRIORITY := 0);",
                "    PROGRAM Inst0 WITH Main : %s;" % self.name.upper().replace("_", ""),
                "  END_RESOURCE",
                "END_CONFIGURATION", ""]
        with open(path, "w") as f:
            f.write("\n".join(out))


def natural_end_slopes(m, s):
    cs = CubicSpline(m, s, bc_type="natural")
    return float(cs(m[0], 1)), float(cs(m[-1], 1))


def reference_c_only(m, s, endtype):
    """The curve of C points only, as DESIGN.md section 7 reads seed 001."""
    if endtype == 2:
        v = 0.0
    else:
        v0, vn = natural_end_slopes(m, s)
        v = v0 if endtype == 1 else 0.5 * (v0 + vn)
    return CubicSpline(m, s, bc_type=((1, v), (1, v))), v


def prog_random():
    """Random C-only curves against scipy, each end type, up to 1000 points."""
    rng = np.random.default_rng(20261123)
    p = Prog("t_curve_random", "CAMCURVE on random curves of C points against "
             "scipy.interpolate.CubicSpline with bc_type=((1, v), (1, v)), v from the end "
             "type as DESIGN.md section 7 reads seed 001 \"Interpolation\" (averaged: the mean "
             "of the natural spline's end slopes; start: its start slope; zero: 0).  "
             "Tolerances: 1e-9 UU at the fix points (the brief), relative 1e-9 elsewhere.")
    p.check(1, "the slave passes through every fix point within 1e-9 UU")
    p.check(2, "slave position equals scipy's clamped spline between the fix points")
    p.check(3, "slave speed dS/dM equals scipy's first derivative")
    p.check(4, "slave acceleration d2S/dM2 equals scipy's second derivative")
    p.check(5, "averaged end: the end slope is the mean of the natural spline's end slopes")
    p.check(6, "start-slope end: the end slope is the natural spline's start slope")
    p.check(7, "zero end: the speed is 0 at the start and at the end of the cycle")
    p.check(8, "no position step across the cycle boundary (SPOSC continuous)")
    p.check(9, "no speed step across the cycle boundary")
    p.check(10, "position and speed continuous at every fix point (left and right limits)")
    p.check(11, "a 1000-point curve builds and is valid")
    p.check(12, "a master position beyond the cycle is taken modulo the cycle")
    cases = [(12, 0), (12, 1), (12, 2), (60, 0), (60, 1), (60, 2), (1000, 0), (1000, 2)]
    for k, (n, et) in enumerate(cases):
        cv = "cv%d" % k
        c = "c%d" % k
        p.fbs.append("%s : CAM_CURVE;" % cv)
        p.fbs.append("%s : CAMCURVE;" % c)
        m = np.cumsum(rng.uniform(1.0, 20.0, n)) - 5.0 * rng.uniform()
        s = np.cumsum(rng.uniform(-8.0, 12.0, n))
        ref, v = reference_c_only(m, s, et)
        L = m[-1] - m[0]
        rise = s[-1] - s[0]
        scale = 1.0 + np.max(np.abs(s))
        p.set_curve(cv, m, s, endtype=et)
        p.line("%s(BUILD := TRUE, MPOS := %s, CURVE := %s);" % (c, lit(m[0]), cv))
        if n == 1000:
            p.ok(11, "%s.VALID AND NOT %s.ERROR AND %s.NFIX = 1000" % (c, c, c))
        # every fix point (the last one is the next cycle's first)
        idx = range(n) if n <= 60 else list(range(0, n, 7)) + [n - 2, n - 1]
        for i in idx:
            p.line("%s(MPOS := %s, CURVE := %s);" % (c, lit(m[i]), cv))
            # SPOSC: at the last point the cycle ends and SPOS starts over
            p.near(1, "%s.SPOSC" % c, s[i], 1e-9)
        # random master positions inside the cycle
        for x in rng.uniform(m[0], m[-1], 40 if n <= 60 else 120):
            p.line("%s(MPOS := %s, CURVE := %s);" % (c, lit(x), cv))
            p.near(2, "%s.SPOS" % c, float(ref(x)), 1e-9 * scale)
            d1 = float(ref(x, 1))
            d2 = float(ref(x, 2))
            p.near(3, "%s.SVEL" % c, d1, 1e-9 * (1.0 + abs(d1)) * 10)
            p.near(4, "%s.SACC" % c, d2, 1e-8 * (1.0 + abs(d2)) * 10)
        # the end slope of each end type
        p.line("%s(MPOS := %s, CURVE := %s);" % (c, lit(m[0]), cv))
        p.near({0: 5, 1: 6, 2: 7}[et], "%s.SVEL" % c, v, 1e-9 * (1.0 + abs(v)))
        # across the cycle boundary: just before and exactly at the end
        dlt = 1e-6 * L
        a_end = float(ref(m[-1], 2))
        p.line("%s(MPOS := %s, CURVE := %s);" % (c, lit(m[-1] - dlt), cv))
        p.line("x1 := %s.SPOSC; v1 := %s.SVEL;" % (c, c))
        if et == 2:
            p.near(7, "%s.SVEL" % c, 0.0, abs(a_end) * dlt * 1.01 + 1e-9)
        p.line("%s(MPOS := %s, CURVE := %s);" % (c, lit(m[-1]), cv))
        # position: the left limit predicted from the speed; the step would be >= 1e-3
        p.ok(8, "NEAR(%s.SPOSC - x1, %s * %s, %s)" % (c, lit(v), lit(dlt), lit(abs(a_end) * dlt * dlt + 1e-9 * scale)),
             "%s.SPOSC - x1" % c)
        p.ok(9, "NEAR(%s.SVEL, v1, %s)" % (c, lit(abs(a_end) * dlt * 1.01 + 1e-9)), "%s.SVEL - v1" % c)
        p.near(9, "%s.SVEL" % c, v, 1e-9 * (1.0 + abs(v)))
        # continuity at interior fix points
        for i in list(range(1, min(n - 1, 12))) + [n // 2]:
            e = 1e-7 * (m[i + 1] - m[i])
            acc = max(abs(float(ref(m[i] - e, 2))), abs(float(ref(m[i] + e, 2))))
            vi = float(ref(m[i], 1))
            p.line("%s(MPOS := %s, CURVE := %s); x1 := %s.SPOS; v1 := %s.SVEL;" % (c, lit(m[i] - e), cv, c, c))
            p.line("%s(MPOS := %s, CURVE := %s);" % (c, lit(m[i] + e), cv))
            p.ok(10, "NEAR(%s.SPOS - x1, %s, %s) AND NEAR(%s.SVEL, v1, %s)"
                 % (c, lit(2 * e * vi), lit(2 * e * e * acc + 1e-9 * scale), c, lit(2 * e * acc * 1.01 + 1e-9)),
                 "%s.SVEL - v1" % c)
        # modulo: three cycles on, and one back
        x = float(rng.uniform(m[0], m[-1]))
        for kk in (3, -1):
            p.line("%s(MPOS := %s, CURVE := %s);" % (c, lit(x + kk * L), cv))
            p.near(12, "%s.SPOS" % c, float(ref(x)), 1e-9 * scale * (1 + abs(kk)))
            p.near(12, "%s.SPOSC" % c, float(ref(x)) + kk * rise, 1e-9 * scale * (1 + abs(kk)))
            p.ok(12, "%s.CYCLES = %s" % (c, lit(kk)))
    p.fbs.append("x1 : LREAL;")
    p.fbs.append("v1 : LREAL;")
    return p


def piecewise_reference(m, s, tang, endtype):
    """Seed-style curves with T segments: each run of C segments between two
    fixed slopes is scipy's clamped spline of that run; the slope at the cycle
    boundary from the end type (natural end slopes of the first and last runs,
    the other end of each run clamped to the T slope)."""
    n = len(m)
    fixed = {}
    for i in range(n - 1):
        if tang[i]:
            d = (s[i + 1] - s[i]) / (m[i + 1] - m[i])
            fixed[i] = d
            fixed[i + 1] = d
    assert 0 not in fixed and n - 1 not in fixed
    first = min(fixed)
    last = max(fixed)
    v0 = float(CubicSpline(m[:first + 1], s[:first + 1], bc_type=((2, 0.0), (1, fixed[first])))(m[0], 1))
    vn = float(CubicSpline(m[last:], s[last:], bc_type=((1, fixed[last]), (2, 0.0)))(m[-1], 1))
    v = {0: 0.5 * (v0 + vn), 1: v0, 2: 0.0}[endtype]
    fixed[0] = v
    fixed[n - 1] = v
    pieces = []
    knots = sorted(fixed)
    for a, b in zip(knots, knots[1:]):
        if tang[a] and b == a + 1:
            d = fixed[a]
            pieces.append((m[a], m[b], lambda x, nu=0, a=a, d=d: (s[a] + d * (x - m[a])) if nu == 0 else (d if nu == 1 else 0.0)))
        else:
            cs = CubicSpline(m[a:b + 1], s[a:b + 1], bc_type=((1, fixed[a]), (1, fixed[b])))
            pieces.append((m[a], m[b], lambda x, nu=0, cs=cs: float(cs(x, nu))))

    def f(x, nu=0):
        for lo, hi, g in pieces:
            if lo <= x < hi:
                return g(x, nu)
        return pieces[-1][2](x, nu)
    return f, v


def prog_seed():
    p = Prog("t_curve_seed", "CAMCURVE on seed 001's worked examples: \"Stamping of Boxes\" "
             "(fix points 0/0 C, 1500/1200 T, 2500/2400 C, 4000/3600 C) and \"Slave "
             "Synchronization\" (0/0 C, 1200/1500 T, 2400/2500 C, 3600/4000 C).  Straight "
             "segments from the closed form S = S1 + (M - M1)(S2 - S1)/(M2 - M1); the "
             "spline runs from scipy's CubicSpline, clamped to the T slope beside a T segment "
             "(DESIGN.md section 7).  Table mode: seed \"Accuracy\", linear between table points.")
    p.check(1, "stamping: the T segment 1500..2500 is straight: S = 1200 + 1.2 (M - 1500)")
    p.check(2, "stamping: zero acceleration on the T segment, speed 1.2")
    p.check(3, "stamping: the spline runs match scipy (each end type)")
    p.check(4, "stamping: the splines beside the T segment take its slope (no speed step at 1500, 2500)")
    p.check(5, "stamping: the slave passes through the four fix points")
    p.check(6, "slave synchronization example: T segment 1200..2400 straight at speed 1000/1200")
    p.check(7, "slave synchronization example: the splines match scipy, no speed step at the tangent points")
    p.check(8, "no speed step across the cycle boundary (each end type)")
    p.check(9, "table mode, 40 intervals: the table points lie on the spline")
    p.check(10, "table mode: linear between table points, SACC 0, SVEL the chord's slope")
    p.check(11, "table mode: TINTERVAL = 60000 ms / (Cycles/min 60 x 40 intervals) = 25 ms")
    p.check(12, "the master cycle is 4000 and the slave rise per cycle 3600; MPOS 14000 is 2000 of cycle 3")
    p.check(13, "correction zone 3000..1000 wraps over the cycle end (seed \"Correction Start = 3000, End = 1000\")")
    examples = [
        ([0.0, 1500.0, 2500.0, 4000.0], [0.0, 1200.0, 2400.0, 3600.0], [False, True, False, False], (1, 2, 3, 4, 5)),
        ([0.0, 1200.0, 2400.0, 3600.0], [0.0, 1500.0, 2500.0, 4000.0], [False, True, False, False], (6, 6, 7, 7, 7)),
    ]
    rng = np.random.default_rng(7)
    k = 0
    for m, s, tang, ids in examples:
        m = np.array(m)
        s = np.array(s)
        d = (s[2] - s[1]) / (m[2] - m[1])
        for et in (0, 1, 2):
            cv = "cv%d" % k
            c = "c%d" % k
            k += 1
            p.fbs.append("%s : CAM_CURVE;" % cv)
            p.fbs.append("%s : CAMCURVE;" % c)
            ref, v = piecewise_reference(m, s, tang, et)
            p.set_curve(cv, m, s, tang, endtype=et)
            if ids[0] == 1 and et == 0:
                p.line("%s.CYCLESMIN := 60.0; %s.CORRSTART := 3000.0; %s.CORREND := 1000.0;" % (cv, cv, cv))
            p.line("%s(BUILD := TRUE, MPOS := 0.0, CURVE := %s);" % (c, cv))
            for x in np.linspace(m[1], m[2], 9)[:-1]:
                p.line("%s(MPOS := %s, CURVE := %s);" % (c, lit(x), cv))
                p.near(ids[0], "%s.SPOS" % c, s[1] + (x - m[1]) * d, 1e-9)
                p.ok(ids[1], "%s.SACC = 0.0 AND NEAR(%s.SVEL, %s, 1.0E-12)" % (c, c, lit(d)), "%s.SACC" % c)
            for x in list(rng.uniform(m[0], m[1], 10)) + list(rng.uniform(m[2], m[3], 10)):
                p.line("%s(MPOS := %s, CURVE := %s);" % (c, lit(x), cv))
                p.near(ids[2], "%s.SPOS" % c, ref(x), 1e-9 * 4000)
                p.near(ids[2], "%s.SVEL" % c, ref(x, 1), 1e-11 * 100)
                p.near(ids[2], "%s.SACC" % c, ref(x, 2), 1e-12 * 100)
            for i in (1, 2):
                e = 1e-3
                p.line("%s(MPOS := %s, CURVE := %s); v1 := %s.SVEL;" % (c, lit(m[i] - e), cv, c))
                p.line("%s(MPOS := %s, CURVE := %s);" % (c, lit(m[i] + e), cv))
                p.ok(ids[3], "NEAR(%s.SVEL, v1, 1.0E-5) AND NEAR(v1, %s, 1.0E-5)" % (c, lit(d)), "%s.SVEL - v1" % c)
            for i in range(4):
                p.line("%s(MPOS := %s, CURVE := %s);" % (c, lit(m[i]), cv))
                p.near(ids[4], "%s.SPOSC" % c, s[i], 1e-9)
            p.line("%s(MPOS := %s, CURVE := %s); v1 := %s.SVEL; x1 := %s.SPOSC;" % (c, lit(m[3] - 1e-3), cv, c, c))
            p.line("%s(MPOS := %s, CURVE := %s);" % (c, lit(m[3]), cv))
            p.ok(8, "NEAR(%s.SVEL, v1, 1.0E-5) AND NEAR(%s.SVEL, %s, 1.0E-9) AND NEAR(%s.SPOSC - x1, %s, 1.0E-5)"
                 % (c, c, lit(v), c, lit(v * 1e-3)), "%s.SVEL - v1" % c)
            if ids[0] == 1 and et == 0:
                p.line("%s(MPOS := 14000.0, CURVE := %s);" % (c, cv))
                p.ok(12, "%s.MCYCLE = 4000.0 AND %s.SRISE = 3600.0 AND %s.MCPOS = 2000.0 AND %s.CYCLES = 3.0 "
                     "AND NEAR(%s.SPOSC, %s, 1.0E-9)" % (c, c, c, c, c, lit(1800.0 + 3 * 3600.0)), "%s.SPOSC" % c)
                for x, want in ((3500.0, True), (500.0, True), (3000.0, True), (999.0, True), (1000.0, False),
                                (2000.0, False), (7500.0, True)):
                    p.line("%s(MPOS := %s, CURVE := %s);" % (c, lit(x), cv))
                    p.ok(13, "%s%s.INZONE" % ("" if want else "NOT ", c))
    # table mode on the stamping curve, averaged end
    m = np.array([0.0, 1500.0, 2500.0, 4000.0])
    s = np.array([0.0, 1200.0, 2400.0, 3600.0])
    tang = [False, True, False, False]
    ref, v = piecewise_reference(m, s, tang, 0)
    p.fbs.append("cvt : CAM_CURVE;")
    p.fbs.append("ct : CAMCURVE;")
    p.set_curve("cvt", m, s, tang, endtype=0, intervals=40)
    p.line("cvt.CYCLESMIN := 60.0;")
    p.line("ct(BUILD := TRUE, MPOS := 0.0, CURVE := cvt);")
    p.ok(11, "ct.VALID AND NEAR(ct.TINTERVAL, 25.0, 1.0E-12)", "ct.TINTERVAL")
    for j in range(0, 41):
        x = 100.0 * j
        p.line("ct(MPOS := %s, CURVE := cvt);" % lit(x))
        p.near(9, "ct.SPOSC", ref(x) if j < 40 else s[3], 1e-9 * 4000)
    for x in rng.uniform(0.0, 4000.0, 30):
        j = int(x // 100.0)
        a, b = ref(100.0 * j), ref(100.0 * (j + 1)) if j < 39 else s[3]
        p.line("ct(MPOS := %s, CURVE := cvt);" % lit(x))
        p.near(10, "ct.SPOS", a + (x - 100.0 * j) / 100.0 * (b - a), 1e-9 * 4000)
        p.ok(10, "ct.SACC = 0.0 AND NEAR(ct.SVEL, %s, 1.0E-9)" % lit((b - a) / 100.0), "ct.SVEL")
    p.fbs.append("x1 : LREAL;")
    p.fbs.append("v1 : LREAL;")
    return p


def prog_mixed():
    """Random curves with T segments against scipy, piece by piece."""
    rng = np.random.default_rng(4242)
    p = Prog("t_curve_mixed", "CAMCURVE on random curves of C and T points: each run of C "
             "segments against scipy.interpolate.CubicSpline clamped to the slopes of the T "
             "segments beside it and, at the cycle ends, to the end type's slope from the "
             "natural spline of the first and last runs (DESIGN.md section 7); T segments "
             "against the closed form of a straight line.")
    p.check(1, "mixed curves: the slave passes through every fix point within 1e-9 UU")
    p.check(2, "mixed curves: the spline runs equal scipy's clamped splines (position, speed, acceleration)")
    p.check(3, "mixed curves: T segments straight, SACC 0")
    p.check(4, "mixed curves: no speed step at any fix point nor across the cycle boundary")
    p.check(5, "table mode with fix points off the grid: the table samples the spline, linear between")
    for k, et in enumerate((0, 1, 2, 0, 1, 2)):
        n = 8 + 4 * k
        cv = "cv%d" % k
        c = "c%d" % k
        p.fbs.append("%s : CAM_CURVE;" % cv)
        p.fbs.append("%s : CAMCURVE;" % c)
        m = np.cumsum(rng.uniform(20.0, 200.0, n))
        s = np.cumsum(rng.uniform(-50.0, 150.0, n))
        tang = [False] * n
        # T segments: not the first or last, never two in a row
        for i in rng.choice(np.arange(2, n - 3), size=max(1, n // 5), replace=False):
            if not tang[i - 1] and not tang[i + 1]:
                tang[i] = True
        ref, v = piecewise_reference(m, s, tang, et)
        p.set_curve(cv, m, s, tang, endtype=et)
        p.line("%s(BUILD := TRUE, MPOS := %s, CURVE := %s);" % (c, lit(m[0]), cv))
        for i in range(n):
            p.line("%s(MPOS := %s, CURVE := %s);" % (c, lit(m[i]), cv))
            p.near(1, "%s.SPOSC" % c, s[i], 1e-9)
        for x in rng.uniform(m[0], m[-1], 40):
            i = int(np.searchsorted(m, x, side="right") - 1)
            p.line("%s(MPOS := %s, CURVE := %s);" % (c, lit(x), cv))
            if tang[i]:
                d = (s[i + 1] - s[i]) / (m[i + 1] - m[i])
                p.near(3, "%s.SPOS" % c, s[i] + d * (x - m[i]), 1e-9 * 1e4)
                p.ok(3, "%s.SACC = 0.0 AND NEAR(%s.SVEL, %s, 1.0E-12)" % (c, c, lit(d)), "%s.SACC" % c)
            else:
                p.near(2, "%s.SPOS" % c, ref(x), 1e-9 * 1e4)
                p.near(2, "%s.SVEL" % c, ref(x, 1), 1e-9)
                p.near(2, "%s.SACC" % c, ref(x, 2), 1e-10)
        # the acceleration is linear on each piece: its largest size is at a knot
        amax = max(abs(ref(x, 2)) for x in list(m[:-1] + 1e-9) + list(m[1:] - 1e-9))
        for i in list(range(1, n - 1)) + [n - 1]:
            e = 1e-6
            p.line("%s(MPOS := %s, CURVE := %s); v1 := %s.SVEL;" % (c, lit(m[i] - e), cv, c))
            p.line("%s(MPOS := %s, CURVE := %s);" % (c, lit(m[i] + e), cv))
            # a speed step would be the size of the slopes (0.1 .. 7 UU/MU)
            p.ok(4, "NEAR(%s.SVEL, v1, %s)" % (c, lit(2 * e * amax * 1.01 + 1e-9)), "%s.SVEL - v1" % c)
    # table mode, 30 intervals over a 1000 MU cycle: fix points off the grid
    m = np.array([0.0, 130.0, 410.0, 555.0, 820.0, 1000.0])
    s = np.array([0.0, 90.0, 300.0, 420.0, 610.0, 700.0])
    tang = [False, False, True, False, False, False]
    ref, v = piecewise_reference(m, s, tang, 0)
    p.fbs.append("cvt : CAM_CURVE;")
    p.fbs.append("ct : CAMCURVE;")
    p.set_curve("cvt", m, s, tang, endtype=0, intervals=30)
    p.line("ct(BUILD := TRUE, MPOS := 0.0, CURVE := cvt);")
    g = 1000.0 / 30
    for x in rng.uniform(0.0, 1000.0, 40):
        j = min(int(x // g), 29)
        a = ref(j * g)
        b = ref((j + 1) * g) if j < 29 else s[-1]
        p.line("ct(MPOS := %s, CURVE := cvt);" % lit(x))
        p.near(5, "ct.SPOS", a + (x - j * g) / g * (b - a), 1e-9 * 1e3)
    p.fbs.append("v1 : LREAL;")
    return p


def prog_errors():
    p = Prog("t_curve_errors", "CAMCURVE refuses bad curves with an error code naming the "
             "problem (the header of st/parts/camcurve.st) and keeps the curve in use.")
    p.check(1, "fewer than 3 fix points: error 1 (seed: at least three fix points)")
    p.check(2, "more than 1024 fix points: error 2")
    p.check(3, "master positions not increasing: error 3 naming the point")
    p.check(4, "two T segments meeting with different slopes: error 4 naming the point")
    p.check(5, "first and last segments straight with different slopes: error 5")
    p.check(6, "end type outside 0..2: error 6")
    p.check(7, "intervals outside 0..1023: error 7")
    p.check(8, "a start/stop pair outside the master cycle: error 9 naming the pair")
    p.check(9, "correction zone outside the master cycle: error 10")
    p.check(10, "a refused curve leaves the curve in use (VALID, same slave position)")
    p.check(11, "a good curve after a refused one clears ERROR")
    p.check(12, "no curve set yet: VALID FALSE, outputs 0")
    p.check(13, "collinear T segments in a row are accepted (a longer straight line)")
    p.check(14, "BUILD acts on its rising edge only")
    p.check(15, "fix points so close that the slope overflows (1e10 UU over 1e-300 MU): "
                "error 12 naming the segment, the curve in use stays")
    p.check(17, "a start/stop pair with START = STOP, or a whole cycle apart (CAMSYNC would wait "
                "for START for ever): error 9 naming the pair")
    p.check(16, "MPOS NaN or 1e300 (beyond 1e15 cycles): every output holds its last value, no jump")
    p.fbs.append("cv : CAM_CURVE;")
    p.fbs.append("c : CAMCURVE;")
    p.fbs.append("tiny : LREAL;")
    p.fbs.append("qn : LREAL;")
    p.fbs.append("spos : LREAL;")
    p.fbs.append("mcpos : LREAL;")
    good = ([0.0, 1500.0, 2500.0, 4000.0], [0.0, 1200.0, 2400.0, 3600.0], [False, True, False, False])

    def build():
        p.line("c(BUILD := FALSE, MPOS := 2000.0, CURVE := cv);")
        p.line("c(BUILD := TRUE, MPOS := 2000.0, CURVE := cv);")

    p.set_curve("cv", good[0][:2], good[1][:2])
    build()
    p.ok(1, "c.ERROR AND c.ERRORID = 1 AND NOT c.VALID")
    p.ok(12, "NOT c.VALID AND c.SPOS = 0.0 AND c.SVEL = 0.0")
    p.set_curve("cv", *good)
    build()
    p.ok(11, "NOT c.ERROR AND c.ERRORID = 0 AND c.VALID AND NEAR(c.SPOS, 1800.0, 1.0E-9)", "c.SPOS")
    p.line("cv.NFIX := 1025;")
    build()
    p.ok(2, "c.ERROR AND c.ERRORID = 2")
    p.ok(10, "c.VALID AND NEAR(c.SPOS, 1800.0, 1.0E-9)", "c.SPOS")
    p.set_curve("cv", [0.0, 1000.0, 1000.0, 4000.0], [0.0, 1.0, 2.0, 3.0])
    build()
    p.ok(3, "c.ERROR AND c.ERRORID = 3 AND c.ERRPOINT = 2", "INT_TO_LREAL(c.ERRPOINT)")
    p.ok(10, "c.VALID AND NEAR(c.SPOS, 1800.0, 1.0E-9)", "c.SPOS")
    p.set_curve("cv", [0.0, 1000.0, 900.0, 4000.0], [0.0, 1.0, 2.0, 3.0])
    build()
    p.ok(3, "c.ERROR AND c.ERRORID = 3 AND c.ERRPOINT = 2", "INT_TO_LREAL(c.ERRPOINT)")
    p.set_curve("cv", [0.0, 1000.0, 2000.0, 3000.0, 4000.0], [0.0, 500.0, 1000.0, 2000.0, 3000.0],
                [False, True, True, False, False])
    build()
    p.ok(4, "c.ERROR AND c.ERRORID = 4 AND c.ERRPOINT = 2", "INT_TO_LREAL(c.ERRPOINT)")
    p.set_curve("cv", [0.0, 1000.0, 2000.0, 3000.0, 4000.0], [0.0, 500.0, 1000.0, 2000.0, 3000.0],
                [False, True, True, False, False])
    p.line("cv.FIX[2].SLAVE := 1000.0; cv.FIX[3].SLAVE := 1500.0;")
    build()
    p.ok(13, "NOT c.ERROR AND c.VALID AND NEAR(c.SPOS, 1000.0, 1.0E-9) AND c.SACC = 0.0", "c.SPOS")
    p.set_curve("cv", [0.0, 1000.0, 2000.0, 3000.0, 4000.0], [0.0, 500.0, 1700.0, 2000.0, 3000.0],
                [True, False, False, True, False])
    build()
    p.ok(5, "c.ERROR AND c.ERRORID = 5")
    p.set_curve("cv", *good, endtype=3)
    build()
    p.ok(6, "c.ERROR AND c.ERRORID = 6")
    p.set_curve("cv", *good, intervals=1024)
    build()
    p.ok(7, "c.ERROR AND c.ERRORID = 7")
    p.set_curve("cv", *good)
    p.line("cv.NSTARTSTOP := 2; cv.STARTSTOP[1].START := 1000.0; cv.STARTSTOP[1].STOP := 1500.0;")
    p.line("cv.STARTSTOP[2].START := 2500.0; cv.STARTSTOP[2].STOP := 4500.0;")
    build()
    p.ok(8, "c.ERROR AND c.ERRORID = 9 AND c.ERRPOINT = 2", "INT_TO_LREAL(c.ERRPOINT)")
    p.line("cv.STARTSTOP[2].STOP := 2500.0;")
    build()
    p.ok(17, "c.ERROR AND c.ERRORID = 9 AND c.ERRPOINT = 2", "INT_TO_LREAL(c.ERRPOINT)")
    p.line("cv.STARTSTOP[2].START := 0.0; cv.STARTSTOP[2].STOP := 4000.0;")
    build()
    p.ok(17, "c.ERROR AND c.ERRORID = 9 AND c.ERRPOINT = 2", "INT_TO_LREAL(c.ERRPOINT)")
    p.line("cv.STARTSTOP[2].START := 2500.0;")
    p.line("cv.STARTSTOP[2].STOP := 3000.0; cv.CORRSTART := 3000.0; cv.CORREND := -1.0;")
    build()
    p.ok(9, "c.ERROR AND c.ERRORID = 10")
    p.line("cv.CORREND := 1000.0;")
    build()
    p.ok(11, "NOT c.ERROR AND c.VALID")
    # rising edge: changing the table while BUILD stays TRUE changes nothing
    p.line("cv.FIX[2].SLAVE := 9999.0;")
    p.line("c(BUILD := TRUE, MPOS := 2000.0, CURVE := cv);")
    p.ok(14, "NEAR(c.SPOS, 1800.0, 1.0E-9)", "c.SPOS")
    build()
    p.ok(14, "NOT c.ERROR AND NEAR(c.SPOS, 1200.0 + 500.0 * 8.799, 1.0E-9)", "c.SPOS")
    # 1e-300 and NaN computed: matiec refuses literals beyond the REAL range
    p.line("tiny := 1.0E-30; tiny := tiny * tiny; tiny := tiny * tiny * tiny * tiny * tiny;")
    p.line("qn := 0.0; qn := qn / qn;")
    p.line("spos := c.SPOS; mcpos := c.MCPOS;")
    p.set_curve("cv", [0.0, 1.0, 1000.0, 4000.0], [0.0, 1.0e10, 1.0e10 + 1.0, 1.0e10 + 2.0])
    p.line("cv.FIX[1].MASTER := tiny;")
    build()
    p.ok(15, "c.ERROR AND c.ERRORID = 12 AND c.ERRPOINT = 0 AND c.VALID AND c.SPOS = spos", "INT_TO_LREAL(c.ERRORID)")
    p.line("c(BUILD := FALSE, MPOS := qn, CURVE := cv);")
    p.ok(16, "c.VALID AND c.SPOS = spos AND c.MCPOS = mcpos", "c.SPOS")
    p.line("c(BUILD := FALSE, MPOS := 1.0E30 / tiny, CURVE := cv);")
    p.ok(16, "c.VALID AND c.SPOS = spos AND c.MCPOS = mcpos", "c.SPOS")
    return p


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    for p in (prog_seed(), prog_random(), prog_mixed(), prog_errors()):
        p.write(os.path.join(out, p.name + ".st"))


if __name__ == "__main__":
    main()
