"""Kinematic geometry from the exact time derivatives: path curvature, centre of curvature,
instant centres (absolute and relative), and the time-derivative operator itself.

Along the motion every quantity E(z, z', z'') has the total time derivative
    D E = E_z z' + E_z' z'' + E_z'' z'''
with z = (q, u). The inputs' u', u'', u''' are given; q', q'', q''' are solved from the
derivatives of g(q, u, p) = 0 (kincas/core/symbolic.py). So jerk is D applied three times to a
position: exact, by CasADi, never by differences.

Path of a point P with velocity v and acceleration a:
    curvature  kappa = (vx ay - vy ax) / |v|^3         (positive turning counter-clockwise)
    centre     C = P + |v|^2 / (vx ay - vy ax) * (-vy, vx)
Instant centre of link L (origin O, angular velocity w): the point where the velocity field
v(r) = v_O + w k x (r - O) vanishes, r = O + (-v_Oy, v_Ox) / w. Relative to body B, the same
with the relative field v_A(r) - v_B(r) = c + (w_A - w_B) k x r, whose zero is
r = (-c_y, c_x) / (w_A - w_B), c = (v_OA - w_A k x O_A) - (v_OB - w_B k x O_B).

Each is null (NaN) where it is undefined: a point at rest has no path direction; a straight
stretch (no normal acceleration) has no finite centre of curvature; a translating link, or two
links turning at the same rate, have no finite instant centre. "At rest" and "the same rate"
are judged against the input rates: |v| <= 1e-9 times the speed scale
V = sum_i |u'_i| (times a size, the largest coordinate of a declared point, for an angle
input), |w| <= 1e-9 V / size.
"""
from __future__ import annotations

import re

import casadi as ca

from ..model.mechanism import GROUND
from .tolerances import NULL_REL, ROUNDING_REL, TINY

_PATH = {"curvature", "cx", "cy"}
_IC = {"icx", "icy"}


# --- the time derivative along the motion ---


class Time:
    """The symbols of one quantity function's motion and the operator D along it."""

    def __init__(self, sym, z, zd, zdd, zddd):
        self.sym, self.z, self.zd, self.zdd, self.zddd = sym, z, zd, zdd, zddd
        self.cache = {}  # expressions shared by several quantities of one function

    def d(self, e, order: int = 1, third=None):
        """D^order e: the order-th time derivative of e (third: override of z''')."""
        zddd = self.zddd if third is None else third
        for _ in range(order):
            de = ca.jtimes(e, self.z, self.zd)
            if ca.depends_on(e, self.zd):
                de += ca.jtimes(e, self.zd, self.zdd)
            if ca.depends_on(e, self.zdd):
                de += ca.jtimes(e, self.zdd, zddd)
            e = de
        return e

    @property
    def speed_scale(self):
        """sum |u'| (times the size for angle inputs): what "at rest" is measured against."""
        sym = self.sym
        size = self.size
        ud = self.zd[sym.nq:]
        terms = [ca.fabs(ud[k]) * (size if i.is_angle else 1.0) for k, i in enumerate(sym.mech.inputs)]
        return sum(terms, ca.SX(0))

    @property
    def size(self):
        """A length scale of the mechanism, symbolic in its parameters (the structure's model
        is shared by every parameter value): the largest coordinate of a declared point."""
        sym = self.sym
        xy = [sym.val(v) for _, pt in sym.mech.ground for v in pt]
        xy += [sym.val(v) for lk in sym.mech.links for _, pt in lk.points for v in pt]
        return ca.fmax(ca.mmax(ca.fabs(ca.vertcat(*xy))), TINY)


# --- names ---

_REL = re.compile(r"^(?P<a>[^/.()]+)/(?P<b>[^/.()]+)\.(?P<attr>icx|icy)$")


def _bodies(sym):
    return set(sym.angles) | {GROUND}


def check(sym, name: str):
    """None when `name` is not a geometry quantity; else the problems with it ([] if fine)."""
    m = _REL.match(name)
    if m:
        bad = [b for b in (m["a"], m["b"]) if b not in _bodies(sym)]
        return [f"unknown body {b!r} (a link's name or \"ground\")" for b in bad]
    obj, _, attr = name.rpartition(".")
    if attr in _PATH and obj in sym.points:
        return []
    if attr in _IC and obj in sym.angles:
        return []
    return None


# --- expressions ---


def _frame_velocity(sym, body, t):
    """(origin, its velocity, angle rate) of a body's frame; the ground's are zero."""
    if body == GROUND:
        zero = ca.SX(0)
        return (zero, zero), (zero, zero), zero
    ox, oy, th = sym.frames[body]
    return (ox, oy), (t.d(ox), t.d(oy)), t.d(th)


def _null_unless(ok, value):
    return ca.if_else(ok, value, ca.SX(float("nan")))


def expression(sym, name: str, t):
    m = _REL.match(name)
    if m:
        return _instant_centre(sym, m["a"], m["b"], m["attr"], t)
    obj, _, attr = name.rpartition(".")
    if attr in _IC:
        return _instant_centre(sym, obj, GROUND, attr, t)
    return _path(sym, obj, attr, t)


def _path(sym, point, attr, t):
    x, y = sym.points[point]
    vx, vy, ax, ay = t.d(x), t.d(y), t.d(x, 2), t.d(y, 2)
    v2 = vx * vx + vy * vy
    cross = vx * ay - vy * ax
    moving = ca.sqrt(v2) > NULL_REL * t.speed_scale
    if attr == "curvature":
        return _null_unless(moving, cross / (v2 * ca.sqrt(v2)))
    # a finite centre needs a normal acceleration that rounding cannot fake
    turning = ca.logic_and(moving, ca.fabs(cross) > ROUNDING_REL * ca.sqrt(v2 * (ax * ax + ay * ay)))
    k = v2 / cross
    return _null_unless(turning, x - k * vy if attr == "cx" else y + k * vx)


def _instant_centre(sym, a, b, attr, t):
    (oax, oay), (vax, vay), wa = _frame_velocity(sym, a, t)
    (obx, oby), (vbx, vby), wb = _frame_velocity(sym, b, t)
    # c: the relative velocity field at the global origin; (w_a - w_b) k x r its rotation
    cx = (vax + wa * oay) - (vbx + wb * oby)
    cy = (vay - wa * oax) - (vby - wb * obx)
    dw = wa - wb
    turning = ca.fabs(dw) > NULL_REL * t.speed_scale / t.size
    return _null_unless(turning, -cy / dw if attr == "icx" else cx / dw)
