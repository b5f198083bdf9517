"""The command line: `kincas solve SCENE.toml [--json]`.

Exit status: 0 when every pose was solved, 3 when some were not, 2 when the scene itself is
wrong (with one message on standard error naming the section and the field, no traceback).

>>> main(["--version"])
kincas 0.1.0
0
"""
from __future__ import annotations

import argparse
import importlib
import json
import math
import sys

import numpy as np

from .. import __version__
from ..errors import KincasError, OutputError
from ..model.mechanism import Param

EXIT_OK, EXIT_SCENE, EXIT_UNSOLVED, EXIT_INTERRUPTED = 0, 2, 3, 130

# Further commands live in their own modules: each defines `cli_arguments(parser)` and
# `cli_run(args) -> exit status`, and is imported only when it exists.
COMMANDS = {
    "range": ("kincas.analysis.singular", "range of motion of the input, its limits and singular positions"),
    "modes": ("kincas.analysis.modes", "the distinct assembly modes at the scene's input, as [guess] blocks"),
    "optimize": ("kincas.synthesis.optimize", "optimise parameters as the scene's [optimize] section says"),
    "tolerance": ("kincas.analysis.tolerance", "first-order and Monte-Carlo spread of outputs from parameter tolerances"),
    "study": ("kincas.cli.study", "many designs at once: the scene's [study] section, one row per design"),
    "cam": ("kincas.cli.cam", "design a disc cam from the scene's [cam_design] section (profile, pressure angle, curvature)"),
}


