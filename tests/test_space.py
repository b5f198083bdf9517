"""Spatial mechanisms (space = "3d") against closed forms written here: the RSSR's closure
solved by hand, the Cardan joint, a spherical four-bar and Bennett's linkage; derivatives
against central differences; residuals after every solve; the same answers at any scale."""
import math

import numpy as np
import pytest

import kincas
from kincas import Body, Input, Joint, SpatialMechanism

# --- RSSR: crank about z through A, rocker about x through D, a bar B-C between them ---

R_CRANK, R_ROCK, LC, D = 15.0, 60.0, 125.0, np.array([100.0, 40.0, 30.0])


def rssr(scale=1.0, offset=(0.0, 0.0, 0.0), lc=LC):
    o = np.asarray(offset, float)
    P = lambda v: tuple(float(c) for c in np.asarray(v, float) * scale + o)
    return SpatialMechanism(
        parameters={"lc": lc * scale},
        ground={"A": P((0, 0, 0)), "D": P(D)},
        bodies=[Body("crank", {"A": P((0, 0, 0)), "B": P((R_CRANK, 0, 0))}), Body.bar("coupler", "B", "C", "lc"),
                Body("rocker", {"D": P(D), "C": P(D + (0, 0, R_ROCK))})],
        joints=[Joint("revolute", "A", axis=(0, 0, 1)), Joint("revolute", "D", axis=(1, 0, 0))],
        inputs=[Input.joint("A")])


def rssr_closed(th, lc=LC, sign=1.0):
    """Rocker angle phi: C = D + R (0, -sin phi, cos phi) and |B - C| = lc, B = r (cos th,
    sin th, 0), is a sin(phi) + b cos(phi) = c, so phi = delta + sign acos(c / rho)."""
    bx, by = R_CRANK * np.cos(th), R_CRANK * np.sin(th)
    a = -2 * R_ROCK * (D[1] - by)
    b = 2 * R_ROCK * D[2]
    c = lc ** 2 - (D[0] - bx) ** 2 - (D[1] - by) ** 2 - D[2] ** 2 - R_ROCK ** 2
    return np.arctan2(a, b) + sign * np.arccos(c / np.hypot(a, b))


def wrap(a):
    return np.angle(np.exp(1j * np.asarray(a)))


def test_rssr_against_its_closure_solved_by_hand_through_a_full_turn():
    m = rssr()
    th = np.linspace(0, 2 * np.pi, 121)
    sw = kincas.sweep(m, {"A.angle": th}, report=["D.angle", "C.x", "C.y", "C.z", "A.angle"])
    assert sw.ok.all() and sw.residual.max() < 1e-12
    phi = sw["D.angle"]
    sign = min((1.0, -1.0), key=lambda s: abs(wrap(rssr_closed(th[0], sign=s) - phi[0])))
    assert np.abs(wrap(rssr_closed(th, sign=sign) - phi)).max() < 1e-11  # one branch all the way
    C = D + R_ROCK * np.stack([0 * phi, -np.sin(phi), np.cos(phi)], axis=1)
    got = np.stack([sw["C.x"], sw["C.y"], sw["C.z"]], axis=1)
    assert np.abs(got - C).max() < 1e-10 * LC
    assert np.abs(wrap(sw["A.angle"] - th)).max() < 1e-12


def test_rssr_rates_against_central_differences():
    m, th, h = rssr(), np.array([0.3, 1.7, 4.0]), 1e-5
    w, al = 2.0, 3.0  # crank rate and acceleration
    sw = kincas.sweep(m, {"A.angle": th}, rates={"A.angle": w}, accelerations={"A.angle": al},
                      report=["D.omega", "D.alpha", "rocker.omega_x", "rocker.alpha_x", "rocker.omega_y",
                              "C.vz", "C.az"])
    s = min((1.0, -1.0), key=lambda s: abs(wrap(rssr_closed(th[0], sign=s) - kincas.sweep(
        m, {"A.angle": th[:1]}, report=["D.angle"])["D.angle"][0])))
    f = lambda t: rssr_closed(t, sign=s)
    d1 = (f(th + h) - f(th - h)) / (2 * h)
    d2 = (f(th + h) - 2 * f(th) + f(th - h)) / h ** 2
    omega, alpha = d1 * w, d2 * w ** 2 + d1 * al
    assert np.allclose(sw["D.omega"], omega, rtol=1e-7, atol=1e-9)
    assert np.allclose(sw["rocker.omega_x"], omega, rtol=1e-7, atol=1e-9)  # about +x
    assert np.abs(sw["rocker.omega_y"]).max() < 1e-12
    assert np.allclose(sw["D.alpha"], alpha, rtol=1e-4, atol=1e-6)
    assert np.allclose(sw["rocker.alpha_x"], alpha, rtol=1e-4, atol=1e-6)
    phi = f(th)
    assert np.allclose(sw["C.vz"], -R_ROCK * np.sin(phi) * omega, rtol=1e-7, atol=1e-8)


