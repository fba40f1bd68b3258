#!/usr/bin/env python3
"""Ctrl-C on `make run-epicpos` (what `make run` runs), typed at a terminal.

    test_ctrl_c.py TREE INI WORK

make runs in a pseudo-terminal, as a person would start it, on the
example's configuration with a free port and a retain file in WORK (make's
INI=). Once plcrt serves Modbus, ^C is typed: the terminal driver sends
SIGINT to the foreground process group. What the person must see: the one
line `plcrt: outputs safe (DAC 0 V), retain saved to FILE`, make ending with
status 0 and no "Interrupt" error, the retain file written."""
import os
import pty
import select
import socket
import sys
import time

import exlib
from exlib import example_ini, free_port, report
from peer import default_signals

tree, ini, work = os.path.abspath(sys.argv[1]), sys.argv[2], os.path.abspath(sys.argv[3])
os.makedirs(work, exist_ok=True)
port = free_port()
retain = os.path.join(work, "ctrlc.retain")
myini = example_ini(ini, os.path.join(work, "ctrlc.ini"), port, retain)

env = {k: v for k, v in os.environ.items() if k not in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL")}
pid, fd = pty.fork()
if pid == 0:
    default_signals()           # a terminal's make: Ctrl-C not ignored, whatever started the tests
    os.chdir(tree)
    os.execvpe("make", ["make", "--no-print-directory", "run-epicpos", f"INI={myini}"], env)

out = b""


def read_for(seconds, until=None):
    """Collect the terminal's output for a while (or until a condition)."""
    global out
    end = time.time() + seconds
    while time.time() < end:
        if until and until():
            return True
        r, _, _ = select.select([fd], [], [], 0.1)
        if r:
            try:
                data = os.read(fd, 4096)
            except OSError:
                return False
            if not data:
                return False
            out += data
    return bool(until and until())


def serving():
    try:
        socket.create_connection(("127.0.0.1", port), timeout=0.2).close()
        return True
    except OSError:
        return False


up = read_for(60, serving)
report("ctrl-c: make run-epicpos in a terminal serves Modbus", up, out.decode(errors="replace")[-800:])
read_for(0.5)
os.write(fd, b"\x03")
read_for(15)
deadline = time.time() + 5
status = None
while time.time() < deadline:
    done, st = os.waitpid(pid, os.WNOHANG)
    if done:
        status = os.waitstatus_to_exitcode(st)
        break
    time.sleep(0.1)
if status is None:
    os.kill(pid, 9)
    os.waitpid(pid, 0)
text = out.decode(errors="replace").replace("\r\n", "\n")
want = f"plcrt: outputs safe (DAC 0 V), retain saved to {retain}"
lines = [ln.strip() for ln in text.splitlines()]
report(f"ctrl-c: plcrt prints '{want}'", want in lines, text[-800:])
report("ctrl-c: make ends with status 0 and no 'Interrupt'", status == 0 and "Interrupt" not in text,
       f"status {status}: {text[-800:]}")
report("ctrl-c: the retain file is written", os.path.exists(retain), os.listdir(work))
after = text.split(want, 1)[1].strip() if want in text else ""
report("ctrl-c: nothing after that line (one line on Ctrl-C)", want in text and after == "", repr(after))
sys.exit(1 if exlib.failed else 0)
