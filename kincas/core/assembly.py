"""Assembly group by group: each Assur group's mode, its conditioning, and a pose built without
a guess.

g_q in block-triangular form has one irreducible diagonal block per Assur group (a dyad's block
is 2 x 2); the equations of block i involve only the unknowns of blocks 0..i. So:

- a group's **assembly mode** is the sign of its block's determinant, det(g_q[rows, cols]):
  for a dyad it is exactly which of its two circle intersections it takes. A pose's mode is
  the vector of these signs, one per group; det g_q (their product) cannot tell (+, +) from
  (-, -), the vector can.
- a group's **conditioning** is its block's smallest singular value relative to its largest,
  columns scaled to O(1) (angles times a length, lengths as ratios): a pure number, the same
  for a mechanism of 1e-6 m and of 1e6 m. It is 0 where the group is at a singular position.
- a pose is **assembled** group by group in solve order: each block by a small Newton on its
  own equations (the blocks before it fixed) from a few starts, keeping the solution in the
  wanted mode (default +1: the mode whose block determinant is positive) nearest a reference
  pose. A group with no solution from any start has no assembly there: that is decided in a
  few block Newton steps, without an optimiser.
- at a pose at (or within rounding of) a singular position, `polish_singular`
  (kincas/core/limits.py) puts the unknowns exactly on it: the extended system g = 0,
  g_q[rows, cols] v = 0, v0.v = 1 at fixed inputs, which converges quadratically where
  plain Newton crawls (g_q singular).

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)], inputs=[kincas.Input.angle("crank")])
>>> model = kincas.model_of(m)
>>> sol = assemble(model, np.array([0.0]), np.zeros(0), m.size())
>>> sol.ok, modes(model, sol.J, m.size())[0].tolist()  # no guess needed: the default mode
(True, [1])
"""
from __future__ import annotations

import numpy as np

from .newton import newton
from .turns import nearest, settle, tied, turns, wandered
from .numeric import Solution
from .tolerances import ACCEPT, NEAR_SINGULAR, ROUNDING_REL, SIGN_TOL, TOL  # noqa: F401


# --- the groups: blocks of g_q ---


def blocks(model) -> list[tuple[np.ndarray, np.ndarray]]:
    """(rows, cols) of each Assur group's block of g_q, in solve order (a block's equations
    involve only its own unknowns and those of the blocks before it): `model.blocks`
    (kincas/core/structure.py) as index arrays. A tall g_q (redundant joints) is one block."""
    return model.memo("assembly.blocks", lambda: [(np.asarray(b.rows, int), np.asarray(b.cols, int))
                                                  for b in model.blocks])


def group_links(model) -> list[list[str]]:
    """The links whose unknowns each group solves (how events and resumes name a group)."""
    names = model.sym.unknown_links()
    return [sorted({names[j] for j in cols}) for _, cols in blocks(model)]


def modes(model, J, L) -> tuple[np.ndarray, np.ndarray]:
    """Each Assur group's mode and conditioning at one pose or many.

    Parameters
    ----------
    model : kincas.core.numeric.Model
    J : numpy.ndarray
        g_q at one pose (ng, nq) or at many (n, ng, nq).
    L : float
        The mechanism's size (columns of angles are scaled by 1/L: only positive factors,
        so the signs are those of the unscaled blocks).

    Returns
    -------
    mode : numpy.ndarray of int
        (groups,) or (n, groups): the sign of each block's determinant, 0 where the block is
        within SIGN_TOL of singular (or tall: redundant joints).
    conditioning : numpy.ndarray
        Same shape: sigma_min / sigma_max of each column-scaled block (a 1 x 1 block:
        its entry's magnitude, at most 1).

    Examples
    --------
    >>> import numpy as np, kincas
    >>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
    ...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 4),
    ...            kincas.Link.bar("rocker", "D", "C", 1)], inputs=[kincas.Input.angle("crank")])
    >>> model = kincas.model_of(m)
    >>> q = np.array([np.pi / 2, 0.0])  # a parallelogram at 90 deg (rocker, coupler angles)
    >>> mode, cond = modes(model, model.jac(q, np.array([np.pi / 2]), np.zeros(0)), 4.0)
    >>> mode.tolist(), bool(cond[0] > 0.1)
    ([1], True)
    """
    J = np.asarray(J, float)
    one = J.ndim == 2
    J = J[None] if one else J
    n, bl = J.shape[0], blocks(model)
    sign, cond = np.zeros((n, len(bl)), int), np.zeros((n, len(bl)))
    c = model.column_scale(L)
    # the blocks of one shape in one batched SVD (LAPACK runs per matrix: the same numbers)
    for idx, R, C in _by_shape(model):
        B = J[:, R[:, :, None], C[:, None, :]] * c[C][None, :, None, :]  # (n, blocks, r, c)
        good = np.isfinite(B).all(axis=(2, 3))
        if not good.any():
            continue
        s = np.linalg.svd(B[good], compute_uv=False)
        ni = np.nonzero(good)
        # a 1 x 1 block's sigma_min / sigma_max is always 1: its entry (columns scaled to
        # O(1)) is measured against 1 instead, as the kernel measures every block (a slider
        # crank's rod, whose block is l cos(phi) / L, is singular where the rod is square
        # to the slide)
        top = s[:, 0] if B.shape[2] > 1 or B.shape[3] > 1 else np.maximum(s[:, 0], 1.0)
        cond[ni[0], idx[ni[1]]] = s[:, -1] / np.maximum(top, np.finfo(float).tiny)
        if B.shape[2] == B.shape[3]:
            sign[ni[0], idx[ni[1]]] = np.sign(np.linalg.det(B[good])) * (cond[ni[0], idx[ni[1]]] >= SIGN_TOL)
    return (sign[0], cond[0]) if one else (sign, cond)


