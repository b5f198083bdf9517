"""Pictures of a mechanism: the drawing at a pose with the paths of its points over a sweep
(animations of a sweep and plots of its quantities are in `kincas.outputs`).

matplotlib is an optional extra (`pip install "kincas[plot]"`), imported only to draw.
Positions come from the solved unknowns `sweep.q` through the compiled model, so a drawing
shows exactly the poses that were solved; poses not "ok" are left out of paths.

>>> import numpy as np, kincas
>>> from matplotlib.figure import Figure
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
>>> sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 2 * np.pi, 37)})
>>> ax = draw(m, sw, pose=9, ax=Figure().subplots())    # crank at 90 deg, paths of B and C
>>> ax.get_aspect()
1.0
"""
from __future__ import annotations

from collections import Counter

import numpy as np

from ..model.mechanism import GROUND, Mechanism
from ..results import Sweep
from .poses import Geometry, _hull, check_paths, default_pose, geometry  # noqa: F401  (their old home)
from .poses import _on_line, links_of
from .projection import drawn, project_paths, ring_points

PLOT_EXTRA = 'pip install "kincas[plot]"'


def require_matplotlib(what: str = "kincas.plot") -> None:
    """Raise ModuleNotFoundError with a one-line message saying what to install.

    >>> require_matplotlib("--plot")
    """
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise ModuleNotFoundError(f"{what} needs matplotlib: {PLOT_EXTRA}", name="matplotlib") from None


# --- shapes ---


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.hypot(*v)
    return v / n if n > 0 and np.isfinite(n) else np.zeros(2)


def _rectangle(centre, d, length, width) -> np.ndarray:
    """Corners of a rectangle centred at `centre` with its long side along unit vector d."""
    n = np.array([-d[1], d[0]])
    a, b = 0.5 * length * np.asarray(d), 0.5 * width * n
    return np.array([centre - a - b, centre + a - b, centre + a + b, centre - a + b])


# --- the drawing: artists made once, moved to any pose ---

INK, PAPER = "#222222", "white"


