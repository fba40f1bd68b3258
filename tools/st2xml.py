#!/usr/bin/env python3
"""st2xml: Structured Text library -> PLCopen XML (TC6-XML 2.01).

    tools/st2xml.py [-o OUT.xml] [--name NAME] FILE.st...

Reads the declarations of the given ST files (IEC 61131-3 2nd edition, the
dialect matiec accepts) and writes one PLCopen project that the OpenPLC
editor and Beremiz open: every TYPE in <types><dataTypes>, every FUNCTION,
FUNCTION_BLOCK and PROGRAM in <pous> with its interface (variable sections
with their RETAIN / NON_RETAIN / CONSTANT qualifiers, types, initial
values, the comment beside each declaration as its documentation), the
comment before or right after the POU's header as the POU's documentation,
and the body verbatim as ST text, {{ }} C pragmas included.

The one idea: declarations are parsed, bodies are not. A body is the exact
source text between the last END_VAR and END_FUNCTION..., so what the XML
carries compiles to what the ST compiled to. Comments follow stc and matiec's
reading for library code: (* ends at the first *), strings and pragmas
hide comment markers.

Python 3 standard library only (xml.etree). Output is deterministic: the
creation date is SOURCE_DATE_EPOCH if set, else the newest input's mtime.
"""
import argparse
import os
import re
import sys
import textwrap
import time
import xml.etree.ElementTree as ET
from xml.sax.saxutils import escape as xml_escape

NS = "http://www.plcopen.org/xml/tc6_0201"
XHTML = "http://www.w3.org/1999/xhtml"

ELEMENTARY = {
    "BOOL", "BYTE", "WORD", "DWORD", "LWORD", "SINT", "INT", "DINT", "LINT",
    "USINT", "UINT", "UDINT", "ULINT", "REAL", "LREAL", "TIME", "DATE", "DT",
    "TOD",
}
# long spellings matiec accepts, written with TC6's element names
ALIASES = {"DATE_AND_TIME": "DT", "TIME_OF_DAY": "TOD"}

VAR_SECTIONS = {
    "VAR_INPUT": "inputVars", "VAR_OUTPUT": "outputVars",
    "VAR_IN_OUT": "inOutVars", "VAR": "localVars", "VAR_TEMP": "tempVars",
    "VAR_EXTERNAL": "externalVars", "VAR_GLOBAL": "globalVars",
}
QUALIFIERS = {"RETAIN": "retain", "NON_RETAIN": "nonretain",
              "CONSTANT": "constant"}
POU_KINDS = {"FUNCTION": "function", "FUNCTION_BLOCK": "functionBlock",
             "PROGRAM": "program"}


class StError(Exception):
    """A declaration the exporter cannot read: file:line: message."""


# ---------------------------------------------------------------- tokens

TOKEN_RE = re.compile(r"""
    (?P<comment>\(\*.*?\*\))
  | (?P<pragma>\{\{.*?\}\}|\{[^}]*\})
  | (?P<string>'(?:\$.|[^'$])*'|"(?:\$.|[^"$])*")
  | (?P<word>[A-Za-z_][A-Za-z0-9_]*(?:\#[A-Za-z0-9_.:+\-]+)?)
  | (?P<number>[0-9][0-9_]*(?:\#[0-9A-Fa-f_]+|\.[0-9_]+(?:[Ee][+-]?[0-9]+)?
                 |[Ee][+-]?[0-9]+)?)
  | (?P<punct>:=|=>|\.\.|<=|>=|<>|\*\*|[-+*/<>=&:;,.()\[\]\#%])
  | (?P<space>\s+)
  | (?P<other>.)
""", re.S | re.X)


class Tok:
    __slots__ = ("kind", "text", "start", "end", "up")

    def __init__(self, kind, text, start, end):
        self.kind, self.text, self.start, self.end = kind, text, start, end
        self.up = text.upper() if kind == "word" else text

    def __repr__(self):
        return "%s(%r)" % (self.kind, self.text)


def tokens(src, path):
    out = []
    for m in TOKEN_RE.finditer(src):
        kind = m.lastgroup
        if kind == "space":
            continue
        if kind == "other":
            text = m.group()
            raise StError("%s:%d: unexpected %r (unterminated comment, string "
                          "or pragma?)" % (path, src.count("\n", 0, m.start()) + 1, text))
        out.append(Tok(kind, m.group(), m.start(), m.end()))
    return out


