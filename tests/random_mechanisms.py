"""Seeded random planar mechanisms for the property tests (tests/test_property_*.py).

A mechanism is generated from an assembled configuration chosen first: the points' positions
are drawn in a normalised frame (size about 1), the links are whatever joins them (a bar's
length is the distance drawn, a plate's local coordinates are its points seen from a frame
drawn at random), slides are lines drawn through their points. So an assembly is known to
exist, and its positions are known without kincas. The normalised mechanism is then moved to a
random scale (1e-4 to 1e4), orientation and offset (up to 1e4 sizes from the origin); every
number of the declaration is a named parameter, so one family is one kincas structure (one
model, one compiled kernel) and every number has a sensitivity.

Along the sweep the positions are solved again here, independently of kincas: a small Newton
in numpy on this module's own loop equations (each link's origin and angle as unknowns), with a
finite-difference Jacobian, continued from the drawn configuration in small steps. A draw is
kept only if that Jacobian stays well conditioned over the sweep and a margin around it (no
singular position near the poses), else the next draw of the same seed is tried.

`case(family, seed)` gives a `Case`: the `kincas.Mechanism`, the sweep's inputs, rates,
accelerations and jerks, the reference positions, and what the tests need to recompute every
property by hand (each link's local coordinates, centre of gravity, the loads). Failures name
`case.label` (family and seed): `case(family, seed)` rebuilds the same mechanism.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

import kincas
from kincas import Input, Link, Load, Mechanism, Slide
from kincas.model import Gear

FAMILIES = ("fourbar_grashof", "fourbar_nongrashof", "slider_crank", "slider_driven",
            "inverted_slider", "quick_return", "pin_in_slot", "watt", "stephenson",
            "triad", "dyad_chain", "five_bar", "actuator", "geared_five_bar")
GEARED = ("geared_five_bar",)  # kincas refuses reactions with gears (the Newton-Euler test skips them)
COND_MIN = 0.03  # smallest singular value of the normalised Jacobian kept over a sweep


def count(default: int) -> int:
    """Mechanisms per family: KINCAS_PROPERTY_N overrides the CI's default."""
    return int(os.environ.get("KINCAS_PROPERTY_N", default))


def rot(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s], [s, c]])


# --------------------------------------------------------------------------- the drawing


@dataclass
class Spec:
    """A mechanism in normalised coordinates at its drawn configuration."""

    family: str
    ground: dict  # point -> (x, y)
    pos: dict  # moving point -> (x, y) at the drawn configuration
    links: list  # ("bar", name, P, Q) or ("plate", name, [points])
    slides: list = field(default_factory=list)  # (name, point, along, global angle, t)
    inputs: list = field(default_factory=list)  # ("angle", link) / ("slide", name) / ("parameter", bar)
    gears: list = field(default_factory=list)  # (link 1, link 2, r1, r2): external mesh, ground carrier
    origins: dict = field(default_factory=dict)  # plate -> the point at its frame's origin


def _pt(rng, c, r0, r1):
    """A point at a distance in [r0, r1] from c, in a random direction."""
    a, r = rng.uniform(-math.pi, math.pi), rng.uniform(r0, r1)
    return (c[0] + r * math.cos(a), c[1] + r * math.sin(a))


class Redraw(Exception):
    """This draw cannot give the family's shape: draw again."""


def _dyad_point(rng, b, d):
    """A joint C for a dyad hanging on b and d, away from their line (no toggle near)."""
    ell = math.dist(b, d)
    if ell < 0.2:
        raise Redraw
    for _ in range(50):
        c = _pt(rng, ((b[0] + d[0]) / 2, (b[1] + d[1]) / 2), 0.3 * ell, 1.2 * ell)
        u, v = np.subtract(c, b), np.subtract(c, d)
        ang = abs(math.atan2(u[0] * v[1] - u[1] * v[0], u @ v))
        if 0.5 < ang < math.pi - 0.5:
            return c
    raise Redraw


def _fourbar(rng, grashof):
    for _ in range(200):
        A, D = (0.0, 0.0), (1.0, 0.0)
        B = _pt(rng, A, 0.2, 0.9)
        C = _dyad_point(rng, B, D)
        lens = sorted([1.0, math.dist(A, B), math.dist(B, C), math.dist(C, D)])
        if (lens[0] + lens[3] < lens[1] + lens[2] - 0.02) == grashof:
            break
    else:
        raise Redraw
    E = _pt(rng, B, 0.2, 0.8)
    return Spec("fourbar_grashof" if grashof else "fourbar_nongrashof", {"A": A, "D": D},
                {"B": B, "C": C, "E": E},
                [("bar", "crank", "A", "B"), ("plate", "coupler", ["B", "C", "E"]),
                 ("bar", "rocker", "D", "C")], inputs=[("angle", "crank")])


