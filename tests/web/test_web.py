"""plcweb against a running plcrt with the EPICPOS example, in a real
headless browser (Debian's chromium and chromedriver, driven by Selenium),
and its security over plain HTTP.

Independent references: pymodbus reads of the example's Modbus map
(docs/examples.md) and plcrt's diagnostics, plctrace's own CSV of the same
capture, plctrace forced, and the line numbers of an ST file the test writes.

  test_web.py PLCRT INI WORK [SHOTS]
SHOTS: where the pages' screenshots go (default WORK/shots; docs/img for
docs/web.md: make web-screenshots)."""
import argparse
import base64
import csv
import http.client
import io
import json
import os
import socket
import subprocess
import sys
import tarfile
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..", "..")
sys.path.insert(0, os.path.join(HERE, "..", "common"))
sys.path.insert(0, os.path.join(ROOT, "plcweb"))
from peer import Plcrt, Report, free_port, wait_for  # noqa: E402
from pymodbus.client import ModbusTcpClient  # noqa: E402
from plclink import plctrace  # noqa: E402  (plctrace's own module, imported)
from selenium import webdriver  # noqa: E402
from selenium.webdriver.chrome.service import Service  # noqa: E402
from selenium.webdriver.common.action_chains import ActionChains  # noqa: E402
from selenium.webdriver.common.by import By  # noqa: E402

PLCWEB = os.path.join(ROOT, "plcweb", "plcweb")
MD = 2048                       # %MD0; %MDn at 2048 + 2n
POSIT = MD + 2 * 40             # %MD40: the axis's posit, copied every cycle
QUOTA, SPEED = MD, MD + 2       # slQuotaPos, slVelAsse
C_START, C_STILL, C_LOOPON = 2, 44, 47
FORCED = 1072                   # input register: variables forced
AX = "CONFIG0.RES0.AXIS.AXIS"   # the EPICPOS instance
report = Report("web")


def s32(hi, lo):
    v = hi << 16 | lo
    return v - (1 << 32) if v & 0x80000000 else v


class Mb:
    """pymodbus on the example's map: the reference the page is checked against."""

    def __init__(self, port):
        self.c = ModbusTcpClient("127.0.0.1", port=port, timeout=3)
        self.c.connect()

    def md(self, addr):
        r = self.c.read_holding_registers(addr, 2, slave=1).registers
        return s32(r[0], r[1])

    def set_md(self, addr, v):
        self.c.write_registers(addr, [(v >> 16) & 0xFFFF, v & 0xFFFF], slave=1)

    def coil(self, a):
        return self.c.read_coils(a, 1, slave=1).bits[0]

    def set_coil(self, a, v):
        self.c.write_coil(a, v, slave=1)

    def diag(self, off):
        r = self.c.read_input_registers(off, 2, slave=1).registers
        return r[0] << 16 | r[1]


class Http:
    """plain HTTP to plcweb, with or without a session"""

    def __init__(self, port, work=None):
        self.port, self.cookie, self.csrf, self.work = port, None, None, work

    def req(self, method, path, body=None, csrf=True, headers=None):
        c = http.client.HTTPConnection("127.0.0.1", self.port, timeout=30)
        h = dict(headers or {})
        if self.cookie:
            h["Cookie"] = "plcweb=" + self.cookie
        if csrf and self.csrf and method == "POST":
            h["X-CSRF-Token"] = self.csrf
        if isinstance(body, dict):
            body, h["Content-Type"] = json.dumps(body), "application/json"
        c.request(method, path, body=body, headers=h)
        r = c.getresponse()
        data = r.read()
        for k, v in r.getheaders():
            if k.lower() == "set-cookie" and v.startswith("plcweb="):
                self.cookie = v.split(";")[0].split("=", 1)[1]
        c.close()
        return r.status, data

    def login(self, user, pw):
        st, data = self.req("POST", "/login", {"user": user, "password": pw})
        if st == 200:
            self.csrf = json.loads(self.req("GET", "/api/session")[1])["csrf"]
        return st, data


def browser():
    o = webdriver.ChromeOptions()
    o.binary_location = "/usr/bin/chromium"
    for a in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--disable-gpu",
              "--window-size=1280,1000", "--disable-extensions"):
        o.add_argument(a)
    d = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=o)
    d.set_page_load_timeout(30)
    return d


def make_ini(src, dst, port, retain, force=True, backend=None, extra=""):
    out, section = [], ""
    for line in open(src).read().splitlines():
        s = line.strip()
        if s.startswith("["):
            section = s.strip("[]")
        key = s.split("=")[0].strip() if "=" in s and not s.startswith(";") else ""
        if section == "modbus" and key == "port":
            line = f"port = {port}"
        elif section == "retain" and key == "file":
            line = f"file = {retain}"
        elif section == "io" and key == "backend" and backend:
            line = f"backend = {backend}"
        out.append(line)
    out += ["", "[debug]", "allow_force = yes"] if force else []
    out += [extra]
    open(dst, "w").write("\n".join(out) + "\n")


def project_archive(path, port, work, error):
    """A project of one program; with error, main.st line 9 is wrong."""
    body = "    n := n + ;\n" if error else "    n := n + 1;\n"
    main = ("(* plcweb's upload test *)\n"
            "PROGRAM WebTest\n"
            "  VAR\n"
            "    n : DINT;\n"
            "  END_VAR\n"
            "  VAR\n"
            "    out AT %MD0 : DINT;\n"
            "  END_VAR\n" + body +
            "    out := n;\n"
            "END_PROGRAM\n")
    config = ("CONFIGURATION Config0\n  RESOURCE Res0 ON PLC\n"
              "    TASK main(INTERVAL := T#1ms, PRIORITY := 0);\n"
              "    PROGRAM webtest WITH main : WebTest;\n  END_RESOURCE\nEND_CONFIGURATION\n")
    ini = f"[io]\nbackend = none\n[modbus]\nport = {port}\n[retain]\nfile = {work}/webtest.retain\n"
    with tarfile.open(path, "w:gz") as t:
        for name, text in (("myproj/main.st", main), ("myproj/config.st", config), ("myproj/plcrt.ini", ini)):
            b = text.encode()
            ti = tarfile.TarInfo(name)
            ti.size = len(b)
            t.addfile(ti, io.BytesIO(b))


