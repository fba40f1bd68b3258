#!/usr/bin/env python3
"""plcrt's Modbus server against clients that misbehave, and the scan under
a flood: raw sockets (to send what no library sends), pymodbus beside them.

Each case is a defect a user met (docs/modbus.md, "Rules"):
- a client sending one byte every 0.2 s is cut 0.5 s after its first byte,
  while another client is served;
- a client silent for idle_timeout is closed;
- at max_clients a new client is admitted and the longest idle gives way;
- FC 43/14 and FC 8 carrying data get exception 01 and the next request on
  the same connection is answered in step; the MBAP length says where a
  request ends; a protocol id other than 0 closes the connection;
- a reader never sees half of a %MD value another client rewrites;
- 16 clients flooding FC 3 of 125 registers never make the 1 ms scan wait:
  no overrun of its own, its Modbus exchange well under a period.

usage: test_mbserver.py PLCRT_IOTEST PLCRT_1MS WORKDIR"""
import os
import select
import socket
import struct
import sys
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from peer import Plcrt, Report, free_port, wait_for  # noqa: E402
from pymodbus.client import ModbusTcpClient  # noqa: E402

PLCRT, PLCRT_1MS, WORK = sys.argv[1], sys.argv[2], sys.argv[3]
report = Report("runtime-mbserver")
DIAG = 1024
IDLE = 1            # s, idle_timeout of the first plcrt
CAP = 4             # its max_clients


def ini(name, port, extra):
    path = os.path.join(WORK, name + ".ini")
    with open(path, "w") as f:
        f.write(f"[scan]\npriority = 80\n[io]\nbackend = none\n[modbus]\nport = {port}\n{extra}[retain]\nfile =\n")
    return path


def frame(tid, pdu, proto=0, length=None, unit=1):
    """An MBAP header (length = unit + PDU unless given) and the PDU."""
    return struct.pack(">HHHB", tid, proto, len(pdu) + 1 if length is None else length, unit) + bytes(pdu)


def fc3(addr, n):
    return [3, addr >> 8, addr & 255, n >> 8, n & 255]


def recv_exact(s, n):
    b = b""
    while len(b) < n:
        got = s.recv(n - len(b))
        if not got:
            return None
        b += got
    return b


def reply(s):
    """(transaction id, PDU) of the next reply, or None if the server closed."""
    h = recv_exact(s, 7)
    if h is None:
        return None
    tid, _, length, _ = struct.unpack(">HHHB", h)
    pdu = recv_exact(s, length - 1)
    return None if pdu is None else (tid, pdu)


def closed_within(s, seconds):
    """Time until the server closes s (no reply in between), or None."""
    t0 = time.monotonic()
    s.settimeout(seconds)
    try:
        got = s.recv(100)
    except socket.timeout:
        return None
    except OSError:
        got = b""
    return time.monotonic() - t0 if got == b"" else None


def connect(port):
    s = socket.create_connection(("127.0.0.1", port))
    s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    s.settimeout(3)
    return s


def u32(regs, i=0):
    return regs[i] << 16 | regs[i + 1]


def test_slow_bytes(port):
    """One byte every 0.2 s: each gap is under 0.5 s, the frame is not."""
    other = ModbusTcpClient("127.0.0.1", port=port, timeout=3)
    other.connect()
    slow = connect(port)
    req = frame(1, fc3(0, 1))
    stop, served, worst = [False], [0], [0.0]

    def serve_other():
        while not stop[0]:
            t = time.monotonic()
            if not other.read_holding_registers(0, 1, slave=1).isError():
                served[0] += 1
                worst[0] = max(worst[0], time.monotonic() - t)
            time.sleep(0.02)

    th = threading.Thread(target=serve_other)
    th.start()
    t0, cut = time.monotonic(), None
    for b in req:
        try:
            slow.send(bytes([b]))
        except OSError:
            cut = time.monotonic() - t0
            break
        r, _, _ = select.select([slow], [], [], 0.2)
        if r:
            try:
                got = slow.recv(100)
            except OSError:
                got = b""
            cut = time.monotonic() - t0 if got == b"" else None
            break
    stop[0] = True
    th.join()
    # the server's rule is in wall-clock time, so is this check; the lower
    # bound is exact (t0 is taken before the first byte leaves), the upper
    # one holds what this script may be late in seeing the close on a loaded
    # host, and stays under the whole frame's 2.4 s (a rule per gap, or per
    # frame once whole, would never cut it)
    report("a frame sent one byte every 0.2 s is cut 0.5 s after its first byte",
           cut is not None and 0.45 <= cut <= 1.5, f"closed after {cut} s" if cut else "never closed, or answered")
    # a server that waited for the slow frame would hold the other client
    # up to the 0.5 s cut: the bound is under that, with room for this
    # script's own lateness under load
    report("meanwhile another client is served without delay", served[0] >= 3 and worst[0] < 0.45,
           f"{served[0]} replies, slowest {worst[0] * 1000:.0f} ms")
    slow.close()
    other.close()


