#!/usr/bin/env python3
"""Checks a PLCopen XML export (tools/st2xml.py) against the ST it came from.

    check_xml.py NAME OUT.xml OUTDIR FILE.st...      (STC in the environment)

The expected side never comes from the exporter's own parser:
  - POUs, their variable sections, qualifiers and variable names: a second,
    grep-level reading of the ST (comments and pragmas blanked by regex,
    VAR ... END_VAR split at ';');
  - variable types, types' members, initial values and RETAIN: what stc
    generated for the original ST plus a probe that instantiates every block,
    program and data type (POUS.h struct members and prototypes, the *_init__
    functions of POUS.c, VARIABLES.csv);
  - bodies: the XML is written back to ST (this file's own writer), the same
    probe appended, compiled with stc, and VARIABLES.csv, POUS.h and POUS.c
    must equal those of the original.
Prints PASS:/FAIL: lines; exit status 1 on any failure.
"""
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET

NS = "http://www.plcopen.org/xml/tc6_0201"
XH = "http://www.w3.org/1999/xhtml"
P = "{%s}" % NS
ELEM = {"BOOL", "BYTE", "WORD", "DWORD", "LWORD", "SINT", "INT", "DINT", "LINT",
        "USINT", "UINT", "UDINT", "ULINT", "REAL", "LREAL", "TIME", "DATE", "DT", "TOD"}
SECTION_OF = {"VAR_INPUT": "inputVars", "VAR_OUTPUT": "outputVars",
              "VAR_IN_OUT": "inOutVars", "VAR": "localVars", "VAR_TEMP": "tempVars",
              "VAR_EXTERNAL": "externalVars"}
ST_OF = {v: k for k, v in SECTION_OF.items()}

failures = 0


def report(ok, name, detail=""):
    global failures
    if not ok:
        failures += 1
    print("%s: %s%s" % ("PASS" if ok else "FAIL", name, (" (%s)" % detail) if detail else ""))


# ------------------------------------------------ the grep-level reading

def blank(src):
    """Comments and pragmas replaced by spaces, strings kept."""
    return re.sub(r"'(?:\$.|[^'$])*'|\(\*.*?\*\)|\{\{.*?\}\}|\{[^}]*\}",
                  lambda m: m.group() if m.group()[0] == "'" else " ", src, flags=re.S)


def grep_reading(files):
    text = "\n".join(blank(open(f, encoding="utf-8").read()) for f in files)
    pous, addresses = [], {}
    for m in re.finditer(r"(?<![\w])(FUNCTION_BLOCK|FUNCTION|PROGRAM)\s+(\w+)(.*?)\bEND_\1\b",
                         text, re.S | re.I):
        kind = {"FUNCTION_BLOCK": "functionBlock", "FUNCTION": "function",
                "PROGRAM": "program"}[m.group(1).upper()]
        sections = []
        for s in re.finditer(r"\b(VAR_INPUT|VAR_OUTPUT|VAR_IN_OUT|VAR_TEMP|VAR_EXTERNAL|VAR)\b"
                             r"((?:\s+(?:RETAIN|NON_RETAIN|CONSTANT)\b)*)(.*?)\bEND_VAR\b",
                             m.group(3), re.S | re.I):
            names = []
            for decl in s.group(3).split(";"):
                if ":" in decl:
                    names += [n.split()[0] for n in decl.split(":")[0].split(",")]
                    at = re.search(r"\bAT\s+(%\S+)", decl.split(":")[0], re.I)
                    if at:
                        addresses[(m.group(2), names[-1])] = at.group(1)
            quals = sorted(q.upper() for q in s.group(2).split())
            sections.append((SECTION_OF[s.group(1).upper()], quals, names))
        pous.append((m.group(2), kind, sections))
    counts = {k: len(re.findall(r"\bEND_%s\b" % k, text, re.I))
              for k in ("FUNCTION_BLOCK", "FUNCTION", "PROGRAM")}
    types = []
    for tb in re.finditer(r"\bTYPE\b(.*?)\bEND_TYPE\b", text, re.S | re.I):
        for t in re.finditer(r"(\w+)\s*:\s*(STRUCT\b.*?\bEND_STRUCT|[^;]*)\s*;", tb.group(1), re.S | re.I):
            types.append(t.group(1))
    return pous, counts, types, addresses


# ------------------------------------------------ the XML side

def xtext(e):
    p = e.find("{%s}p" % XH)
    return p.text or ""


