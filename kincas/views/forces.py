"""Forces and instant centres over a sweep, format-free, for every picture (PNG, GIF, SVG,
DXF, HTML) to draw: springs as zigzags between their two points (always drawn), and when
asked, arrows for the loads, the links' weights, the springs' pulls, the inputs' efforts and the joints'
reactions, and a cross at each moving link's instant centre.

Every value is a quantity kincas already computes at the solved poses, through the compiled
model (`effort(KEY)`, `reaction(P, BODY).x`, `L.icx`: kincas/core/dynamics.py and
geometry.py), with the rates and accelerations the sweep was solved with; a load's force is
the declared vector, a spring's the one of Hooke's law k (d - d0) along its line. What a
mechanism cannot give (reactions with gears, say) is left out, not refused.

A force F is drawn as an arrow of length `scale` |F| ending at its point of application, so
that the largest over the sweep is 15 % of the picture's extent; a torque T (a load on a
link, an angle input's effort) is an arc of radius 3 units of size around its point, the
arrow head turning the way it acts, its value written beside it.

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(ground={"O": (0, 0), "S": (0, -2)},
...     links=[kincas.Link.bar("crank", "O", "A", 1)], inputs=[kincas.Input.angle("crank")],
...     loads=[kincas.Load.spring("S", "A", 10, 1)])
>>> sw = kincas.sweep(m, {"crank.angle": [0.0, np.pi / 2]})
>>> ov = overlay(m, sw)
>>> [a.label for a in ov.arrows][:2], [t.label for t in ov.torques]
(['spring S-A on A', 'reaction(O, crank)'], ['effort(crank.angle)'])
>>> np.round(ov.centres[0][1][0], 9).tolist()       # the crank turns about O
[0.0, 0.0]
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..model.mechanism import GROUND, Mechanism, Param
from ..results import Sweep

COLOURS = {"load": "#d62728", "spring": "#9467bd", "effort": "#2ca02c", "reaction": "#1f77b4",
           "centre": "#111111"}
SHARE = 0.15  # the largest force's arrow, as a share of the picture's extent


@dataclass
class Arrow:
    """A force `vec` (N x 2, force units) acting at `at` (N x 2), NaN where not known."""
    label: str
    kind: str  # "load", "spring", "effort", "reaction"
    at: np.ndarray
    vec: np.ndarray


@dataclass
class Torque:
    """A torque `value` (N, counter-clockwise positive) about `at` (N x 2)."""
    label: str
    kind: str
    at: np.ndarray
    value: np.ndarray


@dataclass
class Overlay:
    arrows: list = field(default_factory=list)
    torques: list = field(default_factory=list)
    centres: list = field(default_factory=list)  # (link, N x 2), NaN where it translates
    scale: float = 0.0  # length per unit of force

    def segments(self, i: int, r: float):
        """What is drawn at pose i, format-free: [(label, kind, polyline, head)] where the
        polyline is K x 2 and head the arrow's head triangle (3 x 2), both in world units;
        `r` is the picture's unit of size."""
        out = []
        for a in self.arrows:
            p, v = a.at[i], a.vec[i] * self.scale
            if np.isfinite(p).all() and np.isfinite(v).all() and np.hypot(*v) > 0.05 * r:
                out.append((a.label, a.kind, np.array([p - v, p]), _head(p, v, r)))
        for t in self.torques:
            p, val = t.at[i], t.value[i]
            if np.isfinite(p).all() and np.isfinite(val) and val != 0:
                s = np.sign(val)  # an arc of 270 degrees, the head at its end
                ang = np.linspace(-0.75 * np.pi * s, 0.6 * np.pi * s, 25) + np.pi / 2
                arc = p + 3 * r * np.stack([np.cos(ang), np.sin(ang)], axis=1)
                tangent = arc[-1] - arc[-2]
                tangent *= 1.5 * r / max(np.hypot(*tangent), 1e-300)
                out.append((t.label, t.kind, arc, _head(arc[-1] + tangent, tangent, r)))
        return out


def _head(tip, v, r):
    """An arrow head at `tip` pointing along v."""
    d = v / max(np.hypot(*v), 1e-300)
    n = np.array([-d[1], d[0]])
    return np.array([tip, tip - 1.6 * r * d + 0.6 * r * n, tip - 1.6 * r * d - 0.6 * r * n])