def test_rssr_same_answers_at_any_scale_and_far_from_the_origin():
    th = np.linspace(0, 2 * np.pi, 37)
    ref = kincas.sweep(rssr(), {"A.angle": th}, report=["D.angle", "C.y", "D.omega"])
    for scale, off in ((1e-4, (0, 0, 0)), (1e4, (0, 0, 0)), (1.0, (1e6, -2e6, 3e6))):
        sw = kincas.sweep(rssr(scale, off), {"A.angle": th}, report=["D.angle", "C.y", "D.omega"])
        assert sw.ok.all() and sw.residual.max() < 1e-12
        assert np.abs(wrap(sw["D.angle"] - ref["D.angle"])).max() < 1e-9
        assert np.allclose((sw["C.y"] - off[1]) / scale, ref["C.y"], rtol=0, atol=1e-8 * LC)
        assert np.allclose(sw["D.omega"], ref["D.omega"], rtol=1e-8, atol=1e-10)


def test_rssr_sensitivity_to_the_coupler_length_against_central_differences():
    th, h = np.array([0.5, 2.5]), 1e-4
    sw = kincas.sweep(rssr(), {"A.angle": th}, report=["D.angle", "d(D.angle)/d(lc)", "d(C.z)/d(lc)"])
    up = kincas.sweep(rssr(lc=LC + h), {"A.angle": th}, report=["D.angle", "C.z"])
    dn = kincas.sweep(rssr(lc=LC - h), {"A.angle": th}, report=["D.angle", "C.z"])
    assert np.allclose(sw["d(D.angle)/d(lc)"], wrap(up["D.angle"] - dn["D.angle"]) / (2 * h), rtol=1e-6)
    assert np.allclose(sw["d(C.z)/d(lc)"], (up["C.z"] - dn["C.z"]) / (2 * h), rtol=1e-6)


# --- Cardan joint: input shaft about x, output shaft at beta in the xy plane ---


def cardan(beta):
    s = (math.cos(beta), math.sin(beta), 0.0)
    return SpatialMechanism(
        ground={"O": (0, 0, 0)},
        bodies=[Body("shaft_in", {"O": (0, 0, 0), "P": (-1, 0, 0)}),
                Body("shaft_out", {"O": (0, 0, 0), "Q": s})],
        joints=[Joint("revolute", "O", axis=(1, 0, 0), bodies=("ground", "shaft_in"), name="in"),
                Joint("revolute", "O", axis=s, bodies=("ground", "shaft_out"), name="out"),
                Joint("universal", "O", axes=((0, 1, 0), (0, 0, 1)), bodies=("shaft_in", "shaft_out"),
                      name="cross")],
        inputs=[Input.joint("in")])