def _by_shape(model):
    """The groups by block shape: (their indices, rows (k, r), cols (k, c)) per shape."""
    def build():
        shapes = {}
        for i, (rows, cols) in enumerate(blocks(model)):
            shapes.setdefault((len(rows), len(cols)), []).append(i)
        bl = blocks(model)
        return [(np.array(ix), np.array([bl[i][0] for i in ix]), np.array([bl[i][1] for i in ix]))
                for ix in shapes.values()]
    return model.memo("assembly.by_shape", build)


# --- group by group assembly ---


def _block_newton(model, q, u, p, L, i, max_iter=30):
    """The one Newton (kincas/core/newton.py) on group i alone, the other unknowns fixed, its
    residual measured against its own length: (q, relative residual)."""
    rows, cols = blocks(model)[i]
    eq, qs = model.scales(u, p)
    call = model._block_calls()[i]
    q = q.copy()

    def F(x):
        q[cols] = x
        g, J = call(q, u, p)
        return g.ravel(), J
    res = newton(F, q[cols], qs[cols], eq[rows], max_iter=max_iter)
    q[cols] = res.x
    return q, res.residual


def _starts(model, cols, L, near, count):
    """Start values for a block's unknowns: the reference pose's first, then a spread."""
    is_len = model.sym.is_length[cols]
    out = [] if near is None else [np.asarray(near, float)[cols]]
    k = len(cols)
    grid = np.array([0.3, 2.4, -1.8, 1.2, -0.6, 3.0, -2.7, 0.9])
    rng = np.random.default_rng(k)  # a local, seeded generator: reproducible starts
    for i in range(count):
        if k <= 2 and i < len(grid):  # a dyad: spread over both circles
            v = np.array([grid[i], grid[(3 * i + 1) % len(grid)]])[:k]
        else:
            v = rng.uniform(-np.pi, np.pi, k)
        out.append(np.where(is_len, v * L, v))
    return out


# --- a dyad of two angles: its circle intersections ---


def _dyad(model, q, u, p, L, i):
    """Group i's equations, where it is a dyad of two angles, in the form
    g(t1, t2) = c + R(t1) m1 + R(t2) m2 (the other unknowns fixed at q): (c, m1, m2), read
    off five evaluations of g and checked at a sixth; None for any other group."""
    rows, cols = blocks(model)[i]
    if len(rows) != 2 or len(cols) != 2 or model.sym.is_length[cols].any():
        return None

    def g(t1, t2):
        x = q.copy()
        x[cols] = t1, t2
        return model.residual(x, u, p)[rows]
    g00, gp0, g0p = g(0.0, 0.0), g(np.pi, 0.0), g(0.0, np.pi)
    a1, a2 = (g00 - gp0) / 2, (g00 - g0p) / 2  # M1 e1, M2 e1
    b1 = g(np.pi / 2, 0.0) - (g00 + gp0) / 2  # M1 e2
    b2 = g(0.0, np.pi / 2) - (g00 + g0p) / 2  # M2 e2
    c = (g00 + gp0) / 2 - a2
    M1, M2 = np.column_stack([a1, b1]), np.column_stack([a2, b2])
    rot = lambda M: abs(M[0, 0] - M[1, 1]) + abs(M[0, 1] + M[1, 0]) <= ROUNDING_REL * (np.abs(M).max() + L)
    if not (rot(M1) and rot(M2)):
        return None  # not two rotations (a reflected frame, a slide): Newton's business
    t = np.array([0.7, -1.9])
    e = lambda a: np.array([np.cos(a), np.sin(a)])
    if np.abs(c + M1 @ e(t[0]) + M2 @ e(t[1]) - g(*t)).max() > ROUNDING_REL * L:
        return None
    return c, a1, a2


