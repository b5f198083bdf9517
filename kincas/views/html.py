"""`kincas solve SCENE --html out.html`: one self-contained page (no network: its script is
inline) with the mechanism animated on a canvas, a slider and a play button to scrub the
poses, the paths of its points, and every reported quantity plotted against the input with
a cursor that follows the slider.

The page opens at pose 0, or at `#pose=I`. It keeps in its DOM what a test (or a curious
user) may read: `<body data-pose=I data-transform="sx ox oy">` (a world point (x, y) is drawn
at canvas pixel (ox + sx x, oy - sx y)) and `<pre id="errors">` collecting any JavaScript
error, which also goes into the title.

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
import math

import numpy as np

from ..model.mechanism import Mechanism
from ..results import Sweep
from .picture import INK, picture

MAX_FRAMES = 2000  # poses kept in the page (evenly spread) so that it stays small
WIDTH, HEIGHT = 640, 480  # the mechanism's canvas, CSS pixels


def _num(v, digits=9):
    """A JSON number (None for NaN), to `digits` significant digits."""
    v = float(v)
    return None if not math.isfinite(v) else float(f"{v:.{digits}g}")


def _arr(a, digits=9):
    a = np.asarray(a, float)
    if a.ndim == 0:
        return _num(a, digits)
    return [_arr(x, digits) for x in a]


def page_data(m: Mechanism, sweep: Sweep, scene=None, paths=None, dense: int = 0,
              view: str | None = None) -> dict:
    """Everything the page draws, as JSON-ready lists (scene units when a scene is given); a
    spatial mechanism's in space, with the `camera` the page opens with (`html3d.camera`)."""
    from .columns import heading, user_columns, _abscissa
    pic = picture(m, sweep, paths, dense, view, world=True)
    n = len(sweep)
    keep = np.unique(np.round(np.linspace(0, n - 1, min(n, MAX_FRAMES))).astype(int)) if n else np.zeros(0, int)
    inputs, values = user_columns(sweep, scene)
    values = {k: v for k, v in values.items() if k not in inputs}
    xkey, x = _abscissa(sweep, inputs)
    units = scene.study.units.get("length", "") if scene is not None else ""
    box = pic.box()
    caption = [", ".join(f"{k} = {float(v[i]):.6g}" for k, v in inputs.items())
               + ("" if sweep.status[i] == "ok" else f" ({sweep.status[i]})") for i in keep]
    out = {
        "title": (getattr(getattr(scene, "study", None), "title", "") or "kincas"),
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
        "x": {"name": heading(xkey, scene) if xkey else "pose", "values": _arr(x[keep])},
        "quantities": [{"name": heading(k, scene), "values": _arr(np.asarray(v)[keep])}
                       for k, v in values.items()],
    }
    if pic.xy.shape[-1] == 3:
        from .html3d import camera
        from .projection import check_view
        out.update(camera(check_view(view, True)))
    return out


def _joints(pic, keep) -> list:
    """Per kept pose, the gears', racks' and cams' polylines (views/draw_joints.py), coarser
    than in the other pictures so that the page stays small: [{colour, pts}]."""
    colours = {b.name: b.colour for b in pic.bodies}
    return [[{"colour": "#c0392b" if len(a) == 1 else colours.get(body, INK), "pts": _arr(a, 7)}
             for _, body, a in pic.joint_curves(int(i), 41)] for i in keep]


def html_page(m: Mechanism, sweep: Sweep, scene=None, paths=None, dense: int = 0,
              view: str | None = None) -> str:
    """The page as text (a spatial mechanism's turns with the mouse, opening in `view`)."""
    data = page_data(m, sweep, scene, paths, dense, view)
    page = _PAGE
    if "camera" in data:  # a spatial mechanism: the view that turns (views/html3d.py)
        from .html3d import MECHANISM_3D
        page = _HEAD + MECHANISM_3D + _TAIL
    data = json.dumps(data, allow_nan=False, separators=(",", ":"))
    data = data.replace("</", "<\\/")  # nothing in the data may close the script element
    return (page.replace("@W@", str(WIDTH)).replace("@H@", str(HEIGHT)).replace("@INK@", INK)
            .replace("@DATA@", data))


def write_html(path, m: Mechanism, sweep: Sweep, scene=None, paths=None, dense: int = 0,
               view: str | None = None) -> None:
    """Write the page to `path`."""
    from .atomic import open_replacing
    with open_replacing(path, "w", encoding="utf-8") as f:
        f.write(html_page(m, sweep, scene, paths, dense, view))


