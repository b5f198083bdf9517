"""The first pose from a guess: the guessed points decide the assembly, also of unguessed links.

`Model.initial_q` walks the spanning tree from the ground and turns each link towards a
guessed (or already placed) point of it. A link with no such point is *free* of the guess: it
keeps the angle 0, and Newton from there reaches whichever assembly that angle happens to be
near. A slider-crank driven by its slide, with only the crank pin B guessed, has its rod
placed at angle 0 from B; Newton on the dyad then swings the crank over to the mirror
assembly, B's guess notwithstanding. A quick return with only its ram guessed leaves the
slotted lever free, and Newton keeps the lever's way through the slot that angle 0 is near,
where the ram cannot be near its guess.

So each free link is tried in four turns (0, 90, 180, 270 degrees; the links placed after it
are turned towards their guessed points from wherever it puts them), Newton solves from each
start, and the assembly kept is the one whose guessed points lie nearest their guesses:

    cost = sum over guessed points P of |P - G_P|^2 / l_P^2

(l_P: the length of the Assur group that places P, the last one whose unknowns move it; points
that only the inputs move cost the same in every assembly). The links are tried one after
another in placement order, each in the turn found best for the ones before it; a start
replaces the angle-0 one only where it is nearer by more than rounding. Links whose angle the
guessed points set are not tried otherwise: their placement is the guess's own word. No free
link: the placement as it was (the common case: a four-bar, a slider-crank guessed at their
coupler points).

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(ground={"A": (0, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("rod", "B", "C", 1.78)],
...     slides=[kincas.Slide("C", "ground", through=(0, 0.45), name="guide")],
...     inputs=[kincas.Input.slide("guide")])
>>> model, u, p = kincas.model_of(m), np.array([0.662]), np.zeros(0)
>>> B = (np.cos(-2.24) + 1e-3, np.sin(-2.24) + 1e-3)  # one of two assemblies: crank at -2.241
>>> round(float(model.newton(model.initial_q(u, p, {"B": B}, 2.78), u, p).q[0]), 3)  # rod at 0
-2.848
>>> round(float(model.newton(guessed_start(model, u, p, 2.78, {"B": B}), u, p).q[0]), 3)
-2.241
"""
from __future__ import annotations

import math

import casadi as ca
import numpy as np

from .tolerances import FREE_LINKS, NEARER

TURNS = (0.0, math.pi / 2, math.pi, -math.pi / 2)


def guessed_start(model, u, p, L, guess: dict) -> np.ndarray:
    """Where Newton starts the first pose from guessed points: `Model.initial_q`, with each
    link free of the guess turned so that the assembly reached is the one nearest the guessed
    points (see the module's text); the solved pose where a turn was tried."""
    u, p = np.asarray(u, float), np.asarray(p, float)
    free: list[str] = []
    q0 = model.initial_q(u, p, guess, L, free=free)
    if not guess or not free or model.nq == 0:
        return q0
    cost = _cost(model, u, p, guess)
    if cost is None:
        return q0  # no guessed point that an unknown moves: nothing to agree with
    best, best_c, chosen, tried = q0, np.inf, {}, set()
    for lk in free[:FREE_LINKS]:
        base = dict(chosen)
        for a in TURNS:
            turn = {**base, lk: a}
            key = tuple(sorted((k, v) for k, v in turn.items() if v != 0.0))
            if key in tried:
                continue  # the same start as one solved before
            tried.add(key)
            sol = model.newton(model.initial_q(u, p, guess, L, turn=turn), u, p, L)
            if sol.ok:
                c = cost(sol.q)
                if c < (1 - NEARER) * best_c or best_c == np.inf:
                    best, best_c, chosen = sol.q, c, turn
    return best

def _cost(model, u, p, guess):
    """q -> the guessed points' cost (module text) at q; None where no unknown moves them."""
    names = model.sym.mech.moving_points
    call, owner = _points(model)
    eq, _ = model.scales(u, p)
    held = [k for k, nm in enumerate(names) if nm in guess and owner[k] >= 0]
    if not held:
        return None
    dim = model.sym.dim
    rows = np.ravel([[dim * k + i for i in range(dim)] for k in held]).astype(int)
    G = np.ravel([np.asarray(guess[names[k]], float) for k in held])
    lp = np.repeat([eq[model.blocks[owner[k]].rows[0]] for k in held], dim)

    def cost(q):
        d = (np.asarray(call(q, u, p)[0]).ravel()[rows] - G) / lp
        return float(d @ d)
    return cost


def _points(model):
    """(q, u, p) -> the moving points (x1, y1, x2, y2, ...), and per moving point the index
    of the Assur group that places it (the last whose unknowns move it; -1: none does)."""
    def build():
        from .numeric import _Call  # numeric's Model is what calls this module
        sym = model.sym
        P = ca.vec(sym._point_matrix())
        group = np.full(sym.nq, -1)
        for i, b in enumerate(model.blocks):
            group[b.cols] = i
        owner = np.full(P.numel() // sym.dim, -1)
        for r, c in zip(*ca.jacobian(P, sym.q).sparsity().get_triplet()):
            owner[r // sym.dim] = max(owner[r // sym.dim], group[c])
        return _Call(ca.Function("guessed_points", [sym.q, sym.u, sym.p], [P])), owner
    return model.memo("guessed.points", build)
