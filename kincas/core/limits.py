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
>>> p = np.zeros(0)
>>> polish_singular(model, q + 1e-9, u, p, m.size(), [0]) is not None  # at the limit: onto it
True
>>> polish_singular(model, q, u - 1e-6, p, m.size(), [0]) is None  # 1e-6 rad before it: not at one
True
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from .assembly import blocks
from .newton import newton
from .tolerances import MAX_ITER, NULL_RESIDUAL, ROUNDING, STEP_SLACK, TINY


# --- scaled Jacobians ---


def _scales(model, L):
    """Column scales of g_q (unknowns) and g_u (inputs): a size-L mechanism gives O(1) entries."""
    cu = np.array([1.0 / L if i.is_angle else 1.0 for i in model.sym.mech.inputs])
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


def null_direction(J, rows, cols, cq) -> np.ndarray:
    """The null direction of the block J[rows, cols] of a column-scaled g_q (J = g_q cq), in
    unscaled unknowns (the right singular vector of its smallest singular value, times cq):
    the one null-vector routine of `locate_singular` and `polish_singular`."""
    return np.linalg.svd(J[np.ix_(rows, cols)])[2][-1] * cq[cols]


def _singular_system(model, q, u, p, L, parts, d=None, scales=None):
    """The extended system of the module's text at the pose (q, u), for the blocks `parts`
    ((rows, cols) each) singular together, the inputs moving along u + s d (d None: the
    inputs fixed, no unknown s). Unknowns x = [q, (s), v_1[cols_1], ...]: v_k the null
    direction of block k, nonzero on its own unknowns only; residuals [g; per block
    (g_q v_k)[rows_k], v0_k . v_k - 1]. Returns (F, x0, step_scale, res_scale) for the one
    Newton (kincas/core/newton.py): q scaled per group as every solve scales it, s in the
    input's unit (radians, or lengths over L), v as the null direction of the column-scaled
    g_q it is; g over its group's length, g_q v and v0 . v - 1 the pure numbers they are."""
    nq, ng = model.nq, model.ng
    f = _extended(model)
    J, _ = scaled_jacobians(model, q, u, p, L)
    cq, cu = _scales(model, L)
    v0s = []
    for rows, cols in parts:
        v0 = np.zeros(nq)
        v0[cols] = null_direction(J, rows, cols, cq)
        v0s.append(v0)
    x0 = np.r_[np.asarray(q, float), [0.0] if d is not None else [], *(v[cols] for v, (_, cols) in zip(v0s, parts))]
    v0s = [v / (v @ v) for v in v0s]
    u0 = np.array(u, float)
    eq, qs = model.scales(u0, p) if scales is None else scales
    ns = 0 if d is None else 1
    offs = np.cumsum([nq + ns] + [len(cols) for _, cols in parts])
    step_scale = np.r_[qs, [] if d is None else [1.0 / max(np.abs(d * cu * L).max(initial=0.0), TINY)],
                       *(cq[cols] for _, cols in parts)]
    # s moves the inputs by s d: its unit is the step that moves them by one radian, or by L
    res_scale = np.r_[eq, *(np.ones(len(rows) + 1) for rows, _ in parts)]

    def F(x):
        uu = u0 if d is None else u0 + x[nq] * d
        Fs, As = [], []
        for k, (rows, cols) in enumerate(parts):
            vv = np.zeros(nq)
            vv[cols] = x[offs[k]:offs[k + 1]]
            Fx, JF = f(x[:nq], uu, p, vv, v0s[k])
            Fx = Fx.ravel()
            sel = np.r_[np.arange(ng) if k == 0 else np.arange(0), ng + rows, 2 * ng]
            A = np.zeros((len(sel), x.size))
            A[:, :nq] = JF[sel, :nq]
            if d is not None:
                A[:, nq] = JF[sel, nq:-nq] @ d
            A[:, offs[k]:offs[k + 1]] = JF[np.ix_(sel, nq + model.nu + cols)]
            Fs.append(Fx[sel])
            As.append(A)
        return np.concatenate(Fs), np.vstack(As)
    return F, x0, step_scale, res_scale


