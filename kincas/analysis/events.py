"""Singular positions met by a sweep, group by group, from per-pose measures.

The sweep hands over, for every solved pose, each Assur group's mode (the sign of its block
of g_q's determinant) and conditioning (its block's sigma_min / sigma_max, columns scaled to
O(1): a pure number, the same at 1e-6 m and at 1e6 m); see kincas/core/assembly.py. Then:

- a pose where a group's conditioning is below NEAR_SINGULAR may sit *at* a singular position (Newton
  stops about sqrt(TOL) from one): `polish_singular` decides, and where it converges the
  pose is moved exactly onto it, flagged, and its velocities and accelerations are null
  (g_q has no inverse there: `null_derivatives`), so no wrong number is ever reported;
- a group whose mode differs between two consecutive solved poses crossed a singular
  position of its own: located and flagged, one event per group (two loops folding at once
  are two events, although det g_q keeps its sign); a change that cannot be located is
  still an event (kind "singular");
- a solved pose next to one with no assembly: the limit of each group that lies between
  them is located; the same where the stretch with no assembly lies inside one step
  between two solved poses (the careful path finds it where continuation of the step
  fails, kincas/analysis/continuation.py): both poses flagged, the pose after it a resume;
- a pose whose whole g_q is numerically singular is flagged where it stands.

Events carry "kind", "pose", "inputs" and "group" (the links of the group concerned).

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 4),
...            kincas.Link.bar("rocker", "D", "C", 1)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (4.5, 0.87)})
>>> sw = kincas.sweep(m, {"crank.angle": np.radians([150.0, 180.0])}, report=["C.y", "C.vy"])
>>> sw.flags[1], abs(float(sw["C.y"][1])) < 1e-12, bool(np.isnan(sw["C.vy"][1]))
('change point', True, True)
"""
from __future__ import annotations

import numpy as np

from ..core import branch
from ..core.assembly import group_links, modes, refine
from ..core.limits import on_step, polish_singular
from ..core.tolerances import CLASSIFY, NEAR_SINGULAR, REACHED, SAME_INPUT
from ..model.names import parse_quantity
from .singular import FLAG_SIGMA, classify, locate_singular, scaled_jacobians

MAX_GROUPS_AT_GAP = 8  # groups tried for a limit next to a gap (the worst conditioned first)


# --- the events of a sweep ---


