#!/usr/bin/env python3
"""The EPICPOS example (examples/epicpos) under the real plcrt, driven over
Modbus as its README and docs/examples.md describe: start-up, START/STOP and manual inputs,
refused commands, emergency, bad Modbus input, RETAIN across restarts and
damaged retain files.

usage: test_epicpos.py PLCRT EXAMPLE_INI WORKDIR
Prints PASS:/FAIL: lines; exits 1 if anything failed.

Expected values come from examples/epicpos/README.md, docs/examples.md
(the register map), docs/epicpos.md,
docs/runtime.md and the simulated axis of the example's configuration
(1 count = 1 Um, 1666.667 Um/s at 10 V, the drive lag of its .ini); the overshoot of
the example's own tuning is predicted by the reference model below."""
import math
import os
import shutil
import re
import socket
import struct
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from exlib import MD, Mb, Plcrt, example_ini, free_port, report, wait_for  # noqa: E402
import exlib  # noqa: E402
from onecycle import Recording, View  # noqa: E402

PLCRT, INI, WORK = sys.argv[1], sys.argv[2], sys.argv[3]

# coils (docs/examples.md)
AVMAN, INMAN, START, STOP, OFTOLL, OFFERMO = 0, 1, 2, 3, 8, 9
CMD = {n: 16 + i for i, n in enumerate(
    "INIT EMRG RESUME START STOP LOOPON LOOPOFF CNTLOCK CNTUNLOCK CNTREV CNTDIR PRESET "
    "CALON CALOFF MANFW MANBW REGOFF REGON DELCNT WRPOSIT".split())}
ST = {n: 40 + i for i, n in enumerate(
    "init emrg toll prsok still prson movdir loopon foller regoff cal cntlock cntrev".split())}
# %MD numbers: set-up (0..30) and read-only values (40..53)
PARAMS = ("slQuotaPos slVelAsse cnratio maxpos minpos prspos maxvel prsvel sprsvel toll maxfollerr "
          "rampmode taccdec tacc tdec tinvt rtype stopt toldly pgain feedfw integt derivt prsmode "
          "prmdir unitvel decpt offset vout delta newposit").split()
P = {n: i for i, n in enumerate(PARAMS)}
POSIT, VEL, FOLTERR, REFCNT, REFCODE, PARERR, DACVAL = 40, 41, 43, 48, 49, 50, 51
# initial values: docs/examples.md (slQuotaPos 2000, slVelAsse 50) and docs/epicpos.md's defaults,
# which are the seed's example values (1.6)
DEFAULTS = {"slQuotaPos": 2000, "slVelAsse": 50, "cnratio": 100000, "maxpos": 999999,
            "minpos": -999999, "maxvel": 100000, "toll": 5, "taccdec": 100, "toldly": 10,
            "pgain": 10, "feedfw": 1000}

# what a check compares, read in one request (so from one cycle): the
# program's posit, vel and state coils and the plant (tests/common/onecycle.py)
PRG = "CONFIG0.RES0.AXIS."
VIEW = View([(n, PRG + n.upper(), "DINT") for n in ("posit", "vel", "folterr", "dacval", "refcnt", "refcode")]
            + [(n, PRG + n.upper(), "BOOL") for n in ("ofToll", "ofAxeFermo")]
            + [(n, PRG + "ST_" + n.upper(), "BOOL") for n in ST], sim_axes=1)


def snap(m):
    """One cycle: posit, vel, folterr, dacval, refcnt, refcode, ofToll,
    ofAxeFermo, the states by name ('st') and the plant ('x', 'v')."""
    v = VIEW.read(m.c)
    v["st"] = {n: bool(v[n]) for n in ST}
    v["x"], v["v"] = v["sim"][0]
    return v


MAXVEL_UMS = 100000 / 60.0      # maxvel, Um/min -> Um/s
SIM = exlib.ini_section(INI, "sim.axis0")
LAG = float(SIM["lag"])         # the drive's time constant, s
SIM_MAXVEL = float(SIM["maxvel"])   # counts/s at 10 V (1 count = 1 Um)
TCAMP = 0.004                   # the seed's TCamp 0004 (1.6)


def model_overshoot(dist, vpct, taccdec, pgain, feedfw=1000):
    """Reference model of a START move as docs/epicpos.md defines it: an
    epicycloidal profile (ramp time taccdec/100 s from 0 to maxvel), every
    tcamp feed-forward (the profile's mean speed over the coming sample) +
    pgain/1000 x 32767 x error / (maxvel x tcamp), error against the counted
    (whole) position; the example's drive: first-order lag, 1666.667 Um/s at
    10 V, stepped by the PLC's 1 ms. Returns the peak beyond the quota, Um."""
    v = vpct / 100.0 * MAXVEL_UMS
    tr = taccdec / 100.0 * v / MAXVEL_UMS
    dr = tr * v / 2
    if 2 * dr > dist:
        raise ValueError("model covers moves that reach their speed")
    tc = (dist - 2 * dr) / v

    def ramp(u):
        return v * tr * (u * u / 2 + (math.cos(2 * math.pi * u) - 1) / (4 * math.pi ** 2))

    def sp(t):
        if t <= 0:
            return 0.0
        if t < tr:
            return ramp(t / tr)
        if t < tr + tc:
            return dr + v * (t - tr)
        if t < 2 * tr + tc:
            s = t - tr - tc
            return dr + v * tc + v * s - ramp(s / tr)
        return float(dist)

    x = vm = u = peak = 0.0
    k_samp = round(TCAMP / 0.001)
    for k in range(int((2 * tr + tc + 1.0) * 1000)):
        t = k * 0.001
        if k % k_samp == 0:
            ff = (sp(t + TCAMP) - sp(t)) / TCAMP
            u = feedfw / 1000.0 * ff / MAXVEL_UMS + pgain / 1000.0 * (sp(t) - math.floor(x)) / (MAXVEL_UMS * TCAMP)
            u = max(-1.0, min(1.0, round(u * 32767) / 32767))
        for _ in range(10):
            vm += (u * SIM_MAXVEL - vm) * (1 - math.exp(-0.0001 / LAG))
            x += vm * 0.0001
        peak = max(peak, x)
    return peak - dist


