"""Property tests on random mechanisms with masses, inertias, gravity, a force, a torque and a
spring (tests/random_mechanisms.py): efforts by a power balance, reactions by Newton-Euler on
every body, both written here from the reported positions, velocities and accelerations
(which tests/test_property_kinematics.py checks against differences of positions).

- Virtual power: the inputs' efforts times their rates equal minus the power of the loads,
  gravity and the inertia forces (d'Alembert), at every pose.
- Newton-Euler: on every link, the reported pin reactions, slide forces, input torques or
  forces, loads, weight and inertia force add up to zero, and so do their moments about a
  point of the link.

A failure names the family and the seed (random_mechanisms.case(family, seed) rebuilds it).
"""
from __future__ import annotations

import numpy as np
import pytest

import random_mechanisms as rm

N = rm.count(6)
EPS = np.finfo(float).eps


def cross(r, f):
    return r[0] * f[1] - r[1] * f[0]


class Motion:
    """Positions, velocities, accelerations of points and links as reported, and of each
    link's centre of gravity by rigid-body kinematics from its first point."""

    def __init__(self, c, sw):
        self.c, self.sw = c, sw

    def point(self, p):
        sw, c = self.sw, self.c
        if p in c.mech.ground_points:
            g = dict(c.mech.ground)[p]
            x = np.array([c.mech.value(g[0]), c.mech.value(g[1])])[:, None] * np.ones(len(sw))
            return x, 0 * x, 0 * x
        return tuple(np.stack([sw[f"{p}.{a}"], sw[f"{p}.{b}"]]) for a, b in (("x", "y"), ("vx", "vy"), ("ax", "ay")))

    def link(self, name):
        sw = self.sw
        return sw[f"{name}.angle"], sw[f"{name}.omega"], sw[f"{name}.alpha"]

    def cg(self, name):
        """Position, velocity, acceleration of the link's centre of gravity."""
        c = self.c
        first = c.mech.link(name).point_names[0]
        x0, v0, a0 = self.point(first)
        th, w, al = self.link(name)
        col = lambda v: v[:, None] if v.ndim == 1 else v
        d = col(c.cg_local(name)) - col(c.local_at(name, first))
        R = lambda v: np.stack([np.cos(th) * v[0] - np.sin(th) * v[1], np.sin(th) * v[0] + np.cos(th) * v[1]])
        r = R(d)
        perp = np.stack([-r[1], r[0]])
        x, v, a = x0 + r, v0 + w * perp, a0 + al * perp - w ** 2 * r
        lk = c.mech.link(name)
        key = lk.points[1][1][0] if lk.two_point else None
        if key in c.inputs and lk.inertial.cg is None:  # an actuator's middle slides along it
            rel_v, rel_a = R(np.array([c.rates[key] / 2, 0.0])), R(np.array([c.accelerations[key] / 2, 0.0]))
            v = v + rel_v
            a = a + rel_a + 2 * w * np.stack([-rel_v[1], rel_v[0]])  # and Coriolis
        return x, v, a


def mass(c, name):
    i = c.mech.link(name).inertial
    return c.mech.value(i.mass), c.mech.value(i.inertia)


def gravity(c):
    return np.array([c.mech.value(v) for v in c.mech.gravity])[:, None]


def spring_force(c, mo, ld):
    """Force on the spring's first point (the opposite on its second), and its power."""
    (xp, vp, _), (xq, vq, _) = mo.point(ld.points[0]), mo.point(ld.points[1])
    k, l0 = c.mech.value(ld.stiffness), c.mech.value(ld.free_length)
    d = np.hypot(*(xp - xq))
    f = -k * (d - l0) / d * (xp - xq)
    return f, xp, xq, (f * (vp - vq)).sum(axis=0)


def power_errors(c, sw) -> list[str]:
    mo = Motion(c, sw)
    terms = [sw[f"effort({k})"] * c.rates[k] for k in c.keys]  # what the inputs supply
    g = gravity(c)
    for lk in c.mech.links:
        m, J = mass(c, lk.name)
        x, v, a = mo.cg(lk.name)
        th, w, al = mo.link(lk.name)
        terms += [m * (g * v).sum(axis=0), -m * (a * v).sum(axis=0), -J * al * w]
    for ld in c.mech.loads:
        if ld.kind == "force":
            F = np.array([c.mech.value(v) for v in ld.value])[:, None]
            terms.append((F * mo.point(ld.at)[1]).sum(axis=0))
        elif ld.kind == "torque":
            terms.append(c.mech.value(ld.value) * mo.link(ld.at)[1])
        else:
            terms.append(spring_force(c, mo, ld)[3])
    total = sum(terms)
    scale = sum(np.abs(t) for t in terms)
    # every term is a product of reported values each exact to ~1e-12 relative (accelerations
    # far from the origin lose (1 + offset) ulps): 1e-10 of the largest term's size is generous
    tol = (1e-10 + 100 * EPS * (1 + c.offset)) * scale
    bad = np.flatnonzero(~(np.abs(total) <= tol))
    return [f"pose {k}: the power balance leaves {total[k]:.3e} of {scale[k]:.3e}" for k in bad]


