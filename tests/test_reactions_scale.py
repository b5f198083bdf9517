"""Joint reactions far from the origin and off unit scale, against Newton-Euler written here in
mpmath at 50 digits (issue 14, item 1).

Each mechanism is placed at an offset x0 (0 to 1e6 times its size) and scaled by s (1e-6 to
1e6): every length times s, gravity times s, inertias times s^2, forces times s, masses and
time unchanged, so every force scales by s and every torque by s^2. The reference takes the
same double-precision inputs as kincas (as exact mpf numbers), solves the positions in closed
form, differentiates them in time with mpmath (mp.diff at 50 digits) and solves each body's
three equations of motion, with moments about the origin, by LU at 50 digits. Reactions must
agree to 1e-9 of the largest force of the pose, efforts to 1e-9 of the largest torque.
"""
from __future__ import annotations

import mpmath as mp
import pytest

import kincas
from kincas import Input, Link, Load, Mechanism, Slide

DPS = 50
REL = 1e-9
SCALES = (1e-6, 1.0, 1e6)
OFFSETS = (0.0, 100.0, 1e4, 1e6)  # times the mechanism's size


def e(th):
    return mp.matrix([mp.cos(th), mp.sin(th)])


def cross(r, f):
    return r[0] * f[1] - r[1] * f[0]


def circles(c1, r1, c2, r2, sign):
    """The intersection of two circles on the side `sign` of c1 -> c2 (left for +1)."""
    d = c2 - c1
    dd = mp.sqrt(d[0] ** 2 + d[1] ** 2)
    a = (r1 ** 2 - r2 ** 2 + dd ** 2) / (2 * dd)
    h = mp.sqrt(r1 ** 2 - a ** 2)
    return c1 + (a * d + sign * h * mp.matrix([-d[1], d[0]])) / dd


def linear_solve(residual, n):
    """Solve residual(x) = 0, linear in x (n unknowns), at the working precision."""
    zero = mp.matrix(n, 1)
    r0 = residual(zero)
    A = mp.matrix(n, n)
    for j in range(n):
        ej = mp.matrix(n, 1)
        ej[j] = 1
        rj = residual(ej)
        for i in range(n):
            A[i, j] = rj[i] - r0[i]
    return mp.lu_solve(A, -r0)


def acc(f):
    """Second time derivative at t = 0 of each component of a position function f(t)."""
    return mp.matrix([mp.diff(lambda t: f(t)[k], 0, 2) for k in range(2)])


def angular(f):
    return mp.diff(f, 0, 2)


def number(m, v):
    """A field of `m` as an exact mpf: a number, or the value of the parameter it names."""
    return mp.mpf(m.parameter(v) if isinstance(v, str) else v)


def vector(m, pair):
    return mp.matrix([number(m, v) for v in pair])


def close(pose, ref, forces, torques):
    """Every force within REL of the largest force, every torque within REL of the largest torque."""
    for group in (forces, torques):
        big = max(abs(ref[k]) for k in group)
        for k in group:
            assert abs(pose[k] - float(ref[k])) <= REL * big, (k, pose[k], float(ref[k]))


# --- a four-bar (issue 14's example) ---

THETA, RATE = 0.7, 2.0


def fourbar(x0, s):
    """The issue's four-bar at A = (x0, 0), scaled by s; every number that changes with x0 or
    s is a parameter, so all cases share one compiled model."""
    values = dict(ax=x0, dx=x0 + 4 * s, l1=s, l2=3.5 * s, l3=3 * s, j1=0.3 * s * s,
                  j2=2.0 * s * s, j3=s * s, gy=-9.81 * s, fx=3.0 * s, fy=-5.0 * s)
    return Mechanism(parameters=values, ground={"A": ("ax", 0.0), "D": ("dx", 0.0)},
                     links=[Link.bar("crank", "A", "B", "l1", mass=2.0, inertia="j1"),
                            Link.bar("coupler", "B", "C", "l2", mass=1.5, inertia="j2"),
                            Link.bar("rocker", "D", "C", "l3", mass=1.0, inertia="j3")],
                     inputs=[Input.angle("crank")], guess={"C": (x0 + 3.6 * s, 2.9 * s)},
                     gravity=(0.0, "gy"), loads=[Load.force("C", ("fx", "fy"))])