# ---- helpers ----

def state(m):
    b = m.coils(40, 13)
    return {n: b[i] for i, n in enumerate(ST)}


def params(m):
    return dict(zip(PARAMS, m.md(0, 31)))


def pulse(m, coil, until=None, timeout=0.5):
    """Input coil on until the program has seen it (until(), or 50 ms), then off."""
    m.set_coil(coil, 1)
    if until:
        wait_for(until, timeout, 0.002)
    else:
        time.sleep(0.05)
    m.set_coil(coil, 0)


def command(m, name):
    m.set_coil(CMD[name], 1)
    time.sleep(0.03)


def start_move(m, quota):
    m.set_md(P["slQuotaPos"], quota)
    pulse(m, START, lambda: not m.coils(ST["still"]))


def move(m, quota, timeout):
    """START to quota, follow the move until still in tolerance (or timeout):
    (last state, posit)."""
    start_move(m, quota)
    _, s = follow(m, timeout)
    return s, m.md(POSIT)


def follow(m, timeout, done=lambda s: s["still"] and s["toll"]):
    """Sample posit, vel and the plant while waiting for done(state);
    returns (samples, last state). A sample: (t, posit, vel, sim position,
    [ofToll, ofAxeFermo], st_still), all of one cycle."""
    samples, t0 = [], time.monotonic()
    while True:
        v = snap(m)
        s = v["st"]
        samples.append((time.monotonic() - t0, v["posit"], v["vel"], v["x"],
                        [bool(v["ofToll"]), bool(v["ofAxeFermo"])], s["still"]))
        if done(s) or time.monotonic() - t0 > timeout:
            return samples, s


def still_for(m, secs):
    """How far the plant and posit stray over secs from where they are now
    (counts, Um): 0 for an axis at rest, within toll for one settling."""
    v0 = snap(m)
    dx = dp = 0
    end = time.monotonic() + secs
    while time.monotonic() < end:
        v = snap(m)
        dx = max(dx, abs(v["x"] - v0["x"]))
        dp = max(dp, abs(v["posit"] - v0["posit"]))
        time.sleep(0.02)
    return dx, dp


def settle(m, timeout=3.0):
    """Wait until posit has not changed for 0.3 s (the loop creeps the last
    counts after st_toll)."""
    end, last, since = time.monotonic() + timeout, None, time.monotonic()
    while time.monotonic() < end:
        p = m.md(POSIT)
        if p != last:
            last, since = p, time.monotonic()
        elif time.monotonic() - since >= 0.3:
            return True
        time.sleep(0.02)
    return False


def new_plcrt(tag, retain, period=None):
    port = free_port()
    cfg = VIEW.add_to(example_ini(INI, os.path.join(WORK, f"epicpos-{tag}.ini"), port, retain, period))
    p = Plcrt(PLCRT, cfg, WORK, "epicpos")
    return p, Mb(port)


def run(name, fn, *args):
    t0 = time.monotonic()
    try:
        return fn(*args)
    except Exception as e:  # noqa: BLE001
        report(name, False, repr(e))
        return None
    finally:
        print(f"# {name}: {time.monotonic() - t0:.1f} s", flush=True)


# ---- tests on one running plcrt ----

def t_startup(m):
    s = wait_for(lambda: (lambda s: s if s["loopon"] else None)(state(m)), 3.0) or state(m)
    report("epicpos: the start-up sequence of 1.6 completes by itself (st_init, st_loopon, "
           "not st_emrg, st_still, not st_regoff)",
           s["init"] and s["loopon"] and not s["emrg"] and s["still"] and not s["regoff"]
           and not s["cntlock"] and not s["cntrev"], s)
    refcnt = m.md(REFCNT)
    report("epicpos: no command of the start-up sequence is refused (refcnt 0)", refcnt == 0, f"refcnt {refcnt}")
    pr = params(m)
    bad = {k: (pr[k], v) for k, v in DEFAULTS.items() if pr[k] != v}
    report("epicpos: set-up registers hold the documented initial values", not bad, f"(got, expected) {bad}")
    v = snap(m)
    report("epicpos: after start-up the axis is still at 0", v["posit"] == 0 and v["x"] == 0 and v["v"] == 0,
           f"posit {v['posit']}, plant {v['x']} counts at {v['v']} counts/s")


def t_first_move(m):
    """The seed's example as shipped: quota 2500 at 80 % of maxvel."""
    quota, pct = 2500, 80
    m.set_md(P["slVelAsse"], pct)
    start_move(m, quota)
    samples, s = follow(m, 8.0)
    v = snap(m)
    posit, pos = v["posit"], v["x"]
    report("epicpos: START positions to slQuotaPos within toll, st_toll and ofToll on, "
           "ofAxeFermo on", v["st"]["toll"] and abs(posit - quota) <= 5 and v["ofToll"] and v["ofAxeFermo"],
           f"posit {posit}, states {v['st']}")
    report("epicpos: posit is the plant's position (1 count = 1 Um)", abs(posit - pos) <= 1,
           f"posit {posit}, plant {pos} counts")
    moving = [outs for (*_, outs, still) in samples if not still]
    report("epicpos: while moving ofToll and ofAxeFermo are off",
           len(moving) >= 5 and not any(o[0] or o[1] for o in moving),
           f"{len(moving)} samples while moving, outputs seen {sorted(set(map(tuple, moving)))}")
    cruise = [v for (_, p, v, *_) in samples if 0.35 * quota < p < 0.65 * quota]
    want = pct * 100000 // 100
    report(f"epicpos: cruising speed is slVelAsse % of maxvel (vel {want} Um/min +-5 %)",
           len(cruise) >= 5 and all(abs(v - want) <= 0.05 * want for v in cruise),
           f"{len(cruise)} samples in cruise: {sorted(set(cruise))}")
    peak = max(p for (_, p, *_) in samples)
    over = peak - quota
    pred = model_overshoot(quota, pct, 100, 10)
    report(f"epicpos: overshoot with the seed's tuning is the loop's own "
           f"(model {pred:.1f} Um, measured {over} Um, +-3)",
           abs(over - pred) <= 3, f"peak posit {peak}, quota {quota}")
    return samples


