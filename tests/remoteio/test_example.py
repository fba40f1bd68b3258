#!/usr/bin/env python3
"""The remote I/O example as a user runs it (`make run-remoteio`,
examples/remoteio/README.md): run.sh starts the line, the two pymodbus
modules and plcrt; the lamps follow the buttons, the pump fills the tank
from level 300, the flow counter the PLC read comes back to the module,
and a stop leaves nothing running.

usage: test_example.py PLCRT WORKDIR"""
import os
import re
import signal
import subprocess
import sys
import threading

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "common"))
from peer import Report, free_port, wait_for  # noqa: E402

PLCRT, WORK = sys.argv[1], sys.argv[2]
os.makedirs(WORK, exist_ok=True)
report = Report("remoteio-example")
# the example's file, on ports free now (others may run plcrt on this host)
panel = free_port()
ini = os.path.join(WORK, "remoteio.ini")
with open("examples/remoteio/remoteio.ini") as f:
    text = f.read().replace("port = 5020", f"port = {panel}")
with open(ini, "w") as f:
    f.write(text + f"[modbus]\nport = {free_port()}\n")
p = subprocess.Popen(["examples/remoteio/run.sh", PLCRT, ini], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                     text=True, start_new_session=True, env=dict(os.environ, REMOTEIO_PANEL_PORT=str(panel)))
lines = []


def read():
    for line in p.stdout:
        lines.append(line.rstrip())
        print("  ", line.rstrip(), flush=True)


threading.Thread(target=read, daemon=True).start()
LINE = re.compile(r"buttons (\d{8}) lamps (\d{8}) \| level (\d+) pump (ON|off)\s+flow (\d+) \(PLC saw (\d+)\)")


def parsed():
    return [m.groups() for m in (LINE.search(x) for x in lines) if m]


try:
    report("the modules and plcrt start", wait_for(lambda: any("running" in x for x in lines) and parsed(), 30),
           "\n".join(lines[-10:]))
    # a lamp lit by the button pressed: the button of this line or of the one before
    report("the lamps follow the buttons", wait_for(lambda: any(
        lamps != "00000000" and lamps in (b, prev[0]) for prev, (b, lamps, *_) in zip(parsed(), parsed()[1:])), 30),
        "\n".join(lines[-6:]))
    report("the pump runs once the level fell below 300", wait_for(
        lambda: any(pump == "ON" for _, _, _, pump, _, _ in parsed()), 60), "\n".join(lines[-6:]))
    report("the flow counter read by the PLC comes back to the module (32-bit, low word first)", wait_for(
        lambda: any(int(seen) > 0x10 and int(seen) <= int(flow) for *_, flow, seen in parsed()), 30),
        "\n".join(lines[-6:]))
finally:
    os.killpg(p.pid, signal.SIGTERM)
    try:
        p.wait(timeout=15)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        p.wait()
# the reader thread may still be taking the last lines: polled for
report("stopped: plcrt's outputs safe", wait_for(lambda: any("outputs safe" in x for x in lines), 20),
       "\n".join(lines[-5:]))
sys.exit(0 if report.all_passed() else 1)
