#!/usr/bin/env python3
"""Remote I/O (the modbus_io backend, docs/remote-io.md) against real
peers: pymodbus servers over TCP and over RTU on socat's pseudo-terminals,
libmodbus's own unit-test server; faults put between them by proxies.

The program (st/copy.st) copies every input to the output of the same
number; a value a peer serves comes back to it as a write. Delays are
counted in the device's own requests (how many reads the peer served
between the change and the write), not in seconds: docs/remote-io.md
bounds them in poll rounds.

usage: test_remoteio.py PLCRT UNIT_TEST_SERVER WORKDIR"""
import os
import signal
import struct
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "common"))
sys.path.insert(0, HERE)
from peer import Plcrt, Report, free_port, wait_for  # noqa: E402
from iopeer import FaultProxy, Peers, PtyPair, SerialProxy  # noqa: E402
from pymodbus.client import ModbusTcpClient  # noqa: E402

PLCRT, UTSERVER, WORK = sys.argv[1], sys.argv[2], sys.argv[3]
os.makedirs(WORK, exist_ok=True)
report = Report("remoteio")
IODIAG = 20000          # the first backend's diagnostics (docs/modbus.md)
ROUND_BOUND = 3         # rounds of a device between an input's change and the write it causes


def ini(name, text):
    path = os.path.join(WORK, name + ".ini")
    with open(path, "w") as f:
        f.write(text)
    return path


class Plc:
    """plcrt on a configuration, with a Modbus client to its own map."""

    def __init__(self, name, body, backend="modbus_io"):
        self.port = free_port()
        self.p = Plcrt(PLCRT, ini(name, f"[io]\nbackend = {backend}\n[modbus]\nport = {self.port}\n"
                                  f"[retain]\nfile =\n{body}"), WORK, name)
        self.c = ModbusTcpClient("127.0.0.1", port=self.port, timeout=3)
        self.c.connect()

    def regs(self, addr, n):
        r = self.c.read_input_registers(addr, n)
        return None if r.isError() else r.registers

    def bits(self, addr, n):
        r = self.c.read_discrete_inputs(addr, n)
        return None if r.isError() else r.bits[:n]

    def u32(self, addr):
        r = self.regs(addr, 2)
        return None if r is None else r[0] << 16 | r[1]

    def dev(self, k, what):
        """device k's diagnostic register (docs/remote-io.md)."""
        off = {"rounds": 0, "timeouts": 2, "exceptions": 4, "bad_frames": 6, "losses": 8, "round_us": 12,
               "age_us": 14}
        if what in ("ok", "last_exc"):
            r = self.regs(IODIAG + 16 + 16 * k + (10 if what == "ok" else 11), 1)
            return None if r is None else r[0]
        return self.u32(IODIAG + 16 + 16 * k + off[what])

    def own_overruns(self):
        return self.u32(1024 + 40)

    def stop(self):
        self.c.close()
        return self.p.stop()


def rounds_between(dev, since_reads, addr, want):
    """The reads dev served from since_reads until the write of want at addr
    arrived, or None if it has not arrived."""
    for reads, a, vals in dev.writes:
        if reads >= since_reads and a <= addr and vals[addr - a:addr - a + len(want)] == want:
            return reads - since_reads
    return None


def words(v, low_first):
    hi, lo = struct.unpack(">HH", struct.pack(">i", v))
    return [lo, hi] if low_first else [hi, lo]


