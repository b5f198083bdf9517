"""Pictures of gears, racks and cams on a mechanism drawing (kincas/views/plot.py).

Gears: each pitch circle about its body's frame origin, with a radius drawn at the body's
angle so that the rotation shows. Racks: the pitch line, `radius` from the line the pinion's
centre travels along on the teeth side, with tick marks fixed to the rack. Cams: the profile
carried by its body, the contact point, and the follower: a roller's circle, a flat face
along the follower link's x axis (a knife edge is its point, already drawn).

`joint_geometry` evaluates, at every pose of a sweep, the frames of the bodies these need and
the contact points; `JointArtists` makes the artists once and moves them to any pose.

>>> import numpy as np, kincas
>>> from matplotlib.figure import Figure
>>> from kincas.views.plot import draw
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

from dataclasses import dataclass

import numpy as np

from ..core.drawing import joint_bodies, joint_values
from ..model import spline
from ..model.joints import Circle
from ..model.mechanism import GROUND

@dataclass
class JointGeometry:
    """`frames[body]` (N x 3: origin x, y, angle; NaN where a moving body is unknown),
    `contact[cam]` (N x 2), and the numbers of each joint at the parameters' values."""

    frames: dict
    contact: dict
    numbers: dict


def joint_geometry(model, Q, U, p, ok) -> JointGeometry | None:
    """Frames and contact points at every pose (Q, U: N rows; p: parameter values)."""
    m = model.mech
    if not (m.gears or m.racks or m.cams):
        return None
    raw, nums = joint_values(model, Q, U, p)
    bodies = joint_bodies(m)
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
    numbers, k = {}, 0
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


def curves(m, geo, i: int, unit: float, fine: int = 121) -> list[tuple[str, str, np.ndarray]]:
    """What the joints draw at pose i, format-free: (label, body whose colour it takes,
    (K x 2) polyline) for each pitch circle and its turning radius, rack pitch line and its
    ticks (NaN rows break a polyline), cam profile, contact point (one row), roller circle and
    flat face. `geo` is `plot.geometry`'s, `unit` the drawing's unit of size, `fine` the
    number of points of a circle (three times that for a cam's profile)."""
    jg, out = geo.joints, []
    if jg is None:
        return out
    t = np.linspace(0, 2 * np.pi, fine)
    circ = np.stack([np.cos(t), np.sin(t)], axis=1)

    def pitch(label, body, r):
        x, y, th = jg.frames[body][i]
        out.append((label, body, np.array([x, y]) + r * circ))
        out.append((label + " mark", body, np.array([[x, y], [x + r * np.cos(th), y + r * np.sin(th)]])))
    for k, g in enumerate(m.gears):
        for b, r in zip(g.links, jg.numbers[("gear", k)]):
            pitch(f"{g.name or 'gear'} pitch circle", b, float(r))
    for k, rk in enumerate(m.racks):
        r = float(jg.numbers[("rack", k)])
        pitch(f"{rk.name or 'rack'} pinion pitch circle", rk.pinion, r)
        through, dvec, s = (a[i] for a in geo.slides[rk.slide])
        sv = geo.slides[rk.slide][2]
        sv = sv[np.isfinite(sv)] if np.isfinite(sv).any() else np.zeros(1)
        lo, hi = sv.min() - 4 * unit, sv.max() + 4 * unit
        nrm = np.array([-dvec[1], dvec[0]]) * (-1.0 if rk.teeth == "right" else 1.0)
        base = through + r * nrm
        along = m.slide(rk.slide).along
        out.append((f"{rk.name or 'rack'} pitch line", along, np.array([base + lo * dvec, base + hi * dvec])))
        step = 1.5 * unit  # ticks fixed to the rack: at multiples of `step` from `through`
        ks = np.arange(np.ceil(lo / step), np.floor(hi / step) + 1) * step
        ticks = [row for k_ in ks for row in (base + k_ * dvec, base + k_ * dvec + 0.8 * unit * nrm, [np.nan] * 2)]
        out.append((f"{rk.name or 'rack'} teeth", along, np.array(ticks).reshape(-1, 2)))
    for c in m.cams:
        data = jg.numbers[("cam", c.name)]
        local = profile_points(c, data[1:], 3 * fine)
        out.append((f"{c.name} profile", c.body, _world(jg.frames[c.body][i], local)))
        cp = jg.contact[c.name][i]
        out.append((f"{c.name} contact", "", cp.reshape(1, 2)))
        if c.roller:
            out.append((f"{c.name} roller", "", geo.point(c.roller)[i] + float(data[0]) * circ))
        elif c.flat:
            fth = jg.frames[c.flat][i][2]
            half = 0.6 * np.ptp(local, axis=0).max()
            dvec = np.array([np.cos(fth), np.sin(fth)])
            out.append((f"{c.name} face", c.flat, np.array([cp - half * dvec, cp + half * dvec])))
    return out