def _parser(argv: list[str] | None = None) -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="kincas", description="Kinematics of planar closed-chain mechanisms.")
    ap.add_argument("--version", action="store_true", help="print the version and exit")
    sub = ap.add_subparsers(dest="command")
    s = sub.add_parser("solve", help="solve a scene: positions, velocities, accelerations over its inputs")
    s.add_argument("scene", help="the scene file (TOML)")
    s.add_argument("--json", action="store_true", help="print the documented JSON object")
    s.add_argument("--csv", metavar="OUT.csv", help="write a row per pose, a column per quantity")
    s.add_argument("--plot", metavar="OUT.png", help="draw the mechanism with the paths of its points")
    s.add_argument("--animate", metavar="OUT.gif", help="animate the sweep")
    s.add_argument("--plot-quantities", metavar="OUT.png", help="plot the reported quantities against the input")
    s.add_argument("--html", metavar="OUT.html", help="one self-contained page: the mechanism animated, a slider, the quantities plotted")
    s.add_argument("--svg", metavar="OUT.svg", help="the drawing and the paths as vector graphics")
    s.add_argument("--dxf", metavar="OUT.dxf", help="links, pivots, slides and paths as DXF entities, a layer per body (kincas[cad])")
    s.add_argument("--paths", metavar="P,Q", help="points whose paths --plot and --animate draw (default: every moving point)")
    s.add_argument("--evolute", metavar="P,Q", help="with --plot: draw the evolutes (centres of curvature) of these points' paths")
    s.add_argument("--centrodes", metavar="L,M", help="with --plot: draw the fixed and moving centrodes of these links")
    s.add_argument("--pose", type=int, metavar="I", help="the pose --plot draws, by index (default: the first solved; -1: the last)")
    s.add_argument("--no-progress", action="store_true", help="no progress bar, even on a terminal")
    chosen = next((a for a in (argv or []) if not a.startswith("-")), None)
    for name, (module, text) in COMMANDS.items():
        c = sub.add_parser(name, help=text)
        if name != chosen:  # only the command being run is imported
            continue
        mod = importlib.import_module(module)
        mod.cli_arguments(c)
        c.set_defaults(run=mod.cli_run)
    return ap


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status."""
    argv = sys.argv[1:] if argv is None else list(argv)
    ap = _parser(argv)
    args = ap.parse_args(argv)
    if args.version:
        print(f"kincas {__version__}")
        return EXIT_OK
    if args.command is None:
        ap.print_help()
        return EXIT_SCENE
    try:
        _check_args(args)
        return args.run(args) if hasattr(args, "run") else _solve(args)
    except KeyboardInterrupt:  # Ctrl-C: the user knows why; one line, the shell's usual 130
        print("\nkincas: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # `kincas solve ... | head`: the reader left, nothing is wrong
        sys.stderr.close()
        return EXIT_OK
    except OutputError as e:  # a file or option that cannot be honoured: one line
        print(f"kincas: {e}", file=sys.stderr)
        return EXIT_SCENE
    except KincasError as e:
        print(f"kincas: error in {getattr(args, 'scene', 'scene')}:\n{e}", file=sys.stderr)
        return EXIT_SCENE


def _check_args(args) -> None:
    """Options every command shares, checked before any work: a seed is >= 0, --write names a
    directory, and --starts / --samples fit in memory (a typo must not take the machine)."""
    from pathlib import Path
    from . import bounds
    seed = getattr(args, "seed", None)
    if seed is not None and seed < 0:
        raise OutputError(f"--seed: expected a whole number >= 0, got {seed}")
    write = getattr(args, "write", None)
    if write and Path(write).exists() and not Path(write).is_dir():
        raise OutputError(f"--write: {write} exists and is not a directory (--write names a directory)")
    starts, samples = getattr(args, "starts", None), getattr(args, "samples", None)
    if not (starts or args.command in ("tolerance", "range")):
        return
    from .scene import load
    from ..core.numeric import compile
    sc = load(args.scene)
    if args.command == "range" and not sc.study.inputs:
        raise OutputError("[[inputs]]: none declared, so there is no range of motion to find "
                          "(kincas range ranges an input; kincas solve solves a structure)")
    nq, nrep = compile(sc.mechanism).sym.nq, len(sc.quantities)
    try:
        if starts:
            bounds.check("--starts", starts, bounds.per_sample(nq, 0, 0))
        if args.command == "tolerance":
            t = sc.study.raw.get("tolerance", {})
            field, n = ("--samples", samples) if samples else ("[tolerance] samples", t.get("samples"))
            if isinstance(n, int) and not isinstance(n, bool) and n > 0:
                std = t.get("std", {})
                poses = max((len(v) for v in sc.study.inputs.values()), default=1)
                bounds.check(field, n, bounds.per_sample(nq, nrep, len(std) if isinstance(std, dict) else 1, poses))
    except ValueError as e:
        raise OutputError(str(e)) from None


def _solve(args) -> int:
    from .scene import load
    sc = load(args.scene)
    wants_files = (args.csv or args.plot or args.animate or args.plot_quantities or args.html
                   or args.svg or args.dxf)
    if wants_files or args.pose is not None or args.evolute or args.centrodes:  # fail before a long solve
        from .outputs import check_outputs
        check_outputs(args, sc.mechanism, len(next(iter(sc.study.inputs.values()))))
    sw = sc.run(progress=progress_for(args))
    from .numbers import clean  # zero to the solve's accuracy is printed as 0, not as noise
    inputs, values = sc.user_inputs(sw), clean(sc.user_values(sw), sc, sw)
    if args.json:
        doc = {"title": sc.study.title, "units": sc.study.units,
               "inputs": {k: _list(v) for k, v in inputs.items()},
               "rates": _user_rates(sc, sw.rates), "accelerations": _user_rates(sc, sw.accelerations),
               "status": sw.status.tolist(), "flags": list(sw.flags),
               "values": {k: _list(v) for k, v in values.items()},
               "events": [_user_event(sc, e) for e in sw.events]}
        # dumps, not dump: json.dump streams through the pure-Python encoder, 4x slower
        sys.stdout.write(json.dumps(doc, allow_nan=False) + "\n")
    else:
        _table(sc, sw, inputs, values)
    if wants_files:
        from .outputs import write_outputs
        write_outputs(sc, sw, args)
    return EXIT_OK if all(s == "ok" for s in sw.status) else EXIT_UNSOLVED


def progress_for(args):
    """A progress callback for long runs on a terminal; None when piped or with --json."""
    if getattr(args, "json", False) or getattr(args, "no_progress", False) or not sys.stderr.isatty():
        return None
    try:
        from .progress import Progress
    except ModuleNotFoundError:
        return None
    return Progress(stream=sys.stderr)


def _user_rates(sc, rates: dict) -> dict:
    """Each input's rate (or acceleration) in the scene's units: one number when it is the
    same at every pose, else a list."""
    out = {}
    for k, v in rates.items():
        v = np.atleast_1d(np.asarray(v, float))
        if k.endswith(".angle") and sc.study.deg:
            v = np.degrees(v)
        v = np.array([float(f"{x:.15g}") for x in v])  # through radians: 60.00000000000001 is 60
        out[k] = float(v[0]) if v.size and np.ptp(v) == 0 else _list(v)
    return out


def _user_event(sc, e: dict) -> dict:
    """A singular position or a resumption, with its input values in the scene's units."""
    deg = sc.study.deg
    ins = {k: (math.degrees(v) if deg and k.endswith(".angle") else v) for k, v in e["inputs"].items()}
    return {**e, "inputs": ins}


