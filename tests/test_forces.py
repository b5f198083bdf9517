"""Efforts, shaking forces and joint reactions against independent computations written here:
power balance with closed-form velocities, Newton-Euler per body with closed-form
accelerations (mpmath), -sum m a; reactions balancing every body; exact sensitivities against
central differences."""
from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest

import kincas
from kincas import Input, Link, Load, Mechanism, Slide
from conftest import run_cli, write_scene

mp.mp.dps = 30
G = (0.0, -9.81)


def d(f, x0, order=1):
    return float(mp.diff(f, x0, order))


# --- a four-bar with a coupler point: static efforts by power balance ---

A, D, CR, CO, RO, EX, EY = (0.0, 0.0), (4.0, 0.0), 1.0, 3.5, 3.0, 1.2, 0.8


def fourbar_points(th):
    bx, by = CR * mp.cos(th), CR * mp.sin(th)
    dx, dy = D[0] - bx, D[1] - by
    dd = mp.sqrt(dx ** 2 + dy ** 2)
    a = (CO ** 2 - RO ** 2 + dd ** 2) / (2 * dd)
    h = mp.sqrt(CO ** 2 - a ** 2)
    cx, cy = bx + (a * dx - h * dy) / dd, by + (a * dy + h * dx) / dd
    ux, uy = (cx - bx) / CO, (cy - by) / CO
    return (bx, by), (cx, cy), (bx + EX * ux - EY * uy, by + EX * uy + EY * ux)


def fourbar(**kw):
    return Mechanism(ground={"A": A, "D": D, "S": (1.0, 3.0)},
                     links=[Link.bar("crank", "A", "B", CR),
                            Link("coupler", {"B": (0, 0), "C": (CO, 0), "E": (EX, EY)}),
                            Link.bar("rocker", "D", "C", RO)],
                     inputs=[Input.angle("crank")], guess={"C": (3.6, 2.9)}, **kw)


FORCE, TORQUE, K, D0 = (30.0, -50.0), 7.0, 40.0, 1.5


@pytest.mark.parametrize("th", [0.5, 2.2, 4.4])
def test_static_effort_by_power_balance(th):
    m = fourbar(loads=[Load.force("E", FORCE), Load.torque("rocker", TORQUE), Load.spring("S", "E", K, D0)])
    w = 1.7
    pose = kincas.solve(m, {"crank.angle": th}, rates=w, report=["effort(crank.angle)"])
    pt = lambda i, j: (lambda t: fourbar_points(t)[i][j])
    ex, ey = float(fourbar_points(th)[2][0]), float(fourbar_points(th)[2][1])
    vex, vey = d(pt(2, 0), th) * w, d(pt(2, 1), th) * w
    rocker = lambda t: mp.atan2(fourbar_points(t)[1][1] - D[1], fourbar_points(t)[1][0] - D[0])
    wr = d(rocker, th) * w
    length = math.hypot(ex - 1.0, ey - 3.0)
    dl = ((ex - 1.0) * vex + (ey - 3.0) * vey) / length
    # T w + F.v_E + tau w_r - k (l - l0) l' = 0: no power is left over
    T = -(FORCE[0] * vex + FORCE[1] * vey + TORQUE * wr - K * (length - D0) * dl) / w
    assert abs(pose["effort(crank.angle)"] - T) < 1e-10 * (1 + abs(T))


def test_static_effort_does_not_depend_on_the_rate():
    m = fourbar(loads=[Load.force("E", FORCE)])
    a = kincas.solve(m, {"crank.angle": 1.0}, rates=0.0, report=["effort(crank.angle)"])
    b = kincas.solve(m, {"crank.angle": 1.0}, rates=5.0, accelerations=2.0, report=["effort(crank.angle)"])
    assert abs(a["effort(crank.angle)"] - b["effort(crank.angle)"]) < 1e-10


# --- a slider-crank with masses: inverse dynamics against Newton-Euler per body ---

R, L = 0.08, 0.3
M1, J1, M2, J2, M3 = 1.2, 2e-3, 0.9, 7e-3, 0.6
PLOAD = (-400.0, 0.0)  # on the piston pin P
W, ACC = 150.0, 40.0


def slider_crank(**kw):
    return Mechanism(ground={"A": (0, 0)},
                     links=[Link.bar("crank", "A", "B", R, mass=M1, inertia=J1),
                            Link("block", {"P": (0, 0), "Q": (0.05, 0)}, mass=M3, cg=(0, 0)),
                            Link.bar("rod", "B", "P", L, mass=M2, inertia=J2)],
                     slides=[Slide("P", "ground", name="guide"), Slide("Q", "ground", name="guide2")],
                     inputs=[Input.angle("crank")], guess={"P": (0.38, 0), "Q": (0.43, 0)},
                     gravity=G, loads=[Load.force("P", PLOAD)], **kw)


