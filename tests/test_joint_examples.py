"""The examples with gears, racks, cams, relative inputs and fixed pins in moving slots,
checked through `kincas solve --json` against closed forms written here, independently of
kincas (circle intersections, the Willis formula, the lift of an eccentric). Velocities and
accelerations are checked against 5-point central differences of the closed forms along the
inputs' rates (the examples' accelerations are zero).
"""
from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from conftest import EXAMPLES, run_cli, write_scene

D = math.pi / 180


def wrap(a):
    """Degrees to (-180, 180]."""
    w = np.mod(np.asarray(a, float) + 180.0, 360.0) - 180.0
    return np.where(w == -180.0, 180.0, w)


def deg(a):
    return np.degrees(a)


def circles(c1, r1, c2, r2, side):
    """Intersection of two circles (arrays of centres), on the left (+1) or right (-1) of
    the direction c1 -> c2."""
    d = c2 - c1
    L = np.hypot(*d)
    a = (r1 * r1 - r2 * r2 + L * L) / (2 * L)
    h = np.sqrt(r1 * r1 - a * a)
    e = d / L
    n = np.array([-e[1], e[0]])
    return c1 + a * e + side * h * n


def polar(r, a):
    return np.array([r * np.cos(a), r * np.sin(a)])


def ang(v):
    return deg(np.arctan2(v[1], v[0]))


# --- the closed forms: inputs in degrees -> quantities (angles in degrees, unwrapped) ---


def geared_fivebar(u):
    t1 = u[0] * D
    t2 = -(20 / 40) * t1
    B, C = polar(25, t1), np.array([[60], [0]]) + polar(30, t2)
    P = circles(B, 90, C, 90, +1)
    return {"P.x": P[0], "P.y": P[1], "crank2.angle": deg(t2), "crank2/crank1.angle": deg(t2 - t1),
            "left.angle": ang(P - B)}


def planetary(u):
    """Willis: (w_ring - w_arm) / (w_sun - w_arm) = -rs / rr with the ring fixed gives
    w_arm = w_sun rs / (rs + rr); the planet: (w_p - w_arm) = -(rs / rp) (w_sun - w_arm)."""
    ts = u[0] * D
    ta = ts * 30 / (30 + 60)
    tp = ta - (30 / 15) * (ts - ta)
    C = polar(45, ta)
    M = C + polar(15, tp)
    return {"arm.angle": deg(ta), "planet.angle": deg(tp), "planet/arm.angle": deg(tp - ta),
            "M.x": M[0], "M.y": M[1]}


def rack_fourbar(u):
    th = u[0] * D
    x = 20 * th  # s = G.x - rack.x = -r theta (teeth on the right, offset 0)
    R2 = np.stack([x + 100, 0 * x])
    Dp = np.array([[150.0], [80.0]])
    C = circles(R2, 70, Dp, 60, +1)
    return {"R1.x": x - 150, "travel.s": -x, "C.x": C[0], "C.y": C[1], "rocker.angle": ang(C - Dp)}


def eccentric_cam(u):
    th = u[0] * D
    c = polar(10, th)
    y = c[1] + np.sqrt(40 ** 2 - c[0] ** 2)
    return {"F.y": y, "cam.contact.x": 0 * th, "cam.contact.y": y,
            "cam.phi": deg(np.arctan2(y - c[1], -c[0]) - th)}


def roller_cam(u):
    th = u[0] * D
    c, A = polar(15, th), np.array([[60.0], [60.0]])
    F = circles(A, 55, c, 50, -1)
    return {"arm.angle": ang(F - A), "F.x": F[0], "F.y": F[1], "cam.phi": ang(F - c) - u[0]}


def flat_tappet(u):
    th = u[0] * D
    return {"F.y": 8 * np.sin(th) + 30, "cam.contact.x": 8 * np.cos(th),
            "cam.contact.y": 8 * np.sin(th) + 30, "cam.phi": 90 - u[0], "tappet.angle": 0 * th}


def elbow_arm(u):
    a, b = u[0] * D, u[1] * D
    H = polar(300, a) + polar(250, a + b)
    return {"H.x": H[0], "H.y": H[1], "forearm.angle": deg(a + b), "forearm/upper.angle": u[1]}