def test_idle(port):
    # idle_timeout is wall-clock time: the lower bounds are exact (the
    # test's clock starts first), the upper ones leave this script 1 s to
    # see the close on a loaded host
    silent = connect(port)
    t = closed_within(silent, IDLE + 2)
    report(f"a silent client is closed after idle_timeout ({IDLE} s)",
           t is not None and IDLE - 0.1 <= t <= IDLE + 1.0, f"closed after {t} s")
    silent.close()
    once = connect(port)
    once.sendall(frame(7, fc3(0, 1)))
    r = reply(once)
    t = closed_within(once, IDLE + 2)
    report("a client silent after a request is closed idle_timeout after it",
           r is not None and r[0] == 7 and t is not None and IDLE - 0.1 <= t <= IDLE + 1.0, f"reply {r}, closed after {t} s")
    once.close()


def test_cap(port):
    # no connection of the tests before is left: the server itself closed
    # test_idle's (so it had run rounds past test_slow_bytes' close). The
    # order of idleness is that of the replies below (plcrt counts requests
    # in sequence, not in time), so no pause is needed between them.
    old = []
    for i in range(CAP):
        s = connect(port)
        s.sendall(frame(10 + i, fc3(0, 1)))
        old.append((s, reply(s)))
    ok_before = all(r is not None and r[0] == 10 + i for i, (_, r) in enumerate(old))
    new = connect(port)
    new.sendall(frame(20, fc3(0, 1)))
    r = reply(new)
    report(f"at max_clients ({CAP}) a new client is admitted and served", ok_before and r is not None and r[0] == 20,
           f"before {[x[1] for x in old]}, new {r}")
    t = closed_within(old[0][0], 0.3)     # at once: idle_timeout is 1 s
    report("the longest idle client gave way to it", t is not None, "" if t is not None else "still open")
    rest = []
    for i, (s, _) in enumerate(old[1:], 1):
        s.sendall(frame(30 + i, fc3(0, 1)))
        rest.append(reply(s))
    report("the other clients are still served", all(x is not None and x[0] == 30 + i for i, x in enumerate(rest, 1)),
           str(rest))
    for s, _ in old:
        s.close()
    new.close()


def test_unknown_functions(port):
    s = connect(port)
    s.sendall(frame(1, [16, 0, 50, 0, 2, 4, 0x11, 0x11, 0x22, 0x22]))        # %QW50..51
    w = reply(s)
    # FC 43/14 (read device identification) and FC 8/0 (diagnostics, echo)
    # with data, then a read, all in one segment: each answered in step
    s.sendall(frame(2, [0x2B, 0x0E, 0x01, 0x00]) + frame(3, [0x08, 0x00, 0x00, 0x12, 0x34])
              + frame(4, fc3(50, 2)))
    got = [reply(s) for _ in range(3)]
    report("FC 43/14 with data: exception 01", w is not None and got[0] == (2, bytes([0xAB, 0x01])), f"{w} {got[0]}")
    report("FC 8 with data: exception 01", got[1] == (3, bytes([0x88, 0x01])), str(got[1]))
    report("the next request on the same connection is answered correctly",
           got[2] == (4, bytes([3, 4, 0x11, 0x11, 0x22, 0x22])), str(got[2]))
    # FC 8 whose data reads like a request: still one request, by its length
    s.sendall(frame(5, [0x08, 0x00, 0x00] + list(frame(99, [6, 0, 50, 0, 9]))) + frame(6, fc3(50, 1)))
    got = [reply(s) for _ in range(2)]
    report("FC 8 carrying a whole frame as data: exception 01 and nothing written",
           got == [(5, bytes([0x88, 0x01])), (6, bytes([3, 2, 0x11, 0x11]))], str(got))
    s.close()


def test_mbap(port):
    s = connect(port)
    # FC 3 whose length field counts two bytes more than FC 3 has
    s.sendall(frame(1, fc3(50, 1) + [0xAA, 0xBB], length=8) + frame(2, fc3(50, 1)))
    got = [reply(s) for _ in range(2)]
    report("MBAP length honoured: a longer FC 3 is exception 03, the next request in step",
           got == [(1, bytes([0x83, 0x03])), (2, bytes([3, 2, 0x11, 0x11]))], str(got))
    s.close()
    s = connect(port)
    s.sendall(frame(1, fc3(50, 1), length=1))
    t = closed_within(s, 1)
    report("an MBAP length too short for a request closes the connection", t is not None, "" if t is not None else "not closed")
    s.close()
    s = connect(port)
    s.sendall(frame(1, fc3(50, 1), proto=1))
    t = closed_within(s, 1)
    report("protocol id 1: closed without a reply", t is not None, "" if t is not None else "answered or still open")
    s.close()


