"""Pictures of gears, racks and cams on a mechanism drawing (kincas/cli/plot.py).

Gears: each pitch circle about its body's frame origin, with a radius drawn at the body's
angle so that the rotation shows. Racks: the pitch line, `radius` from the line the pinion's
centre travels along on the teeth side, with tick marks fixed to the rack. Cams: the profile
carried by its body, the contact point, and the follower: a roller's circle, a flat face
along the follower link's x axis (a knife edge is its point, already drawn).

`joint_geometry` evaluates, at every pose of a sweep, the frames of the bodies these need and
the contact points; `JointArtists` makes the artists once and moves them to any pose.

>>> import numpy as np, kincas
>>> from matplotlib.figure import Figure
>>> from kincas.cli.plot import draw
>>> from kincas.model import Cam, Circle
>>> m = kincas.Mechanism(ground={"O": (0, 0)},
...     links=[kincas.Link.bar("shaft", "O", "K", 10), kincas.Link.bar("arm", "O", "F", 45)],
...     cams=[Cam("cam", "shaft", Circle((10, 0), 40), knife="F")],
...     inputs=[kincas.Input.angle("shaft")], guess={"F": (0, 45)})
>>> sw = kincas.sweep(m, {"shaft.angle": np.radians([0.0, 90.0])})
>>> ax = draw(m, sw, ax=Figure().subplots())
>>> sorted(a.get_label() for a in ax.lines if a.get_label().startswith("cam "))
['cam contact', 'cam profile']
"""
from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np

from ..model import spline
from ..model.joints import Circle
from ..model.mechanism import GROUND

_FUNCTIONS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


@dataclass
class JointGeometry:
    """`frames[body]` (N x 3: origin x, y, angle; NaN where a moving body is unknown),
    `contact[cam]` (N x 2), and the numbers of each joint at the parameters' values."""

    frames: dict
    contact: dict
    numbers: dict


def _bodies(m) -> list[str]:
    out = []
    for g in m.gears:
        out += [*g.links]
    for r in m.racks:
        out += [r.pinion, m.slide(r.slide).along]
    for c in m.cams:
        out += [c.body] + ([c.flat] if c.flat else [])
    return list(dict.fromkeys(out))


def _function(model):
    if model not in _FUNCTIONS:
        import casadi as ca
        sym, m = model.sym, model.sym.mech
        out = [c for b in _bodies(m) for c in sym.frames[b]]
        out += [c for cam in m.cams for c in sym.cams[cam.name]["contact"]]
        nums = []
        for g in m.gears:
            nums += [sym.val(r) for r in g.radii]
        for r in m.racks:
            nums.append(sym.val(r.radius))
        for c in m.cams:
            nums.append(sym.val(c.roller_radius) if c.roller else ca.SX(0))
            nums += ([*(sym.val(v) for v in c.profile.center), sym.val(c.profile.radius)]
                     if isinstance(c.profile, Circle) else [sym.val(v) for v in c.profile.radii])
        _FUNCTIONS[model] = (ca.Function("joints_pose", [sym.q, sym.u, sym.p], [ca.vertcat(*out)]),
                             ca.Function("joints_numbers", [sym.p], [ca.vertcat(*nums)]))
    return _FUNCTIONS[model]


def joint_geometry(model, Q, U, p, ok) -> JointGeometry | None:
    """Frames and contact points at every pose (Q, U: N rows; p: parameter values)."""
    m = model.sym.mech
    if not (m.gears or m.racks or m.cams):
        return None
    f, fn = _function(model)
    n = Q.shape[0]
    raw = np.asarray(f.map(n)(Q.T, U.T, np.repeat(np.reshape(p, (-1, 1)), n, axis=1))).T.reshape(n, -1)
    bodies = _bodies(m)
    frames = {}
    for k, b in enumerate(bodies):
        fr = raw[:, 3 * k:3 * k + 3].copy()
        if b != GROUND:
            fr[~ok] = np.nan
        frames[b] = fr
    c0 = 3 * len(bodies)
    contact = {}
    for k, c in enumerate(m.cams):
        xy = raw[:, c0 + 2 * k:c0 + 2 * k + 2].copy()
        xy[~ok] = np.nan
        contact[c.name] = xy
    nums, numbers, k = np.asarray(fn(p)).ravel(), {}, 0
    for i, g in enumerate(m.gears):
        numbers[("gear", i)], k = nums[k:k + 2], k + 2
    for i, r in enumerate(m.racks):
        numbers[("rack", i)], k = nums[k], k + 1
    for c in m.cams:
        size = 4 if isinstance(c.profile, Circle) else 1 + len(c.profile.radii)
        numbers[("cam", c.name)], k = nums[k:k + size], k + size
    return JointGeometry(frames, contact, numbers)


def profile_points(cam, data, n: int = 361) -> np.ndarray:
    """(n x 2) points of a cam's closed profile in its body's frame (data: its numbers)."""
    if isinstance(cam.profile, Circle):
        t = np.linspace(0, 2 * np.pi, n)
        return np.stack([data[0] + data[2] * np.cos(t), data[1] + data[2] * np.sin(t)], axis=1)
    a = cam.profile.angles
    t = np.linspace(a[0], a[0] + spline.TURN, n)
    r = spline.evaluate(a, data, t, order=0)[0]
    return np.stack([r * np.cos(t), r * np.sin(t)], axis=1)


