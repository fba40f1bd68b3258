#!/usr/bin/env python3
"""EPICPOS benchmarks: the cost of one EPICPOS call, of one scan with 1, 16
and 256 axes, and the largest number of axes plcrt runs at 1 ms with no
overrun on this machine.

usage: bench.py WORKDIR
Environment (set by bench/part.mk): STC, STC_INC, ST_LIB, C_BLOCKS_ST,
C_BLOCKS_OBJ, CC, GEN_CFLAGS (flags for the generated C, as plcrt's build),
CFLAGS, PLCRT_LINK (plcrt's objects), PLCRT_LIBS.
BENCH_SECONDS: length of one plcrt run in the search (default 4)."""
import os
import re
import shlex
import shutil
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
WORK = os.path.abspath(sys.argv[1])
ENV = {k: os.environ[k] for k in ("STC", "STC_INC", "ST_LIB", "C_BLOCKS_ST", "C_BLOCKS_OBJ", "CC",
                                  "GEN_CFLAGS", "CFLAGS", "PLCRT_LINK", "PLCRT_LIBS")}
SECONDS = float(os.environ.get("BENCH_SECONDS", "4"))
RUNS = 5              # timed runs; the median is reported
BUDGET_NS = 1_000_000  # the 1 ms task interval
MAX_AXES = 16384


def sh(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        sys.exit(f"bench-epicpos: {' '.join(cmd)} failed:\n{r.stdout}{r.stderr}")
    return r.stdout + r.stderr


def split(var):
    return shlex.split(ENV[var])


def program(n):
    """Compile the program with n axes; returns its folder (gen/ inside)."""
    d = os.path.join(WORK, f"axes{n}")
    gen = os.path.join(d, "gen")
    if os.path.exists(os.path.join(gen, "VARIABLES.csv")):
        return d
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(HERE, "axes.st.in")) as f:
        axes = f.read().replace("@N@", str(n))
    parts = [ENV["ST_LIB"], *split("C_BLOCKS_ST"), os.path.join(HERE, "bench_axis.st")]
    text = ""
    for p in parts:
        with open(p) as f:
            text += f.read()
    text += axes
    with open(os.path.join(d, "program.st"), "w") as f:
        f.write(text)
    sh([ENV["STC"], "-T", gen, os.path.join(d, "program.st")])
    return d


def harness(name, n):
    """Build bench/epicpos/NAME.c against the program with n axes."""
    d = program(n)
    exe = os.path.join(d, name)
    sh([ENV["CC"], *split("GEN_CFLAGS"), "-I", ENV["STC_INC"], "-I", os.path.join(d, "gen"),
        "-o", exe, os.path.join(HERE, name + ".c"), *split("C_BLOCKS_OBJ"), "-lm"])
    return exe


def plcrt(n):
    """Link the program with n axes into plcrt, as plcrt_program does."""
    d = program(n)
    exe = os.path.join(d, "plcrt")
    if os.path.exists(exe):
        return exe
    c, o = os.path.join(d, "program.c"), os.path.join(d, "program.o")
    sh([os.path.join(ROOT, "plc_runtime", "gen_program.sh"), os.path.join(d, "gen"), c])
    sh([ENV["CC"], *split("GEN_CFLAGS"), "-I", ENV["STC_INC"], "-I", os.path.join(d, "gen"),
        "-I", os.path.join(ROOT, "plc_runtime"), "-c", c, "-o", o])
    sh([ENV["CC"], *split("CFLAGS"), "-o", exe, o, *split("PLCRT_LINK"), *split("PLCRT_LIBS")])
    return exe


def callgrind(cmd, fn):
    """Instructions executed inside fn (inclusive) over the whole run."""
    out = sh(["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null",
              f"--toggle-collect={fn}*", *cmd])
    return int(re.search(r"Collected : (\d+)", out).group(1))


def fields(text):
    """'key value key value ...' of a harness's output line as a dict of numbers."""
    w = text.split()
    return {w[i]: float(w[i + 1]) for i in range(0, len(w) - 1, 2)}