FB_FORCES = [f"reaction({p}, {b}).{c}" for p, b in
             (("A", "crank"), ("B", "crank"), ("B", "coupler"), ("C", "coupler"), ("C", "rocker"),
              ("D", "rocker"), ("A", "ground"), ("D", "ground")) for c in "xy"]


def fourbar_reference(m, sign, l2=None, dx=None):
    """Newton-Euler of the four-bar `m` (moments about the origin) at 50 digits, or more inside
    mp.diff; l2 and dx replace the coupler's length and D.x."""
    with mp.workdps(max(DPS, mp.mp.dps)):
        g = dict(m.ground)
        A, D = vector(m, g["A"]), vector(m, g["D"])
        D[0] = D[0] if dx is None else dx
        l1, l3 = number(m, "l1"), number(m, "l3")
        l2 = number(m, "l2") if l2 is None else l2
        (m1, j1), (m2, j2), (m3, j3) = ((number(m, lk.inertial.mass), number(m, lk.inertial.inertia))
                                        for lk in m.links)
        grav, load = vector(m, m.gravity), vector(m, m.loads[0].value)

        def pos(t):
            B = A + l1 * e(THETA + RATE * t)
            C = circles(B, l2, D, l3, sign)
            return B, C

        B, C = pos(0)
        G1, G2, G3 = (A + B) / 2, (B + C) / 2, (D + C) / 2
        a1 = acc(lambda t: (A + pos(t)[0]) / 2)
        a2 = acc(lambda t: (pos(t)[0] + pos(t)[1]) / 2)
        a3 = acc(lambda t: (D + pos(t)[1]) / 2)
        al2 = angular(lambda t: mp.atan2(*(pos(t)[1] - pos(t)[0])[::-1]))
        al3 = angular(lambda t: mp.atan2(*(pos(t)[1] - D)[::-1]))
        w1, w2, w3 = m1 * (grav - a1), m2 * (grav - a2), m3 * (grav - a3)  # weight + inertia

        # unknowns: FA on crank from ground, FB on coupler from crank, FC on rocker from
        # coupler, FD on rocker from ground, T the motor's torque on the crank (no crank
        # acceleration: its J alpha is 0)
        def residual(x):
            FA, FB, FC, FD = (mp.matrix([x[2 * k], x[2 * k + 1]]) for k in range(4))
            T = x[8]
            crank = list(FA - FB + w1) + [cross(A, FA) - cross(B, FB) + cross(G1, w1) + T]
            coupler = list(FB - FC + load + w2) + [cross(B, FB) - cross(C, FC) + cross(C, load)
                                                   + cross(G2, w2) - j2 * al2]
            rocker = list(FC + FD + w3) + [cross(C, FC) + cross(D, FD) + cross(G3, w3) - j3 * al3]
            return mp.matrix(crank + coupler + rocker)

        x = linear_solve(residual, 9)
        FA, FB, FC, FD = ((x[2 * k], x[2 * k + 1]) for k in range(4))
        ref = {}
        for (p, b), f in {("A", "crank"): FA, ("B", "crank"): (-FB[0], -FB[1]),
                          ("B", "coupler"): FB, ("C", "coupler"): (-FC[0], -FC[1]),
                          ("C", "rocker"): FC, ("D", "rocker"): FD,
                          ("A", "ground"): (-FA[0], -FA[1]), ("D", "ground"): (-FD[0], -FD[1])}.items():
            ref[f"reaction({p}, {b}).x"], ref[f"reaction({p}, {b}).y"] = f
        ref["effort(crank.angle)"] = x[8]
        ref["C.x"], ref["C.y"] = C
        return ref


def solve_fourbar(x0, s, extra=()):
    m = fourbar(x0, s)
    names = FB_FORCES + ["effort(crank.angle)", "C.x", "C.y"] + list(extra)
    pose = kincas.solve(m, {"crank.angle": THETA}, rates=RATE, report=names)
    return m, pose


