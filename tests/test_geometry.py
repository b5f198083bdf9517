"""Jerk, path curvature and instant centres against closed forms written here (mpmath, 30 digits)
and textbook constructions; null where a quantity is undefined."""
from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism, Slide

mp.mp.dps = 30
R, L = 0.3, 1.1  # slider-crank: crank and rod
W, ACC, JERK = 2.5, -1.7, 3.3  # the crank's rate, acceleration and jerk


def slider_crank():
    """Crank A-B about the origin, rod B-P, block P-Q kept on the x axis by two slides."""
    return Mechanism(ground={"A": (0, 0)},
                     links=[Link.bar("crank", "A", "B", R), Link.bar("rod", "B", "P", L),
                            Link("block", {"P": (0, 0), "Q": (0.2, 0)})],
                     slides=[Slide("P", "ground", name="guide"), Slide("Q", "ground", name="guide2")],
                     inputs=[Input.angle("crank")], guess={"P": (1.4, 0), "Q": (1.6, 0)})


def closed(theta):
    """Slider-crank closed form: slider x and rod angle at crank angle theta (mpmath)."""
    y = R * mp.sin(theta)
    return R * mp.cos(theta) + mp.sqrt(L ** 2 - y ** 2), mp.atan2(-y, mp.sqrt(L ** 2 - y ** 2))


def along_time(f, th0, order):
    """order-th time derivative at t=0 of f(theta(t)), theta = th0 + W t + ACC t^2/2 + JERK t^3/6."""
    return mp.diff(lambda t: f(th0 + W * t + ACC * t ** 2 / 2 + JERK * t ** 3 / 6), 0, order)


@pytest.mark.parametrize("th0", [0.4, 2.0, -2.7])
def test_jerk_against_a_30_digit_derivative_of_the_closed_form(th0):
    pose = kincas.solve(slider_crank(), {"crank.angle": th0}, rates=W, accelerations=ACC,
                        jerks=JERK, report=["P.jx", "P.jy", "rod.jerk", "guide.jerk", "B.jy",
                                            "crank.jerk", "P.ax", "rod.alpha"])
    jx = float(along_time(lambda th: closed(th)[0], th0, 3))
    jrod = float(along_time(lambda th: closed(th)[1], th0, 3))
    jby = float(along_time(lambda th: R * mp.sin(th), th0, 3))
    scale = R * W ** 3 * 10
    assert abs(pose["P.jx"] - jx) < 1e-12 * scale
    assert abs(pose["guide.jerk"] - jx) < 1e-12 * scale
    assert abs(pose["P.jy"]) < 1e-12 * scale
    assert abs(pose["B.jy"] - jby) < 1e-12 * scale
    assert abs(pose["rod.jerk"] - jrod) < 1e-12 * W ** 3 * 10
    assert abs(pose["crank.jerk"] - JERK) < 1e-12
    assert abs(pose["P.ax"] - float(along_time(lambda th: closed(th)[0], th0, 2))) < 1e-12 * scale


def test_jerk_of_inputs_defaults_to_zero_and_scene_takes_jerk(tmp_path):
    m = slider_crank()
    a = kincas.solve(m, {"crank.angle": 1.0}, rates=W, report=["crank.jerk", "P.jx"])
    b = kincas.solve(m, {"crank.angle": 1.0}, rates=W, jerks=0.0, report=["crank.jerk", "P.jx"])
    assert a["crank.jerk"] == 0 and abs(a["P.jx"] - b["P.jx"]) < 1e-12
    jx = float(mp.diff(lambda t: closed(1.0 + W * t)[0], 0, 3))
    assert abs(a["P.jx"] - jx) < 1e-11


# --- a four-bar's coupler point: curvature and centre of curvature ---

A, D, CR, CO, RO = (0.0, 0.0), (4.0, 0.0), 1.0, 3.5, 3.0
EX, EY = 1.2, 0.8  # coupler point in the coupler's frame (origin B, x axis towards C)


