"""The `--html` page of a spatial mechanism: the same page as a planar one's
(`kincas.views.html`: slider, play button, the quantities plotted with a cursor), whose
mechanism view turns with the mouse. Written in plain JavaScript on a canvas, inline in the
page (no network, no library: it works from file://).

- drag: orbit (left-right turns the mechanism about the world axis drawn upwards in the
  view it opened in, up-down tilts it about the screen's horizontal);
- wheel: zoom; shift-drag: pan; double-click, or the buttons iso / xy / yz / zx: that view.

The projection is orthographic, as in `kincas.views.projection`: the camera's rows are the
drawing's right and up directions and the direction towards the viewer; bodies are drawn
farthest first. For a test, the page keeps in its DOM `data-camera` (the rows, JSON) and
`data-transform="s ox oy"`: a world point p is drawn at the page's pixel
(ox + s (right . p), oy - s (up . p)).

>>> c = camera("iso")
>>> [round(v, 6) for v in c["camera"][2]], c["up"], sorted(c["views"])
([0.57735, 0.57735, 0.57735], 2, ['iso', 'xy', 'yz', 'zx'])
"""
from __future__ import annotations

from importlib import resources

from .projection import UP_AXIS, VIEWS, axes

ORBIT_JS = resources.files(__package__).joinpath("orbit.js").read_text(encoding="utf-8")


def camera(view: str) -> dict:
    """What the page needs to open in `view` and to go to the others: `camera` (rows right,
    up, toward the viewer), `up` (the index of the world axis it turns about), `views` (every
    view's camera) and `view`."""
    return {"camera": axes(view).tolist(), "up": UP_AXIS[view], "view": view,
            "views": {v: axes(v).tolist() for v in VIEWS}, "ups": dict(UP_AXIS)}


