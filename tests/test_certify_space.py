"""Every assembly of a spatial mechanism, certified (kincas/core/polynomial_space.py).

The counts are known independently and written here: RSSR 2 (the rocker's circle against
the coupler's sphere: a cos phi + b sin phi = k), a spherical four-bar 2 (a line, the
intersection of two planes, through a sphere), the spatial slider-crank 2 (a quadratic in
the slider's travel), a pose with none (0, exit 3), and Dietmaier's Stewart-Gough platform
with 40 real assemblies (the published count, P. Dietmaier 1998; each one checked here by its
six leg lengths). The Stewart test runs msolve on 12 unknowns: a few seconds (marked slow)."""
from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

import kincas
import kincas.cli.scene
from conftest import EXAMPLES, run_cli
from kincas import Body, Input, Joint, SpatialMechanism
from kincas.analysis import certify_msolve
from kincas.core.polynomial_space import closure_space, matrix, quaternion, unit_vector
from kincas.core.tolerances import ACCEPT

needs_msolve = pytest.mark.skipif(not certify_msolve.available(),
                                  reason='msolve not installed (pip install "kincas[certify]")')


def certified(m, inputs):
    found = kincas.modes(m, inputs, certify=True)
    assert found.certified and found.count == len(found) and not found.rejected
    for md in found:
        assert md.residual <= ACCEPT
    return found


def rssr(coupler=125.0):
    return SpatialMechanism(
        ground={"A": (0, 0, 0), "D": (100, 40, 30)},
        bodies=[Body("crank", {"A": (0, 0, 0), "B": (15, 0, 0)}),
                Body.bar("coupler", "B", "C", coupler),
                Body("rocker", {"D": (100, 40, 30), "C": (100, 40, 90)})],
        joints=[Joint("revolute", "A", axis=(0, 0, 1)), Joint("revolute", "D", axis=(1, 0, 0))],
        inputs=[Input.joint("A")])


def rssr_count(u, coupler):
    """C = D + 60 (0, -sin phi, cos phi); |C - B|^2 = L^2 is a cos phi + b sin phi = k."""
    B, D = np.array([15 * math.cos(u), 15 * math.sin(u), 0.0]), np.array([100.0, 40, 30])
    w = D - B  # |w + 60 (0, -s, c)|^2 = L^2
    a, b, k = 120 * w[2], -120 * w[1], coupler ** 2 - w @ w - 3600
    return 2 if k * k < a * a + b * b else 0


@needs_msolve
def test_rssr_two_assemblies():
    assert rssr_count(math.pi / 2, 125.0) == 2
    found = certified(rssr(), {"A.angle": math.pi / 2})
    assert found.count == 2 and found.rounded == []
    for md in found:  # both close the coupler and keep C on the rocker's circle
        B, C = np.array(md.points["B"]), np.array(md.points["C"])
        assert abs(np.linalg.norm(C - B) - 125) < 1e-9 and abs(C[0] - 100) < 1e-9
    assert found[0].points["C"][1] != pytest.approx(found[1].points["C"][1])


@needs_msolve
def test_rssr_rounded_input_and_no_assembly(capsys, tmp_path):
    found = certified(rssr(), {"A.angle": 0.5})  # tan(0.25) is irrational: rounded, and said
    assert found.count == rssr_count(0.5, 125.0) == 2 and "A.angle" in found.rounded[0]
    assert rssr_count(math.pi / 2, 30.0) == 0
    assert certified(rssr(30.0), {"A.angle": math.pi / 2}).count == 0


def test_unit_vector_and_quaternion_map():
    a, same = unit_vector((0.6, 0.0, 0.8))  # 0.6 is not 3/5 in binary; the direction is
    assert same and a == (Fraction(3, 5), 0, Fraction(4, 5))
    a, same = unit_vector((1.0, 2.0, 2.5))
    assert sum(c * c for c in a) == 1 and not same
    assert np.allclose([float(c) for c in a], np.array([1, 2, 2.5]) / math.sqrt(11.25), atol=1e-11)
    a, same = unit_vector((0.0, -3.0, 4.0))
    assert same and a[1] * 5 == -3
    rng = np.random.default_rng(1)
    for _ in range(20):
        e = rng.normal(size=4)
        e /= np.linalg.norm(e)
        q = quaternion(matrix(e))
        assert q[0] >= 0 and np.allclose(q, e * np.sign(e[0]))


def spherical_fourbar():
    """Exact rational geometry (every axis through O exactly): crank about z carrying
    B = (60, 0, 80), output about (4, 0, 3)/5 carrying C = (0, 100, 0), the coupler's
    joints' axes along OB and OC."""
    return SpatialMechanism(
        ground={"O": (0, 0, 0)},
        bodies=[Body("crank", {"O": (0, 0, 0), "B": (60, 0, 80)}),
                Body("coupler", {"B": (60, 0, 80), "C": (0, 100, 0)}),
                Body("output", {"O": (0, 0, 0), "C": (0, 100, 0)})],
        joints=[Joint("revolute", "O", axis=(0, 0, 1), name="input", bodies=("ground", "crank")),
                Joint("revolute", "O", axis=(4, 0, 3), name="out", bodies=("ground", "output")),
                Joint("revolute", "B", axis=(3, 0, 4)), Joint("revolute", "C", axis=(0, 1, 0))],
        inputs=[Input.joint("input")])