def sweep_events(model, m, U, Q, ok, p, L, flags, signs, sigma, crossed=()):
    """Events and flags of a sweep from the per-pose measures the solve gives.

    Parameters
    ----------
    model : kincas.core.numeric.Model
    m : kincas.Mechanism
    U, Q : numpy.ndarray
        Inputs (n, nu) and unknowns (n, nq) per pose; Q is updated where a pose is moved
        exactly onto a singular position.
    ok : numpy.ndarray of bool
        Which poses are solved.
    flags : list
        One entry per pose, filled in place.
    signs : numpy.ndarray
        (n, groups): each group's mode, the sign of its block's determinant (for a tall g_q,
        one relative orientation per pose, see `tall_orientation`).
    sigma : numpy.ndarray
        (n,): a lower bound of the groups' conditioning; only poses where it is small, and
        the ends of a change, get the exact per-group measures (`modes`) here.
    crossed : sequence of (j, k, (q, u), (q, u))
        Steps between two solved poses j and k across which the branch did not go on (a
        stretch with no assembly inside one step), each with the poses nearest the gap
        that continuation reached from j's side and from k's (kincas/analysis/continuation.py).

    Returns
    -------
    events : list of dict
    at : numpy.ndarray of bool
        The poses at a singular position (their velocities and accelerations are null).
    """
    n = len(ok)
    at = np.zeros(n, dtype=bool)
    events: list[dict] = []
    if model.nq == 0 or not m.inputs or n == 0:
        return events, at
    sigma = np.asarray(sigma, float)
    if not len(crossed) and nothing_met(ok, signs, sigma):
        return events, at
    signs = np.nan_to_num(np.asarray(signs, float)).astype(int)
    names = group_links(model)
    keys = [i.key for i in m.inputs]
    exact: dict = {}

    def measure(k):  # (modes, conditioning) of every group at pose k, from g_q there
        if k not in exact:
            exact[k] = modes(model, model.jac(Q[k], U[k], p), L)
        return exact[k]

    def event(kind, pose, u, group):
        flags[pose] = flags[pose] or kind
        events.append({"kind": kind, "pose": int(pose),
                       "inputs": {k: float(v) for k, v in zip(keys, u)}, "group": names[group]})

    def kind_at(q, u, tol=CLASSIFY):
        return classify(*scaled_jacobians(model, q, u, p, L), tol=tol) or "singular"

    # poses at a singular position: exactly onto it, flagged, one event per group
    for k in np.flatnonzero(ok & ~(sigma > NEAR_SINGULAR)):
        groups = [int(i) for i in np.flatnonzero(measure(k)[1] < NEAR_SINGULAR)]
        if not groups:
            continue
        q = polish_singular(model, Q[k], U[k], p, L, groups)
        if q is None:  # next to one, not at it: positions to rounding, derivatives null,
            # since an error of rounding in the input moves them by more than 1e-6 there
            Q[k], at[k] = refine(model, Q[k], U[k], p, L), True
            flags[k] = flags[k] or kind_at(Q[k], U[k], tol=NEAR_SINGULAR)
            step = U[k + 1] - U[k] if k + 1 < n else U[k] - U[k - 1] if k else None
            for i in groups if step is not None and np.any(step) else ():
                found = locate_singular(model, Q[k], U[k], p, L, step, group=i)
                if found is not None and abs(found[2]) <= REACHED:  # the pose all but reached it
                    event(kind_at(found[0], found[1]), k, found[1], i)
            continue
        Q[k], at[k] = q, True
        exact.pop(k)
        signs[k, groups if signs.shape[1] == len(names) else 0] = 0
        kind = kind_at(q, U[k])
        flags[k] = kind
        for i in groups:
            event(kind, k, U[k], i)
    # poses whose g_q is numerically singular as a whole, flagged where they stand
    for k in np.flatnonzero(ok & ~at & ~(sigma > 1e3 * FLAG_SIGMA)):
        J, Gu = scaled_jacobians(model, Q[k], U[k], p, L)
        sv = np.linalg.svd(J, compute_uv=False)
        if sv[-1] <= FLAG_SIGMA * max(sv[0], 1.0):
            flags[k] = flags[k] or classify(J, Gu)
    # a group changing mode between two solved poses crossed a singular position of its own
    # (the changes found for all poses at once: a Python loop over every pose cost more than
    # the compiled solve of a long sweep)
    flips = branch.changed(signs[:-1], signs[1:])
    for k in np.flatnonzero(ok[:-1] & ok[1:] & flips.any(axis=1)):
        for i in np.flatnonzero(flips[k]):
            c0, c1 = measure(k)[1][i], measure(k + 1)[1][i]
            start, other = (k, k + 1) if c0 <= c1 else (k + 1, k)
            found = locate_singular(model, Q[start], U[start], p, L, U[other] - U[start], group=int(i))
            if on_step(found):
                pose = start if found[2] <= 0.5 else other
                event(kind_at(found[0], found[1]), pose, found[1], int(i))
            else:  # crossed, but not located: said all the same
                event("singular", k + 1, U[k + 1], int(i))
    # a solved pose next to one with no assembly: the limits between them
    gap = np.r_[False, ~ok[:-1]] | np.r_[~ok[1:], False]
    for k in np.flatnonzero(ok & gap):
        for nb in (k - 1, k + 1):
            if not 0 <= nb < n or ok[nb] or np.allclose(U[nb], U[k]):
                continue
            for i in np.argsort(measure(k)[1])[:MAX_GROUPS_AT_GAP]:
                found = locate_singular(model, Q[k], U[k], p, L, U[nb] - U[k], group=int(i))
                if on_step(found):
                    event(kind_at(found[0], found[1]), k, found[1], int(i))
    # a gap inside one step between two solved poses: its limits, located from the poses
    # nearest it on either side, flag the poses before and after it
    for j, k, near_j, near_k in crossed:
        seen = len(events)
        for pose, (q, u), other in ((j, near_j, U[k]), (k, near_k, U[j])):
            if not np.any(other - u):
                continue
            cond = modes(model, model.jac(q, u, p), L)[1]
            for i in np.argsort(cond, kind="stable")[:MAX_GROUPS_AT_GAP]:
                found = locate_singular(model, q, u, p, L, other - u, group=int(i))
                if on_step(found):
                    event(kind_at(found[0], found[1]), pose, found[1], int(i))
                    break
        if len(events) == seen:  # crossed, but not located: said all the same
            event("singular", k, U[k], int(np.argmin(measure(k)[1])))
    return _distinct(events), at


def nothing_met(ok, signs, sigma, every: bool | None = None) -> bool:
    """Whether the sweep met no singular position and no gap: every pose solved (`every`,
    if the caller knows it already), every group well conditioned at every pose (none near
    NEAR_SINGULAR or FLAG_SIGMA) and in one mode throughout. The usual sweep: then none of
    the searches of `sweep_events` has anything to look at."""
    if not (ok.all() if every is None else every) or not sigma.min(initial=np.inf) > _SIGMA_BOUND:  # (NaN: not)
        return False
    signs = np.asarray(signs)
    return not np.count_nonzero(signs != signs[:1])  # (NaN != NaN: a NaN sign is a change;
    # count_nonzero costs a third of a ufunc's reduction .all())