def _slider_crank(rng, driven):
    O = (0.0, 0.0)
    A = _pt(rng, O, 0.2, 0.5)
    ang = rng.uniform(-math.pi, math.pi)
    while True:  # the rod well away from square to the guide (no dead centre near)
        B = _pt(rng, A, 0.6, 1.4)
        rod = math.atan2(B[1] - A[1], B[0] - A[0])
        if abs(math.cos(rod - ang)) > 0.45:
            break
    P = _pt(rng, B, 0.1, 0.3)
    links = [("bar", "crank", "O", "A"), ("plate", "rod", ["A", "B", "P"])]
    slides = [("guide", "B", "ground", ang, rng.uniform(-0.5, 0.5))]
    inputs = [("slide", "guide")] if driven else [("angle", "crank")]
    return Spec("slider_driven" if driven else "slider_crank", {"O": O}, {"A": A, "B": B, "P": P},
                links, slides, inputs)


def _inverted(rng):
    """Inverted slider-crank: the crank's pin A in the slot of a lever turning about Q."""
    O, Q = (0.0, 0.0), (1.0, 0.0)
    while True:
        A = _pt(rng, O, 0.2, 0.6)
        if math.dist(A, Q) > 0.5:
            break
    sl = math.atan2(A[1] - Q[1], A[0] - Q[0]) + rng.uniform(-0.3, 0.3)  # the slot's line
    # the slot's line passes through A at angle sl; the lever's pivot Q lies off it
    E = _pt(rng, Q, 0.5, 1.0)
    return Spec("inverted_slider", {"O": O, "Q": Q}, {"A": A, "E": E},
                [("bar", "crank", "O", "A"), ("plate", "lever", ["Q", "E"])],
                [("slot", "A", "lever", sl, rng.uniform(-0.3, 0.3))], [("angle", "crank")])


def _quick_return(rng):
    """Whitworth-like quick return: crank pin in the lever's slot, rod to a ram on a guide."""
    sp = _inverted(rng)
    E = sp.pos["E"]
    ang = rng.uniform(-math.pi, math.pi)
    while True:
        F = _pt(rng, E, 0.5, 1.0)
        rod = math.atan2(F[1] - E[1], F[0] - E[0])
        if abs(math.cos(rod - ang)) > 0.45 and abs(math.sin(rod - ang)) > 0.2:
            break
    sp.family = "quick_return"
    sp.pos["F"] = F
    sp.links.append(("bar", "rod", "E", "F"))
    sp.slides.append(("ram", "F", "ground", ang, rng.uniform(-0.5, 0.5)))
    return sp


def _pin_in_slot(rng):
    """A ground pin G in the slot of a moving guide whose end A rides on the crank."""
    O, G = (0.0, 0.0), (1.0, 0.3)
    A = _pt(rng, O, 0.2, 0.5)
    sl = math.atan2(G[1] - A[1], G[0] - A[0])  # the slot's line through G and near A
    T = _pt(rng, A, 0.3, 0.8)
    return Spec("pin_in_slot", {"O": O, "G": G}, {"A": A, "T": T},
                [("bar", "crank", "O", "A"), ("plate", "guide", ["A", "T"])],
                [("slot", "G", "guide", sl, rng.uniform(-0.2, 0.2))], [("angle", "crank")])


def _watt(rng):
    """Watt I: a four-bar whose coupler and rocker (both ternary) carry a second dyad E-G-F."""
    sp = _fourbar(rng, rng.random() < 0.5)
    B, C = sp.pos["B"], sp.pos["C"]
    F = _pt(rng, C, 0.3, 0.8)  # on the rocker
    E = sp.pos["E"]
    G = _dyad_point(rng, E, F)
    sp.family, sp.pos = "watt", {"B": B, "C": C, "E": E, "F": F, "G": G}
    sp.links = [("bar", "crank", "A", "B"), ("plate", "coupler", ["B", "C", "E"]),
                ("plate", "rocker", ["D", "C", "F"]), ("bar", "link5", "E", "G"),
                ("bar", "link6", "F", "G")]
    return sp


def _stephenson(rng):
    """Stephenson III driven at a link outside its four-bar loop: the rest is a triad."""
    sp = _fourbar(rng, rng.random() < 0.5)
    E = sp.pos["E"]
    H = _pt(rng, E, 0.6, 1.2)  # third ground pivot
    Dd = _dyad_point(rng, E, H)  # driver's pin
    sp.family = "stephenson"
    sp.ground["H"] = H
    sp.pos["K"] = Dd
    sp.links += [("bar", "rod", "E", "K"), ("bar", "driver", "H", "K")]
    sp.inputs = [("angle", "driver")]
    return sp