def _dyad_solutions(model, q, u, p, L, i, near):
    """The dyad's assemblies (its two circle intersections; one at a limit, none where the
    circles miss each other: the discriminant decides), each angle taken nearest the
    reference pose's; None where group i is not such a dyad."""
    form = _dyad(model, q, u, p, L, i)
    if form is None:
        return None
    c, m1, m2 = form
    v, r1, r2 = -c, float(np.hypot(*m1)), float(np.hypot(*m2))
    d = float(np.hypot(*v))
    if d <= ROUNDING_REL * L:
        return None if abs(r1 - r2) <= ROUNDING_REL * L else []  # concentric: a continuum, or none
    x = (d * d + r1 * r1 - r2 * r2) / (2 * d)
    h2 = r1 * r1 - x * x
    if h2 < -ROUNDING_REL * L * L:
        return []  # the circles miss each other: no assembly
    h = np.sqrt(max(h2, 0.0))
    e = v / d
    n = np.array([-e[1], e[0]])
    cols = blocks(model)[i][1]
    ref = q[cols] if near is None else np.asarray(near, float)[cols]
    out = []
    for side in ((1,) if h == 0 else (1, -1)):
        X = x * e + side * h * n
        t = np.array([np.arctan2(X[1], X[0]) - np.arctan2(m1[1], m1[0]),
                      np.arctan2(v[1] - X[1], v[0] - X[0]) - np.arctan2(m2[1], m2[0])])
        t += 2 * np.pi * np.round((ref - t) / (2 * np.pi))  # the turn of the reference pose
        qs = q.copy()
        qs[cols] = t
        out.append(qs)
    return out


def _candidates(model, q, u, p, L, i, target, near, starts):
    """Solutions of group i (the groups before it fixed in q): first one in mode `target`
    (from the reference pose's start, then spread starts), then one in another mode. A
    dyad of two angles gets its circle intersections instead of Newton runs."""
    rows, cols = blocks(model)[i]
    c = np.where(model.sym.is_length, 1.0 / L, 1.0)
    far = lambda qs: 0.0 if near is None else float(np.abs((qs - near) * c).sum())  # noqa: E731
    closed = _dyad_solutions(model, q, u, p, L, i, near)
    if closed is not None:
        found = [(modes(model, model.jac(qs, u, p), L)[0][i], far(qs), qs) for qs in closed]
        yield from ((t[0], t[2]) for t in sorted(found, key=lambda t: (target != 0 and t[0] != target, t[1])))
        return
    # a gear's or rack's angle: its assemblies lie about a turn apart (kincas/core/turns.py),
    # each start may land on another: every start is run and the nearest of each mode kept
    ties = bool(tied(model)[cols].any())
    every = near is not None and ties
    other, taken, found = None, None, {}
    before = np.concatenate([c for _, c in blocks(model)[:i]] + [np.zeros(0, int)])
    for s in _starts(model, cols, L, near, starts if len(cols) <= 2 else 4 * starts):
        q0 = q.copy()
        q0[cols] = s
        if ties:  # the turns that gears and racks want, from the groups before (core/turns.py)
            q0 = turns(model, q0, u, p, cols=cols, known=set(before.tolist()), start=near is None)
        qs, r = _block_newton(model, q0, u, p, L, i)
        if r > ACCEPT:
            continue
        mode = modes(model, model.jac(qs, u, p), L)[0][i]
        if every:
            if (mode == target or mode != 0) and (mode not in found or far(qs) < far(found[mode])):
                found[mode] = qs
            continue
        if mode == target:
            yield mode, qs
            taken, target = mode, None  # one per mode
        elif other is None and mode != 0 and mode != taken:
            other = mode, qs
        if target is None and other is not None:
            break
    if other is not None:
        yield other
    yield from sorted(found.items(), key=lambda t: (target != 0 and t[0] != target, far(t[1])))


