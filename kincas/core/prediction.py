"""The fast kernel's prediction of the next pose from the last three solved ones.

A sweep solves q(u) pose after pose; each pose starts Newton from a prediction, and where the
prediction is already converged (its Newton step below STEP) the pose costs one evaluation
(kF) instead of two (kN, kF). The prediction is Hermite's: the polynomial through the last
poses' unknowns with their exact tangents dq/du (which kF computes anyway).

Along the line of the last step, u(t) = u0 + t (u0 - u1) (t = 0 the last pose, t = -1 the
one before, t = -s the one before that, the target at t = l = (u - u0).(u0 - u1) / |u0 - u1|^2),
with f_i = q_i and d_i = T_i (u0 - u1) (the derivative in t):

- the cubic through (0, f0, d0) and (-1, f1, d1): p3(t) = f0 + d0 t + c2 t^2 + E t^3 with
  E = d0 + d1 + 2 (f1 - f0) (the trapezoid rule's defect over the last step, O(h^3)) and
  c2 = 2 d0 + d1 + 3 (f1 - f0); written as the second-order prediction
  q0 + T0 (u - u0) + l/2 (T0 - T1)(u - u0) plus l^2 (l + 3/2) E, so that its linear term
  follows the sweep where it turns (T0 (u - u0), not d0 l). Error O(h^4) on a straight sweep.
- the quintic through the third pose too: p5 = p3 + w(t) (g + b (t + s)) with
  w(t) = t^2 (t + 1)^2 (zero with its derivative at both nodes of p3, so p5 keeps them), and
  g, b fitted to (f2, d2) at t = -s: with R0 = f2 - p3(-s), R1 = d2 - p3'(-s),
  g = R0 / w(-s), b = (R1 - w'(-s) g) / w(-s). Error O(h^6): on 40 chained four-bars at
  1/6 deg steps 4e-14 against the cubic's 3e-11, so that most poses need no Newton step.

The quintic is used only where it is well posed and its weights stay small (they amplify the
rounding of q): the step before the last between QUINTIC_RATIO times the last (s - 1 in that
range), the target at most QUINTIC_REACH steps ahead, the three inputs on one line; else the
cubic alone (a first or second step, with repeated poses, reads the cubic's own fallbacks:
l = 0 where u0 = u1). Uniform steps (s = 2, l = 1) give p5(1) = p3(1) + 10 R0 + 3 R1.

Both are kernel functions (kincas/core/kernel.py: kP the cubic, kP5 the quintic): the quintic
costs about three times the cubic's arithmetic, so the C loop (and the virtual machine alike)
runs it only where it pays: where the cubic's error at the last pose (the correction Newton
made to it, or under the quintic p5 - p3) lay between QUINTIC_ON (below, the cubic is
converged already, and amplifies the rounding of the solved poses less: a dense sweep's
prediction, and so its quantities, stay at the cubic's rounding, ~1e-15) and QUINTIC_TRY (above, the quintic would miss by more than STEP too, and
Newton is needed either way: a four-bar at 1 deg steps).

>>> import casadi as ca, numpy as np
>>> f = lambda t: np.array([np.sin(t), t ** 5])  # two "unknowns" of one input
>>> df = lambda t: np.array([[np.cos(t)], [5 * t ** 4]])
>>> h, t0 = 0.01, 0.3
>>> pose = lambda t: (df(t), [t], f(t))  # (T, u, q)
>>> def predicted(*poses):
...     (T0, u0, q0), (T1, u1, q1), (T2, u2, q2) = poses
...     args = [q0, T0, u0, [t0 + h], T1, u1, q1, T2, u2, q2]
...     return np.asarray(ca.evalf(quintic(*[ca.DM(a) for a in args])[0])).ravel() - f(t0 + h)
>>> fifth = predicted(pose(t0), pose(t0 - h), pose(t0 - 2 * h))
>>> third = predicted(pose(t0), pose(t0 - h), pose(t0 - h))  # no third pose: the cubic
>>> bool(abs(fifth[1]) < 1e-16 and abs(fifth[0]) < 1e-13 < 1e-10 < abs(third[0]))
True
"""
from __future__ import annotations

import casadi as ca

from .tolerances import QUINTIC_REACH, QUINTIC_RATIO, STRAIGHT


def _along(u0, u, u1):
    """(du, dup, dd, safe, l): the step u - u0, the last step u0 - u1, its square |dup|^2,
    that square or 1 where it is 0 (a first step), and l = du.dup / safe, the step in units
    of the last along its line. Written without if_else: casadi would carry an if_else into
    every unknown's expression that l multiplies."""
    du, dup = u - u0, u0 - u1
    dd = ca.dot(dup, dup)
    safe = dd + (dd == 0)
    return du, dup, dd, safe, ca.dot(du, dup) / safe


def _times(T, v):
    """T v (T an nq x nu matrix, v an nu-vector) summed in the order the C loop sums it
    (kincas/core/sweep_loop.py SWEEP_C): T[:, 0] v[0] + T[:, 1] v[1] + ..., so that both give the
    same numbers."""
    t = T[:, 0] * v[0]
    for j in range(1, v.numel()):
        t = t + T[:, j] * v[j]
    return t