def readme_commands():
    """The mbpoll lines of examples/epicpos/README.md, by the start of their comment."""
    readme = os.path.join(os.path.dirname(INI), "README.md")
    setup, cmds = None, {}
    for line in open(readme).read().splitlines():
        line = line.strip()
        if line.startswith("M="):
            setup = line
        elif line.startswith("$M") and "#" in line:
            cmd, comment = line.split("#", 1)
            cmds[comment.strip()] = cmd.strip()
    return setup, cmds


def mbpoll(setup, cmd, port):
    """Run one README line as a user would (bash, mbpoll), on the test's port;
    returns {address: value} of what it printed, and its whole output."""
    script = setup.replace("-p 1502", f"-p {port}") + "\n" + cmd
    r = subprocess.run(["bash", "-c", script], capture_output=True, text=True, timeout=20)
    vals = {int(a): int(v) for a, v in re.findall(r"^\[(\d+)\]:\s+(-?\d+)", r.stdout, re.M)}
    said = [ln.strip() for ln in (r.stdout + r.stderr).splitlines()
            if ln.startswith("[") or "rror" in ln or "llegal" in ln]
    return vals, f"`{cmd}` exit {r.returncode}: " + " | ".join(said)


def t_readme(m, port):
    """examples/epicpos/README.md's mbpoll session, as printed there."""
    setup, cmds = readme_commands()
    pick = {k: next((c for d, c in cmds.items() if d.startswith(k)), None)
            for k in ("slQuotaPos", "START input", "posit", "ofToll", "refcnt")}
    if not setup or None in pick.values():
        report("epicpos: README's mbpoll session found", False, f"{setup} {cmds}")
        return
    _, out = mbpoll(setup, pick["slQuotaPos"], port)
    quota = m.md(P["slQuotaPos"])
    report("epicpos: README: mbpoll writes slQuotaPos := 5000", quota == 5000, out)
    _, out = mbpoll(setup, pick["START input"], port)
    _, s = follow(m, 8.0)
    posit = m.md(POSIT)
    report("epicpos: README: mbpoll START input on, then off: the axis goes to 5000",
           s["toll"] and abs(posit - 5000) <= 5, f"posit {posit}; {out}")
    settle(m)
    vals, out = mbpoll(setup, pick["posit"], port)
    got = list(vals.values())
    report("epicpos: README: mbpoll reads posit and vel (at rest: |vel| within one count per 100 ms)",
           len(got) == 2 and abs(got[0] - m.md(POSIT)) <= 1 and abs(got[1]) <= 600, out)
    vals, out = mbpoll(setup, pick["ofToll"], port)
    report("epicpos: README: mbpoll reads ofToll, ofAxeFermo (both on)", list(vals.values()) == [1, 1], out)
    # a refused START, then the README's line for why. The register map
    # (docs/examples.md) puts refcnt (%MD48) at 2048 + 2 x 48 = 2144: this fails while the
    # README's mbpoll line reads from 2146 (refcode, parerr, DAC value)
    m.set_md(P["toll"], -1000000)
    pulse(m, START)
    time.sleep(0.1)
    want = m.md(REFCNT, 3)
    vals, out = mbpoll(setup, pick["refcnt"], port)
    m.set_md(P["toll"], 5)
    report("epicpos: README: the mbpoll line for refcnt, refcode, parerr reads them",
           list(vals.values()) == want, f"expected {want} (%MD48..50, holding {MD + 2 * REFCNT}); {out}")


def t_stiff_no_overshoot(m):
    """A stiffer loop (pgain 100): the model puts the overshoot below toll, so no
    sample may pass quota + toll."""
    base = m.md(POSIT)
    quota = base + 2500
    pred = model_overshoot(2500, 80, 100, 100)
    m.set_md(P["pgain"], 100)
    time.sleep(0.02)
    start_move(m, quota)
    samples, s = follow(m, 8.0)
    peak = max(p for (_, p, *_) in samples)
    report(f"epicpos: with pgain 100 (model overshoot {pred:.1f} Um) posit never passes quota + toll "
           f"while moving ({len(samples)} samples)",
           pred < 5 and peak <= quota + 5 and s["toll"], f"peak {peak}, quota {quota}, final {m.md(POSIT)}")
    m.set_md(P["pgain"], 10)


def t_manual(m):
    for coil, sign, name in ((AVMAN, 1, "forward"), (INMAN, -1, "backward")):
        p0 = m.md(POSIT)
        m.set_coil(coil, 1)
        time.sleep(0.4)
        p1 = m.md(POSIT)
        time.sleep(0.3)
        p2 = m.md(POSIT)
        moving = not m.coils(ST["still"])
        m.set_coil(coil, 0)
        s = wait_for(lambda: (lambda s: s if s["still"] else None)(state(m)), 3.0) or state(m)
        p3 = m.md(POSIT)
        dx, dp = still_for(m, 0.3)
        report(f"epicpos: manual {name} input: posit {'in' if sign > 0 else 'de'}creases while it is on",
               moving and sign * (p1 - p0) > 50 and sign * (p2 - p1) > 200,
               f"posit {p0} -> {p1} -> {p2}, st_still {not moving}")
        report(f"epicpos: manual {name} input off: the axis stops (st_still) and stays within toll",
               s["still"] and sign * (p3 - p2) >= 0 and dx <= 5 and dp <= 5,
               f"posit {p2} -> {p3}, then moves {dp} (plant {dx} counts), states {s}")


