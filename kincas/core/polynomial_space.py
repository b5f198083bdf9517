"""The closure equations of a spatial mechanism as polynomials with exact rational
coefficients (kincas/core/polynomial.py), for an exact solver.

Coordinates: each moving rigid body has its reference point r (3 variables, the numerical
model's own: the centroid of its drawn points, relative to the first ground point) and its
rotation matrix R (9 variables) with R'R = I (6 equations) and det R = 1. Why R and not the
model's unit quaternion e? R(e) = R(-e): with quaternions every assembly is two real
solutions (msolve would isolate both, and the count would have to be halved by a sign rule);
with R each assembly is one solution, and det R = 1 drops the reflections that R'R = I
alone admits (measured on Dietmaier's Stewart-Gough platform: 40 real solutions in about
1 s, against 54 with the reflections in 3.9 s). Every point is r + R (P0 - c): linear in the
variables, so a ball joint's closure equations are linear, and so are a revolute joint's
axis (R1 a = R2 a: the relative rotation R1'R2 keeps a, i.e. is a rotation about a, with no
flipped assembly) and a prismatic joint's R1 = R2 when one body is the ground or bilinear
otherwise; the linear ones are eliminated exactly before msolve. The box on (r, R) is a box
on every point by exact interval arithmetic (the points are linear in the variables).

A point carried by bars only is 3 variables; a bar |P - Q|^2 = L^2. A joint angle input u
fixes the relative rotation: R2 b = R1 (cos u b + sin u (a x b)) for b perpendicular to the
axis a, with (cos u, sin u) the rational rotation of `polynomial.unit` (rounded and said
when u is not a multiple of 90 degrees); a is needed as an exact rational unit vector: an
axis that is not one (|a|^2 not 1 in the rationals) is taken as the nearest rational point
of the unit sphere (stereographic, denominator at most 2^20), and said. A slide input along
a direction likewise. A parameter input (a Stewart leg's length) enters exactly.

The scene's numbers enter as the shortest decimals of their floats (`exact`: what the scene
wrote; small coefficients make msolve several times faster than the floats' dyadic rationals).

A solution maps back to kincas's unknowns: r as it is, e from R (Shepperd's method) with
qw >= 0 (the first non-zero component positive where qw = 0).

>>> import kincas
>>> m = kincas.SpatialMechanism(ground={"O": (0, 0, 0)},
...     bodies=[kincas.Body("arm", {"O": (0, 0, 0), "P": (2, 0, 0)})],
...     joints=[kincas.Joint("revolute", "O", axis=(0, 0, 1))], inputs=[kincas.Input.joint("O")])
>>> S = closure_space(m, [math.pi / 2])
>>> len(S.names), S.rounded
(12, [])
"""
from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from .polynomial_planar import NotPolynomial
from ..model.mobility import GROUND
from ..model.space_parts import ON_SECOND
from .polynomial import Poly, PolySystem, unit
from .tolerances import CERTIFY_DENOMINATOR


def exact(v: float) -> Fraction:
    """A scene's number as the shortest decimal that rounds to its float (what the scene
    wrote: 0.645275, not the 53-bit dyadic rational of the float, ~1e-17 away). msolve's
    work grows with the coefficients' size: Dietmaier's platform took 4 times longer with
    the dyadic rationals; and a direction written (0.6, 0, 0.8) stays exactly (3, 0, 4) / 5.

    >>> exact(0.1), exact(2.0)
    (Fraction(1, 10), Fraction(2, 1))
    """
    return Fraction(repr(float(v)))


def snapped(v: float, size: float) -> Fraction:
    """The simplest rational within about 1e-12 of the size of v (a grid of size / 2^40,
    then the simplest fraction near it): a float's noise such as -1.07e-14 becomes 0.

    >>> snapped(-1.0658141036401503e-14, 146.0), snapped(34.20201433256687, 146.0)
    (Fraction(0, 1), Fraction(176585, 5163))
    """
    grid = Fraction(size).limit_denominator(1 << 20) / (1 << 40) or Fraction(1, 1 << 40)
    k = Fraction(float(v)) / grid
    lo, hi = (math.floor(k) - Fraction(1, 2)) * grid, (math.floor(k) + Fraction(3, 2)) * grid
    return _simplest(lo, hi)


