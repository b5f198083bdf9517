"""Efforts and shaking forces of a spatial mechanism, by virtual power with the exact
Jacobians (kincas/core/dynamics.py does the same in 2D).

A virtual change of the input rates u' moves the chain with q' = T u', T = dq/du = -g_q^-1
g_u. The partial velocities of a point P (position P(q, u)) and of a body's angular velocity
(omega = 2 vec(e' (x) conj(e)), linear in e') are then, for input k,
    dv_P/du'_k = P_q T_k + P_u_k,    domega/du'_k = 2 vec((e_q T_k + e_u_k) (x) conj(e)),
and the generalised force the input must supply makes the virtual power of everything vanish:
    Q_k = sum_bodies [ m (a_G - g) . dv_G/du'_k + (I alpha + omega x I omega) . domega/du'_k ]
          - sum_forces F . dv_P/du'_k - sum_torques tau . domega/du'_k
          + sum_springs k (d - d0) dd'/du'_k,
with I = R I0 R' the inertia tensor about the centre of gravity in world axes (I0 given in the
drawing axes, the body's own at the drawing pose). A two-point bar's mass sits at its middle.
Shaking: the force the mechanism puts on the ground, -sum m a_G, and its moment about the
origin, -sum (r_G x m a_G + I alpha + omega x I omega).

>>> import numpy as np, kincas
>>> from kincas import SpatialMechanism, Body, Joint, Input
>>> m = SpatialMechanism(ground={"O": (0, 0, 0)},
...     bodies=[Body("arm", {"O": (0, 0, 0), "P": (2, 0, 0)}, mass=3.0, cg=(1, 0, 0))],
...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")], gravity=(0, -10, 0))
>>> round(kincas.solve(m, {"O.angle": 0.0}, report=["effort(O.angle)"])["effort(O.angle)"], 12)
30.0
"""
from __future__ import annotations

import re

import casadi as ca

from ..model.mobility import GROUND
from .quaternions import conj, qmul, rotation

_EFFORT = re.compile(r"^effort\((?P<key>[^()]+)\)$")
SHAKING = {"shaking.x": 0, "shaking.y": 1, "shaking.z": 2, "shaking.mx": 3, "shaking.my": 4, "shaking.mz": 5}


def check(sym, name: str):
    """None when `name` is not a force quantity; else its problems ([] if none)."""
    m = _EFFORT.match(name)
    if m:
        return [] if m["key"] in sym.ukeys else [f"no input {m['key']!r} (inputs: {sym.ukeys})"]
    return [] if name in SHAKING else None


def _vec(e):
    return ca.vertcat(*e)


def _bodies(sym):
    """Per massive body: (name, mass, G (3 SX), e or None, I0 3x3 SX or None)."""
    m, out = sym.mech, []
    for b in m.bodies:
        mass = sym.val(b.mass)
        if b.two_point:
            P, Q = (sym.points[n] for n in b.point_names)
            out.append((b.name, mass, [(P[i] + Q[i]) / 2 for i in range(3)], None, None))
            continue
        cg = b.cg if b.cg is not None else None
        G0 = sym._rel(cg) if cg is not None else None
        if G0 is None:
            loc = [sym._rel(xyz) for _, xyz in b.points]
            G0 = [sum(v[i] for v in loc) / len(loc) for i in range(3)]
        G = [g + o for g, o in zip(sym.world(b.name, G0), sym.origin)]
        I0 = ca.reshape(ca.vertcat(*[sym.val(c) for c in b.inertia]), 3, 3).T
        out.append((b.name, mass, G, sym.frames[b.name][1], I0))
    return out


def _partials(sym, x):
    """d(x')/du' (len(x) x nu) for an expression x(q, u): x_q T + x_u."""
    x = _vec(x)
    T = getattr(sym, "_T", None)
    if T is None:  # dq/du: one symbolic solve per model, shared by every partial velocity
        T = sym._T = -sym.lsolve(sym.Ju)
    return ca.mtimes(ca.jacobian(x, sym.q), T) + ca.jacobian(x, sym.u)


def _omega_partials(sym, e):
    """d(omega)/du' (3 x nu) of a body with quaternion e."""
    de = _partials(sym, e)
    cols = []
    for k in range(sym.nu):
        w = qmul([de[i, k] for i in range(4)], conj(e))
        cols.append(2 * ca.vertcat(*w[1:]))
    return ca.horzcat(*cols) if cols else ca.SX(3, 0)


def _rates(sym, t, e):
    """(omega, alpha) of a body, world axes, from its quaternion's time derivatives."""
    d1 = [t.d(c, 1) for c in e]
    d2 = [t.d(c, 2) for c in e]
    return 2 * _vec(qmul(d1, conj(e))[1:]), 2 * _vec(qmul(d2, conj(e))[1:])


def _inertial(sym, t):
    """Per massive body: (G, m a_G, its moment I alpha + omega x I omega (3 SX, 0 for a bar))."""
    out = []
    for name, mass, G, e, I0 in _bodies(sym):
        aG = _vec([t.d(c, 2) for c in G])
        M = ca.SX.zeros(3)
        if e is not None:
            w, al = _rates(sym, t, e)
            R = ca.vertcat(*[ca.horzcat(*row) for row in rotation(e)])
            Iw = ca.mtimes(ca.mtimes(R, I0), R.T)
            M = ca.mtimes(Iw, al) + ca.cross(w, ca.mtimes(Iw, w))
        out.append((name, mass, G, e, mass * aG, M))
    return out


def expression(sym, name: str, t):
    m = sym.mech
    key = t.cache.get(("space.inertial",))
    if key is None:
        key = t.cache[("space.inertial",)] = _inertial(sym, t)
    if name in SHAKING:
        i = SHAKING[name]
        if i < 3:
            return -sum((maG[i] for *_, maG, _ in key), ca.SX(0))
        mom = ca.SX.zeros(3)
        for _, _, G, _, maG, M in key:
            mom += ca.cross(_vec(G), maG) + M
        return -mom[i - 3]
    k = sym.ukeys.index(_EFFORT.match(name)["key"])
    g = _vec([sym.val(c) for c in m.gravity])
    Q = ca.SX(0)
    for _, mass, G, e, maG, M in key:
        Q += ca.dot(maG - mass * g, _partials(sym, G)[:, k])
        if e is not None:
            Q += ca.dot(M, _omega_partials(sym, e)[:, k])
    frames = {b.name: sym.frames[b.name][1] for b in m.bodies if not b.two_point}
    for ld in m.loads:
        if ld.kind == "force":
            F = _vec([sym.val(c) for c in ld.value])
            Q -= ca.dot(F, _partials(sym, sym.points[ld.at])[:, k])
        elif ld.kind == "torque":
            tau = _vec([sym.val(c) for c in ld.value])
            Q -= ca.dot(tau, _omega_partials(sym, frames[ld.at])[:, k])
        else:
            A, B = (sym.points[p] for p in ld.points)
            dvec = _vec([A[i] - B[i] for i in range(3)])
            d = ca.norm_2(dvec)
            dd = ca.mtimes((dvec / d).T, _partials(sym, A) - _partials(sym, B))
            Q += sym.val(ld.stiffness) * (d - sym.val(ld.free_length)) * dd[0, k]
    return Q


__all__ = ["check", "expression", "GROUND"]
