"""The careful path of a sweep: continuation with step cutting, recovery after a failure,
and the branch a sweep resumes on after poses with no assembly; and the designs' first poses,
continued in the parameters. Both walks are the one continuation (kincas/analysis/path.py).

A pose the fast pass does not accept is solved here from the last solved pose: predicted along
the exact tangent dq/du = -g_q^-1 g_u (or the secant through the pose before, next to a
singular position), corrected by Newton, the step halved where the corrector fails, wanders or
changes the sign of det g_q.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.assembly import assemble, modes
from ..core.batch import BatchEvaluator, batched_solve as _solve
from ..core.blocks import numeric_signs
from ..core.designs_kernel import MAX_STEPS, NEWTON, STEP
from ..core.newton import stop_rule
# the first pose of a sweep (its home is the core: `kincas modes` and `range` start there too)
from ..core.assembly import ambiguous as _ambiguous, first_pose as _first, no_assembly as _no_assembly  # noqa: F401
from ..core import branch
from ..core.numeric import Model, Solution
from ..core.limits import on_step, polish_singular
from ..core.tolerances import ACCEPT, BRANCH, CAREFUL_DEPTH, ILL, NEAR_SINGULAR, SLOW, STRAIGHT
from ..model.mechanism import Mechanism
from .path import Bisect, Steps, Walk, follow, follow_all, wandered
from .resume import carry_groups, larger_groups, resume_label
from .watch import passes_singular as _passes_singular, watch_conditioning, within_reach  # noqa: F401


@dataclass
class _Pose:
    """The pose a walk starts from (a Solution's `q`, without its Newton)."""

    q: np.ndarray


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
        sol = _continue(model, run.Q[j], U[j], u, p, L, depth=CAREFUL_DEPTH if fresh else 0, prev=prev, reach=reach)
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


def walk_inputs(model: Model, q0, u0, u1, p, L, depth: int, prev=None) -> Walk:
    """The careful path's walk from the solved pose (q0, u0) to the inputs u1 (the one
    continuation, kincas/analysis/path.py: a step to u1 halved `depth` times at most).

    Each step is predicted along the exact tangent dq/du, except where g_q is nearly
    singular: there the tangent is undefined (at a change point two branches cross), and
    the secant through the pose before (`prev` = (q, u) before q0) carries the branch
    straight through. Newton corrects it. A step is cut when the corrector fails ("not
    converged") or needs many iterations ("slow"), lands far from the prediction
    ("wandered"), a group's mode (sign of its block of det g_q) changes ("branch
    changed"), or a singular position lies inside it ("singular crossed"). The shortest
    step is kept where every group kept its mode or changed it by crossing a singular
    position of its own that lies in the step (else it jumped branch).

    Returns the Walk: `at` the Solution at u1 where `reason` is "reached"; `reach` the
    (Solution, u) of every intermediate pose solved, in order (where it failed, the last
    entry is as far as the branch was followed).
    """
    def step(w):
        qa, ua, ub = w.at.q, w.where, w.target
        J0 = model.jac(qa, ua, p)
        before = w.before
        pred = _secant(qa, ua, ub, (before[0].q, before[1])) \
            if before is not None and _ill(model, J0, L) else None
        if pred is None:
            pred = qa + model.tangent(qa, ua, p) @ (ub - ua)
        sol = model.newton(pred, ub, p, L)
        if not sol.ok:
            return sol, "not converged"
        ends = []

        def measured():  # each end's groups' (modes, conditioning): the tests below share them
            if not ends:
                ends.extend((modes(model, J0, L), modes(model, sol.J, L)))
            return ends
        if w.last:  # the shortest step: a group may change mode only by crossing
            # a singular position of its own that lies in this step (else it jumped branch)
            kept = _same_branch(model, J0, sol, L, measured) or _crossed(model, qa, ua, ub, J0, sol, p, L, measured)
            return sol, None if kept else "branch changed"
        if sol.iterations > SLOW:
            return sol, "slow"
        if wandered(qa, pred, sol.q, np.where(model.is_length, L, 1.0)):
            return sol, "wandered"
        if not _same_branch(model, J0, sol, L, measured):
            return sol, "branch changed"
        if _passes_singular(model, qa, ua, ub, J0, sol, p, L, measured):
            return sol, "singular crossed"
        return sol, None
    start = _Pose(np.asarray(q0))
    before = None if prev is None else (_Pose(np.asarray(prev[0])), prev[1])
    return follow(start, u0, Bisect(u1, depth, before), step)


def _continue(model: Model, q0, u0, u1, p, L, depth: int, prev=None, reach=None) -> Solution | None:
    """The Solution at u1 continued from (q0, u0) by `walk_inputs`, or None where the walk
    stopped short. `reach`, a list, receives (q, u) of every intermediate pose solved, in
    order: where the walk failed, its last entry is as far as the branch was followed."""
    w = walk_inputs(model, q0, u0, u1, p, L, depth, prev)
    if reach is not None:
        reach.extend((sol.q, u) for sol, u in w.reach)
    return w.at if w.ok else None


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
            _continue(model, sol.q, U[k], U[j], p, L, depth=CAREFUL_DEPTH, reach=back)
            near_k = back[-1] if back else (sol.q, U[k])
            run.__dict__.setdefault("crossed", []).append((int(j), int(k), near_j, near_k))
            return True
    return False


def _crossed(model: Model, q0, u0, u1, J0, sol: Solution, p, L, measured=None) -> bool:
    """Whether every group whose mode differs between J0 (at u0) and sol (at u1) has a
    singular position of its own between u0 and u1 (located from the nearer end).
    `measured()`, if given, returns `modes` at J0 and at sol.J."""
    from .singular import locate_singular
    (s0, c0), (s1, c1) = measured() if measured is not None else (modes(model, J0, L), modes(model, sol.J, L))
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
    return not c < ILL * max(1.0, np.sqrt(J.shape[0]))


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


def _same_branch(model: Model, J0, sol: Solution, L, measured=None) -> bool:
    """Whether every Assur group kept its mode from J0 to sol.J (or is nearly singular at
    either: there the mode is not defined, and the sweep's events locate the crossing).

    A tall g_q (redundant joints) has no determinant, but a relative invariant serves:
    with J0 = Q0 R0 (Q0 an orthonormal basis of J0's column space), det(Q0' J) is
    continuous in J and equals det R0 at J0, so it changes sign only where Q0' J is
    singular: det(Q0' J1) and det(R0) of opposite signs mean a singular position was
    crossed, exactly as det g_q's sign change does for a square system. `measured()`, if
    given, returns `modes` at J0 and at sol.J."""
    if model.square:
        (s0, _), (s1, _) = measured() if measured is not None else (modes(model, J0, L), modes(model, sol.J, L))
        return not branch.changed(s0, s1).any()
    c = model.column_scale(L)
    Q0, R0 = np.linalg.qr(J0 * c)
    d0, d1 = float(np.prod(np.diag(R0))), float(np.linalg.det(Q0.T @ (sol.J * c)))
    return np.sign(d0) == np.sign(d1) or min(abs(d0), abs(d1)) < BRANCH


def walk_parameters(model, u, q0, p0, P, Ls, sign0, blocks=None) -> list:
    """The designs' first poses, continued from the nominal's (q0 at the parameters p0, the
    inputs u) to each design's parameters (rows of P, sizes Ls): the one continuation
    (kincas/analysis/path.py), every design one walk of fixed steps, all in lockstep with one
    batched step. A step of at most STEP times the size in every parameter (counted per
    design, so that a design's numbers do not depend on the others computed with it: chunks
    on a cluster), predicted along dq = -g_q^-1 g_p dp, corrected by Newton (undamped: the
    predictor starts it close; each design stopping by the one rule of kincas/core/newton.py)
    and kept where its residual is accepted ("not converged" else) and every Assur group kept
    the nominal's mode `sign0` ("branch changed" else: kincas/core/branch.py). Returns the
    walks: `at` the design's unknowns where `ok`, `reason` the stop as every walk gives it."""
    nd = P.shape[0]
    dP = P - p0
    steps = np.clip(np.ceil(np.abs(dP).max(axis=1, initial=0.0) / (STEP * Ls)), 1, MAX_STEPS).astype(int)
    walks = [Walk(np.asarray(q0, float), p0, Steps([p0 + dP[d] * (i / steps[d]) for i in range(1, steps[d] + 1)]))
             for d in range(nd)]
    pos = {id(w): d for d, w in enumerate(walks)}
    ev = BatchEvaluator(model)
    length = model.is_length[None, :]
    blocks = list(model.blocks) if blocks is None else blocks

    def step(live):
        a = np.array([pos[id(w)] for w in live])
        qa, pc, pt = np.stack([w.at for w in live]), np.stack([w.where for w in live]), np.stack([w.target for w in live])
        ua, La = np.repeat(u[None, :], len(a), axis=0), Ls[a]
        _, J, _, Gp = ev.derivatives(qa, ua, pc)
        qa = qa - _solve(J, np.einsum("dij,dj->di", Gp, pt - pc))
        D, go, last = np.where(length, La[:, None], 1.0), np.ones(len(a), bool), np.inf
        for _ in range(NEWTON):
            gv, J, _, _ = ev.derivatives(qa, ua, pt)
            dq = _solve(J, gv)
            size = np.abs(dq / D).max(axis=1, initial=0.0)
            converged, stalled = stop_rule(np.abs(gv).max(axis=1) / La, size, last)
            qa = np.where((go & ~stalled)[:, None], qa - dq, qa)
            go, last = go & ~(converged | stalled), size
            if not go.any():
                break
        gv, J, _, _ = ev.derivatives(qa, ua, pt)
        r = np.abs(gv).max(axis=1) / La
        with np.errstate(all="ignore"):
            s = numeric_signs(J * np.where(length, 1.0, 1.0 / La[:, None])[:, None, :], blocks)
        solved = (r <= ACCEPT) & np.isfinite(qa).all(axis=1)
        kept = branch.kept(sign0, s)
        return [(qa[j], None if solved[j] and kept[j] else "not converged" if not solved[j] else "branch changed")
                for j in range(len(a))]
    return follow_all(walks, step)