def comment_text(tok):
    """The text of a (* *) comment, its continuation lines dedented."""
    body = tok.text[2:-2].strip("\n")
    lines = body.split("\n")
    first = lines[0].strip()
    rest = textwrap.dedent("\n".join(lines[1:])) if len(lines) > 1 else ""
    return (first + ("\n" + rest if rest else "")).strip()


# ---------------------------------------------------------------- parser

class Parser:
    """Reads one file's library elements from its tokens."""

    def __init__(self, src, path):
        self.src, self.path = src, path
        self.toks = tokens(src, path)
        self.i = 0

    # token access: peek and next skip comments; peek moves nothing
    def _ahead(self):
        j = self.i
        while j < len(self.toks) and self.toks[j].kind == "comment":
            j += 1
        return j

    def _skip(self):
        self.i = self._ahead()

    def peek(self):
        j = self._ahead()
        return self.toks[j] if j < len(self.toks) else None

    def next(self):
        j = self._ahead()
        if j >= len(self.toks):
            raise StError("%s: unexpected end of file" % self.path)
        self.i = j + 1
        return self.toks[j]

    def line(self, tok):
        return self.src.count("\n", 0, tok.start) + 1

    def fail(self, tok, msg):
        raise StError("%s:%d: %s" % (self.path, self.line(tok), msg))

    def expect(self, text):
        t = self.next()
        if t.up != text:
            self.fail(t, "expected %s, found %s" % (text, t.text))
        return t

    def name(self):
        t = self.next()
        if t.kind != "word" or "#" in t.text:
            self.fail(t, "expected a name, found %s" % t.text)
        return t.text

    def until(self, stops):
        """Source text up to (not including) the first depth-0 token in stops."""
        depth, first = 0, None
        while True:
            t = self.peek()
            if t is None:
                raise StError("%s: unexpected end of file" % self.path)
            if depth == 0 and t.up in stops:
                break
            if t.text in ("(", "["):
                depth += 1
            elif t.text in (")", "]"):
                depth -= 1
            if first is None:
                first = t
            last = t
            self.next()
        if first is None:
            return ""
        return self.src[first.start:last.end]

    def comments_between(self, a, b):
        return [t for t in self.toks[a:b] if t.kind == "comment"]

    # library elements
    def library(self):
        """List of ('type', dict) and ('pou', dict) in file order."""
        items, mark = [], 0
        while True:
            t = self.peek()
            if t is None:
                break
            lead = self.comments_between(mark, self._ahead())[-1:]
            if t.up == "TYPE":
                self.next()
                for dt in self.type_block():
                    items.append(("type", dt))
            elif t.up in POU_KINDS:
                items.append(("pou", self.pou(lead)))
            elif t.up == "CONFIGURATION":
                self.next()
                while self.next().up != "END_CONFIGURATION":
                    pass
            else:
                self.fail(t, "expected TYPE, FUNCTION, FUNCTION_BLOCK or PROGRAM, found %s" % t.text)
            mark = self.i
        return items

    def type_block(self):
        types = []
        while self.peek().up != "END_TYPE":
            self._skip()
            start = self.i
            name = self.name()
            self.expect(":")
            if self.peek().up == "STRUCT":
                self.next()
                members = []
                while self.peek().up != "END_STRUCT":
                    members.extend(self.declaration(None))
                self.next()
                base, init = {"kind": "struct", "members": members}, None
            elif self.peek().text == "(":
                self.next()
                values = []
                while True:
                    vname = self.name()
                    vval = None
                    if self.peek().text == ":=":
                        self.next()
                        vval = self.until({",", ")"}).strip()
                    values.append((vname, vval))
                    if self.next().text == ")":
                        break
                base = {"kind": "enum", "values": values}
                init = self._init()
            else:
                base = self.type_spec()
                init = self._init()
            end = self.expect(";")
            types.append({"name": name, "base": base, "init": init,
                          "doc": self._trailing_doc(start, end)})
        self.next()
        return types

    def _init(self):
        if self.peek().text == ":=":
            self.next()
            return self.until({";"}).strip()
        return None

    def type_spec(self):
        t = self.next()
        if t.up == "ARRAY":
            self.expect("[")
            dims = []
            while True:
                lo = self.until({".."}).strip()
                self.expect("..")
                hi = self.until({",", "]"}).strip()
                dims.append((lo, hi))
                if self.next().text == "]":
                    break
            self.expect("OF")
            return {"kind": "array", "dims": dims, "base": self.type_spec()}
        if t.up in ("STRING", "WSTRING"):
            length = None
            if self.peek() is not None and self.peek().text in ("[", "("):
                close = "]" if self.next().text == "[" else ")"
                length = self.until({close}).strip()
                self.expect(close)
            return {"kind": t.up.lower(), "length": length}
        if t.kind != "word":
            self.fail(t, "expected a type, found %s" % t.text)
        up = ALIASES.get(t.up, t.up)
        if up in ELEMENTARY:
            if self.peek() is not None and self.peek().text == "(":
                # subrange: INT (lo..hi)
                self.next()
                lo = self.until({".."}).strip()
                self.expect("..")
                hi = self.until({")"}).strip()
                self.expect(")")
                kind = "subrangeUnsigned" if up.startswith("U") or up in ("BYTE", "WORD", "DWORD", "LWORD") \
                    else "subrangeSigned"
                return {"kind": kind, "lo": lo, "hi": hi, "base": {"kind": "elementary", "name": up}}
            return {"kind": "elementary", "name": up}
        return {"kind": "derived", "name": t.text}

    def declaration(self, section):
        """One `a, b [AT %..] : type [:= init];` line: a list of variables."""
        self._skip()
        start = self.i
        names = [self.name()]
        while self.peek().text == ",":
            self.next()
            names.append(self.name())
        address = None
        if self.peek().up == "AT":
            self.next()
            address = self.until({":"}).strip()
        self.expect(":")
        typ = self.type_spec()
        init = self._init()
        end = self.expect(";")
        doc = self._trailing_doc(start, end)
        return [{"name": n, "type": typ, "init": init, "address": address, "doc": doc}
                for n in names]

    def _trailing_doc(self, start, end_tok):
        """Comments inside the declaration or on its line after the ';'."""
        docs = []
        k = self.toks.index(end_tok)
        for t in self.toks[start:k]:
            if t.kind == "comment":
                docs.append(comment_text(t))
        eol = self.src.find("\n", end_tok.end)
        eol = len(self.src) if eol < 0 else eol
        j = k + 1
        while j < len(self.toks) and self.toks[j].kind == "comment" and self.toks[j].start < eol:
            docs.append(comment_text(self.toks[j]))
            j += 1
        return "\n".join(d for d in docs if d) or None

    def pou(self, lead):
        kw = self.next()
        kind = POU_KINDS[kw.up]
        end_kw = "END_" + kw.up
        name = self.name()
        rtype = None
        if kind == "function":
            self.expect(":")
            rtype = self.type_spec()
        # documentation: the comments right after the header, else the
        # comment just before the POU
        hdr_end = self.i
        self._skip()
        docs = [comment_text(c) for c in self.comments_between(hdr_end, self.i)]
        if not docs:
            docs = [comment_text(c) for c in lead]
        body_from = self.toks[self.i - 1].end if self.i > hdr_end else self.toks[hdr_end - 1].end
        sections = []
        while self.peek().up in VAR_SECTIONS:
            sec = self.next()
            quals = {}
            while self.peek().up in QUALIFIERS:
                quals[QUALIFIERS[self.next().up]] = True
            variables = []
            while self.peek().up != "END_VAR":
                variables.extend(self.declaration(sec.up))
            end = self.next()
            sections.append({"kind": VAR_SECTIONS[sec.up], "quals": quals, "vars": variables})
            body_from = end.end
        # the body: verbatim up to END_xxx (pragmas and comments are tokens)
        j = self.i
        while j < len(self.toks) and self.toks[j].up != end_kw:
            if self.toks[j].up in POU_KINDS or self.toks[j].up in ("END_FUNCTION", "END_FUNCTION_BLOCK", "END_PROGRAM"):
                self.fail(self.toks[j], "expected %s, found %s" % (end_kw, self.toks[j].text))
            j += 1
        if j == len(self.toks):
            self.fail(kw, "%s %s has no %s" % (kw.text, name, end_kw))
        body = self.src[body_from:self.toks[j].start]
        self.i = j + 1
        return {"name": name, "kind": kind, "rtype": rtype, "sections": sections,
                "body": tidy_body(body), "doc": "\n\n".join(d for d in docs if d) or None}


