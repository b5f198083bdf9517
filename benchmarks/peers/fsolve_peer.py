"""scipy.optimize.fsolve, warm-started pose to pose: what a user writes by hand.

The unknowns are the coordinates of the moving points but the crank's tip (which the input
places); the equations are the distances every link keeps, |P - Q|^2 - l^2 = 0 (a triangle
its three sides), and each slide's point on its line, u x (P - T) = 0: the same system as
`mp_newton.py`, here vectorised with numpy index arrays. Each pose starts from the solution
of the one before. With `jacobian=True` fsolve gets the analytic Jacobian (`fprime`),
without it fsolve estimates it by forward differences, as its documentation describes.
fsolve runs with its documented defaults (xtol 1.49e-8). A pose counts as solved when
fsolve reports success (ier == 1).

Velocities: the differentiated equations J v = -(dg/dA) V_A, solved with numpy and the
analytic Jacobian in both variants (a user of fsolve writes them by hand too).

>>> import cases
>>> run = prepare(cases.fourbar(16), jacobian=True)
>>> r = run()
>>> bool(r.ok.all()), r.P["B"].shape
(True, (16, 2))
"""
from __future__ import annotations

import numpy as np

from . import Run, crank_velocity
from .mp_newton import pairs

NAME = "scipy fsolve"


def available():
    from . import module_available
    return module_available("scipy.optimize")


def supports(case):
    return "needs a starting position for every point (the case gives none)" if case.guessless else None


class System:
    """The distance equations of a case, vectorised: residual g(x; A), Jacobian, velocities."""

    def __init__(self, case):
        o, self.tip, _ = case.crank
        self.case = case
        self.free = [p for p in case.moving if p != self.tip]
        # every point gets a row in a (n, 2) table: free points first, then the tip, then ground
        names = self.free + [self.tip] + list(case.ground)
        self.index = {p: i for i, p in enumerate(names)}
        self.table = np.zeros((len(names), 2))
        for g, xy in case.ground.items():
            self.table[self.index[g]] = xy
        cons = pairs(case)
        self.I = np.array([self.index[p] for p, _, _ in cons], dtype=int)
        self.J = np.array([self.index[q] for _, q, _ in cons], dtype=int)
        self.L2 = np.array([l * l for _, _, l in cons])
        self.S = np.array([self.index[p] for p, _, _ in case.slides], dtype=int)
        self.T = np.array([case.ground[t] for _, t, _ in case.slides]).reshape(-1, 2)
        self.U = np.array([(np.cos(a), np.sin(a)) for _, _, a in case.slides]).reshape(-1, 2)
        self.nf, self.nc, self.ns = len(self.free), len(cons), len(case.slides)

    def _fill(self, x, A):
        self.table[:self.nf] = x.reshape(-1, 2)
        self.table[self.nf] = A
        return self.table

    def residual(self, x, A):
        t = self._fill(x, A)
        d = t[self.I] - t[self.J]
        g = np.empty(self.nc + self.ns)
        g[:self.nc] = (d * d).sum(axis=1) - self.L2
        w = t[self.S] - self.T
        g[self.nc:] = self.U[:, 0] * w[:, 1] - self.U[:, 1] * w[:, 0]
        return g

    def jacobian(self, x, A):
        """dg/dx (square) and, for the velocities, the rows' gradients with respect to A."""
        t = self._fill(x, A)
        d = 2 * (t[self.I] - t[self.J])
        full = np.zeros((self.nc + self.ns, len(self.table), 2))
        rows = np.arange(self.nc)
        full[rows, self.I] += d
        full[rows, self.J] -= d
        srows = self.nc + np.arange(self.ns)
        full[srows, self.S, 0] = -self.U[:, 1]
        full[srows, self.S, 1] = self.U[:, 0]
        return full[:, :self.nf].reshape(len(full), -1), full[:, self.nf]

    def velocity(self, x, A, VA):
        Jx, JA = self.jacobian(x, A)
        return np.linalg.solve(Jx, -JA @ VA)


def prepare(case, jacobian: bool = True):
    from scipy.optimize import fsolve

    sysm = System(case)
    x0 = np.array([c for p in sysm.free for c in case.guess[p]], dtype=float)
    o, tip, r = case.crank
    pivot = np.asarray(case.ground[o], dtype=float)
    theta = case.theta
    A = pivot + r * np.stack([np.cos(theta), np.sin(theta)], axis=1)
    VA = crank_velocity(case, theta)
    outs = case.outputs
    fprime = (lambda x, a: sysm.jacobian(x, a)[0]) if jacobian else None

    def run():
        n = len(theta)
        X = np.full((n, len(x0)), np.nan)
        V = np.full((n, len(x0)), np.nan)
        ok = np.zeros(n, dtype=bool)
        x = x0.copy()
        for k in range(n):
            sol, info, ier, _ = fsolve(sysm.residual, x, args=(A[k],), fprime=fprime, full_output=True)
            if ier == 1:
                x = sol
                X[k], V[k], ok[k] = sol, sysm.velocity(sol, A[k], VA[k]), True
        P, W = {}, {}
        for p in outs:
            if p == tip:
                P[p], W[p] = np.where(ok[:, None], A, np.nan), np.where(ok[:, None], VA, np.nan)
            else:
                j = 2 * sysm.free.index(p)
                P[p], W[p] = X[:, j:j + 2], V[:, j:j + 2]
        return Run(P, W, ok)
    return run
