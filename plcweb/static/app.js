// plcweb's pages: Overview, Variables, Axes, Trace, Project. Every value is
// fetched from plcweb's JSON requests (plcweb/plcweb); every write sends the
// session's CSRF token in X-CSRF-Token. Text from the PLC is set with
// textContent, never as HTML.
"use strict";
const page = location.pathname.replace(/^\/+|\/+$/g, "") || "overview";
let session = null;

function $(id) { return document.getElementById(id); }
function el(tag, text, cls) {
  const e = document.createElement(tag);
  if (text !== undefined && text !== null) e.textContent = String(text);
  if (cls) e.className = cls;
  return e;
}
function say(text, ok) {
  const m = $("message");
  m.textContent = text || "";
  m.className = "message " + (ok ? "ok" : "error");
}
async function api(method, path, body, raw) {
  const opt = {method, headers: {}};
  if (method !== "GET") opt.headers["X-CSRF-Token"] = session ? session.csrf : "";
  if (raw) { opt.body = body; Object.assign(opt.headers, raw); }
  else if (body !== undefined) { opt.body = JSON.stringify(body); opt.headers["Content-Type"] = "application/json"; }
  const r = await fetch(path, opt);
  if (r.status === 401) { location.href = "/login?next=" + encodeURIComponent(location.pathname); throw new Error("log in"); }
  const j = await r.json();
  if (!r.ok) throw new Error(j.error || r.statusText);
  return j;
}
function every(ms, fn) {
  let busy = false;
  const tick = async () => {
    if (busy) return;
    busy = true;
    try { await fn(); } catch (e) { if (e.message !== "log in") say(e.message); } finally { busy = false; }
  };
  tick();
  return setInterval(tick, ms);
}
function short(path) { return path.split(".").slice(2).join("."); }
function fmt(v) {
  if (v === null || v === undefined) return "…";
  if (typeof v === "number" && !Number.isInteger(v)) return v.toPrecision(7).replace(/\.?0+$/, "");
  return String(v);
}

// ---- Overview ----
const OV = [
  ["program", "programs"], ["scan period (µs)", "period_us"], ["cycles", "cycles"],
  ["overruns", "overruns"], ["… the program's own", "overruns_own"], ["… late wake-ups", "overruns_late"],
  ["periods skipped", "skipped"],
  ["exec min / mean / p99 / max (µs)", ["exec_min", "exec_mean", "exec_p99", "exec_max"]],
  ["wake latency min / mean / p99 / max (µs)", ["lat_min", "lat_mean", "lat_p99", "lat_max"]],
  ["Modbus clients", "clients"], ["requests served", "requests"], ["exceptions sent", "exceptions"],
  ["retain saves (failures)", ["retain_saves", "retain_failures"]], ["forced variables", "forced"],
  ["forcing allowed", "force_allowed"], ["I/O errors", "io_errors"], ["trace", "trace_state"],
  ["variables", "nvars"], ["up (s)", "uptime_s"], ["tag list (writes)", "tags"], ["watch", "watch_state"],
  ["variables watched, ms the trace is held per sample", ["watching", "watch_round_ms"]]];
