"""`kincas solve SCENE --html out.html`: one self-contained page (no network: its script is
inline) with the mechanism animated on a canvas, a slider and a play button to scrub the
poses, the paths of its points, and every reported quantity plotted against the input with
a cursor that follows the slider.

The page opens at pose 0, or at `#pose=I`. It keeps in its DOM what a test (or a curious
user) may read: `<body data-pose=I data-transform="sx ox oy">` (a world point (x, y) is drawn
at the page's pixel (ox + sx x, oy - sx y)) and `<pre id="errors">` collecting any JavaScript
error, which also goes into the title. The page fills the window (the drawing on the left,
the plots with their axes, ticks and units on the right, both sized again when the window
is), follows changes of `#pose=I`, plays at a chosen speed, and with `--forces`,
`--centres` draws the force arrows and instant centres (views/forces.py).

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(ground={"O": (0, 0)},
...     links=[kincas.Link.bar("crank", "O", "A", 1), kincas.Link.bar("rod", "A", "B", 3)],
...     slides=[kincas.Slide("B", "ground", name="slider")],
...     inputs=[kincas.Input.angle("crank")], guess={"B": (3.5, 0)})
>>> sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 2 * np.pi, 9)}, report=["B.x"])
>>> page = html_page(m, sw)
>>> page.startswith("<!DOCTYPE html>") and "<script src" not in page and "http" not in page
True
"""
from __future__ import annotations

import json
from importlib import resources

import numpy as np

from ..model.mechanism import Mechanism
from ..results import Sweep
from .page_parts import _arr, _centres, _forces, _joints, _labels, _wrap
from .picture import INK, picture  # noqa: F401

MAX_FRAMES = 2000  # poses kept in the page (evenly spread) so that it stays small
WIDTH, HEIGHT = 640, 480  # the mechanism's canvas, CSS pixels


def page_data(m: Mechanism, sweep: Sweep, scene=None, paths=None, dense: int = 0,
              view: str | None = None, *, forces: bool = False, centres: bool = False) -> dict:
    """Everything the page draws, as JSON-ready lists (scene units when a scene is given);
    `forces`, `centres`: arrows and instant centres per pose (views/forces.py, planar only);
    a spatial mechanism's in space, with the `camera` the page opens with (`html3d.camera`)."""
    from .columns import heading, quantity_unit, user_columns, _abscissa, _units_of
    pic = picture(m, sweep, paths, dense, view, world=True, forces=forces, centres=centres)
    spatial = pic.xy.shape[-1] == 3
    n = len(sweep)
    keep = np.unique(np.round(np.linspace(0, n - 1, min(n, MAX_FRAMES))).astype(int)) if n else np.zeros(0, int)
    inputs, values = user_columns(sweep, scene)
    values = {k: v for k, v in values.items() if k not in inputs}
    xkey, x = _abscissa(sweep, inputs)
    units = scene.study.units.get("length", "") if scene is not None else ""
    box = pic.box()
    unit = lambda k: quantity_unit(_units_of(scene), k)  # noqa: E731
    shown = lambda k, v: f"{k} = {v:.6g}" + ("°" if unit(k) == "deg" else f" {unit(k)}" if unit(k) else "")  # noqa: E731
    caption = [", ".join(shown(k, float(v[i])) for k, v in inputs.items())
               + ("" if sweep.status[i] == "ok" else f" ({sweep.status[i]})") for i in keep]
    out = {
        "title": (getattr(getattr(scene, "study", None), "title", "") or "kincas"),
        "springs": [{"label": label, "a": a, "b": b} for label, a, b in pic.springs],
        "forces": _forces(pic, keep), "centres": _centres(pic, keep),
        "labels": [] if spatial else _labels(pic, keep),  # names in free space: planar pictures
        "units": units, "names": pic.names, "ground": pic.ground, "r": pic.r,
        "box": _arr(box), "ok": [bool(v) for v in sweep.ok[keep]],
        "xy": _arr(pic.xy[keep]), "caption": caption, "poses": [int(i) for i in keep],
        "bodies": [{"name": b.name, "ring": b.ring, "colour": b.colour, "driven": b.driven}
                   for b in pic.bodies],
        "guides": [{"name": g.name, "point": g.point, "ground": g.ground, "colour": g.colour,
                    "lo": g.lo, "hi": g.hi, "through": _arr(g.through[keep]),
                    "direction": _arr(g.direction[keep])} for g in pic.guides],
        "paths": {p: _arr(v) for p, v in pic.paths.items()},
        "joints": _joints(pic, keep),
        "x": {"name": xkey or "pose", "unit": unit(xkey) if xkey else "", "values": _arr(x[keep])},
        "quantities": [{"name": k, "unit": unit(k), "heading": heading(k, scene),
                        "values": _arr(np.asarray(v, float)[keep]), "wrap": _wrap(k, unit(k))}
                       for k, v in values.items()],
    }
    if spatial:
        from .html3d import camera
        from .projection import check_view
        out.update(camera(check_view(view, True)))
    return out


