// kincas app: the live page of one mechanism (served by `kincas app`, or inside Jupyter by
// `kincas.widget`). Everything is drawn here from the server's state (docs/app.md); every edit
// goes to the server, which re-solves and answers with the new state. No request leaves for
// anywhere but the server (or the notebook kernel) that served the page.
//
// The element's dataset keeps what a test may read: data-version (the state shown),
// data-pose (the pose shown), data-busy ("1" while a request is out or waiting),
// data-transform "sx ox oy" (world (x, y) is drawn at canvas pixel (ox + sx x, oy - sx y)).
// A spatial mechanism (drawing.space) is drawn turned by a camera (views/orbit.js, inlined
// before this file, as views/draw.js is: the shapes every page draws, shared with the `--html`
// pages): its points relative to the box's centre c, projected on the camera's rows,
// (x, y) = (right . (p - c), up . (p - c)), are drawn as a planar one's; data-camera keeps the
// rows (JSON). The mouse turns it (drag) and zooms (wheel); its points are not dragged.
// Its loads and weights are projected the same way (an arrow keeps the force's own size), and
// its bodies are drawn farthest first, by the mean depth -(toward . (p - c)) of their points.
"use strict";

// requests over HTTP to the server that served the page
function kincasHttp(base) {
  async function answer(r) {
    const body = await r.json().catch(() => ({ error: r.statusText }));
    if (!r.ok) throw new Error(body.error || r.statusText);
    return body;
  }
  return {
    call(name, body) {
      if (name === "state") return fetch(base + "api/state").then(answer);
      return fetch(base + "api/" + name, {
        method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body || {}),
      }).then(answer);
    },
    toml: null,  // the download link fetches api/scene.toml itself
  };
}

