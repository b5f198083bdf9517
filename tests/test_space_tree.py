"""The spatial model's tree reduction (kincas/model/space_tree.py, docs/spatial.md): a body hung
on a revolute of a placed body has the joint's angle as its one unknown (none where an input
drives it). Counts as the mechanisms say; a planar four-bar drawn in a tilted plane (no axis
a coordinate axis), far from the origin and tiny, against its closed form through three
crank turns, with its rates and its effort (Lagrange's equation from the closed form); the
compiled pass and the careful path pose by pose; a driven chain hung the other way round."""
import math

import numpy as np
import pytest

import kincas
from kincas import Body, Input, Joint, SpatialMechanism
from test_space import bennett, rssr, spherical, wrap

A2, D2, LA, LB, LC = np.array([0.0, 0.0]), np.array([4.0, 0.0]), 1.0, 3.5, 3.0  # a crank-rocker


def rot(a, t):
    a = np.asarray(a, float) / np.linalg.norm(a)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(t) * K + (1 - math.cos(t)) * K @ K


TILT = rot((1.0, 2.0, 2.0), 0.7)  # the four-bar's plane: normal TILT z, not a coordinate axis


def planar(u):
    """B and C of the crank-rocker at crank angle u (the branch drawn: C above B D at u = 0),
    by hand: C on the circles about B (LB) and D (LC)."""
    u = np.asarray(u, float)
    B = np.stack([LA * np.cos(u), LA * np.sin(u)], -1)
    d = D2 - B
    L = np.linalg.norm(d, axis=-1, keepdims=True)
    x = (L ** 2 + LB ** 2 - LC ** 2) / (2 * L)
    h = np.sqrt(LB ** 2 - x ** 2)
    e = d / L
    C = B + x * e + h * np.stack([-e[..., 1], e[..., 0]], -1)
    return B, C


def lift(xy, scale, offset):
    xy = np.atleast_2d(xy)
    return np.asarray(offset, float) + scale * (np.c_[xy, np.zeros(len(xy))] @ TILT.T)


def fourbar(scale=1.0, offset=(0.0, 0.0, 0.0), flip=False, masses=False, gravity=(0.0, 0.0, 0.0)):
    B0, C0 = (v[0] for v in planar([0.0]))
    P = lambda xy: tuple(float(c) for c in lift(xy, scale, offset)[0])
    n = tuple(TILT[:, 2])
    mass = lambda k, cg: dict(mass=k, cg=P(cg), inertia=0.7 * k * scale ** 2) if masses else {}
    return SpatialMechanism(
        ground={"A": P(A2), "D": P(D2)},
        bodies=[Body("crank", {"A": P(A2), "B": P(B0)}, **mass(1.5, B0)),
                Body("coupler", {"B": P(B0), "C": P(C0)}, **mass(2.0, (B0 + C0) / 2)),
                Body("rocker", {"D": P(D2), "C": P(C0)}, **mass(0.8, C0))],
        # D before C: the rocker hangs on the ground (the first joint in declaration order)
        joints=[Joint("revolute", "A", axis=n), Joint("revolute", "D", axis=n),
                Joint("revolute", "B", axis=n, bodies=("coupler", "crank") if flip else ("crank", "coupler")),
                Joint("revolute", "C", axis=n)],
        inputs=[Input.joint("A")], gravity=gravity)


def closed_angles(u):
    """Joint angles by hand: the crank's u, the coupler's turn relative to the crank (B), the
    rocker's (D), the rocker's relative to the coupler (C), each less its drawn value."""
    B, C = planar(u)
    phc = np.arctan2(*(C - B)[..., ::-1].T)
    phr = np.arctan2(*(C - D2)[..., ::-1].T)
    (Bd, Cd) = planar(np.zeros(1))
    phc0, phr0 = np.arctan2(*(Cd - Bd)[0, ::-1]), np.arctan2(*(Cd - D2)[0, ::-1])
    return {"B.angle": (phc - u) - phc0, "D.angle": phr - phr0, "C.angle": (phr - phc) - (phr0 - phc0),
            "coupler": phc}


