#!/usr/bin/env python3
"""An OpenPLC editor export (tests/editor_export/project, README.md there)
built with plcrt-build as it is, run, and moved over Modbus; a block the
export changes, names declared twice, files whose names put a configuration
first.

    run_export.py TREE WORKDIR

TREE is the source tree (its plcrt-build, its build/ made); WORKDIR an empty
folder. With MATIEC_DIR set, plcrt-build also uses upstream iec2c
(COMPILER=matiec) and the export runs from that build too.
Prints PASS:/FAIL: lines (mk/suite.sh)."""
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from peer import Plcrt, Report, free_port, wait_for  # noqa: E402

tree, work = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
here = os.path.dirname(os.path.abspath(__file__))
report = Report("editor-export")
matiec = os.environ.get("MATIEC_DIR", "")
env = {k: v for k, v in os.environ.items()
       if k not in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL", "COMPILER", "BUILD", "RESULTS", "MATIEC_DIR")}


def build(proj, compiler=""):
    e = dict(env)
    if compiler:
        e.update(COMPILER="matiec", MATIEC_DIR=matiec)
    r = subprocess.run([os.path.join(tree, "plcrt-build"), os.path.relpath(proj, work)], cwd=work, env=e,
                       capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


def project(name, files):
    """A project folder WORK/name with files {name: text}."""
    d = os.path.join(work, name)
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    for n, text in files.items():
        with open(os.path.join(d, n), "w") as f:
            f.write(text)
    return d


export = open(os.path.join(here, "project", "generated_plc.st")).read()
ini = open(os.path.join(here, "project", "plcrt.ini")).read()


def move_axis(exe, proj, what, ini=ini):
    """plcrt moves the simulated axis to 3000 Um when target and go are
    written (docs/getting-started.md's symbols); the plant's own position
    (input registers 1088-1089, docs/modbus.md) says where it went."""
    from pymodbus.client import ModbusTcpClient
    port = free_port()
    cfg = os.path.join(proj, "run.ini")
    with open(cfg, "w") as f:
        f.write(ini.replace("port = 1502", "port = %d" % port)
                   .replace("file = myaxis.retain", "file = %s" % os.path.join(proj, "run.retain")))
    p = Plcrt(exe, cfg, work, what)
    c = ModbusTcpClient("127.0.0.1", port=port)
    try:
        c.connect()

        def dint(addr, fn):
            r = fn(addr, 2, slave=1)
            if r.isError():
                return None
            v = r.registers[0] << 16 | r.registers[1]
            return v - (1 << 32) if v & 0x80000000 else v

        # the program answers (st_still); go waits in it for the loop to close
        ready = wait_for(lambda: (lambda r: not r.isError() and r.bits[0])(
            c.read_coils(10001, 1, slave=1)), 30, 0.05)
        c.write_registers(10000, [0, 3000], slave=1)
        c.write_coil(10000, True, slave=1)
        there = wait_for(lambda: (lambda r: not r.isError() and r.bits[0] and r.bits[1] and
                                  dint(10004, c.read_holding_registers) == 3000)(
            c.read_coils(10001, 2, slave=1)), 60, 0.05)
        plant = dint(1088, c.read_input_registers)
        report("%s: the axis goes to 3000 Um over Modbus" % what,
               ready and there and plant is not None and abs(plant - 3000) <= 5,
               "ready %s, there %s, plant at %s counts; %s" % (ready, there, plant, p.output()[-400:]))
    finally:
        c.close()
        report("%s: plcrt stops with status 0" % what, p.stop() == 0, p.output()[-300:])


# 1. the export as the editor wrote it: built without a warning, and run
proj = project("export", {"generated_plc.st": export, "plcrt.ini": ini})
rc, out = build(proj)
report("export builds as it is", rc == 0, out[-1500:])
report("the library's blocks in it are taken silently", "warning" not in out, out[-1500:])
if rc == 0:
    move_axis(os.path.join(proj, "build", "plcrt"), proj, "export (stc)")

# 2. a block the export changes: its ZLATCH gets an output of its own
zl = re.search(r"FUNCTION_BLOCK ZLATCH\n(.*?)END_FUNCTION_BLOCK", export, re.S)
changed = export.replace(zl.group(0), zl.group(0).replace(
    "    zcount : DINT;\n", "    zcount : DINT;\n    armed : INT := 7;\n", 1))
zl_line = export[:zl.start()].count("\n") + 1
lib_line = next(i + 1 for i, l in enumerate(open(os.path.join(tree, "st/parts/zlatch.st")))
                if l.startswith("FUNCTION_BLOCK ZLATCH"))
proj = project("changed", {"generated_plc.st": changed, "plcrt.ini": ini})
rc, out = build(proj)
warn = [l for l in out.splitlines() if ": warning: " in l]
report("a changed block builds", rc == 0, out[-1500:])
report("one warning names the export's and the library's lines",
       len(warn) == 1 and warn[0].startswith("changed/generated_plc.st:%d:" % zl_line)
       and "'ZLATCH'" in warn[0] and "st/parts/zlatch.st:%d)" % lib_line in warn[0], "\n".join(warn) or out[-800:])
csv = os.path.join(proj, "build", "gen", "VARIABLES.csv")
report("the program uses the export's ZLATCH",
       os.path.exists(csv) and "CONFIG0.RES0.AXIS.ZL.ARMED" in open(csv).read(), csv)

# 3. names declared twice in the user's own files say where the first is
half = "FUNCTION Half : INT\n  VAR_INPUT x : INT; END_VAR\n  Half := x / 2;\nEND_FUNCTION\n"
prog = ("PROGRAM P\n  VAR y AT %QW0 : INT; END_VAR\n  y := Half(8);\nEND_PROGRAM\n"
        "CONFIGURATION C\n  RESOURCE R ON PLC\n    TASK t(INTERVAL := T#10ms, PRIORITY := 0);\n"
        "    PROGRAM p1 WITH t : P;\n  END_RESOURCE\nEND_CONFIGURATION\n")
proj = project("twice", {"a.st": half, "b.st": "\n" + half + prog, "plcrt.ini": "[io]\nbackend = none\n"})
rc, out = build(proj)
report("a name declared in two files: the error names the first",
       rc == 1 and "twice/b.st:2:10: error: duplicate declaration of 'Half' (first declared in twice/a.st:1)" in out,
       out[-800:])
proj = project("twice1", {"a.st": half + "\n" + half + prog, "plcrt.ini": "[io]\nbackend = none\n"})
rc, out = build(proj)
report("a name declared twice in one file: the error gives the first's line",
       rc == 1 and "twice1/a.st:6:10: error: duplicate declaration of 'Half' (first declared at line 1)" in out,
       out[-800:])

# 4. file names that put the configuration first, the program's block last
files = {
    "config.st": "CONFIGURATION Config0\n  RESOURCE Res0 ON PLC\n    TASK main(INTERVAL := T#2ms, PRIORITY := 0);\n"
                 "    PROGRAM axis WITH main : OneAxis;\n  END_RESOURCE\nEND_CONFIGURATION\n",
    "program.st": open(os.path.join(here, "..", "..", "docs", "getting-started.md")).read()
    .split("```st file=myaxis/axis.st\n", 1)[1].split("```", 1)[0]
    .replace("zl : ZLATCH;", "zl : MYLATCH;"),
    "zlatch.st": "(* the project's own latch, used by program.st *)\n" + zl.group(0).replace("ZLATCH", "MYLATCH"),
    "plcrt.ini": ini,
}
proj = project("ordered", files)
rc, out = build(proj)
report("configuration first in name order: builds with stc", rc == 0, out[-800:])
joined = os.path.join(work, "ordered.st")
r = subprocess.run([os.path.join(tree, "build", "stc", "stc"), "--join", joined, "--map", joined + ".map"]
                   + sum((["-L", os.path.join(tree, f)] for f in os.environ["ST_LIB_SRC"].split()), [])
                   + [os.path.join(proj, f) for f in sorted(files) if f.endswith(".st")],
                   capture_output=True, text=True)
text = open(joined).read() if r.returncode == 0 else ""
pos = {k: text.find(k) for k in ("FUNCTION_BLOCK EPICPOS", "FUNCTION_BLOCK MYLATCH",
                                 "PROGRAM OneAxis", "CONFIGURATION Config0")}
report("stc --join: each declaration before its first use",
       r.returncode == 0 and all(v >= 0 for v in pos.values())
       and pos["FUNCTION_BLOCK EPICPOS"] < pos["PROGRAM OneAxis"]
       and pos["FUNCTION_BLOCK MYLATCH"] < pos["PROGRAM OneAxis"] < pos["CONFIGURATION Config0"],
       "%s %s" % (pos, r.stderr[-500:]))
# the map leads a line of the joined file back to its file and line
mp = [l.split(" ", 3) for l in open(joined + ".map").read().splitlines()] if text else []
line = text[:pos["PROGRAM OneAxis"]].count("\n") + 1 if text else 0
hit = [m for m in mp if int(m[0]) <= line <= int(m[1])]
report("stc --join's map leads the program's line back to program.st",
       len(hit) == 1 and hit[0][3].endswith("ordered/program.st")
       and line - int(hit[0][0]) + int(hit[0][2]) == files["program.st"].splitlines().index("PROGRAM OneAxis") + 1,
       str(hit))
r2 = subprocess.run([os.path.join(tree, "build", "stc", "stc"), "-T", os.path.join(work, "joined-gen"), joined],
                    capture_output=True, text=True)
report("the joined file compiles on its own", r2.returncode == 0, r2.stderr[-500:])

# a variable named like a block is no use of it: Outer holds an Inner, and
# Inner's input is called Outer; Inner must still come first
src = os.path.join(work, "names.st")
with open(src, "w") as f:
    f.write("FUNCTION_BLOCK Outer\n  VAR i : Inner; END_VAR\n  i(Outer := 1);\nEND_FUNCTION_BLOCK\n"
            "FUNCTION_BLOCK Inner\n  VAR_INPUT Outer : INT; END_VAR\nEND_FUNCTION_BLOCK\n")
r = subprocess.run([os.path.join(tree, "build", "stc", "stc"), "--join", src + ".out", src], capture_output=True, text=True)
out = open(src + ".out").read() if r.returncode == 0 else ""
report("stc --join: a variable named like a block does not order it",
       0 <= out.find("FUNCTION_BLOCK Inner") < out.find("FUNCTION_BLOCK Outer"), out + r.stderr)

# 5. a configuration without RESOURCE (IEC 61131-3's single resource, as
# matiec takes it): the variables are CONFIG0.AXIS.*, and plcrt finds them
single = dict(files, **{"config.st": "CONFIGURATION Config0\n  TASK main(INTERVAL := T#2ms, PRIORITY := 0);\n"
                                     "  PROGRAM axis WITH main : OneAxis;\nEND_CONFIGURATION\n",
                        "plcrt.ini": ini.replace("CONFIG0.RES0.", "CONFIG0.")})
proj = project("single", single)
rc, out = build(proj)
report("a configuration without RESOURCE builds; plcrt.ini's CONFIG0.AXIS.* symbols are found",
       rc == 0 and "configuration OK (backend sim, 6 Modbus symbols)" in out, out[-800:])
if rc == 0:
    move_axis(os.path.join(proj, "build", "plcrt"), proj, "single resource", single["plcrt.ini"])

# 6. a located variable the image cannot hold (an OpenPLC sample's
# `tempSensor1 AT %IW0.0 : UINT;`): the user's line and what to write
proj = project("located", {
    "hello.st": "PROGRAM Hello\n  VAR\n    tempSensor1 AT %IW0.0 : UINT;\n    far AT %QW2000 : INT;\n"
                "    ok AT %IX0.3 : BOOL;\n  END_VAR\n  far := 1;\nEND_PROGRAM\n"
                "CONFIGURATION Config0\n  RESOURCE Res0 ON PLC\n    TASK t(INTERVAL := T#10ms, PRIORITY := 0);\n"
                "    PROGRAM h WITH t : Hello;\n  END_RESOURCE\nEND_CONFIGURATION\n",
    "plcrt.ini": "[io]\nbackend = none\n"})
rc, out = build(proj)
report("%IW0.0: an error at the user's line saying to write %IW0",
       rc == 1 and "located/hello.st:3:20: error: %IW0.0 is not in plcrt's process image: write %IW0 " in out
       and "static assert" not in out, out[-800:])
report("%QW2000: an error at the user's line giving the image's range",
       "located/hello.st:4:12: error: %QW2000 is not in plcrt's process image: use an address from %QW0 to %QW1023" in out,
       out[-800:])

# 7. upstream iec2c on the same (make test-matiec)
if matiec:
    proj = project("export-matiec", {"generated_plc.st": export, "plcrt.ini": ini})
    rc, out = build(proj, "matiec")
    report("export builds with iec2c", rc == 0, out[-1500:])
    if rc == 0:
        move_axis(os.path.join(proj, "build-matiec", "plcrt"), proj, "export (iec2c)")
    proj = project("ordered-matiec", files)
    rc, out = build(proj, "matiec")
    report("configuration first in name order: builds with iec2c", rc == 0, out[-1500:])

Plcrt.kill_all()
sys.exit(0 if report.all_passed() else 1)
