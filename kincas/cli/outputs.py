"""The `kincas solve` flags that write a sweep's outputs as files (--csv, --plot, --animate,
--plot-quantities, --html, --svg, --dxf): checked before solving, then written by the
writers of kincas/views (CSV tables and quantity plots in views/quantities.py, animations
in views/animation.py, drawings in views/plot.py, svg.py, dxf.py, html.py), which are
still importable from here.

Values are written in the scene's units (degrees where the scene says so).

>>> sorted(FILE_FLAGS)[:3]
['--animate', '--csv', '--dxf']
"""
from __future__ import annotations

from ..errors import OutputError
from ..results import Sweep
from ..views.animation import animate  # noqa: F401  (its old home)
from ..views.columns import _abscissa, heading, user_columns  # noqa: F401  (their old home)
from ..views.quantities import FLAG_STYLE, _break_wraps, _flat, _runs, plot_quantities, write_csv  # noqa: F401
from ..views.atomic import savefig  # noqa: F401  (also its old home)

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
    from ..views.plot import require_matplotlib
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
    _check_view(args, mechanism)
    if (getattr(args, "forces", False) or getattr(args, "centres", False)) and not any(
            getattr(args, a, None) for a in ("plot", "animate", "html", "svg", "dxf")):
        _fail("--forces, --centres: they draw on the pictures; give --plot, --animate, --html, --svg or --dxf")
    geo = {k: _names(getattr(args, k, None) or "") for k in ("evolute", "centrodes")}
    if any(geo.values()):
        if not getattr(args, "plot", None):
            _fail("--evolute, --centrodes: they draw on the picture of --plot OUT.png; give --plot")
        if mechanism is not None:
            from ..views.draw_geometry import check_geometry
            try:
                check_geometry(mechanism, geo["evolute"], geo["centrodes"])
            except ValueError as e:
                _fail(str(e))


def add_view_argument(parser) -> None:
    """`--view iso|xy|yz|zx` for a command that draws pictures through `write_outputs`."""
    from ..views.projection import VIEWS
    parser.add_argument("--view", choices=list(VIEWS), metavar="|".join(VIEWS),
                        help="a spatial scene's projection in --plot, --animate, --svg and the view --html opens "
                             "with (default iso); a planar scene is drawn in its plane (xy only)")


def _check_view(args, mechanism) -> None:
    """--view: a spatial scene's projection (kincas/views/projection.py), for the pictures that
    draw one; a planar scene accepts only its own plane, xy. Evolutes and centrodes are planar."""
    from ..views.projection import check_view, is_spatial
    spatial = mechanism is not None and is_spatial(mechanism)
    view = getattr(args, "view", None)
    if view is not None:
        if not any(getattr(args, a, None) for a in ("plot", "animate", "svg", "html")):
            _fail("--view: it chooses the projection of --plot, --animate, --svg and --html; give one of them")
        if mechanism is not None:
            try:
                check_view(view, spatial)
            except ValueError as e:
                _fail(str(e))
    if spatial and (getattr(args, "evolute", None) or getattr(args, "centrodes", None)):
        _fail("--evolute, --centrodes: the kinematic geometry of planar motion; this scene is spatial")
    if spatial and (getattr(args, "forces", False) or getattr(args, "centres", False)):
        _fail("--forces, --centres: the arrows and instant centres are drawn on planar pictures; this scene is spatial")


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
    view = getattr(args, "view", None)  # a spatial scene's projection (None: iso; planar: its plane)
    length = scene.study.units.get("length", "")
    inputs = scene.user_inputs(sweep)
    captions = [_caption(scene, sweep, inputs, i) for i in range(len(sweep))]
    solved = _SharedPaths(m, sweep, paths, [a for a in ("plot", "animate", "html", "svg", "dxf")
                                            if getattr(args, a, None)])
    over = {"forces": bool(getattr(args, "forces", False)), "centres": bool(getattr(args, "centres", False))}
    jobs = [("csv", lambda p: write_csv(p, sweep, scene)),
            ("plot", lambda p: _save_drawing(p, m, sweep, pose, paths, captions, length,
                                             _names(getattr(args, "evolute", None) or ""),
                                             _names(getattr(args, "centrodes", None) or ""), solved(), view, **over)),
            ("animate", lambda p: _animate(p, m, sweep, paths, captions, length, _rendering(args), solved(),
                                           view, **over)),
            ("plot_quantities", lambda p: savefig(plot_quantities(sweep, scene=scene), p, dpi=100)),
            ("html", lambda p: _html(p, m, sweep, scene, paths, solved.dense(), view, **over)),
            ("svg", lambda p: _svg(p, m, sweep, scene, pose, paths, solved.dense(), view, **over)),
            ("dxf", lambda p: _dxf(p, m, sweep, scene, pose, paths, solved.dense(), **over))]
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


