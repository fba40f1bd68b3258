#!/usr/bin/env python3
"""Follow docs/getting-started.md step by step, so that the page cannot rot.

    run_page.py PAGE TREE WORKDIR

Every fenced block of the page is taken in order, in WORKDIR (an empty
folder, as the page starts from), with PLC set to the source tree:

  ```LANG file=PATH   the block is written to PATH
  ```sh               run with bash -e; it must succeed
  ```sh fails         run; it must fail (a compile error the page shows)
  ```sh wait          run again and again (up to 30 s) until the text block
                      that follows appears in its output
  ```sh background    started and left running (plcrt); the next blocks
                      talk to it
  ```sh setup         what the reader sets up by hand (PLC=...): not run
  ```text             lines the previous sh block must print (spaces
                      compared loosely)
  ```text ctrl-c      Ctrl-C (SIGINT) to the background job: it must end
                      with status 0 and print these lines

Shell variables carry from one block to the next, as in one terminal. The
only liberty taken: the page's Modbus port 1502 becomes a port free now.
After the page: where the simulated axis went (its own position register,
not the program's states), and two messages of plcrt-build the page does
not show: an error in the first user file, a project without plcrt.ini.
Prints PASS:/FAIL: lines (mk/suite.sh)."""
import os
import re
import shlex
import signal
import socket
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from peer import default_signals, free_port  # noqa: E402

page, tree, work = sys.argv[1], os.path.abspath(sys.argv[2]), os.path.abspath(sys.argv[3])
port = free_port()
failed = 0


def report(name, ok, why=""):
    global failed
    print(("PASS: " if ok else "FAIL: ") + name + ("" if ok else ": " + str(why)[-1500:]), flush=True)
    failed += not ok
    return ok


def norm(line):
    return " ".join(line.split())


def shows(out, expected):
    """Every line of expected is a line of out (spaces compared loosely)."""
    lines = {norm(x) for x in out.splitlines()}
    missing = [x for x in expected.splitlines() if norm(x) and norm(x) not in lines]
    return not missing, missing


port_page = port
text = open(page).read().replace("1502", str(port))
blocks = [(m.group(1), m.group(2).strip(), m.group(3))
          for m in re.finditer(r"^```(\w+)([^\n]*)\n(.*?)^```\s*$", text, re.S | re.M)]

os.makedirs(work, exist_ok=True)
envfile = os.path.join(work, ".page-env")
cwdfile = os.path.join(work, ".page-cwd")
with open(cwdfile, "w") as f:
    f.write(work)
