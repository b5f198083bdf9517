// The camera that turns with the mouse, shared by the spatial `--html` page (views/html3d.py)
// and the live page of `kincas app` (views/live/app.js): both inline this file. A camera is
// three rows (right, up, toward the viewer), orthonormal; the projection is orthographic: a
// world point p is drawn at (right . p, up . p), its depth is -(toward . p).
const kDot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
function kRotate(v, k, a) {  // v turned by a about the unit axis k (Rodrigues)
  const c = Math.cos(a), s = Math.sin(a), kv = kDot(k, v);
  const x = [k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2], k[0] * v[1] - k[1] * v[0]];
  return [0, 1, 2].map(j => v[j] * c + x[j] * s + k[j] * kv * (1 - c));
}
function kOrthonormal(cam) {  // Gram-Schmidt against rounding drift; toward = right x up
  const n = v => { const l = Math.hypot(v[0], v[1], v[2]); return v.map(x => x / l); };
  const r = n(cam[0]), u0 = cam[1], ru = kDot(r, u0);
  const u = n([0, 1, 2].map(j => u0[j] - ru * r[j]));
  return [r, u, [r[1] * u[2] - r[2] * u[1], r[2] * u[0] - r[0] * u[2], r[0] * u[1] - r[1] * u[0]]];
}
// The camera after a mouse move of (dx, dy) pixels: left-right turns the mechanism about the
// world axis `up` (0, 1, 2: x, y, z; every camera row turns the other way), up-down tilts it
// about the screen's horizontal (up and toward turn in their plane).
function kOrbit(cam, up, dx, dy) {
  const k = [0, 0, 0]; k[up] = 1;
  cam = cam.map(row => kRotate(row, k, -0.01 * dx));
  const b = 0.01 * dy, c = Math.cos(b), s = Math.sin(b), u = cam[1], t = cam[2];
  return kOrthonormal([cam[0], [0, 1, 2].map(j => c * u[j] + s * t[j]), [0, 1, 2].map(j => -s * u[j] + c * t[j])]);
}