def sc_closed(t, th0):
    """Positions at time t: crank pin B, piston pin P, rod angle."""
    th = th0 + W * t + ACC * t ** 2 / 2
    bx, by = R * mp.cos(th), R * mp.sin(th)
    px = bx + mp.sqrt(L ** 2 - by ** 2)
    return th, (bx, by), (px, mp.mpf(0)), mp.atan2(-by, px - bx)


def newton_euler_by_hand(th0):
    """Crank torque and the pin forces, body by body, from closed-form accelerations."""
    th, (bx, by), (px, _), phi = (v if not isinstance(v, tuple) else tuple(map(float, v))
                                  for v in sc_closed(0, th0))
    th, phi = float(th), float(phi)
    acc = lambda f: d(lambda t: f(sc_closed(t, th0)), 0, 2)
    a1 = (acc(lambda s: s[1][0] / 2), acc(lambda s: s[1][1] / 2))  # crank's centre, mid A-B
    a2 = (acc(lambda s: (s[1][0] + s[2][0]) / 2), acc(lambda s: (s[1][1] + s[2][1]) / 2))
    a3 = acc(lambda s: s[2][0])
    alpha2 = acc(lambda s: s[3])
    g1, g2 = (bx / 2, by / 2), ((bx + px) / 2, by / 2)
    # block: horizontal forces only from the rod (at P) and the load; the slides push
    # vertically. The load and the slide at P act on the block, the first body declared with P
    Px = M3 * a3 - PLOAD[0]  # force on the block from the rod, x
    # rod: forces -P (from the block) at P, Bf (from the crank) at B, gravity; 3 equations
    # unknowns: Py (on block from rod), Bfx, Bfy
    # x: Bfx - Px = M2 a2x ; y: Bfy - Py + M2 g = M2 a2y
    # moment about G2: (B - G2) x Bf + (P - G2) x (-P) = J2 alpha2
    rb, rp = (bx - g2[0], by - g2[1]), (px - g2[0], -g2[1])
    Amat = np.array([[0, 1, 0], [-1, 0, 1], [-rp[0], -rb[1], rb[0]]])
    rhs = np.array([M2 * a2[0] + Px, M2 * a2[1] - M2 * G[1], J2 * alpha2 - rp[1] * Px])
    # (P - G2) x (-P) = -(rp_x Py - rp_y Px)
    Py, Bfx, Bfy = np.linalg.solve(Amat, rhs)
    # crank: -Bf at B, Af at A, torque T, gravity; moment about A
    T = J1 * ACC + (g1[0] * M1 * a1[1] - g1[1] * M1 * a1[0]) - (g1[0] * M1 * G[1]) + (bx * Bfy - by * Bfx)
    Af = (M1 * a1[0] + Bfx, M1 * a1[1] - M1 * G[1] + Bfy)
    return T, (Bfx, Bfy), (Px, Py), Af


@pytest.mark.parametrize("th0", [0.3, 1.7, 3.9, 5.5])
def test_inverse_dynamics_of_a_slider_crank_against_newton_euler(th0):
    names = ["effort(crank.angle)", "reaction(B, rod).x", "reaction(B, rod).y",
             "reaction(P, block).x", "reaction(P, block).y", "reaction(A, crank).x",
             "reaction(A, crank).y", "reaction(B, crank).x", "reaction(A, ground).y"]
    pose = kincas.solve(slider_crank(), {"crank.angle": th0}, rates=W, accelerations=ACC, report=names)
    T, Bf, Pf, Af = newton_euler_by_hand(th0)
    scale = 1e-9 * (abs(T) + 400 * R)
    assert abs(pose["effort(crank.angle)"] - T) < scale
    assert abs(pose["reaction(B, rod).x"] - Bf[0]) < 1e-9 * 400 and abs(pose["reaction(B, rod).y"] - Bf[1]) < 1e-9 * 400
    assert abs(pose["reaction(P, block).x"] - Pf[0]) < 1e-9 * 400
    assert abs(pose["reaction(P, block).y"] - Pf[1]) < 1e-9 * 400
    assert abs(pose["reaction(A, crank).x"] - Af[0]) < 1e-9 * 400
    assert abs(pose["reaction(A, crank).y"] - Af[1]) < 1e-9 * 400
    assert abs(pose["reaction(B, crank).x"] + Bf[0]) < 1e-9 * 400  # action and reaction
    assert abs(pose["reaction(A, ground).y"] + Af[1]) < 1e-9 * 400