def t_stop_input(m):
    m.set_md(P["taccdec"], 20)      # shorter ramps (0.2 s to maxvel) from here on
    base = m.md(POSIT)
    quota = base + 3000
    start_move(m, quota)
    time.sleep(0.5)
    moving = not m.coils(ST["still"])
    p_stop = m.md(POSIT)
    m.set_coil(STOP, 1)
    s = wait_for(lambda: (lambda s: s if s["still"] else None)(state(m)), 3.0) or state(m)
    m.set_coil(STOP, 0)
    settled = settle(m)
    posit, s = m.md(POSIT), state(m)
    dx, _ = still_for(m, 0.3)
    outs = m.coils(OFTOLL, 2)
    # along the deceleration ramp: 80 % of maxvel to 0 in 0.16 s covers
    # 0.16 x 1333 / 2 = 107 Um; the drive's lag adds at most its lag error
    # at speed, 1333 x 0.02 = 27 Um; a cycle or two of latency and toll 5
    ramp = 0.8 * 0.2 * (0.8 * MAXVEL_UMS) / 2
    most = ramp + 0.8 * MAXVEL_UMS * LAG + 5 + 10
    report(f"epicpos: STOP input during a move: the axis stops along the ramp ({ramp:.0f} Um, at most "
           f"{most:.0f} Um past the STOP), short of the quota, and stays; ofAxeFermo on, ofToll off",
           moving and settled and s["still"] and p_stop < posit <= p_stop + most and not s["toll"]
           and dx <= 2 and outs == [False, True],
           f"STOP at posit {p_stop} on the way from {base} to {quota}: stopped at {posit}, then moved {dx}, "
           f"states {s}, ofToll/ofAxeFermo {outs}")
    # START again goes on to the quota
    s, posit = move(m, quota, 8.0)
    report("epicpos: START after a STOP reaches the quota", s["toll"] and abs(posit - quota) <= 5,
           f"posit {posit}, quota {quota}")


def refused_start(m, quota, why):
    """START with something out of range: refused, counted, the axis stays."""
    settle(m)
    r0 = m.md(REFCNT)
    x0 = m.sim(0)[0]
    p0 = m.md(POSIT)
    m.set_md(P["slQuotaPos"], quota)
    pulse(m, START)
    time.sleep(0.2)
    r1, code, parerr = m.md(REFCNT, 3)
    dx, dp = still_for(m, 0.3)
    return r1 - r0, code, parerr, dx, dp, p0, x0


def t_param_range(m):
    base = m.md(POSIT)
    quota = base + 1500
    # toll beyond its range (-999999..999999, index 8)
    m.set_md(P["toll"], -1000000)
    time.sleep(0.05)
    pe = m.md(PARERR)
    report("epicpos: toll -1000000 (out of -999999..999999) is reported at once: parerr 8",
           pe == 8, f"parerr {pe}")
    n, code, parerr, dx, dp, _, _ = refused_start(m, quota, "toll")
    report("epicpos: START with toll out of range is refused: refcnt +1, refcode 4, parerr 8, no move",
           n == 1 and code == 4 and parerr == 8 and dx <= 5 and dp <= 5 and m.coils(ST["still"]),
           f"refcnt +{n}, refcode {code}, parerr {parerr}, plant moved {dx}, posit moved {dp}")
    m.set_md(P["toll"], -5)          # negative in range: its absolute value is used
    time.sleep(0.05)
    pe = m.md(PARERR)
    s, posit = move(m, quota, 6.0)
    report("epicpos: toll corrected (-5 is in range): parerr 0, START reaches the quota within |toll|",
           pe == 0 and s["toll"] and abs(posit - quota) <= 5, f"parerr {pe}, posit {posit}, quota {quota}")
    m.set_md(P["toll"], 5)
    # maxpos below the quota: setpos (index 27) outside minpos..maxpos
    quota2 = quota + 1500
    m.set_md(P["maxpos"], quota2 - 500)
    n, code, parerr, dx, dp, _, _ = refused_start(m, quota2, "maxpos")
    report("epicpos: quota beyond maxpos: START refused (refcnt +1, refcode 4, parerr 27 = setpos), no move",
           n == 1 and code == 4 and parerr == 27 and dx <= 5 and dp <= 5 and m.coils(ST["still"]),
           f"refcnt +{n}, refcode {code}, parerr {parerr}, plant moved {dx}, posit moved {dp}")
    m.set_md(P["maxpos"], 999999)
    start_move(m, quota2)
    _, s = follow(m, 6.0)
    posit, pe = m.md(POSIT), m.md(PARERR)
    report("epicpos: maxpos corrected: parerr 0, START reaches the quota",
           pe == 0 and s["toll"] and abs(posit - quota2) <= 5, f"parerr {pe}, posit {posit}, quota {quota2}")


PARNAME = 1024       # holding 1024..1031 (%MW0..%MW7): parname, 2 characters per register


def parname(m):
    return b"".join(r.to_bytes(2, "big") for r in m.regs(PARNAME, 8)).rstrip(b"\0").decode()


