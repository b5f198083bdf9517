"""Design studies: many designs of one mechanism, one row of results per design.

`study(m, vary, inputs, report)` makes designs from ranges of some parameters (`grid`: a full
grid; `designs`: a Latin hypercube, one design in each of `designs` equal strata of every
range, with a seed; the scene's `[study] samples`), sweeps each over the inputs on the branch of m's guess
(`kincas.sweep_designs`), and evaluates the `report` expressions over each design's sweep.
The expressions are those of `[optimize]` (kincas.synthesis.expressions), evaluated on the
swept poses: `max(E)` and `min(E)` are the extremes over the poses of the sweep, `sum` and
`mean` over the poses; each must give one number per design. A design that is not solved at
every pose gets NaN values and a status saying why ("no assembly at crank.angle = 212 deg").

The designs are cut into chunks that run on local threads (every core by default) or, with
`client=` a `dask.distributed.Client`, as tasks on its cluster (`kincas.analysis.executor`):
a chunk's designs give the same numbers wherever it runs.

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(parameters={"a": 1.0, "d": 4.0}, ground={"A": (0, 0), "D": ("d", 0)},
...     links=[kincas.Link.bar("crank", "A", "B", "a"), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
>>> r = kincas.study(m, {"a": (0.9, 1.1), "d": (3.9, 4.1)},
...                  {"crank.angle": np.linspace(0, 2 * np.pi, 61)},
...                  ["max(rocker.angle) - min(rocker.angle)"], grid=(3, 2))
>>> r.params.shape, r.status[:2], bool(np.all(r.values["max(rocker.angle) - min(rocker.angle)"] > 0))
((6, 2), ['ok', 'ok'], True)
"""
from __future__ import annotations

import ast
import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..model.mechanism import Mechanism
from .._deprecated import keyword, renamed
from ..result_base import Result
from .expressions import AGGREGATE, CONST, SAMPLE, TOTAL, parse, quantity_name
from ..model.names import is_angle_name

FIELDS = {"vary", "grid", "samples", "seed", "report"}


# --- the designs: a full grid or a Latin hypercube ---


def grid_designs(ranges: list[tuple[float, float]], counts: list[int]) -> np.ndarray:
    """Every combination of `counts[j]` equally spaced values over each range (the first
    parameter varies slowest), as an (prod(counts), len(ranges)) table.

    >>> grid_designs([(0, 1), (10, 20)], [2, 3]).tolist()
    [[0.0, 10.0], [0.0, 15.0], [0.0, 20.0], [1.0, 10.0], [1.0, 15.0], [1.0, 20.0]]
    """
    axes = [np.linspace(lo, hi, c) for (lo, hi), c in zip(ranges, counts)]
    return np.stack([a.ravel() for a in np.meshgrid(*axes, indexing="ij")], axis=1)


def latin_hypercube(ranges: list[tuple[float, float]], samples: int, seed=0) -> np.ndarray:
    """`samples` designs with exactly one in each of `samples` equal strata of every range
    (a random permutation of the strata per parameter, a uniform point within each).

    >>> x = latin_hypercube([(0, 1)], 4, seed=1)
    >>> sorted(np.floor(x[:, 0] * 4).astype(int).tolist())
    [0, 1, 2, 3]
    """
    rng = np.random.default_rng(seed)
    k = len(ranges)
    u = (np.stack([rng.permutation(samples) for _ in range(k)], axis=1)
         + rng.random((samples, k))) / samples
    lo, hi = np.array(ranges, dtype=float).T.reshape(2, -1) if k else (np.zeros(0), np.zeros(0))
    return lo + u * (hi - lo)


# --- expressions over a sweep, numerically ---


