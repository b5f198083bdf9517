"""`kincas study SCENE.toml [--out results.nc|.csv|.parquet] [--plot map.png]`.

Reads the scene's `[study]` section (docs/scene-format.md): `vary` (parameter -> [low, high]),
`grid` (values per parameter) or `samples` (a Latin hypercube) with `seed`, and `report`
(expressions in the `[optimize]` language). Writes one row per design: a column per varied
parameter, `status`, a column per report expression named exactly as written (NetCDF: the
same as variables along a dimension `design`). Angles in the scene's unit. Runs on every
local core, or on the Dask cluster at `--scheduler ADDRESS`; `--backend jax` sweeps the designs
in JAX (kincas/core/jax_backend.py).

Exit status: 0 when every design was solved at every pose, 3 when some were not, 2 when the
scene, the `[study]` section or an option is wrong (one line naming it).

>>> sorted(FIELDS)
['grid', 'report', 'samples', 'seed', 'vary']
"""
from __future__ import annotations

import csv
import math
import sys
from pathlib import Path

import numpy as np

from ..errors import ModelError, OutputError, SceneError
from ..synthesis.study import FIELDS, Study, parse_report, study

FORMATS = (".nc", ".csv", ".parquet")


# --- the [study] section ---


def read_section(sc) -> dict:
    """`[study]` as keywords of `kincas.study`; SceneError naming every wrong field."""
    t = sc.study.raw.get("study")
    if not isinstance(t, dict):
        raise SceneError("[study]: missing or not a table (give vary = { PARAMETER = [low, high] }, "
                         "grid = [n, ...] or samples = N, and report = [\"EXPRESSION\", ...])")
    m = sc.mechanism
    problems = [f"[study]: unknown field {k!r} (expected one of {sorted(FIELDS)})"
                for k in t if k not in FIELDS]
    vary = t.get("vary")
    driven = {i.target for i in m.inputs if i.kind == "parameter"}
    ranges = {}
    if not isinstance(vary, dict) or not vary:
        problems.append("[study] vary: expected a table of PARAMETER = [low, high]")
    else:
        for k, v in vary.items():
            if k not in m.param_values:
                problems.append(f"[study] vary: {k}: unknown parameter (declare it in [parameters])")
            elif k in driven:
                problems.append(f"[study] vary: {k}: driven by an input, so it cannot vary by design")
            elif not (isinstance(v, list) and len(v) == 2 and all(_num(x) for x in v) and v[0] <= v[1]):
                problems.append(f"[study] vary: {k}: expected [low, high], two finite numbers "
                                f"with low <= high, got {v!r}")
            else:
                ranges[k] = (float(v[0]), float(v[1]))
    grid, samples, seed = t.get("grid"), t.get("samples"), t.get("seed", 0)
    if (grid is None) == (samples is None):
        problems.append("[study] grid, samples: give exactly one (grid = [values per parameter] "
                        "or samples = N for a Latin hypercube)")
    if grid is not None and not (isinstance(grid, list) and all(_whole(g, 1) for g in grid)
                                 and isinstance(vary, dict) and len(grid) == len(vary)):
        n = len(vary) if isinstance(vary, dict) else "each"
        problems.append(f"[study] grid: expected a whole number >= 1 for {n} varied parameter(s) "
                        f"(in vary's order), got {grid!r}")
    if samples is not None and not _whole(samples, 1):
        problems.append(f"[study] samples: expected a whole number >= 1, got {samples!r}")
    if not _whole(seed, 0):
        problems.append(f"[study] seed: expected a whole number >= 0, got {seed!r}")
    report = t.get("report")
    if report is None:
        problems.append("[study] report: missing (a list of expressions, e.g. [\"max(C.y)\"])")
    else:
        try:
            parse_report(m, report, "[study] report")
        except ModelError as e:
            problems += e.problems
    if problems:
        raise SceneError(problems)
    return {"vary": ranges, "grid": grid, "samples": samples, "seed": seed, "report": list(report)}