class Drawing:
    """Every artist of a mechanism drawing; `update(i)` moves them to pose i."""

    def __init__(self, ax, m: Mechanism, geo: Geometry, paths, labels: bool, units: str = "",
                 path_xy: dict | None = None, overlay=None):
        self.ax, self.m, self.geo = ax, m, geo
        self.i0 = default_pose(geo.ok)
        pts = geo.xy[np.isfinite(geo.xy).all(axis=2)]
        pts = pts if pts.size else np.zeros((1, 2))
        span = np.ptp(pts, axis=0).max()
        self.r = r = 0.02 * (span if span > 0 else m.size())  # the drawing's unit of size
        ends, self.sref = [pts], {}
        for name, (through, d, s) in geo.slides.items():
            # each guide spans the slide coordinates reached, with room for the block
            sv = s[np.isfinite(s)] if np.isfinite(s).any() else np.zeros(1)
            self.sref[name] = (sv.min() - 4 * r, sv.max() + 4 * r)
            for sx in self.sref[name]:
                e = through + sx * d
                ends.append(e[np.isfinite(e).all(axis=1)])
        allpts = np.concatenate([e for e in ends if e.size] or [np.zeros((1, 2))])
        lo, hi = allpts.min(axis=0) - 5 * r, allpts.max(axis=0) + 5 * r
        self.box = np.array([lo, hi])  # the whole sweep fits: an animation keeps its frame
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, color="#e6e6e6", lw=0.6, zorder=0)
        if units and geo.view is None:
            ax.set_xlabel(f"x [{units}]"), ax.set_ylabel(f"y [{units}]")
        elif geo.view is not None:  # a spatial mechanism in a view
            self._view_axes(units)
        self.links = links_of(m)  # a spatial mechanism's bodies
        self.colour = {lk.name: f"C{k % 10}" for k, lk in enumerate(self.links)}
        owner = {p: lk.name for lk in reversed(self.links) for p in lk.point_names}  # the first link
        path_xy = project_paths(path_xy, geo.view)  # a spatial sweep's paths, drawn in its view
        for p in paths:  # a path in its link's colour; NaN at unsolved poses breaks the line
            xy = path_xy[p] if path_xy and p in path_xy else geo.point(p)
            if np.isfinite(xy).all(axis=1).sum() >= 2:
                ax.plot(*xy.T, "--", lw=1.0, color=self.colour.get(owner.get(p), INK), alpha=0.7, zorder=2)
        self._ground_symbols()
        self._make_bodies()
        self._make_slides()
        from .draw_joints import JointArtists
        self.joint_artists = JointArtists(self, geo.joints) if geo.joints is not None else None
        from .draw_forces import OverlayArtists, SpringArtists  # views/draw_forces.py
        from .forces import springs
        self.springs = SpringArtists(self, springs(m))
        self.overlay = OverlayArtists(self, overlay) if overlay is not None else None
        self._make_points(labels)
        self.caption = ax.set_title("", fontsize=9)
        # The limits follow this box, widened to equal scales by matplotlib when drawn (the
        # placeholder positions of the artists above are not part of it).
        ax.dataLim.set_points(self.box)
        ax.set_xmargin(0), ax.set_ymargin(0)
        ax.autoscale_view()

    # --- fixed parts ---
    def _ground_symbols(self):
        """A triangle under each ground pivot standing on a hatched base."""
        from matplotlib.collections import LineCollection
        from matplotlib.patches import Polygon
        r, ax = self.r, self.ax
        ticks = []
        for g in self.m.ground_points:
            x, y = self.geo.point(g)[self.i0]  # fixed: known at every pose
            if not np.isfinite(x):
                continue
            h = 2.5 * r
            ax.add_patch(Polygon([(x, y), (x - 0.7 * h, y - h), (x + 0.7 * h, y - h)], closed=True,
                                 fc="#dddddd", ec=INK, lw=1.0, zorder=1.5))
            ticks += [[(x - 1.1 * h, y - h), (x + 1.1 * h, y - h)]] + [
                [(x + t, y - h), (x + t + 0.3 * h, y - 1.35 * h)] for t in np.linspace(-1.1 * h, 0.8 * h, 6)]
        if ticks:
            ax.add_collection(LineCollection(ticks, colors=INK, linewidths=0.8, zorder=1.5))

    # --- bodies ---
    def _make_bodies(self):
        """Two points: a bar. Three or more: their convex hull filled (a bar between the two
        outermost when they are collinear). The links the inputs turn are drawn on top."""
        from matplotlib.patches import Polygon
        self.bodies = []  # (kind, artist, indices of the points drawn)
        driven = {i.target for i in self.m.inputs if i.kind == "angle"}
        for lk in self.links:
            idx = [self.geo.names.index(p) for p in lk.point_names]
            c, ring = self.colour[lk.name], idx
            if len(idx) >= 3:  # the outline in the body's plane (a spatial body: its own plane)
                pts = ring_points(self.geo, self.i0, idx)
                hull = _hull(pts) if np.isfinite(pts).all() else [0, 1]
                ring = [idx[k] for k in hull]
                x, y = pts[hull].T
                area = 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))  # shoelace
                if len(ring) >= 3 and area > (0.5 * self.r) ** 2:
                    patch = Polygon(np.zeros((len(ring), 2)), closed=True, fc=c, ec=c, alpha=0.45,
                                    lw=2.5, zorder=3)
                    self.bodies.append(("polygon", self.ax.add_patch(patch), ring))
                    continue
                far = np.hypot(*(pts[hull] - pts[hull[0]]).T)
                ring = [ring[0], ring[int(np.argmax(far))]]
            line, = self.ax.plot([], [], "-", lw=5, color=c, solid_capstyle="round",
                                 zorder=4.5 if lk.name in driven else 4, label=lk.name)
            self.bodies.append(("bar", line, ring))

    def _make_slides(self):
        """A slot along a link: two rails in the link's colour. A guide on the ground: one
        hatched surface on the side the links never reach over the sweep (beyond the block),
        so none crosses it; where they reach both sides (a centric slider-crank's rod), two
        plain rails. The block rides between the rails, or against the surface."""
        from matplotlib.collections import LineCollection
        from matplotlib.patches import Polygon
        self.guides = []  # (slide, [(side, rail)], block, hatch or None)
        for sl in (sl for sl in self.m.slides if _on_line(sl, self.geo)):
            sides = (-1.0, 1.0)
            if sl.along == GROUND:
                sides = self._free_sides(sl)
            c = INK if sl.along == GROUND else self.colour[sl.along]
            rails = [(side, self.ax.plot([], [], "-", lw=1.2, color=c, zorder=3.5)[0]) for side in sides]
            block = self.ax.add_patch(Polygon(np.zeros((4, 2)), closed=True, fc="#f2f2f2", ec=INK,
                                              lw=1.2, zorder=5))
            hatch = (self.ax.add_collection(LineCollection([], colors=INK, linewidths=0.7, zorder=3.5))
                     if sl.along == GROUND and len(sides) == 1 else None)
            self.guides.append((sl, rails, block, hatch))

    def _free_sides(self, sl) -> tuple[float, ...]:
        """(+1,) or (-1,): the one side of a ground guide that no link reaches at any pose,
        within the guide's length and beyond the block's half-width; (-1, +1) when the links
        reach both sides (then no side can be hatched without a link crossing it)."""
        through, d, _ = self.geo.slides[sl.name]
        n = np.stack([-d[:, 1], d[:, 0]], axis=1)
        names, xy = self.geo.names, self.geo.xy
        t = np.linspace(0.0, 1.0, 17)[None, :, None]
        samples = [xy[:, [names.index(p)]] for p in self.m.ground_points + self.m.moving_points
                   if p != sl.point]
        for lk in self.links:  # points along every pair of a body's points: its bars and edges
            idx = [names.index(p) for p in lk.point_names]
            for a in range(len(idx)):
                for b in range(a + 1, len(idx)):
                    pa, pb = xy[:, [idx[a]]], xy[:, [idx[b]]]
                    samples.append(pa + t * (pb - pa))
        rel = np.concatenate(samples, axis=1) - through[:, None, :]
        across = np.einsum("ijk,ik->ij", rel, n)
        along = np.einsum("ijk,ik->ij", rel, d)
        lo, hi = self.sref[sl.name]
        inside = (along >= lo) & (along <= hi) & np.isfinite(across)
        w = 1.4 * self.r
        up = bool((across[inside] > w).any())
        down = bool((across[inside] < -w).any())
        if up and down:
            return (-1.0, 1.0)
        return (1.0,) if not up else (-1.0,)

    def _make_points(self, labels: bool):
        """Joints (on two bodies or more, the ground counting as one) as rings, other points
        as dots, and the name of each."""
        names, m = self.geo.names, self.m
        count = Counter([p for lk in self.links for p in lk.point_names] + list(m.ground_points))
        joints = [k for k, p in enumerate(names) if count[p] >= 2]
        self.joints = (joints, self.ax.plot([], [], "o", ms=6, mfc=PAPER, mec=INK, mew=1.3,
                                            ls="none", zorder=6)[0])
        single = [k for k, p in enumerate(names) if count[p] < 2]
        self.dots = (single, self.ax.plot([], [], "o", ms=4, color=INK, ls="none", zorder=6)[0])
        self.labels = [self.ax.text(0, 0, p, fontsize=8, zorder=7, ha="center", va="center",
                                    bbox=dict(fc=PAPER, ec="none", alpha=0.75, pad=0.3))
                       for p in names] if labels else []

    def _view_axes(self, units: str):
        """A spatial mechanism's view: the drawing's axes named after the world's where the view
        looks along one of them, and a cross of the world axes x, y, z in a corner."""
        from .projection import triad
        ax, view = self.ax, self.geo.view
        u = f" [{units}]" if units else ""
        if view in ("xy", "yz", "zx"):
            ax.set_xlabel(view[0] + u), ax.set_ylabel(view[1] + u)
        else:  # an oblique view has no true scale along its axes: no ticks
            ax.set_xticklabels([]), ax.set_yticklabels([])
            ax.set_xlabel(f"{view} view" + u)
        o = np.array([0.07, 0.09])
        for k, v in triad(view):
            if np.hypot(*v) < 1e-9:  # seen end on: a dot
                ax.plot(*o, "o", ms=3, color=INK, transform=ax.transAxes, zorder=8)
                continue
            e = o + 0.06 * v
            ax.annotate("", xy=e, xytext=o, xycoords="axes fraction",
                        arrowprops=dict(arrowstyle="->", color=INK, lw=1.0), zorder=8)
            ax.text(*(o + 0.085 * v), k, transform=ax.transAxes, fontsize=8, ha="center", va="center", zorder=8)

    # --- moving to a pose ---
    def update(self, i: int, caption: str = ""):
        """Move every artist to pose i (nothing moving is shown when it was not solved)."""
        geo, r = self.geo, self.r
        xy = geo.xy[i] if 0 <= i < len(geo.ok) else np.full((len(geo.names), 2), np.nan)
        for kind, artist, idx in self.bodies:
            if kind == "bar":
                artist.set_data(*xy[idx].T)
            else:
                artist.set_visible(bool(np.isfinite(xy[idx]).all()))
                artist.set_xy(np.nan_to_num(xy[idx]))
        if geo.depth is not None and 0 <= i < len(geo.ok):  # in space: the nearer bodies over the farther
            from .projection import depth_order
            order = depth_order(geo.depth[i], [idx for _, _, idx in self.bodies])
            for rank, k in enumerate(order):
                self.bodies[k][1].set_zorder(3 + 1.9 * rank / max(len(order), 1))
        for sl, rails, block, hatch in self.guides:
            through, d, s = (a[i] for a in geo.slides[sl.name])
            fixed = bool(np.isfinite(through).all() and np.isfinite(d).all())  # the guide is there
            ok = fixed and bool(np.isfinite(s))  # and so is the block
            lo, hi = self.sref[sl.name]
            w, nrm = 1.4 * r, np.array([-d[1], d[0]])
            for side, rail in rails:  # w either side of the line the point keeps to
                e = np.array([through + lo * d, through + hi * d]) + side * w * nrm
                rail.set_data(*(e.T if fixed else np.full((2, 2), np.nan)))
            block.set_visible(ok)
            if ok:
                block.set_xy(_rectangle(xy[geo.names.index(sl.point)], d, 4 * r, 2 * w))
            if hatch is not None and fixed:  # a ground guide: ticks beyond its surface
                side = rails[0][0]
                base = through + side * w * nrm
                hatch.set_segments([[base + t * d, base + (t - 0.8 * r) * d + side * 0.8 * r * nrm]
                                    for t in np.arange(lo, hi + 1e-12, 1.2 * r)])
        for idx, line in (self.joints, self.dots):
            line.set_data(*xy[idx].T)
        if self.joint_artists is not None:
            self.joint_artists.update(i)
        self.springs.update(xy)
        if self.overlay is not None:
            self.overlay.update(i)
        spots = self._label_spots(xy, i) if self.labels else ()
        for k, t in enumerate(self.labels):
            ok = bool(np.isfinite(spots[k]).all())
            t.set_visible(ok)
            if ok:
                t.set_position(spots[k])
        self.caption.set_text(caption)

    def _label_spots(self, xy: np.ndarray, i: int) -> np.ndarray:
        """Where the names go at this pose: the freest spots (views/labels.py), off the bars,
        bodies, guides, blocks, ground symbols and springs."""
        from .labels import block, ground_symbol, label_spots
        segments, polygons = [], []
        for kind, _, idx in self.bodies:
            (segments if kind == "bar" else polygons).append(xy[idx])
        for sl, *_ in self.guides:
            through, d, s = (a[i] for a in self.geo.slides[sl.name])
            if np.isfinite(through).all() and np.isfinite(d).all():
                lo, hi = self.sref[sl.name]
                segments.append(np.array([through + lo * d, through + hi * d]))
                p = xy[self.geo.names.index(sl.point)]
                if np.isfinite(p).all():
                    polygons.append(block(p, d, self.r))
        polygons += [ground_symbol(xy[self.geo.names.index(g)], self.r) for g in self.m.ground_points]
        segments += self.springs.lines(xy)
        return label_spots(xy, self.r, segments=segments, polygons=polygons)


