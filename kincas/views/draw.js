// The shapes every kincas page draws alike, in one file: the offline `--html` pages inline it
// (views/html.py, a spatial one's views/html3d.py: the page needs nothing but itself) and the
// live page of `kincas app` is served with it ahead of its own script (views/live/app.js).
// Each function takes the canvas's 2D context and canvas pixels (x right, y down): the caller
// maps the world onto the canvas (a plane's scale, or a spatial camera's projection). `ink` is
// the pictures' ink colour; `R` the picture's unit of size in pixels.
function kPolyline(ctx, pts, colour, width, dash) {  // a point null: a gap in the line
  ctx.beginPath(); ctx.setLineDash(dash || []); ctx.strokeStyle = colour; ctx.lineWidth = width;
  let pen = false;
  for (const p of pts) {
    if (p === null) { pen = false; continue; }
    if (pen) ctx.lineTo(p[0], p[1]); else ctx.moveTo(p[0], p[1]);
    pen = true;
  }
  ctx.stroke(); ctx.setLineDash([]);
}
function kPivot(ctx, x, y, R, ink) {  // a ground pivot on a hatched base, upright on the screen
  const h = 2.5 * R;
  ctx.beginPath(); ctx.moveTo(x, y); ctx.lineTo(x - 0.7 * h, y + h); ctx.lineTo(x + 0.7 * h, y + h);
  ctx.closePath(); ctx.fillStyle = "#dddddd"; ctx.fill(); ctx.strokeStyle = ink; ctx.lineWidth = 1; ctx.stroke();
}
function kBlock(ctx, x, y, angle, R, ink) {  // a slide's block at (x, y), along its guide drawn at `angle`
  ctx.save(); ctx.translate(x, y); ctx.rotate(angle);
  ctx.fillStyle = "#f2f2f2"; ctx.strokeStyle = ink; ctx.lineWidth = 1.2;
  ctx.fillRect(-2 * R, -1.4 * R, 4 * R, 2.8 * R); ctx.strokeRect(-2 * R, -1.4 * R, 4 * R, 2.8 * R);
  ctx.restore();
}
function kBody(ctx, pts, colour) {  // three points or more: its outline, filled; two: a round bar
  if (pts.length >= 3) {
    const a = ctx.globalAlpha;
    ctx.beginPath(); pts.forEach((p, j) => j ? ctx.lineTo(p[0], p[1]) : ctx.moveTo(p[0], p[1]));
    ctx.closePath(); ctx.globalAlpha = 0.45 * a; ctx.fillStyle = colour; ctx.fill(); ctx.globalAlpha = a;
    ctx.strokeStyle = colour; ctx.lineWidth = 2.5; ctx.stroke();
  } else {
    ctx.lineCap = "round"; kPolyline(ctx, pts, colour, 7); ctx.lineCap = "butt";
  }
}
function kJoint(ctx, x, y, r, fill, ink) {  // a joint or point: a small circle
  ctx.beginPath(); ctx.arc(x, y, r, 0, 2 * Math.PI);
  ctx.fillStyle = fill; ctx.fill(); ctx.strokeStyle = ink; ctx.lineWidth = 1.3; ctx.stroke();
}
