"""Which mode each Assur group resumes in after a gap: proven the same, proven other, or unknown.

A dyad's mode is the sign of its block's determinant (which of its two circle points it
takes): an invariant of each pose, so equal signs before and after a gap are the same mode.
A larger group has more assemblies than signs (a class-III triad up to six), so for it equal
signs prove nothing. Its mode after a gap is established in one of two ways, else it is
reported as unknown, with the reason, and never as "same":

- **carried**: where the group and the groups it is built on assemble at every input of the
  gap (a later group is the one that has no assembly), they alone are continued through the
  gap's inputs by the one continuation (kincas/analysis/path.py: predictor along the exact
  tangent, Newton corrector group by group, the step halved where it fails, wanders from the
  prediction or changes a block's sign). The
  assembly they arrive at is the mode left; the resumed one is it, or another.
- **the same limit**: where the mode left ended at a limit of the group and the resumed
  assembly begins at one, and both are the same point (the inputs came back the way they
  went), exactly two real branches meet there, and their block signs differ: equal signs,
  the same branch.

The same rules label a pose where the mode followed ended at a limit while another assembly
of the same sign goes on (no gap at all): that change is a "resume" event, never silent.

>>> import numpy as np
>>> label_text({"branch": "unknown", "unknown": [["leg1", "plate"]], "reason": "r"})
'resumed, mode of group leg1+plate unknown (r)'
"""
from __future__ import annotations

import numpy as np

from ..core import branch
from ..core.assembly import _block_newton, blocks, group_links, modes
from ..core.limits import locate_singular, on_step
from ..core.tolerances import ACCEPT, CARRY_BUDGET, CARRY_DEPTH, CARRY_ITER, SAME_ASSEMBLY as SAME, SAME_INPUT
from .path import Bisect, follow, wandered

WIDE = 2  # a group with more unknowns than this has more assemblies than block signs
# SAME: two assemblies are one when every unknown agrees to this (lengths over L)
DEPTH, BUDGET = CARRY_DEPTH, CARRY_BUDGET  # halvings of, and solves spent on, one input step of a gap

REASON = ("its assemblies of one sign are told apart neither by continuation (it has no "
          "assembly in the gap) nor by a limit it left and came back through")


# --- which groups need more than a sign ---


def larger_groups(model) -> list[int]:
    """Indices of the Assur groups whose block sign does not identify their assembly.

    Parameters
    ----------
    model : kincas.core.numeric.Model

    Returns
    -------
    list of int
        The groups with more than two unknowns (none where g_q is tall: redundant joints).

    Examples
    --------
    >>> import kincas
    >>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},     # the examples' triple rocker
    ...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 1.9),
    ...            kincas.Link.bar("rocker", "D", "C", 3)],
    ...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.2, 2.5)})
    >>> larger_groups(kincas.model_of(m))  # a four-bar's one group is a dyad
    []
    """
    if not model.square:
        return []
    return [i for i, (_, cols) in enumerate(blocks(model)) if len(cols) > WIDE]


# --- the label of a resume ---


def resume_label(model, U, p, L, j, qj, k, qk, carried=None) -> dict:
    """How pose k (unknowns qk) resumed from the last solved pose j (qj) across U[j+1..k-1].

    Parameters
    ----------
    model : kincas.core.numeric.Model
    U : numpy.ndarray
        The sweep's inputs, (n, nu).
    p : numpy.ndarray
        Parameter values.
    L : float
        The mechanism's size.
    j, k : int
        The last solved pose before the resume, and the resumed pose.
    qj, qk : numpy.ndarray
        Their unknowns.
    carried : dict, optional
        {group: unknowns at U[k] or None}, from `carry_groups` if already computed.

    Returns
    -------
    dict
        "branch": "same", "other" (some group provably in another mode: "groups" lists
        their links) or "unknown" (no group changed provably, some could not be
        established: "unknown" lists them and "reason" says why).

    Examples
    --------
    A triple rocker has no assembly from 151.2 to 208.8 deg; at 220 deg its dyad is back on
    the side it left (the sign of its block, which is a dyad's mode):

    >>> import numpy as np, kincas
    >>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},     # the examples' triple rocker
    ...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 1.9),
    ...            kincas.Link.bar("rocker", "D", "C", 3)],
    ...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.2, 2.5)})
    >>> U = np.radians([[140.0], [180.0], [220.0]])
    >>> sw = kincas.sweep(m, {"crank.angle": U[:, 0]}, report=["C.y"])
    >>> sw.status.tolist()
    ['ok', 'no assembly', 'ok']
    >>> resume_label(kincas.model_of(m), U, np.zeros(0), m.size(), 0, sw.q[0], 2, sw.q[2])
    {'branch': 'same'}
    """
    before = modes(model, model.jac(qj, U[j], p), L)[0]
    after = modes(model, model.jac(qk, U[k], p), L)[0]
    changed = {int(i) for i in np.flatnonzero(branch.changed(before, after))}
    unknown = []
    for i in larger_groups(model):
        if i in changed or before[i] == 0 or after[i] == 0:
            continue
        if any(g < i for g in changed):  # built on a group that changed: a new configuration
            unknown.append(i)
            continue
        q = (carried if carried is not None else carry_groups(model, U, p, L, j, qj, k, [i])).get(i)
        if q is not None:
            if not _same(model, q, qk, L, i):
                changed.add(i)
        elif not _same_limit(model, U, p, L, j, qj, k, qk, i):
            unknown.append(i)
    names = group_links(model)
    out = {"branch": "other" if changed else "unknown" if unknown else "same"}
    if changed:
        out["groups"] = [names[i] for i in sorted(changed)]
    if unknown:
        out["unknown"] = [names[i] for i in unknown]
        out["reason"] = REASON
    return out