@pytest.mark.parametrize("s", SCALES)
@pytest.mark.parametrize("k", OFFSETS)
def test_fourbar_reactions_far_and_at_any_scale(k, s):
    m, pose = solve_fourbar(k * s, s)
    ref = fourbar_reference(m, +1)  # the branch of the guess: C left of B -> D
    # the same pose, to the rounding of coordinates at this offset
    assert abs(pose["C.x"] - float(ref["C.x"])) < 1e-12 * (k + 1) * s
    assert abs(pose["C.y"] - float(ref["C.y"])) < 1e-12 * (k + 1) * s
    close(pose, ref, FB_FORCES, ["effort(crank.angle)"])


def test_fourbar_example_of_the_issue():
    # issue 14 quotes reaction(A, crank) = (-10.8027, 18.5353) at the origin, and (2258.9,
    # 7332.4) 1e5 away: the same pose, shifted, carries the same forces
    m, near = solve_fourbar(0.0, 1.0)
    _, far = solve_fourbar(1e5, 1.0)
    ref = fourbar_reference(m, +1)
    assert abs(float(ref["reaction(A, crank).x"]) + 10.8027) < 1e-4
    assert abs(float(ref["reaction(A, crank).y"]) - 18.5353) < 1e-4
    for k in FB_FORCES:
        assert abs(far[k] - near[k]) <= REL * 30


@pytest.mark.parametrize("k, s", [(1e4, 1.0), (1e6, 1e-6), (1e6, 1e6)])
def test_reaction_sensitivities_far_and_at_any_scale(k, s):
    # d(reaction)/d(p) differentiates the same scaled solve: against mp.diff of the reference;
    # moving A and D together moves the whole mechanism, which changes no force
    m = fourbar(k * s, s)
    names = ["reaction(A, crank).x", "reaction(C, rocker).y", "effort(crank.angle)"]
    rep = [f"d({q})/d({p})" for q in names for p in ("ax", "dx", "l2")]
    pose = kincas.solve(m, {"crank.angle": THETA}, rates=RATE, report=rep)
    with mp.workdps(DPS):
        ref = {(q, p): mp.diff(lambda v: fourbar_reference(m, +1, **{p: v})[q], number(m, p))
               for q in names for p in ("l2", "dx")}
    for q in names:
        big = max(abs(ref[q, "l2"]), abs(ref[q, "dx"]))  # force per length (torque: force)
        for p in ("l2", "dx"):
            assert abs(pose[f"d({q})/d({p})"] - float(ref[q, p])) <= REL * big, (q, p)
        assert abs(pose[f"d({q})/d(ax)"] + pose[f"d({q})/d(dx)"]) <= REL * big, q


# --- a slider-crank: the reactions of its slides ---

R, LR, M1, J1, M2, J2, M3, JB = 0.08, 0.3, 1.2, 2e-3, 0.9, 7e-3, 0.6, 1e-4
PLOAD, W, ACC = (-400.0, 35.0), 150.0, 40.0


def slider_crank(x0, s):
    """A slider-crank at A = (x0, -x0/3), its block held by two slides (P and Q) along the
    horizontal through A."""
    y0 = -x0 / 3
    values = dict(ax=x0, ay=y0, r=R * s, l=LR * s, q=0.05 * s, cg=0.02 * s, j1=J1 * s * s,
                  j2=J2 * s * s, j3=JB * s * s, gy=-9.81 * s, fx=PLOAD[0] * s, fy=PLOAD[1] * s)
    return Mechanism(parameters=values, ground={"A": ("ax", "ay")},
                     links=[Link.bar("crank", "A", "B", "r", mass=M1, inertia="j1"),
                            Link("block", {"P": (0.0, 0.0), "Q": ("q", 0.0)}, mass=M3,
                                 inertia="j3", cg=("cg", 0.0)),
                            Link.bar("rod", "B", "P", "l", mass=M2, inertia="j2")],
                     slides=[Slide("P", "ground", through=("ax", "ay"), name="guide"),
                             Slide("Q", "ground", through=("ax", "ay"), name="guide2")],
                     inputs=[Input.angle("crank")],
                     guess={"P": (x0 + 0.38 * s, y0), "Q": (x0 + 0.43 * s, y0)},
                     gravity=(0.0, "gy"), loads=[Load.force("P", ("fx", "fy"))])