def test_cardan_joint_tan_th2_is_tan_th1_over_cos_beta_with_its_velocity_ratio():
    # the input yoke's axis (y) lies in the shafts' plane at th1 = 0: a0 = (0, cos th1, sin th1),
    # a1 = (sin th2 sin b, -sin th2 cos b, cos th2), a0.a1 = 0 <=> tan th2 = tan th1 / cos b
    beta = math.radians(30)
    th = np.linspace(0, 2 * np.pi, 73)  # from the drawing pose, a full turn on its branch
    sw = kincas.sweep(cardan(beta), {"in.angle": th}, report=["out.angle", "out.omega", "out.alpha"])
    assert sw.ok.all() and sw.residual.max() < 1e-12
    th2 = np.arctan2(np.sin(th), np.cos(th) * np.cos(beta))
    assert np.abs(wrap(sw["out.angle"] - th2)).max() < 1e-12
    ratio = np.cos(beta) / (1 - np.sin(beta) ** 2 * np.cos(th) ** 2)
    assert np.allclose(sw["out.omega"], ratio, rtol=1e-10)
    dratio = -np.cos(beta) * np.sin(beta) ** 2 * 2 * np.cos(th) * np.sin(th) / (1 - np.sin(beta) ** 2 * np.cos(th) ** 2) ** 2
    assert np.allclose(sw["out.alpha"], dratio, rtol=1e-8, atol=1e-10)
    # the cross turns about the input's yoke y by angle1: the output's yoke z, seen from the
    # input shaft, is Rot(x, -th1) Rot(s, th2) z = Rot(y, angle1) z = (sin a1, 0, cos a1)
    cr = kincas.sweep(cardan(beta), {"in.angle": th[:9]}, report=["cross.angle1"])
    s_ax = np.array([math.cos(beta), math.sin(beta), 0.0])
    for k in range(9):
        v = rotate(rotate(np.array([0, 0, 1.0]), s_ax, th2[k]), np.array([1.0, 0, 0]), -th[k])
        assert abs(v[1]) < 1e-12 and abs(wrap(cr["cross.angle1"][k] - math.atan2(v[0], v[2]))) < 1e-12


# --- spherical four-bar: four revolutes whose axes meet at O ---


def unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


# a crank of 20 deg about z, an output axis 40 deg from it: the crank turns fully
B0 = np.array([math.sin(math.radians(20)), 0, math.cos(math.radians(20))])
W = np.array([math.sin(math.radians(40)), 0, math.cos(math.radians(40))])
C0 = unit((0.1116189, 0.98480775, 0.13302222))


def spherical():
    return SpatialMechanism(
        ground={"O": (0, 0, 0)},
        bodies=[Body("input", {"O": (0, 0, 0), "B": tuple(B0)}), Body("coupler", {"B": tuple(B0), "C": tuple(C0)}),
                Body("output", {"O": (0, 0, 0), "C": tuple(C0)})],
        joints=[Joint("revolute", "O", axis=(0, 0, 1), bodies=("ground", "input"), name="J1"),
                Joint("revolute", "O", axis=tuple(W), bodies=("ground", "output"), name="J4"),
                Joint("revolute", "B", axis=tuple(B0)), Joint("revolute", "C", axis=tuple(C0))],
        inputs=[Input.joint("J1")])


def rotate(v, a, t):
    return v * np.cos(t) + np.cross(a, v) * np.sin(t) + a * (a @ v) * (1 - np.cos(t))


def test_spherical_four_bar_and_its_redundant_equations():
    m = spherical()
    assert m.mobility == -2 and m.redundant == 3  # Gruebler's spatial count is wrong here
    th = np.linspace(0, 2 * np.pi, 49)
    sw = kincas.sweep(m, {"J1.angle": th}, report=["J4.angle"])
    assert sw.ok.all() and sw.residual.max() < 1e-12
    # b(th).c(phi) = b0.c0, c(phi) = Rot(W, phi) c0 = p cos phi + q sin phi + r
    for t, phi in zip(th, sw["J4.angle"]):
        b = rotate(B0, np.array([0, 0, 1.0]), t)
        assert abs(b @ rotate(C0, W, phi) - B0 @ C0) < 1e-13
    c_par, c_perp, c_ax = C0 - W * (W @ C0), np.cross(W, C0), W * (W @ C0)
    b = rotate(B0, np.array([0, 0, 1.0]), th[7])
    a_, b_, c_ = b @ c_perp, b @ c_par, B0 @ C0 - b @ c_ax  # a sin phi + b cos phi = c
    roots = np.arctan2(a_, b_) + np.array([1, -1]) * np.arccos(c_ / np.hypot(a_, b_))
    assert np.abs(wrap(roots - sw["J4.angle"][7])).min() < 1e-12


# --- Bennett's linkage: moves with one input although Gruebler's count says -2 ---


def dh(theta, a, alpha):
    """Denavit-Hartenberg: Rz(theta) Tx(a) Rx(alpha)."""
    c, s, ca_, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
    return np.array([[c, -s * ca_, s * sa, a * c], [s, c * ca_, -c * sa, a * s],
                     [0, sa, ca_, 0], [0, 0, 0, 1.0]])