# ---- 1. one EPICPOS call ----
def one_call():
    exe = harness("call", 1)
    calls_cg, calls_t = 20000, 200000
    print("== one EPICPOS call: one axis on its plant (SIM_AXIS), tcamp 1 ms so that every call regulates;")
    print("   generated C built with plcrt's flags (-O2)")
    res = {}
    for mode, what in (("still", "still, loop closed (regulating)"),
                       ("move", "in motion (profile + PID)")):
        ir = callgrind([exe, mode, str(calls_cg)], "call_counted") / calls_cg
        runs = [fields(sh([exe, mode, str(calls_t), "timed"])) for _ in range(RUNS)]
        ns = statistics.median(r["mean_ns"] for r in runs)
        res[mode] = (ir, ns)
        print(f"  {what:<34} {ir:7.0f} instructions/call (callgrind, {calls_cg} calls)   "
              f"{ns:6.1f} ns/call (clock_gettime, median of {RUNS} runs' means over {calls_t} calls)")
    ir, ns = res["move"]
    print(f"  one call in motion = {100 * ns / BUDGET_NS:.4f} % of the 1 ms cycle; "
          f"{BUDGET_NS / ns:.0f} such calls would fill it (EPICPOS alone, no plant)")


# ---- 2. one scan with 1, 16, 256 axes ----
def scans():
    print("\n== one 1 ms scan with N axes in one program: per axis EPICPOS + SIM_AXIS + its sequence "
          "(start-up, then back and forth)")
    print(f"  {'axes':>5} {'instr/scan':>12} {'instr/axis':>11} {'us/scan':>9} {'p99':>8} {'us/axis':>8}  share of 1 ms")
    last = None
    for n in (1, 16, 256):
        exe = harness("scan", n)
        counted = 5000 if n < 256 else 1000
        ir = callgrind([exe, str(n), "300", str(counted)], "scan_counted") / counted
        runs = [fields(sh([exe, str(n), "500", "5000", "timed"])) for _ in range(RUNS)]
        mean = statistics.median(r["mean_ns"] for r in runs)
        p99 = statistics.median(r["p99_ns"] for r in runs)
        print(f"  {n:5d} {ir:12.0f} {ir / n:11.0f} {mean / 1000:9.1f} {p99 / 1000:8.1f} {mean / n / 1000:8.3f}"
              f"  {100 * mean / BUDGET_NS:5.1f} %")
        last = (n, mean, p99)
    n, mean, p99 = last
    print(f"  (instructions: callgrind over 5000 scans, 1000 with 256 axes, after 300 of start-up; us: mean and p99"
          f" of 5000 scans after 500, median of {RUNS} runs)")
    print(f"  {n} axes: {mean / 1000:.1f} us per scan = {100 * mean / BUDGET_NS:.1f} % of 1 ms "
          f"(p99 {p99 / 1000:.1f} us = {100 * p99 / BUDGET_NS:.1f} %)")


# ---- 3. the most axes plcrt runs at 1 ms ----
def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def run_plcrt(n, seconds, tmp):
    exe = plcrt(n)
    ini = os.path.join(tmp, "bench.ini")
    with open(ini, "w") as f:
        f.write("[plc]\nstatus_interval = 1\n"
                "status_vars = CONFIG0.RES0.INST0.NREADY, CONFIG0.RES0.INST0.NBAD, CONFIG0.RES0.INST0.NMOVES\n"
                f"[io]\nbackend = none\n[modbus]\nport = {free_port()}\n"
                f"[retain]\nfile = {os.path.join(tmp, 'bench.retain')}\n")
    log = open(os.path.join(tmp, "plcrt.log"), "w+")
    p = subprocess.Popen([exe, "-c", ini], stdout=log, stderr=subprocess.STDOUT)
    time.sleep(seconds)
    p.send_signal(signal.SIGTERM)
    p.wait(timeout=60)
    log.seek(0)
    text = log.read()
    m = re.search(r"statistics: (\d+) cycles of [\d.]+ us, (\d+) overruns", text)
    if not m:
        sys.exit(f"bench-epicpos: plcrt with {n} axes printed no statistics:\n{text}")
    r = {"n": n, "cycles": int(m.group(1)), "overruns": int(m.group(2)),
         "fifo": "(SCHED_FIFO)" in text}
    for key, name in (("lat", "wake latency"), ("exec", "execution")):
        m = re.search(name + r"\s+min\s+([\d.]+)\s+mean\s+([\d.]+)\s+p99\s+([\d.]+)\s+p99.9\s+([\d.]+)\s+max\s+([\d.]+)", text)
        r[key] = dict(zip(("min", "mean", "p99", "p999", "max"), map(float, m.groups())))
    st = re.findall(r"NREADY (\d+)\s+RES0.INST0.NBAD (\d+)\s+RES0.INST0.NMOVES (\d+)", text)
    if not st or int(st[-1][0]) != n or int(st[-1][1]) != 0 or int(st[-1][2]) == 0:
        sys.exit(f"bench-epicpos: plcrt with {n} axes: the axes did not all start and move:\n{text}")
    return r


