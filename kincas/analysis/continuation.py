"""The careful path of a sweep: continuation with step cutting, recovery after a failure,
and the branch a sweep resumes on after poses with no assembly.

A pose the fast pass does not accept is solved here from the last solved pose: predicted along
the exact tangent dq/du = -g_q^-1 g_u (or the secant through the pose before, next to a
singular position), corrected by Newton, the step halved where the corrector fails, wanders or
changes the sign of det g_q.
"""
from __future__ import annotations

import numpy as np

from ..core.assembly import assemble, modes
# the first pose of a sweep (its home is the core: `kincas modes` and `range` start there too)
from ..core.assembly import ambiguous as _ambiguous, first_pose as _first, no_assembly as _no_assembly  # noqa: F401
from ..core import branch
from ..core.numeric import Model, Solution
from ..core.limits import on_step, polish_singular
from ..core.tolerances import BRANCH, NEAR_SINGULAR, STRAIGHT, WATCH
from ..model.mechanism import Mechanism
from .resume import carry_groups, larger_groups, resume_label


MAX_GROUPS = 8  # groups searched for a limit where continuation of a step failed (the worst conditioned first)

# --- a pose of a sweep on the careful path ---


def careful_pose(model: Model, m: Mechanism, U, p, L, guess, k: int, j: int | None, run,
                 events: list) -> Solution:
    """Pose k of a sweep over the input table U, from the last solved pose j (None: none yet).

    `run` holds the poses solved so far (`Q`, `solved`). A pose after a gap (poses with no
    assembly) resumes in the mode of every Assur group it left where that mode assembles, and
    appends a "resume" event saying so: "branch" "same", or "other" with the `groups` (their
    links) whose mode changed.
    """
    u = U[k]
    if j is None:
        return _first(model, u, p, L, guess)
    fresh = j == k - 1
    if not fresh and not _ambiguous(model):  # in or after a gap: decided group by group
        return _resume(model, U, p, L, k, j, run, events)
    big = larger_groups(model)
    memo = run.__dict__.setdefault("carried", {})  # how far each gap was carried, per sweep
    carried = carry_groups(model, U, p, L, j, run.Q[j], k, big, memo) if big and not fresh else {}
    sol = None
    for q in (q for q in carried.values() if q is not None):  # a group carried through the
        sol = assemble(model, u, p, L, want=modes(model, model.jac(run.Q[j], U[j], p), L)[0], near=q)
        break  # gap is in the mode it left: first that, the later groups in theirs
    reach = []  # how far continuation got from pose j (the furthest pose it solved)
    if sol is None:
        prev = (run.Q[j - 1], U[j - 1]) if fresh and j >= 1 and run.solved[j - 1] else None
        sol = _continue(model, run.Q[j], U[j], u, p, L, depth=8 if fresh else 0, prev=prev, reach=reach)
    recovered = sol is None
    if sol is None:
        sol = _recover(model, m, (run.Q[j], U[j]), u, p, L)
        if sol.ok and fresh and _gap_inside(model, run, U, p, L, j, k, sol, reach):
            # the branch of pose j ends inside the step: pose k resumes after a gap
            events.append({"kind": "resume", "pose": int(k)}
                          | resume_label(model, U, p, L, j, run.Q[j], k, sol.q))
            return sol
    if sol.ok and not fresh:  # back in range: in the modes it left where they assemble
        before = modes(model, model.jac(run.Q[j], U[j], p), L)[0]
        after = modes(model, sol.J, L)[0]
        changed = np.flatnonzero(branch.changed(before, after))
        if changed.size:  # first the modes it left, group by group
            alt = assemble(model, u, p, L, want=before, near=run.Q[j])
            if alt is not None:
                got = modes(model, alt.J, L)[0]
                moved = np.flatnonzero(branch.changed(before, got))
                if moved.size < changed.size:
                    sol = alt
        events.append({"kind": "resume", "pose": int(k)}
                      | resume_label(model, U, p, L, j, run.Q[j], k, sol.q, carried or None))
    elif sol.ok and recovered and big:  # the mode followed ended: another took over, if any
        label = resume_label(model, U, p, L, j, run.Q[j], k, sol.q)
        if label["branch"] != "same":
            events.append({"kind": "resume", "pose": int(k)} | label)
    return sol


