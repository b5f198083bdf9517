"""A sweep's quantities as files and plots: CSV tables (a row per pose, headings with
units) and the quantities plotted against the input, with singular positions marked and
unsolved poses shaded.

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

import numpy as np

from ..results import Sweep
from .columns import _abscissa, heading, user_columns
from ..model.names import is_angle_name

FLAG_STYLE = {"limit": ("#d62728", "limit of motion"), "change point": ("#9467bd", "change point"),
              "singular": ("#ff7f0e", "singular position")}


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


def _runs(mask: np.ndarray):
    """(first, last) index of every run of True in mask."""
    idx = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(int), [0]])))
    return list(zip(idx[::2], idx[1::2] - 1))


def _break_wraps(name: str, x, v, half):
    """An angle wrapped to (-half turn, half turn] jumps by a whole turn: no line there.

    >>> _break_wraps("L.angle", np.arange(3.0), np.array([3.0, -3.1, -3.0]), np.pi)[1].tolist()
    [3.0, nan, -3.1, -3.0]
    """
    if not is_angle_name(name) or len(v) < 2:
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
