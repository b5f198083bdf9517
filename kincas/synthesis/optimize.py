"""Optimisation of parameters (link lengths, ground points, ...) by IPOPT, with exact
derivatives through the kinematics.

Simultaneous formulation: the decision variables are the varied parameters *and* the pose
q_k at every sample input u_k; the loop-closure residuals g(q_k, u_k, p) = 0 are equality
constraints. The objective and the constraints are written with quantity names (see
`kincas.expressions`), so they are smooth functions of (q_k, u_k, p) whose first and second
derivatives CasADi builds exactly; nothing is differenced and no pose is solved inside the
optimiser's loop. Each pose starts from a sweep of the initial design, which fixes the
assembly branch. `max(E)` and `min(E)` over the input's range add a sample whose input is
free too, held at a stationary point by dE/du = E_q dq/du + E_u = 0, dq/du = -g_q^-1 g_u.

IPOPT's answer is then checked, not trusted: every pose is polished by Newton's method at the
optimised parameters; the sign of det(g_q) at each sample must be the initial design's (the
same branch); the optimised mechanism is swept from the first sample through all the others
(it must get from one to the next without leaving its branch); every extreme is compared with
that sweep; every constraint is evaluated again. A design that fails any of these is
reported with the reason (`ok` False), never as optimal.

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(parameters={"a": 1.0, "b": 3.5, "c": 3.0},
...     ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", "a"), kincas.Link.bar("coupler", "B", "C", "b"),
...            kincas.Link.bar("rocker", "D", "C", "c")],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
>>> r = optimize(m, {"crank.angle": [np.pi / 2]}, vary={"c": (2.0, 4.0)},
...              minimize="sum((C.y - 2.5)^2)")
>>> r.ok, r.status, round(r.parameters["c"], 6), round(float(np.sqrt(10 - 8 * np.sqrt(10) + 22.25)), 6)
(True, 'Solve_Succeeded', 2.636623, 2.636623)

(At crank angle 90 deg, B = (0, 1); C.y = 2.5 puts C at (sqrt(3.5^2 - 1.5^2), 2.5) = (sqrt(10), 2.5),
so the rocker from D = (4, 0) is c = sqrt((sqrt(10) - 4)^2 + 2.5^2).)
"""
from __future__ import annotations

import sys
import types
from dataclasses import dataclass, field

import numpy as np

from ..model.mechanism import Mechanism
from .._deprecated import attribute, keyword, renamed
from ..result_base import Result
from ..errors import ModelError
from ..results import Sweep
from .curve import Curve, constrain as curve_constrain, distances as curve_distances
from .curve import objective as curve_objective, start as curve_start
from .checks import EXTREME_MOVED
from .simultaneous import Problem

MAX_ROUNDS = 3  # IPOPT runs when extremes moved away from where they were tracked

__all__ = ["optimize", "Curve", "Constraint", "Optimization", "cli_arguments", "cli_run"]


@dataclass
class Constraint:
    """`min <= expr <= max` (either bound may be None); per sample when expr is."""

    expr: str
    min: float | None = None
    max: float | None = None


