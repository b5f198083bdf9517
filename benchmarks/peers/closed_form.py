"""Closed forms of dyad chains: vectorised numpy (the speed limit) and 30-digit mpmath (the reference).

A chain is solved by successive constructions (`Case.steps`), each placing one point from
points already placed:
- crank: A = O + r (cos t, sin t), V_A = omega r (-sin t, cos t);
- "rrr"/"tri" (P, A1, A2, r1, r2, side): the intersection of the circles (A1, r1), (A2, r2)
  on the `side` of the line A1 -> A2 (+1: left). Its velocity solves the two differentiated
  distance equations (P - A1).(V - V1) = 0, (P - A2).(V - V2) = 0 by Cramer's rule;
- "rrp" (P, A, r, T, angle, side): P = T + s u on a ground line with |P - A| = r, the larger s
  for side +1; s' = (P - A).V_A / ((P - A).u);
- "translate" (P, A, dx, dy): P = A + (dx, dy), V = V_A (a parallelogram's coupler);
- "cross" (P, A1, A2, dx, dy): A1 + (dx, dy) reflected across the line A1 -> A2 (an
  antiparallelogram's crossed coupler, whose side of A1 -> A2 changes at every change point);
  its velocity by Cramer's rule as for "rrr" (both distances are kept by the reflection).
Where a point cannot be placed (no real intersection) its values are NaN.

The same code runs on numpy arrays (all poses at once) and on mpmath numbers (one pose at a
time, 30 digits), so the reference is the closed form itself carried far beyond float64.

>>> import cases
>>> c = cases.fourbar(8)
>>> P, V = reference(c)
>>> bool(np.allclose(np.hypot(*(P["B"] - P["A"]).T), 3.5, atol=1e-14))
True
"""
from __future__ import annotations

import math

import numpy as np

from . import Run

NAME = "closed form, numpy"


class _NP:
    sqrt, cos, sin = staticmethod(np.sqrt), staticmethod(np.cos), staticmethod(np.sin)


class _MP:
    def __init__(self, mp):
        self.mp = mp
        self.cos, self.sin = mp.cos, mp.sin

    def sqrt(self, x):
        return self.mp.sqrt(x) if x >= 0 else self.mp.nan


def chain(case, theta, omega, M):
    """Positions and velocities {point: (x, y)} of every placed point (arrays or mp numbers)."""
    o, a, r = case.crank
    zero = 0 * theta
    P = {g: (xy[0] + zero, xy[1] + zero) for g, xy in case.ground.items()}
    V = {g: (zero, zero) for g in case.ground}
    c, s = M.cos(theta), M.sin(theta)
    P[a] = (P[o][0] + r * c, P[o][1] + r * s)
    V[a] = (-omega * r * s, omega * r * c)
    for step in case.steps:
        kind, p = step[0], step[1]
        if kind in ("rrr", "tri", "cross"):
            (x1, y1), (x2, y2) = P[step[2]], P[step[3]]
            a1, a2 = step[2], step[3]
            dx, dy = x2 - x1, y2 - y1
            d2 = dx * dx + dy * dy
            d = M.sqrt(d2)
            ex, ey = dx / d, dy / d
            if kind == "cross":  # w = (wx, wy) reflected across e: 2 (w.e) e - w
                wx, wy = step[4], step[5]
                wd = wx * ex + wy * ey
                px, py = x1 + 2 * wd * ex - wx, y1 + 2 * wd * ey - wy
            else:
                _, _, _, _, r1, r2, side = step
                along = (d2 + r1 * r1 - r2 * r2) / (2 * d)
                h = M.sqrt(r1 * r1 - along * along)
                px, py = x1 + along * ex - side * h * ey, y1 + along * ey + side * h * ex
            ax, ay, bx, by = px - x1, py - y1, px - x2, py - y2
            ra = ax * V[a1][0] + ay * V[a1][1]
            rb = bx * V[a2][0] + by * V[a2][1]
            det = ax * by - ay * bx
            P[p], V[p] = (px, py), ((ra * by - ay * rb) / det, (ax * rb - bx * ra) / det)
        elif kind == "rrp":
            _, _, a1, rr, t, ang, side = step
            ux, uy = math.cos(ang), math.sin(ang)
            wx, wy = P[a1][0] - P[t][0], P[a1][1] - P[t][1]
            along, across = wx * ux + wy * uy, wx * uy - wy * ux
            sl = along + side * M.sqrt(rr * rr - across * across)
            px, py = P[t][0] + sl * ux, P[t][1] + sl * uy
            qx, qy = px - P[a1][0], py - P[a1][1]
            sdot = (qx * V[a1][0] + qy * V[a1][1]) / (qx * ux + qy * uy)
            P[p], V[p] = (px, py), (sdot * ux, sdot * uy)
        elif kind == "translate":
            _, _, a1, dx, dy = step
            P[p], V[p] = (P[a1][0] + dx, P[a1][1] + dy), V[a1]
        else:
            raise ValueError(f"unknown construction {kind!r}")
    return P, V


def solve_numpy(case, theta=None, steps=None):
    """All poses at once in float64: {point: (N, 2)} positions and velocities."""
    from dataclasses import replace
    c = case if steps is None else replace(case, steps=steps)
    theta = case.theta if theta is None else theta
    with np.errstate(invalid="ignore", divide="ignore"):
        P, V = chain(c, theta, case.omega, _NP)
    return ({k: np.stack(v, axis=-1) for k, v in P.items()},
            {k: np.stack(v, axis=-1) for k, v in V.items()})


def reference(case, steps=None, dps: int = 30):
    """The reference: the closed form (or, for a class-III chain, Newton's method) in mpmath at
    `dps` digits, rounded to float64 at the end. {point: (N, 2)} positions and velocities."""
    if case.steps is None and steps is None:
        from .mp_newton import reference as newton_reference
        return newton_reference(case, dps=dps)
    import mpmath
    from dataclasses import replace
    c = case if steps is None else replace(case, steps=steps)
    n = len(case.theta)
    names = list(case.ground) + list(case.moving)
    P = {k: np.full((n, 2), np.nan) for k in names}
    V = {k: np.full((n, 2), np.nan) for k in names}
    with mpmath.workdps(dps):
        M, om = _MP(mpmath.mp), mpmath.mpf(case.omega)
        for i, t in enumerate(case.theta):
            Pi, Vi = chain(c, mpmath.mpf(float(t)), om, M)
            for k in names:
                P[k][i] = [float(Pi[k][0]), float(Pi[k][1])]
                V[k][i] = [float(Vi[k][0]), float(Vi[k][1])]
    return P, V


# --- the numpy closed form as a timed tool ---


def available():
    return None


def supports(case):
    return None if case.steps is not None else "no closed form: a class-III chain is solved as a whole"


def prepare(case):
    outs = case.outputs

    def run():
        P, V = solve_numpy(case)
        ok = np.all([np.isfinite(P[k]).all(axis=1) for k in outs], axis=0)
        return Run({k: P[k] for k in outs}, {k: V[k] for k in outs}, ok)
    return run