@needs_msolve
def test_spherical_fourbar_two_assemblies():
    u = math.pi / 2
    # independent: C on the sphere |C| = 100, on the plane a.C = a.C0 (the output's circle),
    # on the plane B(u).C = B0.C0 (the coupler keeps the angle BOC): a line through a sphere
    B = np.array([60 * math.cos(u), 60 * math.sin(u), 80.0])
    a = np.array([0.8, 0, 0.6])
    n1, n2, d1, d2 = a, B, a @ [0, 100, 0], np.array([60, 0, 80.0]) @ [0, 100, 0]
    M = np.array([n1, n2])
    p0 = np.linalg.lstsq(M, [d1, d2], rcond=None)[0]  # the line's point nearest O
    count = 2 if p0 @ p0 < 100 ** 2 else 0
    found = certified(spherical_fourbar(), {"input.angle": u})
    assert count == 2 and found.count == 2 and found.rounded == []
    for md in found:
        C = np.array(md.points["C"])
        assert abs(np.linalg.norm(C) - 100) < 1e-9 and abs(a @ C - d1) < 1e-9 and abs(B @ C - d2) < 1e-8


@needs_msolve
def test_spatial_slider_crank_two_assemblies():
    sc = kincas.cli.scene.load(EXAMPLES / "space_slider_crank.toml")
    m, u = sc.mechanism, math.pi
    j = m.joint("slide")
    C0 = np.array(dict(m.bodies[2].points)["C"], float)
    a = np.array(j.axis) / np.linalg.norm(j.axis)
    B = np.array([40 * math.cos(u), 40 * math.sin(u), 0.0])  # |C0 + s a - B|^2 = 150^2
    w = C0 - B
    disc = (a @ w) ** 2 - (w @ w - 150 ** 2)
    found = certified(m, {"A.angle": u})
    assert disc > 0 and found.count == 2
    s = sorted(-(a @ w) + k * math.sqrt(disc) for k in (-1, 1))
    got = sorted(float((np.array(md.points["C"]) - C0) @ a) for md in found)
    assert np.allclose(got, s, atol=1e-9)


@needs_msolve
def test_no_assembly_exit_3(capsys, tmp_path):
    src = (EXAMPLES / "space_rssr.toml").read_text().replace("length = 125", "length = 30")
    f = tmp_path / "short.toml"
    f.write_text(src)
    assert rssr_count(0.0, 30.0) == 0  # the scene's pose: the sweep's first, 0 deg
    code, out, err = run_cli(capsys, "modes", f, "--certify", "--json")
    assert code == 3 and out["count"] == 0


@needs_msolve
def test_cli_json_three_coordinates(capsys):
    code, out, err = run_cli(capsys, "modes", EXAMPLES / "space_rssr.toml", "--certify", "--json")
    assert code == 0 and out["certified"] and out["count"] == 2
    for md in out["modes"]:
        assert all(len(xyz) == 3 for xyz in md["points"].values())


DIETMAIER = {  # P. Dietmaier (1998): base A_i, platform P_i (its own frame), leg lengths
    "A": [(0, 0, 0), (1.107915, 0, 0), (0.549094, 0.756063, 0), (0.735077, -0.223935, 0.525991),
          (0.514188, -0.526063, -0.368418), (0.590473, 0.094733, -0.205018)],
    "P": [(0, 0, 0), (0.542805, 0, 0), (0.956919, -0.528915, 0), (0.665885, -0.353482, 1.402538),
          (0.478359, 1.158742, 0.107672), (-0.137087, -0.235121, 0.353913)],
    "L": [1, 0.645275, 1.086284, 1.503439, 1.281933, 0.771071]}


@pytest.mark.slow
@needs_msolve
def test_stewart_dietmaier_40():
    sc = kincas.cli.scene.load(EXAMPLES / "space_stewart_40.toml")
    m = sc.mechanism
    assert [m.value(f"l{k + 1}") for k in range(6)] == DIETMAIER["L"]
    S = closure_space(m, DIETMAIER["L"])
    assert len(S.names) == 12 and S.rounded == []
    found = certified(m, {f"l{k + 1}": v for k, v in enumerate(DIETMAIER["L"])})
    assert found.count == 40  # the published count: 40, all of the complex ones real
    assert [md.note for md in found if md.note] == []  # each refined inside its box (to its error bound)
    poses = []
    for md in found:  # each: six legs of the given lengths (an independent check)
        for A, P, L, k in zip(DIETMAIER["A"], DIETMAIER["P"], DIETMAIER["L"], range(6)):
            assert abs(np.linalg.norm(np.array(md.points[f"P{k + 1}"]) - A) - L) < 1e-9
        poses.append(np.ravel([md.points[f"P{k + 1}"] for k in range(6)]))
    gaps = [np.abs(p - q).max() for i, p in enumerate(poses) for q in poses[i + 1:]]
    assert min(gaps) > 1e-6  # 40 distinct assemblies