def label_text(e: dict) -> str:
    """A resume event in words (for the command line).

    Parameters
    ----------
    e : dict
        A "resume" event.

    Returns
    -------
    str

    Examples
    --------
    >>> label_text({"branch": "other", "groups": [["coupler", "rocker"]]})
    'resumed on the other branch'
    """
    if e["branch"] != "unknown":
        return f"resumed on the {e['branch']} branch"
    groups = ", ".join("+".join(g) for g in e["unknown"])
    return f"resumed, mode of group {groups} unknown ({e['reason']})"


# --- carried through the gap ---


def carry_groups(model, U, p, L, j, qj, k, groups, memo=None) -> dict:
    """{group: unknowns at U[k], or None}: each group in `groups` with the groups before it,
    continued from the solved pose j through the inputs U[j+1], ..., U[k]. `memo` (a dict
    kept by the caller for one sweep) keeps how far each carry got, so that the poses of one
    gap, tried one after another, continue it by one step each.

    Parameters
    ----------
    model : kincas.core.numeric.Model
    U, p, L, j, qj, k
        As for `resume_label`.
    groups : list of int
        The groups to carry (each with the groups before it).
    memo : dict, optional
        How far each carry got, kept by the caller across the poses of one sweep.

    Returns
    -------
    dict
        {group: unknowns at U[k] (those of the groups carried; the others as in qj), or None
        where a group or one before it has no assembly somewhere in the gap}.

    Examples
    --------
    The triple rocker's dyad cannot be carried through the inputs where it has no assembly:

    >>> import numpy as np, kincas
    >>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},     # the examples' triple rocker
    ...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 1.9),
    ...            kincas.Link.bar("rocker", "D", "C", 3)],
    ...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.2, 2.5)})
    >>> U = np.radians([[140.0], [180.0], [220.0]])
    >>> q0 = kincas.sweep(m, {"crank.angle": U[:1, 0]}).q[0]
    >>> carry_groups(kincas.model_of(m), U, np.zeros(0), m.size(), 0, q0, 2, [0])
    {0: None}
    """
    out = {}
    for i in sorted(groups, reverse=True):  # the longest chain first: it carries the others
        if i in out:
            continue
        q = _carry(model, U, p, L, j, qj, k, i, {} if memo is None else memo)
        out[i] = q
        if q is not None:
            out.update({g: q for g in groups if g < i})
    return out


