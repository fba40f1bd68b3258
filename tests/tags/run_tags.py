#!/usr/bin/env python3
"""The tag list (TAGS.csv, TAGS.json beside VARIABLES.csv) against a running
plcrt: every tag is polled over Modbus (pymodbus) at its table and address,
decoded by its type and word order, and must show the value the program
(tests/tags/tags.st) gives that variable; the list holds every variable a
client can reach and nothing else. Then plctrace get, watch and set by name.

    run_tags.py TREE WORKDIR          Prints PASS:/FAIL: lines."""
import csv
import json
import os
import struct
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from peer import Plcrt, Report, free_port, wait_for  # noqa: E402

tree, work = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
here = os.path.dirname(os.path.abspath(__file__))
report = Report("tags")
P = "CONFIG0.RES0.T."
# the values tags.st gives (inputs: 0 from the none backend)
want = {
    "B_OUT": True, "W_OUT": -1234, "U_OUT": 65000, "B_IN": False, "W_IN": 0, "M_W": 0xBEEF,
    "M_D": -123456789, "M_R": 2.5, "M_L": -1234567890123, "M_LR": -0.1, "ECHO": 5,
    "S_BOOL": True, "S_INT": -32000, "S_DINT": 2000000001, "S_REAL": -1250.0,
    "S_LREAL": 6.02214076e23, "S_UDINT": 4000000000, "S_SINT": -100, "SETME": 5,
}
# where they are served: (table, address, registers, access)
where = {
    "B_OUT": ("coil", 11, 1, "read-write"), "W_OUT": ("holding", 3, 1, "read-write"),
    "U_OUT": ("holding", 4, 1, "read-write"), "B_IN": ("discrete", 5, 1, "read"),
    "W_IN": ("input", 2, 1, "read"), "M_W": ("holding", 1031, 1, "read-write"),
    "M_D": ("holding", 2058, 2, "read-write"), "M_R": ("holding", 2060, 2, "read-write"),
    "M_L": ("holding", 4104, 4, "read-write"), "M_LR": ("holding", 4108, 4, "read-write"),
    "ECHO": ("holding", 2088, 2, "read-write"),
    "S_BOOL": ("coil", 9000, 1, "read"), "S_INT": ("holding", 9000, 1, "read"),
    "S_DINT": ("holding", 9001, 2, "read"), "S_REAL": ("holding", 9003, 2, "read"),
    "S_LREAL": ("holding", 9005, 4, "read"), "S_UDINT": ("input", 2000, 2, "read"),
    "S_SINT": ("input", 2002, 1, "read"), "SETME": ("holding", 9010, 2, "read-write"),
}
port = free_port()
proj = os.path.join(work, "tagproj")
os.makedirs(proj, exist_ok=True)
with open(os.path.join(here, "tags.st")) as f, open(os.path.join(proj, "tags.st"), "w") as g:
    g.write(f.read())
with open(os.path.join(proj, "plcrt.ini"), "w") as f:
    f.write("[io]\nbackend = none\n\n[debug]\nallow_force = yes\n\n[modbus]\nport = %d\n\n[modbus.symbols]\n" % port)
    f.write("".join("%s%s = %s %d%s\n" % (P, n, t, a, " rw" if acc == "read-write" else "")
                    for n, (t, a, _, acc) in where.items() if n.startswith("S") and n != "SETME"
                    or n == "SETME"))
