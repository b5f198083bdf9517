"""`--svg out.svg`: the drawing at one pose and the paths over the sweep as vector graphics.

Coordinates in the file are the mechanism's own (a group flips the y axis), so a CAD or
vector program measures true lengths: each bar is a `<line data-link=NAME>`, each body of
three or more points a `<polygon data-link=NAME>`, each point a `<circle data-point=NAME>`,
each path one or more `<polyline data-path=NAME>` (broken where poses were not solved), each
slide's guide a `<line data-slide=NAME>` and its block a `<polygon data-block=NAME>`.
A spatial mechanism is drawn in a view (`view`: "iso", the default, "xy", "yz", "zx"; see
`kincas.views.projection`): coordinates are then the view's (right, up), true lengths only
parallel to the drawing plane, the root carries `data-view`, bodies are drawn farthest first
and a cross of the world axes stands in the lower left corner (`<g id="triad">`).

>>> import io, numpy as np, kincas, xml.etree.ElementTree as ET
>>> m = kincas.Mechanism(ground={"O": (0, 0)},
...     links=[kincas.Link.bar("crank", "O", "A", 1), kincas.Link.bar("rod", "A", "B", 3)],
...     slides=[kincas.Slide("B", "ground", name="slider")],
...     inputs=[kincas.Input.angle("crank")], guess={"B": (3.5, 0)})
>>> sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 2 * np.pi, 9)})
>>> root = ET.fromstring(svg_text(m, sw, pose=2))          # crank at 90 deg: A = (0, 1)
>>> a = [c for c in root.iter("{http://www.w3.org/2000/svg}circle") if c.get("data-point") == "A"][0]
>>> round(float(a.get("cx")), 9), round(float(a.get("cy")), 9)
(0.0, 1.0)
"""
from __future__ import annotations

from xml.sax.saxutils import escape, quoteattr

import numpy as np

from ..model.mechanism import Mechanism
from ..results import Sweep
from .picture import INK, picture


def _f(v: float) -> str:
    return f"{float(v):.10g}"


def _pts(a: np.ndarray) -> str:
    return " ".join(f"{_f(x)},{_f(y)}" for x, y in a)


def _runs(a: np.ndarray):
    """The runs of finite rows of an (M x 2) array, each with at least two rows."""
    good = np.isfinite(a).all(axis=1)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], good.astype(int), [0]])))
    for lo, hi in zip(edges[::2], edges[1::2]):
        if hi - lo >= 2:
            yield a[lo:hi]


# a scene's length unit -> (SVG's absolute unit, how many of them make one): the file's
# width and height in these, so that an import draws the mechanism at true scale
TRUE_SCALE = {"mm": ("mm", 1.0), "cm": ("cm", 1.0), "in": ("in", 1.0), "m": ("mm", 1000.0),
              "dm": ("mm", 100.0), "km": ("mm", 1e6), "um": ("mm", 1e-3), "µm": ("mm", 1e-3),
              "ft": ("in", 12.0), "pt": ("pt", 1.0), "pc": ("pc", 1.0), "px": ("px", 1.0)}


def svg_size(w: float, h: float, units: str, width: float = 800) -> tuple[str, str]:
    """The width and height attributes of a drawing w x h in the scene's length `units`:
    at true scale where the unit is one SVG measures (mm, cm, in, and m, ft converted),
    else `width` pixels wide.

    >>> svg_size(120, 80, "mm"), svg_size(0.12, 0.08, "m")
    (('120mm', '80mm'), ('120mm', '80mm'))
    """
    if units in TRUE_SCALE:
        u, k = TRUE_SCALE[units]
        return f"{_f(w * k)}{u}", f"{_f(h * k)}{u}"
    return _f(width), _f(width * h / w if w > 0 else width)