def cubic_weights(u0, u, u1):
    """(v0, v1, c): the cubic's scalars, p3 = q0 + T0 v0 + T1 v1 - c (q0 - q1) (see the
    module text): q0 + T0 du + l/2 (T0 - T1) du + c3 E with E = (T0 + T1) dup - 2 (q0 - q1),
    gathered per tangent, c = 2 c3."""
    du, dup, _, _, lam = _along(u0, u, u1)
    c3 = lam * lam * (lam + 1.5)
    return du * (1 + 0.5 * lam) + c3 * dup, c3 * dup - (0.5 * lam) * du, 2 * c3


def quintic_weights(u0, u, u1, u2):
    """(use, w1, w2, e0, e1, e2): whether the quintic applies (1 or 0) and the scalars of its
    correction p5 - p3 = w1 (q1 - q0) + w2 (q2 - q0) + T0 e0 + T1 e1 + T2 e2 (see the module
    text; finite whether or not it applies)."""
    _, dup, dd, safe, lam = _along(u0, u, u1)
    # the third pose at t = -s on the line of the last step, s = 1 + (the step before) / (the last)
    back = u0 - u2
    s = ca.dot(back, dup) / safe
    off = back - s * dup  # off the line: the sweep turned (nothing to fit along it)
    lo, hi = 1 + QUINTIC_RATIO[0], 1 + QUINTIC_RATIO[1]
    use = ca.logic_and(ca.logic_and(dd > 0, ca.logic_and(s >= lo, s <= hi)),
                       ca.logic_and(ca.logic_and(lam >= 0, lam <= QUINTIC_REACH),
                                    ca.dot(off, off) <= STRAIGHT ** 2 * s * s * dd))
    s = ca.if_else(use, s, 2)  # (a value where w(-s) != 0: the weights below stay finite)
    ws, dws = s * s * (s - 1) ** 2, -2 * s * (1 - s) * (1 - 2 * s)  # w(-s), w'(-s)
    wl = lam * lam * (lam + 1) ** 2
    # p5(l) - p3(l) = w(l) (g + b (l + s)) = A R0 + B R1, A and B scalars
    A = wl * (1 / ws - (lam + s) * dws / (ws * ws))
    B = wl * (lam + s) / ws
    # R0 = f2 - p3(-s) and R1 = d2 - p3'(-s) are linear in (f1 - f0, f2 - f0, d0, d1, d2)
    # (p3's c2 and E written out), so A R0 + B R1 is too: its five weights are scalars,
    # computed once, and each unknown costs five multiply-adds. Relative to q0 (q1 - q0 and
    # q2 - q0 are exact where the poses are close): no rounding at the size of q inside.
    s2, s3 = s * s, s * s * s
    w1 = A * (2 * s3 - 3 * s2) + B * (6 * s - 6 * s2)  # f1 - f0
    wd0 = A * (s3 - 2 * s2 + s) + B * (4 * s - 3 * s2 - 1)
    wd1 = A * (s3 - s2) + B * (2 * s - 3 * s2)
    # (at even steps the correction is 4 (f1 - f0) + 10 (f2 - f0) + 5 d0 + 16 d1 + 3 d2: these
    # weights amplify the rounding of the solved q's about four times more than the cubic's,
    # which is why the quintic runs only where the cubic misses by more than that: QUINTIC_ON)
    return use, w1, A, wd0 * dup, wd1 * dup, B * dup


def cubic(q0, T0, u0, u, T1, u1, q1):
    """The unknowns predicted at input u by the cubic through the last two poses (q_i,
    T_i = dq/du, u_i), newest first (see the module text); casadi expressions (SX or DM).
    Each unknown: ((q0 + T0 v0) + T1 v1) - c (q0 - q1), in this order, as the C loop."""
    v0, v1, c = cubic_weights(u0, u, u1)
    return ((q0 + _times(T0, v0)) + _times(T1, v1)) - c * (q0 - q1)


def quintic(q0, T0, u0, u, T1, u1, q1, T2, u2, q2, scale=1):
    """(prediction, miss): the unknowns predicted at input u from the last three poses
    (q_i, T_i = dq/du, u_i), newest first, by the quintic where it applies, else the cubic
    (see the module text), and max |p5 - p3| / scale, the cubic's error as the quintic sees
    it (0 where it does not apply). `scale`: each unknown's (1 for an angle, its group's
    length for a length). Casadi expressions (SX or DM); each unknown's correction summed
    in the C loop's order (kincas/core/sweep_loop.py SWEEP_C)."""
    p3 = cubic(q0, T0, u0, u, T1, u1, q1)
    use, w1, w2, e0, e1, e2 = quintic_weights(u0, u, u1, u2)
    corr = (((w1 * (q1 - q0) + w2 * (q2 - q0)) + _times(T0, e0)) + _times(T1, e1)) + _times(T2, e2)
    miss = ca.mmax(ca.fabs(corr) / scale) if corr.numel() else ca.DM(0)  # the cubic's, scaled
    return ca.if_else(use, p3 + corr, p3), ca.if_else(use, miss, 0)
