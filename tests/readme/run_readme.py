#!/usr/bin/env python3
"""The README's trace and forcing lines, run as a reader would against the
demo (examples/epicpos on the simulated axis), on a free port:

    run_readme.py TREE WORKDIR          Prints PASS:/FAIL: lines.

- its plctrace record command, armed before its mbpoll move to 5000 Um,
  captures the whole move: the position leaves its start and the last
  second of samples sits within the block's tolerance (toll 5 Um) of 5000;
  the plot puts set-point and position in one row, the following error in
  the row under them, with the units the library's declarations give;
- its get and watch lines answer;
- forcing: refused by the demo as it is, allowed by the configuration the
  README makes (force, forced, unforce --all)."""
import csv
import os
import re
import shutil
import subprocess
import sys
from importlib.machinery import SourceFileLoader

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from peer import Plcrt, Report, free_port  # noqa: E402

tree, work = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
os.makedirs(work, exist_ok=True)
report = Report("readme")
readme = open(os.path.join(tree, "README.md")).read()
exe = os.path.join(tree, "build", "plc", "epicpos", "plcrt")
trace = os.path.join(tree, "plc_runtime", "plctrace")


def block_after(text):
    """The indented lines of the README block following the paragraph with text."""
    at = readme.index(text)
    m = re.search(r"\n\n((?:    .*\n)+)", readme[at:])
    return m.group(1).replace("\\\n", " ").replace("    ", "", 1)


def lines_of(block):
    return [re.sub(r"\s+#.*$", "", x).strip() for x in block.splitlines() if x.strip()]


def start(ini_text, tag):
    port = free_port()
    cfg = os.path.join(work, tag + ".ini")
    with open(cfg, "w") as f:
        f.write(ini_text.replace("port = 1502", "port = %d" % port)
                .replace("file = build/epicpos.retain", "file = %s" % os.path.join(work, tag + ".retain")))
    return Plcrt(exe, cfg, work, tag), port


def sh(cmd, port, **kw):
    cmd = cmd.replace("plc_runtime/plctrace", "%s %s --port %d" % (sys.executable, trace, port))
    cmd = cmd.replace("-p 1502", "-p %d" % port)
    return subprocess.Popen(["bash", "-c", cmd], cwd=work, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True, **kw)


ini = open(os.path.join(tree, "examples", "epicpos", "epicpos.ini")).read()
plc, port = start(ini, "demo")
try:
    rec = lines_of(block_after("Record a move cycle by cycle"))
    rec = [x for x in rec if x.startswith("plc_runtime/plctrace record")]
    mb = lines_of(block_after("Move the axis from"))
    setup = next(x for x in mb if x.startswith("M="))
    quota = next(x for x in mb if "2048 5000" in x)
    startl = next(x for x in mb if "-r 2 1" in x)
    r = sh(rec[0], port)
    # the START only once plctrace says it is armed (it says so once plcrt
    # looks for the trigger): a stimulus sent after a fixed wait could come
    # before that on a loaded host, and no capture would follow
    head = []
    for line in r.stdout:
        head.append(line)
        if line.startswith("armed"):
            break
    mv = sh("; ".join([setup, quota, startl]), port).communicate(timeout=60)[0]
    out = "".join(head) + r.communicate(timeout=120)[0]
    path = os.path.join(work, "move.csv")
    rows = list(csv.reader(open(path))) if os.path.exists(path) else []
    report("the README's record command captures", r.returncode == 0 and len(rows) == 8001, out[-500:] + mv[-300:])
    if rows:
        h = rows[0]
        pos = [float(x[h.index("CONFIG0.RES0.AXIS.AXIS.POSIT")]) for x in rows[1:]]
        spt = [float(x[h.index("CONFIG0.RES0.AXIS.AXIS.SETPT")]) for x in rows[1:]]
        report("the whole move is in it: from its start to 5000 Um, settled for the last second",
               abs(pos[0] - 5000) > 100 and all(abs(p - 5000) <= 5 for p in pos[-1000:]) and spt[-1] == 5000,
               "first %s, last second %s..%s, set-point at the end %s" % (pos[0], min(pos[-1000:]),
                                                                           max(pos[-1000:]), spt[-1]))
        report("the plot is there", os.path.exists(os.path.join(work, "move.png")), out)
        pt = SourceFileLoader("plctrace", trace).load_module()
        units = pt.declared_units(pt.st_files([]))
        rows_, err = pt.layout(h[2:], units, None, True)
        report("set-point over position in one row (Um), the following error under them",
               rows_[0] == rows_[1] == 1 and err == 2 and rows_[2] == 3 and units.get("SETPT") == "Um"
               and units.get("POSIT") == "Um", "rows %s, error row %s, units %s" % (rows_, err, units))
    for line in lines_of(block_after("Read and watch single")):
        line = line + (" --count 2" if " watch " in line else "")
        o = sh(line, port).communicate(timeout=60)[0]
        report("README: %s" % line, "CONFIG0.RES0.AXIS.AXIS.POSIT = 5000" in o or "POSIT = 5000" in o, o[-300:])
    o = sh("plc_runtime/plctrace force axis.axis.cam TRUE", port)
    o.communicate(timeout=60)
    report("forcing is off in the demo as it is", o.returncode == 1, "")
finally:
    report("the demo stops with status 0", plc.stop() == 0, plc.output()[-300:])

# the README's way to allow forcing
force = lines_of(block_after("Forcing is off in the demo"))
shutil.copytree(os.path.join(tree, "examples"), os.path.join(work, "examples"), dirs_exist_ok=True)
for line in force:
    if line.startswith(("cp ", "printf ")):
        subprocess.run(["bash", "-c", line], cwd=work, check=True)
fini = open(os.path.join(work, "force.ini")).read()
report("the README's force.ini allows forcing", "allow_force = yes" in fini, fini[-200:])
plc, port = start(fini, "force")
try:
    cmd = next(x for x in force if "plctrace force" in x)
    o = sh(cmd, port)
    t = o.communicate(timeout=60)[0]
    f = sh("plc_runtime/plctrace forced", port).communicate(timeout=60)[0]
    u = sh("plc_runtime/plctrace unforce --all", port)
    u.communicate(timeout=60)
    report("README: %s; forced lists it; unforce --all" % cmd,
           o.returncode == 0 and "CONFIG0.RES0.AXIS.AXIS.CAM = 1" in f and u.returncode == 0, t + f)
finally:
    report("the demo with forcing stops with status 0", plc.stop() == 0, plc.output()[-300:])
Plcrt.kill_all()
sys.exit(0 if report.all_passed() else 1)