def xml_type(t):
    """(kind, ...) of a <type>/<baseType>/<returnType> element."""
    (c,) = list(t)
    tag = c.tag[len(P):]
    if tag in ELEM:
        return ("elem", tag)
    if tag in ("string", "wstring"):
        return ("string", c.get("length"))
    if tag == "derived":
        return ("derived", c.get("name"))
    if tag == "array":
        dims = [(d.get("lower"), d.get("upper")) for d in c.findall(P + "dimension")]
        return ("array", dims, xml_type(c.find(P + "baseType")))
    if tag in ("subrangeSigned", "subrangeUnsigned"):
        r = c.find(P + "range")
        return ("subrange", r.get("lower"), r.get("upper"), xml_type(c.find(P + "baseType")))
    if tag == "enum":
        return ("enum", [(v.get("name"), v.get("value")) for v in c.find(P + "values")])
    if tag == "struct":
        return ("struct", [xml_var(v) for v in c.findall(P + "variable")])
    raise ValueError(tag)


def xml_value(v):
    (c,) = list(v)
    tag = c.tag[len(P):]
    if tag == "simpleValue":
        return ("simple", c.get("value"))
    if tag == "arrayValue":
        return ("array", [(int(e.get("repetitionValue", "1")), xml_value(e)) for e in c])
    return ("struct", [(e.get("member"), xml_value(e)) for e in c])


def xml_var(v):
    init = v.find(P + "initialValue")
    doc = v.find(P + "documentation")
    return {"name": v.get("name"), "type": xml_type(v.find(P + "type")),
            "init": xml_value(init) if init is not None else None,
            "address": v.get("address"), "doc": xtext(doc) if doc is not None else None}


def read_xml(path):
    root = ET.parse(path).getroot()
    pous, types = [], []
    for dt in root.iter(P + "dataType"):
        init = dt.find(P + "initialValue")
        types.append({"name": dt.get("name"), "type": xml_type(dt.find(P + "baseType")),
                      "init": xml_value(init) if init is not None else None})
    for pou in root.iter(P + "pou"):
        itf = pou.find(P + "interface")
        rt = itf.find(P + "returnType")
        sections = []
        for sec in itf:
            tag = sec.tag[len(P):]
            if tag in ST_OF:
                quals = sorted(q for q, a in (("CONSTANT", "constant"), ("NON_RETAIN", "nonretain"),
                                              ("RETAIN", "retain")) if sec.get(a) == "true")
                sections.append((tag, quals, [xml_var(v) for v in sec.findall(P + "variable")]))
        bodies = pou.findall(P + "body")
        st = bodies[0].find(P + "ST") if len(bodies) == 1 else None
        doc = pou.find(P + "documentation")
        pous.append({"name": pou.get("name"), "kind": pou.get("pouType"),
                     "rtype": xml_type(rt) if rt is not None else None, "sections": sections,
                     "body": xtext(st) if st is not None else None,
                     "doc": xtext(doc) if doc is not None else None})
    return root, pous, types


# ------------------------------------------------ XML back to ST (own writer)

def st_type(t):
    k = t[0]
    if k == "elem":
        return t[1]
    if k == "string":
        return "STRING[%s]" % t[1] if t[1] else "STRING"
    if k == "derived":
        return t[1]
    if k == "array":
        return "ARRAY [%s] OF %s" % (", ".join("%s..%s" % d for d in t[1]), st_type(t[2]))
    if k == "subrange":
        return "%s (%s..%s)" % (st_type(t[3]), t[1], t[2])
    if k == "enum":
        return "(%s)" % ", ".join(n if v is None else "%s := %s" % (n, v) for n, v in t[1])
    raise ValueError(k)


def st_value(v):
    if v[0] == "simple":
        return v[1]
    if v[0] == "array":
        return "[%s]" % ", ".join(st_value(x) if n == 1 else "%d(%s)" % (n, st_value(x)) for n, x in v[1])
    return "(%s)" % ", ".join("%s := %s" % (m, st_value(x)) for m, x in v[1])


def st_decl(var, indent):
    at = " AT %s" % var["address"] if var["address"] else ""
    init = " := %s" % st_value(var["init"]) if var["init"] is not None else ""
    return "%s%s%s : %s%s;\n" % (indent, var["name"], at, st_type(var["type"]), init)