class Service_:
    """The test as the service manager: the switch command plcweb runs asks
    for the project's plcrt in place of the running one."""

    def __init__(self, work, plc):
        self.work, self.plc = work, plc
        self.req = os.path.join(work, "switch.request")
        self.done = os.path.join(work, "switch.done")
        self.script = os.path.join(work, "switch.sh")
        open(self.script, "w").write(
            "#!/bin/sh\n# the service manager's restart, for the test\n"
            f'rm -f {self.done}; echo "$1" > {self.req}.tmp && mv {self.req}.tmp {self.req}\n'
            f"for i in $(seq 300); do [ -f {self.done} ] && cat {self.done} && exit 0; sleep 0.1; done\n"
            "echo 'no restart within 30 s'; exit 1\n")
        os.chmod(self.script, 0o755)
        threading.Thread(target=self.run, daemon=True).start()

    def run(self):
        while True:
            if os.path.exists(self.req):
                proj = open(self.req).read().strip()
                os.unlink(self.req)
                self.plc.stop()
                try:
                    self.plc = Plcrt(os.path.join(proj, "build", "plcrt"), os.path.join(proj, "plcrt.ini"),
                                     self.work, "switched")
                    open(self.done, "w").write("restarted\n")
                except RuntimeError as e:
                    open(self.done, "w").write(f"failed: {e}\n")
            time.sleep(0.05)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("plcrt")
    ap.add_argument("ini")
    ap.add_argument("work")
    ap.add_argument("shots", nargs="?")
    ap.add_argument("--plcopen", nargs=2, metavar=("PLCRT", "INI"), help="the PLCopen example, for its axes")
    a = ap.parse_args()
    work = os.path.abspath(a.work)
    shots = os.path.abspath(a.shots or os.path.join(work, "shots"))
    os.makedirs(shots, exist_ok=True)
    port = free_port()
    ini = os.path.join(work, "epicpos.ini")
    make_ini(a.ini, ini, port, os.path.join(work, "epicpos.retain"))
    plc = Plcrt(a.plcrt, ini, work, "plcrt")
    users = os.path.join(work, "users")
    for name, role, pw in (("olga", "operator", "olga-secret-1"), ("victor", "viewer", "victor-secret-1")):
        subprocess.run([sys.executable, PLCWEB, "adduser", "--users", users, name, role], input=pw + "\n",
                       text=True, check=True, capture_output=True)
    svc = Service_(work, plc)
    wport = free_port()
    weblog = open(os.path.join(work, "plcweb.log"), "w+")
    web = subprocess.Popen([sys.executable, PLCWEB, "--users", users, "--port", str(wport),
                            "--plc", f"127.0.0.1:{port}", "--project-dir", os.path.join(work, "projects"),
                            "--switch", svc.script, "--log", os.path.join(work, "writes.log")],
                           stdout=weblog, stderr=subprocess.STDOUT)
    drv = None
    try:
        if not wait_for(lambda: socket.socket().connect_ex(("127.0.0.1", wport)) == 0, 15, 0.1):
            raise RuntimeError("plcweb does not listen")
        mb = Mb(port)
        wait_for(lambda: mb.coil(C_LOOPON), 20, 0.05)
        security(wport, mb, work)
        drv = browser()
        pages(drv, wport, mb, port, shots, work)
        project(drv, wport, work, port, shots)
        viewer(drv, wport, shots)
        throttle(wport)
        reachable(wport)
        plcrt_gone(wport, svc)
        if a.plcopen:
            plcopen_axes(drv, wport, port, a.plcopen, work, shots)
        # last: its plcweb's session cookie replaces the first one's (cookies ignore the port)
        tags_and_backends(drv, a.plcrt, a.ini, users, work, shots)
        log = open(os.path.join(work, "writes.log")).read()
        report("every write is logged with its user: olga's force, unforce, write and axis stop",
               all(f"olga: {w}" in log for w in ("force", "unforce", "write", "axis")), log[-800:])
        log = open(os.path.join(work, "proj", "writes.log")).read()
        report("a write through a tag is logged with its user and the way it went: olga's write and axis stop",
               "Modbus write, holding 2050 (its tag)" in log and "Modbus write, coil 20 (its tag)" in log, log[-800:])
    finally:
        if drv:
            drv.quit()
        web.terminate()
        web.wait(10)
        svc.plc.stop()
        Plcrt.kill_all()
    return 0 if report.all_passed() else 1


