"""Pictures checked as a user would look at them: every example is drawn, the image has its
size, is not blank, and the ends of every link appear where the closed forms put them (data
coordinates taken to pixels through the Axes' transData); hidden, the same pixels are blank.
The drawing's geometry is checked against the closed forms at every pose."""
from __future__ import annotations

import math

import numpy as np
import pytest

import closed_forms as cf
from conftest import EXAMPLES

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg", force=True)

import kincas  # noqa: E402
from kincas.cli.outputs import animate  # noqa: E402
from kincas.views.plot import draw, geometry, new_figure  # noqa: E402
from kincas.cli.scene import load  # noqa: E402

SIZE, DPI = (4.0, 3.0), 80
# planar pictures; spatial scenes (space_*.toml) are drawn in a projection (tests of the 3D views)
EXAMPLE_FILES = sorted(p for p in EXAMPLES.glob("*.toml") if not p.stem.startswith(("space_", "simulate_space_")))


# --- helpers: render, find pixels ---


def render(fig) -> np.ndarray:
    """The figure as an RGB array, rows from the top."""
    fig.canvas.draw()
    return np.asarray(fig.canvas.buffer_rgba())[..., :3].copy()


def pixel(ax, xy, height) -> tuple[int, int]:
    """(column, row) of a data point: transData gives pixels from the bottom left."""
    x, y = ax.transData.transform(np.asarray(xy, float))
    return int(round(x)), int(round(height - y))


def inked(img, col, row, radius=3) -> bool:
    """Whether anything darker than the light grid is drawn within `radius` pixels."""
    win = img[max(row - radius, 0):row + radius + 1, max(col - radius, 0):col + radius + 1]
    return bool(win.size) and bool((win.min(axis=2) < 200).any())


def _cross(a, b) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


def hide_drawing(ax):
    for a in [*ax.lines, *ax.patches, *ax.collections, *ax.texts]:
        a.set_visible(False)


def true_points(path, sc, sw) -> dict[str, np.ndarray]:
    """Positions (N x 2) of every point, from the closed forms where the example has one,
    else from the solver's reported positions (a different route from the drawing's)."""
    if path.stem in cf.CLOSED_FORMS:
        sol = cf.solve(path.stem, cf.load_scene(path))
        return {k: np.asarray(v, float) for k, v in sol.points.items()}
    m = sc.mechanism
    names = [f"{p}.{c}" for p in m.moving_points for c in "xy"]
    rep = kincas.sweep(m, sc.study.inputs, report=names)
    out = {p: np.stack([rep[f"{p}.x"], rep[f"{p}.y"]], axis=1) for p in m.moving_points}
    g = {p: (m.value(x), m.value(y)) for p, (x, y) in m.ground}
    out.update({p: np.tile(xy, (len(sw), 1)) for p, xy in g.items()})
    return out


# --- every example, drawn ---