def write_st(pous, types):
    out = []
    if types:
        out.append("TYPE\n")
        for t in types:
            if t["type"][0] == "struct":
                out.append("  %s : STRUCT\n" % t["name"])
                out += [st_decl(m, "    ") for m in t["type"][1]]
                out.append("  END_STRUCT;\n")
            else:
                init = " := %s" % st_value(t["init"]) if t["init"] is not None else ""
                out.append("  %s : %s%s;\n" % (t["name"], st_type(t["type"]), init))
        out.append("END_TYPE\n\n")
    for p in pous:
        kw = {"function": "FUNCTION", "functionBlock": "FUNCTION_BLOCK", "program": "PROGRAM"}[p["kind"]]
        out.append("%s %s%s\n" % (kw, p["name"], " : " + st_type(p["rtype"]) if p["rtype"] else ""))
        for kind, quals, variables in p["sections"]:
            out.append("  %s%s\n" % (ST_OF[kind], "".join(" " + q for q in quals)))
            out += [st_decl(v, "    ") for v in variables]
            out.append("  END_VAR\n")
        out.append(p["body"] + "\n")
        out.append("END_%s\n\n" % kw)
    return "".join(out)


# ------------------------------------------------ stc's output

def probe(fbs, programs, types):
    """A program holding one instance of every block and data type, and a
    configuration running it and every program."""
    s = ["\nPROGRAM XPROBE\n  VAR\n"]
    s += ["    i_%s : %s;\n" % (n, n) for n in fbs]
    s += ["    t_%s : %s;\n" % (n, n) for n in types]
    s += ["    xdummy : BOOL;\n  END_VAR\n  xdummy := NOT xdummy;\nEND_PROGRAM\n\n",
          "CONFIGURATION XCONF\n  RESOURCE XRES ON PLC\n",
          "    TASK xtask(INTERVAL := T#1ms, PRIORITY := 0);\n",
          "    PROGRAM xprobe WITH xtask : XPROBE;\n"]
    s += ["    PROGRAM xp_%s WITH xtask : %s;\n" % (n, n) for n in programs]
    s += ["  END_RESOURCE\nEND_CONFIGURATION\n"]
    return "".join(s)


def stc(src, outdir):
    os.makedirs(outdir, exist_ok=True)
    path = os.path.join(outdir, "all.st")
    with open(path, "w", encoding="utf-8") as f:
        f.write(src)
    r = subprocess.run([os.environ.get("STC", "build/stc/stc"), "-T", outdir, path],
                       capture_output=True, text=True)
    if r.returncode != 0:
        return None, r.stderr
    gen = {}
    for n in ("POUS.h", "POUS.c", "VARIABLES.csv"):
        with open(os.path.join(outdir, n), encoding="utf-8") as f:
            gen[n] = f.read()
    return gen, ""


def c_structs(h):
    """name -> [(C type, member)] for every typedef struct in POUS.h."""
    out = {}
    for m in re.finditer(r"typedef struct (\w+)? ?\{\n(.*?)\} (\w+);", h, re.S):
        # a block instance passed VAR_IN_OUT is a "struct NAME *" member
        out[m.group(3)] = [(t.strip(), n) for t, n in
                           re.findall(r"^\s+(?:struct )?(\w+ ?\*?)\s*(\w+)(?:\[\d+\])?;", m.group(2), re.M)]
    return out


def c_arrays(h):
    return {m.group(3): (m.group(1), int(m.group(2)))
            for m in re.finditer(r"typedef struct \{ (\w+) table\[(\d+)\]; \} (\w+);", h)}


def c_type_of(t):
    """The C type name stc gives an XML type (its documented naming)."""
    k = t[0]
    if k == "elem":
        return t[1]
    if k == "string":
        return "STRING"
    if k == "derived":
        return t[1].upper()
    if k == "array":
        # stc: the size of a dimension from 0, else its bounds (m = minus)
        dims = [str(int(hi) - int(lo) + 1) if int(lo) == 0 else
                "%s_%s" % (lo.replace("-", "m"), hi.replace("-", "m")) for lo, hi in t[1]]
        return "__ARRAY_OF_%s_%s" % (c_type_of(t[2]), "_".join(dims))
    if k == "subrange":
        return c_type_of(t[3])
    raise ValueError(k)


