#!/usr/bin/env python3
"""The seed 001 tuning procedure, automated (tools/aposs_tune.py), on the
APOSS example (examples/aposs) under the real plcrt: the seed's own example
(VELMAX 1400 rpm, a drive reaching 1600 rpm at 10 V) must give FFVEL =
1400 / 1600 x 1000 = 875 within 1 %, never trip POSERR, leave KPROP at 70 %
of the gain where the axis began to oscillate, and make the test move
follow better than before.
  test_tune.py PLCRT EXAMPLE.ini WORKDIR"""
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "examples"))
import exlib  # noqa: E402
from exlib import Plcrt, free_port, report  # noqa: E402


def main():
    exe, ini, work = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    for f in os.listdir(work):      # plots of an earlier run must not count
        if f.startswith("aposs-tune-"):
            os.remove(os.path.join(work, f))
    port = free_port()
    cfg = exlib.example_ini(ini, os.path.join(work, "tune.ini"), port, "")
    plc = Plcrt(exe, cfg, work, "aposs-tune")
    try:
        r = subprocess.run([sys.executable, os.path.join(HERE, "..", "..", "tools", "aposs_tune.py"),
                            "--port", str(port), "--out", work], capture_output=True, text=True, timeout=400)
        with open(os.path.join(work, "tune.out"), "w") as f:
            f.write(r.stdout + r.stderr)
        report("apossaxis/tune: the tool ran to its end (no error on the axis, no POSERR trip)",
               r.returncode == 0, (r.stdout + r.stderr)[-800:])
        m = re.search(r"^gains: (.*)$", r.stdout, re.M)
        g = {}
        if m:
            it = m.group(1).split()
            g = {it[i]: int(it[i + 1]) for i in range(0, len(it), 2)}
        ffvel = g.get("FFVEL", -1)
        report("apossaxis/tune: FFVEL within 1 % of 1400/1600 x 1000 = 875",
               abs(ffvel - 875) <= 8.75, f"FFVEL {ffvel}")
        kp, kosc = g.get("KPROP", -1), g.get("KPROP_OSC", -1)
        report("apossaxis/tune: KPROP is 70 % of the gain where the standstill began to oscillate",
               kosc > 0 and abs(kp - 0.7 * kosc) <= 1, f"KPROP {kp}, oscillating from {kosc}")
        mb = exlib.Mb(port)
        try:
            r2 = mb.c.read_input_registers(1154, 1, slave=1)
            errnum = r2.registers[0] if not r2.isError() else -1
        finally:
            mb.close()
        report("apossaxis/tune: the axis has no error after tuning (no POSERR trip, error 8)",
               errnum == 0, f"ERRNUM {errnum}")
        fe = re.findall(r"following error RMS ([0-9.]+) qc", r.stdout)
        ok = len(fe) >= 2 and float(fe[-1]) < 0.1 * float(fe[0])
        report("apossaxis/tune: the test move follows at least 10 times closer after tuning than before",
               ok, f"RMS before/after {fe[:1]} {fe[-1:]}")
        report("apossaxis/tune: plots of the runs before and after",
               all(os.path.getsize(os.path.join(work, f"aposs-tune-{w}.png")) > 1000 for w in ("before", "after"))
               if all(os.path.exists(os.path.join(work, f"aposs-tune-{w}.png")) for w in ("before", "after"))
               else False, "missing")
    finally:
        plc.stop()
    return 1 if exlib.failed else 0


if __name__ == "__main__":
    sys.exit(main())