def html_page(m: Mechanism, sweep: Sweep, scene=None, paths=None, dense: int = 0,
              view: str | None = None, *, forces: bool = False, centres: bool = False) -> str:
    """The page as text (a spatial mechanism's turns with the mouse, opening in `view`)."""
    data = page_data(m, sweep, scene, paths, dense, view, forces=forces, centres=centres)
    page = _PAGE
    if "camera" in data:  # a spatial mechanism: the view that turns (views/html3d.py)
        from .html3d import MECHANISM_3D
        page = _HEAD + DRAW_JS + MECHANISM_3D + _TAIL
    data = json.dumps(data, allow_nan=False, separators=(",", ":"))
    data = data.replace("</", "<\\/")  # nothing in the data may close the script element
    return (page.replace("@W@", str(WIDTH)).replace("@H@", str(HEIGHT)).replace("@INK@", INK)
            .replace("@DATA@", data))


def write_html(path, m: Mechanism, sweep: Sweep, scene=None, paths=None, dense: int = 0,
               view: str | None = None, **kw) -> None:
    """Write the page to `path` (`kw`: forces, centres)."""
    from .atomic import open_replacing
    with open_replacing(path, "w", encoding="utf-8") as f:
        f.write(html_page(m, sweep, scene, paths, dense, view, **kw))