def _triad(rng):
    """A class-III Assur triad: ternary plate B1 B2 B3 held by three legs from the crank's pin
    P and ground pivots G2, G3 (no dyad closes first)."""
    O = (0.0, 0.0)
    P = _pt(rng, O, 0.2, 0.4)
    c = (rng.uniform(0.6, 1.0), rng.uniform(-0.2, 0.2))
    B = [_pt(rng, c, 0.25, 0.45) for _ in range(3)]
    legs = [P] + [_pt(rng, b, 0.5, 0.9) for b in B[1:]]
    return Spec("triad", {"O": O, "G2": legs[1], "G3": legs[2]},
                {"P": P, "B1": B[0], "B2": B[1], "B3": B[2]},
                [("bar", "crank", "O", "P"), ("bar", "leg1", "P", "B1"),
                 ("plate", "plate", ["B1", "B2", "B3"]), ("bar", "leg2", "G2", "B2"),
                 ("bar", "leg3", "G3", "B3")], inputs=[("angle", "crank")])


def _dyad_chain(rng):
    """A four-bar, then two more dyads, each hung on a point of the last rocker and a ground pivot."""
    sp = _fourbar(rng, True)
    sp.family = "dyad_chain"
    sp.links[2] = ("plate", "rocker", ["D", "C", "R1"])
    sp.pos["R1"] = _pt(rng, sp.pos["C"], 0.2, 0.6)
    lastpt = "R1"
    for i in (1, 2):
        g = f"H{i}"
        sp.ground[g] = _pt(rng, sp.pos[lastpt], 0.7, 1.2)
        j = f"J{i}"
        sp.pos[j] = _dyad_point(rng, sp.pos[lastpt], sp.ground[g])
        nxt = f"R{i + 1}"
        sp.pos[nxt] = _pt(rng, sp.pos[j], 0.2, 0.6)
        sp.links += [("bar", f"arm{i}", lastpt, j), ("plate", f"out{i}", [g, j, nxt])]
        lastpt = nxt
    return sp


def _five_bar(rng):
    """Two cranks driven together (two inputs), joined by two links at C."""
    A, E = (0.0, 0.0), (1.0, 0.0)
    B, D = _pt(rng, A, 0.3, 0.6), _pt(rng, E, 0.3, 0.6)
    C = _dyad_point(rng, B, D)
    return Spec("five_bar", {"A": A, "E": E}, {"B": B, "D": D, "C": C},
                [("bar", "crank1", "A", "B"), ("bar", "link1", "B", "C"),
                 ("bar", "crank2", "E", "D"), ("bar", "link2", "D", "C")],
                inputs=[("angle", "crank1"), ("angle", "crank2")])


def _actuator(rng):
    """A bell crank O-B-C turned by an actuator A-B whose length is the input (a parameter)."""
    O, A = (0.0, 0.0), (1.0, 0.0)
    while True:
        B = _pt(rng, O, 0.3, 0.7)
        u, v = np.subtract(B, O), np.subtract(B, A)
        if 0.5 < abs(math.atan2(u[0] * v[1] - u[1] * v[0], u @ v)) < math.pi - 0.5:
            break
    C = _pt(rng, O, 0.3, 0.8)
    return Spec("actuator", {"O": O, "A": A}, {"B": B, "C": C},
                [("plate", "bell", ["O", "B", "C"]), ("bar", "jack", "A", "B")],
                inputs=[("parameter", "jack")])


def _geared_five_bar(rng):
    """A five-bar whose two cranks are gears in mesh (one input): gear centres A and E."""
    A, E = (0.0, 0.0), (1.0, 0.0)
    lam = rng.uniform(0.3, 0.7)
    B, D = _pt(rng, A, 0.3, 0.7), _pt(rng, E, 0.3, 0.7)
    C = _dyad_point(rng, B, D)
    return Spec("geared_five_bar", {"A": A, "E": E}, {"B": B, "D": D, "C": C},
                [("plate", "gear1", ["A", "B"]), ("bar", "link1", "B", "C"),
                 ("plate", "gear2", ["E", "D"]), ("bar", "link2", "D", "C")],
                inputs=[("angle", "gear1")], gears=[("gear1", "gear2", lam, 1 - lam)],
                origins={"gear1": "A", "gear2": "E"})


DRAW = {"fourbar_grashof": lambda r: _fourbar(r, True),
        "fourbar_nongrashof": lambda r: _fourbar(r, False),
        "slider_crank": lambda r: _slider_crank(r, False),
        "slider_driven": lambda r: _slider_crank(r, True),
        "inverted_slider": _inverted, "quick_return": _quick_return,
        "pin_in_slot": _pin_in_slot, "watt": _watt, "stephenson": _stephenson,
        "triad": _triad, "dyad_chain": _dyad_chain, "five_bar": _five_bar,
        "actuator": _actuator, "geared_five_bar": _geared_five_bar}


# --------------------------------------------------------------------------- normalised model


