"""World positions of every pose of a sweep, as every picture (matplotlib, SVG, DXF, HTML)
draws them: points and slide lines from the solved unknowns `sweep.q` through the compiled
model, so a picture shows exactly the poses that were solved (NaN where a pose was not).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.drawing import pose_values
from ..model.mechanism import GROUND, Mechanism
from ..results import Sweep


@dataclass
class Geometry:
    """World positions over a sweep: `xy[i, k]` is point `names[k]` at pose i (NaN when the
    pose was not solved); each slide's line at each pose as a point `through` (N x 2), a unit
    direction `direction` (N x 2) and the slide coordinate `s` (N,) of its point. A spatial
    sweep has 3 columns where a planar one has 2; drawn in a view
    (`kincas.views.projection.project`) it has 2 again, and `depth` (N x K, larger farther from
    the viewer), `world` (the N x K x 3 positions) and `view` (its name) are set.

    >>> import numpy as np, kincas
    >>> m = kincas.Mechanism(ground={"O": (0, 0)},
    ...     links=[kincas.Link.bar("crank", "O", "A", 1), kincas.Link.bar("rod", "A", "B", 3)],
    ...     slides=[kincas.Slide("B", "ground", name="slider")],
    ...     inputs=[kincas.Input.angle("crank")], guess={"B": (3.5, 0)})
    >>> g = geometry(m, kincas.sweep(m, {"crank.angle": [0.0, np.pi / 2]}))
    >>> np.round(g.point("B"), 6).tolist(), np.round(g.slides["slider"][2], 6).tolist()
    ([[4.0, 0.0], [2.828427, 0.0]], [4.0, 2.828427])
    """

    names: list[str]
    xy: np.ndarray
    slides: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]
    ok: np.ndarray
    joints: object = field(default=None, repr=False)  # gears, racks, cams: views/draw_joints.py
    depth: np.ndarray | None = field(default=None, repr=False)
    world: np.ndarray | None = field(default=None, repr=False)
    view: str | None = None

    def point(self, name: str) -> np.ndarray:
        """(N x 2) positions of one point (N x 3 in space)."""
        return self.xy[:, self.names.index(name)]


def geometry(m: Mechanism, sweep: Sweep) -> Geometry:
    """Positions of all points and the lines of all slides at every pose of `sweep`."""
    from ..core.numeric import compile
    model = compile(m)
    keys = [i.key for i in m.inputs]
    missing = [k for k in keys if k not in sweep.inputs]
    if missing:
        raise ValueError(f"the sweep has no values for the inputs {missing}: was it made with this mechanism?")
    n, ok = len(sweep), sweep.ok
    names = list(m.ground_points) + list(m.moving_points)
    U = np.stack([np.asarray(sweep.inputs[k], float) for k in keys], axis=1).reshape(n, len(keys))
    p = np.array([v for _, v in m.parameters], float)
    Q = np.where(ok[:, None], sweep.q, 0.0)  # what depends on q is masked below
    raw = pose_values(model, Q, U, p)
    ng, dim = len(m.ground_points), model.dim  # (x, y) or, in space, (x, y, z)
    xy = raw[:, :dim * len(names)].reshape(n, len(names), dim).copy()
    xy[~ok, ng:] = np.nan  # ground points are known at every pose, moving ones when solved
    slides = {}
    if dim == 3:  # per slide: through (N x 3), unit direction or normal (N x 3), s (N,)
        for k, sl in enumerate(m.slides):
            c = 3 * len(names) + 6 * k
            through, d = raw[:, c:c + 3].copy(), raw[:, c + 3:c + 6].copy()
            if sl.along != GROUND:
                through[~ok], d[~ok] = np.nan, np.nan
            s = np.einsum("ij,ij->i", xy[:, names.index(sl.point)] - through, d)
            slides[sl.name] = (through, d, s)
        return Geometry(names, xy, slides, ok, None)
    for k, sl in enumerate(m.slides):
        c = 2 * len(names) + 3 * k
        through, angle = raw[:, c:c + 2].copy(), raw[:, c + 2].copy()
        if sl.along != GROUND:
            through[~ok], angle[~ok] = np.nan, np.nan
        d = np.stack([np.cos(angle), np.sin(angle)], axis=1)
        s = np.einsum("ij,ij->i", xy[:, names.index(sl.point)] - through, d)  # signed distance
        slides[sl.name] = (through, d, s)
    from .draw_joints import joint_geometry
    return Geometry(names, xy, slides, ok, joint_geometry(model, Q, U, p, ok))


def _hull(pts: np.ndarray) -> list[int]:
    """Indices of the convex hull of 2-D points, counter-clockwise (Andrew's monotone chain)."""
    def turn(o, a, b):  # z of (a - o) x (b - o): positive when o -> a -> b turns left
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    def chain(idx):  # keep only left turns
        out: list[int] = []
        for i in idx:
            while len(out) >= 2 and turn(pts[out[-2]], pts[out[-1]], pts[i]) <= 0:
                out.pop()
            out.append(i)
        return out
    order = sorted(range(len(pts)), key=lambda i: tuple(pts[i]))
    return chain(order)[:-1] + chain(order[::-1])[:-1]



def default_pose(sweep: Sweep | np.ndarray) -> int:
    """The pose drawn when none is asked for: the first one solved (0 when none was)."""
    k = np.flatnonzero(sweep.ok if isinstance(sweep, Sweep) else sweep)
    return int(k[0]) if k.size else 0


def is_spatial(m) -> bool:
    """True for a mechanism declared in space (`space = "3d"`): one that has a `space`
    attribute "3d". Planar mechanisms have none (or "2d").

    >>> import kincas
    >>> is_spatial(kincas.Mechanism(ground={"O": (0, 0)}, links=[kincas.Link.bar("c", "O", "A", 1)],
    ...                             inputs=[kincas.Input.angle("c")]))
    False
    """
    return str(getattr(m, "space", "2d")).lower() == "3d"


def _on_line(sl, geo) -> bool:
    """A slide the pictures draw: one on a line whose line the geometry has (a spatial slide
    on a plane keeps its point on a plane: no guide, no block)."""
    return getattr(sl, "on_line", True) and sl.name in geo.slides


def links_of(m) -> tuple:
    """The bodies a picture draws: a planar mechanism's `links`, a spatial one's `bodies`
    (each with `name` and `point_names`).

    >>> import kincas
    >>> [lk.name for lk in links_of(kincas.Mechanism(ground={"O": (0, 0)},
    ...     links=[kincas.Link.bar("c", "O", "A", 1)], inputs=[kincas.Input.angle("c")]))]
    ['c']
    """
    return tuple(m.links if hasattr(m, "links") else m.bodies)


def check_paths(m: Mechanism, paths) -> list[str]:
    """The points whose paths are drawn: `paths`, checked, or every moving point (None).

    >>> import kincas
    >>> m = kincas.Mechanism(ground={"O": (0, 0)}, links=[kincas.Link.bar("c", "O", "A", 1)],
    ...                      inputs=[kincas.Input.angle("c")])
    >>> check_paths(m, None), check_paths(m, ["O"])
    (['A'], ['O'])
    """
    bad = [p for p in paths or () if p not in m.moving_points + m.ground_points]
    if bad:
        raise ValueError(f"paths: unknown point(s) {bad} (points: {m.ground_points + m.moving_points})")
    return list(m.moving_points if paths is None else paths)