def evaluate(e, quantities: dict, params: dict, angle: float = 1.0):
    """(kind, value) of a parsed expression (`kincas.synthesis.expressions.parse`) over
    designs x poses: `quantities` name -> (n_designs, n_poses) arrays in the caller's units,
    `params` name -> (n_designs,) values; aggregates reduce over the poses. `angle` is the
    caller's angle unit in radians (trigonometric functions convert through it)."""

    def ev(node):
        if isinstance(node, ast.Constant):
            return CONST, float(node.value)
        if isinstance(node, ast.Attribute):
            return SAMPLE, quantities[quantity_name(node)]
        if isinstance(node, ast.Name):
            if node.id == "pi":
                return CONST, math.pi
            return CONST, np.asarray(params[node.id], dtype=float)[:, None]
        if isinstance(node, ast.UnaryOp):
            k, v = ev(node.operand)
            return k, (-v if isinstance(node.op, ast.USub) else v)
        if isinstance(node, ast.BinOp):
            (ka, a), (kb, b) = ev(node.left), ev(node.right)
            k = _join(ka, kb, e, ast.unparse(node))
            op = type(node.op)
            with np.errstate(all="ignore"):
                return k, {ast.Add: np.add, ast.Sub: np.subtract, ast.Mult: np.multiply,
                           ast.Div: np.divide, ast.Pow: np.power}[op](a, b)
        f = node.func.id
        if f in AGGREGATE:
            k, v = ev(node.args[0])
            if k == TOTAL:
                raise ModelError(f"{e.where}: {f}() of a total")
            v = np.asarray(v, dtype=float)
            red = {"sum": np.sum, "mean": np.mean, "max": np.max, "min": np.min}[f]
            return TOTAL, red(v, axis=1, keepdims=True) if v.ndim == 2 and v.shape[1] else v
        args = [ev(a) for a in node.args]
        with np.errstate(all="ignore"):
            if len(args) == 2:
                k = _join(args[0][0], args[1][0], e, ast.unparse(node))
                a, b = args[0][1], args[1][1]
                return k, (np.hypot(a, b) if f == "hypot" else np.arctan2(a, b) / angle)
            k, a = args[0]
            if f in ("sin", "cos", "tan"):
                return k, getattr(np, f)(np.multiply(a, angle))
            if f in ("asin", "acos", "atan"):
                return k, {"asin": np.arcsin, "acos": np.arccos, "atan": np.arctan}[f](a) / angle
            return k, {"sqrt": np.sqrt, "exp": np.exp, "log": np.log, "abs": np.abs}[f](a)
    return ev(e.tree)


def _join(ka, kb, e, text):
    if {ka, kb} == {SAMPLE, TOTAL}:
        raise ModelError(f"{e.where}: {text!r} mixes values per sample with totals "
                         f"(wrap the per-sample part in sum(), mean(), max() or min())")
    return TOTAL if TOTAL in (ka, kb) else SAMPLE if SAMPLE in (ka, kb) else CONST


def parse_report(m: Mechanism, report, where: str = "report") -> list:
    """Parsed report expressions; ModelError naming `where` for any that cannot give one
    number per design (unknown names, values per pose left outside an aggregate)."""
    from ..core.numeric import compile

    out, problems = [], []
    if isinstance(report, str) or not isinstance(report, (list, tuple)) or not report:
        raise ModelError(f"{where}: expected a list of expressions")
    sym = compile(m)
    for text in report:
        try:
            e = parse(text, f"{where}: {text!r}")
        except ModelError as err:
            problems += err.problems
            continue
        problems += sym.check_names(e.quantities, where)
        problems += [f"{where}: {text!r}: {n!r} is not a parameter" for n in e.names
                     if n not in m.param_values]
        out.append(e)
    if problems:
        raise ModelError(problems)
    fake = {q: np.zeros((1, 2)) for e in out for q in e.quantities}
    pars = {k: np.zeros(1) for k in m.param_values}
    for e in out:
        kind, _ = evaluate(e, fake, pars)
        if kind == SAMPLE:
            problems.append(f"{where}: {e.text!r} has a value per pose, not one per design "
                            f"(wrap it in max(), min(), sum() or mean())")
    if problems:
        raise ModelError(problems)
    return out


# --- the study ---