def security(wport, mb, work):
    before = mb.md(SPEED)
    anon = Http(wport)
    st, _ = anon.req("POST", "/api/write", {"path": "CONFIG0.RES0.AXIS.SLVELASSE", "value": "77"})
    st2, _ = anon.req("GET", "/api/overview")
    report("no write without login: 401, slVelAsse unchanged (pymodbus)", st == 401 and st2 == 401
           and mb.md(SPEED) == before, f"{st} {st2} {mb.md(SPEED)}")
    v = Http(wport)
    v.login("victor", "victor-secret-1")
    results = [v.req("POST", p, b)[0] for p, b in (
        ("/api/write", {"path": "CONFIG0.RES0.AXIS.SLVELASSE", "value": "77"}),
        ("/api/force", {"path": "CONFIG0.RES0.AXIS.SLVELASSE", "value": "77"}),
        ("/api/unforce", {"all": True}), ("/api/axis", {"axis": AX, "action": "stop"}),
        ("/api/project", b"x"), ("/api/project/switch", None))]
    report("a viewer's session writes nothing: write, force, unforce, axis, project upload, switch all 403",
           results == [403] * 6 and mb.md(SPEED) == before and mb.diag(FORCED) == 0, f"{results}")
    st, _ = v.req("GET", "/api/overview")
    report("a viewer reads: the overview answers", st == 200, st)
    o = Http(wport, os.path.join(work, "projects"))
    o.login("olga", "olga-secret-1")
    st, body = o.req("POST", "/api/write", {"path": "CONFIG0.RES0.AXIS.SLVELASSE", "value": "77"}, csrf=False)
    st2, _ = o.req("POST", "/api/write", {"path": "CONFIG0.RES0.AXIS.SLVELASSE", "value": "77"},
                   csrf=False, headers={"X-CSRF-Token": "guessed"})
    report("an operator's write without the CSRF token, or a wrong one: 403, nothing written",
           st == 403 and st2 == 403 and mb.md(SPEED) == before, f"{st} {st2} {body[:200]}")
    st, body = o.req("POST", "/api/write", {"path": "CONFIG0.RES0.AXIS.SLVELASSE", "value": "77"})
    report("an operator's write with it: slVelAsse 77 read back by pymodbus (holding 2050), nothing left forced",
           st == 200 and wait_for(lambda: mb.md(SPEED) == 77, 20, 0.02)
           and wait_for(lambda: mb.diag(FORCED) == 0, 20, 0.02),
           f"{st} {body[:200]} {mb.md(SPEED)}")
    st, body = o.req("POST", "/api/write", {"path": "CONFIG0.RES0.AXIS.SLVELASSE", "value": "78"},
                     headers={"Origin": "http://elsewhere.example"})
    report("a write sent by another site's page (its Origin), cookie and token included: 403, nothing written",
           st == 403 and mb.md(SPEED) == 77, f"{st} {body[:200]} {mb.md(SPEED)}")
    o.req("POST", "/api/write", {"path": "CONFIG0.RES0.AXIS.SLVELASSE", "value": str(before)})
    st, body = o.req("POST", "/api/force", "[1, 2]", headers={"Content-Type": "application/json"})
    st2, body2 = o.req("POST", "/api/force", "{not json", headers={"Content-Type": "application/json"})
    st3, body3 = o.req("POST", "/api/write", "x" * 100, headers={"Content-Length": "999999999"})
    st4, _ = o.req("GET", "/api/overview")
    report("bad requests (a JSON list, broken JSON, a body claimed of 1 GB): refused in words, plcweb runs on",
           st == 409 and b"give a variable" in body and st2 == 409 and st3 == 413 and st4 == 200,
           f"{st} {body[:100]} {st2} {body2[:100]} {st3} {body3[:100]} {st4}")
    evil = io.BytesIO()
    with tarfile.open(fileobj=evil, mode="w:gz") as t:
        for name in ("proj/plcrt.ini", "proj/main.st", "../../outside.st"):
            ti = tarfile.TarInfo(name)
            ti.size = 3
            t.addfile(ti, io.BytesIO(b"(**)"[:3]))
    st, body = o.req("POST", "/api/project", evil.getvalue(), headers={"X-Filename": "evil.tar.gz"})
    res = json.loads(body) if st == 200 else {}
    report("an archive with a path leaving the project folder: refused, naming it; nothing written outside",
           st == 200 and res.get("state") == "failed" and "../../outside.st" in res.get("summary", "")
           and not os.path.exists(os.path.join(o.work, "..", "outside.st")), f"{st} {body[:300]}")
    st, body = o.req("POST", "/api/force", {"path": "CONFIG0.RES0.AXIS.SLVELASSE", "value": "12.5"})
    report("a force of 12.5 into a DINT: refused in plctrace's words", st == 409 and b"is not an integer" in body,
           f"{st} {body[:200]}")


def login(drv, wport, user, pw, page="/overview"):
    # the page before goes first: still polling its plcweb, it would meet
    # the cookies' removal with its own way to a log-in page, which can
    # overtake the navigation below (another plcweb's log-in, logged in)
    drv.get("about:blank")
    drv.execute_cdp_cmd("Network.clearBrowserCookies", {})
    drv.get(f"http://127.0.0.1:{wport}{page}")
    wait_for(lambda: f"127.0.0.1:{wport}/login" in drv.current_url, 30, 0.05)
    # the form takes a click once its script handles it (the button is on)
    wait_for(lambda: drv.execute_script(
        "const b = document.getElementById('login-button'); return !!b && !b.disabled"), 60, 0.05)
    drv.find_element(By.ID, "user").send_keys(user)
    drv.find_element(By.ID, "password").send_keys(pw)
    drv.find_element(By.ID, "login-button").click()
    # the page after the form (chromium on a loaded host may take long)
    return wait_for(lambda: f"127.0.0.1:{wport}/" in drv.current_url and "/login" not in drv.current_url
                    and drv.execute_script("return document.body.dataset.ready") == "1", 60, 0.05)


def page_state(drv):
    """Where the browser is, for a failure's message."""
    try:
        return str(drv.execute_script(
            "return {url: location.href, ready: document.body.dataset.ready || null,"
            " watch: localStorage.getItem('plcweb.watch'), text: document.body.innerText.slice(0, 300)}"))
    except Exception as e:
        return f"{drv.current_url} ({e})"


def text(drv, eid):
    try:
        return drv.find_element(By.ID, eid).text
    except Exception:
        return ""