def _world(frame, pts):
    x, y, th = frame
    c, s = np.cos(th), np.sin(th)
    return np.stack([x + c * pts[:, 0] - s * pts[:, 1], y + s * pts[:, 0] + c * pts[:, 1]], axis=1)


class JointArtists:
    """The artists of every gear, rack and cam of a `plot.Drawing`; `update(i)` moves them."""

    def __init__(self, drawing, jg: JointGeometry):
        self.d, self.jg, m, ax = drawing, jg, drawing.m, drawing.ax
        colour = lambda b: drawing.colour.get(b, "#555555")  # noqa: E731
        self.gears = []
        for i, g in enumerate(m.gears):
            for b, r in zip(g.links, jg.numbers[("gear", i)]):
                circle, = ax.plot([], [], "-.", lw=1.0, color=colour(b), zorder=3.2,
                                  label=f"{g.name or 'gear'} pitch circle")
                mark, = ax.plot([], [], "-", lw=1.2, color=colour(b), zorder=3.2)
                self.gears.append((b, float(r), circle, mark))
                self._grow(jg.frames[b][:, :2], float(r))
        self.racks = []
        for i, rk in enumerate(m.racks):  # the pinion's pitch circle, then the rack's line
            r = float(jg.numbers[("rack", i)])
            circle, = ax.plot([], [], "-.", lw=1.0, color=colour(rk.pinion), zorder=3.2,
                              label=f"{rk.name or 'rack'} pinion pitch circle")
            mark, = ax.plot([], [], "-", lw=1.2, color=colour(rk.pinion), zorder=3.2)
            self.gears.append((rk.pinion, r, circle, mark))
            line, = ax.plot([], [], "-", lw=1.4, color=colour(m.slide(rk.slide).along), zorder=3.3,
                            label=f"{rk.name or 'rack'} pitch line")
            ticks, = ax.plot([], [], "-", lw=0.8, color=colour(m.slide(rk.slide).along), zorder=3.3)
            self.racks.append((rk, float(jg.numbers[("rack", i)]), line, ticks))
        self.cams = []
        for c in m.cams:
            data = jg.numbers[("cam", c.name)]
            local = profile_points(c, data[1:])
            prof, = ax.plot([], [], "-", lw=1.6, color=colour(c.body), zorder=3.4, label=f"{c.name} profile")
            dot, = ax.plot([], [], "o", ms=4, color="#c0392b", zorder=6.5, label=f"{c.name} contact")
            extra = None
            if c.roller:
                extra, = ax.plot([], [], "-", lw=1.2, color=INK_ROLLER, zorder=5.5, label=f"{c.name} roller")
            elif c.flat:
                extra, = ax.plot([], [], "-", lw=3, color=colour(c.flat), zorder=5.5, label=f"{c.name} face")
            self.cams.append((c, float(data[0]), local, prof, dot, extra))
            fr = jg.frames[c.body]
            for i in np.flatnonzero(np.isfinite(fr).all(axis=1))[:: max(1, len(fr) // 24)]:
                self._grow(_world(fr[i], local), 0.0)

    def _grow(self, pts, r):
        """Widen the drawing's box to hold these points (and circles of radius r about them)."""
        pts = pts[np.isfinite(pts).all(axis=1)]
        if pts.size:
            box = self.d.box
            box[0] = np.minimum(box[0], pts.min(axis=0) - r - 2 * self.d.r)
            box[1] = np.maximum(box[1], pts.max(axis=0) + r + 2 * self.d.r)

    def update(self, i: int):
        jg, nan2 = self.jg, np.full((2, 2), np.nan)
        t = np.linspace(0, 2 * np.pi, 121)
        for b, r, circle, mark in self.gears:
            x, y, th = jg.frames[b][i] if 0 <= i < len(jg.frames[b]) else (np.nan,) * 3
            circle.set_data(x + r * np.cos(t), y + r * np.sin(t))
            mark.set_data([x, x + r * np.cos(th)], [y, y + r * np.sin(th)])  # turns with the body
        for rk, r, line, ticks in self.racks:
            through, dvec, _ = (a[i] for a in self.d.geo.slides[rk.slide])
            lo, hi = self.d.sref[rk.slide]
            nrm = np.array([-dvec[1], dvec[0]]) * (-1.0 if rk.teeth == "right" else 1.0)
            base = through + r * nrm
            ends = np.array([base + lo * dvec, base + hi * dvec])
            line.set_data(*ends.T)
            pitch = 0.5 * self.d.r * 3
            ks = np.arange(np.ceil(lo / pitch), np.floor(hi / pitch) + 1) * pitch  # fixed to the rack
            segs = [[base + k * dvec, base + k * dvec + 0.8 * self.d.r * nrm, [np.nan, np.nan]] for k in ks]
            ticks.set_data(*np.array(segs).reshape(-1, 2).T if segs else nan2)
        for c, rho, local, prof, dot, extra in self.cams:
            fr = jg.frames[c.body][i]
            prof.set_data(*_world(fr, local).T)
            cp = jg.contact[c.name][i]
            dot.set_data([cp[0]], [cp[1]])
            if c.roller:
                ctr = self.d.geo.point(c.roller)[i]
                extra.set_data(ctr[0] + rho * np.cos(t), ctr[1] + rho * np.sin(t))
            elif c.flat:
                fx, fy, fth = jg.frames[c.flat][i]
                half = 0.6 * np.ptp(local, axis=0).max()
                dvec = np.array([np.cos(fth), np.sin(fth)])
                extra.set_data(*np.array([cp - half * dvec, cp + half * dvec]).T)


INK_ROLLER = "#333333"