def test_unknowns_and_equations_after_the_reduction():
    counts = lambda m: (kincas.model_of(m).unknown_names, kincas.model_of(m).sym.ng, m.redundant)
    # RSSR: the crank on its driven revolute (no unknown), the rocker on its own (its angle),
    # the bar B C the one equation
    assert counts(rssr()) == (["D.angle"], 1, 0)
    # a loop of four revolutes: two hung angles, the closing joint's point (3) and axis (2)
    assert counts(spherical()) == (["B.angle", "J4.angle"], 5, 3)
    assert counts(bennett()) == (["O2.angle", "O3.angle"], 5, 3)
    assert counts(fourbar()) == (["B.angle", "D.angle"], 5, 3)  # planar in space: 3 redundant
    from kincas.cli.scene import load
    from conftest import EXAMPLES
    m = load(EXAMPLES / "space_double_cardan.toml").mechanism
    # the shafts hang on their revolutes; the middle shaft on the input's cross at O1 (a ball:
    # its rotation only): its norm, the point O2, the two crosses; one redundant
    assert counts(m) == (["out.angle"] + [f"mid.{c}" for c in ("qw", "qx", "qy", "qz")], 1 + 3 + 1 + 1, 1)
    # the suspension: the wishbones on their revolutes (the lower one driven), the upright on
    # the lower's ball LB: the upper's ball UB (3) and the tie rod (1) close it, with the norm
    m = load(EXAMPLES / "space_suspension.toml").mechanism
    assert counts(m) == (["UA.angle"] + [f"upright.{c}" for c in ("qw", "qx", "qy", "qz")], 3 + 1 + 1, 0)
    from kincas.model.mobility import solved_unknowns
    for f in sorted(EXAMPLES.glob("space_*.toml")):  # the declarations' count is the model's
        m = load(f).mechanism
        assert solved_unknowns(m) == kincas.model_of(m).nq, f.name


@pytest.mark.parametrize("scale, offset", [(1.0, (1e6, -2e6, 3e5)), (1e-6, (3e-6, 1e-6, -2e-6))])
def test_tilted_four_bar_far_and_tiny_through_three_turns_fast_and_careful(scale, offset):
    m = fourbar(scale, offset)
    u = np.linspace(0, 6 * np.pi, 217)
    report = ["A.angle", "B.angle", "C.angle", "D.angle", "C.x", "C.y", "C.z", "B.x", "B.y", "B.z",
              "coupler.R11", "coupler.R12", "coupler.R13", "coupler.R21", "coupler.R22", "coupler.R23",
              "coupler.R31", "coupler.R32", "coupler.R33"]
    fast = kincas.sweep(m, {"A.angle": u}, report=report)
    careful = kincas.sweep(m, {"A.angle": u}, report=report, method="careful")
    assert fast.info["fast pass"] is not None and fast.ok.all() and careful.ok.all()
    for name in report:  # pose by pose
        tol = 1e-12 * scale * 1e3 if name[2:] in ("x", "y", "z") else 1e-11
        assert np.abs(wrap(fast[name] - careful[name])).max() < tol, name
    want = closed_angles(u)
    for sw in (fast, careful):
        assert np.abs(sw["A.angle"] - wrap(u)).max() < 1e-12 and (np.abs(sw["A.angle"]) <= np.pi).all()
        for j in ("B.angle", "C.angle", "D.angle"):  # wrapped in (-pi, pi]
            assert np.abs(wrap(sw[j] - want[j])).max() < 1e-10, j
            assert (np.abs(sw[j]) <= np.pi).all()
        B, C = planar(u)
        for P, W in (("B", lift(B, scale, offset)), ("C", lift(C, scale, offset))):
            got = np.stack([sw[f"{P}.x"], sw[f"{P}.y"], sw[f"{P}.z"]], 1)
            assert np.abs(got - W).max() < 1e-9 * max(scale, np.abs(offset).max() * 1e-6), P
        # the coupler's rotation: TILT Rot(z, coupler - drawn) TILT', continuous through the turns
        R = np.stack([sw[f"coupler.R{i}{k}"] for i in (1, 2, 3) for k in (1, 2, 3)], 1).reshape(-1, 3, 3)
        Rz = np.array([rot((0, 0, 1), t - want["coupler"][0]) for t in want["coupler"]])
        assert np.abs(R - TILT @ Rz @ TILT.T).max() < 1e-10  # 1e6 away: the drawing rounded at 1e-10
        assert np.abs(np.diff(R, axis=0)).max() < 0.2
    # the unknown B.angle is continuous: a whole turn backwards each crank turn, unwrapped
    k = kincas.model_of(m).unknown_names.index("B.angle")
    unwrapped = want["coupler"] - u - want["coupler"][0]  # the coupler only rocks: no wrap
    for sw in (fast, careful):
        assert np.abs(sw.q[:, k] - unwrapped).max() < 1e-10
    assert abs(unwrapped[-1] + 6 * np.pi) < 1e-12