def pages(drv, wport, mb, port, shots, work):
    ok = login(drv, wport, "olga", "olga-secret-1")
    report("log in through the form: the overview loads", ok, drv.current_url)
    c1 = wait_for(lambda: text(drv, "ov-cycles").isdigit() and int(text(drv, "ov-cycles")), 30, 0.05)
    c2 = wait_for(lambda: text(drv, "ov-cycles").isdigit() and int(text(drv, "ov-cycles")) > (c1 or 0)
                  and int(text(drv, "ov-cycles")), 10, 0.05)
    ref = mb.diag(1024)
    report("overview: program, cycles rising live, up to plcrt's own count", "CONFIG0.RES0.AXIS" in
           text(drv, "ov-programs") and c1 and c2 and c2 > c1 and c2 <= ref, f"{c1} {c2} {ref}")
    report("overview: scan period 1000 us, exec and latency figures, clients",
           text(drv, "ov-period_us") == "1000" and text(drv, "ov-exec_min").count("/") == 3
           and int(text(drv, "ov-clients") or 0) >= 2, text(drv, "ov-table"))
    drv.save_screenshot(os.path.join(shots, "web-overview.png"))

    # ---- Variables: search, watch 50, a move, force ----
    drv.get(f"http://127.0.0.1:{wport}/variables")
    wait_for(lambda: drv.execute_script("return document.body.dataset.ready") == "1", 30, 0.05)
    drv.execute_script("localStorage.removeItem('plcweb.watch')")
    drv.find_element(By.ID, "var-search").send_keys("axis.axis.posit")
    row = wait_for(lambda: [r for r in drv.find_elements(By.CSS_SELECTOR, "#var-results tr")
                            if r.find_elements(By.TAG_NAME, "td")[0].text == f"{AX}.POSIT"], 10, 0.05)
    report("search by name finds AXIS.AXIS.POSIT", bool(row))
    if row:
        row[0].find_element(By.CSS_SELECTOR, "button.watch").click()
    # 49 more: the program's numeric variables, as a user would add them
    vs = json.loads(Http_get(drv, wport, "/api/vars?q=CONFIG0.RES0.AXIS."))["vars"]
    mine = (f"{AX}.POSIT", "CONFIG0.RES0.AXIS.SLVELASSE", "CONFIG0.RES0.AXIS.IFSTOP")
    more = [{"path": v["path"], "type": v["type"]} for v in vs if v["path"] not in mine][:47]
    more += [{"path": "CONFIG0.RES0.AXIS.SLVELASSE", "type": "DINT"}, {"path": "CONFIG0.RES0.AXIS.IFSTOP",
                                                                        "type": "BOOL"}]
    drv.execute_script("const w = JSON.parse(localStorage.getItem('plcweb.watch'));"
                       "localStorage.setItem('plcweb.watch', JSON.stringify(w.concat(arguments[0])))", more)
    drv.refresh()
    wait_for(lambda: drv.execute_script("return document.body.dataset.ready") == "1", 30, 0.05)
    rows = {r.get_attribute("data-path") for r in drv.find_elements(By.CSS_SELECTOR, "#watch tbody tr")}
    pos_id = "w-" + f"{AX}.POSIT".replace(".", "_")

    def page_pos():
        try:
            return int(drv.find_element(By.ID, pos_id).find_elements(By.TAG_NAME, "td")[2].text)
        except Exception:
            return None
    wait_for(lambda: page_pos() is not None, 30, 0.05)
    # a move of 3000 Um at 50 % of maxvel (about 4 s), started over Modbus
    p0 = mb.md(POSIT)
    mb.set_md(QUOTA, p0 + 3000)
    mb.set_coil(C_START, True)
    wait_for(lambda: not mb.coil(C_STILL), 20, 0.01)
    mb.set_coil(C_START, False)
    # counted, not timed: 10 refreshes of the list and 5 positions seen
    # while the axis moves (the move lasts about 4 s of PLC time); the rate
    # is a figure shown, not a bound (a loaded host's browser is slower)
    seen, cycles, t0 = [], set(), time.monotonic()
    while time.monotonic() - t0 < 60 and not (len(cycles) >= 10 and len(seen) >= 5) \
            and not (len(seen) and mb.coil(C_STILL)):
        v = page_pos()
        if v is not None and (not seen or seen[-1] != v):
            seen.append(v)
        cycles.add(text(drv, "watch-state"))
        time.sleep(0.02)
    rate = len(cycles) / (time.monotonic() - t0)
    shown = drv.execute_script("return [...document.querySelectorAll('#watch tbody tr')]"
                               ".filter(r => r.cells[2].textContent !== '…').length")
    drv.save_screenshot(os.path.join(shots, "web-variables.png"))
    report(f"watch list of {len(rows)} variables: the position shown changes while the axis moves, rising",
           len(rows) == 50 and len(seen) >= 5 and seen == sorted(seen) and seen[-1] > p0,
           f"{len(rows)} rows, values {seen[:12]}")
    report("all 50 rows show a value; the list refreshes live (10 refreshes seen)",
           shown == 50 and len(cycles) >= 10, f"{shown} rows with a value, {len(cycles)} refreshes, {rate:.1f}/s")
    wait_for(lambda: mb.coil(C_STILL), 15, 0.05)
    final = mb.md(POSIT)
    report("still: the page shows the position pymodbus reads (holding 2128)",
           wait_for(lambda: page_pos() == mb.md(POSIT), 20, 0.05), f"{page_pos()} {final}")

    spd = "w-CONFIG0_RES0_AXIS_SLVELASSE"
    r = drv.find_element(By.ID, spd)
    r.find_element(By.CSS_SELECTOR, "input").send_keys("30")
    r.find_element(By.CSS_SELECTOR, "button.force").click()
    shown = wait_for(lambda: "forced" in drv.find_element(By.ID, spd).get_attribute("class")
                     and drv.find_element(By.ID, spd).find_elements(By.TAG_NAME, "td")[2].text == "30", 10, 0.05)
    lst = subprocess.run([sys.executable, plctrace.__file__, "--port", str(port), "forced"],
                         capture_output=True, text=True).stdout
    report("force slVelAsse 30: the row shows forced and 30; plcrt counts 1 forced (register 1072), "
           "plctrace forced lists it", shown and mb.diag(FORCED) == 1
           and "CONFIG0.RES0.AXIS.SLVELASSE = 30" in lst and mb.md(SPEED) == 30, f"{lst} {mb.diag(FORCED)}")
    drv.save_screenshot(os.path.join(shots, "web-forced.png"))
    r = drv.find_element(By.ID, "w-CONFIG0_RES0_AXIS_IFSTOP")
    r.find_element(By.CSS_SELECTOR, "input").send_keys("maybe")
    r.find_element(By.CSS_SELECTOR, "button.force").click()
    msg = wait_for(lambda: "not a BOOL" in text(drv, "message") and text(drv, "message"), 30, 0.05)
    report("force IFSTOP 'maybe': refused in plctrace's words on the page", msg, text(drv, "message"))
    drv.find_element(By.ID, spd).find_element(By.CSS_SELECTOR, "button.unforce").click()
    report("unforce: the row no longer forced, plcrt counts 0",
           wait_for(lambda: "forced" not in drv.find_element(By.ID, spd).get_attribute("class")
                    and mb.diag(FORCED) == 0, 10, 0.05), mb.diag(FORCED))

    # ---- Axes: the EPICPOS panel, stop during a move ----
    drv.get(f"http://127.0.0.1:{wport}/axes")
    wait_for(lambda: drv.execute_script("return document.body.dataset.ready") == "1", 30, 0.05)
    panel = wait_for(lambda: drv.find_elements(By.CSS_SELECTOR, ".axis"), 30, 0.05)
    ppos = lambda: drv.find_element(By.CSS_SELECTOR, ".axis td.position").text  # noqa: E731
    report("axes: one EPICPOS panel, its position the one pymodbus reads",
           panel and len(panel) == 1 and "EPICPOS" in panel[0].text
           and wait_for(lambda: ppos() == str(mb.md(POSIT)), 20, 0.05), f"{ppos()} {mb.md(POSIT)}")
    p0 = mb.md(POSIT)
    mb.set_md(QUOTA, p0 + 20000)
    mb.set_coil(C_START, True)
    wait_for(lambda: not mb.coil(C_STILL), 20, 0.01)
    mb.set_coil(C_START, False)
    wait_for(lambda: mb.md(POSIT) > p0 + 500, 30, 0.02)
    drv.save_screenshot(os.path.join(shots, "web-axes.png"))
    drv.find_element(By.CSS_SELECTOR, ".axis button.stop").click()
    stopped = wait_for(lambda: mb.coil(C_STILL), 15, 0.05)
    report("axes: Stop during a 20000 Um move: the axis stops short of the quota (pymodbus)",
           stopped and mb.md(POSIT) < p0 + 15000, f"{p0} -> {mb.md(POSIT)}")

    # ---- Trace: capture, plot, CSV, PNG ----
    drv.get(f"http://127.0.0.1:{wport}/trace")
    wait_for(lambda: drv.execute_script("return document.body.dataset.ready") == "1", 30, 0.05)
    wait_for(lambda: json.loads(Http_get(drv, wport, "/api/overview"))["watching"] == 0, 30, 0.1)
    ta = drv.find_element(By.ID, "tr-chans")
    ta.clear()
    ta.send_keys(f"{AX}.SETPT\naxis.axis.posit\naxis.axis.st_still")
    drv.find_element(By.ID, "tr-samples").clear()
    drv.find_element(By.ID, "tr-samples").send_keys("1500")
    drv.find_element(By.ID, "tr-every").clear()
    drv.find_element(By.ID, "tr-every").send_keys("2")
    # armed on the move's start (st_still falls), and confirmed armed
    # before the START: a capture clicked after the START could begin after
    # the move on a loaded host
    drv.execute_script("document.getElementById('tr-kind').value = 'fall'")
    drv.find_element(By.ID, "tr-tvar").send_keys("axis.axis.st_still")
    p0 = mb.md(POSIT)
    mb.set_md(QUOTA, p0 - 1500)
    drv.find_element(By.ID, "tr-capture").click()
    armed = wait_for(lambda: text(drv, "tr-state") == "armed", 30, 0.05)
    # plcweb says armed once plcrt took the ARM, which lands within two
    # cycles (docs/trace.md): three cycles later plcrt looks for the fall
    c0 = mb.diag(1024)
    wait_for(lambda: mb.diag(1024) >= c0 + 3, 20, 0.01)
    mb.set_coil(C_START, True)
    wait_for(lambda: not mb.coil(C_STILL), 20, 0.01)
    mb.set_coil(C_START, False)
    n = wait_for(lambda: drv.execute_script("return window.plcwebPlot && plcwebPlot.series.length"), 30, 0.1)
    series = drv.execute_script("return plcwebPlot.series")
    st, page_csv = Http_get_raw(drv, wport, "/api/trace.csv")
    p = plctrace.Plc("127.0.0.1", port)
    s = p.status()
    data = plctrace.download(p, s)
    p.close()
    ref = os.path.join(work, "plctrace.csv")
    plctrace.write(argparse.Namespace(output=ref, no_plot=True), data, s)
    rows = list(csv.reader(open(ref)))
    seq = json.loads(Http_get(drv, wport, "/api/trace"))["seq"]
    same = n == 3 and s["seq"] == seq and len(rows) == 1501
    bad = []
    for k, sr in enumerate(series if same else []):
        if sr["path"] != rows[0][2 + k]:
            bad.append(("path", sr["path"], rows[0][2 + k]))
        for i, row in enumerate(rows[1:]):
            t = float(row[0])
            if abs(sr["t"][i] - t) > 1e-5 * max(1.0, abs(t)) or float(row[2 + k]) != sr["v"][i]:
                bad.append((sr["path"], i, sr["t"][i], sr["v"][i], row[0], row[2 + k]))
                break
    moving = same and len(set(series[1]["v"])) > 100
    report("trace: the plotted points (time, value, 3 channels x 1500) equal plctrace's CSV of the same capture",
           armed and same and not bad and moving,
           f"armed {armed}, {n} channels, seq {s['seq']}/{seq}, {len(rows)} rows, {bad[:3]}")
    report("trace: the page's CSV download is plctrace's CSV byte for byte",
           st == 200 and page_csv == open(ref, "rb").read(), f"{st} {page_csv[:120]}")
    cv = drv.find_element(By.ID, "tr-plot")
    ActionChains(drv).move_to_element_with_offset(cv, -200, 0).click_and_hold().move_by_offset(150, 0) \
        .release().perform()
    view = drv.execute_script("return plcwebPlot.view")
    ActionChains(drv).move_to_element_with_offset(cv, -100, 0).click().perform()
    ActionChains(drv).move_to_element_with_offset(cv, 0, 0).key_down("\ue008").click().key_up("\ue008").perform()
    cur = drv.execute_script("return plcwebPlot.cursors")
    report("trace: drag zooms on a time span, click and shift-click place cursors A and B with their values",
           view and view[0] < view[1] and view[1] - view[0] < series[0]["t"][-1] - series[0]["t"][0]
           and None not in cur and "B − A" in text(drv, "tr-cursor"), f"{view} {cur} {text(drv, 'tr-cursor')}")
    drv.find_element(By.ID, "tr-diff").click()
    drv.find_element(By.ID, "tr-reset").click()
    report("trace: Zoom out shows the whole capture again, the difference of channels 1 and 2 as a fourth row",
           drv.execute_script("return plcwebPlot.view") is None
           and drv.execute_script("return plcwebPlot.shown().length") == 4)
    drv.save_screenshot(os.path.join(shots, "web-trace.png"))
    drv.find_element(By.ID, "tr-png").click()
    href = drv.find_element(By.ID, "tr-png").get_attribute("href")
    png = base64.b64decode(href.split(",", 1)[1]) if href.startswith("data:image/png;base64,") else b""
    report("trace: the PNG download is the plot as a PNG", png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 5000,
           href[:60])