@pytest.mark.parametrize("path", EXAMPLE_FILES, ids=[p.stem for p in EXAMPLE_FILES])
def test_every_example_is_drawn_with_its_links_where_they_are(path):
    sc = load(path)
    m = sc.mechanism
    sw = sc.run()
    assert sw.ok.any(), "the example solves somewhere"
    truth = true_points(path, sc, sw)
    L = m.size()

    # the drawing's geometry, at every solved pose, against the independent positions
    geo = geometry(m, sw)
    for p, xy in truth.items():
        np.testing.assert_allclose(geo.point(p)[sw.ok], xy[sw.ok], atol=1e-8 * L, rtol=0)
    for name, (through, d, s) in geo.slides.items():  # the block's point lies on its line
        p = geo.point(m.slide(name).point)[sw.ok]
        w = p - through[sw.ok]
        np.testing.assert_allclose(w[:, 0] * d[sw.ok, 1] - w[:, 1] * d[sw.ok, 0], 0, atol=1e-8 * L)
        if f"{name}.s" in sw.values:
            np.testing.assert_allclose(s[sw.ok], sw[f"{name}.s"][sw.ok], atol=1e-8 * L)

    fig = new_figure(SIZE)
    fig.set_dpi(DPI)
    ax = fig.subplots()
    i = int(np.flatnonzero(sw.ok)[len(np.flatnonzero(sw.ok)) // 3])  # not the first: a real pose
    draw(m, sw, i, ax=ax, paths=[])  # no paths: they too pass through the points at pose i
    img = render(fig)
    h, w = img.shape[:2]
    assert (w, h) == (SIZE[0] * DPI, SIZE[1] * DPI)
    ink = (img.min(axis=2) < 200).mean()
    assert 0.01 < ink < 0.5, f"{ink:.3f} of the image is drawn"

    # equal scales: one data unit is as many pixels across as up
    o, ex, ey = (ax.transData.transform(v) for v in ((0, 0), (1, 0), (0, 1)))
    assert math.isclose(ex[0] - o[0], ey[1] - o[1], rel_tol=1e-9)

    ends = {p for lk in m.links for p in lk.point_names}
    where = {p: pixel(ax, truth[p][i], h) for p in ends}
    for p, (col, row) in where.items():
        assert 0 <= col < w and 0 <= row < h, f"{p} is outside the picture"
        assert inked(img, col, row), f"nothing drawn at link end {p} ({col}, {row})"
    polygons = []
    for lk in m.links:  # a body of three points or more is filled: its centroid is coloured
        pts = np.array([truth[p][i] for p in lk.point_names])
        if len(pts) >= 3 and abs(_cross(pts[1] - pts[0], pts[2] - pts[0])) > (0.05 * L) ** 2:
            polygons.append(pixel(ax, pts.mean(axis=0), h))
            assert inked(img, *polygons[-1], radius=1), f"{lk.name} is not filled"

    hide_drawing(ax)  # the same pixels are blank without the mechanism: the checks can fail
    blank = render(fig)
    for p, (col, row) in where.items():
        assert not inked(blank, col, row), f"{p}: the background itself is inked"
    for col, row in polygons:
        assert not inked(blank, col, row, radius=1)


# --- paths, unsolved poses, pyplot, animations ---


def nongrashof():
    """Crank 2, coupler 1.9, rocker 3, ground 4: the crank cannot turn fully."""
    return kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
                            links=[kincas.Link.bar("crank", "A", "B", 2),
                                   kincas.Link.bar("coupler", "B", "C", 1.9),
                                   kincas.Link.bar("rocker", "D", "C", 3)],
                            inputs=[kincas.Input.angle("crank")], guess={"C": (3.0, 2.9)})


def test_paths_skip_unsolved_poses_and_an_unsolved_pose_draws_only_the_ground():
    m = nongrashof()
    th = np.linspace(0, 2 * np.pi, 91)
    sw = kincas.sweep(m, {"crank.angle": th})
    ok = sw.ok
    assert ok.any() and not ok.all()
    # closed form: B on the crank circle; C where the circles about B and D meet (if they do)
    B = 2 * np.stack([np.cos(th), np.sin(th)], axis=1)
    d = np.hypot(*(B - [4, 0]).T)
    assert np.array_equal(ok, (d <= 1.9 + 3) & (d >= 3 - 1.9)), "assembles exactly where it can"
    geo = geometry(m, sw)
    np.testing.assert_allclose(geo.point("B")[ok], B[ok], atol=1e-12)
    assert np.isnan(geo.point("C")[~ok]).all() and np.isfinite(geo.point("D")).all()

    fig = new_figure(SIZE)
    ax = fig.subplots()
    bad = int(np.flatnonzero(~ok)[0])
    draw(m, sw, bad, ax=ax, paths=["C"])
    path_lines = [ln for ln in ax.lines if ln.get_linestyle() == "--"]
    assert len(path_lines) == 1
    y = np.asarray(path_lines[0].get_ydata(), float)
    assert np.isnan(y[~ok]).all() and np.isfinite(y[ok]).all()
    bars = [ln for ln in ax.lines if ln.get_linewidth() == 5]
    assert len(bars) == 3  # each has a moving end, unknown: no segment to draw
    assert not any(np.isfinite(np.asarray(b.get_xdata(), float)).all() for b in bars)
    assert "no assembly" in ax.get_title()
    img = render(fig)
    assert inked(img, *pixel(ax, (0, 0), img.shape[0]))  # the ground pivots are still drawn
    j = int(np.flatnonzero(ok)[5])  # the path of C passes where C was at a solved pose
    assert inked(img, *pixel(ax, geo.point("C")[j], img.shape[0]))


def test_unknown_path_is_an_error():
    m = nongrashof()
    sw = kincas.sweep(m, {"crank.angle": [0.0, 0.1]})
    with pytest.raises(ValueError, match="Z"):
        draw(m, sw, ax=new_figure().subplots(), paths=["C", "Z"])


def test_draw_through_pyplot_when_no_axes_is_given():
    import matplotlib.pyplot as plt
    m = nongrashof()
    sw = kincas.sweep(m, {"crank.angle": [0.0, 0.2]})
    ax = draw(m, sw, -1)
    try:
        assert ax.figure in [plt.figure(n) for n in plt.get_fignums()]
        assert "0.2" in ax.get_title()  # -1: the last pose
    finally:
        plt.close(ax.figure)


def test_animation_of_a_slider_crank(tmp_path):
    from PIL import Image
    sc = load(EXAMPLES / "slider_crank.toml")
    sw = sc.run()
    out = tmp_path / "slider.gif"
    n = animate(sc.mechanism, sw, out, frames=10, size=SIZE, dpi=DPI)
    assert n == 10
    with Image.open(out) as im:
        assert im.n_frames == 10 and im.size == (SIZE[0] * DPI, SIZE[1] * DPI)
        frames = []
        for k in range(im.n_frames):
            im.seek(k)
            frames.append(np.asarray(im.convert("L"), dtype=float))
    assert all((f < 200).mean() > 0.01 for f in frames), "no blank frame"
    assert all(np.abs(a - b).max() > 0 for a, b in zip(frames, frames[1:])), "the crank turns"


def test_animation_shows_only_solved_poses(tmp_path):
    m = nongrashof()
    sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 2 * np.pi, 31)})
    assert animate(m, sw, tmp_path / "a.gif", frames=100, size=(2, 1.5), dpi=40) == sw.ok.sum()