def _num(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _whole(x, lo) -> bool:
    return isinstance(x, int) and not isinstance(x, bool) and x >= lo


# --- the command ---


def cli_arguments(parser) -> None:
    """Arguments of `kincas study`."""
    parser.add_argument("scene", help="the scene file (TOML) with a [study] section")
    parser.add_argument("--out", metavar="OUT", help="write one row per design: .nc (NetCDF), .csv or .parquet")
    parser.add_argument("--plot", metavar="MAP.png", help="a map of the report over the first two varied parameters")
    parser.add_argument("--scheduler", metavar="ADDRESS", help="run on the Dask cluster at this scheduler address")
    parser.add_argument("--workers", type=int, metavar="N", help="local threads (default: every core)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument("--backend", choices=("casadi", "jax"), default="casadi",
                        help="the designs' fast pass: casadi's compiled kernel (default) or JAX "
                             "(pip install 'kincas[gpu]'; a GPU where JAX has one)")


def cli_run(args) -> int:
    """Run `kincas study`: 0 when every design was solved, 3 otherwise."""
    from .common import progress_for
    from .scene import load

    sc = load(args.scene)
    kw = read_section(sc)
    _check_size(sc, kw, args.workers)
    if args.out and Path(args.out).suffix.lower() not in FORMATS:
        raise OutputError(f"--out: {args.out!r}: expected a file ending in {', '.join(FORMATS)}")
    if args.out:
        _check_writer(Path(args.out).suffix.lower())
    if args.plot:
        from ..views.mapplot import check_plot
        check_plot(args.plot, kw["vary"])
    if args.workers is not None and args.workers < 1:
        raise OutputError(f"--workers: expected a whole number >= 1, got {args.workers}")
    if args.backend == "jax" and not (_has("jax") and _has("jaxadi")):
        raise OutputError("--backend jax: needs jax and jaxadi (pip install 'kincas[gpu]')")
    client = _client(args.scheduler) if args.scheduler else None
    st = sc.study
    sc.refuse_jerks(kw["report"], "[study] report")
    try:
        r = study(sc.mechanism, kw["vary"], st.inputs, kw["report"], grid=kw["grid"],
                  designs=kw["samples"], seed=kw["seed"], rates=st.rates,
                  accelerations=st.accelerations, degrees=st.deg, client=client,
                  workers=args.workers, progress=progress_for(args), backend=args.backend)
    finally:
        if client is not None:
            client.close()
    if args.out:
        write(r, args.out)
    if args.plot:
        from ..views.mapplot import plot_map
        plot_map(r, args.plot, title=st.title, units=_map_units(sc, r))
    _summary(st.title, r, args.out, args.plot)
    return 0 if all(s == "ok" for s in r.status) else 3


def _map_units(sc, r) -> dict:
    """The unit of each varied parameter and report expression, for the map's axes and colour
    bars (kincas.synthesis.dimensions; left out where it cannot be decided)."""
    from ..errors import ModelError
    from ..synthesis.dimensions import expression_unit
    from ..synthesis.expressions import parse
    from .common import _param_unit, _unit
    params = sc.mechanism.param_values
    label = lambda n: (sc.study.units.get("angle", "deg") if n == "__angle__" else  # noqa: E731
                       _param_unit(sc, n) if n in params else _unit(sc, n))
    out = {p: _param_unit(sc, p) for p in r.names}
    for text in r.report:
        try:
            out[text] = expression_unit(parse(text, "report"), label)
        except ModelError:
            out[text] = None
    return out


def _check_size(sc, kw, workers) -> None:
    """Refuse, before any design is made, a study that would not fit in memory (one line
    naming the grid or the samples, the memory, and the ways round)."""
    from . import bounds
    from ..analysis.executor import default_workers
    from ..model.mechanism import solved_unknowns
    from ..synthesis.expressions import parse
    grid, n = kw["grid"], kw["samples"]
    designs = math.prod(grid) if grid is not None else n
    field = f"[study] grid = {grid}" if grid is not None else f"[study] samples = {n}"
    poses = max((len(v) for v in sc.study.inputs.values()), default=1)
    wanted = {q for t in kw["report"] for q in parse(t, "report").quantities}
    need = bounds.study_bytes(designs, poses, solved_unknowns(sc.mechanism), len(wanted),
                              len(kw["vary"]), len(kw["report"]), workers or default_workers())
    try:
        bounds.check_total(f"{field} ({designs:,} designs x {poses} poses)", need,
                           "use fewer designs or poses")
    except ValueError as e:
        raise OutputError(str(e)) from None


def _client(address):
    try:
        from ..analysis.executor import connect
        return connect(address)
    except ImportError:
        raise OutputError("--scheduler: needs dask.distributed (pip install 'kincas[dask]')") from None
    except (OSError, TimeoutError, ValueError) as e:
        raise OutputError(f"--scheduler: cannot connect to {address!r}: {e}") from None


def _summary(title, r: Study, out, plot=None):
    ok = int(r.ok.sum())
    print(f"{title or 'kincas'}: study of {len(r.status)} designs over {', '.join(r.names)}: "
          f"{ok} solved at every pose, {len(r.status) - ok} not")
    for t in r.report:
        v = r.values[t][r.ok]
        if len(v) and np.isfinite(v).any():
            print(f"  {t}: from {np.nanmin(v):.6g} to {np.nanmax(v):.6g}")
        else:
            print(f"  {t}: no value (no design solved)")
    for path in (out, plot):
        if path:
            print(f"wrote {path}")


# --- writing the rows ---


def _check_writer(suffix):
    """Fail before a long study when the output's optional package is missing."""
    need = {".nc": ["xarray"], ".parquet": ["pyarrow", "pandas"]}.get(suffix, [])
    if need and not any(_has(p) for p in need):
        extra = "data"
        raise OutputError(f"--out: writing {suffix} needs {' or '.join(need)} "
                          f"(pip install 'kincas[{extra}]')")


def _has(mod) -> bool:
    import importlib.util
    return importlib.util.find_spec(mod) is not None


def write(r: Study, path) -> None:
    """Write the study's rows to .nc, .csv or .parquet (chosen by the suffix)."""
    from ..views.atomic import replacing
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise OutputError(f"--out: {str(path)!r}: expected a file ending in {', '.join(FORMATS)}")
    try:
        with replacing(path) as tmp:  # whole or not at all (kincas/views/atomic.py)
            if suffix == ".csv":
                _write_csv(r, tmp)
            elif suffix == ".parquet":
                _write_parquet(r, tmp)
            else:
                ds = r.to_xarray()
                engine = "netcdf4" if _has("netCDF4") else "h5netcdf" if _has("h5netcdf") else "scipy"
                ds.to_netcdf(tmp, engine=engine)
    except OSError as e:
        raise OutputError(f"--out: cannot write {str(path)!r}: {e.strerror or e}") from None


def _write_csv(r: Study, path):
    cols = r.columns()
    with open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(list(cols))
        for i in range(len(r.status)):
            w.writerow([c[i] if k == "status" else ("" if not math.isfinite(c[i]) else repr(float(c[i])))
                        for k, c in cols.items()])


def _write_parquet(r: Study, path):
    cols = r.columns()
    cols["status"] = [str(s) for s in cols["status"]]
    if _has("pyarrow"):
        import pyarrow as pa
        import pyarrow.parquet as pq
        arrays = {k: pa.array(v, from_pandas=True) if k != "status" else pa.array(v)
                  for k, v in cols.items()}
        pq.write_table(pa.table(arrays), path)
    else:
        r.to_pandas().to_parquet(path)
