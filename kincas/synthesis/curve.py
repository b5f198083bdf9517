"""Path synthesis without prescribed timing: a coupler point nearest to a target curve.

A `Curve` names a moving point P and target points T_1 .. T_n, given in order along the
wanted path but *without* the input values at which P should pass them. In the simultaneous
formulation of `kincas.optimize` those inputs are simply more variables: the sample i has its
pose q_i *and* its input u_i free, and the objective

    sum_i |P(q_i, u_i, p) - T_i|^2,      subject to g(q_i, u_i, p) = 0,

is a smooth function of (p, q_i, u_i), so IPOPT gets exact first and second derivatives. At
an optimum each u_i puts P at a point of the coupler curve locally nearest to T_i (the
derivative along the curve, 2 (P - T_i) . dP/du, vanishes), unless the order is binding.

Order: the u_i follow the targets along the input, `u_1 <= u_2 <= ... <= u_n` ("increasing")
or the reverse ("decreasing"); "auto" (the default) takes the direction in which the initial
design's projections of the targets run, "free" imposes none (each u_i only stays within the
range). The range `within` is the input's interval; a whole turn of an angle input is
periodic: the u_i are then unbounded but span at most one turn, u_n - u_1 <= 2 pi.

Start: the initial design is swept over the range (its guess is its pose at the range's
start), each target is projected onto that coupler curve (the nearest swept pose), and the
u_i and q_i start there, so every sample begins on the initial design's branch.

>>> c = Curve("P", [(0, 1), (1, 0)])
>>> c.point, c.targets.shape, c.order
('P', (2, 2), 'auto')
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError

ORDERS = ("auto", "increasing", "decreasing", "free")
STEPS = 721  # poses of the initial design's sweep onto which the targets are projected
TURN = 2 * math.pi


@dataclass
class Curve:
    """Targets for point `point`, in order along the path, with the inputs left free.

    `targets`: (n, 2) positions; `within`: (low, high) of the single input (radians for an
    angle; default a whole turn from 0 for an angle input); `order`: one of "auto",
    "increasing", "decreasing", "free" (see the module's docstring)."""

    point: str
    targets: np.ndarray
    within: tuple[float, float] | None = None
    order: str = "auto"

    def __post_init__(self):
        t = self.targets
        if not isinstance(t, (list, tuple, np.ndarray)) or not len(t):
            raise ModelError(f"curve: targets: expected a list of [x, y] pairs, got {t!r}")
        for i, xy in enumerate(t):
            if not _pair(xy):
                raise ModelError(f"curve: targets[{i + 1}]: expected [x, y] (finite numbers), "
                                 f"got {xy!r}")
        self.targets = np.asarray(t, dtype=float)
        if self.order not in ORDERS:
            raise ModelError(f"curve: order: expected one of {', '.join(ORDERS)}, got {self.order!r}")
        if self.within is not None:
            w = self.within
            if (not isinstance(w, (tuple, list)) or len(w) != 2 or not all(
                    isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)
                    for x in w) or not w[0] < w[1]):
                raise ModelError(f"curve: within: expected [low, high] with low < high, got {w!r}")
            self.within = (float(w[0]), float(w[1]))


def _pair(p) -> bool:
    return isinstance(p, (list, tuple, np.ndarray)) and len(p) == 2 and all(
        isinstance(x, (int, float, np.floating, np.integer)) and not isinstance(x, bool)
        and math.isfinite(x) for x in p)


# --- the start: the targets projected onto the initial design's coupler curve ---