def tidy_body(text):
    """Drop the blank lines around the body and its common indentation."""
    lines = text.split("\n")
    # the rest of the END_VAR line (normally empty) stays on the first line
    while lines and not lines[0].strip():
        lines.pop(0)
    while lines and not lines[-1].strip():
        lines.pop()
    return textwrap.dedent("\n".join(l.rstrip() for l in lines))


# ---------------------------------------------------------------- values

def top_level(text):
    """(index, char, depth) for each character of text outside string
    literals; depth counts the open ( and [ before it."""
    depth, quote, escaped = 0, None, False
    for k, ch in enumerate(text):
        if quote:
            if escaped:
                escaped = False
            elif ch == "$":
                escaped = True
            elif ch == quote:
                quote = None
            continue
        if ch in "'\"":
            quote = ch
            continue
        if ch in ")]":
            depth -= 1
        yield k, ch, depth
        if ch in "([":
            depth += 1


def split_top(text, sep=","):
    """Split at the separators outside brackets and strings."""
    parts, start = [], 0
    for k, ch, depth in top_level(text):
        if ch == sep and depth == 0:
            parts.append(text[start:k].strip())
            start = k + 1
    if text[start:].strip():
        parts.append(text[start:].strip())
    return parts


def has_top(text, token):
    """token occurs in text outside brackets and strings."""
    return any(depth == 0 and text.startswith(token, k) for k, _, depth in top_level(text))