def Http_get_raw(drv, wport, path):
    h = Http(wport)
    h.cookie = drv.get_cookie("plcweb")["value"]
    return h.req("GET", path)


def Http_get(drv, wport, path):
    return Http_get_raw(drv, wport, path)[1]


def project(drv, wport, work, port, shots):
    drv.get(f"http://127.0.0.1:{wport}/project")
    wait_for(lambda: drv.execute_script("return document.body.dataset.ready") == "1", 30, 0.05)
    bad, good = os.path.join(work, "bad.tar.gz"), os.path.join(work, "good.tar.gz")
    project_archive(bad, port, work, True)
    project_archive(good, port, work, False)
    drv.find_element(By.ID, "pr-file").send_keys(bad)
    drv.find_element(By.ID, "pr-upload").click()
    msgs = wait_for(lambda: [m.text for m in drv.find_elements(By.CSS_SELECTOR, "#pr-messages li")], 60, 0.1)
    report("upload with an ST error: the page shows main.st and its line 9, no switch offered",
           msgs and msgs[0].startswith("main.st:9:") and not drv.find_element(By.ID, "pr-switch").is_displayed(),
           f"{msgs} {text(drv, 'pr-summary')}")
    drv.save_screenshot(os.path.join(shots, "web-project-error.png"))
    drv.find_element(By.ID, "pr-file").clear()
    drv.find_element(By.ID, "pr-file").send_keys(good)
    drv.find_element(By.ID, "pr-upload").click()
    built = wait_for(lambda: text(drv, "pr-summary").startswith("built"), 120, 0.2)
    report("a good upload builds, and the switch is offered", built and
           drv.find_element(By.ID, "pr-switch").is_displayed(), text(drv, "pr-summary"))
    drv.find_element(By.ID, "pr-switch").click()
    sw = wait_for(lambda: "switched" in text(drv, "message"), 60, 0.1)
    drv.get(f"http://127.0.0.1:{wport}/overview")
    prog = wait_for(lambda: "CONFIG0.RES0.WEBTEST" in text(drv, "ov-programs"), 20, 0.1)
    mb = Mb(port)
    n = wait_for(lambda: mb.md(MD) > 0 and mb.md(MD), 30, 0.05)
    report("switch: the new program runs (the overview names CONFIG0.RES0.WEBTEST; its counter at %MD0 "
           "rises, pymodbus)", sw and prog and n and wait_for(lambda: mb.md(MD) > n, 20, 0.01),
           f"{text(drv, 'message')} {text(drv, 'ov-programs')}")


