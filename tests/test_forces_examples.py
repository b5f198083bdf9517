"""The force and geometry examples (examples/forces_*.toml), each against an independent
computation written here: power balance (virtual work) and -sum m a from the closed-form
positions of tests/closed_forms.py and their central differences, the textbook curvature
formula and Kennedy's instant centre, and the V-twin's counterweight by a scalar minimax."""
from __future__ import annotations

import math

import numpy as np
import pytest

import closed_forms as cf
from conftest import EXAMPLES, run_cli

REL = 1e-6  # central differences of the closed forms: relative accuracy of the checks


def scene_of(name):
    return cf.load_scene(EXAMPLES / f"forces_{name}.toml")


def solved(capsys, name):
    code, out, err = run_cli(capsys, "solve", EXAMPLES / f"forces_{name}.toml", "--json")
    assert code == 0, err
    return {k: np.array(v, dtype=float) for k, v in out["values"].items()}


def derivatives(kind, scene, h):
    """Closed-form points and link angles at the scene's inputs, with their first and second
    derivatives per unit of the input (radians for an angle input), by 5-point differences."""
    u = cf.input_values(scene)
    k = cf.angle_unit(scene) if cf.input_kind(scene)[0] == "angle" else 1.0
    sols = [cf.solve(kind, scene, u + j * h) for j in (-2, -1, 0, 1, 2)]
    out = {}
    for name in sols[2].points:
        out[name] = [s.points[name] for s in sols]
    for link in sols[2].frames:
        out[link] = [np.unwrap(s.frames[link][0]) for s in sols]
    hh = h * k
    return {n: (v[2], (v[0] - 8 * v[1] + 8 * v[3] - v[4]) / (12 * hh),
                (-v[0] + 16 * v[1] - 30 * v[2] + 16 * v[3] - v[4]) / (12 * hh ** 2))
            for n, v in out.items()}


def dot(a, b):
    return np.einsum("ij,ij->i", a, b)


def test_bellcrank_actuator_force_by_virtual_work(capsys):
    scene = scene_of("bellcrank")
    d = derivatives("actuator_bellcrank", scene, 1e-3)
    torque = scene["loads"][0]["torque"]
    # Q dstroke + tau dtheta_rocker = 0
    expected = -torque * d["rocker"][1]
    got = solved(capsys, "bellcrank")["effort(stroke)"]
    assert np.allclose(got, expected, rtol=0, atol=REL * np.abs(expected).max())


def test_toggle_clamp_effort_with_its_spring(capsys):
    scene = scene_of("toggle")
    d = derivatives("fourbar_coupler", scene, 0.05)
    tau = scene["loads"][0]["torque"]
    spring = scene["loads"][1]
    anchor, (p, dp, _) = np.array(scene["ground"]["S"], float), d["P"]
    length = np.linalg.norm(p - anchor, axis=1)
    dl = dot(p - anchor, dp) / length
    expected = -tau * d["rocker"][1] + spring["stiffness"] * (length - spring["free_length"]) * dl
    got = solved(capsys, "toggle")["effort(crank.angle)"]
    assert np.allclose(got, expected, rtol=0, atol=REL * np.abs(expected).max())
    # near the toggle position the arm stands still: the handle holds little more than the spring
    assert abs(got[-1]) < 0.1 * np.abs(got).max()


def test_press_motor_torque_with_masses_and_gravity(capsys):
    scene = scene_of("press")
    d = derivatives("slider_crank", scene, 0.05)
    w = math.radians(scene["inputs"][0]["rate"])
    g = np.array(scene["gravity"], float)
    q = np.zeros(len(cf.input_values(scene)))
    for link, (p, r) in (("crank", ("O", "A")), ("rod", ("A", "B"))):
        spec = scene["links"][link]
        # centre of gravity: the middle of the two points
        pos, vel, acc = ((d[p][i] + d[r][i]) / 2 for i in range(3))
        a = acc * w ** 2  # constant rate: a = d2r/du2 w^2
        q += spec["mass"] * dot(a - g, vel) + spec["inertia"] * d[link][2] * w ** 2 * d[link][1]
    force = np.array(scene["loads"][0]["force"], float)
    q -= dot(np.broadcast_to(force, d["B"][1].shape), d["B"][1])
    got = solved(capsys, "press")["effort(crank.angle)"]
    assert np.allclose(got, q, rtol=0, atol=REL * np.abs(q).max())