class Frames:
    """The normalised mechanism as this module solves it: each link's local points, and the
    loop equations g(z, u) = 0 in z = (origin x, origin y, angle) per link."""

    def __init__(self, sp: Spec, rng):
        self.sp = sp
        self.names = [lk[1] for lk in sp.links]
        self.local, self.theta0, self.origin0 = {}, {}, {}
        allpos = {**sp.ground, **sp.pos}
        for lk in sp.links:
            if lk[0] == "bar":
                _, name, p, q = lk
                P, Q = np.asarray(allpos[p]), np.asarray(allpos[q])
                th = math.atan2(*(Q - P)[::-1])
                self.local[name] = {p: np.zeros(2), q: np.array([np.linalg.norm(Q - P), 0.0])}
                self.origin0[name], self.theta0[name] = P, th
            else:
                _, name, pts = lk
                c = np.mean([allpos[p] for p in pts], axis=0)
                o = c + rng.uniform(-0.3, 0.3, 2)
                if name in sp.origins:  # a gear: its centre is its frame's origin
                    o = np.asarray(allpos[sp.origins[name]], float)
                th = rng.uniform(-math.pi, math.pi)
                R = rot(-th)
                self.local[name] = {p: R @ (np.asarray(allpos[p]) - o) for p in pts}
                self.origin0[name], self.theta0[name] = o, th
        self.carriers = {}
        for p in list(sp.ground) + list(sp.pos):
            at = (["ground"] if p in sp.ground else []) + [n for n in self.names if p in self.local[n]]
            self.carriers[p] = at
        # slides: through point and angle in the body's frame
        self.slides = []
        for name, p, along, ang, t in sp.slides:
            P = np.asarray(allpos[p])
            d = np.array([math.cos(ang), math.sin(ang)])
            T = P + t * d
            if along == "ground":
                self.slides.append((name, p, along, T, ang, -t))
            else:
                o, th = self.origin0[along], self.theta0[along]
                self.slides.append((name, p, along, rot(-th) @ (T - o), ang - th, -t))
        self.jack = {t: k for k, (kind, t) in enumerate(sp.inputs) if kind == "parameter"}
        self._slide_cache = {}
        self.z0 = np.concatenate([[*self.origin0[n], self.theta0[n]] for n in self.names])
        self.u0 = np.array([self.input_value(k, self.z0) for k in range(len(sp.inputs))])

    # positions
    def frame(self, z, body):
        if body == "ground":
            return np.zeros(2), 0.0
        i = self.names.index(body)
        return z[3 * i:3 * i + 2], z[3 * i + 2]

    def point(self, z, p, body=None, local=None):
        if body is None:
            body = self.carriers[p][0]
        if body == "ground":
            return np.asarray(self.sp.ground[p], float)
        o, th = self.frame(z, body)
        return o + rot(th) @ (self.local[body][p] if local is None else local)

    def line(self, z, k):
        name, p, along, T, ang, _ = self.slides[k]
        o, th = self.frame(z, along)
        a = th + ang
        return o + rot(th) @ T, np.array([math.cos(a), math.sin(a)])

    def input_value(self, k, z):
        kind, target = self.sp.inputs[k]
        if kind == "angle":
            return self.frame(z, target)[1]
        if kind == "slide":
            kk = [s[0] for s in self.slides].index(target)
            T, d = self.line(z, kk)
            return d @ (self.point(z, self.slides[kk][1]) - T)
        lk = next(lk for lk in self.sp.links if lk[1] == target)
        return self.local[target][lk[3]][0]

    def residual(self, z, u):
        return self.equations(z, u)[0]

    def jacobian(self, z, u):
        return self.equations(z, u)[1]

    def _where(self, z, u, p, body):
        """A point's position on one body, and its derivative in that body's (x, y, angle)."""
        if body == "ground":
            return np.asarray(self.sp.ground[p], float), None
        loc = self.local[body][p]
        if body in self.jack and loc[0] != 0:  # the actuator's far end: its length is an input
            loc = np.array([u[self.jack[body]], 0.0])
        o, th = self.frame(z, body)
        r = rot(th) @ loc
        return o + r, (self.names.index(body), np.array([-r[1], r[0]]))

    def equations(self, z, u):
        """g(z, u) and its exact Jacobian in z (one row per pin coordinate, slide, input)."""
        rows, J = [], []
        n = len(z)

        def add(val, parts):
            row = np.zeros(n)
            for i, grad in parts:  # grad: derivative in (x, y, angle) of link i
                row[3 * i:3 * i + 3] += grad
            rows.append(val)
            J.append(row)

        def pgrad(d, c, sign):  # coordinate c of a point: its derivative in its body's z
            if d[1] is None:
                return []
            i, dth = d[1]
            return [(i, sign * np.array([c == 0, c == 1, dth[c]], float))]

        for p, at in self.carriers.items():
            ref = self._where(z, u, p, at[0])
            for b in at[1:]:
                here = self._where(z, u, p, b)
                for c in (0, 1):
                    add(here[0][c] - ref[0][c], pgrad(here, c, 1.0) + pgrad(ref, c, -1.0))
        for k, (name, p, along, T, ang, _) in enumerate(self.slides):
            P = self._where(z, u, p, self.carriers[p][0])
            (tp, tg), a = self._line_point(z, along, T, ang)
            d = np.array([math.cos(a), math.sin(a)])
            nrm = np.array([-d[1], d[0]])
            w = P[0] - tp
            parts = []
            if P[1] is not None:
                i, dth = P[1]
                parts.append((i, np.array([nrm[0], nrm[1], nrm @ dth])))
            if tg is not None:  # the line's body: its point T and its direction both turn
                i, dth = tg
                parts.append((i, np.array([-nrm[0], -nrm[1], -nrm @ dth - d @ w])))
            add(nrm @ w, parts)
            self._slide_cache[name] = (P, tp, tg, d, nrm, w)
        for g1, g2, r1, r2 in self.sp.gears:  # external mesh: theta2 + k theta1 stays as drawn
            i1, i2, k = self.names.index(g1), self.names.index(g2), r1 / r2
            add(z[3 * i2 + 2] + k * z[3 * i1 + 2] - (self.theta0[g2] + k * self.theta0[g1]),
                [(i1, np.array([0, 0, k])), (i2, np.array([0, 0, 1.0]))])
        for k, (kind, target) in enumerate(self.sp.inputs):
            if kind == "angle":
                add(self.frame(z, target)[1] - u[k], [(self.names.index(target), np.array([0, 0, 1.0]))])
            elif kind == "slide":
                P, tp, tg, d, nrm, w = self._slide_cache[target]
                parts = []
                if P[1] is not None:
                    i, dth = P[1]
                    parts.append((i, np.array([d[0], d[1], d @ dth])))
                if tg is not None:
                    i, dth = tg
                    parts.append((i, np.array([-d[0], -d[1], -d @ dth + nrm @ w])))
                add(d @ w - u[k], parts)
        return np.array(rows), np.array(J)

    def _line_point(self, z, along, T, ang):
        """The slide line's point T (global) with its derivative, and the line's angle."""
        if along == "ground":
            return (np.asarray(T, float), None), ang
        o, th = self.frame(z, along)
        r = rot(th) @ T
        return (o + r, (self.names.index(along), np.array([-r[1], r[0]]))), th + ang

    def newton(self, z, u):
        """Newton from z (quadratic: once the step is below 1e-10, one more step ends it)."""
        for it in range(20):
            r, J = self.equations(z, u)
            dz = np.linalg.solve(J, -r)
            z = z + dz
            if np.abs(dz).max() < 1e-10:
                z = z + np.linalg.solve(*self.equations(z, u)[::-1]) * -1
                break
        return z, np.abs(self.residual(z, u)).max()

    def conditioning(self, z, u):
        s = np.linalg.svd(self.jacobian(z, u), compute_uv=False)
        return s[-1] / s[0]


