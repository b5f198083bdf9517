"""`kincas optimize SCENE.toml`: the scene's [optimize] section solved by IPOPT, the design
reported in the scene's units (kincas/synthesis/optimize.py does the work)."""
from __future__ import annotations

import json
import math
import sys

import numpy as np

from ..model.names import is_angular
from ..synthesis.optimize import Optimization
from .common import _list, _param_unit, _unit
from .scene import load
from .scene_optimize import run_scene
from ..model.names import is_angle_name


def cli_arguments(parser) -> None:
    """Arguments of `kincas optimize`."""
    parser.add_argument("scene", help="the scene file (TOML) with an [optimize] section")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--starts", type=int, metavar="N", help="optimise from N starting designs drawn in the bounds; report the best distinct optima")
    parser.add_argument("--seed", type=int, help="random seed of the starts (default 0)")
    parser.add_argument("--scheduler", metavar="ADDRESS", help="run the starts on the Dask cluster at this scheduler address")


def cli_run(args) -> int:
    """Run `kincas optimize`: 0 for an optimal design that passed every check, 3 otherwise."""
    sc = load(args.scene)
    if getattr(args, "starts", None) is not None:
        return _multistart_run(sc, args)
    r = run_scene(sc)
    doc = report(sc, r)
    if args.json:
        json.dump(doc, sys.stdout, allow_nan=False)
        sys.stdout.write("\n")
    else:
        _print(sc, r, doc)
    return 0 if r.ok else 3


def report(sc, r: Optimization) -> dict:
    """The result as the JSON object of `kincas optimize --json`, in the scene's units."""
    deg = sc.study.deg
    user = lambda n, v: np.degrees(v) if deg and is_angular(n, sc.mechanism) else np.asarray(v, float)
    bounds = sc.study.raw["optimize"]["vary"]
    key = sc.mechanism.inputs[0].key
    num = lambda v: float(v) if math.isfinite(v) else None
    curve = {}
    if "curve" in r.info:  # the fitted input at each target and the distance left there
        c = r.info["curve"]
        fitted = user(key, r.inputs[key])
        if is_angle_name(key):  # within one turn from the sweep's start, not 677 deg
            turn, lo = (360.0 if deg else 2 * math.pi), float(np.min(sc.study.written[key]))
            fitted = lo + np.mod(fitted - lo, turn)
        curve = {"curve": {"point": c["point"], "targets": c["targets"].tolist(),
                           "inputs": {key: _list(fitted)},
                           "distances": _list(c["distances"])}}
    return {
        "title": sc.study.title, "units": sc.study.units, "ok": r.ok, "converged": r.converged,
        "status": r.status, "message": r.message, "problems": r.problems,
        "iterations": r.iterations, "objective": num(r.objective),
        "initial_objective": num(r.initial_objective), "objective_unit": _objective_unit(sc),
        "parameters": r.parameters, "varied": r.varied,
        "initial": {p: sc.mechanism.parameter(p) for p in r.varied},
        "bounds": {p: list(bounds[p]) for p in r.varied},
        "at_bound": {p: side for p in r.varied if (side := _at_bound(r.varied[p], *bounds[p]))},
        "parameter_units": {p: _optimized_unit(sc, p) for p in r.varied},
        "samples": {k: _list(user(k, v)) for k, v in r.inputs.items()},  # the scene's word
        "values": {n: _list(user(n, v)) for n, v in r.values.items()},
        "constraints": [{**{k: c[k] for k in ("expr", "min", "max", "satisfied")},
                         "value": _list(np.atleast_1d(c["value"]))} for c in r.constraints],
        "extremes": [{"kind": e["kind"], "expr": e["expr"], "value": num(e["value"]),
                      "input": {key: num(float(user(key, e["input"])))}} for e in r.extremes],
        **curve,
    }


