#!/usr/bin/env python3
"""plcrt and the service manager's notify protocol, seen by this test's own
AF_UNIX datagram socket in place of systemd's:

    notify.py PLCRT INI WORKDIR

READY=1 once the scan runs, WATCHDOG=1 at about half of WATCHDOG_USEC
while it runs (always within it, never faster than a quarter of it), STOPPING=1 on SIGTERM
and exit status 0; an abstract socket ('@name') works the same; a
WATCHDOG_PID naming another process gets READY=1 but no pings.
Prints PASS:/FAIL: lines."""
import os
import signal
import socket
import struct
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from peer import Report, free_port  # noqa: E402

exe, ini, work = sys.argv[1], sys.argv[2], os.path.abspath(sys.argv[3])
os.makedirs(work, exist_ok=True)
report = Report("install/notify")
WD_US = 2000000   # WatchdogSec=2s
SO_TIMESTAMPNS = getattr(socket, "SO_TIMESTAMPNS", 35)      # Linux's value; Python may lack the name


def stamping(s):
    """Each message stamped by the kernel when it arrives (SO_TIMESTAMPNS,
    the wall clock), not when this script gets to it on a loaded host."""
    s.setsockopt(socket.SOL_SOCKET, SO_TIMESTAMPNS, 1)


def recv_stamped(s):
    """(arrival time, text) of the next message on s."""
    data, anc, _, _ = s.recvmsg(4096, socket.CMSG_SPACE(16))
    for level, kind, raw in anc:
        if level == socket.SOL_SOCKET and kind == SO_TIMESTAMPNS:
            sec, nsec = struct.unpack("qq", raw[:16])
            return sec + nsec / 1e9, data.decode()
    return time.time(), data.decode()


def run(tag, addr, bind, watchdog_pid=None, seconds=4.5):
    """plcrt under a notify socket for a while; the messages with their times."""
    cfg = os.path.join(work, tag + ".ini")
    with open(cfg, "w") as f:
        f.write(open(ini).read().replace("port = 1502", "port = %d" % free_port())
                .replace("file = build/epicpos.retain", "file = %s" % os.path.join(work, tag + ".retain")))
    s = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    s.bind(bind)
    s.settimeout(0.2)
    stamping(s)
    env = dict(os.environ, NOTIFY_SOCKET=addr, WATCHDOG_USEC=str(WD_US))
    if watchdog_pid:
        env["WATCHDOG_PID"] = str(watchdog_pid)
    log = open(os.path.join(work, tag + ".log"), "w")
    p = subprocess.Popen([exe, "-c", cfg], env=env, stdout=log, stderr=log)
    msgs, t0, stopped = [], time.monotonic(), None
    deadline = t0 + 30   # plcrt's start-up on a loaded machine, then `seconds` of pings
    while time.monotonic() < deadline:
        try:
            msgs.append(recv_stamped(s))
            m = msgs[-1][1]
            if m.startswith("READY=1"):
                deadline = time.monotonic() + seconds
        except socket.timeout:
            pass
        if p.poll() is not None:
            break
    p.send_signal(signal.SIGTERM)
    try:
        rc = p.wait(timeout=15)
    except subprocess.TimeoutExpired:
        p.kill()
        rc = p.wait()
    try:
        while True:
            msgs.append(recv_stamped(s))
            stopped = stopped or msgs[-1][1] == "STOPPING=1"
    except (socket.timeout, OSError):
        pass
    s.close()
    return msgs, rc, open(log.name).read()


path = os.path.join(work, "notify.sock")
for tag, addr, bind in (("path", path, path), ("abstract", "@plcrt-notify-%d" % os.getpid(),
                                                "\0plcrt-notify-%d" % os.getpid())):
    msgs, rc, out = run(tag, addr, bind)
    kinds = [m for _, m in msgs]
    ready = [t for t, m in msgs if m.startswith("READY=1")]
    pings = [t for t, m in msgs if m == "WATCHDOG=1"]
    report("%s socket: READY=1 first, once" % tag, len(ready) == 1 and kinds[0].startswith("READY=1"),
           "%s %s" % (kinds[:5], out[-300:]))
    gaps = [b - a for a, b in zip(pings, pings[1:])]
    report("%s socket: WATCHDOG=1 while the scan runs, at about half of WatchdogSec" % tag,
           len(pings) >= 3 and all(0.5 <= g < 1.9 for g in gaps),
           "%d pings, gaps %s s" % (len(pings), ["%.2f" % g for g in gaps]))
    report("%s socket: STOPPING=1 on SIGTERM, exit status 0" % tag,
           kinds and kinds[-1] == "STOPPING=1" and rc == 0, "%s rc %s" % (kinds[-3:], rc))
    os.path.exists(path) and os.unlink(path)

