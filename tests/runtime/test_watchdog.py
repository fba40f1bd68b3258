#!/usr/bin/env python3
"""The scan's watchdog (docs/runtime.md, "The scan"; docs/config.md
[scan] watchdog_ms): a program that does not return (here a FOR loop whose
bound a client sets to the largest DINT, so that it never ends) used to
leave the outputs at their last values for ever, and plcrt deaf to SIGTERM
(the stop waits for the cycle to end). Now the outputs go to their safe
state within the watchdog time and plcrt ends with status 3; a cycle that
is merely long (an overrun) does not trip it.

usage: test_watchdog.py PLCRT WORKDIR  (PLCRT: the tests' spin program, 2 ms)
Prints PASS:/FAIL: lines; exits 1 if anything failed."""
import os
import re
import sys

from pymodbus.client import ModbusTcpClient

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from peer import Plcrt, Report, free_port, wait_for  # noqa: E402

PLCRT, WORK = sys.argv[1], sys.argv[2]
report = Report("watchdog")
WATCHDOG_MS = 300


def main():
    os.makedirs(WORK, exist_ok=True)
    port = free_port()
    cfg = os.path.join(WORK, "watchdog.ini")
    with open(cfg, "w") as f:
        f.write(f"[io]\nbackend = none\n[modbus]\nport = {port}\n[scan]\nwatchdog_ms = {WATCHDOG_MS}\n"
                "[retain]\nfile =\n")
    p = Plcrt(PLCRT, cfg, WORK, "watchdog")
    try:
        mb = ModbusTcpClient("127.0.0.1", port=port, timeout=3)
        mb.connect()

        def md(i):
            r = mb.read_holding_registers(2048 + 2 * i, 2, slave=1)
            return None if r.isError() else r.registers[0] << 16 | r.registers[1]

        def set_md(i, v):
            return not mb.write_registers(2048 + 2 * i, [v >> 16, v & 0xFFFF], slave=1).isError()

        # long cycles (tens of ms, overruns of the 2 ms period) are no reason
        # counted in cycles, not slept for: from two cycles after the write
        # on, every cycle is long; ten of them run and plcrt is still there
        set_md(0, 5_000_000)
        w = wait_for(lambda: md(1), 20)
        c0 = wait_for(lambda: (lambda c: c if c is not None and c >= w + 2 else None)(md(1)), 30, 0.02) if w else None
        c1 = wait_for(lambda: (lambda c: c if c is not None and c >= c0 + 10 else None)(md(1)), 60, 0.02) \
            if c0 else None
        report(f"cycles of millions of iterations (overruns) run on under watchdog_ms = {WATCHDOG_MS}",
               p.alive() and c1 is not None and c0 is not None and c1 > c0, f"cycles {c0} -> {c1}")
        # FOR i := 1 TO 2147483647: i never exceeds the bound, the loop never ends
        set_md(0, 2147483647)
        mb.close()
        try:       # a deadline only: how soon is what plcrt says below
            rc = p.p.wait(timeout=60)
        except Exception:  # noqa: BLE001
            rc = None
        out = p.output()
        # plcrt's own measure of the cycle it stopped (its clock, from the
        # program's start in that cycle): not before the watchdog time, and
        # within a margin of it (plcrt looks four times within the watchdog
        # time; the margin is for its housekeeping woken late on a loaded host)
        m = re.search(r"has been running for (\d+) ms in one cycle", out)
        ran = int(m.group(1)) if m else None
        report("an endless program: plcrt stops by itself with status 3, within the watchdog time and a margin",
               rc == 3 and ran is not None and WATCHDOG_MS <= ran < WATCHDOG_MS + 2000,
               f"rc {rc}, stopped after the program ran {ran} ms")
        report("it says what happened, where the limit is set, and that the outputs are safe",
               "watchdog: the program has been running for" in out
               and f"[scan] watchdog_ms = {WATCHDOG_MS}" in out
               and "stopped by the watchdog: outputs safe (DAC 0 V)" in out, out[-500:])
    finally:
        Plcrt.kill_all()
    sys.exit(0 if report.all_passed() else 1)


if __name__ == "__main__":
    main()
