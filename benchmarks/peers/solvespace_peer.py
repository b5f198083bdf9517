"""python-solvespace (SolveSpace's geometric constraint solver), in its documented solve loop.

The sketch is built once: ground points and the crank's tip (dragged: the input places it,
as a user drags a driving point) in group 1, which the solver holds fixed; the other moving
points in group 2, started at the case's guess. Constraints: `distance` for every pair of
points on a link (a triangle's three sides) and `coincident(point, line)` for every slide.
Each pose moves the tip with `set_params` and calls `solve()`: the solver starts from the
previous pose's parameters, a warm start. A pose counts as solved
when `solve()` returns `ResultFlag.OKAY`; after a failure the last solved parameters are put
back. SolveSpace computes positions only: there are no velocities.

>>> import cases
>>> r = prepare(cases.fourbar(12))()
>>> bool(r.ok.all()), r.V is None
(True, True)
"""
from __future__ import annotations

import math

import numpy as np

from . import Run
from .mp_newton import pairs

NAME = "python-solvespace"


def available():
    from . import module_available
    return module_available("python_solvespace")


def supports(case):
    return "needs a starting position for every point (the case gives none)" if case.guessless else None


def prepare(case):
    from python_solvespace import ResultFlag, SolverSystem

    s = SolverSystem()
    s.set_group(1)
    wp = s.create_2d_base()
    o, tip, r = case.crank
    ent = {}
    for g, (x, y) in case.ground.items():
        ent[g] = s.add_point_2d(x, y, wp)
        s.dragged(ent[g], wp)
    ox, oy = case.ground[o]
    t0 = float(case.theta[0])
    hand = ent[tip] = s.add_point_2d(ox + r * math.cos(t0), oy + r * math.sin(t0), wp)
    s.dragged(hand, wp)
    lines = {}
    for p, t, ang in case.slides:
        far = s.add_point_2d(case.ground[t][0] + math.cos(ang), case.ground[t][1] + math.sin(ang), wp)
        s.dragged(far, wp)
        lines[p] = (t, far)
    s.set_group(2)
    free = [p for p in case.moving if p != tip]
    for p in free:
        ent[p] = s.add_point_2d(*case.guess[p], wp)
    for p, q, l in pairs(case):
        s.distance(ent[p], ent[q], l, wp)
    for p, (t, far) in lines.items():
        s.coincident(ent[p], s.add_line_2d(ent[t], far, wp), wp)
    start = {p: s.params(ent[p].params) for p in free}
    theta, outs, okay = case.theta, case.outputs, ResultFlag.OKAY
    hands = np.stack([ox + r * np.cos(theta), oy + r * np.sin(theta)], axis=1).tolist()

    def run():
        for p, v in start.items():
            s.set_params(ent[p].params, v)
        n = len(theta)
        P = {p: np.full((n, 2), np.nan) for p in outs}
        ok = np.zeros(n, dtype=bool)
        last = dict(start)
        for k in range(n):
            s.set_params(hand.params, hands[k])
            if s.solve() == okay:
                ok[k] = True
                for p in outs:
                    P[p][k] = s.params(ent[p].params)
                last = {p: s.params(ent[p].params) for p in free}
            else:  # start the next pose from the last solved one
                for p, v in last.items():
                    s.set_params(ent[p].params, v)
        return Run(P, None, ok)
    return run