# Replaces the planar page's `drawMechanism` (views/html.py: _HEAD + this + _TAIL); the camera's
# turning is views/orbit.js, shared with the live page of `kincas app`.
MECHANISM_3D = ORBIT_JS + r"""// a spatial mechanism, orthographic, turned with the mouse
const bx = D.box;
let W = mech.width, H = mech.height;
const C0 = [0, 1, 2].map(j => (bx[0][j] + bx[1][j]) / 2);
const fin = p => p !== null && p[0] !== null && p[1] !== null && p[2] !== null;
// the sphere about the box's centre holding every point and path, with the picture's margin:
// the whole sweep stays in view at every angle
let RAD = 0;
for (const pts of D.xy.concat(Object.values(D.paths))) for (const p of pts) if (fin(p))
  RAD = Math.max(RAD, Math.hypot(p[0] - C0[0], p[1] - C0[1], p[2] - C0[2]));
for (const g of D.guides) g.through.forEach((t, i) => {
  const d = g.direction[i];
  if (fin(t) && fin(d)) for (const s of [g.lo, g.hi])
    RAD = Math.max(RAD, Math.hypot(t[0] + s * d[0] - C0[0], t[1] + s * d[1] - C0[1], t[2] + s * d[2] - C0[2]));
});
RAD = RAD > 0 ? RAD + 5 * D.r : 1;
const dot = kDot;
let cam = D.camera.map(r => r.slice()), up = D.up, zoom = 1, panX = 0, panY = 0;
let S = 0, OX = 0, OY = 0, R = 0;  // scale, origin, the picture's unit of size (pixels)
function frame() {  // world -> canvas of the current camera, published for tests
  S = zoom * 0.5 * Math.min(W, H) / RAD; R = D.r * S;
  OX = W / 2 + panX - S * dot(cam[0], C0); OY = H / 2 + panY + S * dot(cam[1], C0);
  const at = mech.getBoundingClientRect();  // published in the page's pixels
  document.body.dataset.transform = S + " " + (OX + at.left + window.scrollX) + " " + (OY + at.top + window.scrollY);
  document.body.dataset.camera = JSON.stringify(cam);
}
function layout() {  // the canvas fills its stage; set again when the window changes
  W = mech.width = Math.max(200, stage.clientWidth);
  H = mech.height = Math.max(150, stage.clientHeight);
  document.body.dataset.window = window.innerWidth + "x" + window.innerHeight;
  plots.width = Math.max(260, document.getElementById("right").clientWidth - 4);
  frame();
}
// a world point: canvas x, canvas y, depth (larger: farther from the viewer)
const P = p => [OX + S * dot(cam[0], p), OY - S * dot(cam[1], p), -dot(cam[2], p)];
const orbit = (dx, dy) => { cam = kOrbit(cam, up, dx, dy); };  // views/orbit.js
const line = (pts, colour, width, dash) => kPolyline(ctx, pts.map(p => fin(p) ? P(p) : null), colour, width, dash);
function triad() {  // the world axes, lower left
  const o = [38, H - 38], col = ["#d62728", "#2ca02c", "#1f77b4"];
  for (let j = 0; j < 3; j++) {
    const e = [o[0] + 26 * cam[0][j], o[1] - 26 * cam[1][j]];
    ctx.beginPath(); ctx.moveTo(o[0], o[1]); ctx.lineTo(e[0], e[1]);
    ctx.strokeStyle = col[j]; ctx.lineWidth = 2; ctx.stroke();
    ctx.fillStyle = col[j]; ctx.font = "11px sans-serif";
    ctx.fillText("xyz"[j], o[0] + 34 * cam[0][j] - 3, o[1] - 34 * cam[1][j] + 4);
  }
}

// each path in the colour of the first body its point belongs to
const pathColour = {};
for (const p of Object.keys(D.paths)) {
  const body = D.bodies.find(b => b.ring.includes(D.names.indexOf(p)));
  pathColour[p] = body ? body.colour : "@INK@";
}

function drawMechanism(i) {
  frame();
  ctx.fillStyle = "white"; ctx.fillRect(0, 0, W, H);
  const xy = D.xy[i];
  for (const [p, pts] of Object.entries(D.paths)) line(pts, pathColour[p], 1, [5, 4]);
  for (const k of D.ground) {  // a pivot on a base, upright on the screen
    const p = xy[k]; if (fin(p)) kPivot(ctx, P(p)[0], P(p)[1], R, "@INK@");
  }
  for (const g of D.guides) {
    const t = g.through[i], d = g.direction[i];
    if (!fin(t) || !fin(d)) continue;
    const a = [0, 1, 2].map(j => t[j] + g.lo * d[j]), b = [0, 1, 2].map(j => t[j] + g.hi * d[j]);
    line([a, b], g.colour, 1.2);
    const p = xy[g.point];
    if (fin(p)) {  // the block, along the guide as drawn
      const [x, y] = P(p), ea = P(a), eb = P(b);
      kBlock(ctx, x, y, Math.atan2(eb[1] - ea[1], eb[0] - ea[0]), R, "@INK@");
    }
  }
  for (const s of D.springs) {  // springs, straight
    if (fin(xy[s.a]) && fin(xy[s.b])) line([xy[s.a], xy[s.b]], "#9467bd", 1.2);
  }
  // the bodies, farthest first (by the mean depth of their points)
  const order = [];
  for (const b of D.bodies) {
    const pts = b.ring.map(k => xy[k]);
    if (!pts.every(fin)) continue;
    const q = pts.map(P);
    order.push([q.reduce((s, v) => s + v[2], 0) / q.length, b, q]);
  }
  order.sort((u, v) => v[0] - u[0]);
  for (const [, b, q] of order) kBody(ctx, q, b.colour);  // (views/draw.js)
  for (let k = 0; k < D.names.length; k++) {  // joints and points, with their names
    const p = xy[k]; if (!fin(p)) continue;
    const [x, y] = P(p);
    kJoint(ctx, x, y, 4, "white", "@INK@");
    ctx.fillStyle = "@INK@"; ctx.font = "11px sans-serif"; ctx.fillText(D.names[k], x + 7, y - 7);
  }
  triad();
}

// the mouse: drag to orbit, shift-drag to pan, wheel to zoom, double-click for the first view
const redraw = () => drawMechanism(Math.max(0, Math.min(N - 1, +slider.value)));
let drag = null;
mech.style.cursor = "grab"; mech.style.touchAction = "none";
mech.addEventListener("pointerdown", e => {
  drag = [e.clientX, e.clientY, e.shiftKey]; mech.setPointerCapture(e.pointerId); mech.style.cursor = "grabbing";
});
mech.addEventListener("pointermove", e => {
  if (!drag) return;
  const dx = e.clientX - drag[0], dy = e.clientY - drag[1];
  if (drag[2]) { panX += dx; panY += dy; } else orbit(dx, dy);
  drag = [e.clientX, e.clientY, drag[2]];
  redraw();
});
const release = () => { drag = null; mech.style.cursor = "grab"; };
mech.addEventListener("pointerup", release); mech.addEventListener("pointercancel", release);
mech.addEventListener("wheel", e => {
  e.preventDefault();
  zoom = Math.min(50, Math.max(0.05, zoom * Math.exp(-0.0015 * e.deltaY)));
  redraw();
}, { passive: false });
function look(v) { cam = D.views[v].map(r => r.slice()); up = D.ups[v]; zoom = 1; panX = 0; panY = 0; redraw(); }
mech.addEventListener("dblclick", () => look(D.view));
const bar = document.createElement("div");  // one button per view, on a line of their own
bar.id = "views"; bar.textContent = "view (drag to turn, wheel to zoom):";
bar.style.marginTop = "4px";
for (const v of Object.keys(D.views)) {
  const b = document.createElement("button");
  b.textContent = v; b.id = "view-" + v; b.style.marginLeft = "4px"; b.onclick = () => look(v);
  bar.appendChild(b);
}
document.getElementById("controls").insertBefore(bar, document.getElementById("caption"));
const wantView = /view=(iso|xy|yz|zx)/.exec(location.hash);
if (wantView) { cam = D.views[wantView[1]].map(r => r.slice()); up = D.ups[wantView[1]]; }
frame();
"""
