"""Animations of a sweep: the mechanism drawn at its solved poses, frame by frame, with the
paths of its points (GIF through Pillow; other formats through matplotlib's writers).
"""
from __future__ import annotations

import numpy as np

from ..model.mechanism import Mechanism
from ..results import Sweep


def animate(m: Mechanism, sweep: Sweep, path, *, paths=None, frames: int = 120, fps: int = 20,
            captions=None, units: str = "", dpi: int = 80, size=(6.4, 4.8), progress=None,
            path_xy=None, view: str | None = None, forces: bool = False, centres: bool = False) -> int:
    """Write an animated GIF of the sweep's solved poses (at most `frames` of them, evenly
    spread); returns the number of frames written. `captions[i]` titles pose i;
    `progress(done, total)` is called after each frame (a progress bar, say); `path_xy`: the
    paths already solved (point -> M x 2, `kincas.views.plot.smooth_paths`), else solved here;
    `view`: a spatial mechanism's ("iso", the default, "xy", "yz", "zx");
    `forces`, `centres`: arrows and instant centres on every frame (kincas/views/forces.py), planar only.

    >>> import os, tempfile, numpy as np, kincas
    >>> m = kincas.Mechanism(ground={"O": (0, 0)},
    ...     links=[kincas.Link.bar("crank", "O", "A", 1), kincas.Link.bar("rod", "A", "B", 3)],
    ...     slides=[kincas.Slide("B", "ground")], inputs=[kincas.Input.angle("crank")],
    ...     guess={"B": (4, 0)})
    >>> sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 2 * np.pi, 25)})
    >>> with tempfile.TemporaryDirectory() as d:
    ...     animate(m, sw, os.path.join(d, "slider.gif"), frames=4, size=(2, 1.5), dpi=40)
    4
    """
    from .plot import Drawing, caption, check_paths, drawn, new_figure, require_matplotlib, smooth_paths
    require_matplotlib("kincas.outputs.animate")
    from matplotlib.animation import PillowWriter
    ok = np.flatnonzero(sweep.ok) if sweep.ok.any() else np.array([0])
    pick = ok[np.unique(np.round(np.linspace(0, ok.size - 1, min(frames, ok.size))).astype(int))]
    fig = new_figure(size)
    chosen = check_paths(m, paths)
    smooth = smooth_paths(m, sweep, chosen) if path_xy is None else {p: path_xy[p] for p in chosen}
    from .forces import planar_overlay
    geo = drawn(m, sweep, view)
    d = Drawing(fig.subplots(), m, geo, chosen, True, units, smooth,
                planar_overlay(m, sweep, geo, forces, centres, extent=None))
    cap = captions if captions is not None else [caption(sweep, i) for i in range(len(sweep))]
    d.update(int(pick[0]), cap[pick[0]])
    fig.canvas.draw()  # lay the figure out once; every frame keeps that layout
    fig.set_layout_engine("none")
    writer = PillowWriter(fps=fps)
    from .atomic import replacing
    with replacing(path) as tmp, writer.saving(fig, tmp, dpi):  # no half animation left
        if progress is not None:
            progress(0, len(pick))
        for k, i in enumerate(pick):  # one drawing per frame
            d.update(int(i), cap[i])
            writer.grab_frame()
            if progress is not None:
                progress(k + 1, len(pick))
    return len(pick)