def _number(m: Mechanism, v) -> float:
    """A declared number or parameter (name, "-name" or Param) at the parameters' values."""
    if isinstance(v, Param):
        return v.scale * m.param_values[v.name]
    if isinstance(v, str):
        return -m.param_values[v[1:]] if v.startswith("-") else m.param_values[v]
    return float(v)


def springs(m: Mechanism) -> list[tuple[str, str, str]]:
    """(label, point a, point b) of each spring load."""
    return [(f"spring {ld.points[0]}-{ld.points[1]}", *ld.points) for ld in getattr(m, "loads", ())
            if ld.kind == "spring"]


def planar_overlay(m: Mechanism, sweep: Sweep, geo, forces: bool = False, centres: bool = False,
                   extent: float | None = None) -> Overlay | None:
    """The `overlay` a picture asks for (None when neither `forces` nor `centres`); they are
    planar quantities, so a spatial mechanism's picture refuses them (ValueError)."""
    if not (forces or centres):
        return None
    from .poses import is_spatial
    if is_spatial(m):
        raise ValueError("forces, centres: the arrows and instant centres are drawn on planar pictures only; "
                         "this mechanism is spatial")
    return overlay(m, sweep, forces=forces, centres=centres, extent=extent, geo=geo)


def weights(m: Mechanism, geo) -> list[Arrow]:
    """Each link's weight m g as an arrow at its centre of gravity (none without gravity).

    The cg is given in the link's frame (default: the mean of its points, which is where the
    mean of its points is in the world too). In the world, at each pose, the frame is the one
    that carries the link's first two points, local p0, p1, onto their world positions P0, P1:
    turned by the angle theta = atan2(P1 - P0) - atan2(p1 - p0), so cg_world = P0 + R(theta)
    (cg - p0)."""
    g = np.array([_number(m, c) for c in m.gravity], float)
    out = []
    if not g.any():
        return out
    for lk in m.links:
        mass = _number(m, lk.inertial.mass)
        if mass == 0:
            continue
        world = np.stack([geo.point(p) for p in lk.point_names], axis=1)  # N x K x 2
        if lk.inertial.cg is None:
            at = world.mean(axis=1)
        else:
            local = np.array([[_number(m, c) for c in xy] for _, xy in lk.points], float)
            cg = np.array([_number(m, c) for c in lk.inertial.cg], float)
            if len(local) < 2:
                at = world[:, 0] + cg - local[0]
            else:
                dw, dl = world[:, 1] - world[:, 0], local[1] - local[0]
                th = np.arctan2(dw[:, 1], dw[:, 0]) - np.arctan2(dl[1], dl[0])
                c, s, v = np.cos(th), np.sin(th), cg - local[0]
                at = world[:, 0] + np.stack([c * v[0] - s * v[1], s * v[0] + c * v[1]], axis=1)
        out.append(Arrow(f"weight of {lk.name}", "load", at, np.tile(mass * g, (len(at), 1))))
    return out


def space_weights(m, geo) -> list[Arrow]:
    """A spatial mechanism's weights m g (N x 3) at each body's centre of gravity (N x 3), from
    the world positions of its points (`geo`: N x K x 3). The cg, given as drawn (default: the
    mean of the points, where a bar's mass is), is carried by the motion that carries the
    body's points: an affine combination of them when it lies in their span (exact for any
    rigid motion), else the best rotation of three or more points not in line (Kabsch); a
    two-point body's cg off its line has no such motion (its spin is no freedom): left out."""
    g = np.array([_number(m, c) for c in m.gravity], float)
    if not g.any():
        return []
    out = []
    for b in m.links:
        mass = _number(m, b.mass)
        if mass == 0:
            continue
        world = np.stack([geo.point(p) for p in b.point_names], axis=1)  # N x K x 3
        if b.cg is None or b.two_point:
            at = world.mean(axis=1)
        else:
            local = np.array([[_number(m, c) for c in xyz] for _, xyz in b.points], float)
            at = _carried(local, world, np.array([_number(m, c) for c in b.cg], float))
        if at is not None:
            out.append(Arrow(f"weight of {b.name}", "load", at, np.tile(mass * g, (len(at), 1))))
    return out


