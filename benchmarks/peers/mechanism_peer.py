"""The `mechanism` package (vector loops solved by scipy's fsolve), used as its README teaches.

Every link side is a `Vector` of known length and unknown angle (a ternary link is three
vectors closing a loop, as in the package's `engine.py` example), every slide a vector of
known angle and unknown length from a ground point, the crank a vector driven by the input,
and each ground point a fixed vector from the origin (the crank's pivot, which the package
puts at (0, 0)). The loop equations are a cycle basis of that graph: a spanning tree from
the origin, and for each other vector u -> v the loop path(u) + vector - path(v) = 0.
`Mechanism.iterate()` then solves every pose with fsolve, warm-started from the one before,
positions first and then velocities from the same loops. The package reports no failures:
every pose counts as claimed solved, and the tables show whether it was right.

>>> import cases
>>> r = prepare(cases.fourbar(12))()
>>> r.P["B"].shape, bool(np.isfinite(r.V["B"]).all())
((12, 2), True)
"""
from __future__ import annotations

import math
import warnings
from collections import deque

import numpy as np

from . import Run

NAME = "mechanism (pkg)"


def available():
    from . import module_available
    return module_available("mechanism")


def supports(case):
    o = case.crank[0]
    if case.guessless:
        return "needs a starting angle for every vector (the case gives none)"
    return None if tuple(case.ground[o]) == (0.0, 0.0) else "the origin must be the crank's pivot"


def edges(case):
    """(tail, head, kind, data): kind "fixed" (r, theta), "input" (r), "angle" (r), "length" (theta)."""
    o, tip, r = case.crank
    out = [(o, g, "fixed", (math.hypot(*xy), math.atan2(xy[1], xy[0])))
           for g, xy in case.ground.items() if g != o]
    out.append((o, tip, "input", (r,)))
    for _, pts, ls in case.links:
        if len(pts) == 2:
            out.append((pts[0], pts[1], "angle", (ls[0],)))
        else:
            (p, q, s), (pq, qs, ps) = pts, ls
            out += [(p, q, "angle", (pq,)), (q, s, "angle", (qs,)), (p, s, "angle", (ps,))]
    out += [(t, p, "length", (ang,)) for p, t, ang in case.slides]
    return out


def cycle_basis(case, es):
    """Loops as lists of (edge index, sign): a BFS spanning tree from the origin plus one edge."""
    o = case.crank[0]
    adj = {}
    for i, (u, v, _, _) in enumerate(es):
        adj.setdefault(u, []).append((i, v, 1))
        adj.setdefault(v, []).append((i, u, -1))
    path, tree, todo = {o: []}, set(), deque([o])
    while todo:
        u = todo.popleft()
        for i, v, sgn in adj.get(u, []):
            if v not in path:
                path[v] = path[u] + [(i, sgn)]
                tree.add(i)
                todo.append(v)
    return [path[u] + [(i, 1)] + [(j, -s) for j, s in path[v]]
            for i, (u, v, _, _) in enumerate(es) if i not in tree]


def prepare(case):
    import mechanism as mp

    es = edges(case)
    names = list(case.ground) + list(case.moving)
    joints = dict(zip(names, mp.get_joints(" ".join(names))))
    vecs, unknown, guess = [], [], []
    where = {**case.ground, **case.guess}
    for u, v, kind, data in es:
        ends = (joints[u], joints[v])
        dx, dy = where[v][0] - where[u][0], where[v][1] - where[u][1]
        if kind == "fixed":
            vecs.append(mp.Vector(ends, r=data[0], theta=data[1]))
            unknown.append(None)
        elif kind == "input":
            vecs.append(mp.Vector(ends, r=data[0]))
            unknown.append("input")
        elif kind == "angle":
            vecs.append(mp.Vector(ends, r=data[0]))
            unknown.append(len(guess))
            guess.append(math.atan2(dy, dx))
        else:
            vecs.append(mp.Vector(ends, theta=data[0]))
            unknown.append(len(guess))
            guess.append(dx * math.cos(data[0]) + dy * math.sin(data[0]))
    loops_ = cycle_basis(case, es)
    assert 2 * len(loops_) == len(guess), "the loops do not match the unknowns"

    def loops(x, inp):
        val = [v() if k is None else v(inp) if k == "input" else v(x[k]) for v, k in zip(vecs, unknown)]
        out = np.zeros((len(loops_), 2))
        for j, lp in enumerate(loops_):
            for i, s in lp:
                out[j] += s * val[i]
        return out.flatten()

    theta = np.asarray(case.theta, dtype=float)
    omega = np.full(theta.size, case.omega)
    g0, g1 = np.array(guess), np.zeros(len(guess))

    def run():
        m = mp.Mechanism(vectors=vecs, origin=joints[case.crank[0]], loops=loops, pos=theta,
                         vel=omega, guess=(g0, g1))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            m.iterate()
        P = {p: np.stack([joints[p].x_positions, joints[p].y_positions], axis=1) for p in case.outputs}
        V = {p: np.stack([joints[p].x_velocities, joints[p].y_velocities], axis=1) for p in case.outputs}
        return Run(P, V, np.ones(theta.size, dtype=bool))
    return run