msgs, rc, out = run("otherpid", path, path, watchdog_pid=1, seconds=2.0)
kinds = [m for _, m in msgs]
report("WATCHDOG_PID of another process: READY=1, no pings",
       any(k.startswith("READY=1") for k in kinds) and "WATCHDOG=1" not in kinds, str(kinds))
# a stalled scan: the program sleeps 4 s in one cycle when coil 0 is set (its
# own watchdog off). A ping may still come up to half the watchdog time
# (1 s, plus the housekeeping thread's wake-up) after the stall began, for
# cycles run before it; from 2 s on none may come until the stall ends, and
# they resume after it
tree = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
proj = os.path.join(work, "stall")
os.makedirs(proj, exist_ok=True)
with open(os.path.join(proj, "stall.st"), "w") as f:
    f.write("PROGRAM Stall\n  VAR stall AT %QX0.0 : BOOL; END_VAR\n"
            "  IF stall THEN\n    stall := FALSE;\n"
            "    {{ { struct timespec ts = { 4, 0 }; nanosleep(&ts, NULL); } }}\n  END_IF;\nEND_PROGRAM\n"
            "CONFIGURATION C\n  RESOURCE R ON PLC\n    TASK t(INTERVAL := T#10ms, PRIORITY := 0);\n"
            "    PROGRAM s WITH t : Stall;\n  END_RESOURCE\nEND_CONFIGURATION\n")
sport = free_port()
with open(os.path.join(proj, "plcrt.ini"), "w") as f:
    f.write("[scan]\nwatchdog_ms = 0\n\n[io]\nbackend = none\n\n[modbus]\nport = %d\n" % sport)
env = {k: v for k, v in os.environ.items() if k not in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL")}
b = subprocess.run([os.path.join(tree, "plcrt-build"), proj], env=env, capture_output=True, text=True)
report("the stalling program builds", b.returncode == 0, b.stdout + b.stderr)
if b.returncode == 0:
    from pymodbus.client import ModbusTcpClient
    sock = os.path.join(work, "stall.sock")
    s = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    s.bind(sock)
    s.settimeout(0.2)
    stamping(s)
    env = dict(os.environ, NOTIFY_SOCKET=sock, WATCHDOG_USEC=str(WD_US))
    log = open(os.path.join(work, "stall.log"), "w")
    p = subprocess.Popen([os.path.join(proj, "build", "plcrt"), "-c", "plcrt.ini"], cwd=proj, env=env,
                         stdout=log, stderr=log)
    msgs, t_stall = [], None
    end = time.monotonic() + 40
    c = ModbusTcpClient("127.0.0.1", port=sport)
    while time.monotonic() < end:
        try:
            msgs.append(recv_stamped(s))
        except socket.timeout:
            pass
        pings = [t for t, m in msgs if m == "WATCHDOG=1"]
        if t_stall is None and len(pings) >= 2:
            c.connect()
            t_stall = time.time()           # the stall begins when the write lands, after this
            c.write_coil(0, True, slave=1)
        if t_stall and len([t for t in pings if t > t_stall + 4]) >= 2:
            break
    c.close()
    p.send_signal(signal.SIGTERM)
    p.wait(timeout=15)
    s.close()
    pings = [t for t, m in msgs if m == "WATCHDOG=1"]
    during = [t - t_stall for t in pings if t_stall and t_stall + 2.0 < t < t_stall + 3.9]
    after = [t for t in pings if t_stall and t > t_stall + 4]
    report("a scan stalled 4 s: no WATCHDOG=1 while it stalls, pings again after",
           t_stall is not None and not during and len(after) >= 2,
           "pings during the stall at %s s, %d after" % (["%.2f" % x for x in during], len(after)))
sys.exit(0 if report.all_passed() else 1)