def _objective_unit(sc) -> str | None:
    """The objective's unit in the scene's units (`kincas.synthesis.dimensions`): that of
    `minimize`, and with a target curve a squared length; None where it cannot be decided."""
    from ..errors import ModelError
    from ..synthesis.dimensions import expression_unit, format_unit, parse_label
    from ..synthesis.expressions import parse

    t = sc.study.raw["optimize"]
    L, angle = sc.study.units.get("length", ""), sc.study.units.get("angle", "deg")
    params = sc.mechanism.param_values

    def label(name):
        if name == "__angle__":
            return angle
        return _optimized_unit(sc, name) if name in params else _unit(sc, name)

    units = []
    if "curve" in t:  # the sum of squared distances to the targets
        units.append(format_unit(parse_label(f"{L}^2")) if L else None)
    if t.get("minimize") is not None:
        data = list((t.get("data") or {}).keys()) if isinstance(t.get("data"), dict) else []
        try:
            units.append(expression_unit(parse(t["minimize"], "minimize", data=data), label))
        except ModelError:
            return None
    return units[0] if len(set(units)) == 1 else None


def _optimized_unit(sc, name: str) -> str:
    """A parameter's unit; for one that only [optimize] uses (a bound such as `peak` in
    `hypot(shaking.x, shaking.y) - peak`), the unit of what its constraints compare it with."""
    if not _only_optimized(sc.study.raw, name):
        return _param_unit(sc, name)
    from ..errors import ModelError
    from ..synthesis.dimensions import term_unit
    from ..synthesis.expressions import parse
    t = sc.study.raw.get("optimize", {})
    data = list(t.get("data") or {}) if isinstance(t.get("data"), dict) else []
    params = sc.mechanism.param_values
    label = lambda n: (sc.study.units.get("angle", "deg") if n == "__angle__" else  # noqa: E731
                       _param_unit(sc, n) if n in params else _unit(sc, n))
    found = set()
    for c in t.get("constraints") or []:
        try:
            u = term_unit(parse(c.get("expr"), "constraint", data=data), name, label)
        except (ModelError, AttributeError, KeyError):
            continue
        if u is not None:
            found.add(u)
    return found.pop() if len(found) == 1 else _param_unit(sc, name)


def _only_optimized(doc: dict, name: str) -> bool:
    """Whether the scene names parameter `name` nowhere but in [parameters] and [optimize]."""
    def uses(v) -> bool:
        if isinstance(v, str):
            return v.lstrip("-") == name
        if isinstance(v, dict):
            return any(uses(x) for x in v.values())
        return isinstance(v, list) and any(uses(x) for x in v)
    return not any(uses(v) for k, v in doc.items() if k not in ("parameters", "optimize", "title", "units"))


def _at_bound(v: float, lo: float, hi: float) -> str | None:
    """"lower" or "upper" when v sits on that bound (to 1e-9 of the range), else None."""
    tol = 1e-9 * max(abs(hi - lo), abs(hi), abs(lo), 1e-300)
    return "lower" if abs(v - lo) <= tol else "upper" if abs(v - hi) <= tol else None


