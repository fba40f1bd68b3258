#!/usr/bin/env python3
"""Optional local check: Beremiz itself reads an export and writes it back as ST.

    beremiz_check.py BEREMIZ_DIR NAME OUT.xml CHECKDIR      (STC in the environment)

BEREMIZ_DIR is a checkout of https://github.com/beremiz/beremiz (nothing of
it is in this repository); the Python running this needs lxml. Beremiz's
plcopen.LoadProject must load the file without error, and its PLCGenerator
(the code the OpenPLC editor and Beremiz run to build a project) must turn
it into ST that, with the probe check_xml.py left in CHECKDIR/orig/all.st,
compiles with stc to the same VARIABLES.csv, POUS.h and POUS.c as the
original ST. Run by `make check-beremiz` after `make test-xmlexport`; never
part of `make test`.
"""
import os
import subprocess
import sys


def report(ok, what, detail=""):
    print("%s: %s%s" % ("PASS" if ok else "FAIL", what, " (%s)" % detail if detail else ""))
    return ok


def main(argv):
    bdir, name, xml, checkdir = argv
    sys.path.insert(0, bdir)
    import fake_wx  # noqa: F401  Beremiz's stand-in for wx, as its CLI uses
    from plcopen.plcopen import LoadProject
    from plcopen.structures import TypeHierarchy
    import PLCGenerator

    project, error = LoadProject(xml)
    if not report(error is None, "%s: Beremiz loads the export" % name, error or ""):
        return 1
    pous = {p.getname(): p for p in project.getpous()}
    std_blocks = {"TON", "TOF", "TP", "R_TRIG", "F_TRIG", "CTU", "CTD", "CTUD", "SR", "RS"}

    class Controller:
        """What PLCGenerator asks of Beremiz's PLCControler, for a library."""

        def GetBaseType(self, typename, debug=False):
            return typename if typename in TypeHierarchy else None

        def GetBlockType(self, typename, inputs=None):
            if typename in std_blocks or (typename in pous and
                                          pous[typename].getpouType() == "functionBlock"):
                return {"inputs": [], "outputs": [], "type": "functionBlock"}
            return None

        def GetDataTypeInfos(self, tagname):
            return None

        def GetConfigurationExtraVariables(self):
            return []

    errors, warnings = [], []
    program = PLCGenerator.GenerateCurrentProgram(Controller(), project, errors, warnings)
    text = "".join(t for t, _ in program) if isinstance(program, list) else program
    if not report(not errors, "%s: Beremiz generates ST from it" % name,
                  "; ".join(map(str, errors)) or "%d lines" % text.count("\n")):
        return 1
    orig = os.path.join(checkdir, "orig")
    with open(os.path.join(orig, "all.st"), encoding="utf-8") as f:
        probe = f.read().split("\nPROGRAM XPROBE", 1)[1]
    out = os.path.join(checkdir, "beremiz")
    os.makedirs(out, exist_ok=True)
    src = os.path.join(out, "all.st")
    with open(src, "w", encoding="utf-8") as f:
        f.write(text + "\nPROGRAM XPROBE" + probe)
    r = subprocess.run([os.environ.get("STC", "build/stc/stc"), "-T", out, src],
                       capture_output=True, text=True)
    if not report(r.returncode == 0, "%s: Beremiz's ST compiles with stc" % name, r.stderr.strip()):
        return 1
    ok = True
    for n in ("VARIABLES.csv", "POUS.h", "POUS.c"):
        same = open(os.path.join(orig, n)).read() == open(os.path.join(out, n)).read()
        ok &= report(same, "%s: Beremiz's ST gives the same %s" % (name, n),
                     "" if same else "diff %s %s" % (os.path.join(orig, n), os.path.join(out, n)))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
