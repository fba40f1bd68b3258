#!/usr/bin/env python3
"""The multi-axis example (examples/multiaxis) under the real plcrt: three
EPICPOS axes on one DAC, positioned one at a time, watched over Modbus.

usage: test_multiaxis.py PLCRT EXAMPLE_INI WORKDIR
Prints PASS:/FAIL: lines; exits 1 if anything failed.

Expected behaviour from examples/multiaxis/README.md, docs/examples.md (the
register map) and docs/epicpos.md
("Several axes on one DAC"): one axis regulated at a time, each positioned to
its quota (and back to 0) within its toll of 2 Um, the others parked; the
plant of each axis (sim backend, 1 count = 1 Um) is the independent witness."""
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from exlib import Mb, finish, report, start_example, stop_and_exit_check, wait_for  # noqa: E402
from onecycle import View  # noqa: E402

PLCRT, INI, WORK = sys.argv[1], sys.argv[2], sys.argv[3]
RUN, ON = 0, 1                  # coils: run, axis 1..3 on the DAC (1..3)
QUOTAS, SPEED, STATUS = 0, 3, 10   # %MD0..2 quotas, %MD3 speed, %MD10..14 pos1..3, current, moves
TOLL = 2                        # the program's toll for all three axes
# a released axis keeps the shared DAC's last value for at most the cycle
# before the drive is switched (docs/epicpos.md: the DAC keeps its value):
# well under one count at the last regulation's small output
PARK = TOLL + 1


# the coils, the status registers and the three plants, read in one request
# (so from one cycle: tests/common/onecycle.py)
P = "CONFIG0.RES0.AXES."
VIEW = View([(f"on{i}", f"{P}ON{i}", "BOOL") for i in (1, 2, 3)]
            + [(f"pos{i}", f"{P}POS{i}", "DINT") for i in (1, 2, 3)]
            + [("cur", P + "CURRENT", "DINT"), ("moves", P + "MOVES", "DINT")], sim_axes=3)


def snapshot(m):
    """One cycle's view of the axes, the DAC switch and the plants."""
    v = VIEW.read(m.c)
    return {"t": time.monotonic(), "pos": [v["pos1"], v["pos2"], v["pos3"]], "cur": v["cur"],
            "moves": v["moves"], "on": [bool(v[f"on{i}"]) for i in (1, 2, 3)],
            "sim": [pos for pos, _ in v["sim"]]}


def watch(m, secs, quotas, log):
    """Sample for secs; returns the problems found (at most a few)."""
    bad = []
    end = time.monotonic() + secs
    while time.monotonic() < end:
        s = snapshot(m)
        log.append((s, list(quotas)))
        if sum(s["on"]) > 1:
            bad.append(f"{sum(s['on'])} axes on the DAC at once: {s}")
        for i in range(3):
            if i + 1 == s["cur"]:
                continue
            if min(abs(s["pos"][i]), abs(s["pos"][i] - quotas[i])) > PARK:
                bad.append(f"axis {i + 1} parked at {s['pos'][i]}, neither 0 nor its quota {quotas[i]}: {s}")
        time.sleep(0.01)
    return bad[:3]


def reached(log, axis, target):
    """Samples where axis was parked (not being positioned) within toll of target."""
    return [s for s, _ in log if s["cur"] != axis + 1 and abs(s["pos"][axis] - target) <= TOLL]


def main():
    p, port = start_example("multiaxis", PLCRT, INI, WORK, VIEW)

    def body():
        m = Mb(port)
        quotas = m.md(QUOTAS, 3)
        report("multiaxis: the quota registers hold three different quotas, all beyond 1000 Um from 0",
               len(set(quotas)) == 3 and all(abs(q) > 1000 for q in quotas), quotas)
        s0 = snapshot(m)
        log = []
        bad = watch(m, 5.0, quotas, log)
        s1 = snapshot(m)
        report("multiaxis: never more than one axis on the DAC; the axes not being positioned "
               f"are parked within {PARK} Um of 0 or of their quota ({len(log)} samples)", not bad, "; ".join(bad))
        for i in range(3):
            at = reached(log, i, quotas[i])
            report(f"multiaxis: axis {i + 1} is positioned to its quota {quotas[i]} within toll", bool(at),
                   f"positions seen while parked: {sorted(set(s['pos'][i] for s, _ in log if s['cur'] != i + 1))[:10]}")
            if at:
                s = at[-1]
                report(f"multiaxis: axis {i + 1} at its quota: posit is the plant's position",
                       abs(s["pos"][i] - s["sim"][i]) <= 1, f"posit {s['pos'][i]}, plant {s['sim'][i]}")
        home = []
        for i in range(3):
            at = [k for k, (s, _) in enumerate(log) if s["cur"] != i + 1 and abs(s["pos"][i] - quotas[i]) <= TOLL]
            home.append(bool(at) and any(s["cur"] != i + 1 and abs(s["pos"][i]) <= TOLL for s, _ in log[at[0]:]))
        report("multiaxis: after the round of quotas each axis goes back to 0 within toll", all(home), home)
        seen = [(s["cur"], s["on"]) for s, _ in log]
        wrong = [(cur, on) for cur, on in seen if 1 <= cur <= 3 and any(on) and not on[cur - 1]]
        report("multiaxis: the axis on the DAC is the one being positioned, each in turn",
               not wrong and {c for c, _ in seen} - {0} == {1, 2, 3},       # 0: before the first cycle
               f"current vs on: {wrong[:5]} of {len(seen)} samples; {seen[:: max(1, len(seen) // 20)]}")
        done = s1["moves"] - s0["moves"]
        report("multiaxis: positionings done increases (at least 4 in 5 s at 50000 Um/s)", done >= 4,
               f"{s0['moves']} -> {s1['moves']}")

        # a new quota over Modbus is used by the next round
        m.set_md(QUOTAS + 1, -7000)
        quotas = [quotas[0], -7000, quotas[2]]
        log2 = []
        ok = wait_for(lambda: (watch(m, 0.3, quotas, log2) or True) and reached(log2, 1, -7000), 12.0)
        report("multiaxis: a quota written over Modbus (axis 2 := -7000) is reached in a later round",
               bool(ok), sorted(set(s["pos"][1] for s, _ in log2))[-10:])

        # run off: the cycle stops after the move in progress, nothing moves
        m.set_coil(RUN, 0)
        time.sleep(1.5)
        a = snapshot(m)
        time.sleep(0.5)
        b = snapshot(m)
        moved = max(abs(x - y) for x, y in zip(a["sim"], b["sim"]))
        report("multiaxis: run coil off: no new positioning, the axes stay still",
               a["moves"] == b["moves"] and moved <= 1, f"moves {a['moves']} -> {b['moves']}, plants moved {moved}")
        m.set_coil(RUN, 1)
        ok = wait_for(lambda: snapshot(m)["moves"] > b["moves"], 3.0)
        report("multiaxis: run coil on again: positioning resumes", bool(ok))
        stop_and_exit_check("multiaxis", m, p)

    finish("multiaxis", body)


main()