_HEAD = r"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>kincas</title>
<style>
body { font: 13px sans-serif; margin: 0; color: #222; }
#mech { position: absolute; left: 0; top: 0; border-bottom: 1px solid #ddd; }
#controls { position: absolute; left: 0; top: @H@px; width: @W@px; padding: 6px 8px; box-sizing: border-box; }
#controls input[type=range] { width: 420px; vertical-align: middle; }
#caption { margin-top: 4px; }
#plots { position: absolute; left: @W@px; top: 0; }
#errors { position: absolute; left: 0; top: 560px; color: #b00; white-space: pre-wrap; }
</style></head>
<body data-pose="-1">
<canvas id="mech" width="@W@" height="@H@"></canvas>
<div id="controls"><button id="play">play</button>
<input id="slider" type="range" min="0" max="0" value="0" step="1">
<span id="pose"></span><div id="caption"></div></div>
<canvas id="plots" width="420" height="@H@"></canvas>
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
const N = D.xy.length;
slider.max = Math.max(N - 1, 0);
document.title = D.title;
"""
_MECHANISM = r"""// world -> canvas: equal scales, the whole sweep in view
const W = mech.width, H = mech.height, bx = D.box;
const sx = Math.min(W / (bx[1][0] - bx[0][0]), H / (bx[1][1] - bx[0][1]));
const ox = W / 2 - sx * (bx[0][0] + bx[1][0]) / 2, oy = H / 2 + sx * (bx[0][1] + bx[1][1]) / 2;
document.body.dataset.transform = sx + " " + ox + " " + oy;
const X = p => ox + sx * p[0], Y = p => oy - sx * p[1];
const fin = p => p !== null && p[0] !== null && p[1] !== null;
const R = D.r * sx;

function line(pts, colour, width, dash) {
  ctx.beginPath(); ctx.setLineDash(dash || []); ctx.strokeStyle = colour; ctx.lineWidth = width;
  let pen = false;
  for (const p of pts) {
    if (!fin(p)) { pen = false; continue; }
    if (pen) ctx.lineTo(X(p), Y(p)); else ctx.moveTo(X(p), Y(p));
    pen = true;
  }
  ctx.stroke(); ctx.setLineDash([]);
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
    const p = xy[k]; if (!fin(p)) continue;
    const x = X(p), y = Y(p), h = 2.5 * R;
    ctx.beginPath(); ctx.moveTo(x, y); ctx.lineTo(x - 0.7 * h, y + h); ctx.lineTo(x + 0.7 * h, y + h);
    ctx.closePath(); ctx.fillStyle = "#dddddd"; ctx.fill(); ctx.strokeStyle = "@INK@"; ctx.lineWidth = 1; ctx.stroke();
  }
  for (const g of D.guides) {
    const t = g.through[i], d = g.direction[i];
    if (!fin(t) || !fin(d)) continue;
    const a = [t[0] + g.lo * d[0], t[1] + g.lo * d[1]], b = [t[0] + g.hi * d[0], t[1] + g.hi * d[1]];
    line([a, b], g.colour, 1.2);
    const p = xy[g.point];
    if (fin(p)) {  // the block
      ctx.save(); ctx.translate(X(p), Y(p)); ctx.rotate(-Math.atan2(d[1], d[0]));
      ctx.fillStyle = "#f2f2f2"; ctx.strokeStyle = "@INK@"; ctx.lineWidth = 1.2;
      ctx.fillRect(-2 * R, -1.4 * R, 4 * R, 2.8 * R); ctx.strokeRect(-2 * R, -1.4 * R, 4 * R, 2.8 * R);
      ctx.restore();
    }
  }
  for (const c of D.joints[i] || []) {  // gears, racks, cams
    if (c.pts.length === 1) {
      const p = c.pts[0]; if (!fin(p)) continue;
      ctx.beginPath(); ctx.arc(X(p), Y(p), 3, 0, 2 * Math.PI); ctx.fillStyle = c.colour; ctx.fill();
    } else line(c.pts, c.colour, 1.2);
  }
  const order = D.bodies.filter(b => !b.driven).concat(D.bodies.filter(b => b.driven));
  for (const b of order) {
    const pts = b.ring.map(k => xy[k]);
    if (!pts.every(fin)) continue;
    if (pts.length >= 3) {
      ctx.beginPath(); pts.forEach((p, j) => j ? ctx.lineTo(X(p), Y(p)) : ctx.moveTo(X(p), Y(p)));
      ctx.closePath(); ctx.globalAlpha = 0.45; ctx.fillStyle = b.colour; ctx.fill(); ctx.globalAlpha = 1;
      ctx.strokeStyle = b.colour; ctx.lineWidth = 2.5; ctx.stroke();
    } else {
      ctx.lineCap = "round"; line(pts, b.colour, 7); ctx.lineCap = "butt";
    }
  }
  for (let k = 0; k < D.names.length; k++) {  // joints and points, with their names
    const p = xy[k]; if (!fin(p)) continue;
    ctx.beginPath(); ctx.arc(X(p), Y(p), 4, 0, 2 * Math.PI);
    ctx.fillStyle = "white"; ctx.fill(); ctx.strokeStyle = "@INK@"; ctx.lineWidth = 1.3; ctx.stroke();
    ctx.fillStyle = "@INK@"; ctx.font = "11px sans-serif"; ctx.fillText(D.names[k], X(p) + 7, Y(p) - 7);
  }
}

