#!/usr/bin/env python3
"""Remote I/O polling (the modbus_io backend, docs/remote-io.md): for 1, 10
and 32 remote TCP devices of 125 holding registers each, served by
libmodbus's own modbus_reply (bench/runtime/refserver.c):

- the polls per second plcrt achieves per device, beside a plain libmodbus
  client loop doing the same reads as fast as the server answers
  (bench/runtime/mbloop.c, the bound);
- the age of a device's newest input at the scan (median, p99), from
  plcrt's own diagnostics, beside the duration of one plain poll;
- the scan's execution time (mean, p99) with the polling and without it.

plcrt runs a 1 ms program with `period_ms = 0` (a poll per scan period at
most). The image holds 125 registers per device in %IW and %MW for 16
devices; devices 17-32 read 124 registers into %ID (it takes pairs).

usage: remoteio_bench.py PLCRT REFSERVER MBLOOP WORKDIR"""
import os
import socket
import statistics
import subprocess
import sys
import time

from pymodbus.client import ModbusTcpClient

PLCRT, REF, LOOP, WORK = sys.argv[1:5]
SECONDS = int(os.environ.get("BENCH_SECONDS", "4"))
os.makedirs(WORK, exist_ok=True)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def block(k):
    if k < 8:
        return f"read = holding 0 125 %IW{125 * k}"
    if k < 16:
        return f"read = holding 0 125 %MW{125 * (k - 8)}"
    return f"read = holding 0 124 %ID{62 * (k - 16)}"


def run_plcrt(ndev, ref_port):
    port = free_port()
    path = os.path.join(WORK, f"remoteio-{ndev}.ini")
    body = "".join(f"[modbus_io.d{k}]\nhost = 127.0.0.1\nport = {ref_port}\nperiod_ms = 0\ntimeout_ms = 500\n"
                   f"{block(k)}\n" for k in range(ndev))
    with open(path, "w") as f:
        f.write(f"[io]\nbackend = {'modbus_io' if ndev else 'none'}\n[modbus]\nport = {port}\n"
                f"[retain]\nfile =\n{body}")
    log = open(os.path.join(WORK, f"remoteio-{ndev}.log"), "w")
    p = subprocess.Popen([PLCRT, "-c", path], stdout=log, stderr=log)
    for _ in range(200):                             # listening?
        with socket.socket() as s:
            if s.connect_ex(("127.0.0.1", port)) == 0:
                break
        time.sleep(0.05)
    c = ModbusTcpClient("127.0.0.1", port=port, timeout=3)
    c.connect()

    def u32(addr):
        r = c.read_input_registers(addr, 2)
        return r.registers[0] << 16 | r.registers[1]
    time.sleep(1.0)                                  # connected, polling
    r0 = [u32(20000 + 16 + 16 * k) for k in range(ndev)]
    t0 = time.monotonic()
    ages = []
    while time.monotonic() - t0 < SECONDS:
        for k in range(ndev):
            ages.append(u32(20000 + 16 + 16 * k + 14))
        time.sleep(0.002)
    dt = time.monotonic() - t0
    r1 = [u32(20000 + 16 + 16 * k) for k in range(ndev)]
    exec_mean, exec_p99, overruns = u32(1024 + 8), u32(1024 + 12), u32(1024 + 40)
    p.terminate()
    p.wait()
    c.close()
    rate = statistics.mean((b - a) / dt for a, b in zip(r0, r1)) if ndev else 0
    ages.sort()
    med = ages[len(ages) // 2] if ages else 0
    p99 = ages[len(ages) * 99 // 100] if ages else 0
    return rate, med, p99, exec_mean, exec_p99, overruns


ref_port = free_port()
ref = subprocess.Popen([REF, str(ref_port)], stdout=subprocess.DEVNULL)
time.sleep(0.3)
try:
    print("remote I/O: polls of 125 holding registers, libmodbus's modbus_reply as the devices' server")
    print(f"{'devices':>8} | {'plcrt polls/s/dev':>17} {'input age at scan med/p99 us':>29} | "
          f"{'plain loop polls/s/dev':>22} {'one poll med/p99 us':>20} | {'scan exec mean/p99 us':>21}")
    base = run_plcrt(0, ref_port)
    for n in (1, 10, 32):
        rate, med, p99, em, ep, ov = run_plcrt(n, ref_port)
        out = subprocess.run([LOOP, str(ref_port), str(n), str(SECONDS)], capture_output=True, text=True).stdout.split()
        lrate, lmed, lp99 = (float(x) for x in out)
        print(f"{n:>8} | {rate:>17.0f} {med:>14} / {p99:<12} | {lrate:>22.0f} {lmed:>9.0f} / {lp99:<8.0f} | "
              f"{em:>9} / {ep:<9} (own overruns {ov})")
    print(f"{'none':>8} | {'':>17} {'':>29} | {'':>22} {'':>20} | {base[3]:>9} / {base[4]:<9} (no polling)")
finally:
    ref.terminate()
    ref.wait()