# --- public drawing functions ---


def caption(sweep: Sweep, i: int) -> str:
    """The inputs at pose i, as a title (with the status when it was not solved)."""
    text = ", ".join(f"{k} = {v[i]:.4g}" for k, v in sweep.inputs.items())
    return text + ("" if sweep.status[i] == "ok" else f" ({sweep.status[i]})")


def draw(m: Mechanism, sweep: Sweep, pose: int | None = None, *, ax=None, paths=None,
         labels: bool = True, title: str | None = None, units: str = "", path_xy=None,
         view: str | None = None, forces: bool = False, centres: bool = False):
    """Draw `m` at pose `pose` of `sweep` (default: the first solved) with the paths of
    `paths` (default: every moving point) over the sweep; returns the matplotlib Axes.
    `path_xy`: those paths already solved (point -> M x 2, `smooth_paths`), else solved here.
    A spatial mechanism is drawn in `view` ("iso", the default, "xy", "yz" or "zx";
    `kincas.views.projection`), a planar one in its plane.
    `forces`: arrows for the loads, springs' pulls, efforts and joint reactions; `centres`:
    each link's instant centre (kincas/views/forces.py), planar only. Springs are always drawn.

    Links with two points are bars, links with three or more are filled polygons, ground
    pivots stand on hatched bases, slides show their guide and block; axes have equal scales.
    """
    require_matplotlib("kincas.plot.draw")
    if ax is None:
        import matplotlib.pyplot as plt
        ax = plt.subplots(figsize=(6.4, 4.8))[1]
    paths = check_paths(m, paths)
    i = default_pose(sweep) if pose is None else int(pose) % max(len(sweep), 1)  # -1: the last
    smooth = smooth_paths(m, sweep, paths) if path_xy is None else {p: path_xy[p] for p in paths}
    from .forces import planar_overlay
    geo = drawn(m, sweep, view)
    d = Drawing(ax, m, geo, paths, labels, units, smooth, planar_overlay(m, sweep, geo, forces, centres))
    d.update(i, caption(sweep, i) if title is None else title)
    return ax


def smooth_paths(m: Mechanism, sweep: Sweep, paths: list[str]) -> dict | None:
    """Paths through about 360 poses, the extra ones SOLVED between the sweep's (see
    `kincas.views.picture.dense_paths`), so that a 12-pose sweep does not draw a 12-gon; None
    for sweeps of more than 60 poses (their poses are dense enough)."""
    from .picture import dense_paths, smooth_steps
    per_step = smooth_steps(len(sweep))
    if per_step == 0 or not paths:
        return None
    return dense_paths(m, sweep, paths, per_step)


def new_figure(size=(6.4, 4.8)):
    """A matplotlib Figure for writing files, independent of pyplot and its backends."""
    require_matplotlib()
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    return fig
