"""One damped Newton method for every solver of kincas.

`newton(F, x, step_scale, res_scale)` solves F(x) = 0 for a system with exact Jacobian:
square (an Assur group: Newton), tall and consistent (redundant joints: Gauss-Newton, which
converges quadratically where the residual at the solution is zero and J has full column
rank) or wide (an assembly with free inputs: the minimum-norm step). Steps are computed in
scaled unknowns z = x / step_scale (angles as they are, lengths over their group's length),
limited to `MAX_STEP` per coordinate (a trust region that keeps a step on its branch) and
backtracked until the residual max |F / res_scale| decreases. It stops by the compiled
kernel's rule (kincas/core/kernel.py): converged when the residual is below `ACCEPT` and
the next step below `TOL` (scaled), and that negligible step is applied, so the careful and
the fast paths both end at rounding. It also stops when the residual is below `TOL` but the
step is not negligible (g_q nearly singular: the step would be magnified rounding), or when
no step makes progress (a non-solution); a result counts as solved below `ACCEPT`
(kincas/core/tolerances.py).

>>> import numpy as np
>>> F = lambda x: (np.array([x[0] ** 2 - 2.0]), np.array([[2 * x[0]]]))
>>> r = newton(F, np.array([1.0]), np.ones(1), np.ones(1))
>>> r.ok, bool(abs(r.x[0] - 2 ** 0.5) < 1e-15), r.iterations <= 6
(True, True, True)
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .tolerances import ACCEPT, BACKTRACK, DECREASE, MAX_ITER, MAX_STEP, TOL


def lsolve(J, b):
    """J^-1 b; least squares where J is tall (redundant joints), wide (minimum norm) or singular.

    >>> lsolve(np.array([[2.0, 0], [0, 4]]), np.array([1.0, 1.0])).tolist()
    [0.5, 0.25]
    """
    if J.shape[0] == J.shape[1]:
        try:
            return np.linalg.solve(J, b)
        except np.linalg.LinAlgError:
            pass
    return np.linalg.lstsq(J, b, rcond=None)[0]


@dataclass
class NewtonResult:
    """The last iterate `x`, its relative residual, the iterations taken (`max_iter` when it
    stopped short of `tol`), whether it is solved (residual <= ACCEPT), F and J there."""

    x: np.ndarray
    residual: float
    iterations: int
    ok: bool
    g: np.ndarray
    J: np.ndarray


def newton(F, x, step_scale, res_scale, *, tol: float = TOL, accept: float = ACCEPT,
           max_iter: int = MAX_ITER, max_step: float = MAX_STEP) -> NewtonResult:
    """Damped Newton (Gauss-Newton where J is not square) on F(x) = 0.

    Parameters
    ----------
    F : callable
        x -> (g, J): residual vector and its exact Jacobian (numpy arrays, not kept by F).
    x : numpy.ndarray
        The start.
    step_scale : numpy.ndarray
        Per unknown, the unit of a step (1 for an angle, a length for a length).
    res_scale : numpy.ndarray
        Per equation, the length its residual is measured against.
    tol : float
        A next step (scaled) below this, at a residual below `accept`, is the last.
    accept : float
        The largest residual of a solved result.
    max_iter, max_step : int, float
        Iterations at most; the largest step per scaled coordinate.

    Returns
    -------
    NewtonResult

    Examples
    --------
    Two circles of radius 1 about (0, 0) and (1, 0) meet at (1/2, sqrt(3)/2):

    >>> def F(x):
    ...     g = np.array([x @ x - 1, (x[0] - 1) ** 2 + x[1] ** 2 - 1])
    ...     return g, np.array([2 * x, [2 * (x[0] - 1), 2 * x[1]]])
    >>> r = newton(F, np.array([0.3, 1.0]), np.ones(2), np.ones(2))
    >>> bool(np.abs(r.x - [0.5, 3 ** 0.5 / 2]).max() < 1e-13), r.ok
    (True, True)
    """
    x = np.array(x, dtype=float)
    g, J = F(x)
    r = _size(g, res_scale)
    for it in range(max_iter):
        dz = lsolve(J * step_scale, -g) if r > 0 else np.zeros_like(x)
        if not np.all(np.isfinite(dz)):
            break
        if r <= accept and np.abs(dz).max(initial=0.0) <= tol:
            # the compiled kernel's rule (kincas/core/kernel.py): converged when the next
            # step is negligible; apply it, so a solve ends where quadratic convergence puts
            # it (rounding), not at the residual that passed the test
            return NewtonResult(x + dz * step_scale, r, it + 1, True, g, J)
        if r <= tol:
            # the residual is at its target but the step is not negligible: g_q is (nearly)
            # singular, so the step is rounding magnified; stay where the residual is
            return NewtonResult(x, r, it, True, g, J)
        dx = dz * (step_scale / max(1.0, np.abs(dz).max() / max_step))  # the trust region
        t = 1.0
        while True:  # backtrack until the residual decreases
            xn = x + t * dx
            gn, Jn = F(xn)
            rn = _size(gn, res_scale)
            if rn < (1 - DECREASE * t) * r or rn <= tol or t < BACKTRACK:
                break
            t /= 2
        if not rn < r and rn > tol:
            break  # no progress: stagnation at a non-solution (or at rounding level)
        x, g, J, r = xn, gn, Jn, rn
    return NewtonResult(x, r, max_iter, r <= accept, g, J)


def _size(g, res_scale) -> float:
    r = np.abs(g / res_scale).max(initial=0.0)
    return float(r) if np.isfinite(r) else np.inf