def value_element(parent, tag, text):
    """<tag> holding simpleValue, arrayValue or structValue for an ST initialiser."""
    v = ET.SubElement(parent, tag)
    fill_value(v, text)
    return v


def fill_value(v, text):
    text = text.strip()
    if text.startswith("[") and text.endswith("]"):
        av = ET.SubElement(v, q("arrayValue"))
        for item in split_top(text[1:-1]):
            m = re.match(r"^([0-9]+)\s*\((.*)\)$", item, re.S)
            e = ET.SubElement(av, q("value"))
            if m:
                e.set("repetitionValue", m.group(1))
                fill_value(e, m.group(2))
            else:
                fill_value(e, item)
    elif text.startswith("(") and text.endswith(")") and has_top(text[1:-1], ":="):
        sv = ET.SubElement(v, q("structValue"))
        for item in split_top(text[1:-1]):
            member, _, val = item.partition(":=")
            e = ET.SubElement(sv, q("value"), member=member.strip())
            fill_value(e, val)
    else:
        ET.SubElement(v, q("simpleValue"), value=text)


# ---------------------------------------------------------------- XML

def q(tag):
    return "{%s}%s" % (NS, tag)


class Cdata:
    """Collects texts to be written as CDATA sections in place of markers."""

    def __init__(self):
        self.texts = []

    def marker(self, text):
        self.texts.append(text)
        return "\x01CDATA%d\x01" % (len(self.texts) - 1)

    def apply(self, xml):
        def sub(m):
            text = self.texts[int(m.group(1))]
            if "]]>" in text:
                # Beremiz pairs each CDATA start and end with <xhtml:p> by
                # regex, so a split CDATA section would break: escape instead
                return xml_escape(text)
            return "<![CDATA[" + text + "]]>"
        return re.sub("\x01CDATA([0-9]+)\x01", sub, xml)


def formatted(parent, tag, text, cdata):
    """A formattedText element: <tag><xhtml:p><![CDATA[text]]></xhtml:p></tag>."""
    e = ET.SubElement(parent, tag)
    p = ET.SubElement(e, "{%s}p" % XHTML)
    p.text = cdata.marker(text)
    return e


def type_element(parent, tag, typ, cdata):
    e = ET.SubElement(parent, tag)
    add_type(e, typ, cdata)
    return e


