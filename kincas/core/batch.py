"""Many designs of one structure at once: batched evaluation and one compiled call per block.

A *design* is one set of parameter values for a compiled model (`kincas.model_of(m)`: the
structure is built once, the parameters stay numeric inputs). `BatchEvaluator` gives g, g_q,
g_u, g_p and the reported quantities at many (q, u, p) columns in one mapped CasADi call
each, for damped-free Newton steps on all of them with numpy's batched linear algebra (no
symbolic inverse, so it scales with the mechanism). The compiled loop over whole designs is
in kincas/core/designs_kernel.py.

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(parameters={"a": 1.0}, ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", "a"), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)], inputs=[kincas.Input.angle("crank")])
>>> ev = BatchEvaluator(kincas.model_of(m))
>>> g, J, Ju, Jp = ev.derivatives(np.zeros((2, 2)), np.zeros((2, 1)), np.array([[1.0], [2.0]]))
>>> g.shape, J.shape, Jp[:, :, 0].round(6).tolist()
((2, 2), (2, 2, 2), [[1.0, 0.0], [1.0, 0.0]])
"""
from __future__ import annotations

import threading

import casadi as ca
import numpy as np

from .caches import Memo

# --- g and its derivatives at many columns ---


class BatchEvaluator:
    """Residuals, Jacobians and quantities at N columns (q, u, p) of one model, mapped.

    Arrays are numpy, one row per column: Q (N, nq), U (N, nu), P (N, np). Not shared
    between threads (the mapped functions are, and casadi's call is re-entrant)."""

    def __init__(self, model):
        self.model, sym = model, model.sym
        self.nq, self.nu, self.np = sym.nq, sym.nu, sym.np
        d = ca.densify
        self._f = ca.Function("derivs", [sym.q, sym.u, sym.p],
                              [d(sym.g), d(sym.Jq), d(sym.Ju), d(ca.jacobian(sym.g, sym.p))])
        self._maps: dict = {}

    def _mapped(self, f, n):
        key = (f.name(), n)
        if key not in self._maps:
            self._maps[key] = f.map(n)
        return self._maps[key]

    def derivatives(self, Q, U, P):
        """g (N, ng), g_q (N, ng, nq), g_u (N, ng, nu), g_p (N, ng, np)."""
        n = Q.shape[0]
        if n == 0:
            sym = self.model.sym
            return (np.zeros((0, sym.ng)), np.zeros((0, sym.ng, self.nq)),
                    np.zeros((0, sym.ng, self.nu)), np.zeros((0, sym.ng, self.np)))
        outs = self._mapped(self._f, n)(np.asarray(Q, float).T, np.asarray(U, float).T,
                                        np.asarray(P, float).T)
        g = np.asarray(outs[0]).T
        mats = []
        for a, w in zip(outs[1:], (self.nq, self.nu, self.np)):
            a = np.asarray(a)  # (ng, n * w): column blocks per design
            mats.append(a.reshape(a.shape[0], n, w).transpose(1, 0, 2))
        return (g, *mats)

    def quantities(self, names, Q, U, P, Ud, Udd) -> np.ndarray:
        """(len(names), N) quantities at N solved columns, each with its own parameters."""
        n = Q.shape[0]
        if n == 0 or not names:
            return np.zeros((len(names), n))
        f = self.model.quantity_function(tuple(names))
        return np.asarray(self._mapped(f, n)(Q.T, U.T, P.T, Ud.T, Udd.T))


def batched_solve(J, b):
    """Batched J^-1 b (J: a stack of square matrices; b: a vector or a matrix per J); NaN
    where J is singular.

    >>> J = np.array([[[2.0, 0.0], [0.0, 4.0]], [[1.0, 1.0], [1.0, 1.0]]])
    >>> batched_solve(J, np.ones((2, 2))).tolist()
    [[0.5, 0.25], [nan, nan]]
    """
    vec = b.ndim == J.ndim - 1
    B = b[..., None] if vec else b
    try:
        X = np.linalg.solve(J, B)
    except np.linalg.LinAlgError:
        X = np.full(B.shape, np.nan)
        for i in range(len(B)):
            try:
                X[i] = np.linalg.solve(J[i], B[i])
            except np.linalg.LinAlgError:
                pass
    return X[..., 0] if vec else X


# --- one lock per compiled model for the Python-side numerics (Model keeps work buffers) ---

# unnamed: clear_all() must not forget a lock some thread holds
_LOCKS = Memo(weak=True)


def model_lock(model) -> threading.RLock:
    """The one lock of `model` (reentrant), for the callers of its numerics on threads."""
    return _LOCKS.get_or_build(model, threading.RLock)
