"""How results look in Jupyter: a `Mechanism` as an SVG drawing of its first pose, a `Sweep`
as a short summary (poses, solved, flags, events) with small plots of its quantities.
`repr` stays one line; these are only the notebook's rich displays.

A mechanism holds no input values, so its "first pose" is the one its declaration implies:
an angle input at the angle its link has between the points the ground and the guess place
(0 when they do not place two of them), a slide input where the guess puts its point, a
parameter input at the parameter's value; solved from the guess, so on its branch.

>>> import numpy as np, kincas, xml.etree.ElementTree as ET
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"B": (0, 1), "C": (3.6, 2.9)})
>>> first_inputs(m)                       # the guess puts B above A: the crank at 90 deg
{'crank.angle': 1.5707963267948966}
>>> ET.fromstring(m._repr_svg_()).tag
'{http://www.w3.org/2000/svg}svg'
"""
from __future__ import annotations

import math
from html import escape

import numpy as np


def first_inputs(m) -> dict[str, float]:
    """The input values the mechanism's ground points and guess imply (see the module); a
    spatial mechanism's are those of its drawn pose (its joints' coordinates 0)."""
    from .poses import is_spatial
    if is_spatial(m):
        return {i.key: m.parameter(i.target) if i.kind == "parameter" else 0.0 for i in m.inputs}
    known = {**{g: (m.value(x), m.value(y)) for g, (x, y) in m.ground},
             **{p: (m.value(x), m.value(y)) for p, (x, y) in m.guess}}
    out = {}
    for inp in m.inputs:
        v = 0.0
        try:
            if inp.kind == "parameter":
                v = m.parameter(inp.target)
            elif inp.kind == "angle" and "/" not in inp.target:
                lk = m.link(inp.target)
                loc = {p: (m.value(x), m.value(y)) for p, (x, y) in lk.points}
                pair = [p for p in lk.point_names if p in known][:2]
                if len(pair) == 2:
                    (p, q), (lp, lq) = pair, (loc[pair[0]], loc[pair[1]])
                    world = math.atan2(known[q][1] - known[p][1], known[q][0] - known[p][0])
                    v = world - math.atan2(lq[1] - lp[1], lq[0] - lp[0])
                    v = math.atan2(math.sin(v), math.cos(v))
            elif inp.kind == "slide":
                sl = m.slide(inp.target)
                if sl.along == "ground" and sl.point in known:
                    tx, ty = (m.value(c) for c in sl.through)
                    a = m.value(sl.angle)
                    px, py = known[sl.point]
                    v = (px - tx) * math.cos(a) + (py - ty) * math.sin(a)
        except (KeyError, ValueError, TypeError, AttributeError):
            v = 0.0
        out[inp.key] = float(v)
    return out


def mechanism_svg(m, width: float = 420) -> str:
    """The mechanism drawn at its first pose (see the module), as SVG text; where it does not
    assemble there, a short picture saying so (not a drawing of the ground alone)."""
    from ..analysis.sweeps import sweep
    from .svg import svg_text
    sw = sweep(m, {k: np.array([v]) for k, v in first_inputs(m).items()}, report=[])
    if not sw.ok[0]:
        return message_svg(f"{type(m).__name__} does not assemble at its first pose ({sw.status[0]})",
                           "check the dimensions and the guess; kincas.solve says more", width)
    return svg_text(m, sw, 0, width=width)


def message_svg(text: str, hint: str = "", width: float = 420) -> str:
    """A small SVG that says `text` (and `hint` under it).

    >>> message_svg("no assembly").count("<text")
    1
    """
    lines = [f'<text x="10" y="24" font-size="13" fill="#b00">{escape(text)}</text>']
    if hint:
        lines.append(f'<text x="10" y="44" font-size="11" fill="#555">{escape(hint)}</text>')
    h = 56 if hint else 36
    return (f'<svg xmlns="http://www.w3.org/2000/svg" width="{width:g}" height="{h}" viewBox="0 0 {width:g} {h}">'
            f'<rect width="{width:g}" height="{h}" fill="#fff6f6" stroke="#e0b0b0"/>{"".join(lines)}</svg>')


def _spark(x, v, w=150, h=40) -> str:
    """A small line plot of v against x, as an inline SVG."""
    ok = np.isfinite(x) & np.isfinite(v)
    if ok.sum() < 2:
        return ""
    x, v = np.asarray(x)[ok], np.asarray(v)[ok]
    x0, x1, y0, y1 = x.min(), x.max(), v.min(), v.max()
    if x1 == x0:
        return ""
    if y1 - y0 <= 1e-9 * max(abs(y0), abs(y1), 1e-300):
        y0, y1 = y0 - 1, y1 + 1
    px = 2 + (w - 4) * (x - x0) / (x1 - x0)
    py = h - 2 - (h - 4) * (v - y0) / (y1 - y0)
    pts = " ".join(f"{a:.1f},{b:.1f}" for a, b in zip(px, py))
    return (f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}">'
            f'<polyline points="{pts}" fill="none" stroke="#1f77b4" stroke-width="1.2"/></svg>')


def sweep_html(sw, most: int = 6) -> str:
    """The sweep's summary and a small plot of each of its first `most` quantities; in the
    scene's units (degrees, with each quantity's unit) when the sweep came from a scene
    (`Sweep.info["display"]`, set by `Scene.run`)."""
    shown = sw.info.get("display") if isinstance(sw.info, dict) else None
    deg = set(shown["degrees"]) if shown else set()
    labels = shown["labels"] if shown else {}
    user = lambda k, v: np.degrees(np.asarray(v, float)) if k in deg else np.asarray(v, float)  # noqa: E731
    lines = sw.summary_lines()
    key = next((k for k, v in sw.inputs.items() if np.ptp(np.asarray(v, float)) > 0), None)
    x = user(key, sw.inputs[key]) if key else np.arange(len(sw), dtype=float)
    cells = []
    for name in list(sw.values)[:most]:
        v = user(name, sw.values[name])
        fin = v[np.isfinite(v)]
        unit = f" {labels[name]}" if labels.get(name) else ""
        rng = f"{fin.min():.4g} to {fin.max():.4g}{unit}" if fin.size else "not solved"
        cells.append(f"<td style='padding:2px 8px'><code>{escape(name)}</code><br>{_spark(x, v)}"
                     f"<br><small>{escape(rng)}</small></td>")
    more = len(sw.values) - most
    tail = f"<p><small>and {more} more quantities</small></p>" if more > 0 else ""
    if key:
        span = f" ({x[0]:.4g} to {x[-1]:.4g} {labels.get(key, '')})".replace(" )", ")") if shown else ""
        against = f"<small>against {escape(key)}{escape(span)}</small>"
    else:
        against = "<small>against the pose</small>"
    return (f"<div><pre style='margin:0'>{escape(chr(10).join(lines))}</pre>"
            f"<table><tr>{''.join(cells)}</tr></table>{against}{tail}</div>")
