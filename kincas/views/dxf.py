"""`--dxf out.dxf`: the mechanism at one pose and the paths over the sweep as DXF entities
(through ezdxf, the optional extra `kincas[cad]`), in the mechanism's own coordinates.

One layer per body (named as the link), `ground` for the pivots and ground guides, `slides`
for the blocks, `paths` for the paths. A bar is a LINE, a body of three or more points a
closed LWPOLYLINE, each point a CIRCLE, each path an LWPOLYLINE per run of solved poses,
each guide a LINE, each block a closed LWPOLYLINE.

A spatial mechanism is written in space, as it is (no projection): a bar is a LINE between
3D points, a body of three or more points a closed 3D POLYLINE (its outline in its own
plane), each path a 3D POLYLINE per run, each guide a LINE, each block a closed 3D POLYLINE
(a rectangle in the plane of the guide and the world axis most across it), each point a
CIRCLE at its height (in a plane z = constant).

>>> import os, tempfile, numpy as np, kincas, ezdxf
>>> m = kincas.Mechanism(ground={"O": (0, 0)},
...     links=[kincas.Link.bar("crank", "O", "A", 1), kincas.Link.bar("rod", "A", "B", 3)],
...     slides=[kincas.Slide("B", "ground", name="slider")],
...     inputs=[kincas.Input.angle("crank")], guess={"B": (3.5, 0)})
>>> sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 2 * np.pi, 9)})
>>> with tempfile.TemporaryDirectory() as d:
...     write_dxf(os.path.join(d, "m.dxf"), m, sw, pose=0)
...     doc = ezdxf.readfile(os.path.join(d, "m.dxf"))
>>> [tuple(round(c, 9) for c in e.dxf.end)[:2] for e in doc.modelspace().query('LINE[layer=="crank"]')]
[(1.0, 0.0)]
"""
from __future__ import annotations

import numpy as np

from ..model.mechanism import Mechanism
from ..results import Sweep
from .picture import picture
from .svg import _runs

_UNITS = {"mm": 4, "cm": 5, "m": 6, "in": 1, "ft": 2, "um": 13, "km": 7}  # DXF $INSUNITS codes


def _require():
    try:
        import ezdxf
    except ModuleNotFoundError:
        raise ModuleNotFoundError('--dxf needs ezdxf: pip install "kincas[cad]"', name="ezdxf") from None
    return ezdxf


def dxf_document(m: Mechanism, sweep: Sweep, pose: int | None = None, *, paths=None,
                 dense: int = 0, units: str = "", forces: bool = False, centres: bool = False,
                 labels: bool = True):
    """An ezdxf document of the drawing at `pose` (default: the first solved) with the paths;
    `forces`, `centres`: arrows and instant centres (layers `forces`, `centres`); `labels`:
    each point's name as a TEXT on layer `labels`."""
    ezdxf = _require()
    from ezdxf import colors
    pic = picture(m, sweep, paths, dense, world=True, forces=forces, centres=centres)
    i = pic.first if pose is None else int(pose) % max(len(sweep), 1)
    xy = pic.xy[i]
    space = xy.shape[-1] == 3  # a spatial mechanism: 3D polylines
    doc = ezdxf.new("R2010")
    if units in _UNITS:
        doc.units = _UNITS[units]
    msp = doc.modelspace()
    rgb = lambda hexc: colors.rgb2int(tuple(int(hexc[k:k + 2], 16) for k in (1, 3, 5)))
    for name in ("ground", "slides", "paths"):
        doc.layers.add(name)
    for b in pic.bodies:
        if b.name not in doc.layers:
            doc.layers.add(b.name).rgb = tuple(int(b.colour[k:k + 2], 16) for k in (1, 3, 5))
        pts = xy[b.ring]
        if not np.isfinite(pts).all():
            continue
        at = {"layer": b.name, "true_color": rgb(b.colour)}
        if len(b.ring) >= 3:
            _polyline(msp, pts, space, True, at)
        else:
            msp.add_line(tuple(pts[0]), tuple(pts[1]), dxfattribs=at)
        for k in b.ring:
            if np.isfinite(xy[k]).all():
                msp.add_circle(tuple(xy[k]), 0.7 * pic.r, dxfattribs={"layer": b.name})
    for k in pic.ground:
        msp.add_circle(tuple(xy[k]), 0.7 * pic.r, dxfattribs={"layer": "ground"})
    for g in pic.guides:
        t, d = g.through[i], g.direction[i]
        if not (np.isfinite(t).all() and np.isfinite(d).all()):
            continue
        msp.add_line(tuple(t + g.lo * d), tuple(t + g.hi * d),
                     dxfattribs={"layer": "ground" if g.ground else "slides"})
        p = xy[g.point]
        if np.isfinite(p).all():
            n, r = _across(d), pic.r
            c = [p - 2 * r * d - 1.4 * r * n, p + 2 * r * d - 1.4 * r * n, p + 2 * r * d + 1.4 * r * n,
                 p - 2 * r * d + 1.4 * r * n]
            _polyline(msp, c, space, True, {"layer": "slides"})
    for name, a in pic.paths.items():
        for run in _runs(a):
            _polyline(msp, run, space, False, {"layer": "paths"})
    curves = pic.joint_curves(i)  # gears, racks, cams (views/draw_joints.py): layer "joints"
    if curves:
        doc.layers.add("joints")
    from .draw_joints import as_circle
    for label, body, a in curves:
        if len(a) == 1 and np.isfinite(a).all():
            msp.add_circle(tuple(a[0]), 0.5 * pic.r, dxfattribs={"layer": "joints"})
        circle = as_circle(label, a)
        if circle is not None:  # a pitch circle, a roller: a true CIRCLE
            msp.add_circle(tuple(circle[:2]), float(circle[2]), dxfattribs={"layer": "joints"})
            continue
        for run in _runs(a):
            msp.add_lwpolyline([tuple(q) for q in run], dxfattribs={"layer": "joints"})
    _extras(doc, msp, pic, i, labels)
    return doc