def locate_singular(model, q, u, p, L, direction, max_iter: int = MAX_ITER, group: int | None = None,
                    probe: bool = False, window: tuple[float, float] | None = None, scales=None):
    """Newton on the extended system from a pose near a singular position, moving the
    inputs along u + s * direction. Returns (q*, u*, s*) there, or None.

    The one Newton of kincas (kincas/core/newton.py) with its stopping rule and thresholds
    (kincas/core/tolerances.py), in the unknowns (q, s, v): q scaled per group as every
    solve scales it (angles as they are, lengths over their group's length), s in the
    input's unit (radians, or lengths over L), v as the null direction of the
    column-scaled g_q it is. Residuals: g over its group's length, g_q v and v0 . v - 1 as
    the pure numbers they are.

    Parameters
    ----------
    model : kincas.core.numeric.Model
    q, u, p : numpy.ndarray
        A solved pose near the singular position, and the parameter values.
    L : float
        The mechanism's size (the scale of the column-scaled Jacobians).
    direction : array_like
        The inputs move along u + s * direction.
    max_iter : int
        Newton iterations at most.
    group : int, optional
        An index into the Assur groups (kincas/core/assembly.py): locate where that group
        alone is singular (g = 0, g_q[rows, cols] v = 0 with v nonzero only on the group's
        unknowns).
    probe : bool
        Return s after `max_iter` iterations, converged or not (a cheap estimate of where).
    window : (float, float), optional
        Give up (None) when s after two iterations lies outside (lo, hi): the singular
        position is not near the step. The same iterates as a probe of two iterations
        followed by a full search from the same start (Newton keeps no state but x), at
        the cost of one search.
    scales : (numpy.ndarray, numpy.ndarray), optional
        `model.scales(u, p)`, where the caller has it already (several groups searched
        from one pose).

    Returns
    -------
    tuple or float or None
        (q*, u*, s*); s with `probe`; None where Newton does not converge.

    Examples
    --------
    See the module's example: the rocker limit of a crank-rocker, to rounding.
    """
    nq, ng = model.nq, model.ng
    if nq == 0:
        return None
    part = (np.arange(ng), np.arange(nq)) if group is None else blocks(model)[group]
    u0, d = np.array(u, float), np.asarray(direction, float)
    F, x0, step_scale, res_scale = _singular_system(model, q, u0, p, L, [part], d, scales)
    if window is not None and max_iter > 2:  # two iterations first: is s near the window?
        seen = []  # the last point F was evaluated at

        def F2(x):
            seen[:] = [x]
            return F(x)
        early = newton(F2, x0, step_scale, res_scale, max_iter=2)
        s = float(early.x[nq])
        if not (np.isfinite(s) and window[0] < s < window[1]):
            return None
        # Newton ran out of its two iterations exactly when it returns the last point it
        # evaluated after two steps (converged: a step applied unevaluated; stalled: a
        # rejected point evaluated last): then go on from there, as one longer run would
        going = early.iterations == 2 and np.array_equal(early.x, seen[0])
        res = newton(F, early.x, step_scale, res_scale, max_iter=max_iter - 2) if going else early
    else:
        res = newton(F, x0, step_scale, res_scale, max_iter=max_iter)
    qx, s = res.x[:nq], float(res.x[nq])
    if probe:
        return s if np.isfinite(s) else None
    if not res.ok or not np.all(np.isfinite(res.x)):
        return None
    return qx, u0 + s * d, s


def on_step(found) -> bool:
    """Whether a singular position `found` by `locate_singular` along a step, (q*, u*, s*),
    lies on that step: s* in [0, 1] to rounding (STEP_SLACK: a position located exactly at
    either end pose is on it). False for None (nothing found).

    >>> on_step((None, None, 1.0 + 1e-12)), on_step((None, None, -1e-3)), on_step(None)
    (True, False, False)
    """
    return found is not None and -STEP_SLACK <= found[2] <= 1 + STEP_SLACK


def polish_singular(model, q, u, p, L, groups, max_iter: int = 30):
    """The pose at inputs u where each group in `groups` (indices) is exactly singular, from
    q nearby: the extended system of the module's text with the inputs fixed (no unknown s)
    and one null direction per group, solved by the one Newton (kincas/core/newton.py).
    Returns q there, or None where no such pose lies within rounding of q (then q is only
    near a singular position, and an ordinary pose): g / L below ROUNDING, the null
    directions' equations below NULL_RESIDUAL.

    See the module's example: from next to the limit it located, polish_singular reaches
    it; 1e-6 rad of the crank before it, there is none.
    """
    if model.nq == 0 or not len(groups):
        return None
    bl, ng = blocks(model), model.ng
    u = np.array(u, float)
    F, x0, step_scale, res_scale = _singular_system(model, q, u, p, L, [bl[i] for i in groups])
    res = newton(F, x0, step_scale, res_scale, max_iter=max_iter)
    if not np.all(np.isfinite(res.x)):
        return None
    Fx = F(res.x)[0]
    if np.abs(Fx[:ng]).max() / L > ROUNDING or np.abs(Fx[ng:]).max() > NULL_RESIDUAL:
        return None
    return res.x[:model.nq]
