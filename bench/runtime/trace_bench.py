#!/usr/bin/env python3
"""The trace's costs: what 16 channels add to a scan per cycle (tracecost,
target <= 1 us), and the download of a 16 channels x 16384 samples capture
over Modbus on loopback with plctrace's client (target < 2 s), from a plcrt
scanning at 250 us (bench/runtime/trace.st); with the overruns of the
scan's own during the capture.

usage: trace_bench.py PLCRT TRACECOST WORKDIR"""
import importlib.machinery
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
cfg = os.path.join(WORK, "trace.ini")
with open(cfg, "w") as f:
    f.write(f"[io]\nbackend = none\n[modbus]\nport = {port}\n[retain]\nfile =\n")
log = open(os.path.join(WORK, "plcrt.log"), "w+")
plc = subprocess.Popen([PLCRT, "-c", cfg], stdout=log, stderr=log)
try:
    for _ in range(200):
        try:
            socket.create_connection(("127.0.0.1", port), timeout=0.2).close()
            break
        except OSError:
            time.sleep(0.05)
    p = pt.Plc("127.0.0.1", port)

    def own_overruns():
        r = p.c.read_input_registers(1024 + 40, 2, slave=1).registers
        return r[0] << 16 | r[1]

    n = 16384
    ids = [p.lookup(f"v{i}")[0] for i in range(16)]
    p.command(pt.CLAIM)
    p.command(pt.CHANNELS, [x for i in ids for x in pt.args32(i)])
    p.command(pt.SETUP, [1] + pt.args32(n) + pt.args32(0) + [0] + pt.args32(0xFFFFFFFF) + [0, 0, 0, 0] + [0])
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