SC_FORCES = [f"reaction({p}, {b}).{c}" for p, b in
             (("A", "crank"), ("B", "crank"), ("B", "rod"), ("P", "block"), ("P", "rod"),
              ("A", "ground")) for c in "xy"] + [f"reaction({g}).{c}" for g in ("guide", "guide2")
                                                  for c in "xy"]


def slider_crank_reference(m, th0):
    with mp.workdps(max(DPS, mp.mp.dps)):
        A = vector(m, dict(m.ground)["A"])
        r, l, q, cg = (number(m, k) for k in ("r", "l", "q", "cg"))
        (m1, j1), (m3, j3), (m2, j2) = ((number(m, lk.inertial.mass), number(m, lk.inertial.inertia))
                                        for lk in m.links)
        grav, load = vector(m, m.gravity), vector(m, m.loads[0].value)
        th = lambda t: th0 + W * t + ACC * t ** 2 / 2

        def pos(t):
            B = A + r * e(th(t))
            P = A + mp.matrix([B[0] - A[0] + mp.sqrt(l ** 2 - (B[1] - A[1]) ** 2), 0])
            return B, P

        B, P = pos(0)
        Q = P + mp.matrix([q, 0])
        G1, G2, G3 = (A + B) / 2, (B + P) / 2, P + mp.matrix([cg, 0])
        a1 = acc(lambda t: (A + pos(t)[0]) / 2)
        a2 = acc(lambda t: (pos(t)[0] + pos(t)[1]) / 2)
        a3 = acc(lambda t: pos(t)[1])
        al2 = angular(lambda t: mp.atan2(*(pos(t)[1] - pos(t)[0])[::-1]))
        w1, w2, w3 = m1 * (grav - a1), m2 * (grav - a2), m3 * (grav - a3)
        up = mp.matrix([0, 1])

        # unknowns: FA on crank from ground, FB on rod from crank, FP on rod from block,
        # N1, N2 the guides' normal forces on the block (at P and Q), T on the crank; the
        # load and the slide at P act on the block, the first body declared with P
        def residual(x):
            FA, FB, FP = (mp.matrix([x[2 * k], x[2 * k + 1]]) for k in range(3))
            n1, n2, T = x[6] * up, x[7] * up, x[8]
            cr = list(FA - FB + w1) + [cross(A, FA) - cross(B, FB) + cross(G1, w1) + T - j1 * ACC]
            ro = list(FB + FP + w2) + [cross(B, FB) + cross(P, FP) + cross(G2, w2) - j2 * al2]
            bl = list(-FP + n1 + n2 + load + w3) + [-cross(P, FP) + cross(P, n1) + cross(Q, n2)
                                                   + cross(P, load) + cross(G3, w3)]
            return mp.matrix(cr + ro + bl)

        x = linear_solve(residual, 9)
        FA, FB, FP = ((x[2 * k], x[2 * k + 1]) for k in range(3))
        ref = {}
        for key, f in {("A", "crank"): FA, ("B", "crank"): (-FB[0], -FB[1]), ("B", "rod"): FB,
                       ("P", "block"): (-FP[0], -FP[1]), ("P", "rod"): FP,
                       ("A", "ground"): (-FA[0], -FA[1]), ("guide",): (0, x[6]),
                       ("guide2",): (0, x[7])}.items():
            name = f"reaction({', '.join(key)})"
            ref[name + ".x"], ref[name + ".y"] = f
        ref["effort(crank.angle)"] = x[8]
        return ref


@pytest.mark.parametrize("s", SCALES)
@pytest.mark.parametrize("k", (0.0, 1e4, 1e6))
def test_slider_crank_slide_reactions_far_and_at_any_scale(k, s):
    m = slider_crank(k * s, s)
    th0 = 1.1
    pose = kincas.solve(m, {"crank.angle": th0}, rates=W, accelerations=ACC,
                        report=SC_FORCES + ["effort(crank.angle)"])
    close(pose, slider_crank_reference(m, th0), SC_FORCES, ["effort(crank.angle)"])