def init_lines(c, func, lhs_prefix):
    """path -> C literal for the assignments of a generated init sequence,
    for-loops over array elements expanded."""
    out = {}
    lines = c.split("\n")
    i = 0
    while i < len(lines):
        ln = lines[i]
        m = re.match(r"\s*for \(LINT (\w+) = (\d+); \1 < (\d+); \1\+\+\) \{", ln)
        if m:
            a = re.match(r"\s*%s([\w.\[\]]+?)\[%s\] = (.*);$" % (re.escape(lhs_prefix), m.group(1)), lines[i + 1])
            for k in range(int(m.group(2)), int(m.group(3))) if a else ():
                out["%s[%d]" % (a.group(1), k)] = a.group(2)
            i += 3
            continue
        a = re.match(r"\s*%s([\w.\[\]]+) = (.*);$" % re.escape(lhs_prefix), ln)
        if a:
            out[a.group(1)] = a.group(2)
        i += 1
    return out


def fb_init(c, name):
    m = re.search(r"void %s_init__\(\w+ \*data__, BOOL retain\) \{\n(.*?)\n\}" % name, c, re.S)
    return init_lines(m.group(1), name, "data__->") if m else {}


def fn_init(c, name, body=False):
    """Initial values and local declarations of a function (or, with body,
    the VAR_TEMP of a block's body function)."""
    pat = r"^void %s_body__\(\w+ \*data__\) \{\n(.*?)\n\}" if body else r"^\w+ %s\([^)]*\) \{\n(.*?)\n\}"
    m = re.search(pat % name, c, re.S | re.M)
    if not m:
        return {}, []
    body = m.group(1)
    pre, _, post = body.partition("BOOL retain = 0;")
    post = post.partition("(void)retain;")[0]   # the initial values end there; the body follows
    locals_ = re.findall(r"^\s+(\w+) (\w+);$", pre, re.M)
    prologue = []
    for ln in post.split("\n"):
        if not re.match(r"^\s*$|^\s+(\(void\)\w+;|[\w.\[\]]+ = (\(\(\w+\)(-?[0-9][\w.+-]*|\{.*\})\)|\w+__\w+);"
                        r"|for \(LINT __stc_k\d+ .*\{|\}|[\w.\[\]]+\[__stc_k\d+\] = .*;)$", ln):
            break
        prologue.append(ln)
    return init_lines("\n".join(prologue), name, ""), [(t, n) for t, n in locals_ if n != "__res"]


# ------------------------------------------------ values

def st_literal(text, ctype):
    """An ST literal as a comparable value (independent of the exporter)."""
    t = text.strip()
    up = t.upper()
    if up in ("TRUE", "FALSE"):
        return 1 if up == "TRUE" else 0
    m = re.match(r"^(?:T|TIME)#(-?)(.*)$", t, re.I)
    if m:
        ns = 0.0
        for num, unit in re.findall(r"([0-9.]+)(ms|us|ns|d|h|m|s)", m.group(2).replace("_", ""), re.I):
            ns += float(num) * {"d": 86400e9, "h": 3600e9, "m": 60e9, "s": 1e9, "ms": 1e6,
                                "us": 1e3, "ns": 1}[unit.lower()]
        ns = -ns if m.group(1) else ns
        return ("time", int(round(ns)))
    if t.startswith("'"):
        s = re.sub(r"\$(.)", lambda x: {"n": "\n", "t": "\t", "'": "'", "$": "$"}.get(x.group(1).lower(), x.group(1)), t[1:-1])
        return ("str", s)
    m = re.match(r"^(\w+)#(.*)$", t)
    if m and m.group(1).isdigit():
        return int(m.group(2).replace("_", ""), int(m.group(1)))
    if m:                                     # INT#5 typed literal
        return st_literal(m.group(2), ctype)
    if re.match(r"^[-+]?[0-9_]+$", t):
        return int(t.replace("_", ""))
    if re.match(r"^[-+]?[0-9_.]+(?:[Ee][-+]?[0-9]+)?$", t):
        return float(t.replace("_", ""))
    return ("enum", up)


def c_literal(lit):
    lit = lit.strip()
    m = re.match(r"^\(\((\w+)\)(.*)\)$", lit)
    if m:
        v = m.group(2).rstrip("LU")
        if m.group(1) == "TIME" or v.startswith("{"):
            n = re.match(r"^\{(-?\d+)L?, (-?\d+)L?\}$", v)
            if n:
                return ("time", int(n.group(1)) * 10 ** 9 + int(n.group(2)))
            s = re.match(r'^\{(\d+), "(.*)"\}$', m.group(2), re.S)
            if s:
                return ("str", s.group(2).encode().decode("unicode_escape"))
        try:
            return int(v)
        except ValueError:
            return float(v)
    if re.match(r"^-?[0-9]+$", lit):
        return int(lit)
    return ("enum", lit.split("__")[-1])


