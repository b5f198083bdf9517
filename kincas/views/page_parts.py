"""The parts of the HTML page's data (kincas/views/html.py) drawn per kept pose: force arrows
and instant centres, where the points' names go, gears' and cams' curves (circles as
circles); and numbers as JSON (None for NaN), rounded so that the page stays small.

>>> _arr([[1.0, float("nan")]], 3)
[[1.0, None]]
"""
from __future__ import annotations

import math

import numpy as np

from .picture import INK
from ..model.names import is_angle_name

LABEL_FRAMES = 180  # the names' places are worked out at most this often over a sweep


def _num(v, digits=9):
    """A JSON number (None for NaN), to `digits` significant digits."""
    v = float(v)
    return None if not math.isfinite(v) else float(f"{v:.{digits}g}")


def _arr(a, digits=9):
    a = np.asarray(a, float)
    if a.ndim == 0:
        return _num(a, digits)
    return [_arr(x, digits) for x in a]


def _wrap(name: str, unit: str):
    """Half a turn for a wrapped angle (its plot breaks where it jumps by a turn), else None."""
    if not is_angle_name(name):
        return None
    return 180.0 if unit == "deg" else math.pi


def _forces(pic, keep) -> list:
    """Per kept pose, the arrows [{label, kind, colour, pts, head, value}] (empty when not asked)."""
    ov = pic.overlay
    if ov is None:
        return []
    from .forces import COLOURS
    vals = {a.label: a.vec for a in ov.arrows} | {t.label: t.value for t in ov.torques}
    return [[{"label": label, "kind": kind, "colour": COLOURS[kind], "pts": _arr(line, 7), "head": _arr(head, 7),
              "value": _arr(vals[label][i], 6)} for label, kind, line, head in ov.segments(int(i), pic.r)]
            for i in keep]


def _centres(pic, keep) -> list:
    """Per kept pose, the instant centres [{label, p}] (empty when not asked)."""
    if pic.overlay is None:
        return []
    return [[{"label": label, "p": _arr(xy[i], 9)} for label, xy in pic.overlay.centres if np.isfinite(xy[i]).all()]
            for i in keep]


def _labels(pic, keep) -> list:
    """Per kept pose, where each point's name goes (views/labels.py), as offsets in world units."""
    from .labels import label_spots, picture_obstacles
    every = max(1, -(-len(keep) // LABEL_FRAMES))  # a long sweep: each place kept a few frames
    out, last = [], None
    for j, i in enumerate(keep):
        if j % every == 0 or last is None:
            segments, polygons = picture_obstacles(pic, int(i))
            spots = label_spots(pic.xy[i], pic.r, segments=segments, polygons=polygons)
            last = _arr(spots - pic.xy[i], 5)
        out.append(last)
    return out


def _joints(pic, keep) -> list:
    """Per kept pose, the gears', racks' and cams' polylines (views/draw_joints.py), coarser
    than in the other pictures so that the page stays small: [{colour, pts}]; a circle (a
    pitch circle, a roller) as its centre and radius, drawn round: [{colour, circle}]."""
    from .draw_joints import as_circle
    colours = {b.name: b.colour for b in pic.bodies}
    out = []
    for i in keep:
        row = []
        for label, body, a in pic.joint_curves(int(i), 41):
            c = "#c0392b" if len(a) == 1 else colours.get(body, INK)
            circle = as_circle(label, a)
            row.append({"colour": c, "circle": _arr(circle, 9)} if circle is not None else {"colour": c, "pts": _arr(a, 7)})
        out.append(row)
    return out
