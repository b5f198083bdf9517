"""A sweep's outputs as files: CSV tables, plots of the quantities against the input, GIF
animations, and the `kincas solve` flags that write them (--csv, --plot, --animate,
--plot-quantities).

Values are written in the scene's units (degrees where the scene says so); without a scene,
as the sweep holds them (radians). A pose that was not solved has empty cells.

>>> import io, numpy as np, kincas
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
>>> sw = kincas.sweep(m, {"crank.angle": [0.0, 0.5]}, report=["C.x", "rocker.omega"])
>>> out = io.StringIO(); write_csv(out, sw)
>>> print(out.getvalue().splitlines()[0])
crank.angle [rad],C.x,rocker.omega [rad/s],status,flag
"""
from __future__ import annotations

import csv
import math
from types import SimpleNamespace

import numpy as np

from ..errors import OutputError
from ..model.mechanism import Mechanism
from ..results import Sweep

FLAG_STYLE = {"limit": ("#d62728", "limit of motion"), "change point": ("#9467bd", "change point"),
              "singular": ("#ff7f0e", "singular position")}


# --- names, units and values in the scene's units ---


def _units_of(scene):
    """What `kincas.cli._unit` needs: the scene, or plain radians/seconds without one."""
    if scene is not None:
        return scene
    return SimpleNamespace(study=SimpleNamespace(units={"length": "", "angle": "rad", "time": "s"}),
                           mechanism=SimpleNamespace(param_values={}))


def heading(name: str, scene=None) -> str:
    """`name [unit]`, units as in the printed table (just `name` when it has none).

    >>> heading("rocker.alpha")
    'rocker.alpha [rad/s^2]'
    """
    from .common import _unit
    u = _unit(_units_of(scene), name)
    return f"{name} [{u}]" if u else name


def user_columns(sweep: Sweep, scene=None, names=None):
    """(inputs, values): name -> array in the scene's units (the sweep's own without one)."""
    inputs = scene.user_inputs(sweep) if scene is not None else dict(sweep.inputs)
    values = scene.user_values(sweep) if scene is not None else dict(sweep.values)
    if scene is not None:  # zero to the solve's accuracy as 0, not as noise
        from .numbers import clean
        values = clean(values, scene, sweep)
    if names is not None:
        missing = [n for n in names if n not in values]
        if missing:
            raise KeyError(f"not reported: {missing} (reported: {list(values)})")
        values = {n: values[n] for n in names}
    return inputs, values


# --- CSV ---


def write_csv(out, sweep: Sweep, scene=None) -> None:
    """A row per pose: inputs, then reported quantities, then status and flag; a header row of
    `name [unit]`; empty cells where a pose was not solved. `out`: a path or an open text file.
    Numbers are written with all their digits (shortest text that reads back the same float).
    """
    if isinstance(out, (str, bytes)) or hasattr(out, "__fspath__"):
        from .atomic import open_replacing
        with open_replacing(out, "w", newline="", encoding="utf-8") as f:  # whole or not at all
            return write_csv(f, sweep, scene)
    inputs, values = user_columns(sweep, scene)
    values = {k: v for k, v in values.items() if k not in inputs}  # an input reported: once
    w = csv.writer(out, lineterminator="\n")
    w.writerow([heading(k, scene) for k in [*inputs, *values]] + ["status", "flag"])
    cols = [*inputs.values(), *values.values()]
    for i in range(len(sweep)):
        cells = ["" if not math.isfinite(c[i]) else repr(float(c[i])) for c in cols]
        w.writerow(cells + [sweep.status[i], sweep.flags[i] or ""])


# --- quantities against the input ---


def _abscissa(sweep: Sweep, inputs: dict) -> tuple[str | None, np.ndarray]:
    """The first input that varies (inputs that sweep advance together), else the pose index."""
    for k, v in inputs.items():
        if len(v) > 1 and np.ptp(v) > 0:
            return k, np.asarray(v, float)
    return None, np.arange(len(sweep), dtype=float)


def _runs(mask: np.ndarray):
    """(first, last) index of every run of True in mask."""
    idx = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(int), [0]])))
    return list(zip(idx[::2], idx[1::2] - 1))


def _break_wraps(name: str, x, v, half):
    """An angle wrapped to (-half turn, half turn] jumps by a whole turn: no line there.

    >>> _break_wraps("L.angle", np.arange(3.0), np.array([3.0, -3.1, -3.0]), np.pi)[1].tolist()
    [3.0, nan, -3.1, -3.0]
    """
    if not name.endswith(".angle") or name.startswith("d(") or len(v) < 2:
        return x, v
    jumps = np.flatnonzero(np.abs(np.diff(v)) > half) + 1
    return np.insert(x.astype(float), jumps, np.nan), np.insert(np.asarray(v, float), jumps, np.nan)