def same(a, b):
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return a == b or abs(a - b) <= 1e-12 * max(abs(a), abs(b))
    return a == b


def zero_of(lit):
    v = c_literal(lit)
    return v in (0, 0.0, ("time", 0), ("str", ""))


def flat_init(var_type, init, path, types_by_name, out):
    """Expand an XML initial value into path -> ST literal text."""
    if init is None:
        return
    k = var_type[0]
    if k == "derived" and var_type[1].upper() in types_by_name:
        t = types_by_name[var_type[1].upper()]["type"]
        if t[0] in ("array", "struct"):
            return flat_init(t, init, path, types_by_name, out)
    if init[0] == "simple":
        out[path] = init[1]
    elif init[0] == "array":
        base = var_type[2]
        k = 0
        for n, v in init[1]:
            for _ in range(n):
                flat_init(base, v, "%s.table[%d]" % (path, k), types_by_name, out)
                k += 1
    elif var_type[0] == "derived" and var_type[1].upper() not in types_by_name:
        # a block instance: its inputs' types are not in this file's types
        for m, v in init[1]:
            flat_init(("block-input",), v, "%s.%s" % (path, m.upper()), types_by_name, out)
    else:
        members = {m["name"].upper(): m for m in (types_by_name[var_type[1].upper()]["type"][1]
                                                   if var_type[0] == "derived" else var_type[1])}
        for m, v in init[1]:
            flat_init(members[m.upper()]["type"], v, "%s.%s" % (path, m.upper()), types_by_name, out)


# ------------------------------------------------ the checks