def _simplest(lo: Fraction, hi: Fraction) -> Fraction:
    """The rational of least denominator in [lo, hi] (continued fractions)."""
    if lo <= 0 <= hi:
        return Fraction(0)
    if hi < 0:
        return -_simplest(-hi, -lo)
    fl = math.floor(lo)
    if fl == lo or fl + 1 <= hi:
        return Fraction(math.ceil(lo))
    return fl + 1 / _simplest(1 / (hi - fl), 1 / (lo - fl))


def direction(v) -> tuple[list[Fraction], bool]:
    """A rational direction along v, and whether it is v's direction to floating rounding.

    A scene's axis is usually a float-normalized simple direction ((3, 0, 4) stored as
    (0.6, 0, 0.8)): its exact rational is another direction by ~1e-16, enough to break an
    overconstrained mechanism's special geometry (a spherical four-bar's axes meeting at one
    point). So v is divided by its largest component and each ratio replaced by the simplest
    rational within floating rounding (denominator at most 2^20); where none is that near,
    the nearest such rational is taken (about 1e-12 off), and said.

    >>> direction((0.6, 0.0, 0.8))
    ([Fraction(3, 4), Fraction(0, 1), Fraction(1, 1)], True)
    """
    f = [float(c) for c in v]
    k = max(range(3), key=lambda i: abs(f[i]))
    out, same = [], True
    for c in f:
        ratio = c / f[k]
        r = Fraction(ratio).limit_denominator(CERTIFY_DENOMINATOR)
        same = same and abs(float(r) - ratio) <= 4 * math.ulp(1.0)
        out.append(r)
    return out, same


def unit_vector(v) -> tuple[tuple[Fraction, Fraction, Fraction], bool]:
    """An exact rational unit vector along v, and whether it is v's own direction exactly.

    A vector whose |v|^2 is a rational square is scaled exactly; otherwise the inverse
    stereographic image of a rational point t: (2 t, 1 - |t|^2) / (1 + |t|^2) from the pole
    nearest -v (|t| <= 1), within about 1e-12 of v / |v|.

    >>> unit_vector((0, 0, 2))
    ((Fraction(0, 1), Fraction(0, 1), Fraction(1, 1)), True)
    >>> u, same = unit_vector((1, 1, 1)); sum(c * c for c in u) == 1, same
    (True, False)
    """
    x, _ = direction(v)
    n2 = sum(c * c for c in x)
    num, den = math.isqrt(n2.numerator), math.isqrt(n2.denominator)
    if num * num == n2.numerator and den * den == n2.denominator:
        n = Fraction(num, den)
        return tuple(c / n for c in x), True
    f = np.asarray(v, float) / np.linalg.norm(np.asarray(v, float))
    k = int(np.argmax(np.abs(f)))  # the pole along the largest component, on v's side
    sgn = 1 if f[k] > 0 else -1
    others = [i for i in range(3) if i != k]
    t = [Fraction(float(sgn * f[i] / (1 + sgn * f[k]))).limit_denominator(CERTIFY_DENOMINATOR) for i in others]
    tt = t[0] * t[0] + t[1] * t[1]
    out = [Fraction(0)] * 3
    out[k] = sgn * (1 - tt) / (1 + tt)
    for i, ti in zip(others, t):
        out[i] = sgn * 2 * ti / (1 + tt)
    return tuple(out), False


def _perpendicular(a):
    """A rational vector perpendicular to a (a x the axis where a is smallest)."""
    k = min(range(3), key=lambda i: abs(a[i]))
    e = [Fraction(0)] * 3
    e[k] = Fraction(1)
    return _cross(a, e)


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _dot(a, b):
    return sum((x * y for x, y in zip(a, b)), Poly())