def fourbar():
    return Mechanism(ground={"A": A, "D": D},
                     links=[Link.bar("crank", "A", "B", CR),
                            Link("coupler", {"B": (0, 0), "C": (CO, 0), "E": (EX, EY)}),
                            Link.bar("rocker", "D", "C", RO)],
                     inputs=[Input.angle("crank")], guess={"C": (3.6, 2.9)})


def fourbar_points(th):
    """B, C, E of the four-bar (C above the ground line) at crank angle th, in mpmath."""
    bx, by = CR * mp.cos(th), CR * mp.sin(th)
    dx, dy = D[0] - bx, D[1] - by
    d = mp.sqrt(dx ** 2 + dy ** 2)
    a = (CO ** 2 - RO ** 2 + d ** 2) / (2 * d)
    h = mp.sqrt(CO ** 2 - a ** 2)
    cx, cy = bx + (a * dx - h * dy) / d, by + (a * dy + h * dx) / d
    ux, uy = (cx - bx) / CO, (cy - by) / CO
    return (bx, by), (cx, cy), (bx + EX * ux - EY * uy, by + EX * uy + EY * ux)


@pytest.mark.parametrize("th0", [0.3, 1.9, 4.0])
def test_curvature_and_centre_against_the_textbook_formula(th0):
    pose = kincas.solve(fourbar(), {"crank.angle": th0}, rates=W, accelerations=ACC,
                        report=["E.curvature", "E.cx", "E.cy", "E.x", "E.y"])
    vx, vy = (float(along_time(lambda th, i=i: fourbar_points(th)[2][i], th0, 1)) for i in (0, 1))
    ax, ay = (float(along_time(lambda th, i=i: fourbar_points(th)[2][i], th0, 2)) for i in (0, 1))
    kappa = (vx * ay - vy * ax) / math.hypot(vx, vy) ** 3
    assert abs(pose["E.curvature"] - kappa) < 1e-10 * abs(kappa) + 1e-12
    # the centre lies on the normal, 1/kappa away, on the side the path turns to
    n = np.array([-vy, vx]) / math.hypot(vx, vy)
    centre = np.array([pose["E.x"], pose["E.y"]]) + n / kappa
    assert np.allclose([pose["E.cx"], pose["E.cy"]], centre, rtol=0, atol=1e-10 * (1 + abs(1 / kappa)))


def intersect(p1, d1, p2, d2):
    """Intersection of the lines p1 + s d1 and p2 + t d2."""
    s = np.linalg.solve(np.column_stack([d1, -np.asarray(d2)]), np.asarray(p2) - np.asarray(p1))[0]
    return np.asarray(p1) + s * np.asarray(d1)


@pytest.mark.parametrize("th0", [0.3, 1.9, 4.0])
def test_instant_centres_by_kennedys_theorem(th0):
    pose = kincas.solve(fourbar(), {"crank.angle": th0}, rates=W,
                        report=["coupler.icx", "coupler.icy", "crank.icx", "crank.icy",
                                "coupler/crank.icx", "coupler/crank.icy", "rocker/crank.icx",
                                "rocker/crank.icy", "crank/ground.icx", "rocker.icx", "rocker.icy"])
    (bx, by), (cx, cy), _ = (tuple(map(float, p)) for p in fourbar_points(th0))
    # the coupler's instant centre: where the lines A-B and D-C meet
    ic = intersect(A, (bx, by), D, (cx - D[0], cy - D[1]))
    assert np.allclose([pose["coupler.icx"], pose["coupler.icy"]], ic, atol=1e-9 * (1 + abs(ic).max()))
    assert np.allclose([pose["crank.icx"], pose["crank.icy"], pose["crank/ground.icx"]], [0, 0, 0], atol=1e-12)
    assert np.allclose([pose["rocker.icx"], pose["rocker.icy"]], D, atol=1e-12)
    assert np.allclose([pose["coupler/crank.icx"], pose["coupler/crank.icy"]], [bx, by], atol=1e-12)
    # rocker relative to crank: on the line A-D and on the line B-C (Kennedy)
    ic13 = intersect(A, (1, 0), (bx, by), (cx - bx, cy - by))
    assert np.allclose([pose["rocker/crank.icx"], pose["rocker/crank.icy"]], ic13,
                       atol=1e-9 * (1 + abs(ic13).max()))