def test_the_joint_angle_keeps_its_sign_when_the_parent_is_the_second_body():
    u = np.linspace(0.2, 5.9, 13)
    want = closed_angles(u)["B.angle"]
    a = kincas.sweep(fourbar(), {"A.angle": u}, report=["B.angle", "C.x"])
    b = kincas.sweep(fourbar(flip=True), {"A.angle": u}, report=["B.angle", "C.x"])
    assert np.abs(wrap(a["B.angle"] - want)).max() < 1e-11
    assert np.abs(wrap(b["B.angle"] + want)).max() < 1e-11  # the crank's turn relative to the coupler
    assert np.abs(a["C.x"] - b["C.x"]).max() < 1e-12


def test_four_bar_rates_against_central_differences_of_its_closed_form():
    m, u, h, w, al = fourbar(), np.array([0.3, 1.9, 4.4]), 1e-5, 1.3, -0.7
    sw = kincas.sweep(m, {"A.angle": u}, rates={"A.angle": w}, accelerations={"A.angle": al},
                      report=["C.vx", "C.vy", "C.vz", "C.ax", "C.ay", "C.az", "B.omega", "D.omega", "D.alpha",
                              "coupler.omega_x", "coupler.omega_z"])
    C = lambda t: lift(planar(t)[1], 1.0, (0, 0, 0))
    d1, d2 = (C(u + h) - C(u - h)) / (2 * h), (C(u + h) - 2 * C(u) + C(u - h)) / h ** 2
    v, acc = d1 * w, d2 * w ** 2 + d1 * al
    assert np.abs(np.stack([sw["C.vx"], sw["C.vy"], sw["C.vz"]], 1) - v).max() < 1e-7
    assert np.abs(np.stack([sw["C.ax"], sw["C.ay"], sw["C.az"]], 1) - acc).max() < 1e-4
    ang = lambda t, k: closed_angles(t)[k]
    for j, k in (("B.omega", "B.angle"), ("D.omega", "D.angle")):
        assert np.abs(sw[j] - w * (ang(u + h, k) - ang(u - h, k)) / (2 * h)).max() < 1e-7, j
    dd = (ang(u + h, "D.angle") - 2 * ang(u, "D.angle") + ang(u - h, "D.angle")) / h ** 2
    dD = (ang(u + h, "D.angle") - ang(u - h, "D.angle")) / (2 * h)
    assert np.abs(sw["D.alpha"] - (dd * w ** 2 + dD * al)).max() < 1e-4
    wc = w * (ang(u + h, "coupler") - ang(u - h, "coupler")) / (2 * h)  # about the plane's normal
    assert np.abs(sw["coupler.omega_x"] - wc * TILT[0, 2]).max() < 1e-7
    assert np.abs(sw["coupler.omega_z"] - wc * TILT[2, 2]).max() < 1e-7


