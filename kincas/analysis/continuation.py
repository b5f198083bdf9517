"""The careful path of a sweep: continuation with step cutting, recovery after a failure,
and the branch a sweep resumes on after poses with no assembly.

A pose the fast pass does not accept is solved here from the last solved pose: predicted along
the exact tangent dq/du = -g_q^-1 g_u (or the secant through the pose before, next to a
singular position), corrected by Newton, the step halved where the corrector fails, wanders or
changes the sign of det g_q.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ..core.numeric import Model, Solution
from ..model.mechanism import Mechanism


# --- a pose of a sweep on the careful path ---


def careful_pose(model: Model, m: Mechanism, U, p, L, guess, k: int, j: int | None, run,
                 events: list) -> Solution:
    """Pose k of a sweep over the input table U, from the last solved pose j (None: none yet).

    `run` holds the poses solved so far (`Q`, `solved`); a resume after a gap appends a
    "resume" event to `events`.
    """
    u = U[k]
    if j is None:
        return _first(model, u, p, L, guess)
    fresh = j == k - 1
    prev = (run.Q[j - 1], U[j - 1]) if fresh and j >= 1 and run.solved[j - 1] else None
    sol = _continue(model, run.Q[j], U[j], u, p, L, depth=8 if fresh else 0, prev=prev)
    if sol is None:
        sol = _recover(model, m, (run.Q[j], U[j]), u, p, L)
    if sol.ok and not fresh:  # back in range: on the same branch if it exists; say which
        before = Solution(run.Q[j], 0.0, 0, True, model.jac(run.Q[j], U[j], p))
        sign, before = _det_sign(model, sol, L), _det_sign(model, before, L)
        if 0 not in (sign, before) and sign != before:
            alt = _same_branch_assembly(model, m, u, p, L, before, run.Q[j], U[j])
            if alt is not None:
                sol, sign = alt, before
        events.append({"kind": "resume", "pose": int(k),
                       "branch": "same" if sign == before or 0 in (sign, before) else "other"})
    return sol


# --- one pose: from the guess, from the previous pose, after a failure ---


def _first(model: Model, u, p, L, guess) -> Solution:
    return model.assemble(u, p, guess, L)  # Newton from the guess, else IPOPT; gears settled


def _recover(model: Model, m: Mechanism, last, u, p, L) -> Solution:
    """Continuation failed: Newton straight from the last pose, then IPOPT (nearest assembly)."""
    sol = model.newton(last[0], u, p, L)
    if not sol.ok:
        pts = model.points(last[0], last[1], p)
        sol = model.nearest_assembly(last[0], u, p, {nm: pts[:, j] for j, nm in enumerate(m.moving_points)}, L)
    return sol


def _same_branch_assembly(model: Model, m: Mechanism, u, p, L, sign, q_last, u_last):
    """Back in range after a gap (a limit, where the branches meet): the assembly whose
    det(g_q) has the given sign, nearest the last solved pose; None if there is none.
    The assemblies come from scattered starts, as `kincas modes` finds them."""
    from .modes import find_modes
    try:
        modes = find_modes(m, {i.key: float(v) for i, v in zip(m.inputs, u)}, starts=128)
    except ModelError:
        return None
    last = model.points(q_last, u_last, p)
    near = [(float(np.linalg.norm(model.points(md.q, u, p) - last)), md.q)
            for md in modes if md.orientation == sign]
    if not near:
        return None
    sol = model.newton(min(near, key=lambda t: t[0])[1], u, p, L)
    return sol if sol.ok and _det_sign(model, sol, L) == sign else None


def _scaled_norm(model: Model, dq, L) -> float:
    return float(np.abs(dq / np.where(model.sym.is_length, L, 1.0)).max(initial=0.0))


def _continue(model: Model, q0, u0, u1, p, L, depth: int, prev=None) -> Solution | None:
    """Predict, correct with Newton. The step is halved when the corrector fails or needs
    many iterations, lands far from the prediction, or the sign of det(g_q) flips (the sign
    tells the assembly branch apart).

    The predictor is the exact tangent dq/du, except where g_q is nearly singular: there the
    tangent is undefined (at a change point two branches cross), and the secant through
    the previous pose `prev` = (q, u) carries the branch straight through.
    """
    J0 = model.jac(q0, u0, p)
    pred = _secant(q0, u0, u1, prev) if prev is not None and _ill(model, J0, L) else None
    if pred is None:
        pred = q0 + model.tangent(q0, u0, p) @ (u1 - u0)
    sol = model.newton(pred, u1, p, L)
    if sol.ok and depth == 0:
        return sol
    if sol.ok:
        moved = _scaled_norm(model, pred - q0, L)
        far = _scaled_norm(model, sol.q - pred, L) > max(0.02, 0.5 * moved)
        if sol.iterations <= 8 and not far and _same_branch(model, J0, sol, L):
            return sol
    if depth == 0:
        return None
    um = 0.5 * (u0 + u1)
    mid = _continue(model, q0, u0, um, p, L, depth - 1, prev)
    return None if mid is None else _continue(model, mid.q, um, u1, p, L, depth - 1, (q0, u0))


def _ill(model: Model, J, L) -> bool:
    """Whether g_q is too close to singular for its tangent to be trusted."""
    if J.size == 0:
        return False
    # The 1-norm condition number (an LU and an inverse) is within a factor n of the 2-norm
    # one, and several times cheaper than singular values for large mechanisms.
    with np.errstate(all="ignore"):
        # (2-norm, from singular values, for a tall g_q: redundant joints)
        c = np.linalg.cond(J * model.column_scale(L), 1 if model.square else None)
    return not c < 1e2 * max(1.0, np.sqrt(J.shape[0]))


def _secant(q0, u0, u1, prev):
    """q0 + (q0 - q_prev) t, when the new step continues the previous one's direction."""
    qp, up = prev
    d0, d1 = u0 - up, u1 - u0
    n0 = float(d0 @ d0)
    if n0 == 0.0:
        return None
    t = float(d1 @ d0) / n0
    if np.linalg.norm(d1 - t * d0) > 1e-9 * np.linalg.norm(d1):
        return None  # the inputs turned: no straight line to follow
    return q0 + (q0 - qp) * t


