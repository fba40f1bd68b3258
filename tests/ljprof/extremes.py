#!/usr/bin/env python3
"""LJPROF on extreme inputs: it never fails, whatever it is given.

    extremes.py DRIVE [CASES] [SEED]

Random limits over twelve decades (VEL, ACC, DEC, ACCMAX 1e-6..1e6, DEC/ACC
1e-3..1e3, jerk times 0 or 1e-3..1e4 ms), distances 0 or 1e-9..1e12, start
positions up to 1e9, start speeds and accelerations up to twice the limits
(beyond them the block first brings them back), sampled at 1 s so most moves
end within the sample budget.  Every case must plan (err 0), give finite
outputs, and every finished move must stop exactly
on its target.  Prints PASS:/FAIL: lines (root-search steps as information:
the search is bounded at 200, a few degenerate moves of 1e-20 s reach it).
"""
import math
import random
import subprocess
import sys


def main():
    drive = sys.argv[1]
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 4000
    rnd = random.Random(int(sys.argv[3]) if len(sys.argv) > 3 else 11)
    cases = []
    for _ in range(n):
        e = lambda a, b: 10 ** rnd.uniform(a, b)
        vel, acc, am = e(-6, 6), e(-6, 6), e(-6, 6)
        dec = acc * e(-3, 3)
        jm = [rnd.choice((0.0, e(-3, 4))) for _ in range(4)]
        d = rnd.choice((-1, 1)) * rnd.choice((0.0, e(-9, 12)))
        v0 = rnd.uniform(-2, 2) * vel * rnd.choice((0, 1))
        a0 = rnd.uniform(-2, 2) * min(acc, dec) * rnd.choice((0, 1))
        p0 = rnd.choice((0.0, e(-3, 9)))
        cases.append([p0, v0, a0, p0 + d, vel, acc, dec, am] + jm + [1000.0])
    inp = "".join(" ".join(repr(x) for x in c) + "\n" for c in cases)
    maxs = 20000
    out = subprocess.run([drive, str(maxs)], input=inp, capture_output=True, text=True, timeout=600)
    rows = [r for r in out.stdout.split("\n") if r]
    if out.returncode != 0 or len(rows) != len(cases):
        print("FAIL: ljprof-extremes/harness: exit %d, %d of %d results" % (out.returncode, len(rows), len(cases)))
        return 1
    bad = {"plans": [], "finite": [], "exact": []}
    finished = 0
    maxit = 0
    for c, r in zip(cases, rows):
        f = r.split()
        vals = [float(x) for x in f[:7]]
        err, it = int(f[7]), int(f[8])
        maxit = max(maxit, it)
        if err != 0 or not vals[0] >= 0.0:
            bad["plans"].append((c, r))
        if not all(math.isfinite(x) for x in vals):
            bad["finite"].append((c, r))
        if int(f[1]) < maxs:
            finished += 1
            if vals[2] != c[3]:
                bad["exact"].append((c, r))
    names = {"plans": "every case is accepted and planned, with a duration >= 0",
             "finite": "every output is a finite number",
             "exact": "every finished move stops exactly on its target"}
    for k, name in names.items():
        if bad[k]:
            print("FAIL: ljprof-extremes/%s: %d cases, first %r -> %s" % (name, len(bad[k]), bad[k][0][0], bad[k][0][1]))
        else:
            print("PASS: ljprof-extremes/%s" % name)
    print("info: %d cases, %d finished within %d samples, root steps max %d" % (len(cases), finished, maxs, maxit))
    return 1 if any(bad.values()) else 0


if __name__ == "__main__":
    sys.exit(main())