def test_atomic(port):
    A, B = 0x11112222, 0x33334444
    addr = 2048 + 2 * 100                 # %MD100, not used by the program
    stop, torn, seen, reads = [False], [], set(), [0]

    def reader():
        s = connect(port)
        tid = 0
        while not stop[0]:
            tid = (tid + 1) & 0xFFFF
            s.sendall(frame(tid, fc3(addr, 2)))
            r = reply(s)
            if r is None or r[1][0] != 3:
                torn.append(f"reply {r}")
                break
            v = int.from_bytes(r[1][2:6], "big")
            reads[0] += 1
            seen.add(v)
            if v not in (0, A, B):
                torn.append(hex(v))
        s.close()

    w = ModbusTcpClient("127.0.0.1", port=port, timeout=3)
    w.connect()
    rs = [threading.Thread(target=reader) for _ in range(2)]
    for t in rs:
        t.start()
    # counted, not timed: at least 200 writes and 200 reads beside them
    # (a deadline only for a server that stops answering)
    writes, t_end = 0, time.monotonic() + 60
    while time.monotonic() < t_end and not (writes >= 200 and reads[0] >= 200 and {A, B} <= seen):
        v = A if writes % 2 == 0 else B
        if w.write_registers(addr, [v >> 16, v & 0xFFFF], slave=1).isError():
            break
        writes += 1
    stop[0] = True
    for t in rs:
        t.join()
    w.close()
    report("a reader never sees half of a %MD value another client rewrites",
           not torn and writes >= 200 and reads[0] >= 200 and {A, B} <= seen,
           f"{writes} writes, {reads[0]} reads, torn: {torn[:5]}, seen {[hex(x) for x in seen]}")


def test_flood():
    port = free_port()
    plc = Plcrt(PLCRT_1MS, ini("flood", port, "max_clients = 16\n"), WORK, "flood")
    try:
        c = ModbusTcpClient("127.0.0.1", port=port, timeout=3)
        c.connect()

        def d(off):
            return u32(c.read_input_registers(DIAG + off, 2, slave=1).registers)
        own0, req0 = d(40), d(28)
        stop, counts, total = [False], [], [0]

        def flood():
            s = connect(port)
            n, tid = 0, 0
            while not stop[0]:
                tid = (tid + 1) & 0xFFFF
                s.sendall(frame(tid, fc3(0, 125)))
                if reply(s) is None:
                    break
                n += 1
                total[0] += 1
            counts.append(n)
            s.close()
        ts = [threading.Thread(target=flood) for _ in range(15)]
        for t in ts:
            t.start()
        # 6000 requests (3 s of them on an idle 2-core machine), counted,
        # not timed; the deadline is for a server that stops answering
        wait_for(lambda: total[0] >= 6000 or not any(t.is_alive() for t in ts), 120, 0.05)
        stop[0] = True
        for t in ts:
            t.join()
        # the diagnostics are published at a cycle's end: two cycles after
        # the last reply they count every request
        n = d(0)
        wait_for(lambda: d(0) >= n + 2, 20)
        own, served, xmax, emax = d(40) - own0, d(28) - req0, d(46), d(10)
        c.close()
        report("16 clients flooding FC 3 of 125 registers: no overrun of the scan's own",
               own == 0 and served >= 6000, f"{own} overruns, {served} requests, worst execution {emax} us")
        # measured on the scan's path around mb_apply and mb_publish: a copy
        # takes microseconds to tens of them (the cache lines come from the
        # server's core); waiting for client threads took 10-17 ms
        report("the scan's Modbus exchange is measured and stays under the 1 ms period (register 1070)",
               0 < xmax < 1000, f"longest exchange {xmax} us")
    finally:
        rc = plc.stop()
    report("SIGTERM after the flood: exit status 0", rc == 0, "" if rc == 0 else f"rc {rc}")


def main():
    os.makedirs(WORK, exist_ok=True)
    port = free_port()
    plc = Plcrt(PLCRT, ini("mbserver", port, f"max_clients = {CAP}\nidle_timeout = {IDLE}\n"), WORK, "mbserver")
    try:
        for t in (test_slow_bytes, test_idle, test_cap, test_unknown_functions, test_mbap, test_atomic):
            try:
                t(port)
            except Exception as e:  # noqa: BLE001
                report(t.__name__, False, repr(e))
    finally:
        rc = plc.stop()
    report("SIGTERM after the tests: exit status 0", rc == 0, "" if rc == 0 else f"rc {rc}")
    try:
        test_flood()
    except Exception as e:  # noqa: BLE001
        report("test_flood", False, repr(e))
    Plcrt.kill_all()
    sys.exit(0 if report.all_passed() else 1)


main()
