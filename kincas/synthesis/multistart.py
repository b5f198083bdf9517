"""Multistart synthesis: the same optimisation from many starting designs, best optima kept.

IPOPT finds a local optimum near its start. `multistart(m, inputs, vary, ...)` draws
`starts` starting designs in the bounds of `vary` (a Latin hypercube: one start in each of
`starts` strata of every range, from `seed`), runs `kincas.optimize` from each (every answer
checked as a single run checks it: assembly at every sample on the start's branch, the path
between samples), through the executor of studies (`kincas.analysis.executor`: one process's
threads, or a Dask cluster with `client=`), and returns the distinct optima that passed their
checks, best first. Two optima are the same when every varied parameter agrees to `same`
times its range.

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(parameters={"d": 4.0}, ground={"A": (0, 0), "D": ("d", 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
>>> r = multistart(m, {"crank.angle": np.array([0.5])}, {"d": (2.0, 6.0)},
...                "sum((C.y - 2.9)^2)", starts=6, seed=0)
>>> r.runs, len(r.optima), sorted(round(o.varied["d"], 4) for o in r.optima)
(6, 2, [2.6375, 4.1737])
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError
from ..model.mechanism import Mechanism
from .._deprecated import keyword, renamed
from ..result_base import Result
from .study import latin_hypercube

SAME = 1e-4  # optima closer than this fraction of every range are one optimum


@dataclass(repr=False)
class Multistart(Result):
    """`optima`: distinct optima that passed every check, best (lowest objective) first;
    `results`: every start's `Optimization`, in the starts' order; `starts`: the starting
    values (n_starts, len(vary))."""

    optima: list
    results: list
    starts: np.ndarray
    names: list[str] = field(default_factory=list)

    @property
    def best(self):
        """The best optimum, or None when no start gave a trustworthy one."""
        return self.optima[0] if self.optima else None

    @property
    def runs(self) -> int:
        return len(self.results)

    @property
    def ok(self) -> bool:
        """Whether some start gave a trustworthy optimum."""
        return bool(self.optima)

    def summary(self) -> str:
        """Starts, distinct optima, the best objective (the `repr`'s body)."""
        best = f"; best objective {self.best.objective:.6g}" if self.best is not None else ""
        return f"{self.runs} starts, {len(self.optima)} distinct optima{best}"

    def to_pandas(self, length: str = "", angle: str = "rad"):
        """A DataFrame, one row per start: its starting values, `objective`, `ok`, `status`
        and the varied parameters it reached (`length`: the unit of lengths, in the units)."""
        from ..frames import multistart_to_pandas, in_angle
        return in_angle(multistart_to_pandas(self, length), angle)

    def to_xarray(self, length: str = "", angle: str = "rad"):
        """A Dataset along `start`, the columns of `to_pandas`."""
        return self.to_pandas(length, angle).to_xarray()


@dataclass
class _Start:
    """One start's optimisation (sent to a worker: small and picklable)."""

    m: Mechanism
    names: list[str]
    samples: object
    kw: dict

    def __call__(self, x):
        from .optimize import optimize

        start = self.m.with_parameters(**dict(zip(self.names, map(float, x))))
        try:
            return start, optimize(start, self.samples, **self.kw)
        except Exception as e:  # a start that cannot even be posed is one failed start
            return start, e


def multistart(m: Mechanism, inputs=None, vary: dict | None = None, minimize: str | None = None,
               constraints=(), *, starts: int = 8, seed=0, keep: int = 3, same: float = SAME,
               client=None, workers: int | None = 1, progress=None, samples=None,
               **kw) -> Multistart:
    """Optimise from `starts` designs drawn in the bounds (see the module's text); `kw` are
    `kincas.optimize`'s keywords. `workers` defaults to 1: IPOPT's linear solver is not
    re-entrant, so one process runs one optimisation at a time (a Dask cluster's worker
    processes run theirs side by side). `samples` is the deprecated name of `inputs`."""
    samples = keyword("multistart", "samples", "inputs", samples, inputs)
    if samples is None or vary is None:
        raise ModelError([f"{k}: missing" for k, v in (("inputs", samples), ("vary", vary)) if v is None])
    names = list(vary)
    ranges = [tuple(float(v) for v in vary[k]) for k in names]
    X = latin_hypercube(ranges, int(starts), seed)
    job = _Start(m, names, samples, {"vary": vary, "minimize": minimize,
                                     "constraints": constraints, **kw})
    from ..analysis.executor import run_chunks

    out = run_chunks(job, list(X), client=client, workers=workers, progress=progress)
    results = [r for _, r in out]
    errors = [r for r in results if isinstance(r, Exception)]
    if errors and len(errors) == len(results) and len({str(e) for e in errors}) == 1:
        raise errors[0]  # the problem itself is wrong (a bad expression), not the starts
    good = sorted((r for r in results if not isinstance(r, Exception) and r.ok),
                  key=lambda r: r.objective)
    width = np.array([max(hi - lo, 1e-300) for lo, hi in ranges])
    optima = []
    for r in good:  # distinct: some parameter differs by more than `same` of its range
        x = np.array([r.varied[k] for k in names])
        if all(np.any(np.abs(x - np.array([o.varied[k] for k in names])) > same * width)
               for o in optima):
            optima.append(r)
    return Multistart(optima=optima[:keep], results=results, starts=X, names=names)


# the name of 0.1 (results are named by what they hold, as Sweep and Pose are)
__getattr__ = renamed(globals(), {'MultistartResult': 'Multistart'}, 'kincas.synthesis.multistart')
