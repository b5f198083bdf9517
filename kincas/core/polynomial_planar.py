"""The closure equations of a planar mechanism as polynomials with exact rational
coefficients (kincas/core/polynomial.py), for an exact solver.

Coordinates: natural ones that mirror the numerical model's unknowns one to one
(kincas/core/symbolic.py). Each link whose angle is unknown gets its cosine and sine (c, s)
as two variables tied by c^2 + s^2 = 1; a floating link also its origin (x, y). A link's
point is then origin + R(c, s) p_local: linear in each link's (c, s), so the loop-closure
equations (two bodies put a shared point at the same place) are linear, the unit circles
quadratic, a slide's "point on the line" bilinear. Why not the points' coordinates with
distance constraints? A ternary link given by its three distances also admits its mirror
image (not an assembly: solutions to discard), and a real solution would have to be mapped
back to angles; with (c, s) every real solution is an assembly, the map to the model's
unknowns is atan2, and the box on (c, s) is a box on every point (each point is linear in
them).

The scene's numbers enter as the exact rationals their floats are. A driven angle, and a
slide's line angle, enter as a rational point of the unit circle (`polynomial.unit`), exact
when the angle is a multiple of 90 degrees (to floating rounding), else rounded by about
1e-12 rad: the system then says so (`rounded`), and the certificate is for the rounded pose.
Gears, racks and cams (transcendental in the angles, or splines) are refused.

>>> import kincas
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)], inputs=[kincas.Input.angle("crank")])
>>> S = closure(m, [math.pi / 2])
>>> S.names, len(S.equations), S.rounded
(['rocker.c', 'rocker.s', 'coupler.c', 'coupler.s'], 4, [])
"""
from __future__ import annotations

import math

from ..errors import ModelError
from ..model.joints import split_relative
from ..model.mechanism import GROUND, Mechanism
from .polynomial import Poly, PolySystem, exact, unit


class NotPolynomial(ModelError):
    """The mechanism has a constraint that is not polynomial (gears, racks, cams)."""


def refusal(m: Mechanism) -> str | None:
    """Why `m` has no polynomial closure equations here, or None."""
    kinds = [(n, getattr(m, f)) for n, f in (("gears", "gears"), ("racks", "racks"), ("cams", "cams"))]
    found = [f"[[{n}]] {parts[0].name or n}" for n, parts in kinds if parts]
    if found:
        return (f"{found[0]}: the certified search takes pins and slides only (a gear, rack or "
                f"cam constraint is not polynomial in the link angles)")
    return None


def closure(m: Mechanism, u) -> PolySystem:
    """The closure equations of `m` at inputs `u` (one value per input, radians or lengths)
    as a `PolySystem`: variables, equations, each moving point's coordinates, and how each
    unknown of the numerical model is read from a solution."""
    why = refusal(m)
    if why:
        raise NotPolynomial(why)
    driven = {i.target: float(v) for i, v in zip(m.inputs, u) if i.kind == "parameter"}
    m = m.with_parameters(**driven) if driven else m
    S = PolySystem()
    val = lambda v: exact(m.value(v))

    def rotation(theta, what):
        c, s, same = unit(theta)
        S.at[what] = theta
        if not same:
            got = S.at[what] = math.atan2(float(s), float(c))
            S.rounded.append(f"{what} = {theta!r} rad taken as {got!r} rad "
                             f"(cos, sin) = ({c}, {s}) (a rational rotation)")
        return Poly.const(c), Poly.const(s)

    angle_in = {i.target: v for i, v in zip(m.inputs, u) if i.kind == "angle"}
    frames = {GROUND: (Poly.const(0), Poly.const(0), Poly.const(1), Poly.const(0))}
    points = {g: (Poly.const(val(x)), Poly.const(val(y))) for g, (x, y) in m.ground}
    for lname, at in m.structure.order:
        lk = m.link(lname)
        loc = {p: (val(x), val(y)) for p, (x, y) in lk.points}
        if lname in angle_in:
            c, s = rotation(float(angle_in[lname]), f"{lname}.angle")  # the input's key
        else:
            c, s = S.var(f"{lname}.c"), S.var(f"{lname}.s")
            S.equations.append(c * c + s * s - 1)
            S.unknowns.append((f"{lname}.angle", "angle", len(S.names) - 2, len(S.names) - 1))
        if at is None:  # floating: its origin is unknown too
            ox, oy = S.var(f"{lname}.x", length=True), S.var(f"{lname}.y", length=True)
            S.unknowns += [(f"{lname}.x", "value", len(S.names) - 2),
                           (f"{lname}.y", "value", len(S.names) - 1)]
        else:  # hangs on point `at`: origin = P - R p_local
            (px, py), (lx, ly) = points[at], loc[at]
            ox, oy = px - (c * lx - s * ly), py - (s * lx + c * ly)
        frames[lname] = (ox, oy, c, s)
        for p, (lx, ly) in loc.items():
            w = (ox + c * lx - s * ly, oy + s * lx + c * ly)
            if p == at:
                continue
            if p in points:  # loop closure: both bodies put p at the same place
                S.equations += [w[0] - points[p][0], w[1] - points[p][1]]
            else:
                points[p] = w
    slide_s = {}
    for sl in m.slides:
        ox, oy, c, s = frames[sl.along]
        tx, ty = (val(v) for v in sl.through)
        ca_, sa = rotation(m.value(sl.angle), f"slide {sl.name}") if \
            m.value(sl.angle) != 0 else (Poly.const(1), Poly.const(0))
        dx, dy = c * ca_ - s * sa, s * ca_ + c * sa  # the line's direction in the world
        ex = points[sl.point][0] - (ox + c * tx - s * ty)
        ey = points[sl.point][1] - (oy + s * tx + c * ty)
        S.equations.append(dx * ey - dy * ex)  # the point is on the line
        slide_s[sl.name] = dx * ex + dy * ey
    for i, v in zip(m.inputs, u):
        rel = split_relative(i.target) if i.kind == "angle" else None
        if rel is not None:  # (c, s) of a = R(u) (c, s) of b: the angle of a relative to b
            (_, _, ca_, sa), (_, _, cb, sb) = frames[rel[0]], frames[rel[1]]
            cu, su = rotation(float(v), f"{i.key}")
            S.equations += [ca_ - (cu * cb - su * sb), sa - (su * cb + cu * sb)]
        elif i.kind == "slide":
            S.equations.append(slide_s[i.target] - exact(float(v)))
    S.points = {p: points[p] for p in m.moving_points}
    return S