"""
# the quantities against the input, the slider and play button: both pages (views/html3d.py)
_TAIL = r"""// the quantities against the input, one panel each, a cursor at the slider's pose
const QH = Math.max(60, Math.min(120, Math.floor((plots.height - 20) / Math.max(D.quantities.length, 1))));
plots.height = Math.max(plots.height, 20 + QH * D.quantities.length);
function extent(v) {
  let lo = Infinity, hi = -Infinity;
  for (const a of v) if (a !== null) { lo = Math.min(lo, a); hi = Math.max(hi, a); }
  if (!isFinite(lo)) return [0, 1];
  if (hi - lo <= 1e-12 * Math.max(Math.abs(lo), Math.abs(hi), 1e-300)) { const c = lo; lo = c - 1; hi = c + 1; }
  return [lo, hi];
}
function drawPlots(i) {
  pctx.fillStyle = "white"; pctx.fillRect(0, 0, plots.width, plots.height);
  const xs = D.x.values, [x0, x1] = extent(xs);
  const L = 10, Rr = plots.width - 10;
  const PX = v => L + (Rr - L) * (v - x0) / (x1 - x0);
  D.quantities.forEach((q, j) => {
    const top = 10 + j * QH, bot = top + QH - 22, [y0, y1] = extent(q.values);
    const PY = v => bot - (bot - top) * (v - y0) / (y1 - y0);
    pctx.strokeStyle = "#ddd"; pctx.lineWidth = 1; pctx.strokeRect(L, top, Rr - L, bot - top);
    pctx.beginPath(); pctx.strokeStyle = "#1f77b4"; pctx.lineWidth = 1.4;
    let pen = false;
    q.values.forEach((v, k) => {
      if (v === null || xs[k] === null) { pen = false; return; }
      if (pen) pctx.lineTo(PX(xs[k]), PY(v)); else pctx.moveTo(PX(xs[k]), PY(v));
      pen = true;
    });
    pctx.stroke();
    pctx.fillStyle = "#222"; pctx.font = "11px sans-serif";
    const v = q.values[i];
    pctx.fillText(q.name + " = " + (v === null ? "-" : Number(v.toPrecision(6))), L + 4, bot + 13);
    if (xs[i] !== null) {  // the cursor
      pctx.beginPath(); pctx.strokeStyle = "#d62728"; pctx.lineWidth = 1;
      pctx.moveTo(PX(xs[i]), top); pctx.lineTo(PX(xs[i]), bot); pctx.stroke();
      if (v !== null) { pctx.beginPath(); pctx.arc(PX(xs[i]), PY(v), 3, 0, 2 * Math.PI); pctx.fillStyle = "#d62728"; pctx.fill(); }
    }
  });
  pctx.fillStyle = "#222"; pctx.fillText("against " + D.x.name, L, plots.height - 4);
}

function show(i) {
  i = Math.max(0, Math.min(N - 1, i | 0));
  slider.value = i;
  drawMechanism(i); drawPlots(i);
  document.getElementById("pose").textContent = "pose " + D.poses[i] + " of " + (D.poses[N - 1] + 1);
  document.getElementById("caption").textContent = D.caption[i];
  document.body.dataset.pose = D.poses[i];
}
let timer = null;
play.onclick = function () {
  if (timer) { clearInterval(timer); timer = null; play.textContent = "play"; return; }
  play.textContent = "pause";
  timer = setInterval(() => show((+slider.value + 1) % N), 50);
};
slider.oninput = () => show(+slider.value);
const wanted = /pose=(-?\d+)/.exec(location.hash);
let start = 0;
if (wanted) {  // the sweep's pose index; the nearest kept frame
  const w = +wanted[1], target = w < 0 ? D.poses[N - 1] + 1 + w : w;
  let best = 0;
  D.poses.forEach((p, k) => { if (Math.abs(p - target) < Math.abs(D.poses[best] - target)) best = k; });
  start = best;
}
if (N) show(start);
</script></body></html>
"""
_PAGE = _HEAD + _MECHANISM + _TAIL
