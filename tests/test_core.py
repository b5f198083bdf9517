"""The Python API against independent answers: closed forms, central differences of solved
positions (tests only), residuals after every solve."""
import math

import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism, ModelError, Slide


# --- independent answers ---


def fourbar_closed(theta, a, b, c, d, sign=+1):
    """Crank a at A=(0,0), coupler b, rocker c at D=(d,0): C by circle intersection."""
    B = np.stack([a * np.cos(theta), a * np.sin(theta)])
    D = np.array([[d], [0.0]])
    e = D - B
    r = np.linalg.norm(e, axis=0)
    x = (b * b - c * c + r * r) / (2 * r)
    with np.errstate(invalid="ignore"):  # NaN where the loop cannot close
        h = np.sqrt(b * b - x * x)
    e = e / r
    return B + x * e + sign * h * np.stack([-e[1], e[0]])


def fourbar(a=1.0, b=3.5, c=3.0, d=4.0, s=1.0, guess=(3.6, 2.9)):
    return Mechanism(parameters={"a": a * s, "b": b * s, "c": c * s},
                     ground={"A": (0, 0), "D": (d * s, 0)},
                     links=[Link.bar("crank", "A", "B", "a"), Link.bar("coupler", "B", "C", "b"),
                            Link.bar("rocker", "D", "C", "c")],
                     inputs=[Input.angle("crank")], guess={"C": (guess[0] * s, guess[1] * s)})


def assert_residuals(sw, tol=1e-12):
    """Every solved pose really closes its loops (checked again, independently of the solver)."""
    model = kincas.model_of(MECH_OF[id(sw)]) if id(sw) in MECH_OF else None
    assert np.all(sw.residual[sw.ok] <= tol), sw.residual[sw.ok].max()
    if model is not None:
        m = MECH_OF[id(sw)]
        p = np.array([v for _, v in m.parameters])
        U = np.stack([sw.inputs[i.key] for i in m.inputs], axis=1)
        for k in np.flatnonzero(sw.ok):
            r = np.abs(model.residual(sw.q[k], U[k], p)).max() / m.size()
            assert r <= tol


MECH_OF = {}


def run(m, inputs, **kw):
    sw = kincas.sweep(m, inputs, **kw)
    MECH_OF[id(sw)] = m
    assert_residuals(sw)
    return sw


# --- positions ---


def test_fourbar_matches_circle_intersection_over_a_turn():
    th = np.linspace(-np.pi, np.pi, 181)
    sw = run(fourbar(), {"crank.angle": th}, report=["C.x", "C.y", "B.x", "coupler.angle"])
    C = fourbar_closed(th, 1, 3.5, 3, 4)
    assert all(s == "ok" for s in sw.status)
    assert np.abs(sw["C.x"] - C[0]).max() < 1e-12 * 4
    assert np.abs(sw["C.y"] - C[1]).max() < 1e-12 * 4
    ang = np.arctan2(C[1] - np.sin(th), C[0] - np.cos(th))
    assert np.abs(np.angle(np.exp(1j * (sw["coupler.angle"] - ang)))).max() < 1e-12


def test_guess_picks_the_branch():
    th = np.linspace(0, 2 * np.pi, 37)
    up = run(fourbar(), {"crank.angle": th}, report=["C.y"])
    down = run(fourbar(guess=(3.6, -2.9)), {"crank.angle": th}, report=["C.y"])
    assert np.allclose(up["C.y"], fourbar_closed(th, 1, 3.5, 3, 4, +1)[1], atol=1e-12)
    assert np.allclose(down["C.y"], fourbar_closed(th, 1, 3.5, 3, 4, -1)[1], atol=1e-12)


@pytest.mark.parametrize("scale", [1e-6, 1.0, 1e6])
def test_same_angles_at_every_scale(scale):
    th = np.linspace(0, 2 * np.pi, 73)
    sw = run(fourbar(s=scale), {"crank.angle": th}, report=["rocker.angle", "coupler.angle", "C.x"])
    ref = run(fourbar(), {"crank.angle": th}, report=["rocker.angle", "coupler.angle", "C.x"])
    for q in ("rocker.angle", "coupler.angle"):
        assert np.abs(np.degrees(sw[q] - ref[q])).max() < 1e-9
    assert np.abs(sw["C.x"] / scale - fourbar_closed(th, 1, 3.5, 3, 4)[0]).max() < 1e-12 * 4


def test_unguessed_points_are_placed_by_the_solver():
    m = Mechanism(ground={"A": (0, 0), "D": (4, 0)},
                  links=[Link.bar("crank", "A", "B", 1), Link.bar("coupler", "B", "C", 3.5),
                         Link.bar("rocker", "D", "C", 3)], inputs=[Input.angle("crank")])
    pose = kincas.solve(m, {"crank.angle": 0.3}, report=["C.x", "C.y"])
    assert pose.ok
    C = [fourbar_closed(np.array([0.3]), 1, 3.5, 3, 4, s)[:, 0] for s in (1, -1)]
    assert min(math.dist((pose["C.x"], pose["C.y"]), c) for c in C) < 1e-12