_HEAD = r"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1">
<title>kincas</title>
<style>
html, body { height: 100%; }
body { font: 13px sans-serif; margin: 0; color: #222; display: flex; flex-direction: column; overflow: hidden; }
#head { padding: 4px 10px; border-bottom: 1px solid #ddd; }
#head h1 { font-size: 16px; margin: 0; display: inline; }
#head .units { color: #666; margin-left: 10px; }
#main { flex: 1; display: flex; min-height: 0; }
#left { display: flex; flex-direction: column; flex: 3 1 0; min-width: 0; }
#stage { flex: 1; min-height: 0; position: relative; }
#mech { position: absolute; left: 0; top: 0; }
#controls { padding: 6px 8px; border-top: 1px solid #ddd; }
#controls input[type=range] { width: 50%; vertical-align: middle; }
#caption { margin-top: 4px; }
#right { flex: 2 1 0; min-width: 0; overflow-y: auto; border-left: 1px solid #ddd; }
#errors { color: #b00; white-space: pre-wrap; margin: 0; }
</style></head>
<body data-pose="-1">
<div id="head"><h1 id="title"></h1><span class="units" id="units"></span></div>
<div id="main">
<div id="left"><div id="stage"><canvas id="mech" width="@W@" height="@H@"></canvas></div>
<div id="controls"><button id="play">play</button>
<input id="slider" type="range" min="0" max="0" value="0" step="1">
<span id="pose"></span>
<label>speed <select id="speed"><option value="0.25">0.25x</option><option value="0.5">0.5x</option>
<option value="1" selected>1x</option><option value="2">2x</option><option value="4">4x</option></select></label>
<div id="caption"></div></div></div>
<div id="right"><canvas id="plots" width="420" height="@H@"></canvas></div>
</div>
<pre id="errors"></pre>
<script>
"use strict";
window.onerror = function (msg, src, line) {
  document.getElementById("errors").textContent += "error: " + msg + " (line " + line + ")\n";
  document.title = "ERROR: " + msg;
};
const D = @DATA@;
const mech = document.getElementById("mech"), ctx = mech.getContext("2d");
const plots = document.getElementById("plots"), pctx = plots.getContext("2d");
const slider = document.getElementById("slider"), play = document.getElementById("play");
const speed = document.getElementById("speed"), stage = document.getElementById("stage");
const N = D.xy.length;
slider.max = Math.max(N - 1, 0);
document.title = D.title;
document.getElementById("title").textContent = D.title;
document.getElementById("units").textContent =
  (D.units ? "lengths in " + D.units : "") + (D.x.unit ? (D.units ? ", " : "") + D.x.name + " in " + D.x.unit : "");
"""
# a planar mechanism's drawing; a spatial one's is views/html3d.MECHANISM_3D (it defines the same
# layout(), drawMechanism(i), W, H and R, which _TAIL uses)
_MECHANISM = r"""// world -> canvas: equal scales, the whole sweep in view; set again when the window changes
const bx = D.box;
let W = mech.width, H = mech.height, sx = 1, ox = 0, oy = 0, R = 1;
function layout() {
  W = mech.width = Math.max(200, stage.clientWidth);
  H = mech.height = Math.max(150, stage.clientHeight);
  sx = Math.min(W / (bx[1][0] - bx[0][0]), H / (bx[1][1] - bx[0][1]));
  ox = W / 2 - sx * (bx[0][0] + bx[1][0]) / 2; oy = H / 2 + sx * (bx[0][1] + bx[1][1]) / 2;
  const at = mech.getBoundingClientRect();  // published in the page's pixels
  document.body.dataset.transform = sx + " " + (ox + at.left + window.scrollX) + " " + (oy + at.top + window.scrollY);
  R = D.r * sx;
  document.body.dataset.window = window.innerWidth + "x" + window.innerHeight;
  plots.width = Math.max(260, document.getElementById("right").clientWidth - 4);
}
const X = p => ox + sx * p[0], Y = p => oy - sx * p[1];
const fin = p => p !== null && p[0] !== null && p[1] !== null;

const canvasOf = p => fin(p) ? [X(p), Y(p)] : null;  // (the shapes: views/draw.js)
const line = (pts, colour, width, dash) => kPolyline(ctx, pts.map(canvasOf), colour, width, dash);
function zigzag(a, b) {  // a spring from a to b, as the other pictures draw it
  const dx = b[0] - a[0], dy = b[1] - a[1], n = Math.hypot(dx, dy);
  if (!(n > 0)) return [a, b];
  const ux = dx / n, uy = dy / n, wx = -uy, wy = ux, out = [a, [a[0] + 0.15 * dx, a[1] + 0.15 * dy]];
  for (let k = 0; k < 12; k++) {
    const t = 0.15 + 0.7 * (k + 0.5) / 12, s = 0.75 * D.r * (k % 2 ? -1 : 1);
    out.push([a[0] + t * dx + s * wx, a[1] + t * dy + s * wy]);
  }
  out.push([a[0] + 0.85 * dx, a[1] + 0.85 * dy], b);
  return out;
}

function drawMechanism(i) {
  ctx.fillStyle = "white"; ctx.fillRect(0, 0, W, H);
  const xy = D.xy[i];
  const owner = {};
  for (const b of D.bodies) for (const k of b.ring) if (!(k in owner)) owner[k] = b.colour;
  for (const [p, pts] of Object.entries(D.paths)) {
    line(pts, owner[D.names.indexOf(p)] || "@INK@", 1, [5, 4]);
  }
  for (const k of D.ground) {  // a pivot on a hatched base
    const p = xy[k]; if (fin(p)) kPivot(ctx, X(p), Y(p), R, "@INK@");
  }
  for (const g of D.guides) {
    const t = g.through[i], d = g.direction[i];
    if (!fin(t) || !fin(d)) continue;
    const a = [t[0] + g.lo * d[0], t[1] + g.lo * d[1]], b = [t[0] + g.hi * d[0], t[1] + g.hi * d[1]];
    line([a, b], g.colour, 1.2);
    const p = xy[g.point];
    if (fin(p)) kBlock(ctx, X(p), Y(p), -Math.atan2(d[1], d[0]), R, "@INK@");  // the block
  }
  for (const c of D.joints[i] || []) {  // gears, racks, cams; circles drawn round
    if (c.circle) {
      const [cx, cy, r] = c.circle; if (cx === null || cy === null) continue;
      ctx.beginPath(); ctx.arc(X([cx, cy]), Y([cx, cy]), r * sx, 0, 2 * Math.PI);
      ctx.strokeStyle = c.colour; ctx.lineWidth = 1.2; ctx.stroke();
    } else if (c.pts.length === 1) {
      const p = c.pts[0]; if (!fin(p)) continue;
      ctx.beginPath(); ctx.arc(X(p), Y(p), 3, 0, 2 * Math.PI); ctx.fillStyle = c.colour; ctx.fill();
    } else line(c.pts, c.colour, 1.2);
  }
  for (const s of D.springs) {
    if (fin(xy[s.a]) && fin(xy[s.b])) line(zigzag(xy[s.a], xy[s.b]), "#9467bd", 1.2);
  }
  const order = D.bodies.filter(b => !b.driven).concat(D.bodies.filter(b => b.driven));
  for (const b of order) {
    const pts = b.ring.map(k => xy[k]);
    if (pts.every(fin)) kBody(ctx, pts.map(canvasOf), b.colour);
  }
  for (const f of D.forces[i] || []) {  // arrows: loads, springs, efforts, reactions
    line(f.pts, f.colour, 1.8);
    ctx.beginPath(); f.head.forEach((p, j) => j ? ctx.lineTo(X(p), Y(p)) : ctx.moveTo(X(p), Y(p)));
    ctx.closePath(); ctx.fillStyle = f.colour; ctx.fill();
  }
  for (const c of D.centres[i] || []) {  // instant centres: a cross and the link's name
    const x = X(c.p), y = Y(c.p);
    ctx.beginPath(); ctx.moveTo(x - 5, y - 5); ctx.lineTo(x + 5, y + 5); ctx.moveTo(x - 5, y + 5); ctx.lineTo(x + 5, y - 5);
    ctx.strokeStyle = "#111"; ctx.lineWidth = 2; ctx.stroke();
    ctx.fillStyle = "#111"; ctx.font = "10px sans-serif"; ctx.fillText("I " + c.label, x + 6, y + 12);
  }
  ctx.textAlign = "center"; ctx.textBaseline = "middle";
  for (let k = 0; k < D.names.length; k++) {  // joints and points, with their names in free space
    const p = xy[k]; if (!fin(p)) continue;
    kJoint(ctx, X(p), Y(p), 4, "white", "@INK@");
    const off = (D.labels[i] || [])[k];
    const at = fin(off) ? [p[0] + off[0], p[1] + off[1]] : [p[0] + 2 * D.r, p[1] + 2 * D.r];
    ctx.fillStyle = "@INK@"; ctx.font = "11px sans-serif"; ctx.fillText(D.names[k], X(at), Y(at));
  }
  ctx.textAlign = "start"; ctx.textBaseline = "alphabetic";
}

"""
# the quantities against the input, the slider and play button: both pages (views/html3d.py)
_TAIL = r"""// the quantities against the input, one panel each with its axes, a cursor at the slider's pose
function extent(v) {
  let lo = Infinity, hi = -Infinity;
  for (const a of v) if (a !== null) { lo = Math.min(lo, a); hi = Math.max(hi, a); }
  if (!isFinite(lo)) return [0, 1];
  if (hi - lo <= 1e-9 * Math.max(Math.abs(lo), Math.abs(hi), 1e-300)) {
    const c = lo, pad = c !== 0 ? 0.05 * Math.abs(c) : 1; lo = c - pad; hi = c + pad;
  }
  return [lo, hi];
}
function ticks(lo, hi, most) {  // round values 1, 2 or 5 x 10^k apart, at most `most`
  const raw = (hi - lo) / Math.max(most, 1), mag = Math.pow(10, Math.floor(Math.log10(raw)));
  const step = [1, 2, 5, 10].map(k => k * mag).find(s => s >= raw) || raw;
  const out = [];
  for (let t = Math.ceil(lo / step) * step; t <= hi + 1e-9 * step; t += step) out.push(Math.abs(t) < 1e-12 * step ? 0 : t);
  return out;
}
const fmt = v => Number(v.toPrecision(6)).toString();
const QH = 130, TOP = 8, LEFT = 62;
function drawPlots(i) {
  const need = TOP + QH * D.quantities.length + 40;
  if (plots.height !== need) plots.height = need;
  pctx.fillStyle = "white"; pctx.fillRect(0, 0, plots.width, plots.height);
  const xs = D.x.values, [x0, x1] = extent(xs);
  const L = LEFT, Rr = plots.width - 12;
  const PX = v => L + (Rr - L) * (v - x0) / (x1 - x0);
  const xt = ticks(x0, x1, Math.max(2, Math.floor((Rr - L) / 70)));
  pctx.font = "10px sans-serif";
  D.quantities.forEach((q, j) => {
    const top = TOP + j * QH + 16, bot = TOP + (j + 1) * QH - 18, [y0, y1] = extent(q.values);
    const PY = v => bot - (bot - top) * (v - y0) / (y1 - y0);
    pctx.fillStyle = "#222"; pctx.font = "11px sans-serif"; pctx.textAlign = "left";
    const v = q.values[i];
    pctx.fillText(q.name + (q.unit ? " [" + q.unit + "]" : "") + " = " + (v === null ? "-" : fmt(v)), L, top - 4);
    pctx.font = "10px sans-serif";
    pctx.strokeStyle = "#eee"; pctx.lineWidth = 1; pctx.textAlign = "right"; pctx.textBaseline = "middle";
    for (const t of ticks(y0, y1, 4)) {  // y ticks with their values, a light grid
      const y = PY(t); pctx.beginPath(); pctx.moveTo(L, y); pctx.lineTo(Rr, y); pctx.stroke();
      pctx.fillStyle = "#444"; pctx.fillText(fmt(t), L - 4, y);
    }
    pctx.textAlign = "center"; pctx.textBaseline = "top";
    for (const t of xt) {  // x ticks
      const x = PX(t); pctx.beginPath(); pctx.moveTo(x, top); pctx.lineTo(x, bot); pctx.stroke();
      pctx.fillStyle = "#444"; pctx.fillText(fmt(t), x, bot + 2);
    }
    pctx.textAlign = "left"; pctx.textBaseline = "alphabetic";
    pctx.strokeStyle = "#888"; pctx.strokeRect(L, top, Rr - L, bot - top);
    pctx.beginPath(); pctx.strokeStyle = "#1f77b4"; pctx.lineWidth = 1.4;
    let pen = false, last = null;
    q.values.forEach((v, k) => {
      if (v === null || xs[k] === null) { pen = false; return; }
      if (pen && q.wrap !== null && Math.abs(v - last) > q.wrap) pen = false;  // an angle wrapping round
      if (pen) pctx.lineTo(PX(xs[k]), PY(v)); else pctx.moveTo(PX(xs[k]), PY(v));
      pen = true; last = v;
    });
    pctx.stroke();
    if (xs[i] !== null) {  // the cursor
      pctx.beginPath(); pctx.strokeStyle = "#d62728"; pctx.lineWidth = 1;
      pctx.moveTo(PX(xs[i]), top); pctx.lineTo(PX(xs[i]), bot); pctx.stroke();
      if (v !== null) { pctx.beginPath(); pctx.arc(PX(xs[i]), PY(v), 3, 0, 2 * Math.PI); pctx.fillStyle = "#d62728"; pctx.fill(); }
    }
  });
  pctx.fillStyle = "#222"; pctx.font = "11px sans-serif"; pctx.textAlign = "center";
  pctx.fillText(D.x.name + (D.x.unit ? " [" + D.x.unit + "]" : ""), (L + Rr) / 2, plots.height - 12);
  pctx.textAlign = "left";
}

let current = 0;
function show(i) {
  i = Math.max(0, Math.min(N - 1, i | 0));
  current = i; slider.value = i;
  drawMechanism(i); drawPlots(i);
  document.getElementById("pose").textContent = "pose " + D.poses[i] + " of " + (D.poses[N - 1] + 1);
  document.getElementById("caption").textContent = D.caption[i];
  document.body.dataset.pose = D.poses[i];
}
let timer = null, clock = 0;
function step(now) {  // about 20 poses a second at 1x
  if (!timer) return;
  if (now - clock >= 50 / (+speed.value)) { clock = now; show((current + 1) % N); }
  timer = requestAnimationFrame(step);
}
play.onclick = function () {
  if (timer) { cancelAnimationFrame(timer); timer = null; play.textContent = "play"; return; }
  play.textContent = "pause"; clock = 0; timer = requestAnimationFrame(step);
};
slider.oninput = () => show(+slider.value);
function fromHash() {  // #pose=I: the sweep's pose index; the nearest kept frame
  const wanted = /pose=(-?\d+)/.exec(location.hash);
  if (!wanted) return 0;
  const w = +wanted[1], target = w < 0 ? D.poses[N - 1] + 1 + w : w;
  let best = 0;
  D.poses.forEach((p, k) => { if (Math.abs(p - target) < Math.abs(D.poses[best] - target)) best = k; });
  return best;
}
window.addEventListener("hashchange", () => { if (N) show(fromHash()); });
window.addEventListener("resize", () => { layout(); if (N) show(current); });
layout();
if (N) show(fromHash());
</script></body></html>
"""
# the shapes every page draws alike (views/draw.js, shared with `kincas app`), inlined: the page
# works offline
DRAW_JS = resources.files(__package__).joinpath("draw.js").read_text(encoding="utf-8")
_PAGE = _HEAD + DRAW_JS + _MECHANISM + _TAIL