@dataclass(repr=False)
class Study(Result):
    """One row per design: `params` (n_designs, len(names)) the varied values, `status`
    ("ok", or why the design failed), `values[text]` one number per design per report
    expression (NaN where the design failed)."""

    names: list[str]
    params: np.ndarray
    status: list[str]
    report: list[str]
    values: dict[str, np.ndarray]

    @property
    def ok(self) -> np.ndarray:
        return np.array([s == "ok" for s in self.status], dtype=bool)

    def columns(self) -> dict[str, np.ndarray]:
        """Column name -> values: each varied parameter, `status`, each report expression."""
        cols = {n: self.params[:, j] for j, n in enumerate(self.names)}
        cols["status"] = np.array(self.status, dtype=object)
        cols.update(self.values)
        return cols

    def summary(self) -> str:
        """Designs solved, varied parameters, report expressions (the `repr`'s body)."""
        return (f"{len(self.status)} designs, {int(self.ok.sum())} ok; varied "
                f"{', '.join(self.names) or 'none'}; report {', '.join(self.report) or 'none'}")

    def to_xarray(self, length: str = "", angle: str = "rad"):
        """An xarray Dataset along the dimension `design` (`length`: the unit of lengths,
        recorded in the varied parameters' units)."""
        from ..frames import study_to_xarray, in_angle
        return in_angle(study_to_xarray(self, length), angle)

    def to_pandas(self, length: str = "", angle: str = "rad"):
        """A pandas DataFrame, one row per design; the varied parameters' units in
        `df.attrs["units"]` (`length` names the unit of lengths)."""
        from ..frames import study_to_pandas, in_angle
        return in_angle(study_to_pandas(self, length), angle)


@dataclass
class _Chunk:
    """What every chunk of a study needs (sent to each task: keep it small)."""

    m: Mechanism
    names: list[str]
    inputs: dict
    rates: dict | None
    accelerations: dict | None
    report: list[str]
    angle: float
    compile: bool | None
    backend: str = "casadi"

    def __call__(self, part):
        """(design indices, failure code and pose per design, values (n, len(report)))."""
        from ..analysis.designs import sweep_designs
        from ..model.names import is_angular

        idx, X = part
        exprs = [parse(t, "report") for t in self.report]
        wanted = list(dict.fromkeys(q for e in exprs for q in e.quantities))
        r = sweep_designs(self.m, X, self.inputs, names=self.names, rates=self.rates,
                          accelerations=self.accelerations, report=wanted, workers=1,
                          compile=self.compile, backend=self.backend)
        ok = r.design_ok
        code, pose = np.zeros(len(idx), dtype=int), np.full(len(idx), -1)
        for d in np.flatnonzero(~ok):
            bad = int(np.flatnonzero(r.code[d] != 0)[0])
            code[d], pose[d] = r.code[d, bad], bad
        q = {n: (r.values[n] / self.angle if is_angular(n) else r.values[n]) for n in wanted}
        pars = {**{k: np.full(len(idx), v) for k, v in self.m.parameters},
                **{n: X[:, j] for j, n in enumerate(self.names)}}
        vals = np.full((len(idx), len(exprs)), np.nan)
        for j, e in enumerate(exprs):
            v = evaluate(e, q, pars, self.angle)[1]
            vals[:, j] = np.broadcast_to(np.asarray(v, dtype=float), (len(idx), 1))[:, 0]
        vals[~ok] = np.nan
        return idx, code, pose, vals