def nothing_met_measures(M, flat=None) -> bool:
    """`nothing_met` for a sweep with every pose solved, from the fast kernel's measures as it
    writes them, pose by pose: M (N, groups + 1) each group's mode then sigma (`flat`, the
    same numbers in one row, is not needed). The same answer as `nothing_met` in a few numpy
    calls, none of them over the whole table but one matrix-vector product: each mode is -1,
    0 or +1 (NaN where not measured), so a group's modes summed over the N poses are whole
    numbers (exact), at most N in size, and each times the first pose's mode is N exactly
    where every pose has that mode, +-1; their total over the groups is then N times the
    number of groups exactly where that holds for every group (a NaN mode makes it NaN).
    Then no mode is NaN, and nothing was met exactly where every sigma exceeds the bound
    (the smallest, NaN if any is). Anything else is left to `nothing_met`."""
    n, g = M.shape
    g -= 1
    if n == 0:
        return False
    sums = _dot(_ones(n), M)  # (BLAS: a matrix-vector product)
    if g <= 8:  # (a few: in Python, a plain loop)
        for v in sums.tolist()[:g]:
            if abs(v) != n:  # (NaN: not n)
                return nothing_met(np.ones(n, dtype=bool), M[:, :-1], M[:, -1], True)
    elif not _dot(sums[:g], M[0, :g]) == n * g:  # (NaN: not)
        return nothing_met(np.ones(n, dtype=bool), M[:, :-1], M[:, -1], True)
    sigma = M[:, g]
    return bool(sigma[sigma.argmin()] > _SIGMA_BOUND)  # (the smallest, NaN if any is: argmin
    # takes NaN for the least; a third of a ufunc's reduction, which .min() goes through)


def nothing_met_summary(summary) -> bool:
    """`nothing_met` for a sweep with every pose solved, from the compiled loop's summary of
    every pose's measures (`FastRun.summary`: how many modes differ from the first pose's,
    NaN counting as different, and the smallest sigma, NaN if any is)."""
    other, low = summary
    return bool(other == 0 and low > _SIGMA_BOUND)  # (NaN: not)


_dot = np.dot
_SIGMA_BOUND = max(NEAR_SINGULAR, 1e3 * FLAG_SIGMA)  # sigma above it everywhere: nothing near singular
_ONES: dict = {}  # N -> N ones, read only


def _ones(n: int) -> np.ndarray:
    """N ones, which `nothing_met_measures` multiplies with, one array per length."""
    got = _ONES.get(n)
    if got is None:
        got = np.ones(n)
        got.flags.writeable = False
        if len(_ONES) >= 64:  # (bounded: sweeps of many lengths)
            _ONES.clear()
        _ONES[n] = got
    return got


def _distinct(events):
    """One event per singular position and group (a limit next to a gap may be found from a
    pose that all but reached it too)."""
    out = []
    for e in events:
        if not any(o["kind"] == e["kind"] and o.get("group") == e.get("group") and o["pose"] == e["pose"]
                   and all(abs(o["inputs"][k] - v) <= SAME_INPUT * max(1.0, abs(v)) for k, v in e["inputs"].items())
                   for o in out):
            out.append(e)
    return out


# --- values at a singular pose ---


def null_derivatives(model, report, values, Q, U, p, at) -> None:
    """At poses at (or next to) a singular position: positions recomputed from the exact
    pose, every quantity that needs g_q's inverse (velocities, accelerations, jerks,
    sensitivities, efforts) set to NaN; the pose's flag says why.

    Parameters
    ----------
    model : kincas.core.numeric.Model
    report : list of str
        The quantity names, one per row of `values`.
    values : numpy.ndarray
        (len(report), n), changed in place.
    Q, U, p : numpy.ndarray
        Unknowns and inputs per pose, parameter values.
    at : numpy.ndarray of bool
        The poses concerned (as `sweep_events` returns them).
    """
    idx = np.flatnonzero(at)
    if idx.size == 0 or not report:
        return
    plain = []
    for r, name in enumerate(report):
        kind, obj, attr = parse_quantity(name)
        order = model.derivative_order(obj, attr) if kind == "plain" else None
        plain.append(order == 0)
    plain = np.array(plain)
    if plain.any():
        names = [nm for nm, keep in zip(report, plain) if keep]
        zeros = np.zeros((idx.size, model.nu))
        values[np.ix_(np.flatnonzero(plain), idx)] = model.quantities(names, Q[idx], U[idx], p, zeros, zeros)
    values[np.ix_(np.flatnonzero(~plain), idx)] = np.nan
