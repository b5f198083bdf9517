"""Springs, force arrows and instant centres on a matplotlib drawing (kincas/views/plot.py),
from the format-free `views.forces`: the artists are made once and moved to any pose, as the
drawing's others are (so an animation shows the forces changing).

A spring is a zigzag (label "spring A-B"); an arrow is a line and a head (labels as
`views.forces`: "reaction(O, crank)", "load at A", "effort(crank.angle)"); an instant centre
a cross (label "instant centre LINK"). A legend names the kinds of arrows drawn.
"""
from __future__ import annotations

import numpy as np

from .forces import COLOURS, zigzag


class SpringArtists:
    """Each spring of the mechanism as a zigzag between its points."""

    def __init__(self, drawing, springs):
        self.d = drawing
        names = drawing.geo.names
        self.items = [(names.index(a), names.index(b),
                       drawing.ax.plot([], [], "-", lw=1.2, color=COLOURS["spring"], zorder=4.5, label=label)[0])
                      for label, a, b in springs]

    def update(self, xy: np.ndarray):
        for a, b, line in self.items:
            ok = np.isfinite(xy[a]).all() and np.isfinite(xy[b]).all()
            line.set_data(*(zigzag(xy[a], xy[b], self.d.r).T if ok else ([], [])))

    def lines(self, xy: np.ndarray) -> list[np.ndarray]:
        """The zigzags at these positions, for the names to keep off."""
        return [zigzag(xy[a], xy[b], self.d.r) for a, b, _ in self.items
                if np.isfinite(xy[a]).all() and np.isfinite(xy[b]).all()]


class OverlayArtists:
    """The arrows and crosses of a `views.forces.Overlay`."""

    def __init__(self, drawing, ov):
        from matplotlib.patches import Polygon
        self.d, self.ov = drawing, ov
        ax, self.arrows = drawing.ax, {}
        kinds = {}
        labels = [a.label for a in ov.arrows] + [t.label for t in ov.torques]
        kind_of = {a.label: a.kind for a in ov.arrows} | {t.label: t.kind for t in ov.torques}
        for label in labels:
            c = COLOURS[kind_of[label]]
            line = ax.plot([], [], "-", lw=1.6, color=c, zorder=8, label=label)[0]
            head = ax.add_patch(Polygon(np.zeros((3, 2)), closed=True, fc=c, ec=c, zorder=8, label=label))
            self.arrows[label] = (line, head)
            kinds.setdefault(kind_of[label], line)
        self.centres = [(xy, ax.plot([], [], "x", ms=8, mew=2, color=COLOURS["centre"], zorder=8,
                                     label=f"instant centre {name}")[0]) for name, xy in ov.centres]
        self.legend = None
        if kinds or self.centres:
            handles = list(kinds.values()) + [c for _, c in self.centres[:1]]
            names = [{"load": "loads", "spring": "springs", "effort": "efforts", "reaction": "reactions"}[k]
                     for k in kinds] + (["instant centres"] if self.centres else [])
            self.legend = ax.legend(handles, names, fontsize=7, loc="best", framealpha=0.8)

    def update(self, i: int):
        shown = {}
        if 0 <= i < len(self.d.geo.ok):
            shown = {label: (line, head) for label, _, line, head in self.ov.segments(i, self.d.r)}
        for label, (line, head) in self.arrows.items():
            ok = label in shown
            line.set_visible(ok), head.set_visible(ok)
            if ok:
                line.set_data(*shown[label][0].T)
                head.set_xy(shown[label][1])
        for xy, cross in self.centres:
            p = xy[i] if 0 <= i < len(xy) else np.full(2, np.nan)
            ok = bool(np.isfinite(p).all())
            cross.set_visible(ok)
            cross.set_data([p[0]], [p[1]]) if ok else cross.set_data([], [])
