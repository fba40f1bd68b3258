// Plot: a trace capture drawn on a canvas, each channel as steps over PLC
// time from the trigger (ms), as plctrace's PNG draws it. Drag: zoom on a
// time span; double-click: zoom out; click: cursor A, shift-click: cursor B
// (their values and the difference shown below the plot). series holds
// exactly the points drawn: {path, t: [...], v: [...]} per channel.
"use strict";
function num(v) { return v === null || Number.isInteger(v) ? String(v) : Number(v.toPrecision(7)).toString(); }
const COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf"];
class Plot {
  constructor(canvas, readout) {
    this.canvas = canvas; this.readout = readout; this.series = []; this.diff = false;
    this.view = null; this.cursors = [null, null]; this.drag = null;
    const pos = ev => { const r = canvas.getBoundingClientRect(); return (ev.clientX - r.left) * canvas.width / r.width; };
    canvas.addEventListener("mousedown", ev => { this.drag = {x0: pos(ev), x1: pos(ev)}; });
    canvas.addEventListener("mousemove", ev => { if (this.drag) { this.drag.x1 = pos(ev); this.draw(); } });
    canvas.addEventListener("mouseup", ev => {
      const d = this.drag; this.drag = null;
      if (!d || !this.series.length) return;
      if (Math.abs(d.x1 - d.x0) > 5) {
        const a = this.tOf(Math.min(d.x0, d.x1)), b = this.tOf(Math.max(d.x0, d.x1));
        this.view = [a, b];
      } else {
        this.cursors[ev.shiftKey ? 1 : 0] = this.tOf(d.x0);
      }
      this.draw();
    });
    canvas.addEventListener("dblclick", () => this.zoomOut());
    this.draw();
  }
  set(d) {
    this.series = d.cols.map(c => ({path: c.path, t: d.time_ms.slice(), v: c.values.slice()}));
    this.cycle = d.cycle;
    this.view = null; this.cursors = [null, null];
    this.draw();
  }
  zoomOut() { this.view = null; this.draw(); }
  shown() {
    const s = this.series.slice();
    if (this.diff && s.length >= 2)
      s.push({path: `${s[0].path.split(".").pop()} − ${s[1].path.split(".").pop()}`, t: s[0].t,
              v: s[0].v.map((x, i) => x - s[1].v[i]), derived: true});
    return s;
  }
  range() {
    const t = this.series[0].t;
    return this.view || [t[0], t[t.length - 1] === t[0] ? t[0] + 1 : t[t.length - 1]];
  }
  box() { return {l: 70, r: this.canvas.width - 10, t: 10, b: this.canvas.height - 36}; }
  tOf(x) { const b = this.box(), [a, c] = this.range(); return a + (x - b.l) / (b.r - b.l) * (c - a); }
  xOf(t) { const b = this.box(), [a, c] = this.range(); return b.l + (t - a) / (c - a) * (b.r - b.l); }
  valueAt(s, t) {      // the step's value at time t (the last sample at or before it)
    let lo = 0, hi = s.t.length - 1;
    if (t < s.t[0]) return null;
    while (lo < hi) { const m = (lo + hi + 1) >> 1; if (s.t[m] <= t) lo = m; else hi = m - 1; }
    return s.v[lo];
  }
  draw() {
    const g = this.canvas.getContext("2d"), W = this.canvas.width, H = this.canvas.height, b = this.box();
    g.fillStyle = "#fff"; g.fillRect(0, 0, W, H);
    if (!this.series.length) { g.fillStyle = "#888"; g.fillText("no capture yet", W / 2 - 30, H / 2); return; }
    const [t0, t1] = this.range(), shown = this.shown();
    const rows = shown.length, rh = (b.b - b.t) / rows;
    g.font = "11px sans-serif"; g.lineWidth = 1;
    shown.forEach((s, k) => {     // one row per channel, each with its own scale (as plctrace's PNG)
      const top = b.t + k * rh, bot = top + rh - 6;
      let lo = Infinity, hi = -Infinity;
      for (let i = 0; i < s.t.length; i++)
        if (s.t[i] >= t0 && s.t[i] <= t1) { lo = Math.min(lo, s.v[i]); hi = Math.max(hi, s.v[i]); }
      if (!isFinite(lo)) { lo = 0; hi = 1; }
      if (hi === lo) { hi += 1; lo -= 1; }
      const pad = (hi - lo) * 0.08; lo -= pad; hi += pad;
      const yOf = v => bot - (v - lo) / (hi - lo) * (bot - top);
      g.strokeStyle = "#ccc"; g.strokeRect(b.l, top, b.r - b.l, bot - top);
      g.fillStyle = "#444";
      for (let j = 0; j <= 2; j++) {
        const v = lo + (hi - lo) * (0.1 + 0.4 * j), y = yOf(v);
        g.strokeStyle = "#eee"; g.beginPath(); g.moveTo(b.l, y); g.lineTo(b.r, y); g.stroke();
        g.fillText(Number(v.toPrecision(5)).toString(), 2, y + 4);
      }
      g.save(); g.beginPath(); g.rect(b.l, top, b.r - b.l, bot - top); g.clip();
      g.strokeStyle = COLORS[k % COLORS.length]; g.lineWidth = 1.2; g.beginPath();
      let first = true, prevY = 0;
      for (let i = 0; i < s.t.length; i++) {
        if (i + 1 < s.t.length && s.t[i + 1] < t0) continue;
        if (s.t[i] > t1) { g.lineTo(this.xOf(s.t[i]), prevY); break; }
        const x = this.xOf(s.t[i]), y = yOf(s.v[i]);
        if (first) { g.moveTo(x, y); first = false; } else { g.lineTo(x, prevY); g.lineTo(x, y); }
        prevY = y;
      }
      if (!first) g.lineTo(b.r, prevY);
      g.stroke();
      g.restore();
      g.fillStyle = COLORS[k % COLORS.length];
      g.fillText(s.path.split(".").slice(2).join(".") || s.path, b.l + 6, top + 12);
    });
    g.fillStyle = "#444"; g.strokeStyle = "#ddd";
    for (let k = 0; k <= 5; k++) {
      const t = t0 + (t1 - t0) * k / 5, x = this.xOf(t);
      g.beginPath(); g.moveTo(x, b.t); g.lineTo(x, b.b); g.stroke();
      g.fillText(Number(t.toPrecision(5)).toString(), x - (k === 5 ? 30 : 12), b.b + 14);
    }
    g.fillText("PLC time from the trigger (ms)", (b.l + b.r) / 2 - 70, b.b + 28);
    if (t0 <= 0 && 0 <= t1) { g.strokeStyle = "#888"; g.setLineDash([2, 3]); g.beginPath(); g.moveTo(this.xOf(0), b.t); g.lineTo(this.xOf(0), b.b); g.stroke(); g.setLineDash([]); }
    const names = ["A", "B"], texts = [];
    this.cursors.forEach((c, k) => {
      if (c === null) return;
      const x = this.xOf(c);
      g.strokeStyle = k ? "#a0a" : "#0a0"; g.beginPath(); g.moveTo(x, b.t); g.lineTo(x, b.b); g.stroke();
      g.fillStyle = g.strokeStyle; g.fillText(names[k], x + 3, b.t + 12);
      texts.push(`${names[k]}: t = ${c.toFixed(3)} ms, ` + shown.map(s => `${s.path.split(".").pop()} = ${num(this.valueAt(s, c))}`).join(", "));
    });
    if (this.cursors[0] !== null && this.cursors[1] !== null)
      texts.push(`B − A: ${(this.cursors[1] - this.cursors[0]).toFixed(3)} ms, ` +
        shown.map(s => `${s.path.split(".").pop()} ${num(this.valueAt(s, this.cursors[1]) - this.valueAt(s, this.cursors[0]))}`).join(", "));
    this.readout.textContent = texts.join("  |  ");
    if (this.drag) { g.fillStyle = "rgba(0,0,200,0.1)"; g.fillRect(Math.min(this.drag.x0, this.drag.x1), b.t, Math.abs(this.drag.x1 - this.drag.x0), b.b - b.t); }
  }
}
