"""plclink: plcweb's side of a running plcrt, over its Modbus TCP port alone.

It offers what the pages show and do: the diagnostics (input registers from
1024, docs/modbus.md), the program's variable table, live values of any
variable by name, write, force and unforce, the axes found in the table, and
trace captures (the register block of docs/trace.md).

The one idea: plcrt gives values of arbitrary program variables only through
its trace, so a watcher thread takes a one-sample capture of the union of
what every browser watches, 20 times a second, claiming the trace for a few
milliseconds and releasing it at once (plctrace or another client can claim
it in between). Every value of one capture comes from the same cycle. The
protocol code is plctrace's own (plc_runtime/plctrace), imported, not copied.
"""
import importlib.machinery
import logging
import importlib.util
import json
import os
import shutil
import socket
import struct
import threading
import time

HERE = os.path.dirname(os.path.realpath(__file__))
log = logging.getLogger("plcweb")
logging.getLogger("pymodbus").setLevel(logging.CRITICAL)   # plcweb says it once, in words


def _load_plctrace():
    """plctrace as a module: beside plcweb in the source tree, or on PATH."""
    for path in (os.environ.get("PLCTRACE"), os.path.join(HERE, "..", "plc_runtime", "plctrace"),
                 shutil.which("plctrace")):
        if path and os.path.isfile(path):
            loader = importlib.machinery.SourceFileLoader("plctrace", path)
            spec = importlib.util.spec_from_loader("plctrace", loader)
            mod = importlib.util.module_from_spec(spec)
            loader.exec_module(mod)
            return mod
    raise SystemExit("plcweb: plctrace not found (plc_runtime/plctrace, or set PLCTRACE=path)")


plctrace = _load_plctrace()
Refused = plctrace.Refused
TYPES = plctrace.TYPES

DIAG = 1024
# diagnostics: name -> register offset from 1024 (32-bit values)
DIAG_NAMES = {"cycles": 0, "overruns": 2, "skipped": 4, "exec_min": 6, "exec_mean": 8, "exec_max": 10,
              "exec_p99": 12, "lat_min": 14, "lat_mean": 16, "lat_max": 18, "lat_p99": 20, "period_us": 22,
              "clients": 24, "refused": 26, "requests": 28, "exceptions": 30, "retain_saves": 32,
              "retain_failures": 34, "io_errors": 36, "uptime_s": 38, "overruns_own": 40,
              "clients_closed_idle": 42, "clients_closed_fault": 44, "exchange_max": 46, "forced": 48}

# Axis kinds: the members (upper case, after the instance's path) that show a
# kind's instance, then what each panel field is. A field may be a pair
# (a, b): a - b. stop/reset: a BOOL command acting on its rising edge.
AXIS_KINDS = [
    ("EPICPOS", {"POSIT", "SETPT", "FOLTERR", "ST_STILL", "ST_EMRG", "DAC"},
     {"state": ["ST_INIT", "ST_LOOPON", "ST_STILL", "ST_TOLL", "ST_EMRG", "ST_FOLLER", "ST_REGOFF", "ST_PRSOK"],
      "position": "POSIT", "setpoint": "SETPT", "folerr": "FOLTERR", "speed": "VEL", "output": "DAC",
      "errors": ["PARERR", "REFCODE", "REFCNT"], "stop": "STOP", "reset": "RESUME"}),
    ("APOSS", {"APOS", "CPOS", "FE", "ERRNUM", "MODE", "DAC"},
     {"state": ["MOTOR", "BUSY", "INPOS", "HOMED", "ERROR"], "mode": "MODE",
      "position": "APOS", "setpoint": "CPOS", "folerr": "FE", "speed": "CVELQ", "output": "DAC",
      "errors": ["ERRNUM", "PARERR", "REFCODE"], "stop": "STOP", "reset": "ERRCLR"}),
    ("PLCopen", {"STATE", "POS", "CMDPOS", "AXISERR", "POWERED", "CMDVEL"},
     {"state": ["POWERED", "HOMED"], "mode": "STATE",
      "position": "POS", "setpoint": "CMDPOS", "folerr": ("CMDPOS", "POS"), "speed": "VEL", "output": None,
      "errors": ["AXISERR", "POWERR"], "stop": None, "reset": None}),
]


def u32(r, i):
    return r[i] << 16 | r[i + 1]