def _polyline(msp, pts, space: bool, close: bool, attribs: dict) -> None:
    """A polyline through `pts`: an LWPOLYLINE in the plane, a 3D POLYLINE in space."""
    if space:
        msp.add_polyline3d([tuple(map(float, q)) for q in pts], close=close, dxfattribs=attribs)
    else:
        msp.add_lwpolyline([tuple(q) for q in pts], close=close, dxfattribs=attribs)


def _across(d: np.ndarray) -> np.ndarray:
    """A unit vector across the unit direction d: its normal in the plane; in space, the world
    axis least along d with its part along d taken away."""
    if len(d) == 2:
        return np.array([-d[1], d[0]])
    e = np.eye(3)[int(np.argmin(np.abs(d)))]
    n = e - (e @ d) * d
    return n / np.linalg.norm(n)


def _extras(doc, msp, pic, i: int, labels: bool) -> None:
    """Springs (layer `springs`), force arrows and instant centres, and the points' names. In
    space (a spatial mechanism's world positions) springs are straight and each name stands at
    its point: the zigzags, the overlay and the placement of names are planar."""
    r = pic.r
    xy = pic.xy[i]
    if xy.shape[-1] == 3:
        ends = [(xy[a], xy[b]) for _, a, b in pic.springs if np.isfinite(xy[[a, b]]).all()]
        if ends:
            doc.layers.add("springs")
        for pa, pb in ends:
            _polyline(msp, [pa, pb], True, False, {"layer": "springs"})
        if labels:
            doc.layers.add("labels")
            for k, name in enumerate(pic.names):
                if np.isfinite(xy[k]).all():
                    msp.add_text(name, height=2.2 * r, dxfattribs={"layer": "labels",
                                                                  "insert": tuple(map(float, xy[k]))})
        return
    springs = pic.spring_lines(i)
    if springs:
        doc.layers.add("springs")
    for _, zz in springs:
        msp.add_lwpolyline([tuple(q) for q in zz], dxfattribs={"layer": "springs"})
    ov = pic.overlay
    if ov is not None:
        doc.layers.add("forces"), doc.layers.add("centres")
        for label, kind, line, head in ov.segments(i, r):
            msp.add_lwpolyline([tuple(q) for q in line], dxfattribs={"layer": "forces"})
            msp.add_lwpolyline([tuple(q) for q in head], close=True, dxfattribs={"layer": "forces"})
            msp.add_text(label, height=1.2 * r, dxfattribs={"layer": "forces", "insert": tuple(line[0])})
        for label, xy in ov.centres:
            p = xy[i]
            if np.isfinite(p).all():
                msp.add_line(tuple(p - r), tuple(p + r), dxfattribs={"layer": "centres"})
                msp.add_line((p[0] - r, p[1] + r), (p[0] + r, p[1] - r), dxfattribs={"layer": "centres"})
                msp.add_text(f"I {label}", height=1.2 * r,
                             dxfattribs={"layer": "centres", "insert": (p[0] + 1.2 * r, p[1] + 1.2 * r)})
    if labels:
        doc.layers.add("labels")
        from .labels import label_offsets
        for name, p, off in label_offsets(pic, i):
            msp.add_text(name, height=2.2 * r, dxfattribs={"layer": "labels", "insert": tuple(p + off),
                                                          "halign": 1, "valign": 2,
                                                          "align_point": tuple(p + off)})


def write_dxf(path, m: Mechanism, sweep: Sweep, pose: int | None = None, **kw) -> None:
    """Write `dxf_document(m, sweep, pose, **kw)` to `path`."""
    from .atomic import replacing
    doc = dxf_document(m, sweep, pose, **kw)
    with replacing(path) as tmp:
        doc.saveas(tmp)
