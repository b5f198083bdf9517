"""Certified assemblies of an overconstrained spatial mechanism whose floats lost its special
geometry (kincas/analysis/certify.py calls `system_to_solve`).

A spherical four-bar or Bennett's linkage moves although its equations outnumber its
unknowns less its inputs: some equations are implied by the others, thanks to a special
geometry (the four axes meeting at one point; Bennett's twists and lengths). A scene gives
that geometry in floats (an axis (cos 40 deg, 0, sin 40 deg)), exact only to 1e-16, and the
polynomial writer takes each axis as a rational direction within ~1e-12
(kincas/core/polynomial_space.py): the exact system is then rigid (without its inputs it
has finitely many solutions, not a motion), and with the input's equation it has none.

The fix: keep only equations that are independent. At the drawing pose (an exact solution
of the system without its inputs, whatever the axes: every rotation the identity) the
Jacobian of the equations is computed in floats, and a largest independent set of rows kept
(QR with column pivoting; a pivot below RANK times the largest counts as dependent: the
rounded geometry leaves the implied rows dependent to ~1e-12). With the input's equations
the kept system is square: finitely many solutions, isolated by msolve. Every assembly of
the mechanism satisfies all of its equations, so also the kept ones: the list is complete
for the kept system of the rationalised geometry, which differs from the scene's floats by
`perturbation` (relative, reported). Each root is then refined by kincas's Newton on the
scene's own floats (every equation, the implied ones too) and must land in its box to its
error bound widened by that perturbation (kincas/analysis/certify.py, `_refined`); a root
of the kept system that violates an implied equation is not an assembly: `discarded`, with
its residual, as the stated rule.

>>> import math, kincas
>>> from kincas.analysis import certify_msolve
>>> sc = kincas.cli.scene.load("examples/space_spherical_fourbar.toml")   # doctest: +SKIP
>>> found = kincas.modes(sc.mechanism, {"input.angle": 0.5}, certify=True)  # doctest: +SKIP
>>> found.count, found.discarded                                          # doctest: +SKIP
(2, [])
"""
from __future__ import annotations

from collections import Counter
from dataclasses import replace

import numpy as np

from ..core.assembly import first_pose
from ..core.numeric import model_of
from ..core.polynomial import independent
from ..core.polynomial_planar import NotPolynomial
from ..core.polynomial_space import closure_space, overconstrained
from ..core.tolerances import RANK

REFUSED = ("the mechanism is overconstrained (it moves thanks to special geometry) and with the "
           "scene's numbers taken as exact rationals it does not move{why}: give its axes and points "
           "exactly (e.g. axes as small integers, points on them), or use the multistart search")


def system_to_solve(m, u, S, solve):
    """S itself, or where S's exact rationals lost the motion of an overconstrained
    mechanism, its square subsystem (`square`), with a note in `rounded`. `solve(S)` returns
    (kind, boxes, value) as kincas/analysis/certify.py's `_solve`."""
    if not overconstrained(m) or not any(i.kind in ("joint", "slide") for i in m.inputs):
        return S
    free = closure_space(m, u, driven_joints=False)
    if solve(free)[0] == "positive":
        return S  # the exact geometry keeps its motion: every equation, as written
    return square(m, u)


def square(m, u):
    """The closure equations at u with only those independent at the drawing pose (plus
    every input's), the geometry's numbers snapped to simple rationals (a faster msolve:
    the certificate is for a nearby geometry already)."""
    S, free = closure_space(m, u, snap=True), closure_space(m, u, driven_joints=False, snap=True)
    model, p = model_of(m), np.array([v for _, v in m.parameters], dtype=float)
    L = m.size()
    guess = {k: tuple(m.value(c) for c in xyz) for k, xyz in m.guess}
    drawn = first_pose(model, model.drawing_inputs(p), p, L, guess)
    if not drawn.ok:
        raise NotPolynomial(REFUSED.format(why=" (and its drawing pose does not assemble)"))
    x0 = free.from_unknowns(drawn.q, model.drawing_inputs(p))  # q at the drawing pose's inputs
    scale = np.where(free.length, L, 1.0)
    keep = [free.equations[k] for k in independent(free.equations, x0, len(free.names), scale, RANK,
                                                   always=free.structural)]
    key = lambda P: tuple(sorted(P.terms.items()))
    driven = Counter(key(P) for P in S.equations) - Counter(key(P) for P in free.equations)
    inputs = [P for P in S.equations if driven[key(P)] > 0]
    implied = len(free.equations) - len(keep)
    note = (f"overconstrained: with the axes as rational directions and the points as simple rationals "
            f"(within {S.perturbation:.0e} of the scene's, relative) the exact system does not move, so the {implied} equations implied at the drawing "
            f"pose were left out; the certificate is for the kept (square) system, each root refined on "
            f"the scene's own floats")
    return replace(S, equations=keep + inputs, rounded=S.rounded + [note], implied=implied)