def _resume(model: Model, U, p, L, k, j, run, events) -> Solution:
    """Pose k after poses with no assembly (the last solved is j), where every group's
    assembly is conclusive (`_ambiguous`): in the modes of pose j, nearest it, or where a
    group's mode does not assemble its other mode (named in the "resume" event); no
    assembly when a group's circles miss each other (a discriminant: no Newton at all)."""
    # pose j's modes, once per gap (every pose of a gap resumes from the same pose j)
    memo = run.__dict__.setdefault("gap_modes", {})
    if j not in memo or not np.array_equal(memo[j][0], run.Q[j]):
        memo.clear()
        memo[j] = np.array(run.Q[j]), modes(model, model.jac(run.Q[j], U[j], p), L)[0]
    before = memo[j][1]
    sol = assemble(model, U[k], p, L, want=before, near=run.Q[j])
    if sol is None:
        return _no_assembly(model, run.Q[j])
    events.append({"kind": "resume", "pose": int(k)} | resume_label(model, U, p, L, j, run.Q[j], k, sol.q))
    return sol


# --- one pose: from the guess, from the previous pose, after a failure ---


def _recover(model: Model, m: Mechanism, last, u, p, L) -> Solution:
    """Continuation failed: Newton straight from the last pose, kept only where every group
    stays in its mode or crossed a singular position of its own on the way (located); else
    the assembly in the last pose's modes, group by group; a pose where only other modes
    assemble, reached without such a crossing, has no assembly on this branch. IPOPT only
    where group assembly is not conclusive (`_ambiguous`)."""
    J0 = model.jac(last[0], last[1], p)
    want = modes(model, J0, L)[0]

    def keeps(sol):
        got = modes(model, sol.J, L)[0]
        return not branch.changed(got, want).any()
    sol = model.newton(last[0], u, p, L)
    if sol.ok and keeps(sol):
        return sol
    alt = assemble(model, u, p, L, want=want, near=last[0])
    if alt is not None and (keeps(alt) or _crossed(model, last[0], last[1], u, J0, alt, p, L)):
        return alt
    if sol.ok and _crossed(model, last[0], last[1], u, J0, sol, p, L):
        return sol  # another mode, through a located singular position: the events say so
    if _ambiguous(model):
        pts = model.points(last[0], last[1], p)
        sol = model.nearest_assembly(last[0], u, p, {nm: pts[:, j] for j, nm in enumerate(m.moving_points)}, L)
        if sol.ok and (keeps(sol) or _crossed(model, last[0], last[1], u, J0, sol, p, L)):
            return sol
    return _no_assembly(model, last[0])


def _scaled_norm(model: Model, dq, L) -> float:
    return float(np.abs(dq / np.where(model.is_length, L, 1.0)).max(initial=0.0))


def _continue(model: Model, q0, u0, u1, p, L, depth: int, prev=None, reach=None) -> Solution | None:
    """Predict, correct with Newton. The step is halved when the corrector fails or needs
    many iterations, lands far from the prediction, or the sign of det(g_q) flips (the sign
    tells the assembly branch apart).

    The predictor is the exact tangent dq/du, except where g_q is nearly singular: there the
    tangent is undefined (at a change point two branches cross), and the secant through
    the previous pose `prev` = (q, u) carries the branch straight through.

    `reach`, a list, receives (q, u) of every intermediate pose solved, in order: where
    the step fails, its last entry is as far as the branch was followed.
    """
    J0 = model.jac(q0, u0, p)
    pred = _secant(q0, u0, u1, prev) if prev is not None and _ill(model, J0, L) else None
    if pred is None:
        pred = q0 + model.tangent(q0, u0, p) @ (u1 - u0)
    sol = model.newton(pred, u1, p, L)
    if sol.ok and depth == 0:  # the shortest step: a group may change mode only by crossing
        # a singular position of its own that lies in this step (else it jumped branch)
        return sol if _same_branch(model, J0, sol, L) or _crossed(model, q0, u0, u1, J0, sol, p, L) else None
    if sol.ok:
        moved = _scaled_norm(model, pred - q0, L)
        far = _scaled_norm(model, sol.q - pred, L) > max(0.02, 0.5 * moved)
        if sol.iterations <= 8 and not far and _same_branch(model, J0, sol, L) \
                and not _passes_singular(model, q0, u0, u1, J0, sol, p, L):
            return sol
    if depth == 0:
        return None
    um = 0.5 * (u0 + u1)
    mid = _continue(model, q0, u0, um, p, L, depth - 1, prev, reach)
    if mid is None:
        return None
    if reach is not None:
        reach.append((mid.q, um))
    return _continue(model, mid.q, um, u1, p, L, depth - 1, (q0, u0), reach)


