"""The problem a sweep method is handed (`SweepProblem`, kincas/analysis/methods.py), and the
careful path over every pose (`SweepProblem.careful_pass`).

`kincas.sweep` (kincas/analysis/sweeps.py) prepares the problem once: the model, the
mechanism's prepared data, the reported names, the input tables; the method composes its two
passes. The fast pass is the compiled one (kincas/core/fast.py), each pose it does not accept
re-solved on the careful path from the last solved pose (`careful`); the careful pass solves
every pose that way and measures, at each, what the fast kernel gives (each Assur group's
mode and conditioning), so that the events of kincas/analysis/events.py read either alike.

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
>>> class Both(kincas.SweepMethod):
...     def sweep(self, problem):
...         self.n = problem.n
...         return problem.careful_pass()
>>> method = Both()
>>> sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 1, 4)}, method=method)
>>> method.n, bool(sw.ok.all()), sw.info["fast pass"]
(4, True, None)
"""
from __future__ import annotations

import numpy as np

from ..core.numeric import Model
from .continuation import careful_pose


class SweepProblem:
    """A sweep prepared for its method (kincas/analysis/methods.py): `n` poses, the `report`
    names, and the two passes a method composes."""

    __slots__ = ("model", "pm", "names", "report", "U", "Ud", "Udd", "p", "L", "m", "guess", "events",
                 "progress", "n")

    def __init__(self, model, pm, names, report, U, Ud, Udd, p, L, m, guess, events, progress):
        self.model, self.pm, self.names, self.report, self.U, self.Ud, self.Udd = model, pm, names, report, U, Ud, Udd
        self.p, self.L, self.m, self.guess, self.events, self.progress = p, L, m, guess, events, progress
        self.n = U.shape[0]

    def first(self, k):
        """Where the careful path would start Newton for pose k, no pose solved yet."""
        return self.pm.placement(self.model, self.U[k], self.guess)

    def careful(self, k, j, run):
        """Pose k, which the fast pass did not accept, from the last solved pose j (events
        met on the way go to `events`)."""
        model, m, U, p, L, g, events = self.model, self.m, self.U, self.p, self.L, self.guess, self.events
        placed = self.first(k) if j is None else None  # the first pose: a function of inputs
        if placed is not None:  # and guess, solved once per placement (warm calls reuse it)
            return placed.solved(lambda: careful_pose(model, m, U, p, L, g, k, j, run, events))
        return careful_pose(model, m, U, p, L, g, k, j, run, events)

    def fast_pass(self, compile=None):
        """The compiled pass (every pose it does not accept on the careful path), or None
        where there is none worth running: a kernel too large to pay for itself on this sweep (unless compile is False)."""
        fast = self.pm.sweeper(self.model, self.names, compile)
        if fast is None or not (compile is False or fast.worth_it(self.n)):
            return None
        return fast.sweep(self.U, self.p, self.L, self.careful, Ud=self.Ud, Udd=self.Udd,
                          progress=self.progress, first=self.first)

    def careful_pass(self):
        """Every pose on the careful path (continuation with step cutting)."""
        return _careful_only(self.model, self.report, self.U, self.Ud, self.Udd, self.p, self.L,
                             self.careful, self.progress)


class _CarefulRun:
    """The arrays of a sweep solved on the careful path alone (as `FastRun` has them)."""

    def __init__(self, n, nq, nr, ng):
        self.Q, self.solved = np.full((n, nq), np.nan), np.zeros(n, dtype=bool)
        self.residual, self.iterations = np.full(n, np.nan), np.zeros(n, dtype=int)
        self.values, self.jacobian = np.full((nr, n), np.nan), np.full((n, ng, nq), np.nan)


def _careful_only(model, report, U, Ud, Udd, p, L, careful, progress) -> _CarefulRun:
    n = U.shape[0]
    run, j = _CarefulRun(n, model.nq, len(report), model.ng), None
    for k in range(n):
        if progress is not None and k % 256 == 0:
            progress(k, n)
        sol = careful(k, j, run)
        run.residual[k], run.iterations[k] = sol.residual, sol.iterations
        if sol.ok:
            run.Q[k], run.solved[k], j = sol.q, True, k
            run.jacobian[k] = sol.J if sol.J is not None else model.jac(sol.q, U[k], p)
    if progress is not None:
        progress(n, n)
    ok = run.solved
    run.values[:, ok] = model.quantities(report, run.Q[ok], U[ok], p, Ud[ok], Udd[ok])
    run.signs, run.sigma = _measures(model, run.jacobian, ok, L)
    return run


def _measures(model: Model, J, ok, L):
    """What the fast kernel gives per pose, from g_q at every pose: each group's mode (N,
    groups), or for a tall g_q an orientation that changes sign where the sweep crosses a
    singular position ((N, 1)), 0 where unsolved; and the smallest singular value of the
    scaled g_q relative to max(1, its largest) (a group's conditioning, for a square one)."""
    n, idx = len(ok), np.flatnonzero(ok)
    dets, sigma = np.zeros(n), np.full(n, np.nan)
    if model.nq == 0 or not len(idx):
        return dets[:, None], sigma
    if model.square:  # each Assur group's mode, as the kernel gives it (see core/assembly.py)
        from ..core.assembly import modes
        signs = np.zeros((n, len(model.blocks)))
        signs[idx], cond = modes(model, J[idx], L)
        sigma[idx] = cond.min(axis=1, initial=1.0)
        return signs, sigma
    # tall (redundant joints): no determinant, so chain the relative test of _same_branch
    # along the sweep: the orientation flips from pose k to the next where det(Q_k' J_next)
    # and det R_k differ in sign (J_k = Q_k R_k).
    J = J[idx] * model.column_scale(L)
    Qk, Rk = np.linalg.qr(J)
    dR = np.prod(np.diagonal(Rk, axis1=1, axis2=2), axis=1)
    o = 1.0
    for a in range(len(idx)):
        dets[idx[a]] = o * abs(dR[a])
        if a + 1 < len(idx):
            flip = np.sign(dR[a]) * np.sign(np.linalg.det(Qk[a].T @ J[a + 1]))
            o = o * flip if flip != 0 else o
    sv = np.linalg.svd(J, compute_uv=False)
    sigma[idx] = sv[:, -1] / np.maximum(sv[:, 0], 1.0)
    return np.sign(dets)[:, None], sigma