def as_circle(label: str, a: np.ndarray):
    """(cx, cy, radius) of a curve that is a circle (a pitch circle, a roller), else None:
    the formats that can draw a true circle draw it round, not as a polygon."""
    if not (label.endswith("pitch circle") or label.endswith("roller")) or not np.isfinite(a).all():
        return None
    c = a[:-1].mean(axis=0)  # the points are evenly spread, the last repeating the first
    return np.array([c[0], c[1], float(np.hypot(*(a[0] - c)))])


_STYLE = {"pitch circle": ("-.", 1.0, 3.2), "mark": ("-", 1.2, 3.2), "pitch line": ("-", 1.4, 3.3),
          "teeth": ("-", 0.8, 3.3), "profile": ("-", 1.6, 3.4), "contact": ("o", 0, 6.5),
          "roller": ("-", 1.2, 5.5), "face": ("-", 3.0, 5.5)}


def style(label: str) -> tuple[str, float, float]:
    """(matplotlib line style, width, z order) of a curve, by the end of its label."""
    return next(v for k, v in _STYLE.items() if label.endswith(k))


class JointArtists:
    """The artists of every gear, rack and cam of a `plot.Drawing`; `update(i)` moves them."""

    def __init__(self, drawing, jg: JointGeometry):
        self.d = drawing
        colour = lambda b: drawing.colour.get(b, "#c0392b" if not b else "#555555")  # noqa: E731
        self.lines = []
        for k, (label, body, xy) in enumerate(curves(drawing.m, drawing.geo, drawing.i0, drawing.r)):
            ls, lw, z = style(label)
            c = "#333333" if label.endswith("roller") else colour(body)
            kw = dict(ms=4) if ls == "o" else dict(lw=lw)
            line, = drawing.ax.plot([], [], ls, color=c, zorder=z, label=label.removesuffix(" mark")
                                    if not label.endswith("mark") else "_" + label, **kw)
            self.lines.append(line)
        for label, body, xy in self._all_poses():
            self._grow(xy)

    def _all_poses(self):
        geo = self.d.geo
        for i in np.flatnonzero(geo.ok)[:: max(1, len(geo.ok) // 24)]:
            yield from curves(self.d.m, geo, int(i), self.d.r)

    def _grow(self, pts):
        """Widen the drawing's box to hold these points."""
        pts = pts[np.isfinite(pts).all(axis=1)]
        if pts.size:
            box = self.d.box
            box[0] = np.minimum(box[0], pts.min(axis=0) - 2 * self.d.r)
            box[1] = np.maximum(box[1], pts.max(axis=0) + 2 * self.d.r)

    def update(self, i: int):
        if not 0 <= i < len(self.d.geo.ok):
            for line in self.lines:
                line.set_data([], [])
            return
        for line, (_, _, xy) in zip(self.lines, curves(self.d.m, self.d.geo, i, self.d.r)):
            line.set_data(*xy.T)
