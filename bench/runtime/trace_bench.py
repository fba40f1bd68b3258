#!/usr/bin/env python3
"""The trace's costs: what 16 channels add to a scan per cycle (tracecost,
target <= 1 us; and in plcrt's own scan_cycle, instructions counted by
callgrind with and without a trace armed), and the download of a 16 channels x 16384 samples capture
over Modbus on loopback with plctrace's client (target < 2 s), from a plcrt
scanning at 250 us (bench/runtime/trace.st); with the overruns of the
scan's own during the capture.

usage: trace_bench.py PLCRT TRACECOST WORKDIR"""
import importlib.machinery
import re
import shutil
import importlib.util
import os
import signal
import socket
import subprocess
import sys
import time

PLCRT, COST, WORK = sys.argv[1:4]
HERE = os.path.dirname(os.path.abspath(__file__))
os.makedirs(WORK, exist_ok=True)

loader = importlib.machinery.SourceFileLoader("plctrace", os.path.join(HERE, "..", "..", "plc_runtime", "plctrace"))
spec = importlib.util.spec_from_loader("plctrace", loader)
pt = importlib.util.module_from_spec(spec)
loader.exec_module(pt)

print("trace: cost per cycle (bench/runtime/tracecost.c)", flush=True)
subprocess.run([COST, "200000"], check=True)

with socket.socket() as s:
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]


def start(prefix=(), rt=True):
    cfg = os.path.join(WORK, "trace.ini")
    with open(cfg, "w") as f:
        f.write(f"[io]\nbackend = none\n[modbus]\nport = {port}\n[retain]\nfile =\n"
                + ("" if rt else "[scan]\npriority = 0\nlock_memory = no\n"))
    log = open(os.path.join(WORK, "plcrt.log"), "w+")
    plc = subprocess.Popen([*prefix, PLCRT, "-c", cfg], stdout=log, stderr=log)
    for _ in range(600):
        try:
            socket.create_connection(("127.0.0.1", port), timeout=0.2).close()
            break
        except OSError:
            time.sleep(0.05)
    return plc, pt.Plc("127.0.0.1", port, timeout=10)


def setup16(p, n, trig=0, tvar=0xFFFFFFFF, level=0.0):
    ids = [p.lookup(f"v{i}")[0] for i in range(16)]
    p.command(pt.CLAIM)
    p.command(pt.CHANNELS, [x for i in ids for x in pt.args32(i)])
    lv = list(pt.struct.unpack(">4H", pt.struct.pack(">d", level)))
    p.command(pt.SETUP, [1] + pt.args32(n) + pt.args32(0) + [trig] + pt.args32(tvar) + lv + [0])


if shutil.which("valgrind") and shutil.which("callgrind_annotate"):
    per = []
    for armed in (False, True):
        out = os.path.join(WORK, f"callgrind.{int(armed)}")
        plc, p = start(("valgrind", "--tool=callgrind", "--toggle-collect=scan_cycle",
                        f"--callgrind-out-file={out}"), rt=False)
        if armed:   # 16 channels, a trigger that never fires: the ring turns every cycle
            setup16(p, 16384, 3, p.lookup("n")[0], 2.0e9)
            p.command(pt.ARM)
        time.sleep(4)
        r = p.c.read_input_registers(1024, 2, slave=1).registers
        p.close()
        plc.send_signal(signal.SIGTERM)
        plc.wait(timeout=60)
        ann = subprocess.run(["callgrind_annotate", out], capture_output=True, text=True).stdout
        m = re.search(r"^\s*([\d,]+)\s+(\(100.0%\)\s+)?PROGRAM TOTALS", ann, re.M)
        per.append(int(m.group(1).replace(",", "")) / max(r[0] << 16 | r[1], 1) if m else 0)
    print(f"trace: instructions per cycle in plcrt's scan_cycle (callgrind): {per[0]:.0f} without a trace, "
          f"{per[1]:.0f} with 16 channels armed: +{per[1] - per[0]:.0f}")

plc, p = start()
try:

    def own_overruns():
        r = p.c.read_input_registers(1024 + 40, 2, slave=1).registers
        return r[0] << 16 | r[1]

    n = 16384
    setup16(p, n)
    ov0 = own_overruns()
    st0 = p.status()
    p.command(pt.ARM)
    p.command(pt.TRIGGER)
    t0 = time.monotonic()
    while True:
        st = p.status()
        if st["readable"] and st["seq"] > st0["captures"]:
            break
        time.sleep(0.05)
    fill = time.monotonic() - t0
    ov1 = own_overruns()
    t0 = time.monotonic()
    rows = pt.download(p, st)
    dl = time.monotonic() - t0
    p.command(pt.RELEASE)
    cyc = rows["cycle"]
    whole = all(b - a == 1 for a, b in zip(cyc, cyc[1:])) and all(
        v == (cyc[k] + 1) * (i + 1) for i, (_, col) in enumerate(rows["cols"]) for k, v in enumerate(col))
    print(f"trace: 16 channels x {n} samples captured at 250 us in {fill:.1f} s; "
          f"overruns of the scan's own meanwhile: {ov1 - ov0}")
    print(f"trace: download over Modbus on loopback (plctrace's client, pymodbus, FC 23 windows): "
          f"{dl:.2f} s (target < 2 s), {16 * n * 2 / dl / 1e3:.0f} k registers/s; "
          f"every value checked against the program: {'yes' if whole else 'NO'}")
    p.close()
finally:
    plc.send_signal(signal.SIGTERM)
    plc.wait(timeout=30)