# --------------------------------------------------------------------------- the case


@dataclass
class Case:
    """A random mechanism with everything the property tests need."""

    family: str
    seed: int
    mech: Mechanism
    inputs: dict  # key -> values over the sweep
    rates: dict
    accelerations: dict
    jerks: dict
    c_acc: float  # accelerations = c_acc * rates, jerks = c_jerk * rates (see derivatives)
    c_jerk: float
    size: float  # the mechanism's length scale (kincas's size())
    scale: float
    offset: float  # distance of the mechanism from the origin, in sizes
    ref: dict  # point -> (N, 2) reference positions over the sweep
    frames: Frames
    keys: list
    units: list  # per input: 1 for an angle, the scale for a length

    @property
    def label(self) -> str:
        return (f"{self.family} seed={self.seed} (scale {self.scale:.3g}, offset "
                f"{self.offset:.3g} sizes; rebuild: random_mechanisms.case({self.family!r}, {self.seed}))")

    @property
    def n(self) -> int:
        return len(next(iter(self.inputs.values())))

    # names of things, as kincas knows them
    @property
    def moving(self):
        return list(self.mech.moving_points)

    def local(self, link, point):
        lk = self.mech.link(link)
        x, y = lk.local(point)
        return np.array([self.mech.value(x), self.mech.value(y)])

    def local_at(self, link, point):
        """A point in its link's frame: (2,), or (2, N) over the sweep for an actuator's end
        (its length is the driven parameter)."""
        lk = self.mech.link(link)
        if lk.two_point and point == lk.point_names[1] and lk.points[1][1][0] in self.inputs:
            u = self.inputs[lk.points[1][1][0]]
            return np.stack([u, 0 * u])
        return self.local(link, point)

    def cg_local(self, link):
        """The centre of gravity in the link's frame (the mean of its points by default)."""
        lk = self.mech.link(link)
        if lk.inertial.cg is not None:
            return np.array([self.mech.value(v) for v in lk.inertial.cg])
        pts = [self.local_at(link, p) for p in lk.point_names]
        mean = sum(v[:, None] if v.ndim == 1 else v for v in pts) / len(pts)
        return mean[:, 0] if mean.shape[1] == 1 else mean

    def bodies_at(self, point):
        out = ["ground"] if point in self.mech.ground_points else []
        return out + [lk.name for lk in self.mech.links if point in lk.point_names]

    def joints(self):
        """(point, body) for every pin and every body there."""
        out = []
        for p in list(self.mech.ground_points) + self.moving:
            at = self.bodies_at(p)
            if len(at) >= 2:
                out += [(p, b) for b in at]
        return out

    def report_positions(self):
        names = [f"{p}.{c}" for p in self.moving for c in "xy"]
        names += [f"{lk.name}.angle" for lk in self.mech.links]
        return names + [f"{s.name}.s" for s in self.mech.slides]

    def report_motion(self):
        names = self.report_positions()
        names += [f"{p}.{c}" for p in self.moving for c in ("vx", "vy", "ax", "ay", "jx", "jy")]
        names += [f"{lk.name}.{c}" for lk in self.mech.links for c in ("omega", "alpha", "jerk")]
        return names + [f"{s.name}.{c}" for s in self.mech.slides for c in ("v", "a")]

    def report_forces(self):
        names = [f"effort({k})" for k in self.keys]
        if self.mech.gears:  # reactions are refused with gears (their contact force is not modelled)
            return names
        names += [f"reaction({p}, {b}).{c}" for p, b in self.joints() for c in "xy"]
        return names + [f"reaction({s.name}).{c}" for s in self.mech.slides for c in "xy"]

    def sweep(self, report, **kw):
        return kincas.sweep(self.mech, self.inputs, rates=self.rates,
                            accelerations=self.accelerations, jerks=self.jerks, report=report, **kw)

    def scene(self, report) -> dict:
        """The same mechanism as a scene (tests/conftest.py dump_toml writes it), angles in radians."""
        m = self.mech
        links = {}
        for lk in m.links:
            t = {}
            if lk.two_point:
                t["points"], t["length"] = list(lk.point_names), lk.points[1][1][0]
            else:
                t["points"] = {p: list(xy) for p, xy in lk.points}
            i = lk.inertial
            t["mass"], t["inertia"] = i.mass, i.inertia
            if i.cg is not None:
                t["cg"] = list(i.cg)
            links[lk.name] = t
        slides = [{"name": s.name, "point": s.point, "along": s.along,
                   "line": {"through": list(s.through), "angle": s.angle}} for s in m.slides]
        inputs = []
        for inp in m.inputs:
            u = self.inputs[inp.key]
            inputs.append({inp.kind: inp.target,
                           "sweep": {"from": float(u[0]), "to": float(u[-1]), "steps": len(u)},
                           "rate": float(self.rates[inp.key]),
                           "acceleration": float(self.accelerations[inp.key]),
                           "jerk": float(self.jerks[inp.key])})
        loads = []
        for ld in m.loads:
            if ld.kind == "force":
                loads.append({"point": ld.at, "force": list(ld.value)})
            elif ld.kind == "torque":
                loads.append({"link": ld.at, "torque": ld.value})
            else:
                loads.append({"spring": list(ld.points), "stiffness": ld.stiffness,
                              "free_length": ld.free_length})
        out = {"title": self.label[:60], "units": {"length": "m", "angle": "rad", "time": "s"},
               "gravity": list(m.gravity), "parameters": dict(m.parameters),
               "ground": {g: list(xy) for g, xy in m.ground}, "links": links}
        if slides:
            out["slides"] = slides
        if m.gears:
            out["gears"] = [{"name": g.name, "links": list(g.links), "radii": list(g.radii),
                             "phase": g.phase} for g in m.gears]
        out["inputs"] = inputs
        out["loads"] = loads
        out["guess"] = {p: list(xy) for p, xy in m.guess}
        out["output"] = {"report": list(report)}
        return out