def _print(sc, r: Optimization, doc: dict):
    print(f"{sc.study.title or 'kincas'}: optimisation by IPOPT ({r.status}, "
          f"{r.iterations} iterations)")
    print(r.message)
    for p in r.problems[1:]:
        print(f"  also: {p}")
    unit = f" [{doc['objective_unit']}]" if doc["objective_unit"] else ""
    print(f"objective{unit}: {r.initial_objective:.8g} (initial design) -> {r.objective:.8g}")
    print(f"{'parameter':>12}  {'initial':>14}  {'optimised':>14}  {'low':>10}  {'high':>10}  unit")
    for p, v in r.varied.items():
        lo, hi = doc["bounds"][p]
        side = doc["at_bound"].get(p)
        mark = f"  <- at its {side} bound" if side else ""
        print(f"{p:>12}  {doc['initial'][p]:>14.8g}  {v:>14.8g}  {lo:>10.6g}  {hi:>10.6g}  "
              f"{doc['parameter_units'][p] or '-'}{mark}")
    for c in doc["constraints"]:
        v = [x for x in c["value"] if x is not None]
        shown = f"{v[0]:.8g}" if len(v) == 1 else f"from {min(v):.8g} to {max(v):.8g} over the samples"
        lo, hi = c["min"], c["max"]
        want = (f"= {lo:g}" if lo == hi else f">= {lo:g}" if hi is None else f"<= {hi:g}"
                if lo is None else f"in [{lo:g}, {hi:g}]")
        print(f"constraint {c['expr']} {want}: {shown}, {'holds' if c['satisfied'] else 'VIOLATED'}")
    for e in doc["extremes"]:
        (k, u), = e["input"].items()
        print(f"{e['kind']}({e['expr']}) = {e['value']:.8g} at {k} = {u:.6g}")
    if "curve" in doc:
        c = doc["curve"]
        (k, u), = c["inputs"].items()
        print(f"{'target x':>12}  {'target y':>12}  {k + ' (fitted)':>20}  {'distance':>12}")
        for (x, y), ui, d in zip(c["targets"], u, c["distances"]):
            shown = lambda v, f: format(v, f) if v is not None else "-"
            print(f"{x:>12.6g}  {y:>12.6g}  {shown(ui, '>20.8g')}  {shown(d, '>12.4g')}")
    print("\n[parameters]   # the optimised design" + ("" if r.ok else " (NOT optimal, see above)"))
    for p, v in r.parameters.items():
        print(f"{p} = {v:.12g}")


# --- kincas optimize SCENE.toml --starts N ---


def _multistart_run(sc, args) -> int:
    """`kincas optimize --starts N`: the best distinct optima, each reported as one run is;
    0 when at least one passed every check, 3 otherwise."""
    import dataclasses

    from ..errors import ModelError, OutputError, SceneError
    from ..synthesis.multistart import multistart
    from .scene_optimize import read_section

    if args.starts < 1:
        raise OutputError(f"--starts: expected a whole number >= 1, got {args.starts}")
    if args.seed is not None and args.seed < 0:
        raise OutputError(f"--seed: expected a whole number >= 0, got {args.seed}")
    kw = read_section(sc)
    if "curve" in sc.study.raw.get("optimize", {}):
        raise OutputError("--starts: not with [optimize.curve] (its fitted inputs start from "
                          "the starting design's curve)")
    client = None
    if args.scheduler:
        from ..analysis.executor import connect
        try:
            client = connect(args.scheduler)
        except ImportError:
            raise OutputError("--scheduler: needs dask.distributed (pip install 'kincas[dask]')") from None
        except (OSError, TimeoutError, ValueError) as e:
            raise OutputError(f"--scheduler: cannot connect to {args.scheduler!r}: {e}") from None
    samples, vary = kw.pop("samples"), kw.pop("vary")
    minimize, constraints = kw.pop("minimize"), kw.pop("constraints")
    try:
        r = multistart(sc.mechanism, samples, vary, minimize, constraints, starts=args.starts,
                       seed=args.seed or 0, client=client, rates=sc.study.rates,
                       accelerations=sc.study.accelerations, **kw)
    except ModelError as e:
        raise SceneError([f"[optimize] {p}" for p in e.problems]) from None
    finally:
        if client is not None:
            client.close()
    docs = []
    for o in r.optima:
        i = next(j for j, x in enumerate(r.results) if x is o)
        start = dataclasses.replace(sc, mechanism=sc.mechanism.with_parameters(
            **dict(zip(r.names, map(float, r.starts[i])))))
        docs.append((start, o, report(start, o)))
    passed = sum(1 for x in r.results if not isinstance(x, Exception) and x.ok)
    if args.json:
        json.dump({"starts": r.runs, "seed": args.seed or 0, "passed": passed,
                   "optima": [d for _, _, d in docs]}, sys.stdout, allow_nan=False)
        sys.stdout.write("\n")
    else:
        print(f"{sc.study.title or 'kincas'}: {r.runs} starts in the bounds, {passed} optima "
              f"passed every check, {len(r.optima)} distinct shown (best first)")
        for k, (start, o, d) in enumerate(docs, 1):
            print(f"\n--- optimum {k} ---")
            _print(start, o, d)
    return 0 if r.optima else 3