def test_coupler_curvature_evolute_and_centrode(capsys):
    scene = scene_of("coupler_curve")
    d = derivatives("fourbar_coupler", scene, 0.05)
    w = math.radians(scene["inputs"][0]["rate"])
    (p, v, a) = (d["P"][0], d["P"][1] * w, d["P"][2] * w ** 2)
    cross = v[:, 0] * a[:, 1] - v[:, 1] * a[:, 0]
    speed = np.linalg.norm(v, axis=1)
    kappa = cross / speed ** 3
    got = solved(capsys, "coupler_curve")
    assert np.allclose(got["P.curvature"], kappa, rtol=REL, atol=REL * np.abs(kappa).max())
    normal = np.stack([-v[:, 1], v[:, 0]], axis=1) / speed[:, None]
    centre = p + normal / kappa[:, None]
    assert np.allclose(np.stack([got["P.cx"], got["P.cy"]], axis=1), centre, rtol=1e-5, atol=1e-5)
    # fixed centrode: the coupler's instant centre where the lines O2-A and O4-B meet
    o2, o4 = np.array([0.0, 0.0]), np.array([cf.num(scene, "r1"), 0.0])
    ic = []
    for A, B in zip(d["A"][0], d["B"][0]):
        m = np.column_stack([A - o2, -(B - o4)])
        ic.append(o2 + np.linalg.solve(m, o4 - o2)[0] * (A - o2))
    ic = np.array(ic)
    assert np.allclose(np.stack([got["coupler.icx"], got["coupler.icy"]], axis=1), ic,
                       rtol=1e-9, atol=1e-9 * np.abs(ic).max())


# --- the V-twin: shaking force from -sum m a, and the counterweight ---


def vtwin_closed(scene, theta):
    """Crank pin C, piston pins P1 and P2 (N x 2) at crank angles theta (radians)."""
    r, l = cf.num(scene, "r"), cf.num(scene, "l")
    c = r * np.stack([np.cos(theta), np.sin(theta)], axis=1)
    out = [c]
    for beta in (math.radians(45), math.radians(135)):
        e = np.array([math.cos(beta), math.sin(beta)])
        along, across = c @ e, c[:, 0] * e[1] - c[:, 1] * e[0]
        out.append((along + np.sqrt(l ** 2 - across ** 2))[:, None] * e)
    return out


def vtwin_shaking_without_crank(scene, theta, w, h=1e-4):
    """-sum m a of the rods and pistons (N x 2), by central differences in time."""
    links = scene["links"]

    def centres(t):
        c, p1, p2 = vtwin_closed(scene, theta + w * t)
        return [(links["rod1"]["mass"], (c + p1) / 2), (links["rod2"]["mass"], (c + p2) / 2),
                (links["piston1"]["mass"], p1), (links["piston2"]["mass"], p2)]

    dt = h / w
    f = np.zeros((len(theta), 2))
    for (m, x0), (_, xm), (_, xp), (_, xmm), (_, xpp) in zip(
            centres(0), centres(-dt), centres(dt), centres(-2 * dt), centres(2 * dt)):
        acc = (-xmm + 16 * xm - 30 * x0 + 16 * xp - xpp) / (12 * dt ** 2)
        f -= m * acc
    return f


def test_vtwin_shaking_force(capsys):
    scene = scene_of("vtwin")
    theta = np.radians(cf.input_values(scene))
    w = math.radians(scene["inputs"][0]["rate"])
    crank = scene["links"]["crank"]
    cw = cf.num(scene, "cw")
    # the crank's centre of gravity turns on a circle of radius cw: -m a = m w^2 cw (cos, sin)
    f = vtwin_shaking_without_crank(scene, theta, w)
    f += crank["mass"] * w ** 2 * cw * np.stack([np.cos(theta), np.sin(theta)], axis=1)
    got = solved(capsys, "vtwin")
    scale = np.abs(f).max()
    assert np.allclose(got["shaking.x"], f[:, 0], rtol=0, atol=REL * scale)
    assert np.allclose(got["shaking.y"], f[:, 1], rtol=0, atol=REL * scale)


def test_vtwin_counterweight_minimises_the_peak_shaking_force(capsys):
    scipy = pytest.importorskip("scipy.optimize")
    scene = scene_of("vtwin")
    theta = np.radians(cf.input_values(scene))
    w = math.radians(scene["inputs"][0]["rate"])
    f0 = vtwin_shaking_without_crank(scene, theta, w)
    unit = scene["links"]["crank"]["mass"] * w ** 2 * np.stack([np.cos(theta), np.sin(theta)], axis=1)
    # the peak over the poses is convex in cw: a bounded scalar search finds its minimum
    peak = lambda cw: np.linalg.norm(f0 + cw * unit, axis=1).max()
    best = scipy.minimize_scalar(peak, bounds=(-80, 40), method="bounded", options={"xatol": 1e-9})
    code, out, err = run_cli(capsys, "optimize", EXAMPLES / "forces_vtwin.toml", "--json")
    assert code == 0, err
    assert abs(out["varied"]["cw"] - best.x) < 1e-4
    assert abs(out["objective"] - best.fun) < 1e-5 * best.fun
    assert best.fun < 0.1 * peak(cf.num(scene, "cw"))  # the counterweight does its job
