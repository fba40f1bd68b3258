#!/usr/bin/env python3
"""plcrt benchmarks: wake latency beside cyclictest, Modbus throughput beside
a reference server on libmodbus's modbus_reply (bench/runtime/refserver.c)
under the same load (bench/runtime/mbload.c), and the runtime's own cost per
cycle.

usage: bench.py PLCRT_1MS PLCRT_250US PORT|auto WORKDIR REFSERVER MBLOAD
(auto: a port free now). BENCH_ONLY=modbus runs the Modbus part alone,
BENCH_ONLY=idle the 1000 idle connections alone."""
import os
import re
import signal
import statistics
import socket
import struct
import subprocess
import sys
import time

def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


P1, P250, WORK, REF, LOAD = sys.argv[1], sys.argv[2], sys.argv[4], sys.argv[5], sys.argv[6]
PORT = free_port() if sys.argv[3] == "auto" else int(sys.argv[3])
SECONDS = int(os.environ.get("BENCH_SECONDS", "10"))
os.makedirs(WORK, exist_ok=True)


def ini(modbus=True, prio=80, clients=32):
    path = os.path.join(WORK, f"bench-{int(modbus)}-{prio}.ini")
    with open(path, "w") as f:
        f.write(f"[scan]\npriority = {prio}\nlock_memory = {'yes' if prio else 'no'}\n"
                f"[io]\nbackend = none\n[modbus]\nenabled = {'yes' if modbus else 'no'}\n"
                f"port = {PORT}\nmax_clients = {clients}\n[retain]\nfile =\n")
    return path


def start(binary, cfg, prefix=()):
    log = open(os.path.join(WORK, "plcrt.log"), "w+")
    p = subprocess.Popen([*prefix, binary, "-c", cfg], stdout=log, stderr=log)
    p.logf = log
    return p


def wait_port():
    for _ in range(400):
        try:
            socket.create_connection(("127.0.0.1", PORT), timeout=0.2).close()
            return
        except OSError:
            time.sleep(0.05)
    raise RuntimeError("plcrt does not listen")


def stop(p):
    p.send_signal(signal.SIGTERM)
    p.wait(timeout=120)
    p.logf.seek(0)
    return p.logf.read()


def plcrt_stats(text):
    """{'lat': {...}, 'exec': {...}, 'cycles': n, 'overruns': n} from the exit statistics."""
    out = {}
    m = re.search(r"statistics: (\d+) cycles of [\d.]+ us, (\d+) overruns", text)
    out["cycles"], out["overruns"] = int(m.group(1)), int(m.group(2))
    m = re.search(r"overruns: (\d+) with the program's execution alone over the period", text)
    out["own"] = int(m.group(1)) if m else 0
    m = re.search(r"^exchange (-?\d+)$", text, re.M)
    out["exchange"] = int(m.group(1)) if m else None
    for key, name in (("lat", "wake latency"), ("exec", "execution")):
        m = re.search(name + r"\s+min\s+([\d.]+)\s+mean\s+([\d.]+)\s+p99\s+([\d.]+)\s+p99.9\s+([\d.]+)\s+max\s+([\d.]+)", text)
        out[key] = dict(zip(("min", "mean", "p99", "p999", "max"), map(float, m.groups())))
    return out


def cyclictest_stats(text):
    hist, over = {}, 0
    for line in text.splitlines():
        m = re.match(r"^(\d+)\s+(\d+)\s*$", line)
        if m:
            hist[int(m.group(1))] = int(m.group(2))
    n = sum(hist.values())
    mx = int(re.search(r"# Max Latencies:\s+(\d+)", text).group(1))
    mn = int(re.search(r"# Min Latencies:\s+(\d+)", text).group(1))
    avg = float(re.search(r"# Avg Latencies:\s+(\d+)", text).group(1))

    def q(frac):
        want, seen = frac * n, 0
        for us in sorted(hist):
            seen += hist[us]
            if seen > want:
                return min(us + 1, mx)        # upper edge of the 1 us bin, as plcrt reports
        return mx
    return {"min": mn, "mean": avg, "p99": q(0.99), "p999": q(0.999), "max": mx, "n": n}


def row(name, d):
    return f"  {name:<22} min {d['min']:8.1f}  mean {d['mean']:8.1f}  p99 {d['p99']:8.1f}  p99.9 {d['p999']:8.1f}  max {d['max']:8.1f} us"