def fits(r):
    """The run holds the 1 ms period: no overrun, or only overruns that
    needed one of the machine's rare stalls (a wake-up or an execution
    beyond its p99.9): p99.9 wake latency + p99.9 execution < 1 ms."""
    return r["overruns"] == 0 or r["lat"]["p999"] + r["exec"]["p999"] < 1000.0


def row(r):
    e, l = r["exec"], r["lat"]
    verdict = ("fits" if r["overruns"] == 0 else
               "fits, overruns from stalls only" if fits(r) else "does not fit")
    return (f"  {r['n']:5d} axes: {r['overruns']:3d} overruns in {r['cycles']:5d} cycles; execution mean {e['mean']:6.1f}"
            f" p99.9 {e['p999']:6.1f} max {e['max']:6.1f} us; wake latency p99.9 {l['p999']:5.1f} max {l['max']:6.1f} us: {verdict}")


def most_axes():
    print(f"\n== plcrt at a 1 ms interval (SCHED_FIFO 80, backend none, Modbus on): the most axes it runs "
          f"with no overrun, {SECONDS:g} s runs")
    tmp = tempfile.mkdtemp(prefix="bench-epicpos-")
    try:
        search(tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def search(tmp):
    # The machine's own stalls overrun even a program that does almost nothing:
    # measured first, so that the search can tell them from the program's.
    base = run_plcrt(1, SECONDS, tmp)
    if not base["fifo"]:
        print("  (plcrt could not get SCHED_FIFO here: normal scheduling)")
    print("  the machine alone (1 axis):")
    print(row(base))
    print("  the search (doubling from 256, then bisection), a number of axes fits when p99.9 wake latency +\n"
          "  p99.9 execution < 1 ms, i.e. any overrun needed a stall of the machine like those above:")
    lo, hi, n, fail, clean = 0, None, 256, None, 0
    while n <= MAX_AXES:
        r = run_plcrt(n, SECONDS, tmp)
        print(row(r), flush=True)
        if r["overruns"] == 0:
            clean = max(clean, n)
        if not fits(r):
            hi, fail = n, r
            break
        lo = n
        n *= 2
    if hi is None:
        print(f"  no limit found up to {lo} axes (the search stops there)")
        return
    while hi - lo > max(8, lo // 32):
        n = (lo + hi) // 2 // 8 * 8
        r = run_plcrt(n, SECONDS, tmp)
        print(row(r), flush=True)
        if r["overruns"] == 0:
            clean = max(clean, n)
        if fits(r):
            lo = n
        else:
            hi, fail = n, r
    if lo == 0:
        print("  even 256 axes do not fit")
        return
    # a longer run must confirm it; if not, 1/16 fewer axes, at most 3 times
    for _ in range(3):
        conf = run_plcrt(lo, 2.5 * SECONDS, tmp)
        print(f"  {lo} axes again, over {2.5 * SECONDS:g} s:")
        print(row(conf), flush=True)
        if conf["overruns"] == 0:
            clean = max(clean, lo)
        if fits(conf):
            break
        hi, fail = lo, conf
        lo = max(8, lo * 15 // 16 // 8 * 8)
    else:
        print(f"  not confirmed in 3 longer runs: the limit on this machine now lies below {hi} axes")
        return
    e, l = conf["exec"], conf["lat"]
    print(f"  largest number of axes at 1 ms: {lo} (to within {hi - lo}; {hi} axes: execution p99.9 "
          f"{fail['exec']['p999']:.0f} us + wake latency p99.9 {fail['lat']['p999']:.0f} us >= 1 ms)")
    print(f"  bound: execution time vs the 1 ms period; at {lo} axes execution mean {e['mean']:.0f} us = "
          f"{e['mean'] / 10:.0f} %, p99 {e['p99']:.0f} us = {e['p99'] / 10:.0f} %, p99.9 {e['p999']:.0f} us = "
          f"{e['p999'] / 10:.0f} %, max {e['max']:.0f} us = {e['max'] / 10:.0f} % of 1 ms, plus wake latency "
          f"p99.9 {l['p999']:.0f} us")
    stall = max(base["lat"]["max"], conf["lat"]["max"], fail["lat"]["max"])
    print(f"  with no overrun at all: {clean} axes was the largest run with 0 overruns; the 1-axis run had "
          f"{base['overruns']} in {SECONDS:g} s and wake-ups came up to {stall / 1000:.1f} ms late in these runs, "
          f"so on this machine a run free of overruns is also a matter of luck")


def main():
    shutil.rmtree(WORK, ignore_errors=True)   # programs are rebuilt from the present sources
    os.makedirs(WORK)
    t0 = time.time()
    one_call()
    scans()
    most_axes()
    print(f"\n(bench-epicpos took {time.time() - t0:.0f} s)")


main()