def _flat(v: np.ndarray):
    """(v, None), or (its mean everywhere it is finite, the mean) when v is constant to
    rounding (a spread within 1e-9 of its size): plotted as a line, not as 1e-14 noise.

    >>> _flat(np.array([0.25, 0.25 + 1e-15, np.nan]))[1]
    0.25
    """
    v = np.asarray(v, float)
    fin = v[np.isfinite(v)]
    if fin.size < 2 or np.ptp(fin) > 1e-9 * max(float(np.abs(fin).max()), 1e-300):
        return v, None
    c = float(f"{np.mean(fin):.12g}")  # its digits beyond rounding are noise
    return np.where(np.isfinite(v), c, np.nan), c


def plot_quantities(sweep: Sweep, names=None, *, scene=None, fig=None):
    """Plot reported quantities (default: all) against the input, one panel each; returns the
    Figure. Poses flagged "limit", "change point" or "singular" are marked by vertical lines,
    poses that were not solved (beyond the limits of motion) are shaded.

    >>> import numpy as np, kincas
    >>> from matplotlib.figure import Figure
    >>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
    ...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
    ...            kincas.Link.bar("rocker", "D", "C", 3)],
    ...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
    >>> sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 6.28, 50)}, report=["C.x", "C.y"])
    >>> len(plot_quantities(sw, fig=Figure()).axes)
    2
    """
    from .plot import new_figure, require_matplotlib
    require_matplotlib("kincas.outputs.plot_quantities")
    inputs, values = user_columns(sweep, scene, names)
    xkey, x = _abscissa(sweep, inputs)
    n = max(len(values), 1)
    ncols = 1 if n <= 4 else 2 if n <= 10 else 3
    nrows = -(-n // ncols)
    if fig is None:
        fig = new_figure((4.6 * ncols, 1.7 * nrows + 0.9))
    axes = np.atleast_1d(fig.subplots(nrows, ncols, sharex=True, squeeze=False)).ravel()
    ok = sweep.ok
    half = 180.0 if scene is not None and scene.study.deg else np.pi  # half a turn
    style = "-" if len(x) > 1 else "o"
    shown = set()
    for ax, (name, v) in zip(axes, values.items()):
        v, flat = _flat(v)
        ax.plot(*_break_wraps(name, x, v, half), style, color="C0", lw=1.4, ms=4)
        ax.ticklabel_format(axis="y", useOffset=False)  # no "1e-12+5e1" offset labels
        if flat is not None:  # constant to rounding: a flat line in a readable band
            pad = 0.05 * abs(flat) if flat != 0 else 1.0
            ax.set_ylim(flat - pad, flat + pad)
        ax.set_ylabel(heading(name, scene), fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(True, color="#e6e6e6", lw=0.6)
        for a, b in _runs(~ok):  # not assembled: shade from halfway to the neighbouring poses
            lo = x[a] if a == 0 else 0.5 * (x[a - 1] + x[a])
            hi = x[b] if b == len(x) - 1 else 0.5 * (x[b] + x[b + 1])
            lab = None if "unsolved" in shown else "not solved"
            ax.axvspan(min(lo, hi), max(lo, hi), color="#bbbbbb", alpha=0.5, lw=0, label=lab)
            shown.add("unsolved")
        for i, flag in enumerate(sweep.flags):
            if flag:
                colour, text = FLAG_STYLE.get(flag, ("#8c564b", flag))
                ax.axvline(x[i], color=colour, lw=1.0, ls="--", label=None if flag in shown else text)
                if math.isfinite(v[i]):
                    ax.plot([x[i]], [v[i]], "o", color=colour, ms=4)
                shown.add(flag)
    for ax in axes[len(values):]:
        ax.set_visible(False)
    for ax in axes[max(len(values) - ncols, 0):len(values)]:
        ax.set_xlabel(heading(xkey, scene) if xkey else "pose", fontsize=8)
        ax.xaxis.set_tick_params(labelbottom=True)  # the bottom panel of its column
    title = getattr(getattr(scene, "study", None), "title", "") or ""
    if title:
        fig.suptitle(title, fontsize=10)
    handles, labels = axes[0].get_legend_handles_labels()
    for ax in axes[1:len(values)]:  # every kind of mark once, whichever panel drew it first
        for h, lab in zip(*ax.get_legend_handles_labels()):
            if lab not in labels:
                handles.append(h), labels.append(lab)
    if handles:
        fig.legend(handles, labels, loc="outside lower center", ncols=len(handles), fontsize=8)
    return fig


# --- animations ---


def animate(m: Mechanism, sweep: Sweep, path, *, paths=None, frames: int = 120, fps: int = 20,
            captions=None, units: str = "", dpi: int = 80, size=(6.4, 4.8), progress=None) -> int:
    """Write an animated GIF of the sweep's solved poses (at most `frames` of them, evenly
    spread); returns the number of frames written. `captions[i]` titles pose i;
    `progress(done, total)` is called after each frame (a progress bar, say).

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
    from .plot import (Drawing, caption, check_paths, geometry, new_figure, require_matplotlib,
                       smooth_paths)
    require_matplotlib("kincas.outputs.animate")
    from matplotlib.animation import PillowWriter
    ok = np.flatnonzero(sweep.ok) if sweep.ok.any() else np.array([0])
    pick = ok[np.unique(np.round(np.linspace(0, ok.size - 1, min(frames, ok.size))).astype(int))]
    fig = new_figure(size)
    chosen = check_paths(m, paths)
    d = Drawing(fig.subplots(), m, geometry(m, sweep), chosen, True, units, smooth_paths(m, sweep, chosen))
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


# --- the command line's output flags ---


def _fail(message: str):
    """A wrong invocation, like a wrong scene: `kincas` prints it in one line, exit status 2."""
    raise OutputError(message)


# flag -> (attribute of the parsed arguments, what writes it: "matplotlib", "animation" or None)
FILE_FLAGS = {"--csv": ("csv", None), "--plot": ("plot", "matplotlib"),
              "--animate": ("animate", "animation"), "--plot-quantities": ("plot_quantities", "matplotlib"),
              "--html": ("html", "html"), "--svg": ("svg", "svg"), "--dxf": ("dxf", "dxf")}


def check_outputs(args, mechanism=None, poses: int | None = None) -> None:
    """Fail early (one line, exit 2), before any solve: a picture asked for without matplotlib,
    a file type that cannot be written, a folder that does not exist or cannot be written,
    --paths naming a point that does not exist, --pose outside the sweep's `poses`."""
    from .plot import require_matplotlib
    for flag, (attr, writer) in FILE_FLAGS.items():
        path = getattr(args, attr, None)
        if not path:
            continue
        if writer in ("matplotlib", "animation"):
            try:
                require_matplotlib(flag)
            except ModuleNotFoundError as e:
                _fail(str(e))
        if writer == "dxf":
            try:
                import ezdxf  # noqa: F401
            except ModuleNotFoundError:
                _fail('--dxf needs ezdxf: pip install "kincas[cad]"')
        check_path(flag, path, _formats(writer))
    pose = getattr(args, "pose", None)
    if poses is not None and pose is not None and not -poses <= pose < poses:
        _fail(f"--pose: {pose} is not a pose of this sweep (0 to {poses - 1}, or -1 for the last)")
    if mechanism is not None and getattr(args, "paths", None):
        known = set(mechanism.moving_points) | set(mechanism.ground_points)
        bad = [p for p in _names(args.paths) if p not in known]
        if bad:
            _fail(f"--paths: unknown point(s) {', '.join(bad)} (points: {', '.join(sorted(known))})")
    geo = {k: _names(getattr(args, k, None) or "") for k in ("evolute", "centrodes")}
    if any(geo.values()):
        if not getattr(args, "plot", None):
            _fail("--evolute, --centrodes: they draw on the picture of --plot OUT.png; give --plot")
        if mechanism is not None:
            from .draw_geometry import check_geometry
            try:
                check_geometry(mechanism, geo["evolute"], geo["centrodes"])
            except ValueError as e:
                _fail(str(e))


def check_path(flag: str, path, formats=None) -> None:
    """The file `path` can be written: its folder exists and is writable, and its extension is
    one of `formats` (any when None)."""
    import os
    from pathlib import Path
    p = Path(path)
    folder = p.parent if str(p.parent) else Path(".")
    if not folder.is_dir():
        _fail(f"cannot write {path} ({flag}): the folder {folder} does not exist")
    if not os.access(folder, os.W_OK):
        _fail(f"cannot write {path} ({flag}): the folder {folder} is not writable")
    if p.is_dir():
        _fail(f"cannot write {path} ({flag}): it is a folder")
    ext = p.suffix.lower().lstrip(".")
    if formats is not None and ext not in formats:
        _fail(f"cannot write {path} ({flag}): {repr(ext) + ' is' if ext else 'a file without extension is'} not "
              f"supported (use one of {', '.join('.' + f for f in sorted(formats))})")


def _formats(writer) -> set[str] | None:
    """File extensions a writer can produce here."""
    if writer == "matplotlib":
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        return set(FigureCanvasAgg.get_supported_filetypes())
    if writer in ("html", "svg", "dxf"):
        return {"html": {"html", "htm"}, "svg": {"svg"}, "dxf": {"dxf"}}[writer]
    if writer == "animation":
        from matplotlib.animation import writers
        out = {"gif", "webp", "apng"}  # Pillow, which the plot extra installs
        if writers.is_available("ffmpeg"):
            out |= {"mp4", "mkv", "webm", "mov", "avi"}
        return out
    return None


def _names(text: str) -> list[str]:
    return [p.strip() for p in str(text).split(",") if p.strip()]


def write_outputs(scene, sweep: Sweep, args) -> None:
    """Write what the flags ask for: args.csv, args.plot, args.animate, args.plot_quantities
    (and, when the parser has them, args.paths "P,Q" and args.pose, the index drawn)."""
    m = scene.mechanism
    check_outputs(args, m, len(sweep))
    paths = _names(args.paths) if getattr(args, "paths", None) else None
    pose = getattr(args, "pose", None)
    length = scene.study.units.get("length", "")
    inputs = scene.user_inputs(sweep)
    captions = [_caption(scene, sweep, inputs, i) for i in range(len(sweep))]
    jobs = [("csv", lambda p: write_csv(p, sweep, scene)),
            ("plot", lambda p: _save_drawing(p, m, sweep, pose, paths, captions, length,
                                             _names(getattr(args, "evolute", None) or ""),
                                             _names(getattr(args, "centrodes", None) or ""))),
            ("animate", lambda p: _animate(p, m, sweep, paths, captions, length, _rendering(args))),
            ("plot_quantities", lambda p: savefig(plot_quantities(sweep, scene=scene), p, dpi=100)),
            ("html", lambda p: _html(p, m, sweep, scene, paths)),
            ("svg", lambda p: _svg(p, m, sweep, scene, pose, paths)),
            ("dxf", lambda p: _dxf(p, m, sweep, scene, pose, paths))]
    for attr, job in jobs:
        path = getattr(args, attr, None)
        if path:
            try:
                job(path)
            except OSError as e:
                _fail(f"cannot write {path}: {e.strerror or e}")
            except ValueError as e:  # a file type matplotlib or Pillow cannot write
                _fail(f"cannot write {path}: {str(e).splitlines()[0] if str(e) else type(e).__name__}")


DENSE = 4  # solved poses between two of the sweep's, for the paths of vector pictures


def _dense(sweep) -> int:
    return DENSE if len(sweep) <= 2000 else 0


def _html(path, m, sweep, scene, paths):
    from .html import write_html
    write_html(path, m, sweep, scene, paths, dense=_dense(sweep))


def _svg(path, m, sweep, scene, pose, paths):
    from .svg import write_svg
    write_svg(path, m, sweep, pose, paths=paths, scene=scene, dense=_dense(sweep))


def _dxf(path, m, sweep, scene, pose, paths):
    from .dxf import write_dxf
    write_dxf(path, m, sweep, pose, paths=paths, dense=_dense(sweep),
              units=scene.study.units.get("length", "") if scene is not None else "")


def _caption(scene, sweep, inputs, i) -> str:
    from .common import _unit
    parts = []
    for k, v in inputs.items():
        u = _unit(scene, k)
        parts.append(f"{k} = {v[i]:.4g}" + ("°" if u == "deg" else f" {u}" if u else ""))
    head = (scene.study.title + ": ") if scene.study.title else ""
    return head + ", ".join(parts) + ("" if sweep.status[i] == "ok" else f" ({sweep.status[i]})")


def _save_drawing(path, m, sweep, pose, paths, captions, length, evolute=(), centrodes=()):
    from .plot import default_pose, draw, new_figure
    fig = new_figure()
    i = default_pose(sweep) if pose is None else pose % len(sweep)
    ax = draw(m, sweep, i, ax=fig.subplots(), paths=paths, title=captions[i], units=length)
    if evolute or centrodes:  # kinematic geometry over the drawing (kincas/cli/draw_geometry.py)
        from .draw_geometry import draw_geometry
        draw_geometry(ax, m, sweep, i, evolute, centrodes)
    savefig(fig, path, dpi=100)


def savefig(fig, path, **kw) -> None:
    """`fig.savefig(path, **kw)`, the file whole or not at all (kincas/cli/atomic.py)."""
    from .atomic import replacing
    with replacing(path) as tmp:
        fig.savefig(tmp, **kw)


def _rendering(args):
    """A progress bar labelled "rendering" where `kincas solve` would show one."""
    from .common import progress_for
    bar = progress_for(args)
    if bar is not None:
        bar.label = "rendering"
    return bar


def _animate(path, m, sweep, paths, captions, length, progress=None):
    animate(m, sweep, path, paths=paths, captions=captions, units=length, progress=progress)