def test_undefined_geometry_is_null_and_the_pose_stays_ok():
    # the slider at dead centre is at rest; the block translates
    pose = kincas.solve(slider_crank(), {"crank.angle": 0.0}, rates=W,
                        report=["P.curvature", "P.cx", "block.icx", "block.icy", "rod.icx", "B.curvature"])
    assert pose.status == "ok"
    assert all(math.isnan(pose[k]) for k in ("P.curvature", "P.cx", "block.icx", "block.icy"))
    assert abs(pose["B.curvature"] - 1 / R) < 1e-12  # the crank pin turns on its circle
    assert abs(pose["rod.icx"] - (R + L)) < 1e-12  # at dead centre: the piston pin itself
    # a parallelogram: the coupler translates, crank and rocker turn at the same rate
    para = Mechanism(ground={"A": (0, 0), "D": (2, 0)},
                     links=[Link.bar("crank", "A", "B", 1), Link.bar("coupler", "B", "C", 2),
                            Link.bar("rocker", "D", "C", 1)],
                     inputs=[Input.angle("crank")], guess={"C": (2.6, 0.8)})
    pose = kincas.solve(para, {"crank.angle": 0.9}, rates=W,
                        report=["coupler.icx", "rocker/crank.icy", "crank/coupler.icx", "C.curvature"])
    assert pose.status == "ok"
    assert math.isnan(pose["coupler.icx"]) and math.isnan(pose["rocker/crank.icy"])
    assert abs(pose["crank/coupler.icx"] - math.cos(0.9)) < 1e-12  # the pin B
    assert abs(pose["C.curvature"] - 1.0) < 1e-12
    # nothing moves: no instant centre, no path direction
    pose = kincas.solve(fourbar(), {"crank.angle": 1.0}, rates=0.0, report=["coupler.icx", "E.curvature"])
    assert math.isnan(pose["coupler.icx"]) and math.isnan(pose["E.curvature"])


def test_unknown_geometry_names_are_refused():
    with pytest.raises(kincas.ModelError, match="nobody"):
        kincas.solve(fourbar(), {"crank.angle": 1.0}, report=["coupler/nobody.icx"])
    with pytest.raises(kincas.ModelError, match="Z.curvature"):
        kincas.solve(fourbar(), {"crank.angle": 1.0}, report=["Z.curvature"])


def test_scene_input_jerk_and_where_it_is_refused(capsys, tmp_path):
    from conftest import run_cli, write_scene
    scene = {"ground": {"A": [0, 0], "D": [4, 0]},
             "links": {"crank": {"points": ["A", "B"], "length": 1},
                       "coupler": {"points": ["B", "C"], "length": 3.5},
                       "rocker": {"points": ["D", "C"], "length": 3}},
             "inputs": [{"angle": "crank", "value": 30, "rate": 10, "jerk": 40}],
             "guess": {"C": [3.6, 2.9]}, "output": {"report": ["crank.jerk", "B.jy"]}}
    code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, scene), "--json")
    assert code == 0, err
    assert abs(out["values"]["crank.jerk"][0] - 40) < 1e-9  # degrees in, degrees out
    # B.y = sin(theta): jerk = cos(th) th''' - 3 sin(th) th' th'' - cos(th) th'^3 (th'' = 0)
    w, j = math.radians(10), math.radians(40)
    assert abs(out["values"]["B.jy"][0] - (math.cos(math.pi / 6) * (j - w ** 3))) < 1e-12
    scene["parameters"] = {"k": 1.0}
    scene["optimize"] = {"vary": {"k": [0.5, 2]}, "minimize": "sum(B.jy^2)"}
    code, _, err = run_cli(capsys, "optimize", write_scene(tmp_path, scene), "--json")
    assert code == 2 and "[optimize]: a jerk quantity with a nonzero input `jerk`" in err
