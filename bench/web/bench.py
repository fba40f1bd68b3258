"""plcweb's load on plcrt: the EPICPOS example at 1 ms, measured for a while
alone, then while 10 clients each watch 50 variables through plcweb at
10 Hz (each does what a browser on the Variables page does: one request for
the 50 values every 100 ms). Figures: plcrt's own overruns and those that
began with a late wake-up, its execution time p99 (register 1036, refreshed
every 0.2 s: median and worst of the window), the watch's refresh rate as
the clients see it (new cycle numbers per second) and plcweb's reply time.

  bench.py PLCRT INI WORK [SECONDS]"""
import http.client
import json
import os
import statistics
import subprocess
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..", "..")
sys.path.insert(0, os.path.join(ROOT, "tests", "common"))
from peer import Plcrt, free_port, wait_for  # noqa: E402
from pymodbus.client import ModbusTcpClient  # noqa: E402

PLCWEB = os.path.join(ROOT, "plcweb", "plcweb")
CLIENTS, VARS, HZ = 10, 50, 10


def diag(c):
    r = c.read_input_registers(1024, 50, slave=1).registers
    return {k: r[o] << 16 | r[o + 1] for k, o in (("cycles", 0), ("overruns", 2), ("exec_p99", 12),
                                                   ("lat_p99", 20), ("own", 40))}


def window(c, seconds):
    """plcrt's figures over seconds: overrun counts and exec p99 samples."""
    d0, p99, lat = diag(c), [], []
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        time.sleep(0.2)
        d = diag(c)
        p99.append(d["exec_p99"])
        lat.append(d["lat_p99"])
    d1 = diag(c)
    return {"cycles": d1["cycles"] - d0["cycles"], "own": d1["own"] - d0["own"],
            "late": (d1["overruns"] - d1["own"]) - (d0["overruns"] - d0["own"]),
            "p99_med": statistics.median(p99), "p99_max": max(p99), "lat_p99_med": statistics.median(lat)}


def client(port, cookie, paths, stop, out):
    q = "&".join("p=" + p for p in paths)
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    cycles, times, errors = set(), [], 0
    nxt = time.monotonic()
    while not stop.is_set():
        t0 = time.monotonic()
        try:
            conn.request("GET", "/api/values?" + q, headers={"Cookie": "plcweb=" + cookie})
            r = conn.getresponse()
            d = json.loads(r.read())
            cycles.add(d["cycle"])
        except (OSError, http.client.HTTPException, ValueError):
            errors += 1
            conn = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
        times.append(time.monotonic() - t0)
        nxt += 1.0 / HZ
        time.sleep(max(0.0, nxt - time.monotonic()))
    out.append((cycles, times, errors))


def main():
    exe, ini_src, work = sys.argv[1], sys.argv[2], os.path.abspath(sys.argv[3])
    seconds = float(sys.argv[4]) if len(sys.argv) > 4 else 10
    os.makedirs(work, exist_ok=True)
    port, wport = free_port(), free_port()
    ini = os.path.join(work, "epicpos.ini")
    text = open(ini_src).read().replace("port = 1502", f"port = {port}").replace(
        "file = build/epicpos.retain", f"file = {work}/epicpos.retain")
    open(ini, "w").write(text)
    plc = Plcrt(exe, ini, work, "plcrt")
    users = os.path.join(work, "users")
    subprocess.run([sys.executable, PLCWEB, "adduser", "--users", users, "bench", "viewer"], input="bench-pass\n",
                   text=True, check=True, capture_output=True)
    web = None
    try:
        c = ModbusTcpClient("127.0.0.1", port=port)
        c.connect()
        time.sleep(1)
        alone = window(c, seconds)
        web = subprocess.Popen([sys.executable, PLCWEB, "--users", users, "--port", str(wport),
                                "--plc", f"127.0.0.1:{port}"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        import socket
        wait_for(lambda: socket.socket().connect_ex(("127.0.0.1", wport)) == 0, 15, 0.1)
        h = http.client.HTTPConnection("127.0.0.1", wport)
        h.request("POST", "/login", body=json.dumps({"user": "bench", "password": "bench-pass"}),
                  headers={"Content-Type": "application/json"})
        r = h.getresponse()
        r.read()
        cookie = r.getheader("Set-Cookie").split(";")[0].split("=", 1)[1]
        h.request("GET", "/api/vars?q=CONFIG0.RES0.AXIS.", headers={"Cookie": "plcweb=" + cookie})
        paths = [v["path"] for v in json.loads(h.getresponse().read())["vars"]][:VARS]
        stop, out = threading.Event(), []
        th = [threading.Thread(target=client, args=(wport, cookie, paths, stop, out)) for _ in range(CLIENTS)]
        for t in th:
            t.start()
        time.sleep(2)           # the watcher under way
        loaded = window(c, seconds)
        h.request("GET", "/api/overview", headers={"Cookie": "plcweb=" + cookie})
        ov = json.loads(h.getresponse().read())
        stop.set()
        for t in th:
            t.join()
        rates = [len(cy) / (seconds + 2) for cy, _, _ in out]
        times = sorted(x for _, ts, _ in out for x in ts)
        errors = sum(e for _, _, e in out)
        print(f"web: plcrt at 1 ms (EPICPOS example), {seconds:g} s alone, then {CLIENTS} clients x {len(paths)} "
              f"variables at {HZ} Hz through plcweb")
        for name, w in (("alone", alone), ("with plcweb", loaded)):
            print(f"web: {name:12s} cycles {w['cycles']}, overruns own {w['own']}, late wake-ups {w['late']}, "
                  f"exec p99 median {w['p99_med']} us (worst {w['p99_max']} us), wake latency p99 median "
                  f"{w['lat_p99_med']} us")
        print(f"web: watch refresh seen by each client: {min(rates):.1f}..{max(rates):.1f} new samples/s "
              f"(target >= 10 with the page's 100 ms poll: the watcher samples at 20 Hz)")
        print(f"web: plcweb reply time p50 {1000 * times[len(times) // 2]:.1f} ms, p99 "
              f"{1000 * times[int(len(times) * 0.99)]:.1f} ms, {errors} errors in {len(times)} requests")
        print(f"web: the watcher holds plcrt's trace {ov['watch_round_ms']} ms per sample of {ov['watching']} "
              f"variables, 20 times a second")
        print(f"web: exec p99 with/without plcweb: {loaded['p99_med']}/{alone['p99_med']} us; "
              f"own overruns with plcweb: {loaded['own']}")
    finally:
        if web:
            web.terminate()
            web.wait(10)
        plc.stop()
    return 0


if __name__ == "__main__":
    sys.exit(main())