def t_param_beyond_int(m):
    """pgain 40000 (seed: valid 0..32767) written to its 32-bit register must
    not be clamped to a valid 32767 on the way: EPICPOS reports it, by index
    (18, the seed's table order) and by name, readable over Modbus."""
    base = m.md(POSIT)
    quota = base + 1500
    pgain0, taccdec0 = m.md(P["pgain"]), m.md(P["taccdec"])
    m.set_md(P["pgain"], 40000)
    time.sleep(0.05)
    pe, name = m.md(PARERR), parname(m)
    report("epicpos: pgain 40000 (out of 0..32767) reaches EPICPOS: parerr 18, parname 'pgain' "
           "in holding 1024..1031", pe == 18 and name == "pgain", f"parerr {pe}, parname {name!r}")
    setup, cmds = readme_commands()
    line = next((c for d, c in cmds.items() if d.startswith("parname")), None)
    if setup and line:
        script = setup.replace("-p 1502", f"-p {m.c.comm_params.port}") + "\n" + line
        r = subprocess.run(["bash", "-c", script], capture_output=True, text=True, timeout=20)
        words = [int(v, 16) for v in re.findall(r"^\[\d+\]:\s+0x([0-9A-Fa-f]+)", r.stdout, re.M)]
        got = b"".join(w.to_bytes(2, "big") for w in words).rstrip(b"\0")
        report("epicpos: README: the mbpoll line for parname reads 'pgain' in ASCII", got == b"pgain",
               f"{got!r}: {r.stdout[-300:]}")
    else:
        report("epicpos: README: an mbpoll line for parname", False, cmds)
    n, code, parerr, dx, dp, _, _ = refused_start(m, quota, "pgain")
    report("epicpos: START with pgain 40000 is refused: refcnt +1, refcode 4, parerr 18, no move",
           n == 1 and code == 4 and parerr == 18 and dx <= 5 and dp <= 5,
           f"refcnt +{n}, refcode {code}, parerr {parerr}, plant moved {dx}, posit moved {dp}")
    m.set_md(P["taccdec"], -70000)   # beyond INT the other way (seed: 0..999)
    m.set_md(P["pgain"], pgain0)
    time.sleep(0.05)
    pe, name = m.md(PARERR), parname(m)
    report("epicpos: taccdec -70000: parerr 11, parname 'taccdec'", pe == 11 and name == "taccdec",
           f"parerr {pe}, parname {name!r}")
    m.set_md(P["taccdec"], taccdec0)
    time.sleep(0.05)
    pe, name = m.md(PARERR), parname(m)
    report(f"epicpos: parameters back (pgain {pgain0}, taccdec {taccdec0}): parerr 0, parname empty", pe == 0 and name == "",
           f"parerr {pe}, parname {name!r}")
    s, posit = move(m, quota, 6.0)
    report("epicpos: and START reaches the quota", s["toll"] and abs(posit - quota) <= 5,
           f"posit {posit}, quota {quota}")


def t_emergency(m):
    base = m.md(POSIT)
    quota = base - 3000
    start_move(m, quota)
    time.sleep(0.4)
    moving = not m.coils(ST["still"])
    command(m, "EMRG")
    time.sleep(0.2)
    v = snap(m)
    s, dac, x0 = v["st"], v["dacval"], v["x"]
    time.sleep(0.2)
    x1, v1 = m.sim(0)
    report("epicpos: EMRG command coil during a move: st_emrg on, loop open, DAC value 0, the axis stops",
           moving and s["emrg"] and not s["loopon"] and dac == 0 and x1 == x0 and v1 == 0,
           f"states {s}, DAC {dac}, plant {x0} -> {x1} at {v1} counts/s")
    r0 = m.md(REFCNT)
    pulse(m, START)
    time.sleep(0.1)
    r1, code = m.md(REFCNT, 2)
    report("epicpos: START in emergency is refused (refcnt +1, refcode 4), the axis stays",
           r1 == r0 + 1 and code == 4 and m.sim(0)[0] == x1, f"refcnt {r0} -> {r1}, refcode {code}")
    command(m, "RESUME")
    time.sleep(0.05)
    s = state(m)
    report("epicpos: RESUME: st_emrg off, loop closed again", not s["emrg"] and s["loopon"], s)
    s, posit = move(m, quota, 8.0)
    report("epicpos: after RESUME, START repeats the positioning to the quota",
           s["toll"] and abs(posit - quota) <= 5, f"posit {posit}, quota {quota}")


def t_following_error(m, port):
    """maxfollerr below the drive's lag error: st_foller and an emergency,
    st_foller held 500 ms at least (counted in cycles by a trace); RESUME
    and a START complete the move."""
    settle(m)
    m.set_md(P["maxfollerr"], 5)
    base = m.md(POSIT)
    quota = base + 2500
    rec = Recording(port, ["res0.axis.st_foller"], "res0.axis.st_foller:rise", 1500,
                    os.path.join(WORK, "foller.csv"), pre=1)
    start_move(m, quota)
    s = wait_for(lambda: (lambda s: s if s["foller"] else None)(state(m)), 2.0, 0.005)
    if not s:
        report("epicpos: following error beyond maxfollerr (5 counts) sets st_foller", False, state(m))
        m.set_md(P["maxfollerr"], 10000)
        rec.p.kill()
        return
    time.sleep(0.25)
    v = snap(m)
    s1, dac, x1, v1 = v["st"], v["dacval"], v["x"], v["v"]
    report("epicpos: following error beyond maxfollerr (5): st_foller, emergency, loop open, DAC 0, "
           "the axis stops", s1["foller"] and s1["emrg"] and not s1["loopon"] and dac == 0 and v1 == 0
           and x1 < quota - 1000, f"states {s1}, DAC {dac}, plant at {x1} ({v1} counts/s)")
    rows = rec.rows()
    on = [t for _, t, (f,) in rows if f]
    off = next((t for _, t, (f,) in rows if not f and on and t > on[0]), None)
    held = (off - on[0]) if off is not None else None
    report("epicpos: st_foller is held 500 ms of PLC time at least, then clears "
           "(the error back within the limit)", held is not None and held >= 500,
           f"held {held:.0f} ms" if held is not None else f"not cleared within {len(rows)} samples")
    m.set_md(P["maxfollerr"], 10000)
    command(m, "RESUME")
    s, posit = move(m, quota, 8.0)
    report("epicpos: after RESUME, START completes the move", s["toll"] and abs(posit - quota) <= 5,
           f"posit {posit}, quota {quota}")


def t_command_coil(m):
    r0 = m.md(REFCNT)
    m.set_coil(CMD["LOOPON"], 1)
    back = wait_for(lambda: not m.coils(CMD["LOOPON"]), 1.0, 0.005)
    report("epicpos: a command coil (LOOPON) is cleared by the program after one cycle", back,
           "coil 21 still on after 1 s")
    command(m, "INIT")
    time.sleep(0.05)
    r1, code = m.md(REFCNT, 2)
    report("epicpos: INIT on an initialised axis is refused (refcnt +1, refcode 1)",
           r1 == r0 + 1 and code == 1 and not m.coils(CMD["INIT"]), f"refcnt {r0} -> {r1}, refcode {code}")