def _scaled_det(model: Model, J, L) -> float:
    # Columns scaled to O(1) so the determinant's size means the same at every scale.
    return float(np.linalg.det(J * model.column_scale(L))) if J.size else 1.0


def _det_sign(model: Model, sol: Solution, L) -> int:
    """The sign of det(g_q), which tells the assembly branches apart; 0 near a singular
    position, and for a tall g_q (redundant joints), which has no determinant."""
    if not model.square:
        return 0
    d = _scaled_det(model, sol.J, L)
    return 0 if abs(d) < 1e-8 else int(np.sign(d))


def _same_branch(model: Model, J0, sol: Solution, L) -> bool:
    """Whether det(g_q) kept its sign from J0 to sol.J (or either is nearly singular).

    A tall g_q (redundant joints) has no determinant, but a relative invariant serves:
    with J0 = Q0 R0 (Q0 an orthonormal basis of J0's column space), det(Q0' J) is
    continuous in J and equals det R0 at J0, so it changes sign only where Q0' J is
    singular: det(Q0' J1) and det(R0) of opposite signs mean a singular position was
    crossed, exactly as det g_q's sign change does for a square system (for which
    this is the same test: Q0 is square and orthogonal)."""
    c = model.column_scale(L)
    if model.square:
        d0, d1 = _scaled_det(model, J0, L), _scaled_det(model, sol.J, L)
    else:
        Q0, R0 = np.linalg.qr(J0 * c)
        d0, d1 = float(np.prod(np.diag(R0))), float(np.linalg.det(Q0.T @ (sol.J * c)))
    return np.sign(d0) == np.sign(d1) or min(abs(d0), abs(d1)) < 1e-8