def svg_text(m: Mechanism, sweep: Sweep, pose: int | None = None, *, paths=None, scene=None,
             dense: int = 0, width: float = 800, view: str | None = None, forces: bool = False,
             centres: bool = False, units: str | None = None) -> str:
    """The SVG document: the drawing at `pose` (default: the first solved) and the paths
    (a spatial mechanism in `view`); `forces`, `centres`: arrows and instant centres
    (views/forces.py, planar only). Sized at true scale in the scene's length unit (`units`,
    default the scene's; see `svg_size`)."""
    pic = picture(m, sweep, paths, dense, view, forces=forces, centres=centres)
    i = pic.first if pose is None else int(pose) % max(len(sweep), 1)
    xy = pic.xy[i]
    (x0, y0), (x1, y1) = pic.box()
    w, h = x1 - x0, y1 - y0
    r, sw_ = pic.r, pic.r * 0.35  # point radius, bar width's unit
    if units is None:
        units = scene.study.units.get("length", "") if scene is not None else ""
    wide, high = svg_size(w, h, units, width)
    title = getattr(getattr(scene, "study", None), "title", "") or "kincas"
    out = ['<?xml version="1.0" encoding="UTF-8"?>',
           f'<svg xmlns="http://www.w3.org/2000/svg" width="{wide}" height="{high}" '
           f'viewBox="{_f(x0)} {_f(-y1)} {_f(w)} {_f(h)}" data-units={quoteattr(units)}'
           + (f' data-view="{pic.view}">' if pic.view else ">"),
           f"<title>{escape(title)}</title>",
           '<rect x="%s" y="%s" width="%s" height="%s" fill="white"/>' % (_f(x0), _f(-y1), _f(w), _f(h)),
           '<g transform="scale(1,-1)" stroke-linecap="round" stroke-linejoin="round">']
    owner = {}
    for b in pic.bodies:
        for k in b.ring:
            owner.setdefault(pic.names[k], b.colour)
    out.append('<g id="paths" fill="none">')
    for p, a in pic.paths.items():
        for run in _runs(a):
            out.append(f'<polyline data-path={quoteattr(p)} points="{_pts(run)}" stroke="{owner.get(p, INK)}" '
                       f'stroke-width="{_f(0.4 * sw_)}" stroke-dasharray="{_f(2 * r)} {_f(1.5 * r)}"/>')
    out.append("</g>")
    out.append('<g id="ground">')
    for k in pic.ground:
        x, y = xy[k]
        g = 2.5 * r
        out.append(f'<polygon data-ground={quoteattr(pic.names[k])} points="{_pts([(x, y), (x - 0.7 * g, y - g), (x + 0.7 * g, y - g)])}" '
                   f'fill="#dddddd" stroke="{INK}" stroke-width="{_f(0.3 * sw_)}"/>')
    out.append("</g>")
    out.append('<g id="slides">')
    for gd in pic.guides:
        t, d = gd.through[i], gd.direction[i]
        if not (np.isfinite(t).all() and np.isfinite(d).all()):
            continue
        a, b = t + gd.lo * d, t + gd.hi * d
        out.append(f'<line data-slide={quoteattr(gd.name)} x1="{_f(a[0])}" y1="{_f(a[1])}" x2="{_f(b[0])}" '
                   f'y2="{_f(b[1])}" stroke="{gd.colour}" stroke-width="{_f(0.4 * sw_)}"/>')
        p = xy[gd.point]
        if np.isfinite(p).all():
            n = np.array([-d[1], d[0]])
            c = [p - 2 * r * d - 1.4 * r * n, p + 2 * r * d - 1.4 * r * n, p + 2 * r * d + 1.4 * r * n,
                 p - 2 * r * d + 1.4 * r * n]
            out.append(f'<polygon data-block={quoteattr(gd.name)} points="{_pts(c)}" fill="#f2f2f2" '
                       f'stroke="{INK}" stroke-width="{_f(0.3 * sw_)}"/>')
    out.append("</g>")
    out.append('<g id="bodies">')
    for b in _order(pic, i):
        pts = xy[b.ring]
        if not np.isfinite(pts).all():
            continue
        if len(b.ring) >= 3:
            out.append(f'<polygon data-link={quoteattr(b.name)} points="{_pts(pts)}" fill="{b.colour}" '
                       f'fill-opacity="0.45" stroke="{b.colour}" stroke-width="{_f(0.6 * sw_)}"/>')
        else:
            (ax, ay), (bx, by) = pts
            out.append(f'<line data-link={quoteattr(b.name)} x1="{_f(ax)}" y1="{_f(ay)}" x2="{_f(bx)}" '
                       f'y2="{_f(by)}" stroke="{b.colour}" stroke-width="{_f(1.6 * sw_)}"/>')
    out.append("</g>")
    out.append('<g id="joints" fill="none">')  # gears, racks, cams: views/draw_joints.py
    colours = {b.name: b.colour for b in pic.bodies}
    from .draw_joints import as_circle
    for label, body, a in pic.joint_curves(i):
        c = colours.get(body, INK)
        if len(a) == 1:  # a cam's contact point
            if np.isfinite(a).all():
                out.append(f'<circle data-joint={quoteattr(label)} cx="{_f(a[0, 0])}" cy="{_f(a[0, 1])}" '
                           f'r="{_f(0.5 * r)}" fill="#c0392b"/>')
            continue
        circle = as_circle(label, a)
        if circle is not None:  # a pitch circle or a roller: a true circle, round at any zoom
            out.append(f'<circle data-joint={quoteattr(label)} cx="{_f(circle[0])}" cy="{_f(circle[1])}" '
                       f'r="{_f(circle[2])}" stroke="{c}" stroke-width="{_f(0.4 * sw_)}"/>')
            continue
        for run in _runs(a):
            out.append(f'<polyline data-joint={quoteattr(label)} points="{_pts(run)}" stroke="{c}" '
                       f'stroke-width="{_f(0.4 * sw_)}"/>')
    out.append("</g>")
    out.append('<g id="springs" fill="none">')
    for label, zz in pic.spring_lines(i):
        out.append(f'<polyline data-spring={quoteattr(label)} points="{_pts(zz)}" stroke="#9467bd" '
                   f'stroke-width="{_f(0.4 * sw_)}"/>')
    out.append("</g>")
    out += _overlay(pic, i, r, sw_)
    out.append('<g id="points">')
    for k, name in enumerate(pic.names):
        x, y = xy[k]
        if np.isfinite([x, y]).all():
            out.append(f'<circle data-point={quoteattr(name)} cx="{_f(x)}" cy="{_f(y)}" r="{_f(0.7 * r)}" '
                       f'fill="white" stroke="{INK}" stroke-width="{_f(0.3 * sw_)}"/>')
    out.append("</g></g>")
    if pic.view:
        out += _triad(pic.view, x0, -y0, r, sw_)
    out.append(f'<g id="labels" font-family="sans-serif" font-size="{_f(2.2 * r)}" fill="{INK}" '
               f'text-anchor="middle" dominant-baseline="central">')
    from .labels import picture_labels
    for name, p, off in picture_labels(pic, i):  # outside the flip, so the text reads upright
        x, y = p + off
        out.append(f'<text x="{_f(x)}" y="{_f(-y)}">{escape(name)}</text>')
    out.append("</g></svg>")
    return "\n".join(out) + "\n"


