#!/usr/bin/env python3
"""The CAM printing example with master marker (examples/cam_printing)
under the real plcrt: engaging over pair 1, prints landing on irregular
boxes after marker correction, disengaging over pair 2 to 0 degrees.

usage: test_cam_printing.py PLCRT EXAMPLE_INI WORKDIR
Prints PASS:/FAIL: lines; exits 1 if anything failed.

Expected values, from the seed's example and closed forms:
- engaging only while the curve's master is inside start/stop pair 1
  (1000 .. 1500), disengaging inside pair 2 (2500 .. 3000); stopped, the
  set-point is the Slave Stop Position 0 plus whole turns (3600 UU) and the
  roller stands there;
- synchronous: the set-point is the seed's curve (scipy, camref.py) at the
  master position the curve sees;
- a print (the curve's MCPOS passing the Master Marker Position 1000) lands
  on the box front: the box was latched at the beam 2375 MU before the
  processing point, so at a print the master has run (count - latch) x
  55/2048 = 2375 + (MCPOS - 1000) MU since its marker, to 0.5 MU (0.05 mm;
  a count is 0.027 MU). The beam's markers deviate by 80 +- 50 MU from the
  box pitch (cam_printing.ini): uncorrected, the prints would miss by that."""
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from camref import Curve  # noqa: E402
from exlib import Mb, finish, report, start_example, stop_and_exit_check  # noqa: E402

PLCRT, INI, WORK = sys.argv[1], sys.argv[2], sys.argv[3]
OBS = 10          # %MD10..22, see the README
STOP = 1          # coil
CURVE = Curve([(0, 0, False), (1500, 1200, True), (2500, 2400, False), (4000, 3600, False)])
QC_MU = 55 / 2048
LAND_TOL = 0.5    # MU


def main():
    p, port = start_example("cam_printing", PLCRT, INI, WORK)

    def body():
        m = Mb(port)
        samples, prints = [], {}
        t0 = time.monotonic()
        stop_at = None
        while time.monotonic() - t0 < 9.0:
            v = m.md(OBS, 13)
            samples.append(v)
            if v[9] > 0:
                prints[v[9]] = (v[6], v[7], v[8])
            if stop_at is None and len(prints) >= 3:
                m.set_coil(STOP, True)
                stop_at = len(samples)
            if v[4] == 6 and stop_at is not None and len(samples) > stop_at + 30:
                break
            time.sleep(0.01)
        states = [v[4] for v in samples]
        order = [s for i, s in enumerate(states) if i == 0 or s != states[i - 1]]
        report(f"cam_printing: STATE runs waiting, engaging, synchronous, waiting for pair 2, "
               f"disengaging, stopped: {order}", order[-5:] == [2, 3, 4, 5, 6]
               and (order[1:] if order[0] == 0 else order)[0] in (1, 2), order)
        eng = [v[1] / 1000 for v in samples if v[4] == 2]
        dis = [v[1] / 1000 for v in samples if v[4] == 5]
        report(f"cam_printing: engaging only inside pair 1, 1000 .. 1500 ({len(eng)} samples, "
               f"{min(eng, default=0):.0f} .. {max(eng, default=0):.0f})",
               len(eng) > 3 and all(1000 <= x <= 1500 for x in eng), eng)
        report(f"cam_printing: disengaging only inside pair 2, 2500 .. 3000 ({len(dis)} samples, "
               f"{min(dis, default=0):.0f} .. {max(dis, default=0):.0f})",
               len(dis) > 3 and all(2500 <= x <= 3000 for x in dis), dis)
        sync = [v for v in samples if v[4] == 3]
        err = max((abs(v[2] / 1000 - CURVE.mod_rise(CURVE(v[1] / 1000), v[2] / 1000)) for v in sync), default=1e9)
        report(f"cam_printing: synchronous, the set-point on the seed's curve (scipy) at MCPOS "
               f"({len(sync)} samples, worst {err:.4f} UU)", len(sync) > 50 and err < 0.01, err)
        land, devs = [], []
        for n in sorted(prints):
            mc, mcpos, latch = prints[n]
            run_mu = (mc - latch) * QC_MU
            land.append((mcpos / 1000 - 1000) - (run_mu - 2375))
            devs.append((latch * QC_MU + 2000) % 4000 - 2000)     # a box every 4000 MU from count 0
        report(f"cam_printing: {len(prints)} prints, each on its box front within {LAND_TOL} MU "
               f"({', '.join(f'{x:+.3f}' for x in land)} MU)",
               len(land) >= 3 and all(abs(x) <= LAND_TOL for x in land), land)
        report(f"cam_printing: the boxes came irregularly, {min(devs, default=0):.1f} .. "
               f"{max(devs, default=0):.1f} MU off the 4000 MU pitch (the correction mattered)",
               len(devs) >= 3 and min(abs(d) for d in devs) > 20 and max(devs) - min(devs) > 5, devs)
        last = samples[-1]
        sp = last[2] / 1000
        report(f"cam_printing: stopped at the Slave Stop Position 0 degrees ({sp:.3f} UU, whole turns of 3600)",
               last[4] == 6 and abs(sp - round(sp / 3600) * 3600) < 0.01, sp)
        time.sleep(0.3)
        a = m.md(OBS + 3)
        time.sleep(0.2)
        b = m.md(OBS + 3)
        report(f"cam_printing: the roller stands there ({a * 9 / 25:.1f}, {b * 9 / 25:.1f} UU)",
               abs(b - a) <= 2 and abs(b * 9 / 25 - sp) <= 1.0, (a, b, sp))
        stop_and_exit_check("cam_printing", m, p)

    finish("cam_printing", body)


if __name__ == "__main__":
    main()
