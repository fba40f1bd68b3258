#!/usr/bin/env python3
"""LJPROF benchmark: what a re-plan costs per call in stc's generated C, and
how the planned durations compare with Ruckig's on thousands of moves.

    bench.py REPLAN DRIVE [CASES]

REPLAN is bench/ljprof/replan.c built with tests/ljprof/drive.st and
st/parts/ljprof.st at -O2; DRIVE the test harness of tests/ljprof (the same
block, sampled).  The Ruckig comparison is tests/ljprof/ruckig_peer.py run
on more cases and another seed.  Prints the figures and the verdicts against
the targets: p99 of a re-plan call <= 5 us, durations within 1e-6 of
Ruckig's.
"""
import os
import re
import subprocess
import sys

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))


def main():
    replan, drive = sys.argv[1], sys.argv[2]
    cases = int(sys.argv[3]) if len(sys.argv) > 3 else 3000
    print("== LJPROF re-plan cost (stc's generated C, -O2, one core, timed call by call)")
    out = subprocess.run([replan, "20000"], capture_output=True, text=True, check=False)
    print(out.stdout, end="")
    m = re.search(r"replan call \(POSA\): n \d+\s+p50 (\d+) ns\s+p99 (\d+) ns", out.stdout)
    ok = out.returncode == 0 and m is not None
    if m:
        p99 = int(m.group(2))
        print("target p99 <= 5000 ns: %s (p99 %d ns)" % ("met" if p99 <= 5000 else "MISSED", p99))
        ok = ok and p99 <= 5000
    print("== LJPROF planned durations against Ruckig (%d random moves, seed 7)" % cases)
    out = subprocess.run([sys.executable, os.path.join(root, "tests/ljprof/ruckig_peer.py"), drive,
                          str(cases), "7"], capture_output=True, text=True, check=False)
    print(out.stdout, end="")
    ok = ok and out.returncode == 0
    print("verdict: %s" % ("all targets met" if ok else "a target MISSED"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
