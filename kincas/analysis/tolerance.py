"""Tolerance analysis: the spread of outputs caused by the spread of parameters.

Parameters (link lengths, ground coordinates, anything named in `[parameters]`) are taken as
independent normal variables with the given standard deviations sigma_j. Two answers:

* first order: Q(p0 + dp) ~ Q(p0) + sum_j dQ/dp_j dp_j, so std(Q) = sqrt(sum_j (dQ/dp_j sigma_j)^2),
  with the exact sensitivities of the implicit function theorem (`kincas.sensitivity`);
* Monte Carlo: N mechanisms drawn at random, each solved at every pose. One drawn mechanism
  is one manufactured part, so the same draw is used at all poses. The draws are the designs
  of one batched sweep (`kincas.sweep_designs`, the executor of `kincas study`): each is
  continued from the nominal's first pose in the parameters, keeping the sign of det(g_q)
  (the nominal's assembly branch), then swept by the compiled fast pass with its checks. A
  sample that cannot be continued to a pose is counted as failed there and left out, never
  used, and taken up again at the next pose from the nominal's pose there. The samples run
  in chunks on the executor of `kincas study` (threads; the compiled loop releases the GIL),
  each chunk reduced to per-pose counts, means and squared deviations, so that 100,000
  samples x 360 poses need no more memory than one chunk.

The two agree when the outputs are close to linear over the tolerance band; their ratio is
reported beside the Monte-Carlo sampling error, 1 / sqrt(2 (N - 1)) relative.

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(parameters={"a": 1.0, "b": 3.5}, ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", "a"), kincas.Link.bar("coupler", "B", "C", "b"),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
>>> r = analyse(m, {"crank.angle": np.array([0.5, 1.0])}, std={"a": 0.01, "b": 0.01},
...             report=["C.y"], draws=400, seed=1)
>>> r.failed.tolist(), bool(np.all(np.abs(r.agreement["C.y"] - 1) < 0.2))
([0, 0], True)
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError
from ..core.tolerances import ROUNDING_REL, TINY
from ..model.mechanism import Mechanism
from .._deprecated import attribute, keyword, renamed
from ..result_base import Result
from ..model.names import is_angle_name

FEW_POSES = 16  # up to this many poses, each is solved from the nominal's (not swept to)
CHUNK = 2048  # samples per task of the executor



@dataclass(repr=False)
class ToleranceAnalysis(Result):
    """First-order and Monte-Carlo standard deviations of each output at each pose.

    `first_order[Q]`, `monte_carlo[Q]`, `nominal[Q]`, `mean_shift[Q]` (Monte-Carlo mean minus
    nominal) are arrays over the poses; `failed[i]` counts the samples that did not assemble
    on the nominal branch at pose i (left out of the statistics); `agreement[Q]` is
    monte_carlo / first_order."""

    names: list[str]
    std: dict[str, float]
    draws: int  # Monte-Carlo draws (0.1: `samples`)
    seed: int | None
    inputs: dict[str, np.ndarray]
    status: list[str]
    nominal: dict[str, np.ndarray]
    first_order: dict[str, np.ndarray]
    monte_carlo: dict[str, np.ndarray]
    mean_shift: dict[str, np.ndarray]
    failed: np.ndarray
    info: dict = field(default_factory=dict)

    samples = attribute("ToleranceAnalysis", "samples", "draws")

    @property
    def ok(self) -> np.ndarray:
        """Boolean mask of the poses whose nominal design was solved."""
        return np.array([s == "ok" for s in self.status], dtype=bool)

    def summary(self) -> str:
        """Poses, Monte-Carlo samples, parameters and outputs (the `repr`'s body)."""
        return (f"{len(self.status)} poses, {int(self.ok.sum())} solved; {self.draws} draws; "
                f"std of {', '.join(self.std)}; outputs {', '.join(self.names)}")

    @property
    def agreement(self) -> dict[str, np.ndarray]:
        """Monte-Carlo std over first-order std (1 where both are zero)."""
        out = {}
        for n in self.names:
            fo, mc = self.first_order[n], self.monte_carlo[n]
            with np.errstate(divide="ignore", invalid="ignore"):
                r = mc / fo
            tiny = ROUNDING_REL * max(1.0, float(np.nanmax(np.abs(self.nominal[n]), initial=0.0)))
            out[n] = np.where((fo <= tiny) & (mc <= tiny), 1.0, r)
        return out

    @property
    def standard_error(self) -> float:
        """Relative sampling error of a Monte-Carlo standard deviation, 1 / sqrt(2 (n - 1))."""
        return 1.0 / math.sqrt(2.0 * max(self.draws - 1, 1))

    def to_pandas(self, length: str = "", angle: str = "rad"):
        """A DataFrame per pose: each output's nominal value, `std Q` and `mc Q`, status, failed."""
        from ..frames import tolerance_to_pandas, in_angle
        return in_angle(tolerance_to_pandas(self, length), angle)

    def to_xarray(self, length: str = "", angle: str = "rad"):
        """A Dataset (pose x quantity): nominal, first_order, monte_carlo; status, failed."""
        from ..frames import tolerance_to_xarray, in_angle
        return in_angle(tolerance_to_xarray(self, length), angle)

    def agrees(self, k: float = 4.0) -> bool:
        """Whether, at every solved pose, |Monte Carlo - first order| is within k sampling
        errors of the output's largest first-order std over the sweep. (Relative to each
        pose's own std would fail where a derivative crosses zero: there the first-order std
        vanishes and the small second-order spread is all that is left.)"""
        ok = np.array([s == "ok" for s in self.status])
        for n in self.names:
            fo, mc = self.first_order[n][ok], self.monte_carlo[n][ok]
            top = float(np.nanmax(fo, initial=0.0))
            if not np.all(np.abs(mc - fo) <= k * self.standard_error * top + TINY):
                return False
        return True


# --- the analysis ---


def analyse(m: Mechanism, inputs, std: dict[str, float], report: list[str] | None = None, *,
            draws: int = 2000, seed: int | None = 0, rates=None, accelerations=None,
            progress=None, workers: int | None = None, samples: int | None = None) -> ToleranceAnalysis:
    """Spread of the `report` quantities over `inputs` from independent normal parameter
    errors with standard deviations `std` (parameter name -> sigma, in its own unit). The
    samples run in chunks on `workers` threads (default: every core); the numbers do not
    depend on how many.

    Parameters
    ----------
    m : Mechanism
    inputs : dict
        Input key -> values, as for `kincas.sweep`.
    std : dict
        Parameter name -> standard deviation.
    report : list of str, optional
        Quantity names (default: points and link angles).
    draws : int
        Monte-Carlo draws: manufactured designs, each with random parameter errors.
    seed : int, optional
    rates, accelerations : dict, optional
        As for `kincas.sweep`.
    progress : callable, optional
    workers : int, optional
        Threads for the draws (default: every core).
    samples : int, optional
        Deprecated name of `draws` (kincas 0.1; a DeprecationWarning). A scene's
        `[tolerance] samples` is unchanged.

    Returns
    -------
    ToleranceAnalysis

    Examples
    --------
    To first order the spread of C.x is |dC.x/da| sigma, with dC.x/da = 1 - 1/2 + 3.25 / 18
    at crank angle 0 (see `kincas.sensitivities`):

    >>> import numpy as np, kincas
    >>> m = kincas.Mechanism(parameters={"a": 1.0}, ground={"A": (0, 0), "D": (4, 0)},
    ...     links=[kincas.Link.bar("crank", "A", "B", "a"), kincas.Link.bar("coupler", "B", "C", 3.5),
    ...            kincas.Link.bar("rocker", "D", "C", 3)],
    ...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
    >>> t = analyse(m, {"crank.angle": [0.0]}, {"a": 0.001}, ["C.x"], draws=400)
    >>> round(float(t.first_order["C.x"][0]), 12), round((1 / 2 + 3.25 / 18) * 0.001, 12)
    (0.000680555556, 0.000680555556)
    >>> bool(abs(t.monte_carlo["C.x"][0] / t.first_order["C.x"][0] - 1) < 0.15)  # 400 samples
    True
    """
    from .sensitivity import sensitivities
    from ..model.names import default_report, parse_quantity

    draws = keyword("analyse", "samples", "draws", samples, draws, 2000)
    report = list(default_report(m) if report is None else report)
    problems = check_std(m, std, "std")
    problems += [f"report: {n!r}: a sensitivity has no spread to analyse" for n in report
                 if parse_quantity(n)[0] == "sens"]
    if not isinstance(draws, int) or isinstance(draws, bool) or draws < 2:
        problems.append(f"draws: expected a whole number >= 2, got {draws!r}")
    if problems:
        raise ModelError(problems)
    to = list(std)
    sig = np.array([float(std[p]) for p in to])
    sens = sensitivities(m, inputs, of=report, to=to, rates=rates, accelerations=accelerations,
                         progress=progress)
    sw = sens.sweep
    fo = np.sqrt(np.einsum("ijk,k->ij", sens.matrix ** 2, sig ** 2))  # poses x outputs
    rng = np.random.default_rng(seed)
    dp = rng.standard_normal((draws, len(to))) * sig  # one row per manufactured mechanism
    mc, shift, failed, retried = _monte_carlo(m, sw, report, to, dp, workers)
    nominal = {n: sw[n] for n in report}
    return ToleranceAnalysis(
        names=report, std={p: float(std[p]) for p in to}, draws=draws, seed=seed,
        inputs=sw.inputs, status=sw.status, nominal=nominal,
        first_order={n: fo[:, j] for j, n in enumerate(report)},
        monte_carlo={n: mc[:, j] for j, n in enumerate(report)},
        mean_shift={n: shift[:, j] for j, n in enumerate(report)}, failed=failed,
        info={"retried": retried})


def check_std(m: Mechanism, std, where: str) -> list[str]:
    """Problems with `std` (parameter -> standard deviation) for `m`, each naming `where`."""
    out = []
    driven = {i.target for i in m.inputs if i.kind == "parameter"}
    if not isinstance(std, dict) or not std:
        return [f"{where}: expected a table of parameter names and standard deviations"]
    for p, s in std.items():
        if p not in m.param_values:
            out.append(f"{where}: {p}: unknown parameter (declare it in [parameters])")
        elif p in driven:
            out.append(f"{where}: {p}: driven by an input, so it has no tolerance")
        if isinstance(s, bool) or not isinstance(s, (int, float)) or not math.isfinite(s) or s < 0:
            out.append(f"{where}: {p}: expected a standard deviation >= 0, got {s!r}")
    return out


def _monte_carlo(m: Mechanism, sw, report, to, dp, workers=None):
    """Monte-Carlo std and mean shift (poses x outputs), failures per pose, restarts.

    The samples are cut into chunks of CHUNK (a fixed size, so that the numbers do not depend
    on the number of workers), run on the executor of `kincas study`
    (kincas/analysis/executor.py: local threads; the compiled loop releases the GIL). Each
    chunk gives, per pose, the count, mean and sum of squared deviations of its good samples
    (nothing larger is kept: 100,000 samples x 360 poses fit in memory), merged in the
    chunks' order by the pairwise update of Chan et al."""
    from .executor import run_chunks

    n_s, n_pose = dp.shape[0], len(sw)
    pv = dict(m.parameters)
    X = np.array([pv[p] for p in to], dtype=float) + dp
    job = _Samples(m, sw, list(report), list(to))
    parts = [X[a:a + CHUNK] for a in range(0, n_s, CHUNK)]
    out = run_chunks(job, parts, workers=workers)
    count = np.zeros((n_pose, 1))
    mean, m2 = np.zeros((n_pose, len(report))), np.zeros((n_pose, len(report)))
    restarts = 0
    for c, mu, s2, again in out:
        tot = count + c
        with np.errstate(invalid="ignore", divide="ignore"):
            delta = mu - mean
            mean = np.where(tot > 0, mean + delta * (c / tot), 0.0)
            m2 = m2 + s2 + delta ** 2 * np.where(tot > 0, count * c / tot, 0.0)
        count, restarts = tot, restarts + again
    ok = np.asarray(sw.ok, dtype=bool)
    enough = ok & (count[:, 0] >= 2)
    with np.errstate(invalid="ignore", divide="ignore"):
        mc = np.where(enough[:, None], np.sqrt(m2 / (count - 1)), np.nan)
    shift = np.where(enough[:, None], mean, np.nan)
    failed = np.where(ok, n_s - count[:, 0], 0).astype(int)
    return mc, shift, failed, restarts


@dataclass
class _Samples:
    """One chunk of drawn mechanisms: each a design of `kincas.sweep_designs`, swept over
    every run of poses the nominal solved (with FEW_POSES poses or fewer, each pose on its
    own), from the nominal's first pose of the run (continued in the parameters, keeping
    each Assur group's mode: the nominal's branch). A sample that cannot be continued to a
    pose counts as failed there, and is taken up again at the next pose, continued in the
    parameters from the nominal's pose there. Returns per pose the count of good samples,
    the mean and the sum of squared deviations of each output from the nominal (angles
    across +-pi), and the number of restarts."""

    m: Mechanism
    sw: object
    report: list
    to: list

    def __call__(self, X):
        from ..core.cancel import checkpoint
        from ..core.numeric import compile
        from .designs import sweep_designs

        m, sw, report = self.m, self.sw, self.report
        model = compile(m)
        n_s, n_pose = X.shape[0], len(sw)
        p0 = np.array([v for _, v in m.parameters], dtype=float)
        keys = list(sw.inputs)
        U = np.stack([sw.inputs[k] for k in keys], axis=1)
        Ud = np.stack([sw.rates[k] for k in keys], axis=1)
        Udd = np.stack([sw.accelerations[k] for k in keys], axis=1)
        Qv = None  # per output (samples, poses), read only where good
        good = np.zeros((n_s, n_pose), dtype=bool)
        ok = np.asarray(sw.ok, dtype=bool)
        if n_pose <= FEW_POSES:  # far apart, as a rule: each from the nominal's pose there
            todo = [(a, a + 1, np.arange(n_s)) for a in np.flatnonzero(ok)]
        else:  # swept along each run of poses the nominal solved
            edges = np.flatnonzero(np.diff(np.r_[0, ok.astype(int), 0]))
            todo = [(a, b, np.arange(n_s)) for a, b in zip(edges[::2], edges[1::2])]
        restarts = 0
        while todo:
            checkpoint()  # Ctrl-C (kincas/core/cancel.py)
            a, b, idx = todo.pop()
            pts = model.points(sw.q[a], U[a], p0)
            guess = {nm: tuple(pts[:, j]) for j, nm in enumerate(m.moving_points)}
            cut = lambda T: {k: T[a:b, j] for j, k in enumerate(keys)}
            r = sweep_designs(m, X[idx], cut(U), names=self.to, rates=cut(Ud),
                              accelerations=cut(Udd), report=list(report), guess=guess, workers=1)
            if Qv is None and (a, b, len(idx)) == (0, n_pose, n_s):  # all of it: no copy
                Qv = [r.values[nm] for nm in report]
            else:
                Qv = Qv or [np.empty((n_s, n_pose)) for _ in report]
                for i, nm in enumerate(report):
                    Qv[i][idx, a:b] = r.values[nm]
            good[idx, a:b] = r.ok
            stopped = ~r.ok.all(axis=1)
            first = np.argmin(r.ok, axis=1)
            for f in np.unique(first[stopped]):
                if a + f + 1 < b:
                    again = idx[stopped & (first == f)]
                    todo.append((a + f + 1, b, again))
                    restarts += len(again)
        good &= ok
        bad = ~good
        Qv = Qv or [np.zeros((n_s, n_pose)) for _ in report]
        c = good.sum(axis=0).astype(float)  # (poses,)
        mu, s2 = np.zeros((n_pose, len(report))), np.zeros((n_pose, len(report)))
        for i, nm in enumerate(report):  # in place: a few passes over (samples, poses)
            d = Qv[i]
            d -= np.where(ok, sw[nm], 0.0)
            d[bad] = 0.0
            wrap = np.abs(d) > np.pi if is_angle_name(nm) else None  # across +-pi
            if wrap is not None and wrap.any():
                d[wrap] -= 2 * np.pi * np.round(d[wrap] / (2 * np.pi))
            with np.errstate(invalid="ignore", divide="ignore"):
                mu[:, i] = np.where(c > 0, d.sum(axis=0) / c, 0.0)
            d -= mu[:, i]
            d[bad] = 0.0
            s2[:, i] = np.einsum("ij,ij->j", d, d)
        return c[:, None], mu, s2, restarts


# the name of 0.1 (results are named by what they hold, as Sweep and Pose are)
__getattr__ = renamed(globals(), {'ToleranceResult': 'ToleranceAnalysis'}, 'kincas.analysis.tolerance')