async function overview() {
  $("ov-plc").textContent = "plcrt at " + session.plc;
  const t = $("ov-table");
  for (const [label, key] of OV) {
    const tr = t.insertRow();
    tr.insertCell().textContent = label;
    const c = tr.insertCell();
    c.id = "ov-" + (Array.isArray(key) ? key[0] : key);
  }
  every(500, async () => {
    const d = await api("GET", "/api/overview");
    for (const [, key] of OV) {
      const keys = Array.isArray(key) ? key : [key];
      const v = keys.map(k => Array.isArray(d[k]) ? d[k].join(", ") : typeof d[k] === "boolean" ? (d[k] ? "yes" : "no") : d[k]);
      $("ov-" + keys[0]).textContent = v.join(" / ");
    }
    const b = $("ov-backend");
    b.textContent = "";
    const kinds = d.backends_known ? d.backends.map(x => x.kind) : ["sim"];
    const bx = $("ov-backends");
    bx.textContent = "";
    if (!d.backends_known)
      bx.appendChild(el("p", "Which backends run is in plcrt's configuration: plcweb --config plcrt.ini names them " +
                              "and shows the CANopen nodes and remote I/O devices."));
    d.backends.forEach((k, i) => {
      if (k.kind === "sim" || k.kind === "none") return;
      const box = el("div", null, "backend");
      box.id = "ov-backend-" + i;
      box.dataset.kind = k.kind;
      box.appendChild(el("h4", `${k.kind === "canopen" ? "CANopen" : "remote I/O (modbus_io)"}: ${k.summary}`));
      if (k.rows.length) {
        const t = el("table", null, "grid");
        const cols = Object.keys(k.rows[0]);
        const h = t.insertRow();
        cols.forEach(c => h.appendChild(el("th", c)));
        for (const row of k.rows) {
          const r = t.insertRow();
          r.dataset.name = row.name;
          for (const c of cols) {
            const cell = r.insertCell();
            cell.textContent = row[c];
            cell.className = c.replace(/\W+/g, "-");
            if (c === "state") cell.classList.add(row.state === "ok" || row.state === "operational" ? "good" : "bad");
          }
        }
        box.appendChild(t);
      }
      bx.appendChild(box);
    });
    if (kinds[0] === "sim") {
      const h = b.insertRow();
      ["sim axis (registers 1088-1151)", "position (counts)", "speed (counts/s)"].forEach(x => h.appendChild(el("th", x)));
      for (const a of d.backend.filter(a => a.axis === 0 || a.position || a.speed)) {
        const r = b.insertRow();
        [a.axis, a.position, a.speed].forEach(x => r.insertCell().textContent = x);
      }
    }
    say("");
  });
}

// ---- Variables ----
function watchList() {
  let w;
  try { w = JSON.parse(localStorage.getItem("plcweb.watch") || "[]"); } catch (e) { w = []; }
  const seen = new Set();      // each variable once, whatever was stored
  return (Array.isArray(w) ? w : []).filter(v => v && typeof v.path === "string" && !seen.has(v.path) && seen.add(v.path));
}
function saveWatch(w) { localStorage.setItem("plcweb.watch", JSON.stringify(w)); }
function addWatch(v) {
  const w = watchList();
  if (!w.some(x => x.path === v.path)) { w.push({path: v.path, type: v.type}); saveWatch(w); drawWatch(); }
}
function rowId(path) { return "w-" + path.replace(/[^A-Za-z0-9_]/g, "_"); }
function drawWatch() {
  const tb = $("watch").tBodies[0];
  tb.textContent = "";
  for (const v of watchList()) {
    const r = tb.insertRow();
    r.id = rowId(v.path);
    r.dataset.path = v.path;
    r.insertCell().textContent = v.path;
    r.insertCell().textContent = v.type;
    const val = r.insertCell(); val.className = "value"; val.textContent = "…";
    const fl = r.insertCell(); fl.className = "flagcell";
    const inp = el("input"); inp.size = 10; inp.className = "op";
    const c = r.insertCell(); c.appendChild(inp);
    const acts = r.insertCell();
    for (const [label, fn] of [["write", "write"], ["force", "force"], ["unforce", "unforce"]]) {
      const b = el("button", label, "op " + label);
      b.onclick = async () => {
        try {
          const r = await api("POST", "/api/" + fn, {path: v.path, value: inp.value});
          say(`${fn} ${v.path}${fn === "unforce" ? "" : " = " + inp.value}: done${r.how ? " (" + r.how + ")" : ""}`, true);
        } catch (e) { say(`${fn} ${v.path}: ${e.message}`); }
      };
      acts.appendChild(b);
    }
    const x = el("button", "✕", "remove");
    x.title = "remove from the watch list";
    x.onclick = () => { saveWatch(watchList().filter(y => y.path !== v.path)); drawWatch(); };
    acts.appendChild(x);
  }
}
let program = null;
async function pollValues(paths, show) {
  const q = paths.map(p => "p=" + encodeURIComponent(p)).join("&");
  const d = await api("GET", "/api/values?" + q);
  if (program !== null && d.program !== program) { location.reload(); return; }   // another program runs
  program = d.program;
  show(d);
}
async function variables() {
  let timer = null;
  $("var-search").addEventListener("input", () => {
    clearTimeout(timer);
    timer = setTimeout(async () => {
      const d = await api("GET", "/api/vars?q=" + encodeURIComponent($("var-search").value));
      $("var-count").textContent = d.count + " found" + (d.count > d.vars.length ? `, ${d.vars.length} shown` : "");
      const t = $("var-results");
      t.textContent = "";
      for (const v of d.vars) {
        const r = t.insertRow();
        r.insertCell().textContent = v.path;
        r.insertCell().textContent = v.type;
        r.insertCell().textContent = v.area;
        const b = el("button", "watch", "watch");
        b.onclick = () => addWatch(v);
        r.insertCell().appendChild(b);
      }
    }, 200);
  });
  $("unforce-all").onclick = async () => {
    try { await api("POST", "/api/unforce", {all: true}); say("every variable released", true); }
    catch (e) { say("unforce all: " + e.message); }
  };
  drawWatch();
  every(100, () => pollValues(watchList().map(v => v.path), d => {
    $("watch-state").textContent = d.state === "ok" ? `cycle ${d.cycle}, ${d.age_ms} ms ago` : d.state;
    for (const r of $("watch").tBodies[0].rows) {
      const p = r.dataset.path, v = d.values[p];
      if (!(p in d.values)) continue;
      r.cells[2].textContent = fmt(v);
      const f = d.forced[p];
      r.classList.toggle("forced", f !== null && f !== undefined);
      r.cells[3].textContent = f !== null && f !== undefined ? "forced" : "";
    }
  }));
}