def raw_request(port, pdu):
    """One Modbus TCP request sent by hand; returns the reply's PDU (b'' if closed)."""
    with socket.create_connection(("127.0.0.1", port), timeout=3) as s:
        s.sendall(struct.pack(">HHHB", 0x1234, 0, len(pdu) + 1, 1) + pdu)
        try:
            head = s.recv(7)
            if len(head) < 7:
                return b""
            n = struct.unpack(">H", head[4:6])[0] - 1
            body = b""
            while len(body) < n:
                chunk = s.recv(n - len(body))
                if not chunk:
                    break
                body += chunk
            return body
        except (socket.timeout, ConnectionResetError):
            return b""


def t_bad_modbus(m, port):
    """Bad requests during a move: each refused with its exception, the move
    and the set-up unaffected."""
    before = params(m)
    base = m.md(POSIT)
    quota = base + 3000
    start_move(m, quota)
    bad = Mb(port)                   # a second client: some of these close the connection
    c = bad.c
    checks = []
    # FC16 of 124 registers is a 261-byte ADU, past Modbus TCP's 260: refused
    # one way or the other, and nothing of it written
    r = c.write_registers(MD, [7] * 124, slave=1)
    checks.append(("FC16 of 124 registers over the set-up (ADU of 261 bytes) refused",
                   r.isError() and getattr(r, "exception_code", 3) == 3, r))
    c.close()
    c.connect()
    reply = raw_request(port, bytes([0x10, 0x08, 0x00, 0x00, 0x00, 0x00]))       # FC16, quantity 0
    checks.append(("FC16 of 0 registers: exception 3", reply == bytes([0x90, 0x03]), reply.hex()))
    reply = raw_request(port, bytes([0x0F, 0x00, 0x00, 0x07, 0xB1, 0xF7]) + bytes(247))   # FC15, 1969 coils
    checks.append(("FC15 of 1969 coils: exception 3", reply == bytes([0x8F, 0x03]), reply.hex()))
    r = c.write_register(8192, 1, slave=1)                        # past the holding map
    checks.append(("FC6 at holding 8192 (unmapped): exception 2", r.isError() and getattr(r, "exception_code", 0) == 2, r))
    r = c.write_registers(8190, [1, 2, 3, 4], slave=1)            # across the end
    checks.append(("FC16 across the end of the holding map: exception 2",
                   r.isError() and getattr(r, "exception_code", 0) == 2, r))
    r = c.write_coil(8192, True, slave=1)
    checks.append(("FC5 at coil 8192 (unmapped): exception 2", r.isError() and getattr(r, "exception_code", 0) == 2, r))
    r = c.write_coils(8190, [True] * 4, slave=1)
    checks.append(("FC15 across the end of the coils: exception 2",
                   r.isError() and getattr(r, "exception_code", 0) == 2, r))
    r = c.read_holding_registers(MD, 126, slave=1)
    checks.append(("FC3 of 126 registers: exception 3", r.isError() and getattr(r, "exception_code", 0) == 3, r))
    bad.close()
    reply = raw_request(port, bytes([0x05, 0x00, CMD["EMRG"], 0x12, 0x34]))   # FC5, value not FF00/0000
    checks.append(("FC5 on the EMRG coil with value 0x1234: exception 3, no emergency",
                   reply == bytes([0x85, 0x03]), reply.hex()))
    reply = raw_request(port, bytes([0x41, 0x00]))                # unknown function
    checks.append(("unknown function 0x41: exception 1", reply == bytes([0xC1, 0x01]), reply.hex()))
    reply = raw_request(port, bytes([0x10, 0x08, 0x00, 0x00, 0x02, 0x06, 1, 2, 3, 4, 5, 6]))  # 2 registers, 6 bytes
    checks.append(("FC16 with a byte count that does not match: exception 3", reply == bytes([0x90, 0x03]),
                   reply.hex()))
    for name, ok, why in checks:
        report("epicpos: bad Modbus input during a move: " + name, ok, why)
    _, s = follow(m, 8.0)
    posit, after = snap(m)["posit"], params(m)
    after["slQuotaPos"] = before["slQuotaPos"] = 0
    report("epicpos: after the bad requests the move ends at the quota, no emergency, set-up unchanged",
           s["toll"] and not s["emrg"] and abs(posit - quota) <= 5 and after == before,
           f"posit {posit}, quota {quota}, states {s}, changed "
           f"{ {k: (before[k], after[k]) for k in before if before[k] != after[k]} }")


def t_readonly_values(m):
    """posit and the states are outputs of the program: writing them changes
    nothing the axis does (docs/examples.md: read only, rewritten every cycle)."""
    settle(m)
    v = snap(m)
    p0, x0, r0 = v["posit"], v["x"], v["refcnt"]
    m.set_md(POSIT, p0 + 50000)
    m.set_coil(ST["emrg"], 1)
    m.set_coil(ST["still"], 0)
    time.sleep(0.1)
    v = snap(m)
    p1, s = v["posit"], v["st"]
    dx, dp = still_for(m, 0.3)
    v = snap(m)
    x1 = v["x"]
    report("epicpos: writing posit and state coils: rewritten by the program, the axis does not move",
           abs(p1 - p0) <= 5 and not s["emrg"] and s["still"] and abs(x1 - x0) <= 5 and dp <= 5
           and v["refcnt"] == r0, f"posit {p0} -> {p1}, states {s}, plant {x0} -> {x1}")