@pytest.mark.parametrize("th0", [0.3, 2.5])
def test_shaking_force_is_minus_sum_of_m_a(th0):
    pose = kincas.solve(slider_crank(), {"crank.angle": th0}, rates=W, accelerations=ACC,
                        report=["shaking.x", "shaking.y", "shaking.moment"])
    acc = lambda f: d(lambda t: f(sc_closed(t, th0)), 0, 2)
    parts = [(M1, lambda s: s[1][0] / 2, lambda s: s[1][1] / 2),
             (M2, lambda s: (s[1][0] + s[2][0]) / 2, lambda s: (s[1][1] + s[2][1]) / 2),
             (M3, lambda s: s[2][0], lambda s: s[2][1])]
    fx = -sum(m * acc(x) for m, x, _ in parts)
    fy = -sum(m * acc(y) for m, _, y in parts)
    mz = -J1 * ACC - J2 * acc(lambda s: s[3])
    for m, x, y in parts:
        s0 = sc_closed(0, th0)
        mz -= m * (float(x(s0)) * acc(y) - float(y(s0)) * acc(x))
    scale = 1e-10 * (M1 + M2 + M3) * R * W ** 2
    assert abs(pose["shaking.x"] - fx) < scale and abs(pose["shaking.y"] - fy) < scale
    assert abs(pose["shaking.moment"] - mz) < scale * L


# --- reactions balance every body: a slotted lever (slide along a moving link) ---


def slotted(**kw):
    return Mechanism(ground={"A": (0, 0), "O": (0.0, -0.5)},
                     links=[Link.bar("crank", "A", "B", 0.2, mass=0.5, inertia=1e-3),
                            Link("lever", {"O": (0, 0), "E": (0.9, 0)}, mass=2.0, inertia=0.1)],
                     slides=[Slide("B", "lever", name="slot")], inputs=[Input.angle("crank")],
                     guess={"E": (0.3, 0.3)}, gravity=G,
                     loads=[Load.force("E", (5.0, -20.0)), Load.torque("lever", 3.0)], **kw)


@pytest.mark.parametrize("th0", [0.4, 2.0, 4.1])
def test_reactions_balance_every_body(th0):
    names = ["reaction(A, crank).x", "reaction(A, crank).y", "reaction(O, lever).x",
             "reaction(O, lever).y", "reaction(slot).x", "reaction(slot).y", "effort(crank.angle)",
             "B.x", "B.y", "E.x", "E.y", "lever.angle", "lever.alpha", "crank.alpha", "B.ax", "B.ay"]
    w = 6.0
    pose = kincas.solve(slotted(), {"crank.angle": th0}, rates=w, accelerations=1.5, report=names)
    p = {k: pose[k] for k in names}
    # crank: pin A, slot force at B, input torque, gravity at its middle, inertia
    gx, gy = p["B.x"] / 2, p["B.y"] / 2
    ax, ay = p["B.ax"] / 2, p["B.ay"] / 2
    fx = p["reaction(A, crank).x"] + p["reaction(slot).x"] - 0.5 * ax
    fy = p["reaction(A, crank).y"] + p["reaction(slot).y"] + 0.5 * G[1] - 0.5 * ay
    mz = (p["B.x"] * p["reaction(slot).y"] - p["B.y"] * p["reaction(slot).x"] + p["effort(crank.angle)"]
          + gx * (0.5 * G[1] - 0.5 * ay) + gy * 0.5 * ax - 1e-3 * p["crank.alpha"])
    assert max(abs(fx), abs(fy), abs(mz)) < 1e-9 * 100
    # lever: pin O, minus the slot force at B, load at E, torque, gravity at its middle, inertia
    th = p["lever.angle"]
    cgx, cgy = 0.45 * math.cos(th), -0.5 + 0.45 * math.sin(th)
    # the lever's centre's acceleration, by hand from its angle, rate and acceleration
    wl = kincas.solve(slotted(), {"crank.angle": th0}, rates=w, accelerations=1.5,
                      report=["lever.omega"])["lever.omega"]
    al = p["lever.alpha"]
    lax = -0.45 * (math.sin(th) * al + math.cos(th) * wl ** 2)
    lay = 0.45 * (math.cos(th) * al - math.sin(th) * wl ** 2)
    fx = p["reaction(O, lever).x"] - p["reaction(slot).x"] + 5.0 - 2.0 * lax
    fy = p["reaction(O, lever).y"] - p["reaction(slot).y"] - 20.0 + 2.0 * (G[1] - lay)
    mz = (0.0 * p["reaction(O, lever).y"] - (-0.5) * p["reaction(O, lever).x"]
          - (p["B.x"] * p["reaction(slot).y"] - p["B.y"] * p["reaction(slot).x"])
          + p["E.x"] * -20.0 - p["E.y"] * 5.0 + 3.0
          + cgx * 2.0 * (G[1] - lay) + cgy * 2.0 * lax - 0.1 * al)
    assert max(abs(fx), abs(fy), abs(mz)) < 1e-9 * 100