def start(m, curve: Curve, sweep_fn, rates=None, accelerations=None):
    """The initial sample inputs (one per target) and the sweep of the initial design at
    them, plus (low, high, periodic, direction) for the NLP. ModelError when the point or the
    mechanism do not fit."""
    if len(m.inputs) != 1:
        raise ModelError("curve: needs a mechanism driven by one input")
    inp = m.inputs[0]
    if curve.point not in m.moving_points:
        raise ModelError(f"curve: point: {curve.point!r} is not a moving point (expected one "
                         f"of {', '.join(m.moving_points)})")
    within = curve.within or ((0.0, TURN) if inp.is_angle else None)
    if within is None:
        raise ModelError(f"curve: within: give the range of {inp.key} in which to fit")
    lo, hi = within
    periodic = inp.is_angle and hi - lo >= TURN - 1e-9
    names = [f"{curve.point}.x", f"{curve.point}.y"]
    dense = sweep_fn(m, {inp.key: np.linspace(lo, hi, STEPS)}, report=names)
    ok = np.flatnonzero(dense.ok)
    if not len(ok):
        raise ModelError(f"curve: the initial design does not assemble anywhere in {inp.key} "
                         f"from {lo:g} to {hi:g}")
    P = np.stack([dense[n][ok] for n in names], axis=1)
    d2 = ((curve.targets[:, None, :] - P[None, :, :]) ** 2).sum(axis=2)
    near = ok[np.argmin(d2, axis=1)]  # nearest swept pose to each target
    u = dense.inputs[inp.key][near]
    direction = _direction(u, curve.order, periodic)
    u = _ordered(u, direction, periodic)
    # the sweep at the starting inputs begins exactly at the first target's projection
    sw0 = sweep_fn(m, {inp.key: u}, rates=rates, accelerations=accelerations, report=[],
                   guess=_points(m, dense, int(near[0])))
    return sw0, (lo, hi, periodic, direction)


def _points(m, sw, i) -> dict:
    from ..core.numeric import compile

    model = compile(m)
    p = np.array([v for _, v in m.parameters], dtype=float)
    u = np.array([sw.inputs[k][i] for k in sw.inputs])
    pts = model.points(sw.q[i], u, p)
    return {n: tuple(pts[:, j]) for j, n in enumerate(m.moving_points)}


def _direction(u, order, periodic) -> int:
    """+1 increasing, -1 decreasing, 0 free; "auto" follows the projections: the direction
    that covers them with the shorter total travel (cyclic for a whole turn)."""
    if order != "auto":
        return {"increasing": 1, "decreasing": -1, "free": 0}[order]
    d = np.diff(u)
    if periodic:
        up = np.mod(d, TURN).sum()
        down = np.mod(-d, TURN).sum()
    else:
        up, down = -d[d < 0].sum(), d[d > 0].sum()  # travel against each direction
    return 1 if up <= down else -1


def _ordered(u, direction, periodic) -> np.ndarray:
    """Starting inputs that satisfy the order: unwrapped along the turn, then made monotone."""
    u = np.array(u, dtype=float)
    if direction == 0:
        return u
    if periodic:  # each next target one step forwards along the turn, within one turn
        for i in range(1, len(u)):
            u[i] = u[i - 1] + direction * np.mod(direction * (u[i] - u[i - 1]), TURN)
        u = u[0] + np.clip(u - u[0], -TURN, TURN)
    acc = np.maximum.accumulate if direction > 0 else np.minimum.accumulate
    return acc(u)


def constrain(prob, lo, hi, periodic, direction):
    """Make the problem's sample inputs free: bounds, order, and at most one turn."""
    K, inp = prob.K, prob.m.inputs[0]
    scale = 1.0 if inp.is_angle else prob.L
    if periodic:
        lo_, hi_ = np.full(K, -np.inf), np.full(K, np.inf)
    else:
        lo_, hi_ = np.full(K, lo), np.full(K, hi)

    def rows(u):
        out = []
        if direction and K > 1:  # direction * (u_{k+1} - u_k) >= 0, scaled to O(1)
            out.append((direction * (u[1:] - u[:-1]) / scale, 0.0, np.inf))
            if periodic:
                out.append((direction * (u[K - 1] - u[0]), 0.0, TURN))
        elif periodic and K > 1:  # free order on a whole turn: each within a turn of the first
            out.append(((u[1:] - u[0]), -TURN, TURN))
        return out

    # a whole turn: report the fitted inputs with the first in [lo, lo + 2 pi)
    normal = (lambda U: U - TURN * math.floor((U[0, 0] - lo) / TURN)) if periodic else None
    prob.free_inputs(lo_, hi_, rows, scale, normal)


def objective(prob, curve: Curve):
    """sum_i |P(q_i, u_i) - T_i|^2 as an SX of the NLP's variables."""
    return prob.squared_distances(curve.point, curve.targets)


def distances(sw, curve: Curve, at) -> np.ndarray:
    """|P - T_i| at the checked poses `at` of the checking sweep."""
    x, y = sw[f"{curve.point}.x"][at], sw[f"{curve.point}.y"][at]
    return np.hypot(x - curve.targets[:, 0], y - curve.targets[:, 1])