def add_type(e, typ, cdata):
    k = typ["kind"]
    if k == "elementary":
        ET.SubElement(e, q(typ["name"]))
    elif k in ("string", "wstring"):
        s = ET.SubElement(e, q(k))
        if typ["length"]:
            s.set("length", typ["length"])
    elif k == "derived":
        ET.SubElement(e, q("derived"), name=typ["name"])
    elif k == "array":
        a = ET.SubElement(e, q("array"))
        for lo, hi in typ["dims"]:
            ET.SubElement(a, q("dimension"), lower=lo, upper=hi)
        type_element(a, q("baseType"), typ["base"], cdata)
    elif k in ("subrangeSigned", "subrangeUnsigned"):
        s = ET.SubElement(e, q(k))
        ET.SubElement(s, q("range"), lower=typ["lo"], upper=typ["hi"])
        type_element(s, q("baseType"), typ["base"], cdata)
    elif k == "enum":
        en = ET.SubElement(e, q("enum"))
        vals = ET.SubElement(en, q("values"))
        for name, val in typ["values"]:
            ve = ET.SubElement(vals, q("value"), name=name)
            if val is not None:
                ve.set("value", val)
    elif k == "struct":
        st = ET.SubElement(e, q("struct"))
        for var in typ["members"]:
            add_variable(st, var, cdata)
    else:
        raise AssertionError(k)


def add_variable(parent, var, cdata):
    v = ET.SubElement(parent, q("variable"), name=var["name"])
    if var.get("address"):
        v.set("address", var["address"])
    type_element(v, q("type"), var["type"], cdata)
    if var["init"] is not None:
        value_element(v, q("initialValue"), var["init"])
    if var["doc"]:
        formatted(v, q("documentation"), var["doc"], cdata)


def project(items, name, stamp):
    cdata = Cdata()
    ET.register_namespace("", NS)
    ET.register_namespace("xhtml", XHTML)
    root = ET.Element(q("project"))
    ET.SubElement(root, q("fileHeader"), companyName=name, productName=name,
                  productVersion="1", creationDateTime=stamp,
                  contentDescription="IEC 61131-3 library exported from Structured Text")
    ch = ET.SubElement(root, q("contentHeader"), name=name, modificationDateTime=stamp)
    ci = ET.SubElement(ch, q("coordinateInfo"))
    for lang in ("fbd", "ld", "sfc"):
        ET.SubElement(ET.SubElement(ci, q(lang)), q("scaling"), x="0", y="0")
    types = ET.SubElement(root, q("types"))
    dts = ET.SubElement(types, q("dataTypes"))
    pous = ET.SubElement(types, q("pous"))
    for what, it in items:
        if what == "type":
            dt = ET.SubElement(dts, q("dataType"), name=it["name"])
            type_element(dt, q("baseType"), it["base"], cdata)
            if it["init"] is not None:
                value_element(dt, q("initialValue"), it["init"])
            if it["doc"]:
                formatted(dt, q("documentation"), it["doc"], cdata)
            continue
        pou = ET.SubElement(pous, q("pou"), name=it["name"], pouType=it["kind"])
        itf = ET.SubElement(pou, q("interface"))
        if it["rtype"] is not None:
            type_element(itf, q("returnType"), it["rtype"], cdata)
        for sec in it["sections"]:
            vl = ET.SubElement(itf, q(sec["kind"]))
            for attr in ("retain", "nonretain", "constant"):
                if sec["quals"].get(attr):
                    vl.set(attr, "true")
            for var in sec["vars"]:
                add_variable(vl, var, cdata)
        body = ET.SubElement(pou, q("body"))
        formatted(body, q("ST"), it["body"], cdata)
        if it["doc"]:
            formatted(pou, q("documentation"), it["doc"], cdata)
    inst = ET.SubElement(root, q("instances"))
    ET.SubElement(inst, q("configurations"))
    ET.indent(root, space="  ")
    xml = ET.tostring(root, encoding="unicode")
    return '<?xml version="1.0" encoding="utf-8"?>\n' + cdata.apply(xml) + "\n"


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("files", nargs="+", metavar="FILE.st")
    ap.add_argument("-o", "--output", help="output file (default: stdout)")
    ap.add_argument("--name", default="library", help="project name in the headers")
    args = ap.parse_args(argv)
    items = []
    try:
        for path in args.files:
            with open(path, encoding="utf-8") as f:
                items += Parser(f.read(), path).library()
    except (StError, OSError) as e:
        print("st2xml: %s" % e, file=sys.stderr)
        return 1
    epoch = os.environ.get("SOURCE_DATE_EPOCH")
    t = int(epoch) if epoch else int(max(os.path.getmtime(p) for p in args.files))
    stamp = time.strftime("%Y-%m-%dT%H:%M:%S", time.gmtime(t))
    xml = project(items, args.name, stamp)
    if args.output:
        tmp = args.output + ".tmp"
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(xml)
        os.replace(tmp, args.output)
    else:
        sys.stdout.write(xml)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
