"""Pictures as a new user saw them (issue [12]): no link crosses a hatched ground guide, a
near-constant quantity is plotted as a constant (no 1e-14 noise, no offset label), paths are
smooth (extra poses solved between the sweep's), an animation reports its progress and its
file type is checked before rendering."""
from __future__ import annotations

import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism, Slide

pytest.importorskip("matplotlib")


def slider_crank(e=0.0):
    return Mechanism(parameters={"e": e}, ground={"O": (0, 0)},
                     links=[Link.bar("crank", "O", "A", 1.0), Link.bar("rod", "A", "B", 3.0)],
                     slides=[Slide("B", "ground", through=(0, "e"), name="slider")],
                     inputs=[Input.angle("crank")], guess={"B": (3.5, e)})


def _cross(p, q, a, b) -> bool:
    """Whether segments pq and ab cross properly (strictly inside both)."""
    d = lambda u, v, w: (v[0] - u[0]) * (w[1] - u[1]) - (v[1] - u[1]) * (w[0] - u[0])
    return d(p, q, a) * d(p, q, b) < 0 and d(a, b, p) * d(a, b, q) < 0


@pytest.mark.parametrize("e", [0.0, 0.5, -0.5], ids=["centric", "offset", "offset-below"])
def test_no_link_crosses_a_hatched_guide(e):
    from matplotlib.figure import Figure
    from kincas.views.plot import Drawing, geometry
    m = slider_crank(e)
    sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 2 * np.pi, 73)})
    d = Drawing(Figure().subplots(), m, geometry(m, sw), [], False)
    crossings = 0
    for i in range(len(sw)):
        d.update(i)
        hatches = [h for *_, h in d.guides if h is not None]
        segs = [s for h in hatches for s in h.get_segments()]
        for kind, line, _ in d.bodies:
            x, y = line.get_data()
            for s in segs:
                crossings += _cross((x[0], y[0]), (x[1], y[1]), s[0], s[1])
    assert crossings == 0


def test_a_near_constant_quantity_is_plotted_flat():
    from matplotlib.figure import Figure
    from kincas.cli.outputs import plot_quantities
    m = slider_crank(0.0)
    sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 2 * np.pi, 73)}, report=["B.y", "B.x"])
    sw.values["B.y"] = 0.25 + 1e-15 * np.sin(np.arange(len(sw)))  # a constant with rounding noise
    fig = Figure()
    plot_quantities(sw, fig=fig)
    fig.canvas.draw() if hasattr(fig.canvas, "draw") else None
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    FigureCanvasAgg(fig).draw()
    ax = fig.axes[0]
    assert ax.yaxis.get_offset_text().get_text() == ""
    lo, hi = ax.get_ylim()
    assert hi - lo > 1e-3 and lo < 0.25 < hi
    labels = [t.get_text() for t in ax.get_yticklabels() if t.get_text()]
    assert all("e-1" not in s for s in labels), labels


def test_paths_are_smooth_and_solved():
    from matplotlib.figure import Figure
    from kincas.views.plot import draw
    m = slider_crank(0.0)
    sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 2 * np.pi, 12)})
    ax = draw(m, sw, ax=Figure().subplots(), paths=["A"])
    dashed = [ln for ln in ax.get_lines() if ln.get_linestyle() == "--"]
    x, y = dashed[0].get_data()
    ok = np.isfinite(x)
    assert ok.sum() >= 100  # not a 12-gon
    assert np.allclose(np.hypot(x[ok], y[ok]), 1.0, atol=1e-12)  # every point solved, on the circle


def test_animate_reports_progress(tmp_path):
    from kincas.cli.outputs import animate
    m = slider_crank(0.0)
    sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 2 * np.pi, 9)})
    calls = []
    animate(m, sw, tmp_path / "a.gif", frames=5, size=(2, 1.5), dpi=30,
            progress=lambda done, total: calls.append((done, total)))
    assert calls[-1] == (5, 5) and [c[0] for c in calls] == sorted(c[0] for c in calls)


def test_animate_format_refused_before_rendering(capsys, tmp_path, monkeypatch):
    from conftest import EXAMPLES, run_cli
    from matplotlib.animation import writers
    if writers.is_available("ffmpeg"):
        pytest.skip("ffmpeg is here: .mp4 can be written")
    from kincas.cli import scene as scene_module

    def no_solve(self, **kw):
        raise AssertionError("solved before checking --animate's file type")
    monkeypatch.setattr(scene_module.Scene, "run", no_solve)
    code, _, err = run_cli(capsys, "solve", EXAMPLES / "slider_crank.toml", "--animate", tmp_path / "x.mp4")
    assert code == 2 and "mp4" in err and ".gif" in err