def viewer(drv, wport, shots):
    login(drv, wport, "victor", "victor-secret-1", "/axes")
    wait_for(lambda: drv.find_elements(By.CSS_SELECTOR, "body"), 20, 0.05)
    drv.get(f"http://127.0.0.1:{wport}/variables")
    wait_for(lambda: drv.execute_script("return document.body.dataset.ready") == "1", 30, 0.05)
    btns = [b for b in drv.find_elements(By.CSS_SELECTOR, "button.force, button.write, #unforce-all")
            if b.is_displayed()]
    report("a viewer's page offers no write, force or unforce button", not btns and "viewer" in text(drv, "who"),
           f"{len(btns)} visible")


def throttle(wport):
    h = Http(wport)
    codes = [h.login("olga", "wrong-password")[0] for _ in range(3)]
    t0 = time.monotonic()
    st, body = h.login("olga", "olga-secret-1")
    report("3 wrong passwords: the 4th try, even the right password, is refused with the time to wait",
           codes == [401] * 3 and st == 429 and b"wait" in body, f"{codes} {st} {body[:100]}")
    ok = wait_for(lambda: h.login("olga", "olga-secret-1")[0] == 200, 30, 0.5)
    report("after the wait the right password logs in", ok, f"{time.monotonic() - t0:.1f} s")


