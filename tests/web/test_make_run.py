"""`make run` starts plcweb beside plcrt and prints its address and a login
(mk/run_web.sh): the address printed serves the login page, the login
printed opens a session that reads plcrt's diagnostics, and plcweb ends
with plcrt.

  test_make_run.py ROOT INI WORK
make runs without a terminal here, as in CI: plcrt is stopped with SIGTERM,
as a service manager would (Ctrl-C at a terminal: tests/examples/test_ctrl_c.py)."""
import http.client
import json
import os
import re
import signal
import subprocess
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "common"))
from peer import Report, free_port, wait_for  # noqa: E402
from pymodbus.client import ModbusTcpClient  # noqa: E402

report = Report("web-make-run")


def main():
    root, ini_src, work = sys.argv[1], sys.argv[2], os.path.abspath(sys.argv[3])
    os.makedirs(work, exist_ok=True)
    port, wport = free_port(), free_port()
    ini = os.path.join(work, "run.ini")
    text = open(ini_src).read().replace("port = 1502", f"port = {port}").replace(
        "file = build/epicpos.retain", f"file = {work}/run.retain")
    open(ini, "w").write(text)
    env = dict(os.environ, WEB_PORT=str(wport))
    p = subprocess.Popen(["make", "--no-print-directory", "-C", root, "run", f"INI={ini}"], env=env,
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True)
    lines = []
    threading.Thread(target=lambda: [lines.append(x.rstrip()) for x in p.stdout], daemon=True).start()
    try:
        line = wait_for(lambda: next((x for x in lines if x.startswith("plcweb: http://")), None), 120, 0.1)
        m = re.match(r"plcweb: http://127\.0\.0\.1:(\d+)/ \(plcrt at 127\.0\.0\.1:(\d+)\): log in as (\S+), "
                     r"password (\S+) ", line or "")
        report("make run prints plcweb's address on 127.0.0.1, the plcrt it watches and a login",
               m and m.group(1) == str(wport) and m.group(2) == str(port), line or "\n".join(lines[-10:]))
        if not m:
            return 1
        c = http.client.HTTPConnection("127.0.0.1", wport, timeout=10)
        c.request("POST", "/login", body=json.dumps({"user": m.group(3), "password": m.group(4)}),
                  headers={"Content-Type": "application/json"})
        r = c.getresponse()
        r.read()
        cookie = (r.getheader("Set-Cookie") or "").split(";")[0]
        wait_for(lambda: any("running CONFIG0" in x for x in lines), 20, 0.1)
        c.request("GET", "/api/overview", headers={"Cookie": cookie})
        r = c.getresponse()
        d = json.loads(r.read())
        report("the printed login opens a session; the overview shows the EPICPOS example running",
               r.status == 200 and d.get("programs") == ["CONFIG0.RES0.AXIS"] and d.get("cycles", 0) > 0, d)
        # the demo's tag list: a parameter written and Stop pressed through Modbus,
        # with forcing not allowed (the example's configuration has no [debug])
        c.request("GET", "/api/session", headers={"Cookie": cookie})
        csrf = json.loads(c.getresponse().read())["csrf"]

        def post(path, body):
            c.request("POST", path, body=json.dumps(body), headers={
                "Cookie": cookie, "X-CSRF-Token": csrf, "Content-Type": "application/json"})
            r = c.getresponse()
            return r.status, json.loads(r.read())
        mb = ModbusTcpClient("127.0.0.1", port=port, timeout=3)
        mb.connect()
        st, w = post("/api/write", {"path": "slvelasse", "value": "37"})
        # the write reaches the program at the next cycle and the reads after
        # that cycle's end: polled for
        wait_for(lambda: mb.read_holding_registers(2050, 2, slave=1).registers == [0, 37], 20, 0.02)
        r = mb.read_holding_registers(2050, 2, slave=1).registers
        report("a parameter written from the page without forcing: slVelAsse 37 read back by pymodbus "
               "(holding 2050), written through its tag", st == 200 and r == [0, 37]
               and "Modbus write" in str(w.get("how")), f"{st} {w} {r}")
        st, w = post("/api/axis", {"axis": "CONFIG0.RES0.AXIS.AXIS", "action": "stop"})
        report("Stop pressed without forcing: sent through the tag of cSTOP (coil 20)",
               st == 200 and "coil 20" in str(w.get("how")), f"{st} {w}")
        mb.close()
        c.close()
        # plcrt itself (its command line starts with it), not the scripts that carry its arguments
        plcrt = subprocess.run(["pgrep", "-f", f"^[^ ]*plcrt -c {ini}"], capture_output=True, text=True).stdout.split()
        for pid in plcrt:
            os.kill(int(pid), signal.SIGTERM)
        status = p.wait(30)
        gone = wait_for(lambda: subprocess.run(["pgrep", "-f", f"plcweb.*--port {wport}"],
                                               capture_output=True).returncode != 0, 10, 0.1)
        report("plcrt stopped: make ends with status 0 and plcweb with it", status == 0 and gone,
               f"status {status}, plcweb gone: {gone}")
    finally:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGTERM)
            p.wait(10)
    return 0 if report.all_passed() else 1


if __name__ == "__main__":
    sys.exit(main())