def _loguniform(rng, lo, hi):
    return float(10 ** rng.uniform(math.log10(lo), math.log10(hi)))


@lru_cache(maxsize=None)
def case(family: str, seed: int, max_offset: float = 1e4, scale: float | None = None) -> Case:
    """The random mechanism `seed` of `family`; offsets up to `max_offset` sizes from the origin."""
    rng = np.random.default_rng([FAMILIES.index(family), seed])
    for attempt in range(200):
        try:
            sp = DRAW[family](rng)
        except Redraw:
            continue
        fr = Frames(sp, rng)
        if fr.conditioning(fr.z0, fr.u0) < COND_MIN:
            continue
        got = _sweep_reference(fr, rng, sp)
        if got is not None:
            break
    else:  # pragma: no cover - the draws above are generous
        raise RuntimeError(f"no well-conditioned {family} for seed {seed}")
    U, Z, direction = got
    s = scale if scale is not None else _loguniform(rng, 1e-4, 1e4)
    phi = rng.uniform(-math.pi, math.pi)
    off_sizes = 0.0 if rng.random() < 0.25 else _loguniform(rng, 0.1, max_offset)
    offset = s * off_sizes * np.array([math.cos(a := rng.uniform(-math.pi, math.pi)), math.sin(a)])
    return _realize(family, seed, sp, fr, rng, U, Z, direction, s, phi, offset, off_sizes)