@dataclass(repr=False)
class Optimization:
    """What the optimiser found, and whether it may be trusted (`ok`).

    `converged`: IPOPT reported success; `ok`: that, and the optimised design passed every
    check (`problems` says which failed). `mechanism` is the optimised design as a new value,
    its guess set to its pose at the first sample (so it keeps the branch). `values` are the
    quantities named in the expressions at the samples (radians); `constraints` gives each
    constraint's value(s) and whether it holds; `extremes` the tracked max()/min()."""

    ok: bool
    converged: bool
    status: str
    message: str
    objective: float
    initial_objective: float
    parameters: dict[str, float]
    varied: dict[str, float]
    mechanism: Mechanism
    inputs: dict[str, np.ndarray]  # the input values posed (0.1: `samples`)
    q: np.ndarray
    values: dict[str, np.ndarray]
    constraints: list[dict]
    extremes: list[dict]
    iterations: int
    problems: list[str] = field(default_factory=list)
    sweep: Sweep | None = None
    info: dict = field(default_factory=dict)

    samples = attribute("Optimization", "samples", "inputs")

    def __repr__(self) -> str:
        return f"<Optimization: {self.summary()}>"

    def summary(self) -> str:
        """Trusted or not, the status, the objective and the varied parameters."""
        varied = ", ".join(f"{k}={v:.6g}" for k, v in self.varied.items())
        return (f"{'ok' if self.ok else 'not ok'} ({self.status}); objective {self.objective:.6g}"
                f" after {self.iterations} iterations; {varied}")

    def to_pandas(self, length: str = "", angle: str = "rad"):
        """A DataFrame per sample (inputs as index, the expressions' quantities as columns),
        the parameters, objective and status in `df.attrs`."""
        from ..frames import optimize_to_pandas, in_angle
        return in_angle(optimize_to_pandas(self, length), angle)

    def to_xarray(self, length: str = "", angle: str = "rad"):
        """A Dataset along `sample`; parameters, objective and status as attributes."""
        from ..frames import optimize_to_xarray, in_angle
        return in_angle(optimize_to_xarray(self, length), angle)

    # --- scipy.optimize.OptimizeResult's familiar names ---
    @property
    def x(self) -> np.ndarray:
        """The varied parameters' optimised values, in the order `vary` gave them."""
        return np.array(list(self.varied.values()), dtype=float)

    @property
    def fun(self) -> float:
        """The objective at the optimum (`objective`)."""
        return self.objective

    @property
    def success(self) -> bool:
        """Converged and every check passed (`ok`)."""
        return self.ok

    @property
    def nit(self) -> int:
        """IPOPT's iterations (`iterations`)."""
        return int(self.iterations)


# `ok` is a field here (scipy's OptimizeResult has `success`), which the dataclass would take
# for a default if it inherited Result's abstract property: a registered Result instead
Result.register(Optimization)


def _as_constraint(c, i) -> Constraint:
    if isinstance(c, Constraint):
        return c
    if isinstance(c, dict):
        bad = set(c) - {"expr", "min", "max"}
        if bad or "expr" not in c:
            raise ModelError(f"constraints[{i + 1}]: expected {{expr, min, max}}, got {sorted(c)}")
        return Constraint(c["expr"], c.get("min"), c.get("max"))
    if isinstance(c, (tuple, list)) and len(c) == 3:
        return Constraint(*c)
    raise ModelError(f"constraints[{i + 1}]: expected (expr, min, max), got {c!r}")



def optimize(m: Mechanism, inputs=None, vary: dict | None = None, minimize: str | None = None,
             constraints=(), *, data=None, rates=None, accelerations=None, deg: bool = False,
             check_path: bool = True, max_iter: int = 1000, tol: float = 1e-12,
             samples=None) -> Optimization:
    """Vary the parameters `vary` (name -> (low, high)) to minimise `minimize` subject to
    `constraints` (Constraint, dict {expr, min, max} or tuple (expr, min, max)), with the
    mechanism posed at the `inputs` (key -> array, as for `kincas.sweep`): the samples.

    `inputs` may instead be a `Curve` (see `kincas.curve`): targets for a point without
    prescribed inputs. Then the input at each target is a variable too (`samples` of the
    result gives the fitted ones), the objective is the sum of squared distances from the
    point to the targets, plus `minimize` if given, and `data` has one value per target.

    `data` gives named arrays, one value per sample, for the expressions. `deg`: quantities,
    data and trigonometric functions in the expressions use degrees for angles (the scene
    convention); radians otherwise.

    Parameters
    ----------
    m : Mechanism
        The initial design; its guess picks the assembly branch kept at every sample.
    inputs : dict or Curve
        Input key -> values of the samples; or target points (`kincas.curve.Curve`).
    vary : dict
        Parameter name -> (low, high).
    minimize : str, optional
        The objective (kincas/synthesis/expressions.py).
    constraints : sequence
        Constraint, dict {expr, min, max} or tuple (expr, min, max).
    data : dict, optional
        Named arrays, one value per sample.
    rates, accelerations : dict, optional
        As for `kincas.sweep`.
    deg : bool
        Angles in degrees in the expressions.
    check_path : bool
        Sweep the optimised design through the samples to check its branch.
    max_iter, tol : int, float
        IPOPT's iterations and tolerance.
    samples : dict or Curve, optional
        Deprecated keyword name of `inputs` (kincas 0.1; a DeprecationWarning).

    Returns
    -------
    Optimization
        `ok` only if IPOPT converged and every check passed; otherwise `problems` says why.

    Examples
    --------
    At crank angle 90 deg, B = (0, 1); C.y = 2.5 puts C at (sqrt(10), 2.5), so the rocker
    from D = (4, 0) is c = sqrt((sqrt(10) - 4)^2 + 2.5^2):

    >>> import numpy as np, kincas
    >>> m = kincas.Mechanism(parameters={"c": 3.0}, ground={"A": (0, 0), "D": (4, 0)},
    ...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
    ...            kincas.Link.bar("rocker", "D", "C", "c")],
    ...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
    >>> r = optimize(m, {"crank.angle": [np.pi / 2]}, vary={"c": (2.0, 4.0)}, minimize="sum((C.y - 2.5)^2)")
    >>> r.ok, round(r.parameters["c"], 9), round(float(np.hypot(np.sqrt(10) - 4, 2.5)), 9)
    (True, 2.636622597, 2.636622597)
    """
    samples = keyword("optimize", "samples", "inputs", samples, inputs)
    problems = [f"{k}: missing" for k, v in (("inputs", samples), ("vary", vary)) if v is None]
    if problems:
        raise ModelError(problems)
    first = _once(m, samples, vary, minimize, constraints, data, rates, accelerations, deg,
                  check_path, max_iter, tol)
    r, rounds = first, 1
    # A max()/min() is tracked where it was on the starting design; if the optimum moved the
    # extreme elsewhere (the checks find it), start again from the optimum with every extreme
    # re-seeded where the checking sweep now finds it.
    while (rounds < MAX_ROUNDS and r.converged and r.problems
           and all(EXTREME_MOVED in p for p in r.problems)):
        r = _once(r.mechanism, samples, vary, minimize, constraints, data, rates, accelerations,
                  deg, check_path, max_iter, tol)
        rounds += 1
    r.initial_objective = first.initial_objective
    r.mechanism = m.with_parameters(**r.varied).with_guess(**dict(r.mechanism.guess))
    r.info["rounds"] = rounds
    return r