def main(argv):
    name, xml_path, outdir, files = argv[0], argv[1], argv[2], argv[3:]
    raw = open(xml_path, encoding="utf-8").read()
    try:
        root, xpous, xtypes = read_xml(xml_path)
    except (ET.ParseError, ValueError) as e:
        report(False, "%s: XML parses" % name, str(e))
        return 1

    # structure
    ok = (root.tag == P + "project" and root.find(P + "fileHeader") is not None
          and root.find(P + "contentHeader/" + P + "coordinateInfo") is not None
          and root.find(P + "types/" + P + "dataTypes") is not None
          and root.find(P + "types/" + P + "pous") is not None
          and root.find(P + "instances/" + P + "configurations") is not None
          and all(root.find(P + "fileHeader").get(a) for a in
                  ("companyName", "productName", "productVersion", "creationDateTime")))
    report(ok, "%s: TC6 2.01 project skeleton" % name,
           "project/fileHeader/contentHeader/types/instances in namespace " + NS)
    nbody = sum(1 for p in xpous if p["body"] is not None)
    ncdata = len(re.findall(r"<ST>\s*<xhtml:p><!\[CDATA\[", raw))
    nplain = sum(1 for p in xpous if p["body"] and "]]>" in p["body"])
    report(nbody == len(xpous) and ncdata + nplain == nbody,
           "%s: every POU has one ST body, xhtml:p CDATA" % name,
           "%d bodies, %d in CDATA" % (nbody, ncdata))

    # POUs and sections against the grep-level reading
    gpous, counts, gtypes, gaddr = grep_reading(files)
    got = [(p["name"], p["kind"]) for p in xpous]
    want = [(n, k) for n, k, _ in gpous]
    ends = {"function": counts["FUNCTION"], "functionBlock": counts["FUNCTION_BLOCK"],
            "program": counts["PROGRAM"]}
    report(got == want and all(sum(1 for _, k in want if k == kind) == n for kind, n in ends.items()),
           "%s: POUs and pouType" % name, "%d POUs: %s" % (len(got), ", ".join(n for n, _ in got)))
    xby = {p["name"]: p for p in xpous}
    for pname, kind, gsecs in gpous:
        p = xby.get(pname)
        xsecs = [(k, q, [v["name"] for v in vs]) for k, q, vs in p["sections"]] if p else None
        report(xsecs == gsecs, "%s: %s sections, qualifiers and names" % (name, pname),
               "%d sections, %d variables" % (len(gsecs), sum(len(s[2]) for s in gsecs))
               if xsecs == gsecs else "XML %r, ST %r" % (xsecs, gsecs))
    xaddr = {(p["name"], v["name"]): v["address"] for p in xpous
             for _, _, vs in p["sections"] for v in vs if v["address"]}
    report(xaddr == gaddr, "%s: located variables' addresses" % name,
           "%d located" % len(gaddr) if xaddr == gaddr else "XML %r, ST %r" % (xaddr, gaddr))
    report([t["name"] for t in xtypes] == gtypes, "%s: data types" % name,
           ", ".join(gtypes) or "none")

    # documentation: each POU's text is a comment of the source
    norm = lambda s: " ".join(s.split())
    srcnorm = norm(" ".join(open(f, encoding="utf-8").read() for f in files))
    bad = [p["name"] for p in xpous if not p["doc"] or norm(p["doc"]) not in srcnorm]
    report(not bad, "%s: POU documentation from the leading comment" % name,
           "missing or not in the source: " + ", ".join(bad) if bad else "%d POUs" % len(xpous))

    # stc: the original plus the probe
    fbs = [n for n, k, _ in gpous if k == "functionBlock"]
    progs = [n for n, k, _ in gpous if k == "program"]
    src = "".join(open(f, encoding="utf-8").read() + "\n" for f in files)
    pr = probe(fbs, progs, gtypes)
    gen, err = stc(src + pr, os.path.join(outdir, "orig"))
    if gen is None:
        report(False, "%s: original ST compiles with stc" % name, err.strip())
        return 1
    h, c = gen["POUS.h"], gen["POUS.c"]
    structs, arrays = c_structs(h), c_arrays(h)
    types_by_name = {t["name"].upper(): t for t in xtypes}
    nvars = ninit = 0
    for p in xpous:
        variables = [v for _, _, vs in p["sections"] for v in vs]
        temps = [v for k, _, vs in p["sections"] if k == "tempVars" for v in vs]
        # VAR_IN_OUT and located variables are pointers in stc's structs
        ptr = {v["name"] for k, _, vs in p["sections"] for v in vs
               if k == "inOutVars" or v["address"]
               or (k == "outputVars" and p["kind"] == "function")}
        in_struct = variables if p["kind"] == "function" else [v for v in variables if v not in temps]
        expect_members = [(c_type_of(v["type"]) + (" *" if v["name"] in ptr else ""),
                           v["name"].upper()) for v in in_struct]
        if p["kind"] == "function":
            m = re.search(r"^(\w+) %s\(([^)]*)\);" % p["name"].upper(), h, re.M)
            args = [] if not m or m.group(2) in ("", "void") else \
                [(t + (" *" if star else ""), n) for t, star, n in
                 re.findall(r"(\w+)\s*(\*?)\s*(\w+)", m.group(2))]
            inits, locs = fn_init(c, p["name"].upper())
            members = args + locs
            rt_ok = m is not None and m.group(1) == c_type_of(p["rtype"])
            report(rt_ok, "%s: %s returnType" % (name, p["name"]),
                   "XML %s, C %s" % (c_type_of(p["rtype"]), m.group(1) if m else "none"))
        else:
            members = structs.get(p["name"].upper(), [])
            inits = fb_init(c, p["name"].upper())
            tinits, tlocs = fn_init(c, p["name"].upper(), body=True)
            want_t = [(c_type_of(v["type"]), v["name"].upper()) for v in temps]
            report(tlocs == want_t, "%s: %s VAR_TEMP in the body" % (name, p["name"]),
                   "%d variables" % len(tlocs) if tlocs == want_t else "XML %r, stc %r" % (want_t, tlocs))
            inits.update(tinits)
        members = [(t.replace(" *", " *").strip(), n) for t, n in members]
        expect_members = [(t.strip(), n) for t, n in expect_members]
        report(members == expect_members, "%s: %s variable names and types" % (name, p["name"]),
               "%d variables" % len(members) if members == expect_members
               else "XML %r, stc %r" % (expect_members, members))
        nvars += len(variables)
        # initial values: given ones equal stc's, absent ones are zero
        inputs = [v for k, _, vs in p["sections"] if k == "inputVars" for v in vs]
        bad = []
        for v in variables:
            vt = v["type"]
            if p["kind"] == "function" and v in inputs:
                continue    # a function's input defaults live at the call sites
            if v["address"]:
                continue    # located: a pointer into the process image
            flat = {}
            flat_init(vt, v["init"], v["name"].upper(), types_by_name, flat)
            for path, lit in flat.items():
                ninit += 1
                if path not in inits or not same(st_literal(lit, None), c_literal(inits[path])):
                    bad.append("%s: XML %s, stc %s" % (path, lit, inits.get(path)))
            if v["init"] is None and vt[0] in ("elem", "string") and v["name"].upper() in inits \
                    and not zero_of(inits[v["name"].upper()]):
                bad.append("%s: no XML value, stc %s" % (v["name"], inits[v["name"].upper()]))
        report(not bad, "%s: %s initial values" % (name, p["name"]), "; ".join(bad) if bad else
               "%d given" % sum(1 for v in variables if v["init"] is not None))
    # RETAIN / NON_RETAIN: VARIABLES.csv's retain column of the probe instances
    csv = [r.split(";") for r in gen["VARIABLES.csv"].split("\n") if r.count(";") >= 7]
    retain = {r[2].upper(): r[6] for r in csv}
    bad, nret = [], 0
    for p in xpous:
        inst = ("XCONF.XRES.XPROBE.I_%s." % p["name"].upper() if p["kind"] == "functionBlock"
                else "XCONF.XRES.XP_%s." % p["name"].upper())
        for k, quals, vs in p["sections"]:
            for v in vs:
                key = inst + v["name"].upper()
                if key in retain:
                    nret += 1
                    if retain[key] != ("1" if "RETAIN" in quals else "0"):
                        bad.append("%s retain %s" % (key, retain[key]))
    report(not bad, "%s: retain attributes match VARIABLES.csv" % name,
           "; ".join(bad) if bad else "%d variables" % nret)
    # data types against POUS.h and the probe's instances
    probe_init = fb_init(c, "XPROBE")
    for t in xtypes:
        tn = t["name"].upper()
        k = t["type"][0]
        if k == "struct":
            want = [(c_type_of(m["type"]), m["name"].upper()) for m in t["type"][1]]
            ok, got = structs.get(tn) == want, structs.get(tn)
        elif k == "enum":
            m = re.search(r"typedef enum \{\n(.*?)\} %s;" % tn, h, re.S)
            got = re.findall(r"%s__(\w+)" % tn, m.group(1)) if m else None
            ok = got == [n.upper() for n, _ in t["type"][1]]
        elif k == "array":
            got = arrays.get(tn)
            size = 1
            for lo, hi in t["type"][1]:
                size *= int(hi) - int(lo) + 1
            ok = got == (c_type_of(t["type"][2]), size)
        else:
            m = re.search(r"typedef (\w+) %s;" % tn, h)
            got = m.group(1) if m else None
            ok = got == c_type_of(t["type"])
        flat, bad = {}, []
        if k == "struct":
            for mvar in t["type"][1]:
                flat_init(mvar["type"], mvar["init"], "T_%s.%s" % (tn, mvar["name"].upper()), types_by_name, flat)
        else:
            flat_init(("derived", t["name"]), t["init"], "T_" + tn, types_by_name, flat)
        for path, lit in flat.items():
            ninit += 1
            if path not in probe_init or not same(st_literal(lit, None), c_literal(probe_init[path])):
                bad.append("%s: XML %s, stc %s" % (path, lit, probe_init.get(path)))
        report(ok and not bad, "%s: type %s (%s)" % (name, t["name"], k),
               "; ".join(bad) if bad else ("stc: %r" % (got,) if not ok else "members and initial values"))

    # bodies: XML -> ST (own writer) -> stc gives the same output
    back = write_st(xpous, xtypes)
    with open(os.path.join(outdir, "roundtrip.st"), "w", encoding="utf-8") as f:
        f.write(back)
    gen2, err = stc(back + pr, os.path.join(outdir, "back"))
    if gen2 is None:
        report(False, "%s: ST written back from the XML compiles with stc" % name, err.strip())
    else:
        for n in ("VARIABLES.csv", "POUS.h", "POUS.c"):
            report(gen2[n] == gen[n], "%s: round trip gives the same %s" % (name, n),
                   "%d lines" % gen[n].count("\n") if gen2[n] == gen[n] else
                   "diff %s %s" % (os.path.join(outdir, "orig", n), os.path.join(outdir, "back", n)))
    print("%s: %d POUs, %d types, %d variables, %d initial values checked"
          % (name, len(xpous), len(xtypes), nvars, ninit))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