def test_four_bar_effort_is_lagranges_equation_of_its_closed_form():
    # one coordinate u: T = M(u) w^2 / 2, M = sum m |dG/du|^2 + I (dphi/du)^2 (inertia 0.7 m
    # about every axis, each body turning about the plane's normal), V = -sum m g.G; the
    # effort is M al + M'(u) w^2 / 2 + V'(u), every derivative by central differences
    g = np.array([0.5, -2.0, -9.81])
    m = fourbar(masses=True, gravity=tuple(g))
    u, w, al, h = np.array([0.4, 2.2, 5.0]), 1.6, -0.9, 1e-4
    sw = kincas.sweep(m, {"A.angle": u}, rates={"A.angle": w}, accelerations={"A.angle": al},
                      report=["effort(A.angle)"])

    def parts(t):
        B, C = planar(t)
        G = [(1.5, lift(B, 1, (0, 0, 0))), (2.0, lift((B + C) / 2, 1, (0, 0, 0))), (0.8, lift(C, 1, (0, 0, 0)))]
        a = closed_angles(t)
        phi = [t, a["coupler"], a["D.angle"]]
        return G, phi

    def M(t):
        (G1, phi1), (G0, phi0) = parts(t + h), parts(t - h)
        out = 0.0
        for (mass, P1), (_, P0), f1, f0 in zip(G1, G0, phi1, phi0):
            out = out + mass * (((P1 - P0) / (2 * h)) ** 2).sum(1) + 0.7 * mass * ((f1 - f0) / (2 * h)) ** 2
        return out

    V = lambda t: -sum(mass * (P @ g) for mass, P in parts(t)[0])
    want = M(u) * al + (M(u + h) - M(u - h)) / (2 * h) * w ** 2 / 2 + (V(u + h) - V(u - h)) / (2 * h)
    assert np.allclose(sw["effort(A.angle)"], want, rtol=1e-5, atol=1e-5 * np.abs(want).max())


def test_a_driven_chain_hung_the_other_way_round_has_no_unknown():
    # an arm on a tilted ground axis through a far point, a link on the arm whose joint names
    # the link first: the link's rotation relative to the arm is Rot(a2, -u2)
    O, a1, a2 = np.array([1e6, -3e5, 2e5]), np.array([0.2, -0.4, 0.9]), np.array([0.6, 0.7, -0.1])
    a1, a2 = a1 / np.linalg.norm(a1), a2 / np.linalg.norm(a2)
    K, P = O + np.array([0.8, 0.3, -0.2]), O + np.array([1.1, 0.9, 0.4])
    t = lambda v: tuple(float(c) for c in v)
    m = SpatialMechanism(ground={"O": t(O)},
                         bodies=[Body("arm", {"O": t(O), "K": t(K)}), Body("link", {"K": t(K), "P": t(P)})],
                         joints=[Joint("revolute", "O", axis=t(a1)),
                                 Joint("revolute", "K", axis=t(a2), bodies=("link", "arm"))],
                         inputs=[Input.joint("O"), Input.joint("K")])
    assert kincas.model_of(m).nq == 0 and kincas.model_of(m).sym.ng == 0
    U = np.array([[0.3, -1.2], [2.9, 4.0], [-2.0, 0.5]])
    sw = kincas.sweep(m, {"O.angle": U[:, 0], "K.angle": U[:, 1]}, report=["P.x", "P.y", "P.z", "K.angle"])
    for k, (u1, u2) in enumerate(U):
        R1 = rot(a1, u1)
        want = O + R1 @ (K - O) + R1 @ rot(a2, -u2) @ (P - K)
        got = np.array([sw["P.x"][k], sw["P.y"][k], sw["P.z"][k]])
        assert np.abs(got - want).max() < 1e-9  # 1e6 from the origin: rounding 1e-10
    assert np.abs(sw["K.angle"] - wrap(U[:, 1])).max() < 1e-12