env = {k: v for k, v in os.environ.items() if k not in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL")}
r = subprocess.run([os.path.join(tree, "plcrt-build"), "tagproj"], cwd=work, env=env, capture_output=True, text=True)
report("the project builds", r.returncode == 0, r.stdout + r.stderr)
gen = os.path.join(proj, "build", "gen")
tags = json.load(open(os.path.join(gen, "TAGS.json")))["tags"] if r.returncode == 0 else []
rows = list(csv.DictReader(open(os.path.join(gen, "TAGS.csv")))) if r.returncode == 0 else []
names = sorted(t["name"] for t in tags)
report("the tag list holds every Modbus-visible variable and no other (not %ID4)",
       names == sorted(P + n for n in want), "extra %s, missing %s" % (
           set(names) - {P + n for n in want}, {P + n for n in want} - set(names)))
report("TAGS.csv says the same as TAGS.json",
       [(x["name"], x["table"], int(x["address"]), int(x["registers"]), x["type"], x["word_order"] or None, x["access"])
        for x in rows] == [(t["name"], t["table"], t["address"], t["registers"], t["type"], t["word_order"], t["access"])
                           for t in tags], "")
bad = [(t["name"], t["table"], t["address"], t["registers"], t["access"]) for t in tags
       if (t["table"], t["address"], t["registers"], t["access"]) != where.get(t["name"][len(P):])]
report("each tag's table, address, registers and access as docs/modbus.md maps them", not bad, str(bad))

FMT = {"BOOL": "?", "SINT": "b", "INT": "h", "UINT": "H", "WORD": "H", "DINT": "i", "UDINT": "I",
       "LINT": "q", "REAL": "f", "LREAL": "d"}


def decode(t, regs):
    """Registers -> value, by the tag's type and word order alone."""
    if t["word_order"] == "low byte":     # an 8-bit type: its byte, the high byte 0
        assert regs[0] < 256, regs
        return struct.unpack(">" + FMT[t["type"]], bytes([regs[0]]))[0]
    if t["registers"] == 1:
        v = regs[0]
        if t["type"] in ("INT", "SINT"):
            return v - 65536 if v & 0x8000 else v
        return bool(v) if t["type"] == "BOOL" else v
    assert t["word_order"] == "high word first"
    return struct.unpack(">" + FMT[t["type"]], b"".join(struct.pack(">H", w) for w in regs))[0]


def poll(c, t):
    fn = {"coil": c.read_coils, "discrete": c.read_discrete_inputs, "input": c.read_input_registers,
          "holding": c.read_holding_registers}[t["table"]]
    rr = fn(t["address"], t["registers"], slave=1)
    if rr.isError():
        return "exception %s" % getattr(rr, "exception_code", rr)
    return bool(rr.bits[0]) if t["table"] in ("coil", "discrete") else decode(t, rr.registers)


def same(a, b, typ):
    return abs(a - b) <= 1e-6 * abs(b) if typ == "REAL" else a == b


if tags:
    from pymodbus.client import ModbusTcpClient
    plc = Plcrt(os.path.join(proj, "build", "plcrt"), os.path.join(proj, "plcrt.ini"), work, "tags")
    c = ModbusTcpClient("127.0.0.1", port=port)
    c.connect()
    try:
        # the program has run (it writes m_d every cycle)
        wait_for(lambda: poll(c, next(t for t in tags if t["name"] == P + "M_D")) == want["M_D"], 20, 0.05)
        # one request per tag: fair here, each tag is compared with its own
        # expected value, and the program writes the same constants every cycle
        got = {t["name"][len(P):]: poll(c, t) for t in tags}
        wrong = {n: (got[n], want[n]) for n in got
                 if isinstance(got[n], str) or not same(got[n], want[n], next(t["type"] for t in tags
                                                                                 if t["name"] == P + n))}
        report("every tag polled over Modbus shows the variable's value (%d tags)" % len(tags), not wrong, str(wrong))

        def pt(*args):
            return subprocess.run([sys.executable, os.path.join(tree, "plc_runtime", "plctrace"), "--port", str(port)]
                                  + list(args), cwd=proj, capture_output=True, text=True)
        r = pt("get", "t.m_d", "t.s_real", "t.b_out")
        report("plctrace get NAME...: the values of one cycle",
               r.returncode == 0 and r.stdout.split("\n")[:3] == [P + "M_D = -123456789", P + "S_REAL = -1250",
                                                                  P + "B_OUT = 1"], r.stdout + r.stderr)
        r = pt("set", "t.setme", "777")
        ok = r.returncode == 0 and wait_for(lambda: poll(c, next(t for t in tags if t["name"] == P + "ECHO")) == 777,
                                            10, 0.05)
        report("plctrace set NAME VALUE: written through its tag, the program sees it", ok, r.stdout + r.stderr)
        r = pt("watch", "t.echo", "t.m_l", "--count", "3", "--interval", "0.1")
        lines = [x for x in r.stdout.splitlines() if x.startswith("cycle ")]
        cycles = [int(x.split()[1]) for x in lines]
        report("plctrace watch NAME...: a line per sample, the cycle moving",
               r.returncode == 0 and len(lines) == 3 and all("T.ECHO = 777" in x and "T.M_L = -1234567890123" in x
                                                             for x in lines) and cycles == sorted(set(cycles)),
               r.stdout + r.stderr)
        r = pt("set", "t.s_dint", "5")
        report("plctrace set on a read-only tag: refused, saying how to make it writable",
               r.returncode == 1 and "read-only over Modbus" in r.stderr and "[modbus.symbols]" in r.stderr, r.stderr)
        r = pt("set", "t.setme", "1e3")
        report("plctrace set with a value its type cannot hold: refused",
               r.returncode != 0 and "not an integer" in r.stderr, r.stderr)
    finally:
        c.close()
        report("plcrt stops with status 0", plc.stop() == 0, plc.output()[-300:])
Plcrt.kill_all()
sys.exit(0 if report.all_passed() else 1)