def plcrt_gone(wport, svc):
    h = Http(wport)
    h.login("olga", "olga-secret-1")
    svc.plc.stop()
    st, body = h.req("GET", "/api/overview")
    _, vals = h.req("GET", "/api/values?p=CONFIG0.RES0.WEBTEST.N")
    state = wait_for(lambda: "does not answer" in json.loads(h.req("GET", "/api/values?p=CONFIG0.RES0.WEBTEST.N")[1])
                     ["state"], 20, 0.1)
    report("plcrt stopped: the overview and the watch list say plcrt does not answer; plcweb runs on",
           st == 502 and b"does not answer" in body and state and h.req("GET", "/api/session")[0] == 200,
           f"{st} {body[:200]} {vals[:200]}")


def tags_and_backends(drv, plcrt, ini_src, users, work, shots):
    """A plcrt with forcing off, as a project: plcrt.ini with the EPICPOS
    example beside two remote I/O devices (pymodbus servers), and its tag
    list in build/gen (plcrt --tags), which plcweb --config finds. A
    parameter written and Stop pressed go through Modbus; the overview
    names the devices and shows the one killed lost."""
    sys.path.insert(0, os.path.join(HERE, "..", "remoteio"))
    from iopeer import Peers
    proj = os.path.join(work, "proj")
    os.makedirs(os.path.join(proj, "build", "gen"), exist_ok=True)
    port, rack_port, panel_port, wport = free_port(), free_port(), free_port(), free_port()
    devs = "".join(f"[modbus_io.{n}]\nhost = 127.0.0.1\nport = {pt}\nperiod_ms = 20\ntimeout_ms = 100\n"
                   f"reconnect_max_ms = 200\nok = %IX100.{k}\nread = discrete 0 8 %IX{101 + k}.0\n\n"
                   for k, (n, pt) in enumerate((("rack", rack_port), ("panel", panel_port))))
    ini = os.path.join(proj, "plcrt.ini")
    make_ini(ini_src, ini, port, os.path.join(work, "proj.retain"), force=False, backend="sim, modbus_io",
             extra=devs)
    r = subprocess.run([plcrt, "-c", ini, "--tags", os.path.join(proj, "build", "gen")], capture_output=True,
                       text=True)
    report("plcrt --tags writes the tag list of the example beside two remote I/O devices",
           r.returncode == 0 and os.path.exists(os.path.join(proj, "build", "gen", "TAGS.json")),
           r.stdout + r.stderr)
    peers = Peers()
    rack, panel = peers.tcp(rack_port), peers.tcp(panel_port)
    Plcrt(plcrt, ini, work, "proj")
    mb = Mb(port)
    web = subprocess.Popen([sys.executable, PLCWEB, "--users", users, "--port", str(wport), "--plc",
                            f"127.0.0.1:{port}", "--config", ini, "--log", os.path.join(proj, "writes.log")],
                           stdout=open(os.path.join(proj, "plcweb.log"), "w"), stderr=subprocess.STDOUT)
    try:
        wait_for(lambda: socket.socket().connect_ex(("127.0.0.1", wport)) == 0, 15, 0.1)
        wait_for(lambda: mb.coil(C_LOOPON), 20, 0.05)
        # ---- a parameter written with forcing off ----
        logged = login(drv, wport, "olga", "olga-secret-1", "/variables")
        drv.execute_script("localStorage.setItem('plcweb.watch', JSON.stringify(arguments[0]))",
                           [{"path": "CONFIG0.RES0.AXIS.SLVELASSE", "type": "DINT"}])
        drv.get(f"http://127.0.0.1:{wport}/variables")     # the page again, with that watch list
        wait_for(lambda: drv.execute_script("return document.body.dataset.ready") == "1", 30, 0.05)
        rows = wait_for(lambda: drv.find_elements(By.ID, "w-CONFIG0_RES0_AXIS_SLVELASSE"), 30, 0.05)
        if not rows:
            drv.save_screenshot(os.path.join(shots, "web-tags-watch.png"))
            report("forcing off: the watch list's row for slVelAsse on the variables page", False,
                   f"log-in {bool(logged)}, {page_state(drv)}")
            return
        row = rows[0]
        row.find_element(By.CSS_SELECTOR, "input").send_keys("41")
        row.find_element(By.CSS_SELECTOR, "button.write").click()
        said = wait_for(lambda: "Modbus write" in text(drv, "message") and text(drv, "message"), 30, 0.05)
        report("forcing off: write slVelAsse 41 from the page; pymodbus reads 41 (holding 2050), the page says "
               "it went as a Modbus write of its tag, nothing forced", said and "holding 2050" in said
               and wait_for(lambda: mb.md(SPEED) == 41, 20, 0.05) and mb.diag(FORCED) == 0,
               f"{text(drv, 'message')} {mb.md(SPEED)}")
        # ---- an axis stopped with forcing off ----
        drv.get(f"http://127.0.0.1:{wport}/axes")
        wait_for(lambda: drv.execute_script("return document.body.dataset.ready") == "1", 30, 0.05)
        wait_for(lambda: drv.find_elements(By.CSS_SELECTOR, ".axis button.stop"), 30, 0.05)
        p0 = mb.md(POSIT)
        mb.set_md(QUOTA, p0 + 20000)
        mb.set_coil(C_START, True)
        wait_for(lambda: not mb.coil(C_STILL), 20, 0.01)
        mb.set_coil(C_START, False)
        wait_for(lambda: mb.md(POSIT) > p0 + 500, 30, 0.02)
        drv.find_element(By.CSS_SELECTOR, ".axis button.stop").click()
        stopped = wait_for(lambda: mb.coil(C_STILL), 15, 0.05)
        report("forcing off: Stop during a 20000 Um move stops the axis short of the quota (pymodbus), "
               "sent through cSTOP's tag", stopped and mb.md(POSIT) < p0 + 15000
               and "coil 20" in text(drv, "message"), f"{p0} -> {mb.md(POSIT)} {text(drv, 'message')}")

        # ---- a tag list that does not fit the running program is not used ----
        tj = os.path.join(proj, "build", "gen", "TAGS.json")
        good = open(tj).read()
        d = json.loads(good)
        for t in d["tags"]:
            if t["name"] == "CONFIG0.RES0.AXIS.SLVELASSE":
                t["type"] = "INT"           # as in another program
        open(tj, "w").write(json.dumps(d))
        h = Http(wport)
        h.login("olga", "olga-secret-1")
        st, body = h.req("POST", "/api/write", {"path": "slvelasse", "value": "55"})
        report("a tag list whose slVelAsse is of another type: not written there; refused in words, as forcing "
               "is off (pymodbus still reads 41)", st == 409 and b"no Modbus tag" in body and b"allow_force" in body
               and mb.md(SPEED) == 41, f"{st} {body[:300]} {mb.md(SPEED)}")
        open(tj, "w").write(good)

        # ---- the I/O backends: the remote I/O devices in words ----
        drv.get(f"http://127.0.0.1:{wport}/overview")
        wait_for(lambda: drv.execute_script("return document.body.dataset.ready") == "1", 30, 0.05)

        def state(name):
            try:
                return drv.find_element(By.CSS_SELECTOR, f"#ov-backend-1 tr[data-name='{name}'] td.state").text
            except Exception:
                return None
        both = wait_for(lambda: state("rack") == "ok" and state("panel") == "ok", 15, 0.1)
        regs = mb.c.read_input_registers(21000, 2, slave=1).registers     # backend 1: modbus_io
        head = text(drv, "ov-backend-1")
        report("overview: remote I/O devices rack and panel by their names, both ok, '2 of 2 devices ok' as plcrt "
               "counts (input registers 21000-21001)", both and regs == [2, 2] and "2 of 2 devices ok" in head,
               f"{head} {regs}")
        drv.execute_script("document.getElementById('ov-backends').scrollIntoView()")
        drv.save_screenshot(os.path.join(shots, "web-backends.png"))
        peers.stop(rack)
        lost = wait_for(lambda: state("rack") == "lost" and state("panel") == "ok", 15, 0.1)
        regs = mb.c.read_input_registers(21000, 4, slave=1).registers
        head = text(drv, "ov-backend-1")
        report("the rack's server killed: the page shows rack lost, panel ok, a fault counted, as plcrt's "
               "registers say (1 of 2 ok)", lost and regs[1] == 1 and (regs[2] << 16 | regs[3]) >= 1
               and "1 of 2 devices ok" in head, f"{head} {regs}")
        report("the tag list is named on the overview by its path from plcweb's folder, no folder above it",
               "tags from " + os.path.relpath(os.path.join(proj, "build", "gen", "TAGS.json")) in text(drv, "ov-tags"),
               text(drv, "ov-tags"))
        drv.execute_script("document.getElementById('ov-backends').scrollIntoView()")
        drv.save_screenshot(os.path.join(shots, "web-backends-lost.png"))
    finally:
        web.terminate()
        web.wait(10)
        peers.close()