def _sweep_reference(fr: Frames, rng, sp):
    """Inputs over the sweep (normalised) and positions there, or None if a pose comes near a
    singular position. Newton is continued from the drawn configuration at half-steps between
    the poses, and a little beyond both ends (the derivative tests' stencils reach there)."""
    nin = len(sp.inputs)
    direction = rng.normal(size=nin)
    direction /= np.linalg.norm(direction)
    span = rng.uniform(0.15, 0.4)
    n = int(rng.integers(5, 9))
    margin = 0.03
    taus = list(np.linspace(0.0, span, 2 * n - 1)) + [span + margin]
    Z, z = [], fr.z0.copy()
    for k, t in enumerate(taus):
        u = fr.u0 + t * direction
        z, res = fr.newton(z, u)
        if res > 1e-12 or fr.conditioning(z, u) < COND_MIN:
            return None
        if k % 2 == 0 and k < len(taus) - 1:
            Z.append(z)
    u = fr.u0 - margin * direction
    z, res = fr.newton(fr.z0.copy(), u)
    if res > 1e-12 or fr.conditioning(z, u) < COND_MIN:
        return None
    U = fr.u0 + np.linspace(0.0, span, n)[:, None] * direction
    return U, np.array(Z), direction


def _realize(family, seed, sp, fr, rng, U, Z, direction, s, phi, offset, off_sizes):
    R = rot(phi)
    glob = lambda xy: offset + s * (R @ np.asarray(xy, float))
    # what the declaration names (which links give a cg, where the loads act) is the same for
    # every mechanism of a family: one kincas structure, one model, one kernel per family
    pick = np.random.default_rng(FAMILIES.index(family))
    params = {}

    def par(name, v):
        params[name] = float(v)
        return name

    ground = {g: (par(f"gx_{g}", glob(xy)[0]), par(f"gy_{g}", glob(xy)[1])) for g, xy in sp.ground.items()}
    links = []
    masses = {}
    for lk in sp.links:
        name = lk[1]
        mass = _loguniform(rng, 0.1, 10)
        loc = fr.local[name]
        ext = max(np.linalg.norm(v) for v in loc.values()) * s
        inertia = mass * ext ** 2 * rng.uniform(0.01, 0.2)
        kw = {"mass": par(f"m_{name}", mass), "inertia": par(f"J_{name}", inertia)}
        if len(links) % 2 == 0:  # the others' cg is the default, the mean of their points
            c = np.mean(list(loc.values()), axis=0) * s + rng.uniform(-0.2, 0.2, 2) * ext
            kw["cg"] = (par(f"cgx_{name}", c[0]), par(f"cgy_{name}", c[1]))
        masses[name] = mass
        if lk[0] == "bar":
            _, _, p, q = lk
            links.append(Link.bar(name, p, q, par(f"len_{name}", s * loc[q][0]), **kw))
        else:
            pts = {p: (par(f"{name}_{p}_x", s * v[0]), par(f"{name}_{p}_y", s * v[1])) for p, v in loc.items()}
            links.append(Link(name, pts, **kw))
    slides = []
    for name, p, along, T, ang, _ in fr.slides:
        if along == "ground":
            T, ang = glob(T), ang + phi
        else:
            T = s * np.asarray(T)
        slides.append(Slide(p, along, through=(par(f"{name}_tx", T[0]), par(f"{name}_ty", T[1])),
                            angle=par(f"{name}_ang", ang), name=name))
    inputs, keys, units = [], [], []
    for kind, target in sp.inputs:
        inp = {"angle": Input.angle, "slide": Input.slide, "parameter": Input.parameter}[kind](
            target if kind != "parameter" else f"len_{target}")
        inputs.append(inp)
        keys.append(inp.key)
        units.append(1.0 if kind == "angle" else s)
    # loads: a force at a moving point, a torque on a link, a spring from a ground point
    mbar = float(np.mean(list(masses.values())))
    gmag = 9.81 * s
    ga = rng.uniform(-math.pi, math.pi)
    gravity = (par("grav_x", gmag * math.cos(ga)), par("grav_y", gmag * math.sin(ga)))
    moving = [p for p in sp.pos]
    fpt = moving[int(pick.integers(len(moving)))]
    fa = rng.uniform(-math.pi, math.pi)
    fmag = 10 * mbar * gmag
    spt = moving[int(pick.integers(len(moving)))]
    gpt = list(sp.ground)[int(pick.integers(len(sp.ground)))]
    l_now = math.dist(sp.ground[gpt], sp.pos[spt]) * s
    tl = sp.links[int(pick.integers(len(sp.links)))][1]
    loads = [Load.force(fpt, (par("F_x", fmag * math.cos(fa)), par("F_y", fmag * math.sin(fa)))),
             Load.torque(tl, par("tau", rng.uniform(-1, 1) * fmag * s)),
             Load.spring(gpt, spt, par("k_spring", 10 * mbar * gmag / s), par("l0_spring", l_now * rng.uniform(0.5, 1.5)))]
    # the sweep's inputs (scaled), the reference positions
    Us = np.empty_like(U)
    for k, (kind, _) in enumerate(sp.inputs):
        Us[:, k] = U[:, k] + phi if kind == "angle" else U[:, k] * s
        if kind == "angle":  # the first pose's angle in (-pi, pi], as kincas starts gears' angles
            Us[:, k] -= 2 * math.pi * round(Us[0, k] / (2 * math.pi))
        Us[:, k] = np.linspace(Us[0, k], Us[-1, k], len(Us))  # as a scene's sweep spaces them
    pos = {}
    for p in list(sp.pos):
        pos[p] = np.array([glob(fr.point(z, p)) for z in Z])
    guess = {p: tuple(glob(np.asarray(xy) + rng.uniform(-0.02, 0.02, 2))) for p, xy in sp.pos.items()}
    gears = []
    for g1, g2, r1, r2 in sp.gears:  # the phase from both angles as kincas starts them, in (-pi, pi]
        wrap = lambda a: (a + math.pi) % (2 * math.pi) - math.pi
        th1 = wrap(fr.theta0[g1] + phi)
        phase = wrap(fr.theta0[g2] + phi) + r1 / r2 * th1
        gears.append(Gear(links=(g1, g2), radii=(par(f"r_{g1}", s * r1), par(f"r_{g2}", s * r2)),
                          phase=par("phase", phase), name="mesh"))
    mech = Mechanism(parameters=params, ground=ground, links=links, slides=slides, inputs=inputs,
                     guess=guess, gravity=gravity, loads=loads, gears=gears)
    wmag = rng.uniform(0.5, 3.0) * (1 if rng.random() < 0.5 else -1)
    rates = {k: wmag * direction[i] * units[i] for i, k in enumerate(keys)}
    c_acc, c_jerk = rng.uniform(-2, 2), rng.uniform(-3, 3)
    return Case(family, seed, mech, {k: Us[:, i] for i, k in enumerate(keys)}, rates,
                {k: c_acc * v for k, v in rates.items()}, {k: c_jerk * v for k, v in rates.items()},
                c_acc, c_jerk, mech.size(), s, off_sizes, pos, fr, keys, units)


