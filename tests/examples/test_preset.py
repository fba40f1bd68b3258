#!/usr/bin/env python3
"""The preset search example (examples/preset) under the real plcrt: preset
modes 0, 1 and 2 against the simulated home cam and zero pulse, watched over
Modbus.

usage: test_preset.py PLCRT EXAMPLE_INI WORKDIR
Prints PASS:/FAIL: lines; exits 1 if anything failed.

Expected counts from examples/preset/README.md (register map:
docs/examples.md) and the plant of
examples/preset/preset.ini (1 count = 1 Um; cam on over counts
20000..22000; zero pulse at 1000 + 4000 k, latched exactly):
- mode 0: the preset is loaded where the cam goes off on the slow way back
  (sprsvel 2000 Um/s, the program's): the first count off the cam is 19999,
  and the block sees the cam within a regulation sample (2 ms) and a cycle
  (1 ms) of it, 2 counts each: 19990..19999 leaves a margin;
- mode 1: the latched zero pulse 17000 crossed backwards: 16999 exactly;
- mode 2: loaded in every cycle while the cam is on, the axis crossing it at
  setvel 20000 Um/s = 20 counts per cycle: the last load is within one cycle
  below the upper edge, 21975..22000 with a margin."""
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from exlib import Mb, finish, ini_section, report, start_example, stop_and_exit_check, wait_for  # noqa: E402
from onecycle import View  # noqa: E402

PLCRT, INI, WORK = sys.argv[1], sys.argv[2], sys.argv[3]
RUN = 0                                # coil
PRSPOS, STATUS = 0, 10                 # %MD0; %MD10..15 mode, posit, count0..2, searches
TOLL = 2                               # the program's toll
SIM = ini_section(INI, "sim.axis0")
CAM_LO, CAM_HI = int(SIM["cam_low"]), int(SIM["cam_high"])
ZOFF, CPR = int(SIM["zero_offset"]), int(SIM["counts_per_rev"])
ZERO = ZOFF + ((CAM_LO - 1 - ZOFF) // CPR) * CPR      # the last zero pulse below the cam: 17000
BANDS = {0: (CAM_LO - 10, CAM_LO - 1), 1: (ZERO - 1, ZERO - 1), 2: (CAM_HI - 25, CAM_HI)}


# the status registers and the two state coils in one request (one cycle)
PRG = "CONFIG0.RES0.PRESETS."
VIEW = View([(n, PRG + n.upper(), "DINT") for n in ("mode", "posit", "count0", "count1", "count2", "searches")]
            + [(n, PRG + n.upper(), "BOOL") for n in ("prson", "prsok")])


def status(m):
    v = VIEW.read(m.c)
    return {"mode": v["mode"], "posit": v["posit"], "count": [v["count0"], v["count1"], v["count2"]],
            "searches": v["searches"], "prson": bool(v["prson"]), "prsok": bool(v["prsok"])}


def main():
    p, port = start_example("preset", PLCRT, INI, WORK, VIEW)

    def body():
        m = Mb(port)
        prspos = 1234                  # before the first PRESET (the axis first moves to count 8000)
        m.set_md(PRSPOS, prspos)
        s = status(m)
        report("preset: the cycle starts with mode 0 and nothing recorded",
               s["mode"] == 0 and s["searches"] == 0 and s["count"] == [0, 0, 0], s)

        ends, prson_seen, last = {}, set(), status(m)
        t0 = time.monotonic()
        while time.monotonic() - t0 < 25 and len(ends) < 3:
            s = status(m)
            if s["prson"]:
                prson_seen.add(s["mode"])
            if s["searches"] > last["searches"]:
                mode = last["mode"]
                # the program waits 500 cycles after each search: the axis rests there
                time.sleep(0.3)
                s2 = status(m)
                ends[mode] = dict(s2 if s2["searches"] == s["searches"] else s,
                                  prsok=s["prsok"] and (s2["prsok"] or s2["searches"] != s["searches"]),
                                  prson=s["prson"] or (s2["prson"] and s2["searches"] == s["searches"]))
            last = s
            time.sleep(0.005)
        report("preset: preset.ini's plant is the README's (cam 20000..22000, zero pulses at 1000 + 4000 k)",
               (CAM_LO, CAM_HI, ZOFF, CPR, ZERO) == (20000, 22000, 1000, 4000, 17000),
               f"cam {CAM_LO}..{CAM_HI}, zero pulses at {ZOFF} + {CPR} k, last below the cam {ZERO}")
        report("preset: three searches, one per mode, within 25 s", sorted(ends) == [0, 1, 2], sorted(ends))
        for mode in sorted(ends):
            e = ends[mode]
            lo, hi = BANDS[mode]
            c = e["count"][mode]
            report(f"preset: mode {mode} put prspos at count {c} (README: "
                   f"{'about 20000' if mode == 0 else '16999' if mode == 1 else '22000, the upper cam edge'}; "
                   f"expected {lo}..{hi})", lo <= c <= hi, e)
            report(f"preset: after the mode {mode} search st_prsok is on and st_prson off",
                   e["prsok"] and not e["prson"], e)
            if mode in (0, 1):
                report(f"preset: mode {mode} ends positioned at prspos ({prspos}) within toll",
                       abs(e["posit"] - prspos) <= TOLL, f"posit {e['posit']}")
        report("preset: st_prson is on during the searches of modes 0, 1 and 2",
               prson_seen >= {0, 1, 2}, sorted(prson_seen))
        # the counts are positions of the plant: a second round finds the same
        m.set_md(PRSPOS, -300)
        again = wait_for(lambda: (lambda s: s if s["searches"] >= 4 else None)(status(m)), 10.0)
        if again:
            time.sleep(0.3)
            s = status(m)
            report("preset: a second mode 0 search with prspos -300: the same place on the cam, "
                   "the axis at -300", BANDS[0][0] <= s["count"][0] <= BANDS[0][1] and abs(s["posit"] + 300) <= TOLL, s)
        else:
            report("preset: a second mode 0 search", False, status(m))
        stop_and_exit_check("preset", m, p)

    finish("preset", body)


main()
