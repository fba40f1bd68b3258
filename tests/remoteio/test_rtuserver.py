#!/usr/bin/env python3
"""plcrt's map on a serial line ([modbus_rtu], docs/modbus.md): mbpoll
(-m rtu) and pymodbus over a socat pseudo-terminal pair as the masters;
malformed frames on the line; a value written over RTU read over TCP
never half-written.

usage: test_rtuserver.py PLCRT WORKDIR"""
import os
import subprocess
import sys
import threading

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "common"))
sys.path.insert(0, HERE)
from peer import Plcrt, Report, free_port, wait_for  # noqa: E402
from iopeer import PtyPair  # noqa: E402
from pymodbus.client import ModbusSerialClient, ModbusTcpClient  # noqa: E402

PLCRT, WORK = sys.argv[1], sys.argv[2]
os.makedirs(WORK, exist_ok=True)
report = Report("rtuserver")
SLAVE = 5

line = PtyPair(WORK, "rtu")
port = free_port()
cfg = os.path.join(WORK, "rtu.ini")
with open(cfg, "w") as f:
    f.write(f"[io]\nbackend = none\n[modbus]\nport = {port}\n[retain]\nfile =\n"
            f"[modbus_rtu]\ndevice = {line.a}\nbaud = 115200\nparity = none\nslave = {SLAVE}\n")
plc = Plcrt(PLCRT, cfg, WORK, "rtu")
tcp = ModbusTcpClient("127.0.0.1", port=port, timeout=3)
tcp.connect()


def mbpoll(*args):
    r = subprocess.run(["mbpoll", "-m", "rtu", "-b", "115200", "-P", "none", "-a", str(SLAVE), "-0", "-1",
                        "-o", "1", *args], capture_output=True, text=True, timeout=30)
    return r.returncode, r.stdout + r.stderr


try:
    report("plcrt says it serves the line", wait_for(lambda: "modbus_rtu: serving on" in plc.output(), 20))
    rc, out = mbpoll("-t", "4", "-r", "1024", line.b, "111", "2222", "333")
    report("mbpoll -m rtu writes %MW0-%MW2 (holding 1024-1026)", rc == 0, out[-300:])
    # the write reaches the image at the next cycle, the TCP reads at that
    # cycle's end: polled for
    wait_for(lambda: (lambda x: not x.isError() and x.registers == [111, 2222, 333])(
        tcp.read_holding_registers(1024, 3)), 20)
    r = tcp.read_holding_registers(1024, 3)
    report("... and they are in the map plcrt serves over TCP", not r.isError() and r.registers == [111, 2222, 333],
           f"{r}")
    rc, out = mbpoll("-t", "4", "-r", "1024", "-c", "3", line.b)
    report("mbpoll -m rtu reads them back", rc == 0 and "[1024]: \t111" in out and "[1025]: \t2222" in out
           and "[1026]: \t333" in out, out[-300:])

    cl = ModbusSerialClient(port=line.b, baudrate=115200, parity="N", bytesize=8, stopbits=1, timeout=1)
    cl.connect()
    c0 = cl.read_input_registers(1024, 2, slave=SLAVE)
    c1 = wait_for(lambda: (lambda r: r if not r.isError() and r.registers != c0.registers else None)(
        cl.read_input_registers(1024, 2, slave=SLAVE)), 20)
    report("pymodbus reads the diagnostics over RTU: the cycle count advances", not c0.isError() and c1, f"{c0}")
    r = cl.read_holding_registers(60000, 4, slave=SLAVE)
    report("pymodbus: the trace block too (the same map)", not r.isError(), f"{r}")
    r = cl.read_holding_registers(9000, 1, slave=SLAVE)
    report("pymodbus: an address outside the map: exception 02", r.isError() and getattr(r, "exception_code", 0) == 2,
           f"{r}")
    r = cl.read_holding_registers(1024, 1, slave=SLAVE + 1)
    report("a frame for another slave: no answer", r.isError() and not hasattr(r, "exception_code"), f"{r}")

    # malformed frames: noise, a bad CRC, a frame cut short, an oversize one
    bad0 = tcp.read_input_registers(1024 + 52, 2).registers
    fd = os.open(line.b, os.O_RDWR | os.O_NOCTTY)
    good = bytes([SLAVE, 3, 0x04, 0x00, 0x00, 0x01])
    for junk in (b"\xff" * 40, good + b"\x00\x00", good[:3], bytes(range(256)), good + b"\x12"):
        os.write(fd, junk)
        wait_for(lambda: False, 0.3)       # silence between them (a frame's end); longer when late is fine
    os.close(fd)
    cl.close()
    cl.connect()
    r = wait_for(lambda: (lambda x: x if not x.isError() else None)(cl.read_holding_registers(1024, 3, slave=SLAVE)), 20)
    report("after noise, a bad CRC, cut and oversize frames: the next request answered",
           r and r.registers == [111, 2222, 333], f"{r}")
    # counted by the RTU server, published at a cycle's end: polled for
    wait_for(lambda: (lambda b: b[0] << 16 | b[1] > bad0[0] << 16 | bad0[1])(
        tcp.read_input_registers(1024 + 52, 2).registers), 20)
    bad1 = tcp.read_input_registers(1024 + 52, 2).registers
    report("malformed frames counted (input registers 1076-1077)", bad1[0] << 16 | bad1[1] > bad0[0] << 16 | bad0[1],
           f"{bad0} -> {bad1}")
    report("plcrt still running", plc.alive())

    # a 32-bit %MD written over RTU is never seen half-written over TCP
    torn = []
    done = threading.Event()

    def reader():
        while not done.is_set():
            x = tcp.read_holding_registers(2048, 2)
            if not x.isError() and x.registers[0] != x.registers[1]:
                torn.append(x.registers)
    t = threading.Thread(target=reader)
    t.start()
    writes = 0
    for i in range(150):
        v = 0xFFFF if i % 2 else 0x0000
        if not cl.write_registers(2048, [v, v], slave=SLAVE).isError():
            writes += 1
    done.set()
    t.join()
    report("a %MD written over RTU (FC 16) never read half-written over TCP", writes > 100 and not torn,
           f"{writes} writes, torn reads {torn[:3]}")
    cl.close()
    ov = tcp.read_input_registers(1024 + 40, 2).registers
    report("the scan's own overruns 0", ov == [0, 0], f"{ov}")
    report("SIGTERM: exit status 0", plc.stop() == 0)
finally:
    Plcrt.kill_all()
    line.close()

sys.exit(0 if report.all_passed() else 1)