def _carried(local, world, cg):
    """`cg` (as drawn, with the body's points `local`, K x 3) where the motion taking `local`
    to `world` (N x K x 3) takes it; None when the points do not fix it."""
    lc = local.mean(axis=0)
    A = local - lc
    size = max(float(np.abs(A).max()), 1e-300)
    w, *_ = np.linalg.lstsq(A.T, cg - lc, rcond=None)  # cg - lc = A' w, a combination
    if np.linalg.norm(A.T @ w - (cg - lc)) <= 1e-9 * size:
        wc = world.mean(axis=1)
        return wc + np.einsum("k,nkj->nj", w, world - wc[:, None])
    if np.linalg.matrix_rank(A, tol=1e-9 * size) < 2:
        return None
    out = np.full((len(world), 3), np.nan)
    for i, W in enumerate(world):
        if np.isfinite(W).all():
            wc = W.mean(axis=0)
            U, _, Vt = np.linalg.svd(A.T @ (W - wc))  # R A' ~ (W - wc)': R = V diag(1, 1, det) U'
            d = np.sign(np.linalg.det(Vt.T @ U.T))
            out[i] = wc + Vt.T @ np.diag([1.0, 1.0, d]) @ U.T @ (cg - lc)
    return out


def actuator(m: Mechanism, parameter: str) -> tuple[str, str] | None:
    """The ends (P, Q) of the two-point link whose length is `parameter` (a linear actuator
    driven by a parameter input), None when no link's length is it."""
    for lk in m.links:
        if lk.two_point:
            (p, _), (q, (length, _)) = lk.points
            if length == parameter or (isinstance(length, Param) and length.name == parameter
                                       and length.scale == 1):
                return p, q
    return None