# the page is followed as a user would, with stc: nothing of a calling
# make (test-matiec exports COMPILER, BUILD, RESULTS) reaches it
env = {k: v for k, v in os.environ.items()
       if k not in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL", "V", "COMPILER", "BUILD", "RESULTS", "MATIEC_DIR")}
env["PLC"] = tree
with open(envfile, "w") as f:
    f.write("")


def sh(code, timeout=120):
    """Run one block as the next commands typed in the same terminal."""
    cwd = open(cwdfile).read().strip()
    script = (f"set -a\n. {shlex.quote(envfile)}\ncd {shlex.quote(cwd)}\nset -e\n{code}\n"
              f"export -p > {shlex.quote(envfile)}\npwd > {shlex.quote(cwdfile)}\n")
    p = subprocess.run(["bash", "-c", script], env=env, stdin=subprocess.DEVNULL, preexec_fn=default_signals,
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=timeout)
    return p.returncode, p.stdout


bg = None          # the background job: (Popen, log path)
plant = []         # the simulated axis's position (counts = Um) after each wait


def sim_position():
    """Where the plant is, from plcrt's sim backend (input registers 1088,
    docs/modbus.md), not from the program: the page's waits rely on st_toll,
    a state of the block under test."""
    from pymodbus.client import ModbusTcpClient
    c = ModbusTcpClient("127.0.0.1", port=port)
    try:
        c.connect()
        r = c.read_input_registers(1088, 2, slave=1)
        v = r.registers[0] << 16 | r.registers[1]
        return v - (1 << 32) if v & 0x80000000 else v
    except Exception as e:  # noqa: BLE001
        return repr(e)
    finally:
        c.close()
i = 0
while i < len(blocks):
    lang, tag, body = blocks[i]
    nxt = blocks[i + 1] if i + 1 < len(blocks) else None
    expect = nxt[2] if nxt and nxt[0] == "text" and nxt[1] == "" else None
    first = body.strip().splitlines()[0] if body.strip() else ""
    m = re.match(r"file=(\S+)", tag)
    if m:
        path = os.path.join(open(cwdfile).read().strip(), m.group(1))
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "w") as f:
            f.write(body)
        report(f"page block {i}: write {m.group(1)}", True)
    elif lang == "sh" and tag == "setup":
        pass
    elif lang == "sh" and tag in ("", "fails"):
        rc, out = sh(body)
        ok = (rc == 0) if tag == "" else (rc != 0)
        why = f"exit status {rc}: {out}"
        if ok and expect is not None:
            ok, why = shows(out, expect)
            why = f"missing {why} in: {out}"
        report(f"page block {i}: `{first}`" + (" fails as shown" if tag else ""), ok, why)
        if expect is not None:
            i += 1
    elif lang == "sh" and tag == "wait":
        end = time.time() + 30
        while True:
            rc, out = sh(body)
            ok, missing = shows(out, expect or "")
            if (ok and rc == 0) or time.time() > end:
                break
            time.sleep(0.3)
        report(f"page block {i}: `{first}` until it shows {expect.strip()!r}", ok and rc == 0,
               f"exit status {rc}, missing {missing} in: {out}")
        plant.append(sim_position())
        i += 1
    elif lang == "sh" and tag == "background":
        cwd = open(cwdfile).read().strip()
        log = os.path.join(work, "background.log")
        script = f"set -a\n. {shlex.quote(envfile)}\ncd {shlex.quote(cwd)}\n{body}"
        p = subprocess.Popen(["bash", "-c", script], env=env, stdin=subprocess.DEVNULL, preexec_fn=default_signals,
                             stdout=open(log, "w"), stderr=subprocess.STDOUT, start_new_session=True)
        bg = (p, log)
        end, up = time.time() + 60, False
        while time.time() < end and p.poll() is None and not up:
            try:
                socket.create_connection(("127.0.0.1", port), timeout=0.2).close()
                up = True
            except OSError:
                time.sleep(0.2)
        report(f"page block {i}: `{first}` serves Modbus on its port", up,
               f"status {p.poll()}: {open(log).read()}")
    elif lang == "text" and tag == "ctrl-c":
        if not bg:
            report(f"page block {i}: Ctrl-C", False, "no background job to stop")
        else:
            p, log = bg
            os.killpg(p.pid, signal.SIGINT)
            try:
                rc = p.wait(timeout=15)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                rc = p.wait()
            out = open(log).read()
            # where the axis went, from plcrt's own status lines (the page
            # sends it to 3000, then back to 0), not from the block's states
            ok, missing = shows(out, body)
            report(f"page block {i}: Ctrl-C ends plcrt with status 0 and {body.strip()!r}",
                   ok and rc == 0, f"status {rc}, missing {missing} in: {out[-1500:]}")
            bg = None
    else:
        report(f"page block {i}: ```{lang} {tag}", False, "a block this test does not know how to follow")
    i += 1

if bg:
    os.killpg(bg[0].pid, signal.SIGKILL)
    bg[0].wait()

# ---- beyond the page: where the axis went (the page sends it to 3000 Um,
# then back to 0; 1 count = 1 Um; toll 5), where plcrt-build's other
# messages point ----
report("the plant is at 3000 +/- 5 counts after the first move, at 0 +/- 5 after the second",
       len(plant) == 2 and all(isinstance(x, int) for x in plant)
       and abs(plant[0] - 3000) <= 5 and abs(plant[1]) <= 5, plant)

