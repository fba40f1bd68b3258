#!/usr/bin/env python3
"""plcrt told whose fault an overrun is: a program made too slow for its
2 ms period over Modbus (tests/runtime/st/spin.st) overruns in every cycle,
each counted as the program's own; plcrt keeps serving Modbus meanwhile and
the cycles are back on time once the program is light again.

usage: test_overrun.py PLCRT WORKDIR"""
import os
import re
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from peer import Plcrt, Report, free_port, wait_for  # noqa: E402
from pymodbus.client import ModbusTcpClient  # noqa: E402

PLCRT, WORK = sys.argv[1], sys.argv[2]
report = Report("runtime-overrun")
os.makedirs(WORK, exist_ok=True)
port = free_port()
cfg = os.path.join(WORK, "spin.ini")
with open(cfg, "w") as f:
    f.write(f"[io]\nbackend = none\n[modbus]\nbind = 127.0.0.1\nport = {port}\n")

plc = Plcrt(PLCRT, cfg, WORK, "spin")       # returns once Modbus listens
mb = ModbusTcpClient("127.0.0.1", port=port, timeout=3)


def md(i):
    r = mb.read_holding_registers(2048 + 2 * i, 2, slave=1)
    return None if r.isError() else r.registers[0] << 16 | r.registers[1]


def set_md(i, v):
    return not mb.write_registers(2048 + 2 * i, [v >> 16, v & 0xFFFF], slave=1).isError()


try:
    ok = wait_for(mb.connect, 10, 0.05) and wait_for(lambda: md(1) is not None, 5, 0.05)
    report("plcrt serves Modbus", ok)
    # heavy: 20 million iterations take far longer than 2 ms on any machine
    set_md(0, 20_000_000)
    w = md(1)
    # the write reaches the program at the start of the cycle after the one
    # running: from two cycles on, every cycle is heavy (counted, not slept for)
    c0 = wait_for(lambda: (lambda c: c if c is not None and c >= w + 2 else None)(md(1)), 30, 0.05)
    c1 = wait_for(lambda: (lambda c: c if c is not None and c >= c0 + 10 else None)(md(1)), 60, 0.05) \
        if c0 else None
    r = mb.read_input_registers(1024 + 40, 2, slave=1)
    own_mb = None if r.isError() else r.registers[0] << 16 | r.registers[1]
    set_md(0, 0)
    report("Modbus is served while the program overruns", c0 is not None and c1 is not None and c1 > c0,
           f"cycles {c0} -> {c1}")

    # light again: 250 cycles (0.5 s of the 2 ms period) without an overrun
    # of the program's own, as plcrt counts them (1064); a late wake-up is
    # the host's (load, no SCHED_FIFO) and is not counted there. The cycle
    # counter (1024) and 1064 come in one request, so from one cycle.
    def diag():
        r = mb.read_input_registers(1024, 42, slave=1)
        return None if r.isError() else (r.registers[0] << 16 | r.registers[1], r.registers[40] << 16 | r.registers[41])
    n = diag()[0]
    light = wait_for(lambda: (lambda d: d if d[0] >= n + 2 else None)(diag()), 30, 0.05)
    end = wait_for(lambda: (lambda d: d if d[0] >= light[0] + 250 else None)(diag()), 60, 0.05) if light else None
    report("light again, the cycles are back on time: 250 cycles without an overrun of the program's own",
           light is not None and end is not None and end[1] == light[1],
           f"cycle {light} -> {end} (cycles, own overruns)")
finally:
    rc = plc.stop()
    mb.close()
out = plc.output()
m = re.search(r"(\d+) overruns \(", out)
e = re.search(r"overruns: (\d+) with the program's execution alone over the period, (\d+) after a late wake-up", out)
heavy = (c1 - c0) if c1 is not None and c0 is not None else 0
total = int(m.group(1)) if m else -1
own = int(e.group(1)) if e else -1
report("every heavy cycle is an overrun counted as the program's own",
       rc == 0 and heavy >= 3 and own >= heavy - 1 and own <= total,
       f"{heavy} heavy cycles, {total} overruns, {own} the program's own; exit {rc}")
report("the diagnostics register 1064 counts them while it happens",
       own_mb is not None and own_mb >= heavy - 1, f"register 1064 = {own_mb}, {heavy} heavy cycles")
warn = re.search(r"overrun\(s\) \(total \d+, \d+ periods skipped, (\d+) with the program alone", out)
report("the overrun warning says how many were the program's", warn is not None and int(warn.group(1)) >= 1,
       "no such warning in the log" if warn is None else warn.group(0))
if not report.all_passed():
    print(out[-2000:])
sys.exit(0 if report.all_passed() else 1)