def t_posit_commands(m):
    """WRPOSIT and DELCNT rewrite posit; the axis itself stays where it is."""
    settle(m)
    x0 = m.sim(0)[0]
    m.set_md(P["newposit"], 100000)
    command(m, "WRPOSIT")
    time.sleep(0.05)
    p1 = m.md(POSIT)
    m.set_md(P["delta"], -2345)
    command(m, "DELCNT")
    time.sleep(0.05)
    p2 = m.md(POSIT)
    dx, _ = still_for(m, 0.2)
    v = snap(m)
    x1 = v["x"]
    report("epicpos: WRPOSIT: posit := newposit (100000); DELCNT: posit + delta (-2345); the axis stays",
           abs(p1 - 100000) <= 2 and p2 - p1 == -2345 and abs(x1 - x0) <= 5 and dx <= 5 and v["st"]["still"],
           f"posit {p1}, then {p2}; plant {x0} -> {x1}")
    p2, x1 = v["posit"], v["x"]         # posit and the plant of one cycle
    # a START goes to a quota in the new frame
    quota = p2 + 1000
    start_move(m, quota)
    _, s = follow(m, 6.0)
    v = snap(m)
    posit, x2 = v["posit"], v["x"]
    report("epicpos: after WRPOSIT/DELCNT a START moves by the difference in the new frame",
           s["toll"] and abs(posit - quota) <= 5 and abs((x2 - x1) - (posit - p2)) <= 2,
           f"posit {p2} -> {posit} (quota {quota}), plant {x1} -> {x2}")


def t_calibration(m):
    """CALON, then vout (seed 1.2.2.1; vout is written only in calibration): the
    DAC outputs vout x 3276.7 (+ offset); the plant runs at that fraction of
    its speed at 10 V. CALOFF: the axis stops where it is."""
    settle(m)
    command(m, "CALON")
    m.set_md(P["vout"], 10)                     # 1.0 V
    time.sleep(0.4)                             # 20 drive time constants
    v = snap(m)
    s, dac, vel, xs, vs = v["st"], v["dacval"], v["vel"], v["x"], v["v"]
    want = 1.0 / 10 * SIM_MAXVEL
    report(f"epicpos: CALON with vout 10: st_cal, DAC 3277 (1 V), the plant at {want:.1f} counts/s, "
           f"vel {want * 60:.0f} Um/min", s["cal"] and abs(dac - 3276.7) <= 1 and abs(vs - want) <= 2
           and abs(vel - want * 60) <= 700, f"states {s}, DAC {dac}, plant {vs} counts/s, vel {vel}")
    m.set_md(P["vout"], 0)                      # back to 0 V while still calibrating
    command(m, "CALOFF")
    time.sleep(0.3)
    v = snap(m)
    s, x1 = v["st"], v["x"]
    dx, dp = still_for(m, 0.3)
    report("epicpos: CALOFF: st_cal off, the axis stops where it is (no run back) and stays",
           not s["cal"] and s["still"] and x1 >= xs and dx <= 5 and dp <= 5 and not s["emrg"],
           f"states {s}, plant at CALOFF {xs}, 0.3 s later {x1}, then moved {dx}")


def t_default_drive():
    """The example runs on the plant's default drive (docs/config.md), and the
    seed's tuning stops within toll on it at any speed (reference model)."""
    docs = os.path.join(os.path.dirname(INI), "..", "..", "docs", "config.md")
    row = next(r for r in open(docs).read().splitlines() if r.startswith("| `lag` |"))
    default = float(row.split("|")[2].strip(" `"))
    worst = max(model_overshoot(2500, pct, 100, 10) for pct in (20, 50, 80, 100))
    report(f"epicpos: the example's drive lag is the plant's default ({default} s) and the seed's "
           f"tuning overshoots it by at most {worst:.1f} Um, within toll 5",
           LAG == default and worst < 5, f"example lag {LAG}, default {default}")


def main_session():
    retain = os.path.join(WORK, "epicpos.retain")
    for f in os.listdir(WORK):
        if f.startswith("epicpos"):
            os.unlink(os.path.join(WORK, f))
    p, m = new_plcrt("main", retain)
    port = m.c.comm_params.port
    run("epicpos: default drive", t_default_drive)
    run("epicpos: start-up", t_startup, m)
    run("epicpos: first move", t_first_move, m)
    run("epicpos: README session", t_readme, m, port)
    run("epicpos: stiff loop", t_stiff_no_overshoot, m)
    run("epicpos: manual inputs", t_manual, m)
    run("epicpos: STOP input", t_stop_input, m)
    run("epicpos: parameter range", t_param_range, m)
    run("epicpos: parameter beyond INT", t_param_beyond_int, m)
    run("epicpos: emergency", t_emergency, m)
    run("epicpos: following error", t_following_error, m, port)
    run("epicpos: command coils", t_command_coil, m)
    run("epicpos: bad Modbus input", t_bad_modbus, m, port)
    run("epicpos: read-only values", t_readonly_values, m)
    run("epicpos: WRPOSIT and DELCNT", t_posit_commands, m)
    run("epicpos: calibration", t_calibration, m)
    report("epicpos: plcrt still running after all of the above", p.alive(), p.output()[-300:])
    m.close()
    rc = p.stop()
    report("epicpos: SIGTERM: exit 0", rc == 0, f"rc {rc}")


# ---- RETAIN across restarts ----

