#!/usr/bin/env python3
"""LJPROF against Ruckig, the time-optimal jerk-limited reference.

    ruckig_peer.py DRIVE [CASES] [SEED]

DRIVE is the compiled LJDRIVE harness (drive.c + drive.st + st/parts/ljprof.st):
it runs the ST block sample by sample for each case fed on its standard
input.  Cases are random: half from rest, half from moving states (speed and
acceleration within the limits, target speed and acceleration 0), with the
four jerk times equal and ACC = DEC, which is the problem Ruckig solves
(one jerk, one acceleration and one speed limit).  Expected values come from
Ruckig only: the time-optimal duration (our planned duration must agree
within 1e-6 relative), the number of samples that follows from it, and
whether the optimal path passes beyond the target (it must not, where
Ruckig's does not).  Every sampled trajectory is also checked for |v| <= VEL,
|a| <= ACC, jerks from the four allowed values, and a final sample exactly on
the target.  Prints PASS:/FAIL: lines and a summary with the worst figures.
"""
import math
import random
import subprocess
import sys

from ruckig import InputParameter, Result, Ruckig, Trajectory

REL = 1e-6          # duration agreement asked for
LIM = 1e-9          # relative slack on the limits


def ruckig_case(v0, a0, d, vel, acc, jerk):
    inp = InputParameter(1)
    inp.current_position = [0.0]
    inp.current_velocity = [v0]
    inp.current_acceleration = [a0]
    inp.target_position = [d]
    inp.target_velocity = [0.0]
    inp.target_acceleration = [0.0]
    inp.max_velocity = [vel]
    inp.max_acceleration = [acc]
    inp.max_jerk = [jerk]
    tr = Trajectory(1)
    res = Ruckig(1).calculate(inp, tr)
    if res not in (Result.Working, Result.Finished):
        return None
    ext = tr.position_extrema[0]
    beyond = (ext.max - d) if d >= 0 else (d - ext.min)
    return tr.duration, max(beyond, 0.0)


def make_cases(n, seed):
    rnd = random.Random(seed)
    cases = []
    while len(cases) < n:
        vel = 10 ** rnd.uniform(-1, 3)
        acc = 10 ** rnd.uniform(-1, 3)
        jms = 10 ** rnd.uniform(0, 3)            # JERKMIN, ms
        jerk = acc / (jms / 1000.0)              # ACCMAX = ACC
        d = rnd.choice((-1, 1)) * 10 ** rnd.uniform(-3, 3)
        moving = len(cases) % 2 == 1
        v0 = a0 = 0.0
        if moving:
            v0 = rnd.uniform(-vel, vel)
            a0 = rnd.uniform(-acc, acc)
            # a state from which the speed limit can still be kept
            if abs(v0 + a0 * abs(a0) / (2 * jerk)) > vel:
                continue
        ref = ruckig_case(v0, a0, d, vel, acc, jerk)
        if ref is None or ref[0] > 40.0 or ref[0] < 0.01:
            continue
        p0 = rnd.uniform(-1000, 1000)
        cases.append(dict(p0=p0, v0=v0, a0=a0, tgt=p0 + d, vel=vel, acc=acc, jms=jms,
                          moving=moving, T=ref[0], beyond=ref[1], d=d))
    return cases


def main():
    drive = sys.argv[1]
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 300
    seed = int(sys.argv[3]) if len(sys.argv) > 3 else 20261123
    cases = make_cases(n, seed)
    dt_ms = 1.0
    lines = "".join(
        "%r %r %r %r %r %r %r %r %r 0 0 0 %r\n" % (c["p0"], c["v0"], c["a0"], c["tgt"], c["vel"],
                                                 c["acc"], c["acc"], c["acc"], c["jms"], dt_ms)
        for c in cases)
    out = subprocess.run([drive], input=lines, capture_output=True, text=True, timeout=600)
    rows = out.stdout.split("\n")
    if out.returncode != 0 or len([r for r in rows if r]) != len(cases):
        print("FAIL: ljprof-ruckig/harness: exit %d, %d of %d results\n%s"
              % (out.returncode, len([r for r in rows if r]), len(cases), out.stderr[-2000:]))
        return 1
    fails = {}
    worst = dict(rel=0.0, v=0.0, a=0.0, over=0.0, snap=0.0)
    iters = []

    def fail(name, c, msg):
        fails.setdefault(name, []).append("%s; case %r" % (msg, c))

    dt = dt_ms / 1000.0
    for c, r in zip(cases, rows):
        f = r.split()
        ptime, samples, fpos = float(f[0]), int(f[1]), float(f[2])
        vmax, amax, over, snap = float(f[3]), float(f[4]), float(f[5]), float(f[6])
        err, it, jok = int(f[7]), int(f[8]), int(f[9])
        iters.append(it)
        kind = "moving" if c["moving"] else "rest"
        rel = abs(ptime - c["T"]) / c["T"]
        worst["rel"] = max(worst["rel"], rel)
        if err or rel > REL:
            fail("duration-" + kind, c, "planned %.17g s, Ruckig %.17g s (rel %.3g), err %d"
                 % (ptime, c["T"], rel, err))
        # the target is reached on the first sample at or after the duration
        lo, hi = c["T"] * (1 - REL) - 1e-9, c["T"] * (1 + REL) + 1e-9
        if not (samples * dt >= lo and (samples - 1) * dt < hi):
            fail("samples-" + kind, c, "done after %d samples of %g s for %.9g s" % (samples, dt, c["T"]))
        if fpos != c["tgt"]:
            fail("final-exact", c, "final %.17g, target %.17g" % (fpos, c["tgt"]))
        worst["v"] = max(worst["v"], vmax)
        worst["a"] = max(worst["a"], amax)
        if vmax > 1 + LIM:
            fail("vel-limit", c, "max |v|/VEL %.17g" % vmax)
        if amax > 1 + LIM:
            fail("acc-limit", c, "max |a|/ACC %.17g" % amax)
        if not jok:
            fail("jerk-values", c, "a jerk outside {0, ACCMAX/JERKMINx}")
        scale = max(1.0, abs(c["d"]))
        if c["beyond"] <= 1e-9 * scale:
            worst["over"] = max(worst["over"], over / scale)
            if over > 1e-9 * scale:
                fail("no-overshoot", c, "went %.3g past the target" % over)
        worst["snap"] = max(worst["snap"], snap / scale)
        if snap > 1e-9 * scale:
            fail("snap-small", c, "planned end %.3g from the target" % snap)
    names = ["duration-rest", "duration-moving", "samples-rest", "samples-moving", "final-exact",
             "vel-limit", "acc-limit", "jerk-values", "no-overshoot", "snap-small"]
    for name in names:
        if name in fails:
            print("FAIL: ljprof-ruckig/%s: %d cases, first: %s" % (name, len(fails[name]), fails[name][0]))
        else:
            print("PASS: ljprof-ruckig/%s" % name)
    iters.sort()
    print("info: %d cases; worst duration rel %.3g; max |v|/VEL %.17g; max |a|/lim %.17g; "
          "overshoot %.3g; snap %.3g (relative to the distance); root steps median %d max %d"
          % (len(cases), worst["rel"], worst["v"], worst["a"], worst["over"], worst["snap"],
             iters[len(iters) // 2], iters[-1]))
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