def _order(pic, i: int) -> list:
    """The bodies in drawing order: planar, the driven ones last (on top); in a view, the
    farthest first."""
    if pic.depth is None or not 0 <= i < len(pic.depth):
        return sorted(pic.bodies, key=lambda b: b.driven)
    from .projection import depth_order
    return [pic.bodies[k] for k in depth_order(pic.depth[i], [b.ring for b in pic.bodies])]


def _triad(view: str, x: float, y: float, r: float, sw_: float) -> list[str]:
    """The world axes x, y, z as drawn in `view`, from the lower left corner (x, y) of the
    picture in SVG's own coordinates (y downwards)."""
    from .projection import triad
    o = np.array([x + 6 * r, y - 6 * r])
    out = [f'<g id="triad" stroke="{INK}" stroke-width="{_f(0.3 * sw_)}" font-family="sans-serif" '
           f'font-size="{_f(2 * r)}" fill="{INK}">']
    for k, v in triad(view):
        e, t = o + 4 * r * np.array([v[0], -v[1]]), o + 5.5 * r * np.array([v[0], -v[1]])
        out.append(f'<line data-axis="{k}" x1="{_f(o[0])}" y1="{_f(o[1])}" x2="{_f(e[0])}" y2="{_f(e[1])}"/>')
        out.append(f'<text x="{_f(t[0])}" y="{_f(t[1])}" stroke="none" text-anchor="middle" '
                   f'dominant-baseline="middle">{k}</text>')
    out.append("</g>")
    return out


def _overlay(pic, i: int, r: float, sw_: float) -> list[str]:
    """The force arrows (`data-force`, with the force's components or the torque as
    `data-value-*`) and the instant centres (`data-centre`), when asked."""
    ov = pic.overlay
    if ov is None:
        return []
    from .forces import COLOURS
    values = {a.label: ("x", a.vec[i]) for a in ov.arrows} | {t.label: ("t", t.value[i]) for t in ov.torques}
    out = ['<g id="forces" fill="none">']
    for label, kind, line, head in ov.segments(i, r):
        c = COLOURS[kind]
        tag, v = values[label]
        val = (f'data-value-x="{_f(v[0])}" data-value-y="{_f(v[1])}"' if tag == "x" else f'data-value="{_f(v)}"')
        out.append(f'<polyline data-force={quoteattr(label)} data-kind="{kind}" {val} points="{_pts(line)}" '
                   f'stroke="{c}" stroke-width="{_f(0.5 * sw_)}"/>')
        out.append(f'<polygon data-head={quoteattr(label)} points="{_pts(head)}" fill="{c}"/>')
    out.append("</g>")
    out.append('<g id="centres">')
    for label, xy in ov.centres:
        p = xy[i]
        if np.isfinite(p).all():
            a, b = p - r, p + r
            out.append(f'<path data-centre={quoteattr(label)} d="M{_f(a[0])},{_f(a[1])} L{_f(b[0])},{_f(b[1])} '
                       f'M{_f(a[0])},{_f(b[1])} L{_f(b[0])},{_f(a[1])}" stroke="{COLOURS["centre"]}" '
                       f'stroke-width="{_f(0.4 * sw_)}" data-x="{_f(p[0])}" data-y="{_f(p[1])}"/>')
    out.append("</g>")
    return out


def write_svg(path, m: Mechanism, sweep: Sweep, pose: int | None = None, **kw) -> None:
    """Write `svg_text(m, sweep, pose, **kw)` to `path`."""
    from .atomic import open_replacing
    with open_replacing(path, "w", encoding="utf-8") as f:
        f.write(svg_text(m, sweep, pose, **kw))
