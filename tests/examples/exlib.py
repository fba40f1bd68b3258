"""Shared helpers of the example tests: start an example's plcrt on its own
configuration with a free port and a private retain file, talk to it with
pymodbus, poll for conditions, report PASS:/FAIL: lines."""
import os
import re
import struct
import sys

from pymodbus.client import ModbusTcpClient

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
import peer  # noqa: E402
from peer import Plcrt, free_port  # noqa: E402,F401

MD = 2048            # holding register of %MD0; %MDn at MD + 2n
DIAG = 1024          # plcrt's diagnostics (input registers)
SIM_DIAG = 1088      # sim backend: per axis position (counts), speed (counts/s)

failed = 0


def report(name, ok, why=""):
    global failed
    print(("PASS: " if ok else "FAIL: ") + name + ("" if ok else ": " + str(why)), flush=True)
    failed += not ok
    return ok


def example_ini(src, dst, port, retain, period=None):
    """Copy an example's configuration, changing only the Modbus port and the
    retain file (and period): the plant and program set-up stay the example's."""
    out, section = [], ""
    for line in open(src).read().splitlines():
        m = re.match(r"\s*\[(.*)\]", line)
        if m:
            section = m.group(1).strip()
        key = line.split("=")[0].strip() if "=" in line and not line.lstrip().startswith((";", "#")) else ""
        if section == "modbus" and key == "port":
            line = f"port = {port}"
        elif section == "retain" and key == "file":
            line = f"file = {retain}"
        elif section == "retain" and key == "period" and period is not None:
            line = f"period = {period}"
        out.append(line)
    with open(dst, "w") as f:
        f.write("\n".join(out) + "\n")
    return dst


def ini_section(path, name):
    """The keys of one section of an INI file (as plcrt reads them)."""
    keys, section = {}, ""
    for line in open(path).read().splitlines():
        line = line.split(";")[0].split("#")[0].strip()
        if line.startswith("["):
            section = line.strip("[]").strip()
        elif "=" in line and section == name:
            k, v = line.split("=", 1)
            keys[k.strip()] = v.strip()
    return keys


def s32(hi, lo):
    return struct.unpack(">i", struct.pack(">HH", hi, lo))[0]


class Mb:
    """A pymodbus client with the example's vocabulary: 32-bit values high word
    first, coils by address. Any Modbus error on a read raises, naming it."""

    def __init__(self, port):
        self.c = ModbusTcpClient("127.0.0.1", port=port, timeout=3)
        if not self.c.connect():
            raise RuntimeError(f"cannot connect to 127.0.0.1:{port}")

    def close(self):
        self.c.close()

    def regs(self, addr, n):
        r = self.c.read_holding_registers(addr, n, slave=1)
        if r.isError():
            raise RuntimeError(f"FC3 {addr}+{n}: {r}")
        return r.registers

    def md(self, n, count=1):
        """%MDn .. %MD(n+count-1) as signed 32-bit values."""
        r = self.regs(MD + 2 * n, 2 * count)
        v = [s32(r[2 * i], r[2 * i + 1]) for i in range(count)]
        return v if count > 1 else v[0]

    def set_md(self, n, *values):
        words = []
        for v in values:
            u = v & 0xFFFFFFFF
            words += [u >> 16, u & 0xFFFF]
        r = self.c.write_registers(MD + 2 * n, words, slave=1)
        if r.isError():
            raise RuntimeError(f"FC16 %MD{n}: {r}")

    def coils(self, addr, n=1):
        r = self.c.read_coils(addr, n, slave=1)
        if r.isError():
            raise RuntimeError(f"FC1 {addr}+{n}: {r}")
        return r.bits[:n] if n > 1 else r.bits[0]

    def set_coil(self, addr, value):
        r = self.c.write_coil(addr, bool(value), slave=1)
        if r.isError():
            raise RuntimeError(f"FC5 {addr}: {r}")

    def inputs32(self, addr, n=1):
        r = self.c.read_input_registers(addr, 2 * n, slave=1)
        if r.isError():
            raise RuntimeError(f"FC4 {addr}+{2 * n}: {r}")
        v = [s32(r.registers[2 * i], r.registers[2 * i + 1]) for i in range(n)]
        return v if n > 1 else v[0]

    def sim(self, axis=0):
        """The simulated plant's own position (counts) and speed (counts/s)."""
        return self.inputs32(SIM_DIAG + 4 * axis, 2)

    def diag(self, off):
        return self.inputs32(DIAG + off) & 0xFFFFFFFF


def wait_for(pred, timeout, poll=0.02):
    """peer.wait_for, polling Modbus every 20 ms by default."""
    return peer.wait_for(pred, timeout, poll)


def stop_and_exit_check(name, m, p):
    """Close the client and stop plcrt with SIGTERM: it must exit 0."""
    m.close()
    rc = p.stop()
    report(f"{name}: SIGTERM: exit 0", rc == 0, f"rc {rc}")


def finish(name, body):
    """Run body(); an exception in the test itself is a failure; no plcrt
    is left running; exit 1 if any check failed."""
    try:
        body()
    except Exception as e:  # noqa: BLE001
        report(f"{name}: run", False, repr(e))
    finally:
        Plcrt.kill_all()
    sys.exit(1 if failed else 0)


def start_example(name, plcrt, ini, work, view=None):
    """plcrt on the example's configuration, with a free port and a fresh
    retain file in work: (the Plcrt, its Modbus port). A view
    (tests/common/onecycle.py) adds the symbols it reads in one request."""
    os.makedirs(work, exist_ok=True)
    for f in os.listdir(work):
        if f.startswith(name):
            os.unlink(os.path.join(work, f))
    port = free_port()
    retain = os.path.join(work, name + ".retain")
    cfg = example_ini(ini, os.path.join(work, name + ".ini"), port, retain)
    if view is not None:
        view.add_to(cfg)
    return Plcrt(plcrt, cfg, work, name), port