# --- a slotted lever: a slide along a moving link, whose point is not the link's ---


def slotted(x0, s):
    values = dict(ax=x0, ay=x0 / 7, oy=x0 / 7 - 0.5 * s, r=0.2 * s, le=0.9 * s, j1=1e-3 * s * s,
                  j2=0.1 * s * s, gy=-9.81 * s, fx=5.0 * s, fy=-20.0 * s, tau=3.0 * s * s)
    return Mechanism(parameters=values, ground={"A": ("ax", "ay"), "O": ("ax", "oy")},
                     links=[Link.bar("crank", "A", "B", "r", mass=0.5, inertia="j1"),
                            Link("lever", {"O": (0.0, 0.0), "E": ("le", 0.0)}, mass=2.0, inertia="j2")],
                     slides=[Slide("B", "lever", name="slot")], inputs=[Input.angle("crank")],
                     guess={"E": (x0 + 0.3 * s, x0 / 7 + 0.3 * s)}, gravity=(0.0, "gy"),
                     loads=[Load.force("E", ("fx", "fy")), Load.torque("lever", "tau")])


SL_FORCES = [f"reaction({p}, {b}).{c}" for p, b in (("A", "crank"), ("O", "lever")) for c in "xy"] \
    + ["reaction(slot).x", "reaction(slot).y"]


def slotted_reference(m, th0, w, al):
    with mp.workdps(DPS):
        g = dict(m.ground)
        A, O = vector(m, g["A"]), vector(m, g["O"])
        r, le, j1, j2, tau = (number(m, k) for k in ("r", "le", "j1", "j2", "tau"))
        grav, load = vector(m, m.gravity), vector(m, m.loads[0].value)
        B_ = lambda t: A + r * e(th0 + w * t + al * t ** 2 / 2)
        phi = lambda t: mp.atan2(*(B_(t) - O)[::-1])
        B, ph = B_(0), phi(0)
        E, n = O + le * e(ph), mp.matrix([-mp.sin(ph), mp.cos(ph)])
        G1, G2 = (A + B) / 2, O + le / 2 * e(ph)
        w1 = mp.mpf(0.5) * (grav - acc(lambda t: (A + B_(t)) / 2))
        w2 = 2 * (grav - acc(lambda t: O + le / 2 * e(phi(t))))
        al2 = angular(phi)

        # unknowns: FA on crank from ground, FO on lever from ground, N the slot's normal
        # force on the crank at B (the lever takes -N n there), T the motor's torque
        def residual(x):
            FA, FO, N, T = mp.matrix([x[0], x[1]]), mp.matrix([x[2], x[3]]), x[4] * n, x[5]
            crank = list(FA + N + w1) + [cross(A, FA) + cross(B, N) + cross(G1, w1) + T - j1 * al]
            lever = list(FO - N + load + w2) + [cross(O, FO) - cross(B, N) + cross(E, load) + tau
                                                + cross(G2, w2) - j2 * al2]
            return mp.matrix(crank + lever)

        x = linear_solve(residual, 6)
        return {"reaction(A, crank).x": x[0], "reaction(A, crank).y": x[1],
                "reaction(O, lever).x": x[2], "reaction(O, lever).y": x[3],
                "reaction(slot).x": x[4] * n[0], "reaction(slot).y": x[4] * n[1],
                "effort(crank.angle)": x[5]}


@pytest.mark.parametrize("k, s", [(0.0, 1.0), (1e6, 1e-6), (1e6, 1.0), (1e4, 1e6)])
def test_slotted_lever_reactions_far_and_at_any_scale(k, s):
    m, th0 = slotted(k * s, s), 2.0
    pose = kincas.solve(m, {"crank.angle": th0}, rates=6.0, accelerations=1.5,
                        report=SL_FORCES + ["effort(crank.angle)"])
    close(pose, slotted_reference(m, th0, 6.0, 1.5), SL_FORCES, ["effort(crank.angle)"])
