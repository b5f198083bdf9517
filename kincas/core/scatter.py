"""Many solves in one vectorised CasADi call: Newton from scattered starts (assembly modes)
and from a first-order predictor over parameter samples (tolerance Monte Carlo).

Both are the scatter phase of their analysis: what they accept is measured with the same
per-group residual as the careful Newton (`Model.scales`, kincas/core/tolerances.py), and
what they do not accept goes through the careful Newton (kincas/core/newton.py).

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

from .tolerances import MAX_STEP, TOL


# --- Newton from every start at once ---


def _step_function(model) -> ca.Function:
    """(q, u, p, eq_scale, q_scale) -> (q after one Newton step, relative residual at q).

    The step solves g_q dq = -g with the exact Jacobian and is shortened so that no unknown
    moves by more than MAX_STEP of its scale (radians, or its group's length): a trust region
    that keeps a start from being thrown across the workspace by a near-singular Jacobian.
    Where g_q is singular the step is NaN and that start is dropped."""
    def build():
        sym = model.sym
        eq, qs = ca.SX.sym("eq", sym.ng), ca.SX.sym("qs", sym.nq)
        dq = -ca.solve(sym.Jq, sym.g)
        shrink = ca.fmax(1, ca.mmax(ca.fabs(dq) / (MAX_STEP * qs))) if sym.nq else ca.SX(1)
        r = ca.mmax(ca.fabs(sym.g / eq)) if sym.nq else ca.SX(0)
        return ca.Function("newton_step", [sym.q, sym.u, sym.p, eq, qs], [sym.q + dq / shrink, r])
    return model.memo("scatter.newton_step", build)


def newton_starts(model, Q, u, p, iterations: int):
    """Trust-region Newton on every row of Q (starts, n x nq) at once, at inputs u and
    parameters p; returns the iterates and their relative residuals (NaN where a start
    diverged). A start stops where its residual reaches TOL.

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
    U, P = np.tile(np.reshape(u, (-1, 1)), n), np.tile(np.reshape(p, (-1, 1)), n)
    X, r = Q.T.copy(), np.full(n, np.inf)
    for _ in range(iterations):
        Xn, rn = (np.asarray(a) for a in step(X, U, P, eq, qs))
        r = rn.ravel()
        done = ~np.isfinite(r) | (r <= TOL)
        X = np.where(done, X, Xn)  # a converged start stays where it is
        if done.all():
            break
    r = np.where(np.all(np.isfinite(X), axis=0), r, np.nan)
    return X.T, r


# --- parameter samples: predictor and Newton steps ---


def sample_function(model, report: tuple[str, ...], newton_steps: int) -> ca.Function:
    """F(q0, u, p0, dp, u', u'', eq_scale) -> (q, relative residual, g_q, quantities): from the
    nominal pose q0 a first-order predictor along dq/dp = -g_q^-1 g_p, then `newton_steps`
    Newton steps with the exact Jacobian, all as one CasADi expression graph (map it over
    samples); the residual is max |g / eq_scale| as everywhere in the core."""
    return model.memo(("scatter.sample", report, newton_steps),
                      lambda: _build_sample_function(model, report, newton_steps))


def _build_sample_function(model, report, newton_steps):
    sym = model.sym
    q0, u, p0, dp = (ca.SX.sym(n, k) for n, k in
                     (("q0", sym.nq), ("u", sym.nu), ("p0", sym.np), ("dp", sym.np)))
    ud, udd, eq = ca.SX.sym("ud", sym.nu), ca.SX.sym("udd", sym.nu), ca.SX.sym("eq", sym.ng)
    p = p0 + dp
    gp = ca.Function("gp", [sym.q, sym.u, sym.p], [ca.jacobian(sym.g, sym.p)])
    if sym.nq:
        # Predictor: the tangent of the solution manifold, dq/dp = -g_q^-1 g_p, at the nominal.
        _, J0 = sym.f_resjac(q0, u, p0)
        q = q0 - ca.solve(J0, ca.mtimes(gp(q0, u, p0), dp))
        for _ in range(newton_steps):  # Newton with the exact Jacobian: g_q dq = -g
            g, J = sym.f_resjac(q, u, p)
            q = q - ca.solve(J, g)
        g, J = sym.f_resjac(q, u, p)
        r = ca.mmax(ca.fabs(g / eq))
    else:
        q, J, r = ca.SX(0, 1), ca.SX(0, 0), ca.SX(0)
    vals = model.quantity_function(report)(q, u, p, ud, udd)
    return ca.Function("tolerance_sample", [q0, u, p0, dp, ud, udd, eq], [q, r, ca.vec(J), vals])