function kincasApp(root, transport) {
  root.classList.add("kincas-app");
  root.innerHTML = `
<div class="k-head"><span class="k-title"></span><span class="k-message"></span></div>
<div class="k-main">
 <div class="k-left">
  <canvas class="k-mech" width="720" height="500"></canvas>
  <div class="k-bar">
   <button class="k-play" type="button">play</button>
   <label>speed <select class="k-speed"><option>0.25</option><option>0.5</option>
    <option selected>1</option><option>2</option><option>4</option></select></label>
   <input class="k-pose" type="range" min="0" max="0" step="1" value="0" aria-label="pose">
   <span class="k-posetext"></span>
  </div>
  <div class="k-bar">
   <label><input class="k-paths" type="checkbox" checked> paths</label>
   <label><input class="k-centres" type="checkbox"> instant centres</label>
   <label><input class="k-forces" type="checkbox"> forces</label>
   <button class="k-fit" type="button">fit view</button>
   <a class="k-download" href="api/scene.toml" download="scene.toml">download scene (TOML)</a>
  </div>
  <div class="k-controls"></div>
 </div>
 <div class="k-right">
  <table class="k-values"></table>
  <canvas class="k-plots" width="480" height="300"></canvas>
 </div>
</div>`;
  const $ = s => root.querySelector(s);
  const mech = $(".k-mech"), ctx = mech.getContext("2d");
  const plots = $(".k-plots"), pctx = plots.getContext("2d");
  const poseSlider = $(".k-pose"), controls = $(".k-controls"), message = $(".k-message");
  let S = null, good = null, pose = 0, view = null, timer = null;
  let busy = false, pending = null, dragging = null, error = "";
  let cam = null, camUp = 2, turning = null, flatCache = null;  // a spatial mechanism's camera
  const INK = "#222222";

  // --- requests: one at a time; edits made meanwhile are merged and sent when it returns ---
  function send(name, body) {
    if (busy) {
      if (pending && pending.name === "change" && name === "change") {
        pending.body = { parameters: { ...pending.body.parameters, ...body.parameters },
                         inputs: { ...pending.body.inputs, ...body.inputs } };
      } else pending = { name, body };
      return;
    }
    busy = true; root.dataset.busy = "1";
    transport.call(name, body).then(st => { error = ""; show(st); }, e => { error = String(e.message || e); showMessage(); })
      .finally(() => {
        busy = false;
        if (pending) { const p = pending; pending = null; send(p.name, p.body); }
        else root.dataset.busy = "0";
      });
  }
  function showMessage() {
    message.textContent = error || (S && S.message) || "";
    message.classList.toggle("k-error", !!error);
  }

  // --- the state ---
  function show(st) {
    const first = S === null;
    S = st;
    if (st.ok.some(v => v)) good = st;
    if (st.pose !== null && st.pose !== undefined) pose = st.pose;
    pose = Math.max(0, Math.min(st.poses - 1, pose));
    $(".k-title").textContent = st.title;
    if (first) document.title = st.title;
    buildControls(st);
    poseSlider.max = Math.max(st.poses - 1, 0);
    poseSlider.disabled = st.poses < 2;
    if (st.drawing.space && !cam) {
      cam = st.drawing.camera.map(r => r.slice()); camUp = st.drawing.up;
      root.dataset.camera = JSON.stringify(cam);
    }
    if (first || (!dragging && !fits(st))) fit();
    showMessage();
    root.dataset.version = st.version;
    draw();
  }

  function fmt(v, digits) {
    if (v === null || v === undefined) return "-";
    const a = Math.abs(v);
    if (a !== 0 && (a < 1e-4 || a >= 1e7)) return v.toExponential((digits || 6) - 1);
    return String(Number(v.toPrecision(digits || 6)));
  }

  // --- sliders: one per parameter and per fixed input ---
  let built = "";
  function row(kind, name, label, unit, value, lo, hi) {
    const step = (hi - lo) / 400;
    const lab = document.createElement("label"); lab.textContent = label;
    const r = document.createElement("input");
    Object.assign(r, { type: "range", min: lo, max: hi, step: step, value: value });
    r.dataset[kind] = name; r.setAttribute("aria-label", label);
    const n = document.createElement("input");
    Object.assign(n, { type: "number", step: "any", value: value });
    n.dataset[kind + "Number"] = name;
    const u = document.createElement("span"); u.textContent = unit || "";
    const edit = v => {
      if (!isFinite(v)) return;
      const body = kind === "parameter" ? { parameters: { [name]: v } } : { inputs: { [name]: v } };
      send("change", body);
    };
    r.addEventListener("input", () => { n.value = r.value; edit(+r.value); });
    n.addEventListener("change", () => { r.value = n.value; edit(+n.value); });
    controls.append(lab, r, n, u);
  }
  function buildControls(st) {
    const fixed = st.inputs.filter(i => !i.swept);
    const key = JSON.stringify([st.parameters.map(p => [p.name, p.lo, p.hi]), fixed.map(i => [i.key, i.lo, i.hi])]);
    if (key !== built) {
      built = key; controls.textContent = "";
      const group = t => { const g = document.createElement("div"); g.className = "k-group"; g.textContent = t; controls.append(g); };
      if (fixed.length) group("inputs");
      for (const i of fixed) row("input", i.key, i.key, i.unit, i.value, i.lo, i.hi);
      if (st.parameters.length) group("parameters");
      for (const p of st.parameters) row("parameter", p.name, p.name, "", p.value, p.lo, p.hi);
    }
    const active = root.ownerDocument.activeElement;
    for (const p of st.parameters) setControl("parameter", p.name, p.value, active);
    for (const i of fixed) setControl("input", i.key, i.value, active);
  }
  function setControl(kind, name, value, active) {
    for (const el of controls.querySelectorAll("input")) {
      if (el.dataset[kind] !== name && el.dataset[kind + "Number"] !== name) continue;
      if (el === active && busy) continue;  // the user is moving it
      el.value = value;
      el.dataset.value = value;
    }
  }

  // --- the view: world -> canvas, equal scales ---
  function boxOf(D) {  // in 3D: the sphere about the box's centre, the same at every angle
    if (!D.space) return D.box;
    const b = D.box, R = 0.5 * Math.hypot(b[1][0] - b[0][0], b[1][1] - b[0][1], b[1][2] - b[0][2]);
    return [[-R, -R], [R, R]];
  }
  function flat(D) {  // a spatial drawing as seen by the camera now (a planar one as it is)
    if (!D.space) return D;
    const key = JSON.stringify(cam);
    if (flatCache && flatCache[0] === D && flatCache[1] === key) return flatCache[2];
    const b = D.box, c = [0, 1, 2].map(j => (b[0][j] + b[1][j]) / 2);
    const on = p => (p === null || p === undefined || p.some(v => v === null)) ? null
      : [kDot(cam[0], p) - kDot(cam[0], c), kDot(cam[1], p) - kDot(cam[1], c)];
    const dir = d => (d === null || d === undefined || d.some(v => v === null)) ? null : [kDot(cam[0], d), kDot(cam[1], d)];
    const far = p => (p === null || p === undefined || p.some(v => v === null)) ? null : kDot(cam[2], c) - kDot(cam[2], p);
    const load = l => ({ ...l, size: l.vector ? Math.hypot(...l.vector) : undefined,  // the force's own size
      vector: l.vector ? dir(l.vector) : l.vector, at: l.at ? l.at.map(on) : l.at });
    const out = { ...D, xy: D.xy.map(q => q.map(on)), depth: D.xy.map(q => q.map(far)), loads: D.loads.map(load),
      guides: D.guides.map(g => ({ ...g, through: g.through.map(on), direction: g.direction.map(dir) })) };
    flatCache = [D, key, out];
    return out;
  }
  function box() { return boxOf((S && S.ok.some(v => v) ? S : good || S).drawing); }
  function fit() {
    const b = box(), W = mech.width, H = mech.height;
    const sx = Math.min(W / (b[1][0] - b[0][0] || 1), H / (b[1][1] - b[0][1] || 1));
    view = { sx, ox: W / 2 - sx * (b[0][0] + b[1][0]) / 2, oy: H / 2 + sx * (b[0][1] + b[1][1]) / 2 };
    root.dataset.transform = view.sx + " " + view.ox + " " + view.oy;
  }
  function fits(st) {
    if (!view || !st.ok.some(v => v)) return true;
    const b = boxOf(st.drawing), W = mech.width, H = mech.height;
    return X(b[0]) >= -W * 0.05 && X(b[1]) <= W * 1.05 && Y(b[1]) >= -H * 0.05 && Y(b[0]) <= H * 1.05;
  }
  const X = p => view.ox + view.sx * p[0], Y = p => view.oy - view.sx * p[1];
  const fin = p => p !== null && p !== undefined && p[0] !== null && p[1] !== null;

  const canvasOf = p => fin(p) ? [X(p), Y(p)] : null;  // (the shapes: views/draw.js)
  const line = (pts, colour, width, dash) => kPolyline(ctx, pts.map(canvasOf), colour, width, dash);
  function arrow(p, d, colour, label, heads) {  // from p along d (pixels); heads 2: a moment
    const x = X(p), y = Y(p), ex = x + d[0], ey = y - d[1], L = Math.hypot(d[0], d[1]);
    if (!(L > 2)) return;
    const ux = d[0] / L, uy = -d[1] / L, h = Math.min(10, L / 2);
    ctx.beginPath(); ctx.strokeStyle = colour; ctx.fillStyle = colour; ctx.lineWidth = 2;
    ctx.moveTo(x, y); ctx.lineTo(ex, ey); ctx.stroke();
    for (let k = 0; k < (heads || 1); k++) {
      const tx = ex - k * h * ux, ty = ey - k * h * uy;
      ctx.beginPath(); ctx.moveTo(tx, ty); ctx.lineTo(tx - h * ux - h * 0.4 * uy, ty - h * uy + h * 0.4 * ux);
      ctx.lineTo(tx - h * ux + h * 0.4 * uy, ty - h * uy - h * 0.4 * ux); ctx.closePath(); ctx.fill();
    }
    if (label) { ctx.font = "11px sans-serif"; ctx.fillText(label, ex + 4, ey - 4); }
  }

  function draw() {
    if (!S) return;
    root.dataset.pose = pose;
    poseSlider.value = pose;
    const swept = S.inputs.filter(i => i.swept);
    $(".k-posetext").textContent = swept.length
      ? swept.map(i => i.key + " = " + fmt(i.values[pose]) + (i.unit ? " " + i.unit : "")).join(", ") + "  (pose " + (pose + 1) + " of " + S.poses + ")"
      : "";
    drawMechanism(); drawValues(); drawPlots();
  }

  function drawMechanism() {
    const W = mech.width, H = mech.height;
    ctx.fillStyle = "white"; ctx.fillRect(0, 0, W, H);
    let st = S, i = pose;
    if (!S.ok.some(v => v) && good) { st = good; i = Math.min(pose, good.poses - 1); ctx.globalAlpha = 0.3; }
    const D = flat(st.drawing), xy = D.xy[i];
    const owner = {};
    for (const b of D.bodies) for (const k of b.ring) if (!(k in owner)) owner[k] = b.colour;
    if ($(".k-paths").checked) for (const k of D.moving) line(D.xy.map(q => q[k]), owner[k] || INK, 1, [5, 4]);
    const R = Math.max(3, D.r * view.sx);
    for (const k of D.ground) {  // a pivot on a hatched base
      const p = xy[k]; if (fin(p)) kPivot(ctx, X(p), Y(p), R, INK);
    }
    if (!st.ok[i]) {
      ctx.globalAlpha = 1; ctx.fillStyle = "#b00"; ctx.font = "14px sans-serif";
      ctx.fillText("no assembly at this pose (" + st.status[i] + ")", 10, 20);
      return;
    }
    for (const g of D.guides) {
      const t = g.through[i], d = g.direction[i];
      if (!fin(t) || !fin(d)) continue;
      line([[t[0] + g.lo * d[0], t[1] + g.lo * d[1]], [t[0] + g.hi * d[0], t[1] + g.hi * d[1]]], g.colour, 1.2);
      const p = xy[g.point];
      if (fin(p)) kBlock(ctx, X(p), Y(p), -Math.atan2(d[1], d[0]), R, INK);  // the block
    }
    for (const c of (D.joints && D.joints[i]) || []) {  // gears, racks, cams
      if (c.pts.length === 1) {
        const p = c.pts[0]; if (!fin(p)) continue;
        ctx.beginPath(); ctx.arc(X(p), Y(p), 3, 0, 2 * Math.PI); ctx.fillStyle = c.colour; ctx.fill();
      } else line(c.pts, c.colour, 1.2);
    }
    let order = D.bodies.filter(b => !b.driven).concat(D.bodies.filter(b => b.driven));
    if (D.space) {  // painter's order: the farthest body first, by the mean depth of its points
      const depth = b => { const d = b.ring.map(k => D.depth[i][k]);
        return d.some(v => v === null) ? -Infinity : d.reduce((a, v) => a + v, 0) / d.length; };
      order = order.map(b => [depth(b), b]).sort((a, b) => b[0] - a[0]).map(x => x[1]);
    }
    for (const b of order) {
      const pts = b.ring.map(k => xy[k]);
      if (pts.every(fin)) kBody(ctx, pts.map(canvasOf), b.colour);
    }
    if ($(".k-forces").checked) { drawLoads(D, xy, i); drawForces(D, xy, i); }
    if ($(".k-centres").checked) drawCentres(st, i);
    for (let k = 0; k < D.names.length; k++) {  // joints and points, with their names
      const p = xy[k]; if (!fin(p)) continue;
      const hot = dragging && dragging.k === k;
      kJoint(ctx, X(p), Y(p), hot ? 6 : 4, hot ? "#ffd24d" : "white", INK);
      ctx.fillStyle = INK; ctx.font = "11px sans-serif"; ctx.fillText(D.names[k], X(p) + 7, Y(p) - 7);
    }
    ctx.globalAlpha = 1;
    if (D.space) triad();
  }
  function triad() {  // the world axes, lower left, and how to turn the view
    const o = [38, mech.height - 38], col = ["#d62728", "#2ca02c", "#1f77b4"];
    ctx.font = "11px sans-serif";
    for (let j = 0; j < 3; j++) {
      ctx.beginPath(); ctx.moveTo(o[0], o[1]); ctx.lineTo(o[0] + 26 * cam[0][j], o[1] - 26 * cam[1][j]);
      ctx.strokeStyle = col[j]; ctx.lineWidth = 2; ctx.stroke();
      ctx.fillStyle = col[j]; ctx.fillText("xyz"[j], o[0] + 34 * cam[0][j] - 3, o[1] - 34 * cam[1][j] + 4);
    }
    ctx.fillStyle = "#666";
    ctx.fillText("drag to turn, wheel to zoom, double-click: isometric (points are not dragged in 3D)", 80, mech.height - 10);
  }

  function drawLoads(D, xy, i) {
    const size = l => l.size !== undefined ? l.size : Math.hypot(l.vector[0], l.vector[1]);
    const forces = D.loads.filter(l => l.kind === "force" || l.kind === "weight");
    const most = Math.max(1e-300, ...forces.map(size));
    const moments = D.loads.filter(l => l.kind === "moment");
    const mostM = Math.max(1e-300, ...moments.map(size));
    const L = 0.12 * Math.min(mech.width, mech.height);
    for (const l of D.loads) {
      if (l.kind === "force" && fin(xy[l.point])) {
        arrow(xy[l.point], [L * l.vector[0] / most, L * l.vector[1] / most], "#c0392b", fmt(size(l), 3));
      } else if (l.kind === "moment" && fin(xy[l.point])) {  // a torque in space: a double-headed arrow
        arrow(xy[l.point], [L * l.vector[0] / mostM, L * l.vector[1] / mostM], "#c0392b", fmt(size(l), 3), 2);
      } else if (l.kind === "spring" && fin(xy[l.points[0]]) && fin(xy[l.points[1]])) {
        const a = xy[l.points[0]], b = xy[l.points[1]], n = 12, pts = [a];
        const dx = b[0] - a[0], dy = b[1] - a[1], len = Math.hypot(dx, dy) || 1, w = 6 / view.sx;
        for (let j = 1; j < n; j++) {
          const s = j / n, side = (j % 2 ? 1 : -1) * w;
          pts.push([a[0] + s * dx - side * dy / len, a[1] + s * dy + side * dx / len]);
        }
        pts.push(b); line(pts, "#8e44ad", 1.5);
      } else if (l.kind === "weight" && fin(l.at[i])) {  // m g at the centre of gravity
        arrow(l.at[i], [L * l.vector[0] / most, L * l.vector[1] / most], "#c0392b",
              l.label + " " + fmt(size(l), 3));
      } else if (l.kind === "torque" && fin(xy[l.point])) {
        torque(xy[l.point], l.value, "#c0392b", fmt(l.value, 3));
      }
    }
  }

  function torque(p, value, colour, label) {  // an arc about p, turning as the torque's sign says
    const r = 18, s = value >= 0 ? 1 : -1, e = -0.2 - s * 4.5;
    ctx.beginPath(); ctx.strokeStyle = colour; ctx.lineWidth = 2;
    ctx.arc(X(p), Y(p), r, -0.2, e, s > 0); ctx.stroke();
    ctx.beginPath(); ctx.arc(X(p) + r * Math.cos(e), Y(p) + r * Math.sin(e), 3.5, 0, 2 * Math.PI);
    ctx.fillStyle = colour; ctx.fill();
    ctx.font = "11px sans-serif"; ctx.fillText(label, X(p) + r + 3, Y(p) - r);
  }
  function drawForces(D, xy, i) {  // reported reactions (arrows) and input efforts (arcs)
    const reactions = D.forces.filter(f => f.kind === "reaction" || f.kind === "effort-arrow");
    let most = 1e-300;
    for (const f of reactions) for (const v of f.vectors) if (fin(v)) most = Math.max(most, Math.hypot(v[0], v[1]));
    const L = 0.12 * Math.min(mech.width, mech.height);
    for (const f of D.forces) {
      const p = xy[f.point]; if (!fin(p)) continue;
      if ((f.kind === "reaction" || f.kind === "effort-arrow") && fin(f.vectors[i])) {
        const v = f.vectors[i];
        arrow(p, [L * v[0] / most, L * v[1] / most], "#2c7fb8", f.label + " " + fmt(Math.hypot(v[0], v[1]), 3));
      } else if (f.kind === "effort" && f.values[i] !== null) {
        torque(p, f.values[i], "#2c7fb8", f.label + " " + fmt(f.values[i], 3));
      }
    }
  }

  function drawCentres(st, i) {
    const colour = {};
    for (const b of st.drawing.bodies) colour[b.name] = b.colour;
    for (const [link, cs] of Object.entries(st.centres)) {
      const c = cs[i]; if (!fin(c)) continue;
      const x = X(c), y = Y(c);
      ctx.strokeStyle = colour[link] || INK; ctx.lineWidth = 2;
      ctx.beginPath(); ctx.moveTo(x - 6, y - 6); ctx.lineTo(x + 6, y + 6); ctx.moveTo(x - 6, y + 6); ctx.lineTo(x + 6, y - 6); ctx.stroke();
      ctx.fillStyle = colour[link] || INK; ctx.font = "11px sans-serif"; ctx.fillText("I(" + link + ")", x + 7, y + 12);
    }
  }

  // --- the numbers at the pose shown ---
  function drawValues() {
    const rows = [];
    for (const inp of S.inputs) rows.push([inp.key, inp.swept ? inp.values[pose] : inp.value, inp.unit]);
    for (const q of S.plot.quantities) rows.push([q.name, S.ok[pose] ? q.values[pose] : null, q.unit]);
    const t = $(".k-values");
    if (t.rows.length !== rows.length) {
      t.textContent = "";
      for (const [name] of rows) {
        const tr = t.insertRow(), th = document.createElement("th");
        th.textContent = name; tr.append(th);
        const td = tr.insertCell(); td.dataset.name = name;
        tr.insertCell().className = "k-unit";
      }
    }
    rows.forEach(([name, v, unit], j) => {
      const tr = t.rows[j];
      tr.cells[0].textContent = name;
      tr.cells[1].dataset.name = name;
      tr.cells[1].dataset.value = v === null || v === undefined ? "" : String(v);
      tr.cells[1].textContent = fmt(v);
      tr.cells[2].textContent = unit || "";
    });
  }

  // --- plots of every quantity against the input, with axes, ticks and units ---
  function ticks(lo, hi, n) {
    const span = hi - lo, raw = span / n, mag = Math.pow(10, Math.floor(Math.log10(raw)));
    const f = raw / mag, step = (f < 1.5 ? 1 : f < 3 ? 2 : f < 7 ? 5 : 10) * mag, out = [];
    for (let v = Math.ceil(lo / step - 1e-9) * step; v <= hi + step * 1e-9; v += step) out.push(Math.abs(v) < step * 1e-9 ? 0 : v);
    return out;
  }
  function extent(v, ok) {
    let lo = Infinity, hi = -Infinity;
    v.forEach((a, k) => { if (a !== null && (!ok || ok[k])) { lo = Math.min(lo, a); hi = Math.max(hi, a); } });
    if (!isFinite(lo)) return [0, 1];
    if (hi - lo <= 1e-9 * Math.max(Math.abs(lo), Math.abs(hi), 1e-300)) { const d = Math.abs(lo) * 0.1 || 1; lo -= d; hi += d; }
    const pad = (hi - lo) * 0.05;
    return [lo - pad, hi + pad];
  }
  const label = (name, unit) => unit ? name + " [" + unit + "]" : name;
  function drawPlots() {
    const Q = S.plot.quantities, PH = 150, ML = 62, MR = 12;
    const h = Math.max(60, 10 + PH * Q.length);
    if (plots.height !== h) plots.height = h;
    pctx.fillStyle = "white"; pctx.fillRect(0, 0, plots.width, plots.height);
    const xs = S.plot.x.values, [x0, x1] = extent(xs), Wp = plots.width;
    const PX = v => ML + (Wp - ML - MR) * (v - x0) / (x1 - x0);
    const xt = ticks(x0, x1, 6);
    Q.forEach((q, j) => {
      const top = 10 + j * PH + 16, bot = top + PH - 16 - 36;
      const [y0, y1] = extent(q.values, S.ok), PY = v => bot - (bot - top) * (v - y0) / (y1 - y0);
      pctx.font = "11px sans-serif"; pctx.fillStyle = INK; pctx.textAlign = "left";
      pctx.fillText(label(q.name, q.unit), ML, top - 4);
      S.ok.forEach((ok, k) => {  // unsolved stretches
        if (ok || xs[k] === null) return;
        const a = PX(xs[Math.max(k - 1, 0)]), b = PX(xs[Math.min(k + 1, xs.length - 1)]);
        pctx.fillStyle = "rgba(214,39,40,0.15)"; pctx.fillRect(Math.min(a, b), top, Math.abs(b - a) || 2, bot - top);
      });
      pctx.strokeStyle = "#eee"; pctx.lineWidth = 1;
      const yt = ticks(y0, y1, 4);
      pctx.textAlign = "right"; pctx.fillStyle = "#444";
      for (const v of yt) {
        pctx.beginPath(); pctx.moveTo(ML, PY(v)); pctx.lineTo(Wp - MR, PY(v)); pctx.stroke();
        pctx.fillText(fmt(v, 4), ML - 4, PY(v) + 4);
      }
      pctx.textAlign = "center";
      for (const v of xt) {
        pctx.beginPath(); pctx.moveTo(PX(v), top); pctx.lineTo(PX(v), bot); pctx.stroke();
        pctx.fillText(fmt(v, 4), PX(v), bot + 13);
      }
      pctx.fillText(label(S.plot.x.name, S.plot.x.unit), (ML + Wp - MR) / 2, bot + 27);
      pctx.strokeStyle = "#888"; pctx.strokeRect(ML, top, Wp - ML - MR, bot - top);
      for (const e of S.events) {  // singular positions
        const x = xs[e.pose]; if (x === null || x === undefined) continue;
        pctx.beginPath(); pctx.setLineDash([3, 3]); pctx.strokeStyle = "#9467bd";
        pctx.moveTo(PX(x), top); pctx.lineTo(PX(x), bot); pctx.stroke(); pctx.setLineDash([]);
        pctx.fillStyle = "#9467bd"; pctx.textAlign = "left"; pctx.fillText(e.kind, PX(x) + 3, top + 11);
      }
      pctx.save(); pctx.beginPath(); pctx.rect(ML, top, Wp - ML - MR, bot - top); pctx.clip();
      pctx.beginPath(); pctx.strokeStyle = "#1f77b4"; pctx.lineWidth = 1.5;
      let pen = false;
      const wrap = q.unit === "deg" ? 180 : q.unit === "rad" ? Math.PI : Infinity;  // angles wrap
      q.values.forEach((v, k) => {
        if (v === null || xs[k] === null || !S.ok[k]) { pen = false; return; }
        if (k > 0 && q.values[k - 1] !== null && Math.abs(v - q.values[k - 1]) > wrap) pen = false;
        if (pen) pctx.lineTo(PX(xs[k]), PY(v)); else pctx.moveTo(PX(xs[k]), PY(v));
        pen = true;
      });
      pctx.stroke();
      const v = q.values[pose];
      if (xs[pose] !== null && xs[pose] !== undefined) {  // the cursor
        pctx.beginPath(); pctx.strokeStyle = "#d62728"; pctx.lineWidth = 1;
        pctx.moveTo(PX(xs[pose]), top); pctx.lineTo(PX(xs[pose]), bot); pctx.stroke();
        if (v !== null && S.ok[pose]) { pctx.beginPath(); pctx.arc(PX(xs[pose]), PY(v), 3, 0, 2 * Math.PI); pctx.fillStyle = "#d62728"; pctx.fill(); }
      }
      pctx.restore();
    });
    pctx.textAlign = "left";
  }

  // --- dragging points ---
  function canvasPoint(e) {
    const r = mech.getBoundingClientRect();
    return [(e.clientX - r.left) * mech.width / r.width, (e.clientY - r.top) * mech.height / r.height];
  }
  function nearest(e) {
    if (!S || !view) return null;
    const st = S.ok[pose] ? S : null;
    if (!st) return null;
    if (st.drawing.space) return null;  // in 3D the mouse turns the view (docs/app.md)
    const [cx, cy] = canvasPoint(e), D = st.drawing, xy = D.xy[pose];
    let best = null;
    for (const k of D.ground.concat(D.moving)) {
      const p = xy[k]; if (!fin(p)) continue;
      const d = Math.hypot(X(p) - cx, Y(p) - cy);
      if (d <= 10 && (!best || d < best.d)) best = { k, d, name: D.names[k] };
    }
    return best;
  }
  mech.addEventListener("pointerdown", e => {
    if (cam) {  // a spatial mechanism: the drag turns it
      turning = [e.clientX, e.clientY];
      if (mech.setPointerCapture && e.pointerId !== undefined) { try { mech.setPointerCapture(e.pointerId); } catch (_) { /* synthetic */ } }
      e.preventDefault(); return;
    }
    const hit = nearest(e); if (!hit) return;
    dragging = hit; mech.classList.add("k-dragging");
    if (mech.setPointerCapture && e.pointerId !== undefined) { try { mech.setPointerCapture(e.pointerId); } catch (_) { /* synthetic */ } }
    e.preventDefault(); draw();
  });
  mech.addEventListener("pointermove", e => {
    if (turning) {
      cam = kOrbit(cam, camUp, e.clientX - turning[0], e.clientY - turning[1]);
      turning = [e.clientX, e.clientY]; root.dataset.camera = JSON.stringify(cam); draw(); return;
    }
    if (!dragging) { mech.classList.toggle("k-over", !!nearest(e)); return; }
    const [cx, cy] = canvasPoint(e);
    send("drag", { point: dragging.name, x: (cx - view.ox) / view.sx, y: (view.oy - cy) / view.sx });
  });
  const drop = () => { turning = null; if (!dragging) return; dragging = null; mech.classList.remove("k-dragging"); draw(); };
  mech.addEventListener("pointerup", drop);
  mech.addEventListener("pointercancel", drop);

  mech.addEventListener("wheel", e => {  // zoom a spatial mechanism about the canvas's centre
    if (!cam || !view) return;
    e.preventDefault();
    const f = Math.min(1.5, Math.max(0.67, Math.exp(-0.0015 * e.deltaY))), W = mech.width, H = mech.height;
    view = { sx: view.sx * f, ox: W / 2 + f * (view.ox - W / 2), oy: H / 2 + f * (view.oy - H / 2) };
    root.dataset.transform = view.sx + " " + view.ox + " " + view.oy; draw();
  }, { passive: false });
  mech.addEventListener("dblclick", () => {
    if (!cam || !S) return;
    cam = S.drawing.camera.map(r => r.slice()); root.dataset.camera = JSON.stringify(cam); fit(); draw();
  });

  // --- the pose, the animation, the toggles ---
  poseSlider.addEventListener("input", () => { pose = +poseSlider.value; draw(); });
  const play = $(".k-play");
  play.addEventListener("click", () => {
    if (timer) { clearInterval(timer); timer = null; play.textContent = "play"; return; }
    play.textContent = "pause";
    timer = setInterval(() => {
      if (!S || S.poses < 2) return;
      pose = (pose + 1) % S.poses; draw();
    }, 40 / +$(".k-speed").value);
  });
  for (const s of [".k-paths", ".k-centres", ".k-forces"]) $(s).addEventListener("change", draw);
  $(".k-fit").addEventListener("click", () => { fit(); draw(); });
  if (transport.download === false) $(".k-download").style.display = "none";
  else if (transport.toml) {  // the host writes the file's text
    $(".k-download").addEventListener("click", e => {
      e.preventDefault();
      transport.toml().then(text => {
        const a = document.createElement("a");
        a.href = URL.createObjectURL(new Blob([text], { type: "application/toml" }));
        a.download = "scene.toml"; a.click(); setTimeout(() => URL.revokeObjectURL(a.href), 1000);
      }, e2 => { error = String(e2.message || e2); showMessage(); });
    });
  }
  root.dataset.busy = "1";
  transport.call("state").then(show, e => { error = String(e.message || e); showMessage(); })
    .finally(() => { if (!busy) root.dataset.busy = "0"; });
  return { show, send };
}