def test_effort_sensitivity_is_exact():
    m = Mechanism(parameters={"r": R, "m2": M2},
                  ground={"A": (0, 0)},
                  links=[Link.bar("crank", "A", "B", "r", mass=M1, inertia=J1),
                         Link.bar("rod", "B", "P", L, mass="m2", inertia=J2),
                         Link("block", {"P": (0, 0), "Q": (0.05, 0)}, mass=M3, cg=(0, 0))],
                  slides=[Slide("P", "ground", name="guide"), Slide("Q", "ground", name="guide2")],
                  inputs=[Input.angle("crank")], guess={"P": (0.38, 0), "Q": (0.43, 0)},
                  gravity=G, loads=[Load.force("P", PLOAD)])
    rep = ["effort(crank.angle)", "d(effort(crank.angle))/d(r)", "d(effort(crank.angle))/d(m2)",
           "d(shaking.x)/d(r)"]
    pose = kincas.solve(m, {"crank.angle": 1.1}, rates=W, accelerations=ACC, report=rep)
    for p, h in (("r", 1e-5), ("m2", 1e-4)):
        v = [kincas.solve(m.with_parameters(**{p: m.parameter(p) + s * h}), {"crank.angle": 1.1},
                          rates=W, accelerations=ACC, report=["effort(crank.angle)", "shaking.x"])
             for s in (-1, 1)]
        fd = (v[1]["effort(crank.angle)"] - v[0]["effort(crank.angle)"]) / (2 * h)
        assert abs(pose[f"d(effort(crank.angle))/d({p})"] - fd) < 1e-6 * (1 + abs(fd))
        if p == "r":
            fd = (v[1]["shaking.x"] - v[0]["shaking.x"]) / (2 * h)
            assert abs(pose["d(shaking.x)/d(r)"] - fd) < 1e-6 * (1 + abs(fd))


def test_slide_and_parameter_inputs_take_forces():
    # the same slider-crank driven by its slide: the effort is the force along the guide,
    # and by power balance T w = -F v when the crank is driven instead (statics, no masses)
    base = dict(ground={"A": (0, 0)},
                links=[Link.bar("crank", "A", "B", R), Link.bar("rod", "B", "P", L)],
                slides=[Slide("P", "ground", name="guide")], loads=[Load.torque("crank", 2.0)])
    m = Mechanism(**base, inputs=[Input.slide("guide")], guess={"B": (0.05, 0.06)})
    pose = kincas.solve(m, {"guide.s": 0.33}, report=["effort(guide.s)", "crank.omega"])
    # power: F * 1 + 2.0 * omega_crank = 0
    assert abs(pose["effort(guide.s)"] + 2.0 * pose["crank.omega"]) < 1e-10


def test_bad_force_names_and_scene_fields(capsys, tmp_path):
    with pytest.raises(kincas.ModelError, match="no input"):
        kincas.solve(fourbar(), {"crank.angle": 1.0}, report=["effort(rocker.angle)"])
    with pytest.raises(kincas.ModelError, match="not a joint"):
        kincas.solve(fourbar(), {"crank.angle": 1.0}, report=["reaction(E, coupler).x"])
    with pytest.raises(kincas.ModelError, match=r"\[\[loads\]\] 1: point"):
        fourbar(loads=[Load.force("Z", (1, 0))])
    with pytest.raises(kincas.ModelError, match="mass: must not be negative"):
        Mechanism(ground={"A": (0, 0)}, links=[Link.bar("a", "A", "B", 1, mass=-1)],
                  inputs=[Input.angle("a")])
    scene = {"ground": {"A": [0, 0], "D": [4, 0]},
             "links": {"crank": {"points": ["A", "B"], "length": 1, "mass": "heavy"},
                       "coupler": {"points": ["B", "C"], "length": 3.5},
                       "rocker": {"points": ["D", "C"], "length": 3}},
             "loads": [{"point": "C"}, {"link": "rocker", "torque": 1, "force": [0, 1]}],
             "inputs": [{"angle": "crank", "value": 10}], "guess": {"C": [3.6, 2.9]}}
    code, _, err = run_cli(capsys, "solve", write_scene(tmp_path, scene), "--json")
    assert code == 2
    assert "[links] crank: mass: unknown parameter 'heavy'" in err
    assert "[[loads]] 1: force: missing" in err
    assert "[[loads]] 2: unknown field 'force'" in err