peers = Peers()
try:
    # ---- TCP: ten devices polled every 10 ms ----------------------------
    ports = [free_port() for _ in range(10)]
    devs = [peers.tcp(p) for p in ports]
    proxy_port = free_port()
    proxy = FaultProxy(proxy_port, ports[9])
    body = ""
    for k in range(10):
        port = proxy_port if k == 9 else ports[k]
        body += (f"[modbus_io.dev{k}]\nhost = 127.0.0.1\nport = {port}\nperiod_ms = 10\ntimeout_ms = 1000\n"
                 f"ok = %IX100.{k}\n" if k < 8 else
                 f"[modbus_io.dev{k}]\nhost = 127.0.0.1\nport = {port}\nperiod_ms = 10\ntimeout_ms = 1000\n"
                 f"ok = %IX101.{k - 8}\n")
        body += f"read = input 0 4 %IW{4 * k}{' safe=-1' if k == 9 else ''}\nwrite = holding 0 4 %QW{4 * k}\n"
        if k == 9:
            body += "safe_after_ms = 300\nreconnect_max_ms = 400\n"
        if k == 8:
            body += "reconnect_max_ms = 800\n"
    # 32-bit: dev0 high word first, dev1 low word first, each writing the other's value
    body += ("[modbus_io.dev0]\nword_order = high_first\nread = holding 100 2 %ID0\nwrite = holding 200 2 %QD2\n"
             "[modbus_io.dev1]\nword_order = low_first\nread = holding 100 2 %ID2\nwrite = holding 200 2 %QD0\n"
             "[modbus_io.dev2]\nread = discrete 0 8 %IX0.0\nwrite = coil 0 8 %QX0.0\n")
    plc = Plc("tcp10", body)
    ok_all = wait_for(lambda: plc.bits(800, 10) == [True] * 10, 15)
    report("10 TCP devices at 10 ms: every ok input on", ok_all, f"ok bits {plc.bits(800, 10)}")

    # every device's four inputs come back as its writes within ROUND_BOUND reads
    marks = [d.reads for d in devs]
    for k, d in enumerate(devs):
        d.set(4, 0, [1000 * k + i + 1 for i in range(4)])
    wait_for(lambda: all(rounds_between(d, marks[k], 0, [1000 * k + i + 1 for i in range(4)]) is not None
                         for k, d in enumerate(devs)), 15)
    # a round of dev0..dev2 serves two read blocks (the 32-bit and bit blocks
    # below), the others' one: the peer counts reads, the bound is in rounds
    per_round = [2, 2, 2] + [1] * 7
    reads = [rounds_between(d, marks[k], 0, [1000 * k + i + 1 for i in range(4)]) for k, d in enumerate(devs)]
    delays = [None if r is None else -(-r // per_round[k]) for k, r in enumerate(reads)]
    report(f"inputs copied to outputs, seen by each peer within {ROUND_BOUND} of its polls",
           all(x is not None and x <= ROUND_BOUND for x in delays), f"polls per device: {delays}")
    report("the inputs are in plcrt's image (input registers 0-39 of its own map)",
           plc.regs(0, 40) == [(1000 * k + i + 1) & 0xFFFF for k in range(10) for i in range(4)], f"{plc.regs(0, 40)}")

    # 32-bit values in both word orders
    ok32 = True
    for v in (0x12345678, -2, 0x7FFF0001):
        m0, m1 = devs[0].reads, devs[1].reads
        devs[0].set(3, 100, words(v, False))     # high first at dev0 -> %ID0 -> %QD0 -> dev1, low first
        devs[1].set(3, 100, words(v ^ 0x00FF00FF, True))
        wait_for(lambda: rounds_between(devs[1], m1, 200, words(v, True)) is not None
                 and rounds_between(devs[0], m0, 200, words(v ^ 0x00FF00FF, False)) is not None, 10)
        got1, got0 = devs[1].get(3, 200, 2), devs[0].get(3, 200, 2)
        if got1 != words(v, True) or got0 != words(v ^ 0x00FF00FF, False):
            ok32 = False
            print(f"   32-bit {v:#x}: dev1 got {got1}, dev0 got {got0}")
    report("32-bit values: high word first in, low word first out and the reverse", ok32)

    # bits: discrete inputs in, coils out
    pattern = [1, 0, 1, 1, 0, 0, 1, 0]
    devs[2].set(2, 0, pattern)
    report("discrete inputs copied to coils", wait_for(lambda: devs[2].get(1, 0, 8) == pattern, 10),
           f"coils {devs[2].get(1, 0, 8)}")

    # ---- faults on dev9 (through the proxy) ------------------------------
    def ok9():
        return plc.bits(809, 1) == [True]
    before = {w: plc.dev(9, w) for w in ("exceptions", "timeouts", "bad_frames", "losses")}
    last9 = [9001, 9002, 9003, 9004]
    others0 = [plc.dev(k, "rounds") for k in range(9)]
    proxy.mode = "exception"
    report("exception: ok drops", wait_for(lambda: plc.bits(809, 1) == [False], 10))
    report("exception: counted, code 04 kept", wait_for(lambda: plc.dev(9, "exceptions") > before["exceptions"]
                                                       and plc.dev(9, "last_exc") == 4, 5),
           f"exceptions {plc.dev(9, 'exceptions')}, last {plc.dev(9, 'last_exc')}")
    report("exception: inputs take their safe value after safe_after_ms",
           wait_for(lambda: plc.regs(36, 4) == [0xFFFF] * 4, 10), f"{plc.regs(36, 4)}")
    others1 = [plc.dev(k, "rounds") for k in range(9)]
    report("meanwhile the other devices were polled on", all(b > a for a, b in zip(others0, others1)),
           f"rounds {others0} -> {others1}")
    devs[9].set(3, 0, [0, 0, 0, 0])          # the module lost its outputs meanwhile
    m9 = devs[9].reads
    proxy.mode = "pass"
    report("back: ok on again", wait_for(ok9, 10))
    report("back: inputs from the device again", wait_for(lambda: plc.regs(36, 4) == last9, 5), f"{plc.regs(36, 4)}")
    report("back: outputs written anew though the program's did not change",
           wait_for(lambda: devs[9].get(3, 0, 4) == last9, 5), f"{devs[9].get(3, 0, 4)} writes {devs[9].writes[-2:]}")

    for mode, what in (("stall", "timeouts"), ("garbage", "bad_frames"), ("silent", "timeouts")):
        n0, c0 = plc.dev(9, what), proxy.conns
        proxy.mode = mode
        dropped = wait_for(lambda: plc.bits(809, 1) == [False], 10)
        counted = wait_for(lambda: plc.dev(9, what) > n0, 5)
        report(f"{mode}: ok drops, counted as {what}", dropped and counted, f"{what} {n0} -> {plc.dev(9, what)}")
        proxy.mode = "pass"
        back = wait_for(ok9, 10)
        report(f"{mode}: reconnected (a new connection), ok on again", back and proxy.conns > c0,
               f"connections {c0} -> {proxy.conns}")

    # a peer killed: dev8's server closed; back-off between reconnections
    # the window the tries are counted in is inside the one timed here (t0
    # before the first count, elapsed after the last), so the upper bound
    # holds however late this script runs; it lasts 2 s at least and until
    # one try is counted (a deadline, not a wait for luck)
    t0 = time.monotonic()
    l0 = plc.dev(8, "losses")
    peers.stop(devs[8])
    report("peer killed: ok drops", wait_for(lambda: plc.bits(808, 1) == [False], 10))
    wait_for(lambda: time.monotonic() - t0 >= 2.0 and plc.dev(8, "losses") - l0 >= 1, 30, 0.05)
    tried = plc.dev(8, "losses") - l0
    elapsed = time.monotonic() - t0
    # back-off 100, 200, 400, 800, 800 ms...: at most elapsed/0.1 + 1 tries even if no time passed in between
    report("peer killed: reconnections back off (not one per 10 ms poll)", 1 <= tried <= elapsed / 0.1 + 2,
           f"{tried} failed connections in {elapsed:.1f} s")
    held = plc.regs(32, 4)
    report("peer killed: inputs hold their last value (no safe_after_ms)", held == [8001, 8002, 8003, 8004], f"{held}")
    log = plc.p.output()
    report("peer killed: logged once", log.count("modbus_io dev8: connection lost") == 1,
           "\n".join(x for x in log.splitlines() if "dev8" in x)[-600:])
    peers.tcp(ports[8], devs[8])
    report("peer restarted: ok on again", wait_for(lambda: plc.bits(808, 1) == [True], 10))
    report("peer restarted: 'answering again' logged",
           wait_for(lambda: "modbus_io dev8: answering again" in plc.p.output(), 5))

    ov = plc.own_overruns()
    report("the scan's own overruns: 0 (1064 of plcrt's diagnostics)", ov == 0, f"{ov}")
    rc = plc.stop()
    report("SIGTERM: exit status 0", rc == 0, f"{rc}")
    # the peers take plcrt's last writes in their own threads: polled for
    report("SIGTERM: the devices' outputs to 0", wait_for(lambda: all(d.get(3, 0, 4) == [0, 0, 0, 0] for d in devs), 10),
           f"{[d.get(3, 0, 4) for d in devs]}")

    # ---- two backends, one input -----------------------------------------
    port = free_port()
    cfg = ini("clash", f"[io]\nbackend = sim, modbus_io\n[modbus]\nport = {port}\n[retain]\nfile =\n"
                       f"[modbus_io.rack]\nhost = 127.0.0.1\nport = {ports[0]}\nread = input 0 2 %ID0\n")
    r = subprocess.run([PLCRT, "-c", cfg], capture_output=True, text=True, timeout=20)
    report("sim and modbus_io writing %ID0: refused at the start, naming both", r.returncode == 2
           and "[sim.axis0] counter" in r.stderr and "[modbus_io.rack] read input 0 2 %ID0" in r.stderr,
           f"{r.returncode}: {r.stderr.strip()}")
    plc = Plc("both", f"[modbus_io.rack]\nhost = 127.0.0.1\nport = {ports[0]}\nread = input 0 4 %IW0\n"
                      "ok = %IX100.0\n", backend="sim, modbus_io")
    devs[0].set(4, 0, [11, 22, 33, 44])
    got = wait_for(lambda: plc.regs(0, 4) == [11, 22, 33, 44], 10)
    moving = plc.u32(IODIAG) is not None and plc.regs(21000, 1) == [1]
    report("sim and modbus_io side by side: remote inputs in, each backend's diagnostics in its block",
           got and moving, f"regs {plc.regs(0, 4)}, modbus_io devices {plc.regs(21000, 1)}")
    plc.stop()

    # ---- libmodbus's unit-test server as the device ----------------------
    port = free_port()
    ut = subprocess.Popen([UTSERVER, "tcp"], env=dict(os.environ, MODBUS_PORT=str(port)),
                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    # no probe of its port: the unit-test server serves one connection only;
    # plcrt retries until it listens, and the first check waits 30 s for it
    # unit-test.h: input register 0x108 = 0x000A, input bits 0x1C4 = 0xAC
    # (LSB first); its holding registers from 0x160 are ours to write
    plc = Plc("libmodbus", f"[modbus_io.ut]\nhost = 127.0.0.1\nport = {port}\nunit = 17\nperiod_ms = 20\n"
                           "ok = %IX100.0\nread = input 264 1 %IW0\nwrite = holding 352 1 %QW0\n"
                           "read = holding 352 1 %IW1\nread = discrete 452 8 %IX0.0\n")
    want = [0x000A, 0x000A]
    report("libmodbus unit-test server: its input register read, written back to it and read again",
           wait_for(lambda: plc.regs(0, 2) == want, 30), f"{plc.regs(0, 2)}")
    report("libmodbus unit-test server: its input bits read",
           wait_for(lambda: plc.bits(0, 8) == [bool(0xAC >> i & 1) for i in range(8)], 5), f"{plc.bits(0, 8)}")
    ut.send_signal(signal.SIGKILL)
    ut.wait()
    report("libmodbus server killed (-9): ok drops, counted as a lost connection",
           wait_for(lambda: plc.bits(800, 1) == [False] and plc.dev(0, "losses") >= 1, 10),
           f"losses {plc.dev(0, 'losses')}")
    report("libmodbus server killed: inputs held", plc.regs(0, 2) == want, f"{plc.regs(0, 2)}")
    plc.stop()

    # ---- RTU: two slaves on one line, over socat pseudo-terminals ---------
    line = PtyPair(WORK, "line")
    peer_line = PtyPair(WORK, "peer")
    sp = SerialProxy(line.b, peer_line.a)
    rdevs = peers.rtu(peer_line.b, [1, 2])
    body = ""
    for k, sid in enumerate((1, 2, 3)):
        body += (f"[modbus_io.s{sid}]\ndevice = {line.a}\nbaud = 115200\nparity = none\nslave = {sid}\n"
                 f"period_ms = 20\ntimeout_ms = 100\nreconnect_max_ms = 400\nok = %IX100.{k}\n"
                 f"read = input 0 4 %IW{4 * k}\nwrite = holding 0 4 %QW{4 * k}\n")
    plc = Plc("rtu", body)
    report("RTU: slaves 1 and 2 answer, ok on; slave 3 (absent) off",
           wait_for(lambda: plc.bits(800, 3) == [True, True, False], 15), f"{plc.bits(800, 3)}")
    marks = {k: rdevs[k].reads for k in (1, 2)}
    for k in (1, 2):
        rdevs[k].set(4, 0, [100 * k + i for i in range(4)])
    wait_for(lambda: all(rounds_between(rdevs[k], marks[k], 0, [100 * k + i for i in range(4)]) is not None
                         for k in (1, 2)), 15)
    delays = [rounds_between(rdevs[k], marks[k], 0, [100 * k + i for i in range(4)]) for k in (1, 2)]
    report(f"RTU: inputs copied to outputs within {ROUND_BOUND} polls of each slave",
           all(x is not None and x <= ROUND_BOUND for x in delays), f"{delays}")
    report("RTU: the absent slave counted as timeouts", (plc.dev(2, "timeouts") or 0) >= 1,
           f"{plc.dev(2, 'timeouts')}")
    b0 = plc.dev(0, "bad_frames")
    sp.corrupt = True
    report("RTU: CRC errors on the line: ok drops, counted as bad frames",
           wait_for(lambda: plc.bits(800, 2) == [False, False] and plc.dev(0, "bad_frames") > b0, 10),
           f"ok {plc.bits(800, 2)}, bad frames {plc.dev(0, 'bad_frames')}")
    sp.corrupt = False
    report("RTU: the line clean again: both slaves back", wait_for(lambda: plc.bits(800, 2) == [True, True], 10),
           f"{plc.bits(800, 2)}")
    ov = plc.own_overruns()
    report("RTU: the scan's own overruns 0", ov == 0, f"{ov}")
    plc.stop()
    line.close()
    peer_line.close()
finally:
    Plcrt.kill_all()
    peers.close()

sys.exit(0 if report.all_passed() else 1)