def sphere_line_count(m, u):
    """The spherical four-bar's assemblies at input u, independently: C on the sphere
    |C| = |C0|, on the output's plane a.C = a.C0, on the plane B(u).C = B0.C0 (the coupler
    keeps the angle BOC): a line through a sphere, 2, 1 or 0 points. Also the predicate."""
    pts = {p: np.array(xyz, float) for b in m.bodies for p, xyz in b.points}
    B0, C0 = pts["B"], pts["C"]
    B = np.array([[math.cos(u), -math.sin(u), 0], [math.sin(u), math.cos(u), 0], [0, 0, 1]]) @ B0
    a = np.asarray(m.joint("out").axis, float)
    a /= np.linalg.norm(a)
    M, d = np.array([a, B]), np.array([a @ C0, B0 @ C0])
    p0 = np.linalg.lstsq(M, d, rcond=None)[0]  # the line's point nearest O
    on = lambda C: max(abs(np.linalg.norm(C) - np.linalg.norm(C0)), abs(a @ C - d[0]), abs(B @ C - d[1]) / 100)
    return (2 if p0 @ p0 < C0 @ C0 else 0), on


@pytest.mark.slow
@needs_msolve
def test_float_axes_spherical_fourbar_certified(capsys):
    """The example's axes meet at O only to float rounding: as exact rationals it is rigid.
    The equations implied at the drawing pose are left out (the square subsystem), every root
    refined on the scene's floats into its box: the line-sphere count."""
    m = kincas.cli.scene.load(EXAMPLES / "space_spherical_fourbar.toml").mechanism
    count, on = sphere_line_count(m, 0.0)
    code, out, err = run_cli(capsys, "modes", EXAMPLES / "space_spherical_fourbar.toml", "--certify", "--json")
    assert code == 0 and out["certified"] and out["count"] == count == 2 and out["rejected"] == []
    assert any("overconstrained" in note for note in out["rounded"])
    for md in out["modes"]:
        assert on(np.array(md["points"]["C"])) < 1e-9 and "note" not in md


def bennett_angles(m, u):
    """Bennett's linkage at input u, independently of kincas: the coupler L2 turns by t2
    about its axis at O2 (carried by the crank), the follower L3 by t4 about the ground's
    axis at O4; the joint at O3 needs the point and the axis z3 the same from both. Every
    root of that 2 x 2 problem on the torus, from a 16 x 16 grid of starts."""
    from scipy.optimize import least_squares
    pts = {p: np.array(xyz, float) for b in m.bodies for p, xyz in b.points}
    pts.update({g: np.array(xyz, float) for g, xyz in m.ground})
    z = {j.point: np.asarray(j.axis, float) / np.linalg.norm(j.axis) for j in m.joints}
    rot = lambda a, t: kincas.core.space_model.axis_rotation(a, t)
    R1 = rot(z["O1"], u)
    o2, a2 = R1 @ pts["O2"], R1 @ z["O2"]

    def f(v):
        P2 = o2 + rot(a2, v[0]) @ (R1 @ pts["O3"] - o2)
        P3 = pts["O4"] + rot(z["O4"], v[1]) @ (pts["O3"] - pts["O4"])
        Z2, Z3 = rot(a2, v[0]) @ R1 @ z["O3"], rot(z["O4"], v[1]) @ z["O3"]
        return np.concatenate([P2 - P3, 100 * (Z2 - Z3)])
    roots = []
    for t2 in np.linspace(-math.pi, math.pi, 16, endpoint=False):
        for t4 in np.linspace(-math.pi, math.pi, 16, endpoint=False):
            r = least_squares(f, [t2, t4], xtol=1e-15, ftol=1e-15, gtol=1e-15)
            w = np.angle(np.exp(1j * r.x))
            if np.abs(r.fun).max() < 1e-8 and all(np.abs(np.angle(np.exp(1j * (w - s)))).max() > 1e-6 for s in roots):
                roots.append(w)
    return roots, lambda v: R1 @ pts["O2"], lambda v: pts["O4"] + rot(z["O4"], v[1]) @ (pts["O3"] - pts["O4"])


@pytest.mark.slow
@needs_msolve
def test_float_axes_bennett_certified():
    m = kincas.cli.scene.load(EXAMPLES / "space_bennett.toml").mechanism
    u = 0.5
    roots, O2, O3 = bennett_angles(m, u)
    found = kincas.modes(m, {"O1.angle": u}, certify=True)
    assert found.count == len(roots) == 1 and not found.rejected
    assert found.rounded and "overconstrained" in found.rounded[-1]
    assert [md.note for md in found] == [""]  # refined on the floats into its box
    assert np.allclose(found[0].points["O3"], O3(roots[0]), atol=1e-8)
    assert np.allclose(found[0].points["O2"], O2(roots[0]), atol=1e-8)
