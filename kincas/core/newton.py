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
the fast paths both end at rounding. Next to a singular position (g_q nearly singular) the
steps may never get below TOL, rounding magnified by 1 / sigma_min: there it stops, solved,
once the step no longer shrinks (by `SHRINK` at least: quadratically at a regular root, by
half onto a double root), that is at rounding, whatever the residual; a small residual
alone is no test there (an error e leaves a residual of only sigma_min e). It also stops
where no step lowers the residual (a non-solution, or rounding), after trying the
least-squares step that leaves a null direction of g_q alone (g_q singular to rounding: a
change point met exactly); a result counts as solved below `ACCEPT`
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

from .tolerances import ACCEPT, BACKTRACK, DECREASE, MAX_ITER, MAX_STEP, RANK, SHRINK, TOL


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


def stop_rule(r, size, last=np.inf, *, accept: float = ACCEPT, tol: float = TOL):
    """The one stopping rule of kincas's Newton iterations, elementwise (a batch of poses, or
    one): (converged, stalled) for a residual `r` (max |g| over its scale), the next Newton
    step's `size` (largest scaled entry) and the size of the last full step `last`.

    converged: solved (r <= accept) and the next step negligible (<= tol): apply that step
    and stop, so a solve ends where quadratic convergence puts it (rounding), as the
    compiled kernel does (kincas/core/kernel.py). stalled: solved and the step no longer
    shrinks (not below SHRINK times the last one): rounding, magnified by 1 / sigma_min next
    to a singular position; stop without it. `newton` below, `scatter.newton_starts` and
    the designs' batched loops (kincas/analysis/design_job.py) all stop by it.

    >>> [bool(b) for b in stop_rule(1e-12, 1e-14)], [bool(b) for b in stop_rule(1e-12, 1e-9, 1e-9)]
    ([True, False], [False, True])
    >>> stop_rule(np.array([1e-12, 1e-6]), np.array([1e-14, 1e-14]))[0].tolist()
    [True, False]
    """
    solved = np.asarray(r) <= accept
    return solved & (np.asarray(size) <= tol), solved & (np.asarray(size) > SHRINK * np.asarray(last))


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
    last = np.inf  # the last full Newton step's size (scaled)
    for it in range(max_iter):
        dz = lsolve(J * step_scale, -g) if r > 0 else np.zeros_like(x)
        if not np.all(np.isfinite(dz)):
            break
        size = np.abs(dz).max(initial=0.0)
        converged, stalled = stop_rule(r, size, last, accept=accept, tol=tol)
        if converged:
            # the compiled kernel's rule (kincas/core/kernel.py): converged when the next
            # step is negligible; apply it, so a solve ends where quadratic convergence puts
            # it (rounding), not at the residual that passed the test
            return NewtonResult(x + dz * step_scale, r, it + 1, True, g, J)
        if stalled:
            # Solved, and the step no longer shrinks. Steps shrink quadratically at a
            # regular root, by half per step onto a double root (a limit), and stop
            # shrinking only once they are rounding magnified by 1 / sigma_min(g_q) (next
            # to a singular position that is well above TOL): this is as close as rounding
            # allows. (A small residual alone says little there: an error e in q leaves a
            # residual of sigma_min e, so stopping at it left a pose 1e-8 from a limit
            # 5e-10 off, where 3e-12 is the rounding limit.)
            return NewtonResult(x, r, it, True, g, J)
        t, xn, gn, Jn, rn = _search(F, x, dz, step_scale, r, res_scale, max_step)
        if not rn < r:
            # No progress. Where g_q is singular to rounding (a change point or a limit met
            # exactly) the Newton step is rounding magnified along the null direction: the
            # least-squares step that leaves that direction alone may still progress
            dz, _, rank, _ = np.linalg.lstsq(J * step_scale, -g, rcond=RANK)
            if rank == min(J.shape) or not np.all(np.isfinite(dz)):
                break  # stagnation at a non-solution, or at rounding level
            t, xn, gn, Jn, rn = _search(F, x, dz, step_scale, r, res_scale, max_step)
            if not rn < r:
                break
            t = 0.0  # not a Newton step: the next is not expected to be smaller
        # a full step is the one whose successor is expected to shrink (a damped step
        # leaves part of itself for the next)
        last = size if t == 1.0 else np.inf
        x, g, J, r = xn, gn, Jn, rn
    return NewtonResult(x, r, max_iter, r <= accept, g, J)


def _search(F, x, dz, step_scale, r, res_scale, max_step):
    """The step dz (scaled) within the trust region, halved until the residual decreases:
    (its fraction t, 1 for the whole step; the point, g, J and residual there)."""
    size = np.abs(dz).max(initial=0.0)
    scale = max(1.0, size / max_step)  # the trust region
    dx = dz * (step_scale / scale)
    t = 1.0
    while True:
        xn = x + t * dx
        gn, Jn = F(xn)
        rn = _size(gn, res_scale)
        if rn < (1 - DECREASE * t) * r or t < BACKTRACK:
            return t / scale, xn, gn, Jn, rn
        t /= 2


def _size(g, res_scale) -> float:
    r = np.abs(g / res_scale).max(initial=0.0)
    return float(r) if np.isfinite(r) else np.inf