def _apply(R, v):
    return [sum((R[i][j] * v[j] for j in range(3)), Poly()) for i in range(3)]


def _apply_t(R, v):
    return [sum((R[j][i] * v[j] for j in range(3)), Poly()) for i in range(3)]


def quaternion(R) -> np.ndarray:
    """A rotation matrix's unit quaternion (w, x, y, z), w >= 0 (Shepperd's method: the
    largest of the four squares first, for accuracy).

    >>> quaternion(np.diag([1.0, -1.0, -1.0])).tolist()
    [0.0, 1.0, 0.0, 0.0]
    """
    R = np.asarray(R, float)
    tr = np.trace(R)
    sq = [1 + tr, 1 + 2 * R[0, 0] - tr, 1 + 2 * R[1, 1] - tr, 1 + 2 * R[2, 2] - tr]
    k = int(np.argmax(sq))
    h = 0.5 * math.sqrt(max(sq[k], 0.0))
    d = lambda i, j: (R[i, j] - R[j, i]) / (4 * h)
    s = lambda i, j: (R[i, j] + R[j, i]) / (4 * h)
    q = [np.array([h, d(2, 1), d(0, 2), d(1, 0)]), np.array([d(2, 1), h, s(0, 1), s(0, 2)]),
         np.array([d(0, 2), s(0, 1), h, s(1, 2)]), np.array([d(1, 0), s(0, 2), s(1, 2), h])][k]
    q /= np.linalg.norm(q)
    nz = next((c for c in q if c != 0), 1.0)
    return -q if (q[0] < 0 or (q[0] == 0 and nz < 0)) else q


def matrix(e) -> np.ndarray:
    """A unit quaternion's rotation matrix."""
    w, x, y, z = e
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def overconstrained(m) -> bool:
    """More equations than unknowns less inputs: the mechanism moves only thanks to special
    geometry (a spherical four-bar's axes meeting at one point, Bennett's linkage)."""
    nq, ng = m.counts()
    return nq - ng < len(m.inputs)


