#!/usr/bin/env python3
"""The CAM box example (examples/cam_dryer) under the real plcrt: the seed's
drier, on for 300 ms from the pass of master curve position 2500.

usage: test_cam_dryer.py PLCRT EXAMPLE_INI WORKDIR
Prints PASS:/FAIL: lines; exits 1 if anything failed.

Expected values, independent of the program: the simulated conveyor runs at
4000 MU/s from 1000 (cam_dryer.ini; 1 count = 1 MU), so the master counter
is a clock: the drier's switch-on count is within one scan's travel (4 MU)
past 2500 + 4000 k, and its time on, (off - on)
/ 4000 MU/s, is 300 ms +- one cycle (1 ms). The plant's clock is the wall
clock at each scan, so a scan woken late at either edge, or periods skipped
by an overrun, move the measured time by as much: plcrt's own diagnostics
(worst wake latency, periods skipped) widen the band by that, and by one
count (0.25 ms) of the counter's resolution."""
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from exlib import Mb, finish, ini_section, report, start_example, stop_and_exit_check  # noqa: E402

PLCRT, INI, WORK = sys.argv[1], sys.argv[2], sys.argv[3]
DRIER = 1                     # coil
OBS = 10                      # %MD10..13: on count, off count, passes, master count
SPEED = float(ini_section(INI, "sim.master")["speed"])


def main():
    p, port = start_example("cam_dryer", PLCRT, INI, WORK)

    def body():
        m = Mb(port)
        report("cam_dryer: the plant is the README's (4000 MU/s)", SPEED == 4000, SPEED)
        seen, on_samples, t0 = [], 0, time.monotonic()
        last = None
        while time.monotonic() - t0 < 20 and len(seen) < 3:
            on_cnt, off_cnt, passes, _ = m.md(OBS, 4)
            if m.coils(DRIER):
                on_samples += 1
            if off_cnt > on_cnt and (last is None or off_cnt != last):
                seen.append((on_cnt, off_cnt, passes))
                last = off_cnt
            time.sleep(0.01)
        report(f"cam_dryer: three drier runs, one per master cycle: {len(seen)}, with "
               f"{seen[-1][2] if seen else 0} passes counted", len(seen) >= 3, seen)
        report("cam_dryer: coil 1 seen on while drying", on_samples > 10, on_samples)
        lat_ms = m.diag(18) / 1000.0          # worst wake latency, us
        skipped = m.diag(4)
        tol = 1.0 + lat_ms + skipped * 1.0 + 1000.0 / SPEED
        print(f"cam_dryer: worst wake latency {lat_ms:.3f} ms, periods skipped {skipped}: "
              f"band 300 +- {tol:.2f} ms", flush=True)
        for on_cnt, off_cnt, passes in seen:
            at = (on_cnt - 2500) % 4000
            dur = (off_cnt - on_cnt) / SPEED * 1000
            ptol = SPEED * (1.0 + lat_ms + skipped) / 1000.0 + 1
            report(f"cam_dryer: on at master {on_cnt} = 2500 + {at} (+ 4000 k), within one scan's travel "
                   f"(and the late wake-ups') past 2500: {ptol:.0f} MU", 0 <= at <= ptol, at)
            report(f"cam_dryer: on for {dur:.2f} ms: 300 ms +- {tol:.2f} ms", abs(dur - 300) <= tol, dur)
        if seen:
            passes = [n for _, _, n in seen]
            report("cam_dryer: one pass of 2500 per cycle counted (ONCOUNT one more at each run)",
                   all(b - a == 1 for a, b in zip(passes, passes[1:])) and passes[0] >= 1, seen)
        stop_and_exit_check("cam_dryer", m, p)

    finish("cam_dryer", body)


if __name__ == "__main__":
    main()