def cases(family: str, n: int, **kw) -> list[Case]:
    return [case(family, seed, **kw) for seed in range(n)]


# --------------------------------------------------------------------------- shared solves

_SOLVED: dict = {}


def solved(c: Case, what: str = "motion", **kw):
    """The case's sweep reporting its positions and motion ("motion") or also its efforts and
    reactions ("forces"), solved once per test session."""
    key = (c.family, c.seed, c.offset, c.scale, what, tuple(sorted(kw.items())))
    if key not in _SOLVED:
        report = c.report_motion() + (c.report_forces() if what == "forces" else [])
        _SOLVED[key] = c.sweep(report, **kw)
    return _SOLVED[key]


def natural_scales(c: Case) -> dict:
    """Each derivative order's natural size: lengths L, L w, L (w^2 + |c_acc| w), ... with w
    the fastest input's rate in radians (or sizes) per unit of time; angles the same over L."""
    w = max(abs(c.rates[k]) / u for k, u in zip(c.keys, c.units))
    a = abs(c.c_acc)
    j = abs(c.c_jerk)
    per = [1.0, w, w * w + a * w, w ** 3 + 3 * a * w * w + j * w]
    return {"length": [c.size * v for v in per], "angle": per}


def check_family(family: str, n: int, check) -> str:
    """Every problem `check(case)` finds in the first n mechanisms of a family, one line each
    naming the mechanism ("" when there is none)."""
    return "\n".join(f"{c.label}: {b}" for c in cases(family, n) for b in check(c))


def solved_checked(c: Case, what: str, check) -> list[str]:
    """`check(case, sweep)` on the case's shared sweep, once every pose is solved."""
    sw = solved(c, what)
    if not sw.ok.all():
        return [f"poses not solved: {sw.status.tolist()}"]
    return check(c, sw)