def zigzag(a, b, r: float, turns: int = 6) -> np.ndarray:
    """A spring's zigzag from a to b (K x 2): straight ends, `turns` teeth of width 1.5 r."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    d = b - a
    n = np.hypot(*d)
    if not np.isfinite(n) or n == 0:
        return np.array([a, b])
    u, w = d / n, np.array([-d[1], d[0]]) / n
    t = np.concatenate([[0.0, 0.15], 0.15 + 0.7 * (np.arange(2 * turns) + 0.5) / (2 * turns), [0.85, 1.0]])
    side = np.concatenate([[0, 0], 0.75 * r * (-1.0) ** np.arange(2 * turns), [0, 0]])
    return a + np.outer(t * n, u) + np.outer(side, w)


def overlay(m: Mechanism, sweep: Sweep, *, forces: bool = True, centres: bool = True,
            extent: float | None = None, geo=None) -> Overlay:
    """The arrows, torques and instant centres over the sweep (see the module's text);
    `extent`: the picture's size that sets the arrows' scale (default: the points' span);
    `geo`: the sweep's `views.poses.geometry`, when already made."""
    from ..core.numeric import compile
    from ..core.dynamics import bodies_at
    from .poses import geometry
    geo = geometry(m, sweep) if geo is None else geo
    n, ok = len(sweep), sweep.ok
    point = geo.point
    ov = Overlay()
    names: list[str] = []
    todo = []  # (kind, label, builder of the drawn thing from the evaluated columns)
    if forces:
        for ld in m.loads:
            if ld.kind == "force":
                f = np.array([_number(m, ld.value[0]), _number(m, ld.value[1])])
                ov.arrows.append(Arrow(f"load at {ld.at}", "load", point(ld.at), np.tile(f, (n, 1))))
            elif ld.kind == "torque":
                pts = [p for p in m.link(ld.at).point_names]
                at = np.nanmean(np.stack([point(p) for p in pts]), axis=0)
                ov.torques.append(Torque(f"torque on {ld.at}", "load", at, np.full(n, _number(m, ld.value))))
        ov.arrows += weights(m, geo)
        for label, a, b in springs(m):
            ld = next(x for x in m.loads if x.kind == "spring" and x.points == (a, b))
            k, d0 = _number(m, ld.stiffness), _number(m, ld.free_length)
            pa, pb = point(a), point(b)
            d = np.hypot(*(pb - pa).T)
            pull = (k * (d - d0) / np.where(d > 0, d, np.nan))[:, None] * (pa - pb)  # on b, towards a
            for p, (tip, f) in zip((b, a), ((pb, pull), (pa, -pull))):
                if p in m.moving_points:
                    ov.arrows.append(Arrow(f"{label} on {p}", "spring", tip, f))
        for inp in m.inputs:
            key = f"effort({inp.key})"
            if inp.kind == "angle":
                lk = m.link(inp.target.partition("/")[0])
                pivot = next((p for p in lk.point_names if p in m.ground_points), lk.point_names[0])
                todo.append(("torque", key, pivot, [key]))
            elif inp.kind == "slide":
                todo.append(("along", key, m.slide(inp.target), [key]))
            elif inp.kind == "parameter" and (ends := actuator(m, inp.target)) is not None:
                todo.append(("actuator", key, ends, [key]))
        for p in list(m.ground_points) + list(m.moving_points):
            at = bodies_at(m, p)
            if len(at) >= 2:
                b = next((x for x in at if x != GROUND), at[-1])
                key = f"reaction({p}, {b})"
                todo.append(("arrow", key, p, [key + ".x", key + ".y"]))
        for sl in m.slides:
            key = f"reaction({sl.name})"
            todo.append(("arrow", key, sl.point, [key + ".x", key + ".y"]))
    if centres:
        for lk in m.links:
            todo.append(("centre", lk.name, None, [f"{lk.name}.icx", f"{lk.name}.icy"]))
    model = compile(m)
    wanted = [t for t in todo if not model.check_names(t[3])]
    names = [q for t in wanted for q in t[3]]
    values = _evaluate(model, m, sweep, names) if names else {}
    for kind, label, where, qs in wanted:
        cols = [values[q] for q in qs]
        if kind == "torque":
            ov.torques.append(Torque(label, "effort", point(where), cols[0]))
        elif kind == "along":
            through, d, s = geo.slides[where.name]
            ov.arrows.append(Arrow(label, "effort", point(where.point), cols[0][:, None] * d))
        elif kind == "actuator":  # along the actuator, on its far end (pushing it out when > 0)
            p, q = (point(e) for e in where)
            d = q - p
            u = d / np.where(np.hypot(*d.T) > 0, np.hypot(*d.T), np.nan)[:, None]
            ov.arrows.append(Arrow(label, "effort", q, cols[0][:, None] * u))
        elif kind == "arrow":
            ov.arrows.append(Arrow(label, "reaction" if label.startswith("reaction") else "load",
                                   point(where), np.stack(cols, axis=1)))
        else:
            xy = np.stack(cols, axis=1)
            if np.isfinite(xy).any():
                ov.centres.append((label, xy))
    mags = [np.hypot(*a.vec[ok].T) for a in ov.arrows]
    big = max((float(np.nanmax(v)) for v in mags if np.isfinite(v).any()), default=0.0)
    if extent is None:
        pts = geo.xy[np.isfinite(geo.xy).all(axis=2)]
        extent = float(np.ptp(pts, axis=0).max()) if pts.size else m.size()
    ov.scale = SHARE * extent / big if big > 0 else 0.0
    return ov


def _evaluate(model, m: Mechanism, sweep: Sweep, names: list[str]) -> dict[str, np.ndarray]:
    """The quantities `names` at the sweep's solved poses (NaN elsewhere), with its rates
    and accelerations."""
    keys = [i.key for i in m.inputs]
    ok, n = sweep.ok, len(sweep)
    col = lambda d, k: np.broadcast_to(np.asarray(d.get(k, 0.0), float), (n,))  # noqa: E731
    U = np.stack([col(sweep.inputs, k) for k in keys], axis=1)[ok]
    Ud = np.stack([col(sweep.rates, k) for k in keys], axis=1)[ok]
    Udd = np.stack([col(sweep.accelerations, k) for k in keys], axis=1)[ok]
    p = np.array([v for _, v in m.parameters], float)
    out = np.full((len(names), n), np.nan)
    if ok.any():
        out[:, ok] = model.quantities(names, sweep.q[ok], U, p, Ud, Udd)
    return dict(zip(names, out))