def assemble(model, u, p, L, want=None, near=None, starts: int = 8) -> Solution | None:
    """A pose assembled group by group, without a guess.

    Parameters
    ----------
    model : kincas.core.numeric.Model
    u, p : numpy.ndarray
        Inputs and parameter values.
    L : float
        The mechanism's size.
    want : sequence of int, optional
        Each group's mode (+1 or -1; 0: the one nearest `near`). Default: +1 for every group,
        and where a group's +1 mode does not assemble (here, or for a group built on it), its
        other mode. With `want`, a group whose wanted mode assembles never takes another (a
        mode is left only through a singular position of its own).
    near : numpy.ndarray, optional
        Unknowns of a reference pose: its values start each group's search, angles are taken
        in its turn, and among solutions of a mode the nearest is taken.
    starts : int
        Spread starts per group where it is not a dyad of two angles (a dyad gets its two
        circle intersections).

    Returns
    -------
    Solution or None
        None where no combination of modes assembles: decided by a dyad's discriminant, or a
        few block Newton runs for other groups, without an optimiser.

    Examples
    --------
    >>> import numpy as np, kincas
    >>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
    ...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 1.9),
    ...            kincas.Link.bar("rocker", "D", "C", 3)], inputs=[kincas.Input.angle("crank")])
    >>> model = kincas.model_of(m)  # a triple rocker: no assembly at 180 deg
    >>> assemble(model, np.array([np.pi]), np.zeros(0), m.size()) is None
    True
    """
    bl = blocks(model)
    u, p = np.asarray(u, float), np.asarray(p, float)
    # a model whose groups are not spread by turning angles (a spatial one: quaternions)
    # says how many spread starts are worth a Newton run each
    starts = min(starts, getattr(model, "assembly_starts", starts))

    def place(i, q):
        if i == len(bl):
            return q
        target = 1 if want is None else int(want[i])  # 0: the nearest, in either mode
        for mode, qs in _candidates(model, q, u, p, L, i, target, near, starts):
            done = place(i + 1, qs)
            if done is not None:
                return done
            if want is not None and target != 0 and mode == target:
                return None  # the mode asked for exists: a group never leaves it for another's sake
        return None

    q = place(0, np.zeros(model.nq) if near is None else np.array(near, float))
    if q is None:
        return None
    sol = model.newton(q, u, p, L)  # the whole system, from the assembled groups: a polish
    return sol if sol.ok else None


# --- at or next to a singular position ---


def refine(model, q, u, p, L):
    """q polished by the one Newton down to rounding (not just to TOL): next to a singular
    position an error in g of TOL moves the unknowns by TOL / sigma, so the last digits need
    the extra steps."""
    eq, qs = model.scales(u, p)
    res = newton(lambda x: model.resjac(x, u, p), np.array(q, float), qs, eq, tol=0.0, max_iter=8)
    return res.x if res.ok else np.array(q, float)


# --- the first pose: from the guess, or group by group ---


def no_assembly(model, q) -> Solution:
    return Solution(np.array(q, float), np.inf, 0, False, None)


def ambiguous(model) -> bool:
    """Whether group-by-group assembly may miss an assembly that exists: only a dyad's block
    Newton from spread starts is conclusive (two circle or circle-line intersections); larger
    groups and tall systems (redundant joints) get IPOPT as a last resort."""
    return not model.square or any(len(c) > 2 for _, c in blocks(model))


def first_pose(model, u, p, L, guess) -> Solution:
    """The first pose of a sweep (and where `kincas modes` and `kincas range` start): from
    the guessed points (the assembly nearest them, kincas/core/guessed.py), or without a
    guess group by group in the default modes (above)."""
    return settle(model, _assembled(model, u, p, L, guess), u, p, L)  # free angles in (-pi, pi]


def _assembled(model, u, p, L, guess) -> Solution:
    if model.nq == 0:
        return model.newton(np.zeros(0), u, p, L)
    if not guess:
        sol = assemble(model, u, p, L)
        if sol is not None or not ambiguous(model):
            return sol if sol is not None else no_assembly(model, np.zeros(model.nq))
    from .guessed import guessed_start  # it builds on this module
    q0 = guessed_start(model, u, p, L, guess) if guess else model.initial_q(u, p, guess, L)
    sol, grouped = model.newton(q0, u, p, L), None
    if not sol.ok and guess:  # group by group from the guessed pose, then IPOPT if in doubt
        sol = grouped = assemble(model, u, p, L, near=q0) or sol
    if sol.ok and guess and wandered(model, q0, sol.q):  # a gear's or rack's angle went turns away:
        targets = {k: np.array(v) for k, v in guess.items()}  # the assembly nearest the guess
        more = [assemble(model, u, p, L, near=q0)] if grouped is None else []
        sol = nearest(model, [sol, *more, model.nearest_assembly(q0, u, p, targets, L)], u, p, targets)
    if not sol.ok and ambiguous(model):  # IPOPT: the assembly nearest the guessed points
        sol = model.nearest_assembly(q0, u, p, {k: np.array(v) for k, v in guess.items()}, L)
    return sol
