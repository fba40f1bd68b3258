#!/usr/bin/env python3
"""plcrt's configuration checked whole, as a user meets it: plcrt
--check-config and the start on temporary files, each bad one refused with
exit status 2 and a message naming file:line, [section] and key; the good
ones served (a Modbus client on the address and port the user meant).

usage: test_config.py PLCRT WORKDIR   (PLCRT built from st/iotest.st)
Prints PASS:/FAIL: lines; exits 1 if anything failed."""
import errno
import os
import socket
import subprocess
import sys

from pymodbus.client import ModbusTcpClient

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from peer import Plcrt, Report, free_port  # noqa: E402

PLCRT, WORK = sys.argv[1], sys.argv[2]
report = Report("runtime-config")
os.makedirs(WORK, exist_ok=True)
VAR = "CONFIG0.RES0.INST0."


def write(name, text):
    path = os.path.join(WORK, name)
    with open(path, "w") as f:
        f.write(text)
    return path


def run(path, check=True):
    argv = [PLCRT, "-c", path] + (["--check-config"] if check else [])
    try:
        r = subprocess.run(argv, capture_output=True, text=True, timeout=10)
    except subprocess.TimeoutExpired:
        return -1, "timeout (plcrt ran with this configuration)"
    return r.returncode, r.stdout + r.stderr


def refused(name, path, want, check=True):
    """plcrt exits 2 and its message holds want."""
    rc, out = run(path, check)
    ok = rc == 2 and want in out
    report(name, ok, "" if ok else f"status {rc}, wanted '{want}' in: {out.strip()[-400:]}")


def serves(host, port):
    """A Modbus read of the diagnostics (input registers 1024..) answers."""
    c = ModbusTcpClient(host, port=port, timeout=3)
    try:
        if not c.connect():
            return False
        r = c.read_input_registers(1024, 2, slave=1)
        return not r.isError()
    finally:
        c.close()


def start_and_serve(name, path, port):
    try:
        p = Plcrt(PLCRT, path, WORK, name)
    except RuntimeError as e:
        report(f"{name}: serves on 127.0.0.1:{port}", False, str(e))
        return
    ok = serves("127.0.0.1", port)
    rc = p.stop()
    report(f"{name}: serves on 127.0.0.1:{port}", ok and rc == 0, f"served {ok}, exit {rc}: {p.output()[-300:]}"
           if not (ok and rc == 0) else "")


def foreign_address():
    """An address of the documentation ranges (RFC 5737) that this host
    does not have (bind() says so)."""
    for a in ("192.0.2.1", "198.51.100.1", "203.0.113.1", "192.0.2.254"):
        with socket.socket() as s:
            try:
                s.bind((a, 0))
            except OSError as e:
                if e.errno == errno.EADDRNOTAVAIL:
                    return a
    return None


def base(port, extra_modbus="", tail=""):
    return (f"[io]\nbackend = none\n[modbus]\nport = {port}\n{extra_modbus}"
            f"[retain]\nfile = {WORK}/plc.retain\n{tail}")


# host names and IPv6 in [modbus] bind
port = free_port()
path = write("localhost.ini", base(port, "bind = localhost\n"))
rc, out = run(path)
report("bind = localhost: --check-config accepts it", rc == 0 and "configuration OK" in out, "" if rc == 0 else out)
start_and_serve("bind = localhost", path, port)

path = write("ipv6.ini", "[io]\nbackend = none\n[modbus]\nbind = ::1\n")
refused("bind = ::1: --check-config refuses it at its line", path, f"{path}:4: [modbus] bind: '::1' is an IPv6 address")
refused("bind = ::1: the start refuses it at its line", path, f"{path}:4: [modbus] bind: '::1' is an IPv6 address", False)

a = foreign_address()
report("an address this host does not have (RFC 5737)", a is not None)
if a:
    path = write("foreign.ini", f"[io]\nbackend = none\n[modbus]\nbind = {a}\n")
    want = f"{path}:4: [modbus] bind: {a} is not an address of this host"
    refused(f"bind = {a}: --check-config refuses it", path, want)
    refused(f"bind = {a}: the start refuses it, naming the key", path, want, False)

# a folder given as the file
refused("-c FOLDER: an error naming the folder", WORK, f"{WORK}: is a folder, not a configuration file")
refused("-c FOLDER: the start refuses it too", WORK, f"{WORK}: is a folder", False)

# an empty name (a shell variable left unset: plcrt -c "$CFG")
refused("-c '': says a file name is missing (was ': No such file or directory')", "",
        "-c needs the name of a configuration file")
refused("-c '': the start refuses it too", "", "-c needs the name of a configuration file", False)

# long lines: a valid status_vars line of 234 characters, line numbers after it
names = ["TICKS", "KEEP_REAL", "QW_ECHO", "IW_FIRST", "QX_LAST", "IX_LAST", "IW_LAST", "KEEP"]
line = "status_vars = " + ", ".join(VAR + n for n in names)
path = write("long.ini", f"[plc]\n{line}\n" + base(free_port()))
rc, out = run(path)
report(f"a {len(line)}-character status_vars line is accepted", rc == 0 and "configuration OK" in out,
       "" if rc == 0 else out)