def _carry(model, U, p, L, j, qj, k, i, memo):
    start, q = memo.get((j, i), (j, None))
    if start > k or start == j:  # nothing carried yet (or past k): from pose j
        start, q = j, np.array(qj, float)
    if q is None or start == k:  # failed on the way to k, or already there
        return q
    bl = blocks(model)
    R = np.concatenate([bl[b][0] for b in range(i + 1)])
    C = np.concatenate([bl[b][1] for b in range(i + 1)])
    scale = np.where(model.is_length, L, 1.0)[C]
    signs = modes(model, model.jac(qj, U[j], p), L)[0][:i + 1]
    if np.any(signs == 0):
        return None

    def step(w):  # groups 0..i predicted along their tangent, each corrected by its own Newton
        q, u0, u1 = w.at, w.where, w.target
        _, J, Ju = model._tangent(q, u0, p)
        with np.errstate(all="ignore"):
            try:
                t = np.linalg.solve(J[np.ix_(R, C)], -np.asarray(Ju)[R])
            except np.linalg.LinAlgError:
                t = np.zeros((len(C), len(u0)))
        pred = q.copy()
        pred[C] = q[C] + (t @ (u1 - u0) if np.all(np.isfinite(t)) else 0.0)
        x = pred.copy()
        for b in range(i + 1):  # the later groups left as they are
            x, r = _block_newton(model, x, u1, p, L, b, max_iter=CARRY_ITER)
            if not r <= ACCEPT:
                return None, "not converged"
        if wandered(q[C], pred[C], x[C], scale):
            return None, "wandered"
        got = modes(model, model.jac(x, u1, p), L)[0][:i + 1]
        if not (got.all() and branch.kept(signs, got)):  # every group defined, in its mode
            return None, "branch changed"
        return x, None

    for kk in range(start + 1, k + 1):  # one walk per input step, with its own budget
        w = follow(q, U[kk - 1], Bisect(U[kk], DEPTH), step, budget=BUDGET)
        q = w.at if w.ok else None
        memo[(j, i)] = (kk, q)
        if q is None:
            return None
    return q


def _same(model, qa, qb, L, i) -> bool:
    """Whether groups 0..i have the same assembly in qa and qb (angles modulo a turn)."""
    cols = np.concatenate([blocks(model)[b][1] for b in range(i + 1)])
    d = (np.asarray(qa) - np.asarray(qb))[cols]
    is_len = model.is_length[cols]
    d = np.where(is_len, d / L, np.angle(np.exp(1j * d)))
    return bool(np.abs(d).max(initial=0.0) <= SAME)


# --- the same limit, left and come back through ---


def _same_limit(model, U, p, L, j, qj, k, qk, i) -> bool:
    """Whether the mode left at pose j ends at a limit of group i that is also where the
    resumed assembly at pose k begins (located from each end toward the gap)."""
    if j + 1 >= len(U) or k < 1:
        return False
    ends = []
    for q, u, nb in ((qj, U[j], U[j + 1]), (qk, U[k], U[k - 1])):
        found = locate_singular(model, q, u, p, L, nb - u, group=i)
        if not on_step(found):
            return False
        ends.append(found)
    (qa, ua, _), (qb, ub, _) = ends
    if np.abs(np.asarray(ua) - np.asarray(ub)).max() > SAME_INPUT * max(1.0, float(np.abs(ua).max())):
        return False
    return _same(model, qa, qb, L, i)


# --- resumes the fast pass made ---


def unlabelled_resumes(model, U, p, L, Q, ok, events) -> list[dict]:
    """"resume" events for the poses solved after a gap that have none yet (the compiled
    pass went on from the last solved pose by itself), labelled as `resume_label` does.

    Parameters
    ----------
    model : kincas.core.numeric.Model
    U, p, L
        As for `resume_label`.
    Q : numpy.ndarray
        (n, nq) unknowns per pose.
    ok : numpy.ndarray of bool
        Which poses are solved.
    events : list of dict
        The sweep's events so far.

    Returns
    -------
    list of dict
        The events to add.

    Examples
    --------
    >>> import numpy as np, kincas
    >>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},     # the examples' triple rocker
    ...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 1.9),
    ...            kincas.Link.bar("rocker", "D", "C", 3)],
    ...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.2, 2.5)})
    >>> U = np.radians([[140.0], [180.0], [220.0]])
    >>> sw = kincas.sweep(m, {"crank.angle": U[:, 0]}, report=["C.y"])
    >>> unlabelled_resumes(kincas.model_of(m), U, np.zeros(0), m.size(), sw.q, sw.ok, sw.events)
    []
    >>> unlabelled_resumes(kincas.model_of(m), U, np.zeros(0), m.size(), sw.q, sw.ok, [])
    [{'kind': 'resume', 'pose': 2, 'branch': 'same'}]
    """
    idx = np.flatnonzero(ok)
    gaps = np.flatnonzero(np.diff(idx) > 1)  # only a pose after a gap can need one (no loop over all)
    if not gaps.size:
        return []
    have = {e["pose"] for e in events if e["kind"] == "resume"}
    out = []
    for g in gaps:
        j, k = idx[g], idx[g + 1]
        if int(k) not in have:
            out.append({"kind": "resume", "pose": int(k)} | resume_label(model, U, p, L, j, Q[j], k, Q[k]))
    return out