def closure_space(m, u, driven_joints=True, snap=False) -> PolySystem:
    """The closure equations of the spatial mechanism `m` at inputs `u` as a `PolySystem`
    (module text), with `to_unknowns` / `from_unknowns` mapping a solution to kincas's
    unknowns and back. `driven_joints=False` leaves out the joint and slide inputs'
    equations (the mechanism free to move: an overconstrained one must keep a motion).
    `snap`: the geometry's numbers (points, lengths) as the simplest rationals within
    ~1e-12 of the size (`snapped`; smaller coefficients, a faster msolve), the distance
    added to `perturbation` (where the certificate is already for a nearby geometry)."""
    driven = {i.target: float(v) for i, v in zip(m.inputs, u) if i.kind == "parameter"}
    m = m.with_parameters(**driven) if driven else m
    S = PolySystem()
    number = exact
    if snap:
        size = m.size()

        def number(v):
            r = snapped(v, size)
            S.perturbation = max(S.perturbation, abs(float(r) - float(v)) / size)
            return r
    o = [number(m.value(c)) for c in m.ground[0][1]] if m.ground else [Fraction(0)] * 3
    rel = lambda xyz: [number(m.value(c)) - oc for c, oc in zip(xyz, o)]
    const = lambda v: [Poly.const(c) for c in v]
    one, zero = Poly.const(1), Poly.const(0)
    frames = {GROUND: (const([0, 0, 0]), [[one, zero, zero], [zero, one, zero], [zero, zero, one]], [0, 0, 0])}
    exempt = m.exempt()  # (a slide joint's point listed in [ground] too is its second body's)
    points = {g: const(rel(xyz)) for g, xyz in m.ground if (g, GROUND) not in exempt}
    layout = []  # per kincas unknown block: ("body", r indices, R indices) or ("point", indices)
    for b in m.bodies:
        if b.two_point:
            continue
        loc = {p: rel(xyz) for p, xyz in b.points}
        c = [sum(v[i] for v in loc.values()) / len(loc) for i in range(3)]
        r = [S.var(f"{b.name}.r{a}", length=True) for a in "xyz"]
        R = [[S.var(f"{b.name}.R{i + 1}{j + 1}") for j in range(3)] for i in range(3)]
        ir = len(S.names) - 12
        layout.append(("body", list(range(ir, ir + 3)), list(range(ir + 3, ir + 12))))
        for i in range(3):  # R'R = I: unit, orthogonal columns
            for j in range(i, 3):
                S.structural.append(len(S.equations))
                S.equations.append(sum((R[k][i] * R[k][j] for k in range(3)), Poly()) - (1 if i == j else 0))
        S.structural.append(len(S.equations))
        S.equations.append(_dot(R[0], _cross(R[1], R[2])) - 1)  # det R = 1: no reflections
        frames[b.name] = (r, R, c)
        for p, P0 in loc.items():
            if (p, b.name) in exempt:
                continue
            w = _world(frames, b.name, P0)
            if p in points:
                S.equations += [w[i] - points[p][i] for i in range(3)]
            else:
                points[p] = w
    for p in m.moving_points:
        if p not in points:
            points[p] = [S.var(f"{p}.{a}", length=True) for a in "xyz"]
            layout.append(("point", list(range(len(S.names) - 3, len(S.names)))))
    for b in m.bodies:
        if b.two_point:
            P, Q = (points[n] for n in b.point_names)
            d = [P[i] - Q[i] for i in range(3)]
            S.equations.append(_dot(d, d) - number(m.value(b.length)) ** 2)
    inputs = {i.target: float(v) for i, v in zip(m.inputs, u)
              if i.kind in ("joint", "slide") and driven_joints}
    for j in m.joints:
        S.equations += _joint(S, m, j, frames, points, rel, inputs)
    for sl in m.slides:
        _, R1, _ = frames[sl.along]
        X1 = _world(frames, sl.along, rel(sl.through))
        d = [points[sl.point][i] - X1[i] for i in range(3)]
        if sl.on_line:
            a, same = _axis(S, sl.direction, f"slide {sl.name}: direction", sl.name in inputs or
                            f"{sl.name}.s" in inputs)
            b1 = _perpendicular(a)
            S.equations += [_dot(d, _apply(R1, b1)), _dot(d, _apply(R1, _cross(a, b1)))]
            key = next((k for k in (f"{sl.name}.s", sl.name) if k in inputs), None)
            if key is not None:
                S.equations.append(_dot(d, _apply(R1, a)) - exact(inputs[key]))
        else:
            S.equations.append(_dot(d, _apply(R1, _axis(S, sl.normal, f"slide {sl.name}: normal", False)[0])))
    S.points = {p: points[p] for p in m.moving_points}
    S.to_unknowns = lambda x: _to_unknowns(layout, x)
    S.from_unknowns = lambda q: _from_unknowns(layout, len(S.names), q)
    return S


def _world(frames, body, P0):
    r, R, c = frames[body]
    if body == GROUND:
        return [Poly.const(v) for v in P0]
    v = _apply(R, [Poly.const(P0[i] - c[i]) for i in range(3)])
    return [r[i] + v[i] for i in range(3)]


def _axis(S, v, what, exact_unit):
    """The axis as the equations take it: a rational direction (`direction`) where only its
    direction matters; an exact rational unit vector where an input's value is measured about
    or along it; rounded beyond floating rounding only where need be, and then said."""
    a, same = direction(v) if not exact_unit else unit_vector(v)
    f = np.asarray(v, float) / np.linalg.norm(np.asarray(v, float))
    r = np.array([float(c) for c in a])
    S.perturbation = max(S.perturbation, float(np.abs(r / np.linalg.norm(r) - f).max()))
    if not same:
        S.rounded.append(f"{what} {tuple(v)!r} taken as the rational direction "
                         f"{tuple(float(c) for c in a)!r}")
    return list(a), same