def whitworth(u):
    th = u[0] * D
    B, A = polar(40, th), np.array([[0.0], [-20.0]])
    d = A - B
    s = np.hypot(*d)
    Dp = B + 100 * d / s
    Ex = Dp[0] + np.sqrt(150 ** 2 - (Dp[1] + 20) ** 2)
    return {"lever.angle": ang(d), "slot.s": s, "E.x": Ex, "D.x": Dp[0], "D.y": Dp[1]}


def designed_cam(u):
    """The motion law the profile was designed for (`kincas cam`, base 30 + roller 6): a
    cycloidal rise of 15 over 120 deg, dwell 60, 3-4-5 return over 120, dwell 60."""
    th = np.mod(u[0], 360.0)
    x1, x2 = th / 120, (th - 180) / 120
    rise = 15 * (x1 - np.sin(2 * np.pi * x1) / (2 * np.pi))
    ret = 15 * (1 - (10 * x2 ** 3 - 15 * x2 ** 4 + 6 * x2 ** 5))
    s = np.select([th < 120, th < 180, th < 300], [rise, 15.0, ret], 0.0)
    return {"F.y": 36 + s}


FORMS = {f.__name__: f for f in (designed_cam, geared_fivebar, planetary, rack_fourbar, eccentric_cam,
                                  roller_cam, flat_tappet, elbow_arm, whitworth)}
RATE = {"x": "vx", "y": "vy", "angle": "omega", "s": "v"}
ACC = {"x": "ax", "y": "ay", "angle": "alpha", "s": "a"}


def scene_of(name):
    return tomllib.loads((EXAMPLES / f"{name}.toml").read_text(encoding="utf-8"))


def inputs_of(scene):
    """(N x k) input values in degrees and the rate of each input."""
    cols, rates = [], []
    for spec in scene["inputs"]:
        sw = spec["sweep"]
        cols.append(np.linspace(sw["from"], sw["to"], sw["steps"]))
        rates.append(spec.get("rate", 1.0))
    return np.stack(cols), np.array(rates)


def differences(form, U, rates, h=1e-3 / D):
    """Velocities and accelerations along the rates (per second, in degrees and mm)."""
    f = [form(U + j * h * rates[:, None]) for j in (-2, -1, 0, 1, 2)]
    out = {}
    for name in f[2]:
        g = [np.asarray(q[name], float) for q in f]
        if name.endswith((".angle", ".phi")):  # unwrapped around the middle sample
            g = [g[2] + wrap(gj - g[2]) for gj in g]
        d1 = (g[0] - 8 * g[1] + 8 * g[3] - g[4]) / (12 * h)
        d2 = (-g[0] + 16 * g[1] - 30 * g[2] + 16 * g[3] - g[4]) / (12 * h * h)
        obj, attr = name.rsplit(".", 1)
        if attr in RATE:
            out[f"{obj}.{RATE[attr]}"], out[f"{obj}.{ACC[attr]}"] = d1, d2
    return out


@pytest.mark.parametrize("name", sorted(FORMS))
def test_joint_example_matches_closed_form(capsys, tmp_path, name):
    scene = scene_of(name)
    U, rates = inputs_of(scene)
    exact = FORMS[name](U)
    # the designed cam's profile is a spline through the design: its positions are exact at
    # the design's angles (every 5 deg here), its rates only to the spline's accuracy
    rate_q = {} if name == "designed_cam" else differences(FORMS[name], U, rates)
    report = list(exact) + list(rate_q)
    code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, {**scene, "output": {"report": report}}),
                             "--json")
    assert code == 0, err
    assert out["status"] == ["ok"] * U.shape[1]
    size = max(np.abs(v).max() for k, v in exact.items() if not k.endswith((".angle", ".phi")))
    for k, e in exact.items():
        got = np.array(out["values"][k], float)
        if k.endswith((".angle", ".phi")):
            assert np.all((got > -180) & (got <= 180)), f"{k} is not wrapped"
            err_ = np.abs(wrap(got - e))
            assert err_.max() <= 1e-9 / D, (k, err_.max())
        else:
            assert np.abs(got - e).max() <= 1e-9 * size, (k, np.abs(got - e).max())
    groups: dict[str, float] = {}
    for k, e in rate_q.items():
        groups[k.rsplit(".", 1)[1]] = max(groups.get(k.rsplit(".", 1)[1], 0.0), np.abs(e).max())
    for k, e in rate_q.items():
        got = np.array(out["values"][k], float)
        attr = k.rsplit(".", 1)[1]
        first = {"ax": "vx", "ay": "vy", "alpha": "omega", "a": "v"}.get(attr, attr)
        tol = 1e-7 * max(groups[attr], groups[first], 1e-6)  # a zero acceleration: on the rate's scale
        assert np.abs(got - e).max() <= tol, (k, np.abs(got - e).max(), tol)


