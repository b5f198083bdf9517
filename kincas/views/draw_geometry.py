"""Kinematic geometry in pictures: the evolute of a point's path (its centres of curvature)
and the centrodes of a link (the paths of its instant centre: fixed, on the ground; moving,
on the link, drawn where the link is at the drawn pose, so that it touches the fixed one at
the instant centre). The values are the exact quantities `P.cx P.cy` and `L.icx L.icy`
(kincas/core/geometry.py) at the solved poses; where they are null the curve breaks.

`kincas solve SCENE --plot out.png --evolute P --centrodes coupler`; from Python:

>>> import numpy as np, kincas
>>> from matplotlib.figure import Figure
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
>>> sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 2 * np.pi, 73)})
>>> ax = kincas.plot.draw(m, sw, 0, ax=Figure().subplots())
>>> curves = draw_geometry(ax, m, sw, 0, evolute=["C"], centrodes=["coupler"])
>>> sorted(curves), curves["coupler fixed centrode"].shape
(['C evolute', 'coupler fixed centrode', 'coupler moving centrode'], (73, 2))
"""
from __future__ import annotations

import numpy as np

from ..model.mechanism import Mechanism
from ..results import Sweep


def check_geometry(m: Mechanism, evolute=(), centrodes=()) -> None:
    """ValueError naming the option when a point or a link is unknown."""
    points = set(m.moving_points) | set(m.ground_points)
    bad = [p for p in evolute or () if p not in points]
    if bad:
        raise ValueError(f"--evolute: unknown point(s) {bad} (points: {sorted(points)})")
    links = [lk.name for lk in m.links]
    bad = [k for k in centrodes or () if k not in links]
    if bad:
        raise ValueError(f"--centrodes: unknown link(s) {bad} (links: {links})")


def curves(m: Mechanism, sweep: Sweep, pose: int, evolute=(), centrodes=()) -> dict[str, np.ndarray]:
    """name -> (N x 2) points, NaN where undefined or not solved: '<P> evolute',
    '<L> fixed centrode', '<L> moving centrode' (placed with the link at `pose`)."""
    from ..core.numeric import compile
    check_geometry(m, evolute, centrodes)
    model = compile(m)
    names = [f"{p}.{c}" for p in evolute for c in ("cx", "cy")]
    names += [f"{k}.{c}" for k in centrodes for c in ("icx", "icy", "angle")]
    n, ok = len(sweep), np.asarray(sweep.ok)
    vals = np.full((len(names), n), np.nan)
    if ok.any() and names:
        keys = list(sweep.inputs)
        col = lambda d: np.stack([np.asarray(d[k], float) for k in keys], axis=1)[ok]
        p = np.array([v for _, v in m.parameters], dtype=float)
        vals[:, ok] = model.quantities(names, sweep.q[ok], col(sweep.inputs), p,
                                       col(sweep.rates), col(sweep.accelerations))
    v = dict(zip(names, vals))
    out = {f"{p} evolute": np.stack([v[f"{p}.cx"], v[f"{p}.cy"]], axis=1) for p in evolute}
    for k in centrodes:
        ic = np.stack([v[f"{k}.icx"], v[f"{k}.icy"]], axis=1)
        out[f"{k} fixed centrode"] = ic
        origin, th = _frame(m, model, sweep, k, v[f"{k}.angle"])
        # the instant centre in the link's own frame at every pose, then placed as at `pose`
        rel = ic - origin
        c, s = np.cos(th), np.sin(th)
        local = np.stack([c * rel[:, 0] + s * rel[:, 1], -s * rel[:, 0] + c * rel[:, 1]], axis=1)
        c0, s0 = np.cos(th[pose]), np.sin(th[pose])
        out[f"{k} moving centrode"] = origin[pose] + np.stack(
            [c0 * local[:, 0] - s0 * local[:, 1], s0 * local[:, 0] + c0 * local[:, 1]], axis=1)
    return out


def _frame(m, model, sweep, link, theta):
    """The origin of a link's frame at every pose, from one of its points."""
    lk = m.link(link)
    name, (lx, ly) = lk.points[0]
    lx, ly = m.value(lx), m.value(ly)
    if name in m.ground_points:
        xy = np.tile([m.value(c) for c in dict(m.ground)[name]], (len(sweep), 1))
    else:
        j = list(m.moving_points).index(name)
        xy = np.full((len(sweep), 2), np.nan)
        ok = np.asarray(sweep.ok)
        keys = list(sweep.inputs)
        U = np.stack([np.asarray(sweep.inputs[k], float) for k in keys], axis=1)
        p = np.array([v for _, v in m.parameters], dtype=float)
        for i in np.flatnonzero(ok):
            xy[i] = model.points(sweep.q[i], U[i], p)[:, j]
    c, s = np.cos(theta), np.sin(theta)
    return xy - np.stack([c * lx - s * ly, s * lx + c * ly], axis=1), theta


def draw_geometry(ax, m: Mechanism, sweep: Sweep, pose: int, evolute=(), centrodes=()):
    """Add evolutes and centrodes to a drawing made by `kincas.plot.draw`; returns the
    curves drawn (name -> N x 2 points)."""
    got = curves(m, sweep, pose, evolute, centrodes)
    styles = {"evolute": ("--", "C3"), "fixed centrode": ("-", "C2"), "moving centrode": (":", "C4")}
    lim = (ax.get_xlim(), ax.get_ylim())
    (x0, x1), (y0, y1) = lim
    far = 2 * ((x1 - x0) + (y1 - y0))
    for name, xy in got.items():
        ls, colour = next(v for k, v in styles.items() if name.endswith(k))
        # a centre passing through infinity comes back from the other side: break the line
        jumps = np.flatnonzero(np.linalg.norm(np.diff(xy, axis=0), axis=1) > far) + 1
        xy = np.insert(xy, jumps, np.nan, axis=0)
        ax.plot(xy[:, 0], xy[:, 1], ls, color=colour, lw=1.2, label=name)
    # far centres (a path nearly straight, a link nearly translating) must not shrink the
    # mechanism to a dot: keep the view at twice the drawing's extent, scales equal
    w, h = x1 - x0, y1 - y0
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlim(x0 - w / 2, x1 + w / 2)
    ax.set_ylim(y0 - h / 2, y1 + h / 2)
    if got:
        ax.legend(loc="best", fontsize="small")
    return got