def _list(v) -> list:
    v = np.asarray(v, dtype=float)
    out = v.tolist()
    if not np.isfinite(v).all():  # JSON has no NaN: null where a pose was not solved
        for i in np.flatnonzero(~np.isfinite(v)):
            out[i] = None
    return out


def _unit(sc, name: str) -> str:
    from ..core.symbolic import is_angular, parse_quantity
    u = sc.study.units
    L, A, T = u.get("length", ""), u.get("angle", "deg"), u.get("time", "s")
    kind, obj, attr = parse_quantity(name)
    if kind == "sens":  # Q's unit per the parameter's: mm/mm, deg/mm
        uq, up = _unit(sc, obj), _param_unit(sc, attr)
        return f"{uq or '1'}/{up}" if up else (f"{uq} per {attr}" if uq else "")
    if name in sc.mechanism.param_values:  # a driven parameter: a length, or an angle
        return _param_unit(sc, name)
    force = _force_unit(sc, name, L)
    if force is not None:
        return force
    base = A if is_angular(name, sc.mechanism) else L  # input keys L.angle included
    order = {"vx": 1, "vy": 1, "omega": 1, "v": 1, "ax": 2, "ay": 2, "alpha": 2, "a": 2,
             "jx": 3, "jy": 3, "jerk": 3}.get(attr, 0)
    return base + ("" if order == 0 else f"/{T}" if order == 1 else f"/{T}^{order}")


def _force_unit(sc, name: str, L: str) -> str | None:
    """Units of force quantities and curvature (None for others). The scene names no mass
    unit, so a force is written `force` (N with masses in kg and SI lengths, or in t and mm)."""
    from ..core.dynamics import _EFFORT
    m = _EFFORT.match(name)
    if m:
        angular = m["key"].endswith(".angle")
        return f"force·{L}" if angular and L else "force"
    if name.startswith("reaction(") or name in ("shaking.x", "shaking.y"):
        return "force"
    if name == "shaking.moment":
        return f"force·{L}" if L else "force"
    if name.endswith(".curvature"):
        return f"1/{L}" if L else ""
    return None


def _param_unit(sc, name: str) -> str:
    """A parameter's unit: the scene's angle unit where it gives a slide's angle, else length."""
    u = sc.study.units
    angular = any(isinstance(sl.angle, Param) and sl.angle.name == name and abs(sl.angle.scale) != 1
                  for sl in sc.mechanism.slides)
    return u.get("angle", "deg") if angular else u.get("length", "")


def rate_line(sc, sw) -> str:
    """The inputs' rates and accelerations, which every velocity and acceleration follows."""
    T = sc.study.units.get("time", "s")
    parts = []
    for k in sw.inputs:
        u = _unit(sc, k)
        r, a = (np.asarray(d.get(k, 0.0), float) for d in (sw.rates, sw.accelerations))
        if k.endswith(".angle") and sc.study.deg:
            r, a = np.degrees(r), np.degrees(a)
        show = lambda v: f"{v.flat[0]:.6g}" if v.size and np.ptp(v) == 0 else "varies"
        parts.append(f"{k} rate {show(r)} {u}/{T}, acceleration {show(a)} {u}/{T}^2")
    return "inputs: " + "; ".join(parts) + " (velocities and accelerations follow these)"


def _table(sc, sw, inputs, values):
    print(sc.study.title or "kincas")
    if sw.inputs:
        print(rate_line(sc, sw))
    values = {k: v for k, v in values.items() if k not in inputs}  # an input reported: once
    cols = list(inputs) + list(values)
    heads = [c if not _unit(sc, c) else f"{c} [{_unit(sc, c)}]" for c in cols]
    width = [max(12, len(h)) for h in heads]
    print("  ".join(h.rjust(w) for h, w in zip(heads, width)) + "  status")
    data = [inputs[c] for c in inputs] + [values[c] for c in values]
    for i in range(len(sw)):
        cells = [("-" if not math.isfinite(d[i]) else f"{d[i]:.6g}").rjust(w) for d, w in zip(data, width)]
        flag = f" ({sw.flags[i]})" if sw.flags[i] else ""
        print("  ".join(cells) + f"  {sw.status[i]}{flag}")
    for e in sw.events:
        e = _user_event(sc, e)
        at = ", ".join(f"{k} = {v:.12g}" for k, v in e["inputs"].items())
        what = f"resumed on the {e['branch']} branch" if e["kind"] == "resume" else e["kind"]
        print(f"pose {e['pose']}: {what} at {at}")
    bad = sum(s != "ok" for s in sw.status)
    print(f"{len(sw)} poses, {len(sw) - bad} solved" + (f", {bad} not solved" if bad else ""))
