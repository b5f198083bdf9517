"""Newton from many scattered starts in one vectorised CasADi call (assembly modes).

This is the scatter phase of `kincas modes`: what it accepts is measured with the same
per-group residual as the careful Newton (`Model.scales`, kincas/core/tolerances.py), and
what it finds is polished by the careful Newton (kincas/core/newton.py).

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)], inputs=[kincas.Input.angle("crank")])
>>> model = kincas.model_of(m)
>>> Q, r = newton_starts(model, np.array([[1.0, 2.0], [-1.0, -2.0]]), np.array([0.5]), np.zeros(0), 60)
>>> bool(np.all(r <= 1e-13))
True
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from .newton import stop_rule
from .tolerances import MAX_STEP


# --- Newton from every start at once ---


def _step_function(model) -> ca.Function:
    """(q, u, p, eq_scale, q_scale) -> (q after one Newton step, relative residual at q, the
    step's largest entry over its unknown's scale before it is shortened).

    The step solves g_q dq = -g with the exact Jacobian and is shortened so that no unknown
    moves by more than MAX_STEP of its scale (radians, or its group's length): a trust region
    that keeps a start from being thrown across the workspace by a near-singular Jacobian.
    Where g_q is singular the step is NaN and that start is dropped."""
    def build():
        sym = model.sym
        eq, qs = ca.SX.sym("eq", sym.ng), ca.SX.sym("qs", sym.nq)
        if sym.ng > sym.nq:  # a tall consistent system (redundant joints: Bennett, a double
            # Cardan): the Gauss-Newton step, each equation over its scale, which is Newton's
            # step wherever the equations are consistent and g_q has full column rank. The
            # normal matrix is dense: this function gives it, and numpy solves it for every
            # start at once (a symbolic 21 x 21 solve made each call of 512 starts 0.24 s; a
            # numeric solver inside casadi failed the whole call at one start's singular matrix)
            Js, gs = sym.Jq / ca.repmat(eq, 1, sym.nq), sym.g / eq
            return ca.Function("normal", [sym.q, sym.u, sym.p, eq, qs],
                               [ca.mtimes(Js.T, Js), ca.mtimes(Js.T, gs), ca.mmax(ca.fabs(gs))])
        dq = -ca.solve(sym.Jq, sym.g)
        size = ca.mmax(ca.fabs(dq) / qs) if sym.nq else ca.SX(0)
        shrink = ca.fmax(1, size / MAX_STEP)
        r = ca.mmax(ca.fabs(sym.g / eq)) if sym.nq else ca.SX(0)
        return ca.Function("newton_step", [sym.q, sym.u, sym.p, eq, qs], [sym.q + dq / shrink, r, size])
    return model.memo("scatter.newton_step2", build)


def newton_starts(model, Q, u, p, iterations: int):
    """Trust-region Newton on every row of Q (starts, n x nq) at once, at inputs u and
    parameters p; returns the iterates and their relative residuals (NaN where a start
    diverged). Each start stops by the one rule of kincas/core/newton.py (`stop_rule`):
    solved and its next step negligible (applied), or solved and its steps no longer
    shrinking (rounding next to a singular position).

    Parameters
    ----------
    model : kincas.core.numeric.Model
    Q : numpy.ndarray
        One start per row.
    u, p : numpy.ndarray
        Inputs and parameters (the same for every start).
    iterations : int
        Newton steps at most.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        The iterates (n x nq) and their residuals, each equation relative to its group.
    """
    n = Q.shape[0]
    eq, qs = model.scales(u, p)
    if model.nq == 0:
        return Q, np.full(n, np.abs(model.residual(np.zeros(0), u, p) / eq).max(initial=0.0))
    step = _step_function(model).map(n)
    if model.sym.ng > model.sym.nq:
        step = _gauss_newton(step, model.sym.nq, n)
    U, P = np.tile(np.reshape(u, (-1, 1)), n), np.tile(np.reshape(p, (-1, 1)), n)
    X, last, live = Q.T.copy(), np.full(n, np.inf), np.ones(n, dtype=bool)
    for _ in range(iterations):
        Xn, r, size = step(X, U, P, eq, qs)
        Xn, r, size = np.asarray(Xn), np.asarray(r).ravel(), np.asarray(size).ravel()
        converged, stalled = stop_rule(r, size, last)
        bad = ~np.isfinite(r)  # (a NaN step, g_q singular, is taken: the start is dropped)
        X = np.where(live & ~stalled & ~bad, Xn, X)  # a converged start takes its last step
        last = np.where(size <= MAX_STEP, size, np.inf)  # a full step: the next should shrink
        live &= ~(converged | stalled | bad)
        if not live.any():
            break
    r = np.asarray(step(X, U, P, eq, qs)[1]).ravel()  # at the iterates returned
    r = np.where(np.all(np.isfinite(X), axis=0), r, np.nan)
    return X.T, r


def _gauss_newton(normal, nq: int, n: int):
    """The step function of a tall system from its mapped normal equations: (X, U, P, eq, qs)
    -> (X after one shortened Gauss-Newton step, relative residual, step size), as
    `_step_function` gives a square system's. Each start's (J'J) dq = -J'g solved by numpy at
    once; a start whose normal matrix is singular (or not finite) gets a NaN step: dropped."""
    def step(X, U, P, eq, qs):
        A, b, r = (np.asarray(v) for v in normal(X, U, P, eq, qs))
        A = A.reshape(nq, n, nq).transpose(1, 0, 2)  # (start, row, column)
        b = b.T[:, :, None]
        try:
            dq = -np.linalg.solve(A, b)[:, :, 0]
        except np.linalg.LinAlgError:  # one start's matrix is singular: each on its own
            dq = np.full((n, nq), np.nan)
            for k in range(n):
                try:
                    dq[k] = -np.linalg.solve(A[k], b[k])[:, 0]
                except np.linalg.LinAlgError:
                    pass
        qsv = np.asarray(qs, float).ravel()
        size = np.max(np.abs(dq) / qsv, axis=1) if nq else np.zeros(n)
        shrink = np.fmax(1.0, size / MAX_STEP)
        return X + (dq / shrink[:, None]).T, r, size
    return step