def latency(binary, period_us):
    p = start(binary, ini(modbus=True))
    wait_port()
    loops = SECONDS * 1000000 // period_us
    ct = subprocess.run(["cyclictest", "-m", "-q", "-t", "1", "-p", "80", "-i", str(period_us),
                         "-l", str(loops), "-h", "10000"], capture_output=True, text=True)
    st = plcrt_stats(stop(p))
    c = cyclictest_stats(ct.stdout)
    print(f"\nwake latency at {period_us} us, {SECONDS} s, SCHED_FIFO 80, plcrt and cyclictest in the same run:")
    print(row("plcrt", st["lat"]))
    print(row("cyclictest", c))
    r99 = st["lat"]["p99"] / max(c["p99"], 1)
    rmax = st["lat"]["max"] / max(c["max"], 1)
    print(f"  ratio plcrt/cyclictest: p99 {r99:.2f}x, max {rmax:.2f}x (aim: <= 1.1x); "
          f"{st['overruns']} overruns in {st['cycles']} cycles")
    return st


def load(clients, seconds):
    r = subprocess.run([LOAD, str(PORT), str(clients), str(seconds)], capture_output=True, text=True, timeout=60)
    m = re.match(r"(\d+) requests/s", r.stdout)
    if r.returncode or not m:
        raise RuntimeError(f"mbload: {r.stdout} {r.stderr}")
    return int(m.group(1))


def exchange_us():
    """Register 1070: the scan's longest Modbus exchange (docs/modbus.md)."""
    with socket.create_connection(("127.0.0.1", PORT), timeout=3) as s:
        s.sendall(bytes([0, 1, 0, 0, 0, 6, 1, 4, 1070 >> 8, 1070 & 255, 0, 2]))
        r = b""
        while len(r) < 13:
            got = s.recv(13 - len(r))
            if not got:
                return -1
            r += got
    return int.from_bytes(r[9:13], "big")


def plcrt_round(clients, seconds):
    p = start(P1, ini(modbus=True))
    wait_port()
    rate = load(clients, seconds)
    st = plcrt_stats(stop_after(p, exchange_us()))
    return rate, st


def stop_after(p, xch):
    text = stop(p)
    return text + f"\nexchange {xch}\n"


def ref_round(clients, seconds):
    q = subprocess.Popen([REF, str(PORT)], stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT)
    try:
        wait_port()
        return load(clients, seconds)
    finally:
        q.terminate()
        q.wait()


def modbus():
    rounds, seconds = 3, float(os.environ.get("BENCH_MB_SECONDS", "3"))
    print(f"\nModbus TCP, FC 3 of 125 registers back to back (mbload), {rounds} rounds of {seconds:g} s; "
          f"plcrt scanning an empty program every 1 ms at SCHED_FIFO 80 beside the reference server "
          f"(libmodbus's modbus_reply, select(), nothing else); requests/s in total, medians:")
    for n in (1, 4, 16):
        plc, ref, worst, over, xch = [], [], [], [], []
        for r in range(rounds):
            order = (0, 1) if r % 2 == 0 else (1, 0)       # neither always goes first
            for which in order:
                if which == 0:
                    rate, st = plcrt_round(n, seconds)
                    plc.append(rate)
                    worst.append(st["exec"]["max"])
                    xch.append(st["exchange"])
                    over.append(f"{st['overruns']}/{st['own']}")
                else:
                    ref.append(ref_round(n, seconds))
        mp, mr = statistics.median(plc), statistics.median(ref)
        print(f"  {n:2d} client(s): plcrt {mp:8.0f}  reference {mr:8.0f}  ratio plcrt/reference {mp / mr:5.2f}  "
              f"(rounds plcrt {plc}, reference {ref}); scan: longest execution {max(worst):.1f} us "
              f"(rounds {worst}), of which the Modbus exchange at most {max(xch)} us (rounds {xch}), "
              f"overruns in all/of its own {over}")


