"""`kincas tolerance SCENE.toml`: first-order and Monte-Carlo spread of the outputs from the
scene's [tolerance] section (read here; kincas/analysis/tolerance.py does the work)."""
from __future__ import annotations

import json
import math
import sys

import numpy as np

from ..analysis.tolerance import ToleranceAnalysis, analyse, check_std
from ..core.numeric import model_of
from ..errors import SceneError
from ..model.names import is_angular, parse_quantity
from .common import _list, _unit, progress_for
from .scene import load


def cli_arguments(parser) -> None:
    """Arguments of `kincas tolerance`."""
    parser.add_argument("scene", help="the scene file (TOML) with a [tolerance] section")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--draws", type=int, help="Monte-Carlo draws (overrides the scene's [tolerance] samples)")
    parser.add_argument("--samples", type=int, help="old name of --draws (deprecated)")
    parser.add_argument("--seed", type=int, help="random seed (overrides the scene)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


def cli_run(args) -> int:
    """Run `kincas tolerance`: 0 when every pose and sample was solved, 3 otherwise."""
    sc = load(args.scene)
    kw = read_section(sc)
    flag, n = draws_option(args)
    if flag is not None:
        kw["samples"] = n
    if args.seed is not None:
        kw["seed"] = args.seed
    if kw["samples"] < 2:
        raise SceneError(f"{flag or '[tolerance] samples'}: expected a whole number >= 2, got {kw['samples']}")
    st = sc.study
    sc.refuse_jerks(sc.quantities, "[tolerance]")
    kw["draws"] = kw.pop("samples")  # the scene's `[tolerance] samples`: analyse's draws
    r = analyse(sc.mechanism, st.inputs, rates=st.rates, accelerations=st.accelerations,
                progress=progress_for(args), **kw)
    user = lambda n, v: np.degrees(v) if is_angular(n, sc.mechanism) and st.deg else np.asarray(v, float)
    inputs = {k: user(k, v) for k, v in r.inputs.items()}
    from ..views.numbers import snap  # a spread that is zero to rounding is printed as 0
    fo = {n: snap(user(n, r.first_order[n]), 0.0) for n in r.names}
    mc = {n: snap(user(n, r.monte_carlo[n]), 0.0) for n in r.names}
    if args.json:
        doc = {"title": st.title, "units": st.units, "samples": r.draws, "seed": r.seed,
               "std": r.std, "inputs": {k: _list(v) for k, v in inputs.items()},
               "status": [str(s) for s in r.status], "failed": r.failed.tolist(),
               "nominal": {n: _list(user(n, r.nominal[n])) for n in r.names},
               "first_order": {n: _list(v) for n, v in fo.items()},
               "monte_carlo": {n: _list(v) for n, v in mc.items()},
               "agreement": {n: _list(v) for n, v in r.agreement.items()},
               "standard_error": r.standard_error, "agrees": r.agrees()}
        json.dump(doc, sys.stdout, allow_nan=False)
        sys.stdout.write("\n")
    else:
        _print(sc, r, inputs, fo, mc, lambda n: _unit(sc, n))
    unsolved = any(s != "ok" for s in r.status) or int(r.failed.sum()) > 0
    return 3 if unsolved else 0


def draws_option(args, note: bool = True):
    """(the option given, its value) for the count of Monte-Carlo draws: `--draws`, or its
    old name `--samples` (with a note on stderr that it goes in the next release); (None,
    None) where neither was given. Both given: SceneError."""
    draws, samples = getattr(args, "draws", None), getattr(args, "samples", None)
    if draws is not None and samples is not None:
        raise SceneError("--draws, --samples: give one (--samples is the old name of --draws)")
    if samples is not None and note:
        print("kincas: --samples is deprecated: use --draws (the old option goes in the next release)",
              file=sys.stderr)
    if samples is not None:
        return "--samples", samples
    return ("--draws", draws) if draws is not None else (None, None)


def _print(sc, r: ToleranceAnalysis, inputs, fo, mc, unit):
    stds = ", ".join(f"{p} {s:g}" for p, s in r.std.items())
    print(f"{sc.study.title or 'kincas'}: tolerance analysis, {r.draws} samples (seed {r.seed})")
    print(f"standard deviations: {stds}")
    print("first-order std (exact sensitivities) and Monte-Carlo std, per pose:")
    cols = [(k, v, unit(k)) for k, v in inputs.items()]
    for n in r.names:
        cols += [(f"std {n}", fo[n], unit(n)), (f"mc {n}", mc[n], unit(n))]
    heads = [f"{h} [{u}]" if u else h for h, _, u in cols]
    width = [max(12, len(h)) for h in heads]
    print("  ".join(h.rjust(w) for h, w in zip(heads, width)) + "  failed")
    for i in range(len(r.status)):
        cells = [("-" if not math.isfinite(v[i]) else f"{v[i]:.6g}").rjust(w)
                 for (_, v, _), w in zip(cols, width)]
        tail = f"  {r.failed[i]}" if r.status[i] == "ok" else f"  ({r.status[i]})"
        print("  ".join(cells) + tail)
    verdict = "agree" if r.agrees() else "differ (the outputs are not linear over the tolerances)"
    print(f"Monte Carlo and first order {verdict}: sampling error {100 * r.standard_error:.2g} %; "
          f"{int(r.failed.sum())} sample poses did not assemble on the nominal branch")


def read_section(sc) -> dict:
    """The `[tolerance]` section as analyse()'s keywords; SceneError naming the field."""
    t = sc.study.raw.get("tolerance")
    if not isinstance(t, dict):
        raise SceneError("[tolerance]: missing or not a table (give at least "
                         "std = { PARAMETER = standard deviation, ... })")
    problems = [f"[tolerance]: unknown field {k!r} (expected one of "
                f"['report', 'samples', 'seed', 'std'])" for k in t
                if k not in ("std", "samples", "seed", "report")]
    if "std" not in t:
        problems.append("[tolerance] std: missing (std = { PARAMETER = standard deviation, ... })")
    else:
        problems += check_std(sc.mechanism, t["std"], "[tolerance] std")
    samples, seed = t.get("samples", 2000), t.get("seed", 0)
    for k, v, lo in (("samples", samples, 2), ("seed", seed, 0)):
        if isinstance(v, bool) or not isinstance(v, int) or v < lo:
            problems.append(f"[tolerance] {k}: expected a whole number >= {lo}, got {v!r}")
    report = t.get("report", [n for n in sc.study.report if parse_quantity(n)[0] != "sens"])
    if not isinstance(report, list) or not all(isinstance(n, str) for n in report):
        problems.append("[tolerance] report: expected a list of quantity names")
    else:
        problems += model_of(sc.mechanism, check=False).check_names(report, "[tolerance] report")
        problems += [f"[tolerance] report: {n!r}: a sensitivity has no spread to analyse"
                     for n in report if parse_quantity(n)[0] == "sens"]
    if problems:
        raise SceneError(problems)
    return {"std": {k: float(v) for k, v in t["std"].items()}, "samples": samples,
            "seed": seed, "report": report}
