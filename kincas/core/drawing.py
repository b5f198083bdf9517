"""World coordinates of what a drawing shows, at every pose of a sweep: points, slides'
lines, bodies' frames and cams' contacts (the pictures in kincas/views/plot.py and
kincas/views/draw_joints.py draw them; they get numpy arrays from here).

A body's frame is its origin (ox, oy) and angle th: a local vector v maps to
origin + R(th) v. The CasADi functions are built once per model (`Model.memo`: threads
drawing at once build them once) and evaluated on all poses in one mapped call.

>>> import numpy as np, kincas
>>> from kincas.core.numeric import compile
>>> m = kincas.Mechanism(ground={"O": (0, 0)},
...     links=[kincas.Link.bar("crank", "O", "A", 1), kincas.Link.bar("rod", "A", "B", 3)],
...     slides=[kincas.Slide("B", "ground", name="slider")],
...     inputs=[kincas.Input.angle("crank")], guess={"B": (3.5, 0)})
>>> sw = kincas.sweep(m, {"crank.angle": [0.0]})
>>> raw = pose_values(compile(m), sw.q, np.zeros((1, 1)), np.zeros(0))
>>> np.round(raw, 6).tolist()  # O, then A and B, then the slide's point, direction angle
[[0.0, 0.0, 1.0, 0.0, 4.0, 0.0, 0.0, 0.0, 0.0]]
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from ..model.joints import Circle


# --- points and slides ---


def _build_pose_function(model):
    sym, m = model.sym, model.sym.mech
    out = [c for g in m.ground_points for c in sym.ground_at(g)]
    out += [c for p in m.moving_points for c in sym.points[p]]
    if sym.dim == 3:  # a spatial slide: its `through` point and direction (or normal), world axes
        from .quaternions import apply, rotation
        for sl in m.slides:
            X = sym.world(sl.along, sym._rel(sl.through))
            out += [X[i] + sym.origin[i] for i in range(3)]
            out += apply(rotation(sym.frames[sl.along][1]), list(sl.direction or sl.normal))
        return ca.Function("pose", [sym.q, sym.u, sym.p], [ca.vertcat(*out)])
    for sl in m.slides:
        ox, oy, th = sym.frames[sl.along]
        tx, ty = (sym.val(v) for v in sl.through)
        out += [ox + ca.cos(th) * tx - ca.sin(th) * ty, oy + ca.sin(th) * tx + ca.cos(th) * ty,
                th + sym.val(sl.angle)]
    return ca.Function("pose", [sym.q, sym.u, sym.p], [ca.vertcat(*out)])


def _mapped(f, Q, U, p):
    """f(q, u, p) at every row of Q and U (N rows), as an N x (outputs) array."""
    n = Q.shape[0]
    P = np.repeat(np.reshape(np.asarray(p, float), (-1, 1)), n, axis=1)
    return np.asarray(f.map(n)(np.asarray(Q, float).T, np.asarray(U, float).T, P)).T.reshape(n, -1)


def pose_values(model, Q, U, p) -> np.ndarray:
    """Per pose: the ground points' and moving points' (x, y), then for each slide the point
    its line goes `through` (x, y) and the line's direction angle, in world coordinates.
    For a spatial mechanism (`model.sym.dim` 3): points' (x, y, z), then per slide its
    `through` point (x, y, z) and its direction (a plane's normal), a unit vector.

    Parameters
    ----------
    model : kincas.core.numeric.Model
    Q, U : numpy.ndarray
        Unknowns (N x nq) and inputs (N x nu) of the poses.
    p : numpy.ndarray
        Parameter values.

    Returns
    -------
    numpy.ndarray
        N x (2 (ground + moving points) + 3 slides); in space N x (3 points + 6 slides).

    Examples
    --------
    See the module's example.
    """
    return _mapped(model.memo("plot.pose", lambda: _build_pose_function(model)), Q, U, p)


# --- gears, racks and cams ---


def joint_bodies(m) -> list[str]:
    """The bodies whose frames the pictures of gears, racks and cams need, in order."""
    out = []
    for g in m.gears:
        out += [*g.links]
    for r in m.racks:
        out += [r.pinion, m.slide(r.slide).along]
    for c in m.cams:
        out += [c.body] + ([c.flat] if c.flat else [])
    return list(dict.fromkeys(out))


def _build_joint_functions(model):
    sym, m = model.sym, model.sym.mech
    out = [c for b in joint_bodies(m) for c in sym.frames[b]]
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
    return (ca.Function("joints_pose", [sym.q, sym.u, sym.p], [ca.vertcat(*out)]),
            ca.Function("joints_numbers", [sym.p], [ca.vertcat(*nums)]))


def joint_values(model, Q, U, p) -> tuple[np.ndarray, np.ndarray]:
    """Per pose the frames (ox, oy, th) of `joint_bodies`, then each cam's contact point
    (x, y); and the joints' numbers at p: gears' radii, racks' radii, each cam's roller
    radius and profile numbers (circle: centre x, y and radius; spline: its radii).

    Parameters
    ----------
    model : kincas.core.numeric.Model
    Q, U : numpy.ndarray
        Unknowns (N x nq) and inputs (N x nu) of the poses.
    p : numpy.ndarray
        Parameter values.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        N x (3 bodies + 2 cams), and the numbers.

    Examples
    --------
    >>> import numpy as np, kincas
    >>> from kincas.core.numeric import compile
    >>> from kincas.model import Cam, Circle
    >>> m = kincas.Mechanism(ground={"O": (0, 0)},
    ...     links=[kincas.Link.bar("shaft", "O", "K", 10), kincas.Link.bar("arm", "O", "F", 45)],
    ...     cams=[Cam("cam", "shaft", Circle((10, 0), 40), knife="F")],
    ...     inputs=[kincas.Input.angle("shaft")], guess={"F": (0, 45)})
    >>> sw = kincas.sweep(m, {"shaft.angle": [0.0]})
    >>> raw, nums = joint_values(compile(m), sw.q, np.zeros((1, 1)), np.zeros(0))
    >>> joint_bodies(m), nums.tolist()  # no roller; the circle's centre and radius
    (['shaft'], [0.0, 10.0, 0.0, 40.0])
    """
    f, fn = model.memo("draw_joints.functions", lambda: _build_joint_functions(model))
    return _mapped(f, Q, U, p), np.asarray(fn(np.asarray(p, float))).ravel()