// ---- Axes ----
async function axes() {
  const got = await api("GET", "/api/axes"), list = got.axes;
  program = got.program;       // the program these axes belong to: another one reloads the page
  const box = $("axes");
  if (!list.length) box.textContent = "No EPICPOS, APOSS or PLCopen axis in this program.";
  const paths = [];
  const FIELDS = [["position", "position"], ["setpoint", "set-point"], ["folerr", "following error"],
                  ["speed", "speed"], ["output", "output (DAC)"], ["mode", "mode"]];
  for (const a of list) {
    const d = el("div", null, "axis");
    d.id = "axis-" + a.path.replace(/[^A-Za-z0-9_]/g, "_");
    d.dataset.path = a.path;
    d.appendChild(el("h3", `${a.kind} ${short(a.path) || a.path}`));
    const st = el("div", null, "states");
    for (const s of a.fields.state) {
      const f = el("span", s.split(".").pop().toLowerCase(), "flag" + (/EMRG|FOLLER|ERROR/.test(s) ? " bad" : ""));
      f.dataset.path = s; st.appendChild(f); paths.push(s);
    }
    d.appendChild(st);
    const t = el("table", null, "kv");
    for (const [k, label] of FIELDS) {
      const src = a.fields[k];
      if (!src) continue;
      const r = t.insertRow();
      r.insertCell().textContent = k === "mode" && a.kind === "PLCopen" ? "state" : label;
      const c = r.insertCell(); c.className = "value " + k; c.textContent = "…";
      c.dataset.src = JSON.stringify(src);
      c.dataset.kind = a.kind;
      (Array.isArray(src) ? src : [src]).forEach(p => paths.push(p));
    }
    for (const e of a.fields.errors) {
      const r = t.insertRow();
      r.insertCell().textContent = e.split(".").pop().toLowerCase();
      const c = r.insertCell(); c.className = "value"; c.dataset.src = JSON.stringify(e); c.textContent = "…";
      paths.push(e);
    }
    d.appendChild(t);
    for (const act of ["stop", "reset"]) {
      if (!a.fields[act]) continue;
      const b = el("button", act === "stop" ? "Stop" : "Reset", "op " + act);
      b.onclick = async () => {
        try {
          const r = await api("POST", "/api/axis", {axis: a.path, action: act});
          say(`${act} ${a.path}: sent${r.how ? " (" + r.how + ")" : ""}`, true);
        }
        catch (e) { say(`${act} ${a.path}: ${e.message}`); }
      };
      d.appendChild(b);
    }
    box.appendChild(d);
  }
  every(100, () => pollValues(paths, d => {
    const v = d.values;
    for (const f of document.querySelectorAll(".flag")) f.classList.toggle("on", !!v[f.dataset.path]);
    for (const c of document.querySelectorAll("#axes td.value")) {
      const src = JSON.parse(c.dataset.src);
      let x = Array.isArray(src) ? (v[src[0]] === null || v[src[1]] === null ? null : v[src[0]] - v[src[1]]) : v[src];
      if (c.classList.contains("mode") && x !== null)
        x = c.dataset.kind === "PLCopen" ? (PLCOPEN[x] || x) : c.dataset.kind === "APOSS" ? (APOSS[x] || x) : x;
      c.textContent = fmt(x);
    }
  }));
}
const PLCOPEN = ["Disabled", "Standstill", "Homing", "DiscreteMotion", "ContinuousMotion", "SynchronizedMotion", "Stopping", "ErrorStop"];
const APOSS = ["idle", "positioning", "constant speed", "stopping", "homing"];