def study(m: Mechanism, vary: dict, inputs, report, *, grid=None, designs=None, seed=0,
          rates=None, accelerations=None, degrees: bool = False, client=None,
          workers: int | None = None, chunk: int | None = None, compile: bool | None = None,
          progress=None, backend: str = "casadi", samples=None) -> Study:
    """Sweep many designs of `m` and evaluate `report` over each (see the module's text).

    Parameters
    ----------
    m : Mechanism
        The nominal design (its guess picks the branch; other parameters keep their values).
    vary : dict
        parameter name -> (low, high).
    inputs, rates, accelerations
        As for `kincas.sweep`.
    report : list of str
        Expressions in the `[optimize]` language, each one number per design.
    grid : sequence of int, optional
        Values per parameter of a full grid; or:
    designs : int, optional
        How many designs, drawn as a Latin hypercube (with `seed`).
    degrees : bool
        Quantities, trigonometric functions and input values in the messages in degrees.
    client : dask.distributed.Client, optional
        Run the chunks on its cluster; else on `workers` local threads (default: all cores).
    chunk : int, optional
        Designs per chunk (default: one per local thread, at most 2,048 designs; on a
        cluster about four chunks per worker, at most 512 designs; with the JAX backend, up
        to 4096 designs a chunk).
    backend : {"casadi", "jax"}
        The designs' fast pass, as for `kincas.sweep_designs`.
    samples : int, optional
        Deprecated name of `designs` (kincas 0.1; a DeprecationWarning). A scene's
        `[study] samples` is unchanged.

    Returns
    -------
    Study

    Examples
    --------
    The rocker's swing of a crank-rocker, from the crank and coupler in line (|AC| = 3.5 -+ a,
    the law of cosines in triangle ADC); the study takes max and min over its 61 poses:

    >>> import numpy as np, kincas
    >>> m = kincas.Mechanism(parameters={"a": 1.0}, ground={"A": (0, 0), "D": (4, 0)},
    ...     links=[kincas.Link.bar("crank", "A", "B", "a"), kincas.Link.bar("coupler", "B", "C", 3.5),
    ...            kincas.Link.bar("rocker", "D", "C", 3)],
    ...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
    >>> r = study(m, {"a": (0.9, 1.1)}, {"crank.angle": np.linspace(0, 2 * np.pi, 61)},
    ...           ["max(rocker.angle) - min(rocker.angle)"], grid=(2,))
    >>> phi = lambda e: np.arccos((16 + 9 - e ** 2) / 24)
    >>> swing = [phi(3.5 + a) - phi(3.5 - a) for a in (0.9, 1.1)]
    >>> r.status, bool(np.allclose(r.values["max(rocker.angle) - min(rocker.angle)"], swing, atol=1e-3))
    (['ok', 'ok'], True)
    """
    from ..analysis.designs import STATUS, design_table
    from ..analysis.executor import default_workers, run_chunks
    from ..analysis.sweeps import _input_table

    names = list(vary)
    ranges = [tuple(float(x) for x in vary[k]) for k in names]
    designs = keyword("study", "samples", "designs", samples, designs)
    if (grid is None) == (designs is None):
        raise ModelError("give either grid (values per parameter) or designs (a count, for a Latin hypercube)")
    if grid is not None:
        X = grid_designs(ranges, list(grid))
    else:
        X = latin_hypercube(ranges, int(designs), seed)
    design_table(m, X, names)  # names checked
    parse_report(m, report)
    U = _input_table(m, inputs, "inputs", None)
    nd = len(X)
    w = default_workers() if workers is None else workers
    # On a cluster about four chunks per worker (retries lose little); on local threads one
    # per thread up to 2,048 designs: each chunk's designs go in one compiled call, and a
    # thread back from C waits for the GIL while another runs Python, so fewer is faster.
    size = chunk or (max(1, min(512, math.ceil(nd / (4 * w)))) if client is not None
                     else max(1, min(2048, math.ceil(nd / w))))
    if backend == "jax" and not chunk:  # one vmapped call does many designs: few large chunks
        size = max(1, min(4096, math.ceil(nd / w)))
    parts = [(np.arange(a, min(a + size, nd)), X[a:a + size]) for a in range(0, nd, size)]
    job = _Chunk(m, names, inputs, rates, accelerations, list(report),
                 math.pi / 180 if degrees else 1.0, compile, backend)
    out = run_chunks(job, parts, client=client, workers=w, progress=progress)
    idx = np.concatenate([o[0] for o in out]) if out else np.zeros(0, int)
    if not np.array_equal(idx, np.arange(nd)):  # every design exactly once, in order
        raise RuntimeError("study: the chunks' results do not cover the designs exactly once")
    code = np.concatenate([o[1] for o in out]) if out else np.zeros(0, int)
    pose = np.concatenate([o[2] for o in out]) if out else np.zeros(0, int)
    vals = np.concatenate([o[3] for o in out]) if out else np.zeros((0, len(report)))
    keys = [i.key for i in m.inputs]
    status = []
    for c, k in zip(code, pose):
        if c == 0:
            status.append("ok")
            continue
        at = ", ".join(f"{key} = {_user(U[k, j], key, degrees):.6g}" for j, key in enumerate(keys))
        status.append(f"{STATUS[c]} at {at}" if at else STATUS[c])
    return Study(names=names, params=X, status=status, report=list(report),
                       values={t: vals[:, j] for j, t in enumerate(report)})


def _user(v, key, degrees):
    return math.degrees(v) if degrees and is_angle_name(key) else float(v)


# the name of 0.1 (results are named by what they hold, as Sweep and Pose are)
__getattr__ = renamed(globals(), {'StudyResult': 'Study'}, 'kincas.synthesis.study')