def t_retain():
    retain = os.path.join(WORK, "epicpos-r.retain")
    p, m = new_plcrt("r1", retain, period=0)
    wait_for(lambda: m.coils(ST["loopon"]), 3.0)
    q1, q2 = -1800, 2500                   # the last move before the restart goes backward
    m.set_md(P["slVelAsse"], 90)
    m.set_md(P["toll"], 8)
    m.set_md(P["taccdec"], 30)
    m.set_md(P["toldly"], 5)
    s, posit0 = move(m, q1, 6.0)
    m.set_md(P["slQuotaPos"], q2)          # written, not started
    command(m, "EMRG")                     # a state that must not come back
    # DAC 0 V: the axis stops where its last correction had taken it
    time.sleep(0.2)
    posit1 = wait_for(lambda: (lambda a: a if a == m.md(POSIT) else None)(m.md(POSIT)), 2.0, 0.05)
    set1 = params(m)
    m.close()
    rc = p.stop()
    report("retain: first run reached its quota and stopped cleanly (SIGTERM, exit 0, statistics)",
           s["toll"] and abs(posit0 - q1) <= 8 and posit1 is not None and rc == 0 and "statistics" in p.output(),
           f"posit {posit0}, after EMRG {posit1}, rc {rc}")

    p, m = new_plcrt("r2", retain, period=0)
    s = wait_for(lambda: (lambda s: s if s["loopon"] else None)(state(m)), 3.0) or state(m)
    set2 = params(m)
    diff = {k: (set1[k], set2[k]) for k in set1 if set1[k] != set2[k]}
    report("retain: slQuotaPos, slVelAsse, toll, taccdec, toldly and the rest of the set-up come back",
           not diff and set2["slQuotaPos"] == q2 and set2["toll"] == 8 and set2["taccdec"] == 30, diff)
    posit = m.md(POSIT)
    report("retain: posit comes back (the axis's position when plcrt stopped)", posit == posit1,
           f"posit {posit}, before the restart {posit1}")
    refcnt = m.md(REFCNT)
    report("retain: states come back at their INIT values and start-up succeeds again "
           "(st_init, st_loopon, no emergency, st_still, not st_toll, st_movdir 0 after a backward move, refcnt 0)",
           s["init"] and s["loopon"] and not s["emrg"] and s["still"] and not s["toll"] and not s["movdir"]
           and refcnt == 0,
           f"states {s}, refcnt {refcnt}")
    dx, dp = still_for(m, 0.3)
    report("retain: after the restart the axis does not move by itself", dx == 0 and dp == 0,
           f"plant moved {dx}, posit moved {dp}")
    s, posit = move(m, q2, 8.0)
    report("retain: START after the restart goes to the retained quota", s["toll"] and abs(posit - q2) <= 8,
           f"posit {posit}, retained quota {q2}")

    # stopped in the middle of a move: nothing moves after the restart
    start_move(m, q2 + 9000)
    time.sleep(0.5)
    mid = m.md(POSIT)
    rc = p.stop()
    m.close()
    p, m = new_plcrt("r3", retain, period=0)
    s = wait_for(lambda: (lambda s: s if s["loopon"] else None)(state(m)), 3.0) or state(m)
    posit = m.md(POSIT)
    dx, dp = still_for(m, 0.5)
    report("retain: SIGTERM during a move, restart: posit where the axis was, still, the axis does not move",
           rc == 0 and mid <= posit <= mid + 300 and s["still"] and dx == 0 and dp == 0,
           f"posit {mid} before SIGTERM, {posit} after; plant moved {dx}, posit moved {dp}; states {s}")
    saved = dict(params(m), posit=m.md(POSIT))
    m.close()
    rc = p.stop()
    return (retain, saved) if rc == 0 else None


def damaged_restart(retain, tag, expect, why):
    """Start on a damaged retain file; check plcrt runs, says so and what it loaded."""
    p, m = new_plcrt(tag, retain, period=0)
    s = wait_for(lambda: (lambda s: s if s["loopon"] else None)(state(m)), 3.0) or state(m)
    pr = params(m)
    posit = m.md(POSIT)
    dx, dp = still_for(m, 0.4)
    wrong = {k: (pr[k], v) for k, v in expect.items() if k in pr and pr[k] != v}
    report(f"retain: {why}: plcrt runs, start-up succeeds, the axis does not move",
           p.alive() and s["init"] and s["loopon"] and not s["emrg"] and s["still"] and dx == 0 and dp == 0,
           f"alive {p.alive()}, states {s}, plant moved {dx}, posit moved {dp}")
    report(f"retain: {why}: the values are {expect['what']}",
           not wrong and posit == expect["posit"], f"(got, expected) {wrong}, posit {posit} (expected {expect['posit']})")
    m.close()
    rc = p.stop()
    return p.output(), rc


def t_damaged(retain, saved):
    """docs/runtime.md: a damaged FILE is reported and moved to FILE.bad, FILE.prev
    is loaded instead; with neither, the declared initial values stand."""
    good = retain + ".good"
    shutil.copy(retain, good)
    size = os.path.getsize(good)
    initial = dict(DEFAULTS, posit=0, what="the initial values")

    # one byte changed, no previous generation
    data = bytearray(open(good, "rb").read())
    data[size // 2] ^= 0x5A
    open(retain, "wb").write(data)
    for f in (retain + ".prev", retain + ".bad"):
        if os.path.exists(f):
            os.unlink(f)
    out, _ = damaged_restart(retain, "bad1", initial, "a byte changed in the retain file, no FILE.prev")
    report("retain: the damaged file is reported by name and moved to FILE.bad",
           "damaged" in out and retain in out and os.path.exists(retain + ".bad")
           and open(retain + ".bad", "rb").read() == bytes(data), out[-400:])

    # truncated to half, the good generation as FILE.prev
    shutil.copy(good, retain + ".prev")
    open(retain, "wb").write(open(good, "rb").read()[: size // 2])
    out, _ = damaged_restart(retain, "bad2", dict(saved, what="those of FILE.prev (the last good generation)"),
                             "retain file truncated to half, FILE.prev intact")
    report("retain: the truncated file is reported and FILE.prev named as loaded",
           retain + ".prev" in out and "previous generation" in out, out[-400:])

    # empty, no FILE.prev
    open(retain, "wb").close()
    os.unlink(retain + ".prev")
    damaged_restart(retain, "bad3", initial, "empty retain file, no FILE.prev")

    # random bytes of the same length, no FILE.prev
    open(retain, "wb").write(os.urandom(size))
    if os.path.exists(retain + ".prev"):
        os.unlink(retain + ".prev")
    damaged_restart(retain, "bad4", initial, "retain file of random bytes, no FILE.prev")


def main():
    os.makedirs(WORK, exist_ok=True)
    try:
        main_session()
        got = run("retain: restart", t_retain)
        if got:
            run("retain: damaged files", t_damaged, *got)
    finally:
        Plcrt.kill_all()
    sys.exit(1 if exlib.failed else 0)


main()