def test_slider_crank_hangs_its_slider_on_the_prismatic_joint():
    # the slider's one unknown is its slide s; the rod the one equation:
    # |C0 + s d - B(u)|^2 = L^2, s = -d.(C0 - B) + sqrt((d.(C0 - B))^2 - |C0 - B|^2 + L^2) (s = 0 drawn)
    from kincas.cli.scene import load
    from conftest import EXAMPLES
    m = load(EXAMPLES / "space_slider_crank.toml").mechanism
    model = kincas.model_of(m)
    assert (model.unknown_names, model.sym.ng) == (["slide.s"], 1)
    d = np.array(m.joint("slide").axis)
    C0, L = np.array([154.4018940888198, 68.88037881776397, 68.32056822664595]), 150.0
    u = np.linspace(0, 4 * np.pi, 145)
    B = 40.0 * np.stack([np.cos(u), np.sin(u), 0 * u], 1)
    b = (C0 - B) @ d
    s = -b + np.sqrt(b ** 2 - ((C0 - B) ** 2).sum(1) + L ** 2)
    assert abs(s[0]) < 1e-9
    for method in ("fast", "careful"):
        sw = kincas.sweep(m, {"A.angle": u}, report=["slide.s", "C.x", "C.y", "C.z", "slide.v"],
                          rates={"A.angle": 1.0}, **({"method": "careful"} if method == "careful" else {}))
        assert sw.ok.all() and np.abs(sw["slide.s"] - s).max() < 1e-10, method
        C = np.stack([sw["C.x"], sw["C.y"], sw["C.z"]], 1)
        assert np.abs(C - (C0 + s[:, None] * d)).max() < 1e-10
        h = 1e-6
        Bh = lambda t: 40.0 * np.stack([np.cos(t), np.sin(t), 0 * t], 1)
        sh = lambda t: -((C0 - Bh(t)) @ d) + np.sqrt(((C0 - Bh(t)) @ d) ** 2 - ((C0 - Bh(t)) ** 2).sum(1) + L ** 2)
        assert np.abs(sw["slide.v"] - (sh(u + h) - sh(u - h)) / (2 * h)).max() < 1e-6


def test_a_revolute_whose_point_the_ground_lacks_is_not_hung_on():
    # a single Cardan joint whose output revolute names the ground although the ground has no
    # point Q (it holds the output shaft's axis only, tests/test_space_acceptance.py): the
    # output shaft is not hung on it but on the cross's ball K: its quaternion and norm, the
    # revolute's axis (2) and the cross (1); the input shaft on its revolute A
    m = SpatialMechanism(
        ground={"A": (0, 0, 0)},
        bodies=[Body("s1", {"A": (0, 0, 0), "K": (0, 0, 0), "P": (-100, 0, 0)}),
                Body("s2", {"K": (0, 0, 0), "Q": (86.60254037844386, 50, 0)})],
        joints=[Joint("revolute", "A", axis=(1, 0, 0), name="in"),
                Joint("universal", "K", axes=((0, 1, 0), (0, 0, 1)), name="x"),
                Joint("revolute", "Q", axis=(0.8660254037844386, 0.5, 0), bodies=("ground", "s2"), name="out")],
        inputs=[Input.joint("in")])
    model = kincas.model_of(m)
    assert model.unknown_names == ["s2.qw", "s2.qx", "s2.qy", "s2.qz"] and model.sym.ng == 4
    # Cardan: tan(out) = tan(in) / cos(beta), beta = 30 deg between the shafts
    th = np.linspace(-1.2, 1.2, 9)
    sw = kincas.sweep(m, {"in.angle": th}, report=["out.angle"])
    assert sw.ok.all()
    assert np.abs(wrap(np.tan(sw["out.angle"]) - np.tan(th) / math.cos(math.radians(30)))).max() < 1e-10