def test_ipopt_fallback_from_a_poor_guess():
    # A guess far outside the reachable workspace: Newton's trust region alone may stall,
    # the least-squares assembly (IPOPT) finds the nearest real one.
    m = fourbar(guess=(40.0, 35.0))
    pose = kincas.solve(m, {"crank.angle": 1.0}, report=["C.x", "C.y"])
    assert pose.ok and pose.residual < 1e-12
    C = fourbar_closed(np.array([1.0]), 1, 3.5, 3, 4, +1)[:, 0]
    assert math.dist((pose["C.x"], pose["C.y"]), C) < 1e-12


def test_out_of_range_poses_are_data_and_the_rest_keep_their_numbers():
    # Non-Grashof (1, 1.9, 3, 4): the crank cannot turn fully; poses past the limits fail.
    m = fourbar(a=1.0, b=1.9, c=3.0, d=4.0, guess=(3.2, 2.5))
    th = np.radians(np.arange(0, 181, 5.0))
    sw = run(m, {"crank.angle": th}, report=["C.x", "C.y"])
    C = fourbar_closed(th, 1, 1.9, 3, 4)
    feasible = np.all(np.isfinite(C), axis=0)
    assert feasible.any() and (~feasible).any()
    assert np.array_equal(sw.ok, feasible)
    assert all(s == "no assembly" for s, f in zip(sw.status, feasible) if not f)
    assert np.all(np.isnan(sw["C.x"][~feasible]))
    assert np.abs(sw["C.x"][feasible] - C[0][feasible]).max() < 1e-10


# --- velocities and accelerations against central differences of solved positions ---


def central(m, key, u, h, names, rates=None):
    sw = run(m, {key: np.array([u - h, u, u + h])}, report=names)
    assert all(s == "ok" for s in sw.status)
    return {n: sw[n] for n in names}


def check_derivatives(m, key, u, pos_names, rate=1.7, acc=-0.6, h=1e-4):
    vel = {"x": "vx", "y": "vy", "angle": "omega", "s": "v"}
    accn = {"x": "ax", "y": "ay", "angle": "alpha", "s": "a"}
    names = []
    for n in pos_names:
        obj, attr = n.rsplit(".", 1)
        names += [n, f"{obj}.{vel[attr]}", f"{obj}.{accn[attr]}"]
    pose = kincas.solve(m, {key: u}, rates={key: rate}, accelerations={key: acc}, report=names)
    assert pose.ok
    c1 = central(m, key, u, h, pos_names)
    c2 = central(m, key, u, 1e-3 * max(1.0, abs(u)) if "angle" not in key else 1e-3, pos_names)
    for n in pos_names:
        obj, attr = n.rsplit(".", 1)
        f1 = np.unwrap(c1[n]) if attr == "angle" else c1[n]
        f2 = np.unwrap(c2[n]) if attr == "angle" else c2[n]
        hh = 1e-3 * max(1.0, abs(u)) if "angle" not in key else 1e-3
        d1 = (f1[2] - f1[0]) / (2 * h)
        d2 = (f2[2] - 2 * f2[1] + f2[0]) / hh ** 2
        v, a = pose[f"{obj}.{vel[attr]}"], pose[f"{obj}.{accn[attr]}"]
        scale_v = max(abs(d1 * rate), 1e-3 * m.size())
        assert abs(v - d1 * rate) <= 1e-6 * scale_v, (n, v, d1 * rate)
        a_ref = d2 * rate ** 2 + d1 * acc
        assert abs(a - a_ref) <= 1e-6 * max(abs(a_ref), 1e-2 * m.size()), (n, a, a_ref)


def test_fourbar_velocities_and_accelerations():
    check_derivatives(fourbar(), "crank.angle", 0.7, ["C.x", "C.y", "rocker.angle", "coupler.angle"])


def offset_slider_crank(driven="angle"):
    inputs = [Input.angle("crank")] if driven == "angle" else [Input.slide("guide")]
    return Mechanism(ground={"O": (0, 0)},
                     links=[Link.bar("crank", "O", "A", 50), Link.bar("rod", "A", "B", 180)],
                     slides=[Slide("B", "ground", through=(0, 20), angle=0.0, name="guide")],
                     inputs=inputs, guess={"B": (200, 20)})


def test_slider_crank_closed_form_and_derivatives():
    th = np.linspace(0, 2 * np.pi, 91)
    sw = run(offset_slider_crank(), {"crank.angle": th}, report=["B.x", "B.y", "guide.s", "rod.angle"])
    x = 50 * np.cos(th) + np.sqrt(180 ** 2 - (20 - 50 * np.sin(th)) ** 2)
    assert np.abs(sw["B.x"] - x).max() < 1e-12 * 230
    assert np.abs(sw["B.y"] - 20).max() < 1e-12 * 230
    assert np.abs(sw["guide.s"] - x).max() < 1e-12 * 230
    check_derivatives(offset_slider_crank(), "crank.angle", 1.1, ["B.x", "rod.angle", "guide.s"])


