"""Spatial mechanisms on flat pictures: orthographic projections of world positions (the
`Geometry` of a spatial sweep, N x K x 3) onto a drawing plane, with the depth of every
point so that what is nearer the viewer is drawn over what is farther.

A view is an orthonormal, right-handed camera basis of the world, its rows

* `right` (the drawing's x axis), `up` (its y axis), and
* `toward`: from the picture towards the viewer, `right x up`.

A world point p is drawn at (right . p, up . p); its depth is `-toward . p` (larger: farther).
Orthographic: lengths parallel to the drawing plane are true, lengths along `toward` vanish.

=====  =====================  ====================  ==================================
view   right                  up                    toward the viewer
=====  =====================  ====================  ==================================
xy     x                      y                     z  (the planar scenes' own view)
yz     y                      z                     x
zx     z                      x                     y
iso    (-1, 1, 0) / sqrt 2    (-1, -1, 2) / sqrt 6  (1, 1, 1) / sqrt 3
=====  =====================  ====================  ==================================

The isometric view looks down the diagonal (1, 1, 1): the three axes are foreshortened
alike (by sqrt(2/3)) and drawn 120 degrees apart, z vertical, x to the lower left, y to the
lower right, as in engineering drawings.

>>> import numpy as np
>>> xy, depth = project_points(np.array([[1.0, 0, 0], [0, 0, 1.0]]), "iso")
>>> np.round(xy, 6).tolist(), np.round(depth, 6).tolist()
([[-0.707107, -0.408248], [0.0, 0.816497]], [-0.57735, -0.57735])
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..core.tolerances import END_ON
from .poses import is_spatial  # noqa: F401  (the command line asks here)

VIEWS = ("iso", "xy", "yz", "zx")
DEFAULT_VIEW = "iso"

_S2, _S3, _S6 = np.sqrt(2.0), np.sqrt(3.0), np.sqrt(6.0)
_AXES = {
    "xy": np.eye(3),
    "yz": np.array([[0.0, 1, 0], [0, 0, 1], [1, 0, 0]]),
    "zx": np.array([[0.0, 0, 1], [1, 0, 0], [0, 1, 0]]),
    "iso": np.array([[-1 / _S2, 1 / _S2, 0], [-1 / _S6, -1 / _S6, 2 / _S6], [1 / _S3, 1 / _S3, 1 / _S3]]),
}
# the world axis drawn upwards in each view: the HTML page turns the mechanism about it
UP_AXIS = {"xy": 1, "yz": 2, "zx": 0, "iso": 2}


def check_view(view: str | None, spatial: bool) -> str | None:
    """The view a picture is drawn in: `view` checked (ValueError naming the choices), the
    isometric one for a spatial mechanism when none is given, None (its own plane) for a
    planar one, which accepts only "xy".

    >>> check_view(None, True), check_view("yz", True), check_view("xy", False), check_view(None, False)
    ('iso', 'yz', None, None)
    """
    if view is not None and view not in VIEWS:
        raise ValueError(f"--view: {view!r} is not a view (one of {', '.join(VIEWS)})")
    if not spatial:
        if view not in (None, "xy"):
            raise ValueError(f"--view {view}: a planar scene is drawn in its own plane (--view xy); "
                             f"yz, zx and iso are for spatial scenes (space = \"3d\")")
        return None
    return view or DEFAULT_VIEW


def axes(view: str) -> np.ndarray:
    """The camera basis of `view`: rows right, up, toward the viewer (3 x 3, orthonormal,
    right-handed).

    >>> a = axes("iso"); bool(np.allclose(a @ a.T, np.eye(3)) and np.isclose(np.linalg.det(a), 1))
    True
    """
    if view not in _AXES:
        raise ValueError(f"view {view!r}: one of {', '.join(VIEWS)}")
    return _AXES[view].copy()


def project_points(a: np.ndarray, view: str) -> tuple[np.ndarray, np.ndarray]:
    """World points (... x 3) drawn in `view`: their drawing coordinates (... x 2) and depth
    (...), larger farther from the viewer; NaN stays NaN."""
    a = np.asarray(a, float)
    c = a @ axes(view).T
    return c[..., :2], -c[..., 2]


def project(geo, view: str):
    """The `Geometry` of a spatial sweep (points N x K x 3) drawn in `view`: a Geometry whose
    points are N x K x 2 drawing coordinates, with `depth` (N x K, larger farther), `world`
    (the points in space) and `view` set, so that every planar drawer draws it.

    A slide's line (through t, unit direction d, coordinate s of its point p = t + s d)
    becomes the line through the drawn t with the drawn direction normalised, and s scaled
    by the same foreshortening, so that t' + s' d' is still the drawn p. A line seen end on
    (its drawn direction shorter than END_ON) has no direction: its guide is not drawn.

    >>> import numpy as np
    >>> from kincas.views.poses import Geometry
    >>> g = Geometry(["O", "A"], np.array([[[0.0, 0, 0], [0, 0, 2]]]), {}, np.array([True]))
    >>> p = project(g, "yz"); p.xy.tolist(), p.depth.tolist(), p.world is g.xy
    ([[[0.0, 0.0], [0.0, 2.0]]], [[-0.0, -0.0]], True)
    """
    xy, depth = project_points(geo.xy, view)
    slides = {}
    for name, (through, d, s) in geo.slides.items():
        t2, _ = project_points(through, view)
        d2, _ = project_points(d, view)
        scale = np.hypot(d2[:, 0], d2[:, 1])
        seen = scale > END_ON
        with np.errstate(invalid="ignore", divide="ignore"):
            d2 = np.where(seen[:, None], d2 / np.where(seen, scale, 1.0)[:, None], np.nan)
            s2 = np.where(seen, np.asarray(s, float) * scale, np.nan)
        slides[name] = (t2, d2, s2)
    return replace(geo, xy=xy, slides=slides, depth=depth, world=geo.xy, view=view)


def project_paths(paths: dict | None, view: str | None) -> dict | None:
    """Paths (point -> M x 3 world positions) drawn in `view`; planar paths (M x 2) or no
    view: unchanged."""
    if paths is None or view is None:
        return paths
    return {p: (project_points(a, view)[0] if np.asarray(a).shape[-1] == 3 else a) for p, a in paths.items()}


def in_plane(pts: np.ndarray) -> np.ndarray:
    """Points of one body (k x 3) in coordinates of their own best-fitting plane (k x 2),
    the plane through their centroid spanned by the two main directions of their spread
    (the first two right singular vectors). A rigid motion moves the plane with the body, so
    an outline chosen in it stays the body's outline at every pose and in every view.
    Planar points (k x 2) are returned as they are.

    >>> import numpy as np
    >>> q = in_plane(np.array([[0.0, 0, 5], [2, 0, 5], [0, 1, 5]]))
    >>> round(float(abs(np.linalg.det(np.c_[q, np.ones(3)]))) / 2, 12)  # the triangle's area, 1
    1.0
    """
    pts = np.asarray(pts, float)
    if pts.shape[-1] == 2 or not np.isfinite(pts).all():
        return pts[..., :2]
    centred = pts - pts.mean(axis=0)
    _, _, vt = np.linalg.svd(centred, full_matrices=False)
    return centred @ vt[:2].T


def ring_points(geo, i: int, idx: list[int]) -> np.ndarray:
    """The points `idx` of one body at pose i in the plane its outline is chosen in: as
    drawn for a planar sweep, in the body's own plane for a spatial one (`in_plane`)."""
    world = geo.world if getattr(geo, "world", None) is not None else geo.xy
    return in_plane(world[i, idx])


