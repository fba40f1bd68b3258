#!/usr/bin/env python3
"""plcrt and the signals a careless hand or a closing terminal sends
(docs/runtime.md, "Running"): every stop signal takes the same orderly way
out (outputs safe, retain saved, exit 0), and a stop asked for while plcrt
is still starting runs no cycle at all.

usage: test_signals.py PLCRT WORKDIR  (PLCRT: the tests' iotest program)
Prints PASS:/FAIL: lines; exits 1 if anything failed."""
import os
import signal
import struct
import subprocess
import sys

from pymodbus.client import ModbusTcpClient

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from peer import Plcrt, Report, default_signals, free_port, wait_for  # noqa: E402

PLCRT, WORK = sys.argv[1], sys.argv[2]
report = Report("signals")
KEEP = 9000            # holding registers of the retained DINT KEEP


def ini(port, retain):
    path = os.path.join(WORK, "signals.ini")
    with open(path, "w") as f:
        f.write(f"""[io]
backend = none
[modbus]
port = {port}
[modbus.symbols]
CONFIG0.RES0.INST0.KEEP = holding {KEEP} rw
[retain]
file = {retain}
; only the save at the stop can keep what the test writes
period = 3600
""")
    return path


def keep(port, value=None):
    c = ModbusTcpClient("127.0.0.1", port=port, timeout=3)
    assert c.connect()
    if value is not None:
        r = c.write_registers(KEEP, [(value >> 16) & 0xFFFF, value & 0xFFFF], slave=1)
        assert not r.isError(), r
    regs = c.read_holding_registers(KEEP, 2, slave=1).registers
    c.close()
    return struct.unpack(">i", struct.pack(">HH", *regs))[0]


def test_stop_signals():
    """SIGHUP (ssh session or terminal closed) and SIGQUIT (Ctrl-backslash)
    killed plcrt by their default action: no safe state, no final save."""
    for sig, value in ((signal.SIGHUP, 4711), (signal.SIGQUIT, -815)):
        name = signal.Signals(sig).name
        retain = os.path.join(WORK, f"{name}.retain")
        port = free_port()
        cfg = ini(port, retain)
        p = Plcrt(PLCRT, cfg, WORK, name)
        keep(port, value)
        rc = p.stop(sig)
        out = p.output()
        report(f"{name}: exit status 0, outputs safe and retain saved",
               rc == 0 and f"outputs safe (DAC 0 V), retain saved to {retain}" in out,
               f"rc {rc}: {out[-300:]}")
        p = Plcrt(PLCRT, cfg, WORK, name)
        got = keep(port)
        p.stop()
        report(f"{name}: the value written just before it is retained", got == value,
               f"retained {got}, written {value}")


def test_nohup():
    """Started under nohup (SIGHUP ignored), plcrt outlives the terminal."""
    port = free_port()
    cfg = ini(port, os.path.join(WORK, "nohup.retain"))
    log = open(os.path.join(WORK, "nohup.log"), "w+")
    p = subprocess.Popen([PLCRT, "-c", cfg], stdout=log, stderr=subprocess.STDOUT,
                         preexec_fn=lambda: (default_signals(), signal.signal(signal.SIGHUP, signal.SIG_IGN)))
    try:
        ok = wait_for(lambda: "running CONFIG0" in open(log.name).read(), 30)
        p.send_signal(signal.SIGHUP)
        try:
            p.wait(timeout=1)
        except subprocess.TimeoutExpired:
            pass
        alive = p.poll() is None
        # whatever the host's speed: had plcrt taken the SIGHUP, it would
        # stop on it and say so, SIGTERM or not (a pending SIGHUP is taken
        # before a SIGTERM); the log must name SIGTERM alone
        p.send_signal(signal.SIGTERM)
        rc = p.wait(timeout=30)
        out = open(log.name).read()
        by_term = "SIGTERM: stopping" in out and "SIGHUP" not in out
        report("under nohup (SIGHUP ignored): SIGHUP leaves plcrt running; SIGTERM still stops it, status 0",
               ok and alive and by_term and rc == 0,
               f"started {ok}, alive after SIGHUP {alive}, stopped by SIGTERM alone {by_term}, rc {rc}")
    finally:
        if p.poll() is None:
            p.kill()
            p.wait()


def test_stop_during_start_up():
    """A SIGTERM that comes while plcrt is starting (here: already pending
    when it starts, a pending signal survives exec) stops it before the
    first cycle: nothing runs, the outputs are put in their safe state, the
    retain file stays the generation it loaded."""
    retain = os.path.join(WORK, "startup.retain")
    port = free_port()
    cfg = ini(port, retain)
    p = Plcrt(PLCRT, cfg, WORK, "startup")
    keep(port, 1234)
    p.stop()
    with open(retain, "rb") as f:
        before = f.read()

    def pending_sigterm():
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGTERM})
        os.kill(os.getpid(), signal.SIGTERM)

    log = os.path.join(WORK, "startup-pending.log")
    with open(log, "w") as f:
        try:
            rc = subprocess.run([PLCRT, "-c", cfg], stdout=f, stderr=subprocess.STDOUT,
                                preexec_fn=pending_sigterm, timeout=10).returncode
        except subprocess.TimeoutExpired:
            rc = "still running after 10 s"
    with open(log) as f:
        out = f.read()
    with open(retain, "rb") as f:
        after = f.read()
    report("SIGTERM during the start-up: exit status 0, stopped before the first cycle, outputs safe",
           rc == 0 and "stopped before the first cycle, outputs safe (DAC 0 V)" in out, f"rc {rc}: {out[-300:]}")
    report("SIGTERM during the start-up: no cycle ran, the retain file is untouched",
           after == before and "running CONFIG0" not in out, out[-300:])


def main():
    os.makedirs(WORK, exist_ok=True)
    for f in os.listdir(WORK):
        os.unlink(os.path.join(WORK, f))
    try:
        for t in (test_stop_signals, test_nohup, test_stop_during_start_up):
            try:
                t()
            except Exception as e:  # noqa: BLE001
                report(t.__name__, False, repr(e))
    finally:
        Plcrt.kill_all()
    sys.exit(0 if report.all_passed() else 1)


if __name__ == "__main__":
    main()
