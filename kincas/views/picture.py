"""What a vector picture of a sweep shows, independent of the format (SVG, DXF, HTML):
every body's outline at each pose, the ground pivots, each slide's guide, and the paths.

Positions come from `kincas.views.poses.geometry` (the solved unknowns through the compiled
model), so every format draws exactly the poses that were solved. A body of two points is a
bar; of three or more, the convex hull of its points at the first solved pose (a bar between
the two farthest when they are collinear). Paths are densified with the solver
(`dense_paths`): extra poses solved between the sweep's, not a spline through them.

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(ground={"O": (0, 0)},
...     links=[kincas.Link.bar("crank", "O", "A", 1), kincas.Link.bar("rod", "A", "B", 3)],
...     slides=[kincas.Slide("B", "ground", name="slider")],
...     inputs=[kincas.Input.angle("crank")], guess={"B": (3.5, 0)})
>>> pic = picture(m, kincas.sweep(m, {"crank.angle": np.linspace(0, 2 * np.pi, 5)}))
>>> [b.name for b in pic.bodies], pic.guides[0].name, np.round(pic.xy[0, pic.names.index("B")], 6).tolist()
(['crank', 'rod'], 'slider', [4.0, 0.0])
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..model.mechanism import GROUND, Mechanism
from ..results import Sweep
from .poses import _hull, _on_line, check_paths, default_pose, geometry, links_of
from .projection import drawn, project_paths, ring_points

COLOURS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
           "#7f7f7f", "#bcbd22", "#17becf"]  # matplotlib's tab10, as the PNG drawings use
INK = "#222222"


@dataclass
class Body:
    name: str
    ring: list[int]  # indices into `names`: a bar (2) or a closed polygon (3+)
    colour: str
    driven: bool = False


@dataclass
class Guide:
    """A slide: its line at each pose (`through` N x 2, unit `direction` N x 2), the coordinate
    range drawn (`lo`, `hi`) and whether it is fixed to the ground."""
    name: str
    point: int
    through: np.ndarray
    direction: np.ndarray
    lo: float
    hi: float
    ground: bool
    colour: str


@dataclass
class Picture:
    names: list[str]
    xy: np.ndarray  # N x P x 2 (x 3: a spatial one in space), NaN where a pose was not solved
    ok: np.ndarray
    ground: list[int]
    bodies: list[Body]
    guides: list[Guide]
    paths: dict[str, np.ndarray] = field(default_factory=dict)  # point -> M x 2 (NaN breaks)
    r: float = 1.0  # the picture's unit of size (2 % of its extent)
    first: int = 0  # the first solved pose
    # pose -> [(label, body, polyline)] of the gears, racks and cams (views/draw_joints.py)
    joint_curves: object = field(default=lambda i, fine=121: [], repr=False)
    depth: np.ndarray | None = field(default=None, repr=False)  # N x P, larger farther (in a view)
    view: str | None = None  # a spatial picture's view (views/projection.py), None in space or planar
    springs: list = field(default_factory=list)  # (label, index a, index b): views/forces.py
    overlay: object = None  # force arrows and instant centres when asked (views/forces.Overlay)

    def spring_lines(self, i: int) -> list[tuple[str, np.ndarray]]:
        """(label, zigzag K x 2) of each spring at pose i whose ends are known (in space, with
        `world=True`: the straight line K x 3 between them)."""
        from .forces import zigzag
        out = []
        for label, a, b in self.springs:
            pa, pb = self.xy[i, a], self.xy[i, b]
            if np.isfinite(pa).all() and np.isfinite(pb).all():
                out.append((label, zigzag(pa, pb, self.r) if len(pa) == 2 else np.array([pa, pb])))
        return out

    def box(self) -> np.ndarray:
        """[[xmin, ymin], [xmax, ymax]] of everything drawn over the sweep, with a margin."""
        parts = [self.xy[np.isfinite(self.xy).all(axis=2)]]
        parts += [p[np.isfinite(p).all(axis=1)] for p in self.paths.values()]
        if self.ok.any():
            parts += [c[np.isfinite(c).all(axis=1)] for _, _, c in self.joint_curves(self.first)]
        for g in self.guides:
            for s in (g.lo, g.hi):
                e = g.through + s * g.direction
                parts.append(e[np.isfinite(e).all(axis=1)])
        pts = np.concatenate([p for p in parts if p.size] or [np.zeros((1, self.xy.shape[-1]))])
        return np.array([pts.min(axis=0) - 5 * self.r, pts.max(axis=0) + 5 * self.r])


def picture(m: Mechanism, sweep: Sweep, paths=None, dense: int | dict = 0, view: str | None = None,
            world: bool = False, *, forces: bool = False, centres: bool = False) -> Picture:
    """The Picture of `sweep`; `paths` names the points whose paths are drawn (default: every
    moving point); `dense` > 0 solves that many extra poses between each two of the sweep's
    for smooth paths, or is those paths already solved (point -> M x 2, from `dense_paths`:
    several pictures of one sweep share one solve). A spatial sweep is drawn in `view`
    (default isometric, `kincas.views.projection`), or kept in space with `world=True`.
    `forces`, `centres`: the arrows of the loads, efforts and reactions, the instant centres
    (views/forces.py; planar mechanisms only, ValueError for a spatial one)."""
    geo = drawn(m, sweep, view, world)
    names, xy = geo.names, geo.xy
    i0 = default_pose(geo.ok)
    pts = xy[np.isfinite(xy).all(axis=2)]
    span = float(np.ptp(pts, axis=0).max()) if pts.size else 0.0
    r = 0.02 * (span if span > 0 else m.size())
    driven = {i.target for i in m.inputs if i.kind == "angle"}
    links = links_of(m)
    colour = {lk.name: COLOURS[k % 10] for k, lk in enumerate(links)}
    bodies = []
    for lk in links:
        idx = [names.index(p) for p in lk.point_names]
        ring = idx
        if len(idx) >= 3:  # the outline in the body's plane (a spatial body: its own plane)
            p0 = ring_points(geo, i0, idx)
            hull = _hull(p0) if np.isfinite(p0).all() else [0, 1]
            ring = [idx[k] for k in hull]
            x, y = p0[hull].T
            area = 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
            if not np.isfinite(p0).all():  # no pose solved: no outline to take, a bar of its first two
                ring = idx[:2]
            elif len(ring) < 3 or not area > (0.5 * r) ** 2:  # collinear: a bar between the farthest
                far = np.hypot(*(p0 - p0[0]).T)
                ring = [idx[0], idx[int(np.nanargmax(far))]]
        bodies.append(Body(lk.name, ring, colour[lk.name], lk.name in driven))
    guides = []
    for sl in (sl for sl in m.slides if _on_line(sl, geo)):
        through, d, s = geo.slides[sl.name]
        sv = s[np.isfinite(s)] if np.isfinite(s).any() else np.zeros(1)
        guides.append(Guide(sl.name, names.index(sl.point), through, d, float(sv.min() - 4 * r),
                            float(sv.max() + 4 * r), sl.along == GROUND,
                            INK if sl.along == GROUND else colour[sl.along]))
    chosen = check_paths(m, paths)
    if isinstance(dense, dict):
        path_xy = {p: dense[p] for p in chosen}
    else:
        path_xy = dense_paths(m, sweep, chosen, dense) if dense > 0 else {p: geo.point(p) for p in chosen}
    from .forces import planar_overlay, springs
    over = planar_overlay(m, sweep, geo, forces, centres, extent=span)
    return Picture(names, xy, geo.ok, [names.index(g) for g in m.ground_points], bodies, guides,
                   project_paths(path_xy, geo.view), r, i0, _joint_curves(m, geo, r), geo.depth, geo.view,
                   [(label, names.index(a), names.index(b)) for label, a, b in springs(m)], over)


def _joint_curves(m: Mechanism, geo, r: float):
    from .draw_joints import curves
    return lambda i, fine=121: (curves(m, geo, i, r, fine) if geo.joints is not None and 0 <= i < len(geo.ok)
                                else [])


def smooth_steps(n: int) -> int:
    """The extra poses to solve between two of a sweep of `n` poses for paths through about
    360 points (at most 16); 0 for more than 60 poses, which are dense enough as they are.

    >>> smooth_steps(13), smooth_steps(60), smooth_steps(361)
    (16, 6, 0)
    """
    if n < 2 or n > 60:
        return 0
    return int(min(16, max(0, -(-360 // (n - 1)) - 1)))


def dense_paths(m: Mechanism, sweep: Sweep, points: list[str], per_step: int) -> dict[str, np.ndarray]:
    """Paths through `per_step` extra poses between each two solved neighbours of the sweep,
    each SOLVED (a sweep over the finer inputs from the first pose's assembly, so it keeps the
    branch); where the finer sweep fails, its poses are left out (NaN breaks the line)."""
    from ..analysis.sweeps import sweep as run
    n = len(sweep)
    if n < 2 or not points:
        return {p: geometry(m, sweep).point(p) for p in points}
    t = np.linspace(0.0, n - 1.0, (n - 1) * (per_step + 1) + 1)
    keys = {i.key for i in m.inputs}  # (a simulation's sweep also has the time `t`)
    fine = {k: np.interp(t, np.arange(n), np.asarray(v, float)) for k, v in sweep.inputs.items() if k in keys}
    i0 = int(np.flatnonzero(sweep.ok)[0]) if sweep.ok.any() else 0
    geo0 = geometry(m, sweep)
    guess = {p: tuple(geo0.point(p)[i0]) for p in m.moving_points} if sweep.ok.any() else None
    mm = m.with_guess(**guess) if guess else m
    start = i0 * (per_step + 1)  # the fine sweep starts at the first solved pose, on its branch
    fine = {k: v[start:] for k, v in fine.items()}
    fsw = run(mm, fine, report=[])
    g = geometry(mm, fsw)
    out = {}
    for p in points:
        xy = np.full((len(t), g.xy.shape[2]), np.nan)  # 3 columns in space
        xy[start:] = g.point(p)
        out[p] = xy
    return out