PLCOPEN_STATES = ["Disabled", "Standstill", "Homing", "DiscreteMotion", "ContinuousMotion",
                  "SynchronizedMotion", "Stopping", "ErrorStop"]


def plcopen_axes(drv, wport, port, plcopen, work, shots):
    """Another program on the same port: plcweb reads its variables anew;
    the PLCopen example's axes (docs/examples.md: state of X at %MD10)."""
    ini = os.path.join(work, "plcopen.ini")
    make_ini(plcopen[1], ini, port, os.path.join(work, "plcopen.retain"))
    Plcrt(plcopen[0], ini, work, "plcopen")
    mb = Mb(port)
    drv.get(f"http://127.0.0.1:{wport}/axes")
    panels = wait_for(lambda: len(drv.find_elements(By.CSS_SELECTOR, ".axis")) == 4
                      and drv.find_elements(By.CSS_SELECTOR, ".axis"), 15, 0.2)
    titles = sorted(p.find_element(By.TAG_NAME, "h3").text for p in panels or [])
    report("another program on the port: its axes, PLCopen X and Y and their EPICPOS devices (adapters not twice)",
           titles == ["EPICPOS MC.DRVX.DEV", "EPICPOS MC.DRVY.DEV", "PLCopen MC.AXISX", "PLCopen MC.AXISY"],
           f"{titles} {text(drv, 'axes')[:200]} {text(drv, 'message')}")
    if not panels:
        return
    x = "axis-CONFIG0_RES0_MC_AXISX"
    same = wait_for(lambda: drv.find_element(By.CSS_SELECTOR, f"#{x} td.mode").text
                    == PLCOPEN_STATES[mb.md(MD + 20)], 10, 0.05)
    report("PLCopen X's state by name, the one the example publishes at %MD10 (pymodbus)", same,
           f"{drv.find_element(By.CSS_SELECTOR, f'#{x} td.mode').text} {mb.md(MD + 20)}")
    drv.save_screenshot(os.path.join(shots, "web-axes-plcopen.png"))


def reachable(wport):
    addrs = {"127.0.0.2"}
    try:
        out = subprocess.run(["hostname", "-I"], capture_output=True, text=True).stdout.split()
        addrs |= {x for x in out if ":" not in x}
    except OSError:
        pass
    refused = {}
    for ad in sorted(addrs):
        s = socket.socket()
        s.settimeout(2)
        refused[ad] = s.connect_ex((ad, wport)) != 0
        s.close()
    listen = [line.split()[1] for line in open("/proc/net/tcp").read().splitlines()[1:]
              if line.split()[1].endswith(f":{wport:04X}") and line.split()[3] == "0A"]
    report("by default plcweb listens on 127.0.0.1 alone: other addresses of this machine are refused",
           all(refused.values()) and listen == ["0100007F:%04X" % wport], f"{refused} {listen}")


if __name__ == "__main__":
    sys.exit(main())