proj = os.path.join(work, "myaxis")
build = [os.path.join(tree, "plcrt-build"), "myaxis"]
axis = os.path.join(proj, "axis.st")
if os.path.exists(axis):
    src = open(axis).read()
    lines = src.splitlines(keepends=True)
    # the line of "go := FALSE;" in the user's first file, found in the text
    n = next(k for k, line in enumerate(lines) if "go := FALSE;" in line)
    lines[n] = lines[n].replace("go := FALSE;", "go := FALS;")
    open(axis, "w").write("".join(lines))
    p = subprocess.run(build, cwd=work, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    open(axis, "w").write(src)
    col = lines[n].index("FALS;") + 1
    want = f"myaxis/axis.st:{n + 1}:{col}: error:"
    report(f"an error in the first user file is reported at {want}", p.returncode == 1 and
           any(x.startswith(want) for x in p.stdout.splitlines()), f"status {p.returncode}: {p.stdout}")
    os.rename(os.path.join(proj, "plcrt.ini"), os.path.join(proj, "other.ini"))
    p = subprocess.run(build, cwd=work, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    os.rename(os.path.join(proj, "other.ini"), os.path.join(proj, "plcrt.ini"))
    report("a project without plcrt.ini: status 2, the message names myaxis/plcrt.ini",
           p.returncode == 2 and "myaxis/plcrt.ini" in p.stdout, f"status {p.returncode}: {p.stdout}")

# ---- with upstream matiec (make test-matiec, MATIEC_DIR set): the same
# project built by plcrt-build COMPILER=matiec, errors in the user's files,
# and the axis moved ----
mdir = os.environ.get("MATIEC_DIR", "")
if mdir and os.path.exists(axis):
    menv = dict(env, COMPILER="matiec", MATIEC_DIR=mdir)

    def mbuild():
        return subprocess.run(build, cwd=work, env=menv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                              text=True, timeout=300)
    cfg = os.path.join(proj, "config.st")
    csrc = open(cfg).read()
    open(cfg, "w").write(csrc.replace(": OneAxis;", ": OneAxes;"))
    p = mbuild()
    open(cfg, "w").write(csrc)
    cl = next(k for k, x in enumerate(csrc.splitlines()) if ": OneAxis;" in x) + 1
    report(f"matiec: an error in the second user file is reported at myaxis/config.st:{cl}",
           p.returncode == 1 and any(x.startswith(f"myaxis/config.st:{cl}") for x in p.stdout.splitlines()),
           p.stdout)
    open(axis, "w").write(src.replace("go := FALSE;", "go := FALS;"))
    p = mbuild()
    open(axis, "w").write(src)
    al = next(k for k, x in enumerate(src.splitlines()) if "go := FALSE;" in x) + 1
    report(f"matiec: an error in the first user file is reported at myaxis/axis.st:{al}",
           p.returncode == 1 and any(x.startswith(f"myaxis/axis.st:{al}-") for x in p.stdout.splitlines()),
           p.stdout)
    p = mbuild()
    report("matiec: the page's project builds into myaxis/build-matiec/plcrt",
           p.returncode == 0 and os.path.exists(os.path.join(proj, "build-matiec", "plcrt")), p.stdout)
    if p.returncode == 0:
        port = free_port()
        ini = os.path.join(proj, "matiec.ini")
        open(ini, "w").write(open(os.path.join(proj, "plcrt.ini")).read().replace("port = 1502", f"port = {port}")
                             .replace(f"port = {port_page}", f"port = {port}"))
        q = subprocess.Popen([os.path.join("build-matiec", "plcrt"), "-c", "matiec.ini"], cwd=proj, preexec_fn=default_signals,
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        from pymodbus.client import ModbusTcpClient
        c = ModbusTcpClient("127.0.0.1", port=port)
        end = time.time() + 30
        while not c.connect() and time.time() < end:
            time.sleep(0.1)

        def cycles():
            r = c.read_input_registers(1024, 2, slave=1)
            return 0 if r.isError() else r.registers[0] << 16 | r.registers[1]
        x0 = sim_position()
        c.write_registers(10000, [0, 1500], slave=1)    # target := 1500 Um
        c.write_coil(10000, True, slave=1)              # go
        # a deadline only; "stays" is 30 PLC cycles later, counted by plcrt,
        # not 0.3 s slept (a loaded host may run few cycles in it)
        end, x = time.time() + 60, None
        while time.time() < end:
            x = sim_position()
            if isinstance(x, int) and abs(x - 1500) <= 5:
                n = cycles()
                end = time.time() + 30
                while cycles() < n + 30 and time.time() < end:
                    time.sleep(0.02)
                x = sim_position()
                break
            time.sleep(0.1)
        c.close()
        q.send_signal(signal.SIGTERM)
        rc = q.wait(timeout=10)
        report(f"matiec: the axis moves from {x0} to 1500 +/- 5 counts and stays; SIGTERM: status 0",
               isinstance(x, int) and abs(x - 1500) <= 5 and rc == 0, f"plant at {x}, status {rc}")

# ---- the build's own lines: one short line per step, V=1 the commands ----
qb = os.path.join(work, "qv")
obj = os.path.join(qb, "c_blocks", "plant.o")
outs = {}
for v in ("0", "1"):
    if os.path.exists(obj):
        os.unlink(obj)
    p = subprocess.run(["make", "--no-print-directory", "-C", tree, f"BUILD={qb}", f"V={v}", obj], env=env,
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    outs[v] = (p.returncode, p.stdout)
report("make: one short line for a compile step (`CC c_blocks/plant.c`)",
       outs["0"][0] == 0 and [norm(x) for x in outs["0"][1].splitlines()] == ["CC c_blocks/plant.c"], outs["0"])
report("make V=1: the compiler's command line instead",
       outs["1"][0] == 0 and any(x.split()[:1] == [os.environ.get("CC", "cc")] and "c_blocks/plant.c" in x
                                 for x in outs["1"][1].splitlines()) and "CC c_blocks" not in outs["1"][1],
       outs["1"])
sys.exit(1 if failed else 0)