// ---- Trace ----
async function trace() {
  const plot = new Plot($("tr-plot"), $("tr-cursor"));
  window.plcwebPlot = plot;
  let lastSeq = null;
  const load = async () => {
    const d = await api("GET", "/api/trace/data");
    lastSeq = d.seq;
    plot.set(d);
    $("tr-csv").href = "/api/trace.csv?seq=" + d.seq;
  };
  $("tr-capture").onclick = async () => {
    const kind = $("tr-kind").value;
    const tv = $("tr-tvar").value.trim();
    const trig = kind === "now" ? "now" : kind === "rise" || kind === "fall" ? `${tv}:${kind}` : `${tv}:${kind}:${$("tr-level").value}`;
    try {
      await api("POST", "/api/trace", {chans: $("tr-chans").value.split("\n").map(s => s.trim()).filter(s => s),
        trigger: trig, pre: $("tr-pre").value, samples: $("tr-samples").value, every: $("tr-every").value});
      say("");
    } catch (e) { say("capture: " + e.message); }
  };
  $("tr-stop").onclick = () => api("POST", "/api/trace", {stop: true}).catch(e => say(e.message));
  $("tr-diff").onchange = () => { plot.diff = $("tr-diff").checked; plot.draw(); };
  $("tr-reset").onclick = () => plot.zoomOut();
  $("tr-png").onclick = (ev) => { $("tr-png").href = plot.canvas.toDataURL("image/png"); };
  every(200, async () => {
    const c = await api("GET", "/api/trace");
    $("tr-state").textContent = c.state === "failed" ? "failed: " + c.error : c.state;
    $("tr-state").className = c.state === "failed" ? "error" : "";
    if (c.state === "done" && c.seq !== lastSeq) await load();
  });
}

// ---- Project ----
function showBuild(r) {
  $("pr-summary").textContent = r.summary || "";
  $("pr-summary").className = r.state === "built" ? "" : "error";
  const ul = $("pr-messages");
  ul.textContent = "";
  for (const m of r.messages || []) {
    const li = el("li", `${m.file}:${m.line}${m.col ? ":" + m.col : ""}: ${m.text}`);
    li.className = "msg"; li.dataset.file = m.file; li.dataset.line = m.line;
    ul.appendChild(li);
  }
  $("pr-output").textContent = r.output || "";
  $("pr-switch").hidden = r.state !== "built";
  $("pr-hint").textContent = r.state === "built" ? (r.can_switch ? "" : r.run_hint) : "";
  if (r.switched !== undefined) say(r.switched ? "switched: the new program runs" : "switch failed: " + r.switch_output, r.switched);
}
async function project() {
  const last = await api("GET", "/api/project");
  if (last.state !== "none") showBuild(last);
  $("pr-upload").onclick = async () => {
    const f = $("pr-file").files[0];
    if (!f) { say("choose an archive first"); return; }
    $("pr-state").textContent = "building…";
    $("pr-summary").textContent = ""; $("pr-messages").textContent = "";
    try { showBuild(await api("POST", "/api/project", f, {"X-Filename": f.name, "Content-Type": "application/octet-stream"})); say(""); }
    catch (e) { say("upload: " + e.message); }
    $("pr-state").textContent = "";
  };
  $("pr-switch").onclick = async () => {
    $("pr-state").textContent = "switching…";
    try { showBuild(await api("POST", "/api/project/switch")); }
    catch (e) { say(e.message); }
    $("pr-state").textContent = "";
  };
}

// ---- start ----
(async () => {
  try { session = await api("GET", "/api/session"); } catch (e) { return; }
  $("who").textContent = `${session.user} (${session.role})`;
  document.body.classList.add(session.role);
  $("logout").onclick = async () => { await api("POST", "/logout"); location.href = "/login"; };
  const sec = $("page-" + page);
  if (!sec) return;
  sec.hidden = false;
  $("nav-" + page).classList.add("current");
  document.title = "plcweb: " + page;
  await {overview, variables, axes, trace, project}[page]();
  document.body.dataset.ready = "1";
})();
