"""`kincas solve SCENE.toml`: the scene's sweep, as a table, JSON, CSV or pictures.

Exit status: 0 when every pose was solved, 3 when some were not (2, a wrong scene, is the
command line's: kincas/cli/app.py).
"""
from __future__ import annotations

import json
import math
import sys

import numpy as np

from .common import EXIT_OK, EXIT_UNSOLVED, _list, _unit, progress_for
from .scene import load
from ..analysis.resume import label_text
from ..model.names import is_angle_name


def cli_arguments(parser) -> None:
    """Arguments of `kincas solve`."""
    parser.add_argument("scene", help="the scene file (TOML)")
    parser.add_argument("--json", action="store_true", help="print the documented JSON object")
    parser.add_argument("--csv", metavar="OUT.csv", help="write a row per pose, a column per quantity")
    parser.add_argument("--plot", metavar="OUT.png", help="draw the mechanism with the paths of its points")
    parser.add_argument("--animate", metavar="OUT.gif", help="animate the sweep")
    parser.add_argument("--plot-quantities", metavar="OUT.png", help="plot the reported quantities against the input")
    parser.add_argument("--html", metavar="OUT.html", help="one self-contained page: the mechanism animated, a slider, the quantities plotted")
    parser.add_argument("--svg", metavar="OUT.svg", help="the drawing and the paths as vector graphics")
    parser.add_argument("--dxf", metavar="OUT.dxf", help="links, pivots, slides and paths as DXF entities, a layer per body (kincas[cad])")
    parser.add_argument("--paths", metavar="P,Q", help="points whose paths --plot and --animate draw (default: every moving point)")
    parser.add_argument("--evolute", metavar="P,Q", help="with --plot: draw the evolutes (centres of curvature) of these points' paths")
    parser.add_argument("--centrodes", metavar="L,M", help="with --plot: draw the fixed and moving centrodes of these links")
    parser.add_argument("--forces", action="store_true", help="on every picture: arrows for the loads, springs, efforts and reactions")
    parser.add_argument("--centres", "--centers", action="store_true", help="on every picture: each link's instant centre")
    from .outputs import add_view_argument
    add_view_argument(parser)
    parser.add_argument("--pose", type=int, metavar="I", help="the pose --plot draws, by index (default: the first solved; -1: the last)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar, even on a terminal")


def cli_run(args) -> int:
    """Solve the scene and print (or write) the results."""
    from . import bounds
    with bounds.json_output(args.json):  # the sweep's size is checked as the output will cost
        sc = load(args.scene)
    wants_files = (args.csv or args.plot or args.animate or args.plot_quantities or args.html
                   or args.svg or args.dxf)
    if (wants_files or args.pose is not None or args.evolute or args.centrodes or args.forces or args.centres
            or args.view):  # fail before a long solve
        from .outputs import check_outputs
        check_outputs(args, sc.mechanism, len(next(iter(sc.study.inputs.values()))))
    sw = sc.run(progress=progress_for(args))
    from ..views.numbers import clean  # zero to the solve's accuracy is printed as 0, not as noise
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


def rate_line(sc, sw) -> str:
    """The inputs' rates and accelerations, which every velocity and acceleration follows."""
    T = sc.study.units.get("time", "s")
    parts = []
    for k in sw.inputs:
        u = _unit(sc, k)
        r, a = (np.asarray(d.get(k, 0.0), float) for d in (sw.rates, sw.accelerations))
        if is_angle_name(k) and sc.study.deg:
            r, a = np.degrees(r), np.degrees(a)
        show = lambda v: f"{v.flat[0]:.6g}" if v.size and np.ptp(v) == 0 else "varies"
        parts.append(f"{k} rate {show(r)} {u}/{T}, acceleration {show(a)} {u}/{T}^2")
    return "inputs: " + "; ".join(parts) + " (velocities and accelerations follow these)"


def _user_rates(sc, rates: dict) -> dict:
    """Each input's rate (or acceleration) in the scene's units: one number when it is the
    same at every pose, else a list."""
    out = {}
    for k, v in rates.items():
        v = np.atleast_1d(np.asarray(v, float))
        if is_angle_name(k) and sc.study.deg:
            v = np.degrees(v)
        v = np.array([float(f"{x:.15g}") for x in v])  # through radians: 60.00000000000001 is 60
        out[k] = float(v[0]) if v.size and np.ptp(v) == 0 else _list(v)
    return out


def _user_event(sc, e: dict) -> dict:
    """A singular position or a resumption, with its input values in the scene's units."""
    deg = sc.study.deg
    ins = {k: (math.degrees(v) if deg and is_angle_name(k) else v) for k, v in e["inputs"].items()}
    return {**e, "inputs": ins}


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
        what = label_text(e) if e["kind"] == "resume" else e["kind"]
        if e["kind"] == "assembly":  # the assembly a sweep without [guess] chose, and why
            pts = ", ".join(f"{pt} = [" + ", ".join(f"{c:.12g}" for c in xyz) + "]"  # 2D or 3D
                            for pt, xyz in e["guess"].items())
            print(f"pose {e['pose']}: assembly chosen at {at}: {e['reason']} ({pts})")
            continue
        print(f"pose {e['pose']}: {what} at {at}")
    bad = sum(s != "ok" for s in sw.status)
    print(f"{len(sw)} poses, {len(sw) - bad} solved" + (f", {bad} not solved" if bad else ""))
