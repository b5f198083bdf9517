"""A map of a study's outputs over two varied parameters (`kincas study --plot map.png`).

One panel per report expression, over the first two varied parameters: a filled image of
the cells of a grid (each design's value at its cell), or, for scattered (Latin hypercube)
designs, a triangulated contour; designs that were not solved at every pose are marked with
a red x and left blank. With one varied parameter, each output is drawn against it.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import OutputError


def check_plot(path, vary) -> None:
    """Fail before a long study when the picture cannot be made."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise OutputError("--plot: needs matplotlib (pip install 'kincas[plot]')") from None
    if Path(path).suffix.lower() not in (".png", ".svg", ".pdf"):
        raise OutputError(f"--plot: {str(path)!r}: expected a .png, .svg or .pdf file")


def _label(name: str, units: dict) -> str:
    """`name [unit]`, or the name alone when its unit is not known (or a pure number)."""
    u = units.get(name)
    return f"{name} [{u}]" if u else name


def plot_map(r, path, title: str = "", units: dict | None = None) -> None:
    """Draw the map of the `Study` r into the file `path`; `units` gives the unit label of
    each varied parameter and report expression (the axes' and colour bars' labels)."""
    units = units or {}
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    k = len(r.report)
    fig, axes = plt.subplots(1, k, figsize=(5.2 * k, 4.4), squeeze=False)
    x = r.params[:, 0]
    bad = ~r.ok
    for ax, text in zip(axes[0], r.report):
        v = np.where(r.ok, r.values[text], np.nan)
        if len(r.names) >= 2:
            y = r.params[:, 1]
            _panel(ax, x, y, v, _label(text, units))
            ax.set_ylabel(_label(r.names[1], units))
            if bad.any():
                ax.plot(x[bad], y[bad], "x", color="tab:red", ms=4, mew=1,
                        label="not solved at every pose")
                ax.legend(loc="upper right", fontsize="small")
        else:
            order = np.argsort(x)
            ax.plot(x[order], v[order], "-", color="tab:blue")
            if bad.any():
                ax.plot(x[bad], np.zeros(bad.sum()) + np.nanmin(v, initial=0.0), "x",
                        color="tab:red", label="not solved at every pose")
                ax.legend(fontsize="small")
            ax.set_ylabel(_label(text, units))
        ax.set_xlabel(_label(r.names[0], units))
        ax.set_title(text, fontsize="medium")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    try:
        from .atomic import savefig
        savefig(fig, path, dpi=110)
    except OSError as e:
        raise OutputError(f"--plot: cannot write {str(path)!r}: {e.strerror or e}") from None
    finally:
        plt.close(fig)


def _panel(ax, x, y, v, label: str = ""):
    xs, ys = np.unique(x), np.unique(y)
    if len(xs) * len(ys) == len(x) and len(xs) > 1 and len(ys) > 1:  # a full grid: its cells
        Z = np.full((len(ys), len(xs)), np.nan)
        Z[np.searchsorted(ys, y), np.searchsorted(xs, x)] = v
        im = ax.pcolormesh(_edges(xs), _edges(ys), np.ma.masked_invalid(Z), shading="flat")
        if np.isfinite(Z).sum() > 3 and np.nanmax(Z) > np.nanmin(Z):
            ax.contour(xs, ys, np.ma.masked_invalid(Z), colors="k", linewidths=0.5, alpha=0.6)
    else:
        good = np.isfinite(v)
        if good.sum() >= 3:
            im = ax.tricontourf(x[good], y[good], v[good], levels=14)
        else:
            im = ax.scatter(x[good], y[good], c=v[good])
    ax.figure.colorbar(im, ax=ax, label=label)


def _edges(c):
    mid = 0.5 * (c[1:] + c[:-1])
    return np.concatenate([[c[0] - (mid[0] - c[0])], mid, [c[-1] + (c[-1] - mid[-1])]])