def newton_euler_errors(c, sw) -> list[str]:
    """Every link's force and moment balance (about its first point) with the reported reactions."""
    mo = Motion(c, sw)
    m_ = c.mech
    g = gravity(c)
    n = len(sw)
    forces = {lk.name: [] for lk in m_.links}  # (application point (2, N), force (2, N))
    torques = {lk.name: [] for lk in m_.links}

    def on(body, at, f):
        if body != "ground":
            forces[body].append((at, f))

    for p, b in c.joints():
        on(b, mo.point(p)[0], np.stack([sw[f"reaction({p}, {b}).x"], sw[f"reaction({p}, {b}).y"]]))
    for s in m_.slides:
        at = mo.point(s.point)[0]
        Nf = np.stack([sw[f"reaction({s.name}).x"], sw[f"reaction({s.name}).y"]])
        key = f"{s.name}.s"
        if key in c.keys:  # a driven slide also pushes along its line with its effort
            a = m_.value(s.angle) + (mo.link(s.along)[0] if s.along != "ground" else 0.0)
            Nf = Nf + sw[f"effort({key})"] * np.stack([np.cos(a) + 0 * Nf[0], np.sin(a) + 0 * Nf[0]])
        on(c.bodies_at(s.point)[0], at, Nf)
        on(s.along, at, -Nf)
    for inp in m_.inputs:
        if inp.kind == "angle":
            torques[inp.target].append(sw[f"effort({inp.key})"])
    for ld in m_.loads:
        if ld.kind == "force":
            F = np.array([m_.value(v) for v in ld.value])[:, None] * np.ones(n)
            on(c.bodies_at(ld.at)[0], mo.point(ld.at)[0], F)
        elif ld.kind == "torque":
            torques[ld.at].append(m_.value(ld.value) + 0 * sw[f"{ld.at}.angle"])
        else:
            f, xp, xq, _ = spring_force(c, mo, ld)
            on(c.bodies_at(ld.points[0])[0], xp, f)
            on(c.bodies_at(ld.points[1])[0], xq, -f)
    bad = []
    for lk in m_.links:
        m, J = mass(c, lk.name)
        x, _, a = mo.cg(lk.name)
        al = mo.link(lk.name)[2]
        fl = forces[lk.name] + [(x, m * (g - a))]  # weight and d'Alembert's inertia force
        tl = torques[lk.name] + [-J * al]
        o = mo.point(lk.point_names[0])[0]
        F = sum(f for _, f in fl)
        M = sum(cross(at - o, f) for at, f in fl) + sum(tl)
        fscale = sum(np.hypot(*f) for _, f in fl)
        mscale = fscale * c.size + sum(np.abs(t) for t in tl)
        # the reactions are a linear solve of Newton-Euler with a well-conditioned chain:
        # 1e-9 of the sum of the forces' sizes (and their moments') is far above rounding
        tol = 1e-9
        ef, em = np.hypot(*F) / fscale, np.abs(M) / mscale
        for k in np.flatnonzero(~((ef <= tol) & (em <= tol))):
            bad.append(f"pose {k}: link {lk.name} out of balance by {ef[k]:.2e} of its forces, "
                       f"{em[k]:.2e} of its moments")
    return bad


@pytest.mark.parametrize("family", rm.FAMILIES)
def test_efforts_by_virtual_power(family):
    failures = rm.check_family(family, N, lambda c: rm.solved_checked(c, "forces", power_errors))
    assert not failures, failures


@pytest.mark.parametrize("family", [f for f in rm.FAMILIES if f not in rm.GEARED])
def test_reactions_balance_every_link(family):
    """At every scale and offset the generator draws (up to 1e4 sizes from the origin)."""
    failures = rm.check_family(family, N, lambda c: rm.solved_checked(c, "forces", newton_euler_errors))
    assert not failures, failures