def _joint(S, m, j, frames, points, rel, inputs) -> list:
    """A joint's equations (its point's coincidence is written with the bodies)."""
    b1, b2 = m.joint_bodies(j)
    R1, R2 = frames[b1][1], frames[b2][1]
    name, eqs = j.name, []
    if j.type == "spherical":
        return eqs
    if j.type == "universal":
        if any(k.startswith(name + ".angle") for k in inputs):
            raise NotPolynomial(f"[[inputs]] {name}: the certified search does not take a universal "
                             f"joint's angle as an input in this version")
        a0, a1 = (_axis(S, ax, f"[[joints]] {name}: axes", False)[0] for ax in j.axes)
        return [_dot(_apply(R1, a0), _apply(R2, a1))]
    angle_in, s_in = f"{name}.angle" in inputs, f"{name}.s" in inputs
    if any(k.startswith(name + ".s") and k != f"{name}.s" for k in inputs):
        raise NotPolynomial(f"[[inputs]] {name}: the certified search does not take a planar "
                         f"joint's s1, s2 as inputs in this version")
    a, _ = _axis(S, j.axis, f"[[joints]] {name}: axis", angle_in or s_in)
    if j.type in ("revolute", "cylindrical", "planar"):
        eqs += [x - y for x, y in zip(_apply(R1, a), _apply(R2, a))]  # R1'R2 turns about a
        if angle_in:  # R2 b = R1 (cos u b + sin u a x b): the relative angle is u exactly
            uval = inputs[f"{name}.angle"]
            c, s, same = unit(uval)
            S.at[f"{name}.angle"] = uval
            if not same:
                S.at[f"{name}.angle"] = math.atan2(float(s), float(c))
                S.rounded.append(f"{name}.angle = {uval!r} rad taken as {S.at[f'{name}.angle']!r} rad "
                                 f"(cos, sin) = ({c}, {s}) (a rational rotation)")
            b = _perpendicular(a)
            ab = _cross(a, b)
            target = [c * b[i] + s * ab[i] for i in range(3)]
            eqs += [x - y for x, y in zip(_apply(R2, b), _apply(R1, target))]
    if j.type in ON_SECOND:
        P0 = rel(next(xyz for bd in m.bodies if bd.name == b2 for p, xyz in bd.points if p == j.point))
        X1 = _world(frames, b1, P0)
        d = [points[j.point][i] - X1[i] for i in range(3)]
        if j.type == "planar":
            eqs.append(_dot(d, _apply(R1, a)))
        else:
            p1 = _perpendicular(a)
            eqs += [_dot(d, _apply(R1, p1)), _dot(d, _apply(R1, _cross(a, p1)))]
            if s_in:
                eqs.append(_dot(d, _apply(R1, a)) - exact(inputs[f"{name}.s"]))
        if j.type == "prismatic":  # no relative rotation at all
            eqs += [R1[i][k] - R2[i][k] for i in range(3) for k in range(3)]
    return eqs


def _to_unknowns(layout, x) -> np.ndarray:
    out = []
    for blk in layout:
        if blk[0] == "body":
            out += [x[i] for i in blk[1]]
            R = np.array([x[i] for i in blk[2]], float).reshape(3, 3)
            U, _, Vt = np.linalg.svd(R)  # the nearest rotation (the box's centre is one to 2^-64)
            out += list(quaternion(U @ Vt))
        else:
            out += [x[i] for i in blk[1]]
    return np.array(out, float)


def _from_unknowns(layout, n, q) -> np.ndarray:
    x, k = np.zeros(n), 0
    for blk in layout:
        if blk[0] == "body":
            for i, v in zip(blk[1], q[k:k + 3]):
                x[i] = v
            e = np.asarray(q[k + 3:k + 7], float)
            for i, v in zip(blk[2], matrix(e / np.linalg.norm(e)).ravel()):
                x[i] = v
            k += 7
        else:
            for i, v in zip(blk[1], q[k:k + 3]):
                x[i] = v
            k += 3
    return x
