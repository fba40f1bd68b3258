#!/usr/bin/env python3
"""The PLCopen example (examples/plcopen) under the real plcrt: two EPICPOS
axes driven only through MC_* blocks (power, home, move absolute, gear-in,
velocity, stop, gear-out), watched over Modbus.

usage: test_plcopen.py PLCRT EXAMPLE_INI WORKDIR
Prints PASS:/FAIL: lines; exits 1 if anything failed.

Expected values from examples/plcopen/README.md and docs/plcopen.md
(register map: docs/examples.md):
- MC_MoveAbsolute ends with the set-point on Position: the set-points when
  Y gears in are the targets (%MD0, %MD1) exactly;
- MC_GearIn: the slave's device takes in cycle k the set-point the block
  computed from the master's set-point of cycle k-1, so
  |(sy - y0) - (sx - x0) * rnum / rden| <= |vx| * 1 ms * rnum / rden + 1 Um
  of rounding, with X at half the move speed (10000 Um/s): 6 Um (one
  cycle more per period that overruns skipped meanwhile);
- states while X runs MC_MoveVelocity: X ContinuousMotion (4), Y
  SynchronizedMotion (5); while MC_Stop is held: X Stopping (6);
- at rest after MC_GearOut both axes in Standstill (1), each within the
  program's toll (2 Um) of its set-point;
- a target beyond maxpos: MC_MoveAbsolute Error 7 (software limit)."""
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from exlib import MD, Mb, finish, report, s32, start_example, stop_and_exit_check, wait_for  # noqa: E402

PLCRT, INI, WORK = sys.argv[1], sys.argv[2], sys.argv[3]
ENABLE, CYCLE, HOME, GO, JOG, GEAR, STOP, RESET = range(8)     # coils
TARGETX, TARGETY, SPEED, RNUM, RDEN = 0, 1, 2, 3, 4             # %MD0..4
TOLL = 2
NAMES = ["statex", "statey", "setptx", "setpty", "posx", "posy", "gearx0", "geary0",
         "lasterr", "steps", "phase", "ingear"]                   # %MD10..%MD21


def status(m):
    r = m.regs(MD + 2 * 10, 2 * len(NAMES))                     # one request: one PLC cycle
    return dict(zip(NAMES, (s32(r[2 * i], r[2 * i + 1]) for i in range(len(NAMES)))))


def main():
    p, port = start_example("plcopen", PLCRT, INI, WORK)

    def body():
        m = Mb(port)
        tx, ty, speed, rnum, rden = m.md(TARGETX, 5)
        report("plcopen: the README's set-up (targets 50000 and 20000 Um, 20000 Um/s, ratio 1:2)",
               (tx, ty, speed, rnum, rden) == (50000, 20000, 20000, 1, 2), (tx, ty, speed, rnum, rden))
        ratio = rnum / rden
        s = wait_for(lambda: (lambda s: s if s["phase"] >= 1 else None)(status(m)), 15.0)
        report("plcopen: both axes powered and homed within 15 s (the sequence at the moves)",
               bool(s) and s["lasterr"] == 0, s or status(m))

        # the gearing, sampled while X runs backward (phase 4)
        s = wait_for(lambda: (lambda s: s if s["phase"] == 4 else None)(status(m)), 15.0)
        report("plcopen: the sequence reaches the velocity move with Y geared within 15 s", bool(s), status(m))
        if s:
            report("plcopen: MC_MoveAbsolute ended both set-points on their targets (seen when Y geared in)",
                   (s["gearx0"], s["geary0"]) == (tx, ty), (s["gearx0"], s["geary0"]))
            skipped0 = m.diag(4)        # periods skipped by overruns (docs/modbus.md)
            samples = []
            while True:
                s = status(m)
                if s["phase"] != 4:
                    break
                samples.append(s)
                time.sleep(0.02)
            # a scan that came late skips periods and PLC time jumps over
            # them (docs/runtime.md): X's profile then moves on by as many
            # cycles in one scan, and Y, a cycle behind, lags by as many more
            skipped = m.diag(4) - skipped0
            bound = speed / 2.0 * 0.001 * (1 + skipped) * ratio + 1.0
            worst = max((abs((x["setpty"] - x["geary0"]) - (x["setptx"] - x["gearx0"]) * ratio)
                         for x in samples), default=None)
            report(f"plcopen: Y's set-point follows X's at {rnum}:{rden} within {bound:g} Um "
                   f"({len(samples)} samples over the velocity move)",
                   len(samples) >= 20 and worst is not None and worst <= bound,
                   f"worst {worst}, {skipped} periods skipped by overruns meanwhile")
            report("plcopen: during the velocity move X is in ContinuousMotion (4), Y in SynchronizedMotion (5)",
                   all(x["statex"] == 4 and x["statey"] == 5 and x["ingear"] == 1 for x in samples),
                   sorted({(x["statex"], x["statey"], x["ingear"]) for x in samples}))
            moved = samples[0]["setptx"] - samples[-1]["setptx"] if samples else 0
            report("plcopen: X runs backward (more than 10000 Um over the samples) and Y half as far",
                   moved > 10000 and abs((samples[0]["setpty"] - samples[-1]["setpty"]) - moved * ratio)
                   <= 2 * bound, (moved, samples[0]["setpty"] - samples[-1]["setpty"] if samples else 0))
        # MC_Stop held: Stopping
        stopping = wait_for(lambda: (lambda s: s if s["phase"] == 5 and s["statex"] == 6 else None)(status(m)), 5.0)
        report("plcopen: MC_Stop held: X in Stopping (6), Y still geared (5)",
               bool(stopping) and stopping["statey"] == 5, stopping or status(m))
        # geared out, at rest
        s = wait_for(lambda: (lambda s: s if s["phase"] == 7 else None)(status(m)), 5.0)
        if s:
            time.sleep(0.5)
            s = status(m)
        report("plcopen: after MC_GearOut both axes in Standstill, each within toll of its set-point",
               bool(s) and s["statex"] == 1 and s["statey"] == 1 and s["ingear"] == 0
               and abs(s["posx"] - s["setptx"]) <= TOLL and abs(s["posy"] - s["setpty"]) <= TOLL,
               s or status(m))
        steps0 = status(m)["steps"]
        s = wait_for(lambda: (lambda s: s if s["steps"] >= steps0 + 5 else None)(status(m)), 12.0)
        report("plcopen: the sequence goes round again (5 more steps), no block in Error",
               bool(s) and s["lasterr"] == 0, s or status(m))

        # by hand (the sequence off in its pause, both axes still): a target beyond maxpos
        wait_for(lambda: (lambda s: s if s["phase"] == 7 else None)(status(m)), 12.0)
        m.set_coil(CYCLE, 0)
        m.set_md(TARGETX, 1500000)
        m.set_coil(GO, 1)
        s = wait_for(lambda: (lambda s: s if s["lasterr"] != 0 else None)(status(m)), 3.0)
        report("plcopen: by hand, MC_MoveAbsolute to 1500000 Um (beyond maxpos): Error 7",
               bool(s) and s["lasterr"] == 7, s or status(m))
        m.set_coil(GO, 0)
        m.set_md(TARGETX, tx)
        stop_and_exit_check("plcopen", m, p)

    finish("plcopen", body)


main()