A_, AL, BE = 1.0, math.radians(40), math.radians(70)
B_ = A_ * math.sin(BE) / math.sin(AL)  # Bennett's condition a / sin(alpha) = b / sin(beta)


def bennett_theta2(t1):
    """Bennett (1903): tan(th1/2) tan(th2/2) = sin((beta + alpha)/2) / sin((beta - alpha)/2)
    for adjacent joint angles (DH, links (a, alpha), (b, beta), (a, alpha), (b, beta)),
    th3 = -th1, th4 = -th2; checked below by closing the loop of DH transforms."""
    k = math.sin((BE + AL) / 2) / math.sin((BE - AL) / 2)
    return 2 * math.atan(k / math.tan(t1 / 2))


def bennett_loop(t1):
    t2 = bennett_theta2(t1)
    return [dh(t1, A_, AL), dh(t2, B_, BE), dh(-t1, A_, AL), dh(-t2, B_, BE)]


def test_bennett_relation_closes_the_dh_loop():
    for t1 in (0.4, 1.3, 2.5, -2.0):
        T = np.linalg.multi_dot(bennett_loop(t1))
        assert np.abs(T - np.eye(4)).max() < 1e-12


def bennett(t1=1.0):
    frames = [np.eye(4)]
    for T in bennett_loop(t1)[:3]:
        frames.append(frames[-1] @ T)
    O = [tuple(F[:3, 3]) for F in frames]
    z = [tuple(F[:3, 2]) for F in frames]
    return SpatialMechanism(
        ground={"O1": O[0], "O4": O[3]},
        bodies=[Body("L1", {"O1": O[0], "O2": O[1]}), Body("L2", {"O2": O[1], "O3": O[2]}),
                Body("L3", {"O3": O[2], "O4": O[3]})],
        joints=[Joint("revolute", "O1", axis=z[0]), Joint("revolute", "O2", axis=z[1]),
                Joint("revolute", "O3", axis=z[2]), Joint("revolute", "O4", axis=z[3], bodies=("L3", "ground"))],
        inputs=[Input.joint("O1")])


def test_bennett_linkage_sweeps_with_one_input_and_follows_its_relation():
    t10 = 1.0
    m = bennett(t10)
    assert m.mobility == -2 and m.redundant == 3
    u = np.linspace(0, 1.8, 19)
    sw = kincas.sweep(m, {"O1.angle": u}, report=["O2.angle", "O3.angle", "O4.angle"])
    assert sw.ok.all() and sw.residual.max() < 1e-12
    t1 = t10 + u
    want = np.array([bennett_theta2(t) for t in t1]) - bennett_theta2(t10)
    assert np.abs(wrap(sw["O2.angle"] - want)).max() < 1e-11
    assert np.abs(wrap(sw["O3.angle"] + u)).max() < 1e-11  # th3 = -th1
    assert np.abs(wrap(sw["O4.angle"] + want)).max() < 1e-11


# --- quantities and names ---


def test_quaternion_and_rotation_matrix_of_a_turned_body():
    sw = kincas.solve(rssr(), {"A.angle": 2.0}, report=[
        "crank.qw", "crank.qx", "crank.qy", "crank.qz", "crank.R11", "crank.R21", "crank.R12", "B.x", "B.y"])
    assert np.allclose([sw["crank.qw"], sw["crank.qz"]], [math.cos(1.0), math.sin(1.0)], atol=1e-13)
    assert abs(sw["crank.qx"]) < 1e-13 and abs(sw["crank.qy"]) < 1e-13
    assert np.allclose([sw["crank.R11"], sw["crank.R21"], sw["crank.R12"]],
                       [math.cos(2.0), math.sin(2.0), -math.sin(2.0)], atol=1e-13)
    assert np.allclose([sw["B.x"], sw["B.y"]], [R_CRANK * math.cos(2.0), R_CRANK * math.sin(2.0)], atol=1e-12)
    sw = kincas.solve(rssr(), {"A.angle": 4.0}, report=["crank.qw", "A.angle"])  # qw >= 0
    assert sw["crank.qw"] >= 0 and abs(sw["A.angle"] - wrap(4.0)) < 1e-12


