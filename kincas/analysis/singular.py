"""Singular positions and the range of motion of an input.

With J = g_q (unknowns) and G = [g_q g_u] (unknowns and the swept input), both scaled so
that their entries are O(1) at every size of mechanism:
- J regular: an ordinary pose (the branch goes on, velocities are finite);
- J singular, G of full rank: a **limit** (turning point: the input cannot go further; a
  rocker's dead centre, the end of an actuator's reach);
- J and G both rank-deficient: a **change point** (branches cross: a folding parallelogram);
- anything else singular (several inputs): **singular**.
A limit is located exactly by Newton on the extended system
    g(q, u) = 0,   g_q(q, u) v = 0,   v0 . v = 1
in (q, u, v), whose Jacobian (second derivatives of g, exact from CasADi) is regular at a
simple turning point. The range of motion follows the branch by pseudo-arclength
continuation (the one continuation, kincas/analysis/path.py, in arclength: through the turns
that natural-parameter continuation cannot pass) until the input turns back (a limit) or an
angle input has made a full turn.

>>> import math, kincas
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 1.9),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.2, 2.5)})
>>> r = input_range(m, {"crank.angle": 0.5})
>>> [k for k, _ in r.limits], round(math.degrees(r.high), 9)  # |BD| = 1.9 + 3 there
(['limit', 'limit'], 151.193259668)
>>> round(math.degrees(math.acos((1 + 16 - 4.9 ** 2) / 8)), 9)
151.193259668
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.limits import _scales, locate_singular, scaled_jacobians  # noqa: F401  (their old home)
from ..core.newton import newton
from ..core.tolerances import (ARC_FIRST, ARC_GROW, ARC_ITER, ARC_LONGEST, ARC_WANDER, FLAG_SIGMA, MAX_STEP,
                               MIN_ARC_STEP, ROUNDING_REL)
from ..model.mechanism import Mechanism
from ..result_base import Result
from .path import Arclength, follow


# --- scaled Jacobians and classification ---


def classify(J: np.ndarray, Gu: np.ndarray, tol: float = FLAG_SIGMA) -> str | None:
    """None, "limit", "change point" or "singular" from the scaled Jacobians at a pose."""
    if J.size == 0:
        return None
    s = np.linalg.svd(J, compute_uv=False)
    if s[-1] > tol * max(s[0], 1.0):
        return None
    G = np.hstack([J, Gu])
    sg = np.linalg.svd(G, compute_uv=False)
    if sg[J.shape[1] - 1] <= tol * max(sg[0], 1.0) * 1e3:  # rank [J Gu] < nq
        return "change point"
    return "limit" if Gu.shape[1] == 1 else "singular"


# --- range of motion by pseudo-arclength continuation ---


@dataclass(repr=False)
class Range(Result):
    """The interval an input can sweep on the starting pose's branch: `low` to `high`, or
    a full turn; `limits` the (kind, input value) of each limit met; `ok` whether the
    interval was found (finite ends)."""

    key: str
    low: float
    high: float
    full_turn: bool
    limits: list[tuple[str, float]] = field(default_factory=list)  # (kind, input value)
    start: float = 0.0

    @property
    def ok(self) -> bool:
        """Whether the range was found: a full turn, or both ends finite."""
        return bool(self.full_turn or (np.isfinite(self.low) and np.isfinite(self.high)))

    def summary(self) -> str:
        """The input, its interval and the limits met (the `repr`'s body)."""
        span = "full turn" if self.full_turn else f"{self.low:.6g} to {self.high:.6g}"
        return f"{self.key} {span}; {len(self.limits)} limits met"

    def to_pandas(self, length: str = "", angle: str = "rad"):
        """A DataFrame of the limits met (kind, input value); key, low, high, full_turn and
        start in `df.attrs`."""
        from ..frames import range_to_pandas, in_angle
        return in_angle(range_to_pandas(self, length), angle)

    def to_xarray(self, length: str = "", angle: str = "rad"):
        """A Dataset along `limit` (kind, value); key, low, high, full_turn, start as attributes."""
        from ..frames import range_to_xarray, in_angle
        return in_angle(range_to_xarray(self, length), angle)


def input_range(m: Mechanism, inputs: dict, key: str | None = None, *, max_steps: int = 20000) -> Range:
    """Range of input `key` (default: the first) on the branch of the pose at `inputs`,
    the other inputs held at their values. Limits are located to rounding precision.

    Parameters
    ----------
    m : Mechanism
    inputs : dict
        Input key -> value: the starting pose.
    key : str, optional
        The input whose range is wanted (default: the first).
    max_steps : int
        Continuation steps at most, each way.

    Returns
    -------
    Range
        `low`, `high`, whether the input turns fully (`full_turn`) and the limits met.

    Examples
    --------
    A Grashof crank turns fully; with a 1.9 coupler the crank stops where |BD| = 1.9 + 3:

    >>> import numpy as np, kincas
    >>> m = kincas.Mechanism(parameters={"a": 1.0, "b": 3.5}, ground={"A": (0, 0), "D": (4, 0)},
    ...     links=[kincas.Link.bar("crank", "A", "B", "a"), kincas.Link.bar("coupler", "B", "C", "b"),
    ...            kincas.Link.bar("rocker", "D", "C", 3)],
    ...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.2, 2.5)})
    >>> input_range(m, {"crank.angle": 0.5}).full_turn
    True
    >>> r = input_range(m.with_parameters(b=1.9), {"crank.angle": 0.5})
    >>> round(float(r.high), 12), round(float(np.arccos((1 + 16 - 4.9 ** 2) / 8)), 12)
    (2.638820188023, 2.638820188023)
    """
    from ..core.numeric import compile
    from ..core.assembly import first_pose
    from .inputs import input_table
    model = compile(m)
    keys = [i.key for i in m.inputs]
    key = key or keys[0]
    i = keys.index(key)
    p = np.array([v for _, v in m.parameters], float)
    L = m.size()
    u0 = input_table(m, inputs, "inputs", None)[0]
    guess = {k: tuple(map(m.value, xy)) for k, xy in m.guess}
    start = first_pose(model, u0, p, L, guess)  # the starting pose, as a sweep's first
    if not start.ok:
        raise ValueError(f"the mechanism does not assemble at {inputs}")
    q0 = start.q
    is_angle = m.inputs[i].is_angle
    cq, cu = _scales(model, L)
    # unknowns / scale are O(1): angles as they are, lengths over the size
    scale = np.concatenate([cq, [cu[i]]]) * L
    ends, limits = {}, []
    for direction in (+1, -1):
        end, lim = _follow(model, q0, u0, p, L, i, direction, scale, is_angle, max_steps)
        ends[direction] = end
        if lim is not None:
            limits.append(("limit", lim))
    full = is_angle and (ends[+1] - u0[i] >= 2 * np.pi or u0[i] - ends[-1] >= 2 * np.pi)
    if full:
        return Range(key, u0[i] - np.pi, u0[i] + np.pi, True, [], u0[i])
    return Range(key, min(ends.values()), max(ends.values()), False,
                 sorted(limits, key=lambda t: t[1]), u0[i])


def _follow(model, q, u, p, L, i, direction, scale, is_angle, max_steps):
    """Walk the branch from (q, u) while input i moves in `direction` at first: the one
    continuation (kincas/analysis/path.py) in arclength, in z = (q, u_i) / scale.

    Returns (the input value where the walk ended, the located limit or None)."""
    nq = model.nq
    z = np.concatenate([q, [u[i]]]) / scale
    t = _curve_tangent(model, q, u, p, i, scale)
    t = t if t[-1] * direction > 0 or abs(t[-1]) < ROUNDING_REL else -t
    u_start = u[i]

    def step(w):  # predict along the curve's tangent, correct across it; the new tangent
        (z, t), h = w.at, w.target
        zn = _correct(model, z + h * t, t, u, p, L, i, scale)
        if zn is None:
            return None, "not converged"
        tn = _curve_tangent(model, zn[:nq] * scale[:nq], _with(u, i, zn[-1] * scale[-1]), p, i, scale)
        return (zn, tn if tn @ t >= 0 else -tn), None

    def stop(w):
        (_, t), (zn, tn) = w.prev, w.at
        if np.sign(tn[-1]) != np.sign(t[-1]) and t[-1] != 0:
            return "limit"  # the input turned back between z and zn
        if is_angle and abs(zn[-1] * scale[-1] - u_start) >= 2 * np.pi:
            return "full turn"
        return None
    w = follow((z, t), None, Arclength(ARC_FIRST, ARC_LONGEST, ARC_GROW, MIN_ARC_STEP), step,
               stop=stop, budget=max_steps, reach=False)
    if w.reason == "limit":  # locate it exactly, from the end nearer it
        (z, t), (zn, tn) = w.prev, w.at
        qn, un = zn[:nq] * scale[:nq], _with(u, i, zn[-1] * scale[-1])
        start = (qn, un) if abs(tn[-1]) < abs(t[-1]) else (z[:nq] * scale[:nq], _with(u, i, z[-1] * scale[-1]))
        found = locate_singular(model, start[0], start[1], p, L, np.eye(len(u))[i])
        ul = found[1][i] if found is not None else 0.5 * (z[-1] + zn[-1]) * scale[-1]
        return ul, ul
    z = w.at[0]
    return z[-1] * scale[-1], None


def _with(u, i, v):
    u = np.array(u, float)
    u[i] = v
    return u


def _curve_tangent(model, q, u, p, i, scale):
    """Unit null vector of [g_q g_ui] in scaled coordinates: the branch's direction."""
    _, J, Ju = model._tangent(q, u, p)
    G = np.hstack([J, Ju[:, [i]]]) * scale
    return np.linalg.svd(G)[2][-1]


def _correct(model, zp, t, u, p, L, i, scale, max_iter=ARC_ITER):
    """Newton on [g(z) = 0; t.(z - zp) = 0] (pseudo-arclength corrector): the one Newton
    (kincas/core/newton.py) in z (angles as they are, lengths over L), g against each
    group's length. None where it does not converge within `max_iter` or lands more than
    half a unit from the prediction (another part of the curve)."""
    nq = model.nq
    eq, _ = model.scales(u, p)

    def F(z):
        g, J, Ju = model._tangent(z[:nq] * scale[:nq], _with(u, i, z[-1] * scale[-1]), p)
        return np.r_[g.ravel(), t @ (z - zp)], np.vstack([np.hstack([J, Ju[:, [i]]]) * scale, t])

    res = newton(F, zp, np.ones(len(zp)), np.r_[eq, 1.0], max_iter=max_iter, max_step=MAX_STEP)
    if not res.ok or res.iterations >= max_iter or not np.abs(res.x - zp).max() <= ARC_WANDER:
        return None
    return res.x
