"""pylinkage, through the API its README recommends: `Ground`, `Crank`, dyads, `simulation.Linkage`,
stepped by `step_fast_with_kinematics` (its numba-compiled loop, positions and velocities).

pylinkage solves dyad chains only: each point by one circle-circle (`RRRDyad`), circle-line
(`RRPDyad`) or rigid-triangle (`FixedDyad`) construction; where two intersections exist it keeps
the one nearest the point's previous position. A class-III chain cannot be written with dyads.
The crank turns by `angular_velocity` radians per step, so the sweep must be in equal steps:
the crank starts one step before the first input angle and every step is one pose. Starting
positions (which pick the branch) are the case's guess; `set_input_velocity` gives omega.

>>> import cases
>>> r = prepare(cases.fourbar(12))()
>>> bool(r.ok.all()), r.P["B"].shape
(True, (12, 2))
"""
from __future__ import annotations

import math

import numpy as np

from . import Run

NAME = "pylinkage"


def available():
    from . import module_available
    err = module_available("pylinkage")
    if err:
        return err
    if module_available("numba"):
        return "pylinkage imports, but numba (its fast path, the `numba` extra) does not"
    return None


def supports(case):
    if case.steps is None:
        return "dyads only: a class-III chain cannot be written with pylinkage's dyads"
    d = np.diff(case.theta)
    if len(d) and np.ptp(d) > 1e-12:
        return "the crank turns in equal steps only"
    return None


def _distance(case, a, b):
    for _, pts, ls in case.links:
        if a in pts and b in pts:
            if len(pts) == 2:
                return ls[0]
            i, j = sorted((pts.index(a), pts.index(b)))
            return {(0, 1): ls[0], (1, 2): ls[1], (0, 2): ls[2]}[(i, j)]
    raise KeyError((a, b))


def build(case):
    """(linkage, crank, [component per output point], starting coordinates)."""
    from pylinkage import Crank, FixedDyad, Ground, RRPDyad, RRRDyad
    from pylinkage.simulation import Linkage

    o, tip, r = case.crank
    step = float(case.theta[1] - case.theta[0]) if len(case.theta) > 1 else 0.01
    comp = {g: Ground(*xy, name=g) for g, xy in case.ground.items()}
    parts = list(comp.values())
    crank = Crank(comp[o], r, angular_velocity=step, initial_angle=float(case.theta[0]) - step, name=tip)
    parts.append(crank)
    comp[tip] = crank.output
    anchor = lambda p: comp[p]
    for st in case.steps:
        kind, p = st[0], st[1]
        hint = (None, None) if case.guessless else case.guess[p]
        if kind in ("translate", "cross"):  # a four-bar's point: a circle-circle dyad like any other
            a = st[2]
            g = next(q for _, pts, _ in case.links if p in pts for q in pts if q != p and q != a)
            st = ("rrr", p, a, g, _distance(case, a, p), _distance(case, g, p), 0)
            kind = "rrr"
        if kind == "rrr":
            _, _, a1, a2, r1, r2, _ = st
            c = RRRDyad(anchor(a1), anchor(a2), r1, r2, x=hint[0], y=hint[1], name=p)
        elif kind == "rrp":
            _, _, a1, rr, t, ang, _ = st
            tx, ty = case.ground[t]
            far = Ground(tx + 10 * math.cos(ang), ty + 10 * math.sin(ang), name=f"{t}_dir")
            parts.append(far)
            c = RRPDyad(anchor(a1), comp[t], far, rr, x=hint[0], y=hint[1], name=p)
        elif kind == "tri":  # a rigid triangle's vertex: fixed distance and angle from A1 -> A2
            _, _, a1, a2, r1, r2, side = st
            base = _distance(case, a1, a2)
            alpha = math.acos((r1 * r1 + base * base - r2 * r2) / (2 * r1 * base))
            c = FixedDyad(anchor(a1), anchor(a2), r1, side * alpha, name=p)
        else:
            raise ValueError(kind)
        parts.append(c)
        comp[p] = c
    linkage = Linkage(parts, name=case.name)
    linkage.set_input_velocity(crank, omega=case.omega)
    start = [c.position for c in linkage.components]
    index = {c.name: i for i, c in enumerate(linkage.components)}
    return linkage, [index[p] for p in case.outputs], start


def prepare(case):
    linkage, cols, start = build(case)
    linkage.compile()  # the numba solver state, as the documentation suggests
    n = len(case.theta)

    def run():
        linkage.set_coords(start)  # back to the starting pose (the branch)
        pos, vel, _ = linkage.step_fast_with_kinematics(iterations=n)
        ok = np.isfinite(pos[:, cols]).all(axis=(1, 2))
        return Run({p: pos[:, c] for p, c in zip(case.outputs, cols)},
                   {p: vel[:, c] for p, c in zip(case.outputs, cols)}, ok)
    return run