class _SharedPaths:
    """The paths every picture of one run draws, solved once for all of them, when the first
    asks: through extra poses solved between the sweep's, as many as the most demanding
    picture asked for needs (a drawing or an animation: paths through about 360 points,
    `kincas.views.picture.smooth_steps`; a vector picture: DENSE, for sweeps of up to 2,000
    poses); None (the sweep's own poses) when none needs more."""

    def __init__(self, m, sweep, paths, pictures):
        from ..views.picture import smooth_steps
        n = len(sweep)
        need = [smooth_steps(n) if p in ("plot", "animate") else DENSE if n <= 2000 else 0 for p in pictures]
        self.m, self.sweep, self.paths, self.steps = m, sweep, paths, max(need, default=0)
        self.xy, self.done = None, False

    def __call__(self) -> dict | None:
        if not self.done:
            from ..views.picture import dense_paths
            from ..views.poses import check_paths
            chosen = check_paths(self.m, self.paths)
            self.xy = dense_paths(self.m, self.sweep, chosen, self.steps) if self.steps and chosen else None
            self.done = True
        return self.xy

    def dense(self) -> int | dict:
        """What the vector pictures take as `dense`: the paths solved, or 0 (none to add)."""
        xy = self()
        return 0 if xy is None else xy


def _html(path, m, sweep, scene, paths, dense=0, view=None, **over):
    from ..views.html import write_html
    write_html(path, m, sweep, scene, paths, dense=dense, view=view, **over)


def _svg(path, m, sweep, scene, pose, paths, dense=0, view=None, **over):
    from ..views.svg import write_svg
    write_svg(path, m, sweep, pose, paths=paths, scene=scene, dense=dense, view=view, **over)


def _dxf(path, m, sweep, scene, pose, paths, dense=0, **over):
    from ..views.dxf import write_dxf
    write_dxf(path, m, sweep, pose, paths=paths, dense=dense,
              units=scene.study.units.get("length", "") if scene is not None else "", **over)


def _caption(scene, sweep, inputs, i) -> str:
    from ..views.columns import quantity_unit as _unit
    parts = []
    for k, v in inputs.items():
        u = _unit(scene, k)
        parts.append(f"{k} = {v[i]:.4g}" + ("°" if u == "deg" else f" {u}" if u else ""))
    head = (scene.study.title + ": ") if scene.study.title else ""
    return head + ", ".join(parts) + ("" if sweep.status[i] == "ok" else f" ({sweep.status[i]})")


def _save_drawing(path, m, sweep, pose, paths, captions, length, evolute=(), centrodes=(), path_xy=None,
                  view=None, forces=False, centres=False):
    from ..views.plot import default_pose, draw, new_figure
    fig = new_figure()
    i = default_pose(sweep) if pose is None else pose % len(sweep)
    ax = draw(m, sweep, i, ax=fig.subplots(), paths=paths, title=captions[i], units=length, path_xy=path_xy,
              view=view, forces=forces, centres=centres)
    if evolute or centrodes:  # kinematic geometry over the drawing (kincas/views/draw_geometry.py)
        from ..views.draw_geometry import draw_geometry
        draw_geometry(ax, m, sweep, i, evolute, centrodes)
    savefig(fig, path, dpi=100)


def _rendering(args):
    """A progress bar labelled "rendering" where `kincas solve` would show one."""
    from .common import progress_for
    bar = progress_for(args)
    if bar is not None:
        bar.label = "rendering"
    return bar


def _animate(path, m, sweep, paths, captions, length, progress=None, path_xy=None, view=None, forces=False,
             centres=False):
    animate(m, sweep, path, paths=paths, captions=captions, units=length, progress=progress, path_xy=path_xy,
            view=view, forces=forces, centres=centres)