def test_relative_elbow_drive_efforts_and_reactions():
    # two-link arm, elbow motor on the upper arm: static efforts from the moment of the load
    # about each joint (the shoulder carries the whole arm, the elbow the forearm)
    l1, l2, a, b, F = 0.3, 0.25, 0.4, 0.9, (2.0, -30.0)
    m = Mechanism(ground={"S": (0, 0)},
                  links=[Link.bar("upper", "S", "E", l1), Link.bar("forearm", "E", "H", l2, mass=1.5)],
                  inputs=[Input.angle("upper"), Input.angle("forearm/upper")], gravity=G,
                  loads=[Load.force("H", F)])
    names = ["effort(upper.angle)", "effort(forearm/upper.angle)", "reaction(E, forearm).x",
             "reaction(E, forearm).y", "reaction(S, upper).y"]
    pose = kincas.solve(m, {"upper.angle": a, "forearm/upper.angle": b},
                        rates={"upper.angle": 0.0, "forearm/upper.angle": 0.0}, report=names)
    e = np.array([l1 * math.cos(a), l1 * math.sin(a)])
    h = e + l2 * np.array([math.cos(a + b), math.sin(a + b)])
    g2 = (e + h) / 2
    cross = lambda r, f: r[0] * f[1] - r[1] * f[0]
    weight = (0.0, 1.5 * G[1])
    # the motor balances the moment of the loads beyond it: T + r x F = 0
    shoulder = -(cross(h, F) + cross(g2, weight))
    elbow = -(cross(h - e, F) + cross(g2 - e, weight))
    assert abs(pose["effort(upper.angle)"] - shoulder) < 1e-10
    assert abs(pose["effort(forearm/upper.angle)"] - elbow) < 1e-10
    # the forearm hangs on the elbow: the pin carries its weight and the load
    assert abs(pose["reaction(E, forearm).x"] + F[0]) < 1e-10
    assert abs(pose["reaction(E, forearm).y"] + F[1] + weight[1]) < 1e-10
    assert abs(pose["reaction(S, upper).y"] + F[1] + weight[1]) < 1e-10


def test_gear_pair_effort_by_its_ratio_and_reactions_refused(capsys, tmp_path):
    from conftest import EXAMPLES
    import tomllib
    scene = tomllib.loads((EXAMPLES / "geared_fivebar.toml").read_text())
    scene["loads"] = [{"link": "crank2", "torque": 8.0}]
    scene["output"] = {"report": ["effort(crank1.angle)", "crank2.omega"]}
    code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, scene), "--json")
    assert code == 0, err
    # external mesh, r1/r2 = 1/2: crank2 turns back at half the rate; T w1 + 8 w2 = 0
    assert np.allclose(out["values"]["effort(crank1.angle)"], 8.0 * 0.5, rtol=0, atol=1e-10)
    scene["output"] = {"report": ["reaction(B, left).x"]}
    code, _, err = run_cli(capsys, "solve", write_scene(tmp_path, scene), "--json")
    assert code == 2 and "gears, racks or cams" in err


def test_optimize_a_counterweight_over_efforts():
    # a crank carrying its own weight (centre of gravity at cw along it) and a load at its pin:
    # the static torque is (m g cw + F r) cos(theta), zero for cw = -F r / (m g)
    from kincas.optimize import optimize
    mass, r, F = 2.0, 1.0, 5.0
    m = Mechanism(parameters={"cw": 0.3}, ground={"A": (0, 0), "D": (4, 0)},
                  links=[Link("crank", {"A": (0, 0), "B": (r, 0)}, mass=mass, cg=("cw", 0)),
                         Link.bar("coupler", "B", "C", 3.5), Link.bar("rocker", "D", "C", 3)],
                  inputs=[Input.angle("crank")], guess={"C": (3.6, 2.9)}, gravity=G,
                  loads=[Load.force("B", (0, -F))])
    res = optimize(m, {"crank.angle": np.linspace(0.2, 1.4, 7)}, vary={"cw": (-2, 2)},
                   minimize="sum(abs(effort(crank.angle))^2)", rates=0.0)
    assert res.ok, res.message
    assert abs(res.varied["cw"] + F * r / (mass * 9.81)) < 1e-8