path = write("long-bad.ini", f"[plc]\n{line}\n; {'-' * 300}\n[scan]\npriorty = 10\n")
refused("the error after long lines is at its own line", path, f"{path}:5: [scan] priorty: unknown key")
path = write("long-var.ini", f"; {'=' * 250}\n[plc]\nstatus_vars = {VAR}TICKS, {VAR}NOSUCH\n")
refused("status_vars: a variable not in the program, at its line", path,
        f"{path}:3: [plc] status_vars: no variable {VAR}NOSUCH in the program")
line = f"status_vars = {VAR}TICKS{' ' * 2100}"
path = write("too-long.ini", f"[plc]\nlog_level = info\n{line}\n")
refused("a line over 2048 characters, at its true line", path,
        f"{path}:3: [plc] status_vars: line of {len(line)} characters; at most 2048")

# retain file in a missing folder
path = write("retain.ini", f"[io]\nbackend = none\n[retain]\nperiod = 5\nfile = {WORK}/no-such-folder/plc.retain\n")
refused("retain file in a missing folder", path,
        f"{path}:5: [retain] file: folder {WORK}/no-such-folder: No such file or directory")

# the symbol map is checked with Modbus disabled
path = write("symbols-off.ini", f"[io]\nbackend = none\n[modbus]\nenabled = no\n[modbus.symbols]\n"
             f"{VAR}KEEP = holding 9000 rw\n{VAR}NOSUCH = holding 9100\n")
refused("symbols checked with Modbus disabled", path,
        f"{path}:7: [modbus.symbols] {VAR}NOSUCH: no such variable in the program")
path = write("symbols-off-bool.ini", f"[io]\nbackend = none\n[modbus]\nenabled = no\n[modbus.symbols]\n"
             f"{VAR}KEEP = coil 10\n")
refused("symbols checked with Modbus disabled (type)", path,
        f"{path}:6: [modbus.symbols] {VAR}KEEP: a coil holds a BOOL, not a DINT")

# ports are decimal, leading zeros included
port = free_port()
path = write("port0.ini", base(f"0{port}"))
rc, out = run(path)
report(f"port = 0{port}: accepted", rc == 0, "" if rc == 0 else out)
start_and_serve(f"port = 0{port}", path, port)
path = write("port-big.ini", base(65536))
refused("port = 65536 refused at its line", path, f"{path}:4: [modbus] port: '65536' is not a decimal integer in 1..65535")

# a port taken when plcrt starts: the start names the key
with socket.socket() as busy:
    busy.bind(("127.0.0.1", 0))
    busy.listen(1)
    port = busy.getsockname()[1]
    path = write("busy.ini", base(port))
    rc, out = run(path)
    report("a port in use passes --check-config (a running plcrt may hold it)", rc == 0, "" if rc == 0 else out)
    refused("a port in use: the start names [modbus] port, status 2", path,
            f"{path}:4: [modbus] port: cannot listen on 127.0.0.1:{port}", False)
    # a second plcrt on the port of a running one stops before its backend
    # opens anything (a CANopen master would reset the nodes the first one
    # drives): here the CAN interface does not even exist, and the message
    # is about the port, not about the interface
    path = write("busy-can.ini", f"[io]\nbackend = canopen\n[modbus]\nport = {port}\n[canopen]\n"
                 "interface = nocan9\n[canopen.io1]\nid = 5\n[retain]\nfile =\n")
    rc, out = run(path, False)
    report("a port in use: refused before the backend is opened (no CAN interface touched)",
           rc == 2 and f"{path}:4: [modbus] port: cannot listen" in out and "another plcrt" in out
           and "nocan9" not in out and "backend canopen" not in out, f"status {rc}: {out.strip()[-400:]}")

# two plcrt on one retain file (two ports): the second is refused, naming
# the first's pid, before it loads or saves anything
shared = os.path.join(WORK, "shared.retain")
first = Plcrt(PLCRT, write("shared1.ini", f"[io]\nbackend = none\n[modbus]\nport = {free_port()}\n"
                                          f"[retain]\nfile = {shared}\n"), WORK, "shared")
path = write("shared2.ini", f"[io]\nbackend = none\n[modbus]\nport = {free_port()}\n[retain]\nfile = {shared}\n")
refused("a retain file in use by another plcrt: refused, naming it and its pid", path,
        f"{path}:6: [retain] file: {shared} is in use by another plcrt (pid {first.p.pid})", False)
first.stop()
second = Plcrt(PLCRT, path, WORK, "shared")
report("once the first stopped, the second starts on the file", second.alive())
second.stop()

Plcrt.kill_all()
sys.exit(0 if report.all_passed() else 1)
