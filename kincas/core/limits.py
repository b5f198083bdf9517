"""Locating a limit (turning point) or a change point exactly: the extended system.

At a simple turning point of the branch q(u), g_q is singular and g = 0, g_q v = 0 for a
null vector v of g_q. With a normalisation v0 . v = 1 (v0 near the null direction) the
extended system
    F(q, s, v) = [g(q, u0 + s d); g_q(q, u0 + s d) v; v0 . v - 1] = 0
in (q, s, v) has a regular Jacobian there (its entries are second derivatives of g, exact
from CasADi), so Newton converges quadratically to the singular pose. For one Assur group
only (`group`), v is nonzero on the group's unknowns and only the group's rows of g_q v are
kept.

>>> import math, numpy as np, kincas
>>> from kincas.core.numeric import compile
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 1.9),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.2, 2.5)})
>>> model = compile(m)
>>> q = model.newton(model.initial_q(np.array([2.6]), [], dict(m.guess), 4), np.array([2.6]), [], 4).q
>>> q, u, s = locate_singular(model, q, np.array([2.6]), np.zeros(0), m.size(), [1.0])
>>> round(math.degrees(u[0]), 9)  # |BD| = 1.9 + 3: the law of cosines
151.193259668
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from .assembly import blocks


# --- scaled Jacobians ---


def _scales(model, L):
    """Column scales of g_q (unknowns) and g_u (inputs): a size-L mechanism gives O(1) entries."""
    cu = np.array([1.0 / L if i.kind == "angle" else 1.0 for i in model.sym.mech.inputs])
    return model.column_scale(L), cu


def scaled_jacobians(model, q, u, p, L):
    """(J, Gu): g_q and g_u with columns scaled so a size-L mechanism gives O(1) entries.

    Parameters
    ----------
    model : kincas.core.numeric.Model
    q, u, p : numpy.ndarray
        Unknowns, inputs and parameter values of the pose.
    L : float
        The mechanism's size.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
    """
    _, J, Ju = model._tangent(q, u, p)
    cq, cu = _scales(model, L)
    return J * cq, Ju * cu


# --- the extended system ---


def _extended(model):
    """F(q, u, p, v, v0) = [g; g_q v; v0.v - 1] and its Jacobian in (q, u, v), returning dense
    numpy arrays (through zero-copy buffers: converting a casadi DM costs milliseconds at 80
    unknowns)."""
    def build():
        from .numeric import _Call
        sym = model.sym
        v, v0 = ca.SX.sym("v", sym.nq), ca.SX.sym("v0", sym.nq)
        F = ca.vertcat(sym.g, ca.mtimes(sym.Jq, v), ca.dot(v0, v) - 1)
        z = ca.vertcat(sym.q, sym.u, v)
        return _Call(ca.Function("extended", [sym.q, sym.u, sym.p, v, v0], [F, ca.jacobian(F, z)]))
    return model.memo("singular.extended", build)


def locate_singular(model, q, u, p, L, direction, max_iter: int = 40, group: int | None = None,
                    probe: bool = False):
    """Newton on the extended system from a pose near a singular position, moving the
    inputs along u + s * direction. Returns (q*, u*, s*) there, or None.

    `group` (an index into the Assur groups, kincas/core/assembly.py) locates where that
    group alone is singular: g = 0, g_q[rows, cols] v = 0 with v nonzero only on the group's
    unknowns. The residual is measured scale-free: g over the size, g_q v as the pure number
    it is (v is the null direction of the column-scaled block, in unscaled unknowns).
    `probe`: return s after max_iter steps, converged or not (a cheap estimate of where)."""
    nq, ng = model.nq, model.ng
    if nq == 0:
        return None
    f = _extended(model)
    rows, cols = (np.arange(ng), np.arange(nq)) if group is None else blocks(model)[group]
    J, _ = scaled_jacobians(model, q, u, p, L)
    cq, _ = _scales(model, L)
    v = np.zeros(nq)
    v[cols] = np.linalg.svd(J[np.ix_(rows, cols)])[2][-1] * cq[cols]  # null direction, unscaled
    v0 = v / (v @ v)
    d = np.asarray(direction, float)
    sel = np.r_[np.arange(ng), ng + rows, 2 * ng]  # g, the group's rows of g_q v, v0.v - 1
    q, u0, s = np.array(q, float), np.array(u, float), 0.0

    def residual(F):
        return np.abs(F[:ng]).max() / L, np.abs(F[ng + rows]).max(initial=0.0) + abs(F[-1])

    for _ in range(max_iter):
        F, JF = (np.asarray(a) for a in f(q, u0 + s * d, p, v, v0))
        F = F.ravel()
        rg, rv = residual(F)
        if rg < 1e-14 and rv < 1e-13:
            break
        A = np.hstack([JF[:, :nq], JF[:, nq:-nq] @ d[:, None], JF[:, -nq:][:, cols]])[sel]
        try:  # Gauss-Newton where g_q is tall (redundant joints: a consistent system)
            step = np.linalg.solve(A, -F[sel]) if A.shape[0] == A.shape[1] else np.linalg.lstsq(A, -F[sel], rcond=None)[0]
        except np.linalg.LinAlgError:
            return None
        if not np.all(np.isfinite(step)):
            return None
        q, s = q + step[:nq], s + step[nq]
        v[cols] += step[nq + 1:]
    if probe:
        return s
    F = np.asarray(f(q, u0 + s * d, p, v, v0)[0]).ravel()
    rg, rv = residual(F)
    if rg > 1e-11 or rv > 1e-8:
        return None
    return q, u0 + s * d, s