class Link:
    """One Modbus connection to plcrt, shared by plcweb's threads under a lock,
    and the watcher that samples watched variables."""

    def __init__(self, host, port, rate=20.0, tags=None, config=None):
        self.host, self.port, self.rate = host, port, rate
        self.tags_path, self.tags, self.tags_key = tags, {}, None
        self.config = config
        self.backends_cfg = read_backends(config) if config else None
        self.lock = threading.RLock()       # the connection
        self.trace_lock = threading.Lock()  # plcweb's own use of the trace
        self.p = None
        self.vars, self.by_path, self.table_key, self.table_time = [], {}, None, 0.0
        self.generation = 0                 # counts the variable tables read: a new program
        self.diag_cache, self.diag_time = None, 0.0
        self.wanted = {}                    # path -> last time a browser asked for it
        self.values, self.value_cycle, self.value_time = {}, None, 0.0
        self.forced, self.watch_state, self.round_ms, self.logged_state = {}, "starting", 0.0, "ok"
        self.capture = {"state": "idle"}
        self.stop_ev = threading.Event()
        threading.Thread(target=self._watcher, daemon=True, name="watcher").start()

    # ---- the connection ----
    def plc(self):
        if self.p is None:
            try:
                self.p = plctrace.Plc(self.host, self.port)
                self.table_time = 0.0           # a new connection: perhaps another program
            except SystemExit as e:
                if "cannot connect" in str(e):
                    raise Refused(f"plcrt at {self.host}:{self.port} does not answer: is it running, on this "
                                  "port (plcweb --plc HOST:PORT)?") from None
                raise Refused(str(e).replace("plctrace: ", "")) from None
        return self.p

    def drop(self):
        if self.p is not None:
            try:
                self.p.close()
            except Exception:
                pass
            self.p = None

    def call(self, fn):
        """fn(plc) under the lock; a broken connection is dropped and reported."""
        with self.lock:
            try:
                return fn(self.plc())
            except Refused as e:
                if "exception None" in str(e) or "Modbus Error" in str(e):    # no reply: not a refusal
                    self.drop()
                    raise Refused(f"plcrt at {self.host}:{self.port} does not answer: is it running?") from None
                raise
            except (OSError, AttributeError, struct.error) as e:
                self.drop()
                raise Refused(f"plcrt at {self.host}:{self.port} does not answer ({e})") from None
            except Exception as e:   # pymodbus: connection errors of its own
                if type(e).__module__.startswith("pymodbus"):
                    self.drop()
                    raise Refused(f"plcrt at {self.host}:{self.port} does not answer ({e})") from None
                raise

    # ---- diagnostics ----
    def diagnostics(self):
        """The diagnostics, the trace block's status and the backend's registers;
        read at most every 0.1 s whatever the number of browsers."""
        now = time.monotonic()
        if self.diag_cache and now - self.diag_time < 0.1:
            return self.diag_cache

        def read(p):
            r = p.c.read_input_registers(DIAG, 50, slave=1)
            if r.isError():
                raise Refused(f"diagnostics: exception {getattr(r, 'exception_code', None)}: {r}")
            b = p.c.read_input_registers(1088, 64, slave=1)
            return r.registers, (b.registers if not b.isError() else []), p.status()
        def read_blocks(p):
            out = []
            for k in range(len(self.backends_cfg or [])):
                r = p.c.read_input_registers(20000 + 1000 * k, 120, slave=1)
                out.append(r.registers if not r.isError() else None)
            return out
        regs, backend, st = self.call(read)
        blocks = self.call(read_blocks)
        d = {k: u32(regs, o) for k, o in DIAG_NAMES.items()}
        d["overruns_late"] = d["overruns"] - d["overruns_own"]
        d["period_ns"] = st["period_ns"]
        d["force_allowed"] = bool(st["force_allowed"])
        d["nvars"] = st["nvars"]
        d["trace_state"] = ["idle", "armed", "triggered", "waiting for a free buffer"][min(st["state"], 3)]
        d["trace_owned"] = bool(st["owned"])
        axes = []
        for k in range(0, min(len(backend), 32), 4):
            pos = struct.unpack(">i", struct.pack(">I", u32(backend, k)))[0]
            spd = struct.unpack(">i", struct.pack(">I", u32(backend, k + 2)))[0]
            axes.append({"axis": k // 4, "position": pos, "speed": spd})
        d["backend"] = axes
        d["backends"] = [decode_backend(kind, names, regs) for (kind, names), regs in
                         zip(self.backends_cfg or [], blocks)]
        d["backends_known"] = self.backends_cfg is not None
        d["tags"] = self.tags_state()
        self.table()
        d["programs"] = sorted({".".join(v["path"].split(".")[:3]) for v in self.vars if v["path"].count(".") >= 2})
        d["watch_state"] = self.watch_state
        d["watching"] = len(self.wanted)
        d["watch_round_ms"] = round(self.round_ms, 1)
        self.diag_cache, self.diag_time = d, now
        return d

    # ---- the variable table ----
    def table(self):
        """The program's variables [(path, type name, area)], read once per
        program (again when plcrt restarts or the count changes: looked at
        once a second)."""
        if self.table_key and time.monotonic() - self.table_time < 1.0:
            return self.vars
        self.table_time = time.monotonic()

        def key(p):
            st = p.status()
            r = p.c.read_input_registers(DIAG + 38, 2, slave=1)
            return st["nvars"], (u32(r.registers, 0) if not r.isError() else 0)
        nvars, up = self.call(key)
        k = (nvars, up)
        if self.table_key and self.table_key[0] == nvars and up >= self.table_key[1]:
            self.table_key = k
            return self.vars

        def read(p):
            wins = p.windows([(plctrace.W_VAR, i, plctrace.WIN_N) for i in range(nvars)])
            return [{"index": i, "type": TYPES.get(w[0], ("-",))[0], "tcode": w[0], "size": w[1],
                     "area": ["internal", "input", "output"][w[2] & 0xFF] if (w[2] & 0xFF) < 3 else "?",
                     "path": plctrace.text_of_regs(w[3:])} for i, w in enumerate(wins)]
        self.vars = self.call(read)
        self.by_path = {v["path"].upper(): v for v in self.vars}
        self.table_key = k
        self.generation += 1
        return self.vars

    def resolve(self, path):
        """A variable by its full path or unique tail, as plcrt's LOOKUP does."""
        if not path.strip():
            raise Refused("give a variable's path (or its unique tail, e.g. axis.posit)")
        self.table()
        v = self.by_path.get(path.upper())
        if v:
            return v
        tail = "." + path.upper()
        hits = [v for k, v in self.by_path.items() if k.endswith(tail)]
        if len(hits) == 1:
            return hits[0]
        if not hits:
            raise Refused(f"{path}: no such variable")
        raise Refused(f"{path}: ambiguous, {len(hits)} variables end with it (give more of the path)")

    def search(self, text, limit=200):
        t = text.upper().strip()
        out = [v for v in self.table() if t in v["path"].upper() and v["tcode"] in TYPES]
        return out[:limit], len(out)

    # ---- live values ----
    def watch(self, paths):
        """Values of paths (full paths), sampled by the watcher; asking for a
        path keeps it watched for 3 s."""
        now = time.monotonic()
        for p in paths:
            self.wanted[p.upper()] = now
        return {"values": {p: self.values.get(p.upper()) for p in paths},
                "forced": {p: self.forced.get(p.upper()) for p in paths},
                "cycle": self.value_cycle, "age_ms": round((now - self.value_time) * 1000) if self.value_time else None,
                "state": self.watch_state, "program": self.generation}

    def _watcher(self):
        while not self.stop_ev.is_set():
            t0 = time.monotonic()
            try:
                self._watch_round(t0)
            except Refused as e:
                self.watch_state = str(e)
            except Exception as e:     # never let the thread die
                self.watch_state = f"watcher: {type(e).__name__}: {e}"
                self.drop()
            if self.watch_state != self.logged_state:      # said once, not 20 times a second
                log.info("watch: %s", self.watch_state)
                self.logged_state = self.watch_state
            self.stop_ev.wait(max(0.0, 1.0 / self.rate - (time.monotonic() - t0)))

    def _watch_round(self, now):
        for p, t in list(self.wanted.items()):
            if now - t > 3:
                del self.wanted[p]
        self.table()
        self.forced = {path.upper(): value for path, value, _ in self.call(plctrace.forced_list)}
        want = [self.by_path[p] for p in self.wanted if p in self.by_path and self.by_path[p]["tcode"] in TYPES]
        if not want:
            self.watch_state = "ok"
            return
        if not self.trace_lock.acquire(blocking=False):
            self.watch_state = "paused while a trace capture of this page runs"
            return
        try:
            t0 = time.monotonic()
            vals, cycle = self.call(lambda p: self._sample(p, want))
            self.round_ms = (time.monotonic() - t0) * 1000
        finally:
            self.trace_lock.release()
        self.values.update(vals)
        self.value_cycle, self.value_time = cycle, time.monotonic()
        self.watch_state = "ok"

    def _pipeline(self, p, pdus):
        """Requests sent together on plctrace's second connection, each reply
        (function code, payload bytes) in order: one round trip for all."""
        if not hasattr(p, "raw"):
            p.windows([])                   # opens it
        s = p.raw
        s.sendall(b"".join(struct.pack(">HHHB", i, 0, len(pdu) + 1, 1) + pdu for i, pdu in enumerate(pdus)))
        out, buf = [], bytearray()
        while len(out) < len(pdus):
            while not (len(buf) >= 6 and len(buf) >= 6 + (buf[4] << 8 | buf[5])):
                # acknowledge at once: plcrt sends each reply as it is served, and a
                # delayed ACK would hold the next one back by tens of ms (Nagle)
                s.setsockopt(socket.IPPROTO_TCP, socket.TCP_QUICKACK, 1)
                chunk = s.recv(65536)
                if not chunk:
                    raise Refused("plcrt closed the connection")
                buf += chunk
            n = 6 + (buf[4] << 8 | buf[5])
            if (buf[0] << 8 | buf[1]) != len(out):
                raise Refused("reply out of order")
            out.append((buf[7], bytes(buf[8:n])))
            del buf[:n]
        return out

    def _windows(self, p, reqs):
        """The read-out window for each (what, first, count), as plctrace's
        windows() reads them (FC 23, selector then window), in one round trip."""
        pdus = [struct.pack(">BHHHHB3H", 23, plctrace.WIN, cnt, plctrace.SEL, 3, 6, what, first >> 16,
                            first & 0xFFFF) for what, first, cnt in reqs]
        out = []
        for (what, first, _), (fc, payload) in zip(reqs, self._pipeline(p, pdus)):
            if fc & 0x80:
                raise Refused(f"window {what:#x}/{first}: exception {payload[0]}: "
                              f"{plctrace.EXCEPTIONS.get(payload[0], '')}")
            out.append(struct.unpack(f">{payload[0] // 2}H", payload[1:1 + payload[0]]))
        return out

    def _command_pdu(self, p, code, args=()):
        regs = [p.token, code] + list(args)
        return struct.pack(f">BHHB{len(regs)}H", 16, plctrace.CMD, len(regs), 2 * len(regs), *regs)

    def _status_pdu(self):
        return struct.pack(">BHH", 3, plctrace.BASE, 32)

    @staticmethod
    def _status_of(payload):
        r = struct.unpack(f">{payload[0] // 2}H", payload[1:1 + payload[0]])
        return {"readable": r[3], "captures": u32(r, 8), "seq": u32(r, 10)}

    def _sample(self, p, want):
        """One capture of one sample per chunk of 32 variables; the trace is
        claimed for this alone and released. The commands of a chunk go in
        one round trip (a refused claim makes the rest refused as well: they
        carry a token that does not own the trace)."""
        vals, cycle = {}, None
        try:
            for k in range(0, len(want), 32):
                chunk = want[k:k + 32]
                pdus = ([self._command_pdu(p, plctrace.CLAIM)] if k == 0 else []) + [
                    self._command_pdu(p, plctrace.CHANNELS, [x for v in chunk for x in plctrace.args32(v["index"])]),
                    self._command_pdu(p, plctrace.SETUP, [1, 0, 1, 0, 0, 0, 0xFFFF, 0xFFFF, 0, 0, 0, 0, 0]),
                    self._status_pdu(),
                    self._command_pdu(p, plctrace.ARM), self._command_pdu(p, plctrace.TRIGGER)]
                replies = self._pipeline(p, pdus)
                for fc, payload in replies:
                    if fc & 0x80:
                        if payload[0] == 6 and k == 0:
                            raise Refused("waiting: another client (plctrace?) owns the trace, "
                                          "through which values are read")
                        raise Refused(f"watch: exception {payload[0]}: {plctrace.EXCEPTIONS.get(payload[0], '')}")
                st0 = self._status_of(replies[-3][1])
                end = time.monotonic() + 2
                while True:
                    st = self._status_of(self._pipeline(p, [self._status_pdu()])[0][1])
                    if st["readable"] and st["seq"] > st0["captures"]:
                        break
                    if time.monotonic() > end:
                        self._pipeline(p, [self._command_pdu(p, plctrace.STOP)])
                        raise Refused("no sample within 2 s: is the scan running?")
                    time.sleep(0.0005)
                reqs = [(i, 0, 1 if v["size"] <= 2 else v["size"] // 2) for i, v in enumerate(chunk)]
                wins = self._windows(p, reqs + [(plctrace.W_CYCLES, 0, 2)])
                for v, w in zip(chunk, wins):
                    raw = 0
                    for x in w:
                        raw = raw << 16 | x
                    vals[v["path"].upper()] = plctrace.decode(raw, v["tcode"])
                cycle = u32(wins[-1], 0)
        finally:
            self._pipeline(p, [self._command_pdu(p, plctrace.RELEASE)])
        return vals, cycle

    # ---- writes ----
    def force(self, path, value):
        v = self.resolve(path)
        self.call(lambda p: plctrace.force_var(p, v["path"], value))
        return v["path"]

    def unforce(self, path=None):
        if path is None:
            self.call(lambda p: p.command(plctrace.UNFORCE_ALL, what="unforce all"))
            return "all"
        v = self.resolve(path)
        self.call(lambda p: p.command(plctrace.UNFORCE, plctrace.args32(v["index"]), f"unforce {v['path']}"))
        return v["path"]

    def forced_now(self):
        return self.call(plctrace.forced_list)

    def cycles_and_forced(self):
        r = self.call(lambda p: p.c.read_input_registers(DIAG, 50, slave=1))
        return u32(r.registers, 0), u32(r.registers, 48)

    # ---- the tag list: writes as an HMI makes them ----
    def tag_list(self):
        """{IEC path upper: tag} of the tag list (TAGS.json, or TAGS.csv),
        read again when the file changes; tags whose variable the running
        program lacks, or has with another type, are left out (a list of
        another program must never write to its addresses)."""
        if not self.tags_path:
            return {}
        path = self.tags_path
        if os.path.isdir(path):
            path = os.path.join(path, "TAGS.json")
        try:
            st = os.stat(path)
            key = (path, st.st_mtime_ns, st.st_size, self.generation)
        except OSError:
            self.tags, self.tags_key = {}, None
            return {}
        if key == self.tags_key:
            return self.tags
        try:
            if path.endswith(".csv"):
                import csv
                with open(path, newline="") as f:
                    raw = [dict(r, address=int(r["address"]), registers=int(r["registers"]))
                           for r in csv.DictReader(f)]
            else:
                with open(path) as f:
                    raw = json.load(f)["tags"]
        except (OSError, ValueError, KeyError, TypeError) as e:
            log.warning("tag list %s: not read (%s): writes are forced", path, e)
            self.tags, self.tags_key = {}, key
            return {}
        self.table()
        tags = {}
        for t in raw:
            v = self.by_path.get(str(t.get("name", "")).upper())
            if v and v["type"].upper() == str(t.get("type", "")).upper():
                tags[v["path"].upper()] = t
        self.tags, self.tags_key = tags, (path, st.st_mtime_ns, st.st_size, self.generation)
        self.tags_skipped = len(raw) - len(tags)
        return tags

    def tags_state(self):
        shown = os.path.relpath(self.tags_path) if self.tags_path else None
        if shown and shown.startswith(".."):
            shown = self.tags_path
        if not self.tags_path:
            return "none (writes are forced: plcweb --tags build/gen/TAGS.json writes through Modbus)"
        tags = self.tag_list()
        if not self.tags_key:
            return f"{shown}: not found (writes are forced)"
        skipped = getattr(self, "tags_skipped", 0)
        return (f"{len(tags)} tags from {shown}"
                + (f" ({skipped} not in the running program: left out)" if skipped else ""))

    def tag_of(self, v):
        t = self.tag_list().get(v["path"].upper())
        return t if t and t.get("access") == "read-write" and t.get("table") in ("coil", "holding") else None

    def tag_write(self, t, value):
        try:
            self.call(lambda p: plctrace.tag_write(p, t, value))
        except ValueError as e:
            raise Refused(str(e)) from None

    def write(self, path, value):
        """Write a value: through the variable's tag, an ordinary Modbus write
        (then what the program, the I/O or a client writes afterwards wins);
        without a tag, forced for a few cycles and released (needs forcing
        allowed). Returns (path, how it was written, in words)."""
        v = self.resolve(path)
        t = self.tag_of(v)
        if v["path"].upper() in {p.upper() for p, _, _ in self.forced_now()}:
            raise Refused(f"{v['path']} is forced: unforce it first, or force the new value")
        if t:
            self.tag_write(t, value)
            return v["path"], f"Modbus write, {t['table']} {t['address']} (its tag)"
        self.forced_write(v, value)
        return v["path"], "forced for two cycles (no Modbus tag)"

    def forced_write(self, v, value):
        """A one-shot write: forced for a few cycles, then released, so that
        the program sees the value at least once and then takes the variable
        back. Needs forcing allowed."""
        c0, n0 = self.cycles_and_forced()
        try:
            self.force(v["path"], value)
        except Refused as e:
            if "exception 1" in str(e):
                why = ("it has no Modbus tag" if self.tags_path else "plcweb has no tag list (--tags)")
                raise Refused(f"write {v['path']}: {why}, so plcweb writes it by forcing it for two cycles, "
                              "and plcrt's configuration does not allow forcing: [debug] allow_force = yes "
                              "(or map it in [modbus.symbols] with rw)") from None
            raise
        try:
            # the scan has taken the force when its count shows it; then two cycles more
            self.wait_cycles(2, lambda: self.cycles_and_forced()[1] > n0)
        finally:
            self.unforce(v["path"])

    def wait_cycles(self, n, first=lambda: True):
        """Until first() holds, then until n more cycles ran (5 s at most)."""
        end = time.monotonic() + 5
        while time.monotonic() < end:
            if first():
                c1 = self.cycles_and_forced()[0]
                while time.monotonic() < end and self.cycles_and_forced()[0] < c1 + n:
                    time.sleep(0.002)
                return
            time.sleep(0.002)

    # ---- axes ----
    def axes(self):
        """Every axis instance the table shows: [{kind, path, fields}]."""
        members = {}
        for v in self.table():
            head, _, tail = v["path"].rpartition(".")
            members.setdefault(head, set()).add(tail.upper())
        found = []
        for head, m in members.items():
            for kind, need, fields in AXIS_KINDS:
                if need <= m:
                    f = {}
                    for k, name in fields.items():
                        if isinstance(name, list):
                            f[k] = [f"{head}.{x}" for x in name if x in m]
                        elif isinstance(name, tuple):
                            f[k] = [f"{head}.{x}" for x in name]
                        elif name and name in m:
                            f[k] = f"{head}.{name}"
                        else:
                            f[k] = None
                    found.append({"kind": kind, "path": head, "fields": f})
                    break
        # an adapter that mirrors its device's members (MC_AXIS_EPICPOS and its
        # Dev) is one axis: the device inside it is shown
        found = [a for a in found if not any(b is not a and b["kind"] == a["kind"]
                                             and b["path"].startswith(a["path"] + ".") for b in found)]
        # A program that copies its own command variable into the block's
        # input every cycle (the examples' cSTOP -> Axis.STOP) overwrites a
        # forced input before the block runs: there the command goes through
        # that variable, <program>.C<COMMAND>, when the program has one axis.
        parents = [a["path"].rpartition(".")[0] for a in found]
        for a in found:
            parent = a["path"].rpartition(".")[0]
            for act in ("stop", "reset"):
                cmd = a["fields"].get(act)
                if cmd and parents.count(parent) == 1:
                    alt = f"{parent}.C{cmd.rpartition('.')[2]}"
                    if alt.upper() in self.by_path:
                        a["fields"][act] = self.by_path[alt.upper()]["path"]
        return sorted(found, key=lambda a: a["path"])

    def axis_action(self, path, action):
        """stop or reset: the axis's command pulsed high for a few cycles."""
        ax = next((a for a in self.axes() if a["path"].upper() == path.upper()), None)
        if ax is None:
            raise Refused(f"{path}: no such axis")
        cmd = ax["fields"].get(action)
        if not cmd:
            raise Refused(f"{ax['kind']} axis {path}: no {action} command here (the program's MC_Stop/MC_Reset)")
        try:
            v = self.resolve(cmd)
            t = self.tag_of(v)
            if not t:
                return self.write(cmd, "TRUE")
            # through its tag: TRUE, two cycles, FALSE: a rising edge the program
            # sees whether or not it clears the command itself
            self.tag_write(t, "TRUE")
            try:
                self.wait_cycles(2)
            finally:
                self.tag_write(t, "FALSE")
            return v["path"], f"Modbus write, {t['table']} {t['address']} (its tag), TRUE for two cycles"
        except Refused as e:
            raise Refused(f"{action} {ax['kind']} {path}: {e}") from None

    # ---- trace captures ----
    def start_capture(self, chans, trigger, pre, samples, every, timeout=60.0):
        """Checks as plctrace record does, then the capture in a thread of its own."""
        if self.capture.get("state") in ("armed", "starting"):
            raise Refused("a capture is already running: stop it first")
        if not chans:
            raise Refused("choose at least one channel")
        if len(chans) > 32:
            raise Refused(f"{len(chans)} channels; at most 32")
        if samples < 1 or pre < 0 or pre >= samples:
            raise Refused("samples must be 1 or more, pre from 0 to below samples")
        if not 1 <= every <= 65535:
            raise Refused("every: 1..65535 cycles")
        try:
            kind, tpath, level = plctrace.parse_trigger(trigger)
        except SystemExit as e:
            raise Refused(str(e).replace("plctrace: ", "")) from None
        cap = self.call(lambda p: p.status()["cap"])
        if samples > cap:
            raise Refused(f"samples {samples}: this plcrt keeps at most {cap} samples per channel "
                          "([trace] samples in its configuration)")
        cvars = [self.resolve(c) for c in chans]
        tvar = None
        if tpath:
            tvar = self.resolve(tpath)
            if kind in ("rise", "fall") and tvar["tcode"] != 1:
                raise Refused(f"trigger {trigger}: {tpath} is {plctrace.a_type(tvar['type'])}; rise and fall take a "
                              f"BOOL (for a number: {tpath}:up:LEVEL or {tpath}:down:LEVEL)")
        self.capture = {"state": "starting", "stop": False}
        threading.Thread(target=self._capture, args=(cvars, kind, tvar, level, pre, samples, every, timeout),
                         daemon=True).start()

    def stop_capture(self):
        self.capture["stop"] = True

    def _capture(self, cvars, kind, tvar, level, pre, samples, every, timeout):
        cap = self.capture
        with self.trace_lock:
            try:
                def setup(p):
                    p.command(plctrace.CLAIM, what="claim the trace")
                    p.command(plctrace.CHANNELS, [x for v in cvars for x in plctrace.args32(v["index"])], "channels")
                    lv = struct.unpack(">4H", struct.pack(">d", level))
                    p.command(plctrace.SETUP, [every] + plctrace.args32(samples) + plctrace.args32(pre)
                              + [plctrace.TRIGGERS[kind]] + plctrace.args32(tvar["index"] if tvar else 0xFFFFFFFF)
                              + list(lv) + [0], "setup")
                    st0 = p.status()
                    p.command(plctrace.ARM, what="arm")
                    if kind in ("now", "manual"):
                        p.command(plctrace.TRIGGER, what="trigger")
                    return st0
                try:
                    st0 = self.call(setup)
                except Refused as e:
                    if "exception 6" in str(e):
                        raise Refused("another client (plctrace?) owns the trace: try again when it is done") from None
                    raise
                cap["state"] = "armed"
                end, alive = time.monotonic() + timeout, time.monotonic()
                while True:
                    if time.monotonic() - alive > 5:
                        self.call(lambda p: p.command(plctrace.CLAIM, what="keep the trace"))
                        alive = time.monotonic()
                    st = self.call(lambda p: p.status())
                    if st["readable"] and st["seq"] > st0["captures"]:
                        break
                    if cap.get("stop") or time.monotonic() > end:
                        self.call(lambda p: p.command(plctrace.STOP, what="stop"))
                        raise Refused("stopped" if cap.get("stop") else
                                      f"no capture within {timeout:g} s (trigger not met?)")
                    time.sleep(0.02)
                data = self.call(lambda p: plctrace.download(p, st))
                cap.update(state="done", data=data, status=st, seq=st["seq"])
            except Refused as e:
                cap.update(state="failed", error=str(e))
            except Exception as e:
                cap.update(state="failed", error=f"{type(e).__name__}: {e}")
            finally:
                try:
                    self.call(lambda p: p.command(plctrace.RELEASE, what="release"))
                except Exception:
                    pass


# ---- the I/O backends' diagnostics (docs/canopen.md, docs/remote-io.md) ----
def read_backends(path):
    """[(kind, [section names])] of plcrt's configuration, in the order of
    [io] backend: the names of the canopen nodes and modbus_io devices in
    file order (the order of their diagnostics). Read line by line: the
    file repeats keys (read, write, bind) that configparser refuses."""
    try:
        lines = open(path).read().splitlines()
    except (OSError, UnicodeDecodeError) as e:
        raise SystemExit(f"plcweb: --config {path}: cannot read it ({getattr(e, 'strerror', None) or e}): "
                         "give plcrt's configuration file, e.g. --config plcrt.ini")
    section, kinds, sections = "", ["sim"], []
    for line in lines:
        s = line.split(";")[0].split("#")[0].strip()
        if s.startswith("[") and s.endswith("]"):
            section = s[1:-1].strip()
            sections.append(section)
        elif section == "io" and "=" in s and s.split("=")[0].strip() == "backend":
            kinds = [k.strip() for k in s.split("=", 1)[1].split(",") if k.strip()]
    out = []
    for kind in kinds:
        names = [x.split(".", 1)[1] for x in sections if x.startswith(kind + ".") and x.count(".") == 1] \
            if kind in ("canopen", "modbus_io") else []
        out.append((kind, names))
    return out


CO_PHASES = ["idle", "waiting for boot-up", "checking device type", "configuring", "operational", "lost", "failed"]
CO_FAULTS = ["lost", "EMCY", "SDO error", "start-up failed", "wrong device type", "unexpected boot-up",
             "short TPDO"]
CO_BUS = ["ok", "error warning", "error passive", "bus-off", "interface down"]


def decode_backend(kind, names, r):
    """A backend's block in words: {kind, summary, rows: [{name, state, ...}]}."""
    if r is None:
        return {"kind": kind, "summary": "its registers do not answer", "rows": []}
    if kind == "canopen":
        rows = []
        for k in range(min(r[2], 10)):
            b = 4 + 6 * k
            phase = r[b] >> 8
            faults = [n for i, n in enumerate(CO_FAULTS) if r[b + 1] & (1 << i)]
            rows.append({"name": names[k] if k < len(names) else f"node {k}", "id": r[b] & 0xFF,
                         "state": CO_PHASES[phase] if phase < len(CO_PHASES) else f"phase {phase}",
                         "faults": ", ".join(faults) or "none", "boot-ups": r[b + 2],
                         "heartbeat losses": r[b + 3], "EMCYs": r[b + 4],
                         "last EMCY": f"{r[b + 5]:04X}" if r[b + 4] else "-"})
        bus = CO_BUS[r[0]] if r[0] < len(CO_BUS) else f"state {r[0]}"
        return {"kind": kind, "summary": f"bus {bus}, {r[3]} of {r[2]} nodes operational, bus-off {r[1]} times",
                "rows": rows}
    if kind == "modbus_io":
        rows = []
        for k in range(min(r[0], 6)):
            b = 16 + 16 * k
            ok, lost = r[b + 10], u32(r, b + 8)
            rounds = u32(r, b)
            state = "ok" if ok else ("lost" if lost or u32(r, b + 2) or rounds else "not reached yet")
            rows.append({"name": names[k] if k < len(names) else f"device {k}", "state": state,
                         "rounds": rounds, "timeouts": u32(r, b + 2), "exceptions": u32(r, b + 4),
                         "bad frames": u32(r, b + 6), "reconnects": lost,
                         "round (ms)": round(u32(r, b + 12) / 1000, 1)})
        n = u32(r, 2)
        return {"kind": kind, "summary": f"{r[1]} of {r[0]} devices ok, {n} fault{'' if n == 1 else 's'} "
                                         "since the start",
                "rows": rows}
    return {"kind": kind, "summary": "", "rows": []}