def _gap_inside(model: Model, run, U, p, L, j, k, sol: Solution, reach) -> bool:
    """Whether the branch of pose j ends at a limit inside the step to pose k, which was
    solved only by Newton from pose j (`_recover`) after continuation failed: then pose k
    lies beyond a stretch with no assembly on this branch (or on another branch), however
    short, and the step is a gap. The limit is searched per group (the worst conditioned
    first) from the furthest pose continuation reached, where it failed (within 1/256 of
    the step of it). Found, (j, k, near j's end, near k's end) is recorded in `run.crossed`
    (each end: the pose nearest the gap continuation reached from that side): the sweep's
    events locate the limits at both ends, as next to poses with no assembly."""
    from .singular import locate_singular
    near_j = reach[-1] if reach else (run.Q[j], U[j])
    d = U[k] - near_j[1]
    if not np.any(d):
        return False
    cond = modes(model, model.jac(near_j[0], near_j[1], p), L)[1]
    for i in np.argsort(cond, kind="stable")[:MAX_GROUPS]:
        found = locate_singular(model, *near_j, p, L, d, group=int(i), window=(-0.5, 1.5))
        if on_step(found):
            back = []  # and from pose k back towards pose j: the other end of the gap
            _continue(model, sol.q, U[k], U[j], p, L, depth=8, reach=back)
            near_k = back[-1] if back else (sol.q, U[k])
            run.__dict__.setdefault("crossed", []).append((int(j), int(k), near_j, near_k))
            return True
    return False


def _passes_singular(model: Model, q0, u0, u1, J0, sol: Solution, p, L) -> bool:
    """Whether a group that is not well conditioned at either end of the step has a singular
    position inside it: then Newton may have landed on the other branch through a change
    point with its mode unchanged (branches cross there), and the step must be cut."""
    from .singular import locate_singular
    c = np.minimum(modes(model, J0, L)[1], modes(model, sol.J, L)[1])
    watch = np.flatnonzero(c < WATCH)
    watch = watch[np.argsort(c[watch], kind="stable")]  # the likeliest crossing first: any one decides
    scales = model.scales(u0, p) if watch.size else None  # one pose's: shared by every search
    for i in watch:
        # two extended Newton steps putting s outside (-0.5, 1.5): not in this step
        found = locate_singular(model, q0, u0, p, L, u1 - u0, group=int(i), window=(-0.5, 1.5), scales=scales)
        if found is not None and 0 < found[2] < 1:
            return True
    return False


def _crossed(model: Model, q0, u0, u1, J0, sol: Solution, p, L) -> bool:
    """Whether every group whose mode differs between J0 (at u0) and sol (at u1) has a
    singular position of its own between u0 and u1 (located from the nearer end)."""
    from .singular import locate_singular
    s0, c0 = modes(model, J0, L)
    s1, c1 = modes(model, sol.J, L)
    for i in np.flatnonzero(branch.changed(s0, s1)):
        start, d = ((q0, u0), u1 - u0) if c0[i] <= c1[i] else ((sol.q, u1), u0 - u1)
        if min(c0[i], c1[i]) < NEAR_SINGULAR and polish_singular(model, *start, p, L, [int(i)]) is not None:
            continue  # that end is the singular position (within rounding)
        found = locate_singular(model, start[0], start[1], p, L, d, group=int(i))
        if not on_step(found):
            return False
    return True


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
    if np.linalg.norm(d1 - t * d0) > STRAIGHT * np.linalg.norm(d1):
        return None  # the inputs turned: no straight line to follow
    return q0 + (q0 - qp) * t


def _det_sign(model: Model, sol: Solution, L) -> int:
    """The sign of det(g_q) (the product of the groups' modes); 0 near a singular position,
    and for a tall g_q (redundant joints), which has no determinant."""
    if not model.square:
        return 0
    return int(np.prod(modes(model, sol.J, L)[0]))


def _same_branch(model: Model, J0, sol: Solution, L) -> bool:
    """Whether every Assur group kept its mode from J0 to sol.J (or is nearly singular at
    either: there the mode is not defined, and the sweep's events locate the crossing).

    A tall g_q (redundant joints) has no determinant, but a relative invariant serves:
    with J0 = Q0 R0 (Q0 an orthonormal basis of J0's column space), det(Q0' J) is
    continuous in J and equals det R0 at J0, so it changes sign only where Q0' J is
    singular: det(Q0' J1) and det(R0) of opposite signs mean a singular position was
    crossed, exactly as det g_q's sign change does for a square system."""
    if model.square:
        s0, s1 = modes(model, J0, L)[0], modes(model, sol.J, L)[0]
        return not branch.changed(s0, s1).any()
    c = model.column_scale(L)
    Q0, R0 = np.linalg.qr(J0 * c)
    d0, d1 = float(np.prod(np.diag(R0))), float(np.linalg.det(Q0.T @ (sol.J * c)))
    return np.sign(d0) == np.sign(d1) or min(abs(d0), abs(d1)) < BRANCH