def _once(m, samples, vary, minimize, constraints, data, rates, accelerations, deg, check_path,
          max_iter, tol) -> Optimization:
    from ..core.numeric import compile
    from ..analysis.sweeps import sweep

    model = compile(m)
    prob = Problem(m, model, vary, data, deg)
    curve = samples if isinstance(samples, Curve) else None
    if minimize is None and curve is None:
        raise ModelError("minimize: missing (an expression; optional only with a curve)")
    objective = None if minimize is None else prob.parse(minimize, "minimize")
    cons = [prob.parse_constraint(_as_constraint(c, i), i) for i, c in enumerate(constraints)]
    named = ([("minimize", objective)] if objective else []) + [
        (f"constraints[{i + 1}]", e) for i, (_, e) in enumerate(cons)]
    for where, e in named if curve is not None else ():
        if e.extremes:
            raise ModelError(f"{where}: max()/min() over the input's range cannot be combined "
                             f"with a curve (its inputs are fitted)")
    if curve is None:
        sw0 = sweep(m, samples, rates=rates, accelerations=accelerations, report=[])
        prob.set_samples(sw0, sweep)
    else:  # the inputs at the targets are variables too, started at the projections
        sw0, shape = curve_start(m, curve, sweep, rates, accelerations)
        prob.set_samples(sw0, sweep)
        curve_constrain(prob, *shape)
        prob.used += [n for n in (f"{curve.point}.x", f"{curve.point}.y") if n not in prob.used]
    f = 0 if objective is None else prob.evaluate(objective, "minimize", objective=True)[1]
    if curve is not None:
        f = f + curve_objective(prob, curve)
    rows = [(c, prob.evaluate(e, c.expr)) for c, e in cons]
    r = Optimization(**prob.solve(f, rows, check_path, max_iter, tol))
    if curve is not None:
        r.info["curve"] = {"point": curve.point, "targets": curve.targets,
                           "distances": curve_distances(r.sweep, curve, prob.at)}
    return r


# --- `kincas.optimize(...)`: the function, also reachable by its 0.1 module path ---


class _CallableModule(types.ModuleType):
    """`kincas.optimize` is both this module (scripts of 0.1 import `kincas.optimize` and call
    `kincas.optimize.optimize`) and the function: calling the module calls `optimize`, so
    importing the module path never hides the function."""

    def __call__(self, *args, **kwargs) -> Optimization:
        return optimize(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule


# the name of 0.1 (results are named by what they hold, as Sweep and Pose are)
__getattr__ = renamed(globals(), {'OptimizeResult': 'Optimization'}, 'kincas.synthesis.optimize')