def test_designed_cam_rates_to_the_splines_accuracy(capsys):
    """F.vy = s'(theta) and F.ay = s''(theta) per degree, to 1e-4 and 1e-2 of their largest
    (the profile's spline through points 1 deg apart)."""
    code, out, err = run_cli(capsys, "solve", EXAMPLES / "designed_cam.toml", "--json")
    assert code == 0, err
    U = np.linspace(0, 360, 73)[None, :]
    d = differences(designed_cam, U, np.array([1.0]), h=1e-4 / D)
    v, a = np.array(out["values"]["F.vy"], float), np.array(out["values"]["F.ay"], float)
    join = np.isin(U[0] % 360, [0, 120, 180, 300])  # the differences straddle a join there
    assert np.abs(v - d["F.vy"])[~join].max() <= 1e-4 * np.abs(d["F.vy"]).max()
    assert np.abs(a - d["F.ay"])[~join].max() <= 1e-2 * np.abs(d["F.ay"]).max()


def test_planetary_willis_rates(capsys):
    """The arm at a third of the sun's speed (rate 3 -> 1), the planet at -3, relative -4."""
    code, out, err = run_cli(capsys, "solve", EXAMPLES / "planetary.toml", "--json")
    assert code == 0, err
    w_sun = 3.0
    w_arm = w_sun * 30 / (30 + 60)  # Willis, ring fixed
    w_planet = w_arm - (30 / 15) * (w_sun - w_arm)
    np.testing.assert_allclose(out["values"]["arm.omega"], w_arm, rtol=1e-12)
    np.testing.assert_allclose(out["values"]["planet.omega"], w_planet, rtol=1e-12)
    np.testing.assert_allclose(out["values"]["planet/arm.omega"], w_planet - w_arm, rtol=1e-12)


def test_eccentric_cam_pressure_angle(capsys):
    """In-line knife edge: the follower moves along y, the normal is (F - c) / R, so the
    pressure angle is atan(|c_x| / (y - c_y)); null where the follower stands (90, 270 deg)."""
    code, out, err = run_cli(capsys, "solve", EXAMPLES / "eccentric_cam.toml", "--json")
    assert code == 0, err
    u = np.linspace(0, 360, 37)
    c = polar(10, u * D)
    y = c[1] + np.sqrt(1600 - c[0] ** 2)
    want = deg(np.arctan2(np.abs(c[0]), y - c[1]))
    got = out["values"]["cam.pressure"]
    for k, (g, w) in enumerate(zip(got, want)):
        if u[k] in (90.0, 270.0):
            assert g is None, (u[k], g)
        else:
            assert abs(g - w) < 1e-9, (u[k], g, w)


def test_roller_cam_pressure_angle(capsys):
    """The roller's centre moves across the arm: the pressure angle is the angle between the
    normal F - c and the arm's perpendicular."""
    code, out, err = run_cli(capsys, "solve", EXAMPLES / "roller_cam.toml", "--json")
    assert code == 0, err
    u = np.linspace(0, 360, 37) * D
    c, A = polar(15, u), np.array([[60.0], [60.0]])
    F = circles(A, 55, c, 50, -1)
    n, t = F - c, np.array([-(F - A)[1], (F - A)[0]])
    want = deg(np.arctan2(np.abs(n[0] * t[1] - n[1] * t[0]), np.abs((n * t).sum(axis=0))))
    np.testing.assert_allclose(np.array(out["values"]["cam.pressure"], float), want, atol=1e-9)
