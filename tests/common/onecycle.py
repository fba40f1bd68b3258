"""Values of a running plcrt taken from one cycle.

plcrt answers each Modbus request from one cycle's snapshot: the image, the
diagnostics, the backend's registers and the symbol map were all published
together at the end of one cycle (docs/modbus.md, plc_runtime/mbmap.h).
Two requests may straddle a cycle, so values a check compares with each
other must come from one request. Two ways to get that here:

- View: the variables a check compares are put in the configuration's
  symbol map at consecutive input registers from 1152, right after the
  backend's registers (1088-1151: the sim plant's position and speed of
  each axis), and read back with one FC 4 request. Add the view's lines to
  the test's copy of the configuration (View.add_to), then View.read.
- same_cycle: where the values cannot sit in one request (coils and
  registers of a program whose addresses are its own), plcrt's cycle
  counter is read before and after the reads and the reads are repeated
  until it did not move. Suits programs whose period is long against a
  request's round trip (10 ms and more); at 1 ms use a View.
- Recording: how long something lasts, or what happened in which cycle,
  comes from plctrace's cycle-exact trace, never from the test's clock:
  the recording is armed, and confirmed armed, before the stimulus.
"""
import csv
import os
import re
import struct
import subprocess
import sys

from peer import default_signals

PLCTRACE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "plc_runtime", "plctrace")

SYMBOLS = 1152        # first input register free for the symbol map
BACKEND = 1088        # the backend's registers (sim: 4 per axis)
CYCLES = 1024         # input registers 1024-1025: cycles run
MAX_READ = 125        # registers in one FC 4 request

# elementary type -> (registers, struct format of the big-endian bytes)
TYPES = {
    "BOOL": (1, ">H"), "SINT": (1, ">h"), "INT": (1, ">h"), "USINT": (1, ">H"),
    "BYTE": (1, ">H"), "UINT": (1, ">H"), "WORD": (1, ">H"),
    "DINT": (2, ">i"), "UDINT": (2, ">I"), "DWORD": (2, ">I"), "REAL": (2, ">f"),
    "LINT": (4, ">q"), "ULINT": (4, ">Q"), "LWORD": (4, ">Q"), "LREAL": (4, ">d"),
}


class View:
    """Named program variables (and the sim plant's axes) read in one
    request. items: (name, IEC path as in VARIABLES.csv, elementary type)."""

    def __init__(self, items, sim_axes=0):
        self.items, addr = [], SYMBOLS
        for name, path, typ in items:
            n, fmt = TYPES[typ.upper()]
            self.items.append((name, path, addr, n, fmt))
            addr += n
        self.sim_axes = sim_axes
        self.first = BACKEND if sim_axes else SYMBOLS
        self.count = addr - self.first
        if self.count > MAX_READ:
            raise ValueError(f"a view of {self.count} registers does not fit one request ({MAX_READ})")

    def lines(self):
        return [f"{path} = input {addr}" for _, path, addr, _, _ in self.items]

    def add_to(self, ini_path):
        """Put the view's symbols into the configuration file: into its
        [modbus.symbols] section if it has one (a second one is refused),
        else in a new one at the end."""
        text = open(ini_path).read().splitlines()
        at = next((i + 1 for i, line in enumerate(text)
                   if re.match(r"\s*\[\s*modbus\.symbols\s*\]", line)), None)
        if at is None:
            text += ["", "[modbus.symbols]"]
            at = len(text)
        text[at:at] = self.lines()
        with open(ini_path, "w") as f:
            f.write("\n".join(text) + "\n")
        return ini_path

    def read(self, client, unit=1):
        """One FC 4 request: {name: value}, and 'sim' = [(position, speed)
        per axis] when the view has sim axes. Raises on a Modbus error."""
        r = client.read_input_registers(self.first, self.count, slave=unit)
        if r.isError():
            raise RuntimeError(f"FC4 {self.first}+{self.count}: {r}")
        regs = r.registers
        out = {}
        for name, _, addr, n, fmt in self.items:
            raw = struct.pack(f">{n}H", *regs[addr - self.first:addr - self.first + n])
            out[name] = struct.unpack(fmt, raw)[0]
        if self.sim_axes:
            out["sim"] = [struct.unpack(">ii", struct.pack(">4H", *regs[4 * a:4 * a + 4]))
                          for a in range(self.sim_axes)]
        return out


def cycles(client, unit=1):
    """plcrt's cycle counter (input registers 1024-1025)."""
    r = client.read_input_registers(CYCLES, 2, slave=unit)
    if r.isError():
        raise RuntimeError(f"FC4 {CYCLES}+2: {r}")
    return (r.registers[0] << 16) | r.registers[1]


def same_cycle(client, reads, tries=200, unit=1):
    """reads() repeated until plcrt's cycle counter read before and after it
    is the same: its values then come from one cycle. Raises after tries."""
    for _ in range(tries):
        c0 = cycles(client, unit)
        v = reads()
        if cycles(client, unit) == c0:
            return v
    raise RuntimeError(f"no {tries} reads fitted in one cycle: the period is too short "
                       "for this check (put the values in one request: onecycle.View)")


class Recording:
    """plctrace record in the background, on plcrt's Modbus port: the
    constructor returns once plctrace says it is armed (plcrt looks for the
    trigger from then on), so the stimulus may follow at once. rows() waits
    for the capture: [(cycle, PLC time in ms, [value per channel])], one
    row per sample."""

    def __init__(self, port, chans, trigger, samples, path, pre=0, every=1, timeout=60):
        # under this interpreter: it has plctrace's pymodbus (a bus test's
        # guest has another python3 first on its PATH)
        argv = [sys.executable, PLCTRACE, "--port", str(port), "record", "--trigger", trigger, "--pre", str(pre),
                "--samples", str(samples), "--every", str(every), "--timeout", str(timeout),
                "--no-plot", "-o", path]
        for c in chans:
            argv += ["--chan", c]
        self.path, self.err = path, []
        self.p = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                  preexec_fn=default_signals)
        for line in self.p.stderr:
            self.err.append(line)
            if line.startswith("armed"):
                return
        self.p.wait()
        raise RuntimeError("plctrace did not arm: " + "".join(self.err)[-500:])

    def rows(self, timeout=120):
        out, err = self.p.communicate(timeout=timeout)
        if self.p.returncode != 0:
            raise RuntimeError(f"plctrace record: status {self.p.returncode}: " + ("".join(self.err) + err)[-500:])
        with open(self.path) as f:
            r = list(csv.reader(f))
        return [(int(row[1]), float(row[0]), [float(x) for x in row[2:]]) for row in r[1:]]