def test_unknown_quantity_and_bad_declarations_are_named():
    with pytest.raises(kincas.ModelError, match="C.angle"):
        kincas.solve(rssr(), {"A.angle": 0.0}, report=["C.angle"])
    with pytest.raises(kincas.ModelError, match="not perpendicular"):
        Joint("universal", "O", axes=((1, 0, 0), (1, 1, 0)))
    with pytest.raises(kincas.ModelError, match="two-point bar"):
        SpatialMechanism(ground={"A": (0, 0, 0)}, bodies=[Body.bar("b", "A", "B", 1)],
                         joints=[Joint("revolute", "A", axis=(0, 0, 1), bodies=("ground", "b"))],
                         guess={"B": (1, 0, 0)})
    with pytest.raises(kincas.ModelError, match=r"\[guess\] P: missing"):
        SpatialMechanism(ground={"A": (0, 0, 0), "C": (2, 0, 0)},
                         bodies=[Body.bar("b1", "A", "P", 1), Body.bar("b2", "P", "C", 1.5)])


def test_rssr_modes_are_the_two_roots_of_its_closure_and_its_range_a_full_turn():
    modes = kincas.find_modes(rssr(), {"A.angle": 0.7}, starts=64)
    got = sorted(md.angles["D.angle"] for md in modes)
    want = sorted(wrap(rssr_closed(0.7, sign=s)) for s in (1.0, -1.0))
    assert len(got) == 2 and np.allclose(got, want, atol=1e-10)
    assert sum(md.from_guess for md in modes) == 1
    r = kincas.input_range(rssr(), {"A.angle": 0.7})
    assert r.full_turn


def test_designs_of_a_spatial_mechanism_match_their_own_sweeps():
    th = np.linspace(0, 6, 7)
    r = kincas.sweep_designs(rssr(), {"lc": [120.0, 130.0]}, {"A.angle": th}, report=["D.angle"])
    for k, lc in enumerate((120.0, 130.0)):
        want = kincas.sweep(rssr(lc=lc), {"A.angle": th}, report=["D.angle"])["D.angle"]
        assert np.allclose(r.values["D.angle"][k], want, atol=1e-11)


def rotz(t):
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


def test_cylindrical_and_planar_joints_move_as_their_coordinates_say():
    P0, X0 = np.array([2.0, 1.0, 0.5]), np.array([1.0, 0.0, 0.0])
    cyl = SpatialMechanism(bodies=[Body("sleeve", {"X": tuple(X0), "P": tuple(P0)})],
                           joints=[Joint("cylindrical", "X", axis=(0, 0, 1), name="c")],
                           inputs=[Input.joint("c.angle"), Input.joint("c.s")])
    th, s = np.array([0.3, 2.0, -2.9]), np.array([0.5, -1.0, 2.0])
    sw = kincas.sweep(cyl, {"c.angle": th, "c.s": s}, report=["P.x", "P.y", "P.z", "c.angle", "c.s", "sleeve.omega_z"])
    assert sw.ok.all() and sw.residual.max() < 1e-12
    for k in range(3):
        want = X0 + rotz(th[k]) @ (P0 - X0) + s[k] * np.array([0, 0, 1.0])
        assert np.allclose([sw["P.x"][k], sw["P.y"][k], sw["P.z"][k]], want, atol=1e-12)
    assert np.allclose(sw["c.angle"], th, atol=1e-12) and np.allclose(sw["c.s"], s, atol=1e-12)
    assert np.allclose(sw["sleeve.omega_z"], 1.0)  # rate 1 of the angle input
    pla = SpatialMechanism(bodies=[Body("puck", {"X": tuple(X0), "P": tuple(P0)})],
                           joints=[Joint("planar", "X", axis=(0, 0, 1), name="pl")],
                           inputs=[Input.joint("pl.s1"), Input.joint("pl.s2"), Input.joint("pl.angle")])
    sw = kincas.sweep(pla, {"pl.s1": s, "pl.s2": -s, "pl.angle": th}, report=["P.x", "P.y", "P.z"])
    assert sw.ok.all() and sw.residual.max() < 1e-12
    for k in range(3):  # e1 = x (global x on the plane), e2 = n x e1 = y
        want = X0 + rotz(th[k]) @ (P0 - X0) + np.array([s[k], -s[k], 0.0])
        assert np.allclose([sw["P.x"][k], sw["P.y"][k], sw["P.z"][k]], want, atol=1e-12)