def test_slide_input_drives_the_slider_back_to_the_crank():
    # Inverse slider-crank: the slide coordinate is the input, the crank angle follows.
    m = offset_slider_crank("slide").with_guess(A=(40, 30))
    s = np.linspace(150, 220, 15)
    sw = run(m, {"guide.s": s}, report=["crank.angle", "B.x"])
    assert all(st == "ok" for st in sw.status)
    th = sw["crank.angle"]
    x = 50 * np.cos(th) + np.sqrt(180 ** 2 - (20 - 50 * np.sin(th)) ** 2)
    assert np.abs(x - s).max() < 1e-10
    check_derivatives(m, "guide.s", 190.0, ["crank.angle", "B.x"])


def test_floating_link_and_parameter_input():
    # An actuator (two-point link whose length is a driven parameter) pushes a bell crank
    # pivoted at the ground; a floating block slides on a ground line (two slides) and
    # carries a vertical slot in which the bell crank's pin K runs.
    m = Mechanism(parameters={"stroke": 300.0},
                  ground={"O": (0, 0), "P": (250, 150)},
                  links=[Link.bar("actuator", "O", "E", "stroke"),
                         Link("bell", {"P": (0, 0), "E": (-100, 0), "K": (0, 120)}),
                         Link("block", {"K2": (0, 0), "K3": (50, 0)})],
                  slides=[Slide("K2", "ground", through=(0, 300), name="s1"),
                          Slide("K3", "ground", through=(0, 300), name="s2"),
                          Slide("K", "block", angle=math.pi / 2, name="pin")],
                  inputs=[Input.parameter("stroke")],
                  guess={"E": (150, 120), "K": (240, 270), "K2": (240, 300), "K3": (290, 300)})
    assert m.mobility == 0  # rigid count; the driven length is the one freedom
    L = np.linspace(260, 320, 13)
    sw = run(m, {"stroke": L}, report=["E.x", "E.y", "K.x", "K.y", "bell.angle", "K2.x", "K2.y",
                                       "block.angle", "pin.s"])
    assert all(s == "ok" for s in sw.status)
    # Independent check: E is where the circle about O (radius stroke) meets the circle
    # about P (radius 100); in the bell's frame E = (-100, 0) and K = (0, 120), so
    # K - P is E - P turned by -90 degrees and scaled by 1.2.
    for Li, ex, ey in zip(L, sw["E.x"], sw["E.y"]):
        assert abs(math.hypot(ex, ey) - Li) < 1e-10 and abs(math.hypot(ex - 250, ey - 150) - 100) < 1e-10
    kx = 250 + 1.2 * (sw["E.y"] - 150)
    ky = 150 - 1.2 * (sw["E.x"] - 250)
    assert np.abs(sw["K.x"] - kx).max() < 1e-10 and np.abs(sw["K.y"] - ky).max() < 1e-10
    assert np.abs(sw["K2.x"] - kx).max() < 1e-10 and np.abs(sw["K2.y"] - 300).max() < 1e-10
    assert np.abs(sw["block.angle"]).max() < 1e-12
    assert np.abs(sw["pin.s"] - (ky - 300)).max() < 1e-10
    check_derivatives(m.with_parameters(stroke=290.0), "stroke", 290.0, ["E.x", "bell.angle", "K2.x"])


# --- declarations ---


def test_mechanisms_are_values():
    m = fourbar()
    m2 = m.with_parameters(a=1.2)
    assert m.parameter("a") == 1.0 and m2.parameter("a") == 1.2 and m != m2
    assert m == fourbar() and hash(m) == hash(fourbar())
    with pytest.raises(AttributeError):
        m.links = ()


def test_every_problem_is_reported_at_once():
    with pytest.raises(ModelError) as e:
        Mechanism(ground={"A": (0, 0)},
                  links=[Link.bar("crank", "A", "B", "nolength"), Link.bar("rod", "B", "C", 2)],
                  slides=[Slide("C", "nobody")], inputs=[Input.angle("crank")],
                  guess={"Z": (0, 0)})
    text = str(e.value)
    for part in ("[links] crank", "nolength", "[[slides]]", "nobody", "[guess] Z"):
        assert part in text


def test_mobility_mismatch_states_both_numbers():
    # Too many inputs for the count may still be right (a redundant joint): the rank test
    # decides at the first solve, not when the mechanism is declared (it once raised there).
    m = Mechanism(ground={"A": (0, 0), "D": (4, 0)},
                  links=[Link.bar("crank", "A", "B", 1), Link.bar("coupler", "B", "C", 3.5),
                         Link.bar("rocker", "D", "C", 3)],
                  inputs=[Input.angle("crank"), Input.angle("rocker")])
    with pytest.raises(ModelError) as e:
        kincas.sweep(m, {"crank.angle": [0.1], "rocker.angle": [1.2]})
    assert "1 degree(s) of freedom" in str(e.value) and "2 input(s)" in str(e.value)


def test_unknown_quantity_is_an_error_before_solving():
    with pytest.raises(ModelError, match="C.zz"):
        kincas.sweep(fourbar(), {"crank.angle": [0.0]}, report=["C.zz"])
