"""`kincas simulate SCENE.toml`: the motion of the scene's free inputs under its loads.

One row per output time: `t`, every free input and its rate, then the `[output]` report, in
the scene's units. `--json`, `--csv`, `--plot-quantities`, `--animate`, `--html` as for
`kincas solve`, with the time as the axis. `--steady` finds the periodic steady state
instead (kincas/analysis/steady.py). Exit 0 when the whole duration was integrated, 3 when
the motion stopped early (the reason and the time in the events), 2 for a wrong scene.
"""
from __future__ import annotations

import json
import math
import sys

import numpy as np

from .common import EXIT_OK, EXIT_UNSOLVED, _list, _unit
from .scene import load
from .scene_simulate import arguments_of
from ..model.names import is_angle_name


def cli_arguments(parser) -> None:
    """Arguments of `kincas simulate`."""
    parser.add_argument("scene", help="the scene file (TOML) with free inputs and [simulate]")
    parser.add_argument("--json", action="store_true", help="print inputs (t, values), rates, values, events as JSON")
    parser.add_argument("--csv", metavar="OUT.csv", help="write a row per output time")
    parser.add_argument("--plot-quantities", metavar="OUT.png", help="plot the reported quantities against time")
    parser.add_argument("--animate", metavar="OUT.gif", help="animate the motion")
    parser.add_argument("--html", metavar="OUT.html", help="one page: the motion animated, the quantities plotted")
    parser.add_argument("--steady", action="store_true",
                        help="the periodic steady state: mean speed and coefficient of speed fluctuation")
    parser.add_argument("--no-progress", action="store_true", help="(accepted for symmetry with solve)")


def run_scene(sc):
    """Simulate the scene as written: a kincas Simulation."""
    from ..analysis.simulate import simulate
    sim = sc.study.simulation
    return simulate(sc.mechanism, sim["duration"], sim["steps"] or 101, report=sc.quantities,
                    **arguments_of(sc))


def user_series(sc, r) -> tuple[dict, dict]:
    """(inputs with `t` first, the free inputs' rates and the report) in the scene's units."""
    from ..analysis.simulate import rate_name
    from ..model.names import is_angular
    k = 180 / math.pi if sc.study.deg else 1.0
    ins = {"t": r.time}
    rates = {}
    for key in sc.study.simulation["free"]:
        ang = is_angle_name(key)
        ins[key] = r.inputs[key] * (k if ang else 1.0)
        rates[rate_name(key)] = r.rates[key] * (k if ang else 1.0)
    values = {n: v * (k if is_angular(n, sc.mechanism) else 1.0) for n, v in r.values.items()}
    return ins, {**rates, **{n: v for n, v in values.items() if n not in rates}}


def cli_run(args) -> int:
    from . import bounds
    with bounds.json_output(args.json):
        sc = load(args.scene)
    if args.steady:
        from .flywheel import print_steady
        return print_steady(sc, args)
    wants = args.csv or args.animate or args.plot_quantities or args.html
    if wants:
        from .outputs import check_outputs
        check_outputs(args, sc.mechanism)
    r = run_scene(sc)
    ins, values = user_series(sc, r)
    events = [{"time": e["time"], "reason": e["reason"]} for e in r.events]
    if args.json:
        doc = {"title": sc.study.title, "units": sc.study.units,
               "inputs": {k: _list(v) for k, v in ins.items()},
               "status": r.status.tolist(), "values": {k: _list(v) for k, v in values.items()},
               "events": events}
        sys.stdout.write(json.dumps(doc, allow_nan=False) + "\n")
    else:
        _table(sc, ins, values, r, events)
    if wants:
        from .outputs import write_outputs
        args.plot = args.svg = args.dxf = args.paths = args.pose = None
        write_outputs(sc, r.sweep(), args)
    return EXIT_OK if r.ok else EXIT_UNSOLVED


def _table(sc, ins, values, r, events):
    print(sc.study.title or "kincas simulate")
    cols = {**ins, **values}
    T = sc.study.units.get("time", "s")
    unit = lambda c: T if c == "t" else _unit(sc, c)  # noqa: E731
    heads = [c if not unit(c) else f"{c} [{unit(c)}]" for c in cols]
    width = [max(12, len(h)) for h in heads]
    print("  ".join(h.rjust(w) for h, w in zip(heads, width)) + "  status")
    for i in range(len(r.time)):
        cells = [("-" if not np.isfinite(v[i]) else f"{v[i]:.6g}").rjust(w) for v, w in zip(cols.values(), width)]
        print("  ".join(cells) + f"  {r.status[i]}")
    for e in events:
        print(f"stopped at t = {e['time']:.9g} {T}: {e['reason']}")
    good = int(np.sum(r.status == "ok"))
    print(f"{len(r.time)} times, {good} reached" + ("" if r.ok else f", {len(r.time) - good} not reached"))