def cost(st_mb):
    print("\nthe runtime's own cost per cycle, empty program at 1 ms:")
    print(f"  wall clock (from the 1 ms latency run, Modbus on, no client): mean {st_mb['exec']['mean']:.1f} us, "
          f"p99 {st_mb['exec']['p99']:.1f} us, max {st_mb['exec']['max']:.1f} us")
    for mb in (False, True):
        out = os.path.join(WORK, f"callgrind.{int(mb)}")
        p = start(P1, ini(modbus=mb, prio=0),
                  prefix=("valgrind", "--tool=callgrind", "--toggle-collect=scan_cycle", f"--callgrind-out-file={out}"))
        if mb:
            wait_port()
        time.sleep(4)
        text = stop(p)
        st = plcrt_stats(text)
        ann = subprocess.run(["callgrind_annotate", out], capture_output=True, text=True).stdout
        m = re.search(r"^\s*([\d,]+)\s+\(100.0%\)\s+PROGRAM TOTALS", ann, re.M) or re.search(r"^\s*([\d,]+)\s+PROGRAM TOTALS", ann, re.M)
        ir = int(m.group(1).replace(",", "")) if m else 0
        print(f"  instructions per cycle (valgrind, inside scan_cycle), Modbus {'on ' if mb else 'off'}: "
              f"{ir / max(st['cycles'], 1):8.0f}  ({st['cycles']} cycles)")


def rss_kb(pid):
    with open(f"/proc/{pid}/status") as f:
        return int(re.search(r"^VmRSS:\s+(\d+)", f.read(), re.M).group(1))


def fc3_latencies(n=400):
    """n FC3 requests (10 registers) from one working client, one after the
    other: their round trips in ms."""
    s = socket.create_connection(("127.0.0.1", PORT), timeout=5)
    s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    out = []
    for i in range(n):
        req = struct.pack(">HHHBBHH", i & 0xFFFF, 0, 6, 1, 3, 0, 10)
        t0 = time.perf_counter()
        s.sendall(req)
        got = b""
        while len(got) < 9 + 20:
            chunk = s.recv(64)
            if not chunk:
                raise RuntimeError("connection closed")
            got += chunk
        out.append((time.perf_counter() - t0) * 1000)
    s.close()
    return out


def clients_connected():
    """Input registers 1048-1049: Modbus clients connected (docs/modbus.md)."""
    s = socket.create_connection(("127.0.0.1", PORT), timeout=5)
    s.sendall(struct.pack(">HHHBBHH", 1, 0, 6, 1, 4, 1048, 2))
    got = b""
    while len(got) < 13:
        got += s.recv(64)
    s.close()
    hi, lo = struct.unpack(">HH", got[9:13])
    return (hi << 16 | lo) - 1   # less this request's own connection


def idle_connections(n=998, rounds=3):
    """Target: 1000 connections (998 idle ones, a working client and the
    diagnostics reader, at
    max_clients 1000) cost less than 50 MB and delay the working
    client by less than 1 ms (median round trip, with them against without;
    medians of `rounds` rounds)."""
    import resource
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    resource.setrlimit(resource.RLIMIT_NOFILE, (max(soft, min(hard, n + 256)), hard))
    p = start(P1, ini(prio=0, clients=n))
    wait_port()
    time.sleep(0.5)
    base_rss, med0, med1, extra, held, total = [], [], [], [], [], []
    try:
        for _ in range(rounds):
            r0 = rss_kb(p.pid)
            med0.append(statistics.median(fc3_latencies()))
            socks = [socket.create_connection(("127.0.0.1", PORT), timeout=5) for _ in range(n)]
            time.sleep(1.0)
            held.append(clients_connected())
            total.append(rss_kb(p.pid) / 1024)
            extra.append((rss_kb(p.pid) - r0) / 1024)
            med1.append(statistics.median(fc3_latencies()))
            for c in socks:
                c.close()
            time.sleep(0.5)
            base_rss.append(r0 / 1024)
    finally:
        stop(p)
    mem, d = statistics.median(extra), statistics.median(med1) - statistics.median(med0)
    print(f"\n{n} idle Modbus connections + 1 working (plcrt at 1 ms, {rounds} rounds, medians):")
    print(f"  connections held by plcrt: {min(held)}..{max(held)} of {n}")
    tot = statistics.median(total)
    print(f"  plcrt's resident memory {statistics.median(base_rss):.1f} MB without them, {tot:.1f} MB "
          f"with them (+{mem:.2f} MB; the client table is sized for max_clients at start) "
          f"(target < 50 MB): {'met' if tot < 50 else 'NOT met'}")
    print(f"  working client's FC3 round trip {statistics.median(med0):.3f} ms without, "
          f"{statistics.median(med1):.3f} ms with them: +{d:.3f} ms (target < 1 ms): "
          f"{'met' if d < 1.0 else 'NOT met'}")


def main():
    if os.environ.get("BENCH_ONLY") == "modbus":
        modbus()
        return
    if os.environ.get("BENCH_ONLY") == "idle":
        idle_connections()
        return
    st1 = latency(P1, 1000)
    latency(P250, 250)
    modbus()
    idle_connections()
    cost(st1)


main()