def triad(view: str) -> list[tuple[str, np.ndarray]]:
    """The world axes x, y, z as drawn in `view` (unit vectors foreshortened), for the small
    axis cross in a corner of every spatial picture.

    >>> [(k, np.round(v, 3).tolist()) for k, v in triad("xy")]
    [('x', [1.0, 0.0]), ('y', [0.0, 1.0]), ('z', [0.0, 0.0])]
    """
    a = axes(view)
    return [(k, a[:2, j]) for j, k in enumerate("xyz")]


def depth_order(depth: np.ndarray, groups: list[list[int]]) -> list[int]:
    """The order in which to draw groups of points (bodies) at one pose: farthest first, by
    the mean depth of each group's points (a group not solved last).

    >>> depth_order(np.array([0.0, 1.0, 2.0]), [[0, 1], [2], [0]])
    [1, 0, 2]
    """
    mean = [float(np.mean(depth[g])) if len(g) else np.nan for g in groups]
    key = [-d if np.isfinite(d) else np.inf for d in mean]
    return sorted(range(len(groups)), key=lambda k: key[k])


def drawn(m, sweep, view: str | None = None, world: bool = False):
    """`kincas.views.poses.geometry(m, sweep)` as a picture draws it: a spatial sweep drawn
    in `view` (default isometric), or in space as it is with `world=True` (DXF, the HTML
    page's turning view); a planar sweep as it is (`view` None or "xy")."""
    from . import poses
    geo = poses.geometry(m, sweep)
    spatial = geo.xy.shape[-1] == 3
    view = check_view(view, spatial)
    return project(geo, view) if spatial and not world else geo
