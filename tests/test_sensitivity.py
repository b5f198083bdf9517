"""Exact sensitivities d(Q)/d(p) against central differences of re-solved poses.

Every quantity kind (positions, velocities, accelerations, link angles and their rates, slide
coordinates and their rates) is differentiated with respect to every parameter of mechanisms
where parameters are link lengths, ground coordinates, coordinates in a link's own frame, a
slide's offset and a slide's angle. The reference is a five-point central difference of poses
solved again at perturbed parameter values; kincas's derivatives are not used for it.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism, Slide
from kincas.cli import main
from kincas.cli.scene import load, loads
from kincas.analysis.sensitivity import sensitivities

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
RATES = {"x": "vx", "y": "vy", "angle": "omega", "s": "v"}
ACCS = {"x": "ax", "y": "ay", "angle": "alpha", "s": "a"}
KIND = {"x": "L", "y": "L", "vx": "V", "vy": "V", "ax": "A", "ay": "A", "angle": "th",
        "omega": "w", "alpha": "al", "s": "L", "v": "V", "a": "A"}


def all_quantities(m: Mechanism) -> list[str]:
    """Every position, angle and slide coordinate of `m`, with its velocity and acceleration."""
    base = [f"{p}.{c}" for p in m.moving_points for c in "xy"]
    base += [f"{lk.name}.angle" for lk in m.links] + [f"{s.name}.s" for s in m.slides]
    out = []
    for n in base:
        obj, a = n.rsplit(".", 1)
        out += [n, f"{obj}.{RATES[a]}", f"{obj}.{ACCS[a]}"]
    return out


def central(m, inputs, p, names, rates, accs, rel=1e-4):
    """Five-point central difference in parameter p of every quantity, from poses re-solved
    at p - 2h, p - h, p + h, p + 2h (angles unwrapped against the nominal pose)."""
    v0 = m.parameter(p)
    h = rel * max(abs(v0), 0.01 * m.size())
    nominal = kincas.sweep(m, inputs, rates=rates, accelerations=accs, report=names)
    f = {}
    for k in (-2, -1, 1, 2):
        sw = kincas.sweep(m.with_parameters(**{p: v0 + k * h}), inputs, rates=rates,
                          accelerations=accs, report=names)
        assert all(s == "ok" for s in sw.status) and sw.residual.max() < 1e-12
        f[k] = sw.values
    out = {}
    for n in names:
        g = {k: f[k][n] for k in f}
        if n.endswith(".angle"):
            g = {k: nominal[n] + np.angle(np.exp(1j * (v - nominal[n]))) for k, v in g.items()}
        out[n] = (g[-2] - 8 * g[-1] + 8 * g[1] - g[2]) / (12 * h)
    return out


def check_all(m, inputs, rates=None, accs=None, tol=1e-6):
    """Every d(Q)/d(p) of `m` against central differences; errors are relative to the
    largest sensitivity of the same kind (so quantities that are identically zero count)."""
    driven = {i.target for i in m.inputs if i.kind == "parameter"}
    params = [p for p in m.param_values if p not in driven]
    names = all_quantities(m)
    sens = [f"d({q})/d({p})" for q in names for p in params]
    sw = kincas.sweep(m, inputs, rates=rates, accelerations=accs, report=names + sens)
    assert all(s == "ok" for s in sw.status) and sw.residual.max() < 1e-12
    scale = {}
    for q in names:
        k = KIND[q.rsplit(".", 1)[1]]
        top = max(np.abs(sw[f"d({q})/d({p})"]).max() for p in params)
        scale[k] = max(scale.get(k, 0.0), top)
    checked = 0
    for p in params:
        fd = central(m, inputs, p, names, rates, accs)
        for q in names:
            exact = sw[f"d({q})/d({p})"]
            err = np.abs(exact - fd[q]).max()
            assert err <= tol * scale[KIND[q.rsplit(".", 1)[1]]], (q, p, exact, fd[q])
            checked += 1
    return checked, sw


# --- mechanisms whose parameters sit in every kind of place ---


def coupler_fourbar():
    """Ground coordinate (r1), two-point lengths, and a coupler point in the coupler's frame."""
    return Mechanism(
        parameters={"r1": 100.0, "r2": 30.0, "r3": 90.0, "r4": 80.0, "px": 30.0, "py": 50.0},
        ground={"O2": (0, 0), "O4": ("r1", 0)},
        links=[Link.bar("crank", "O2", "A", "r2"),
               Link("coupler", {"A": (0, 0), "B": ("r3", 0), "P": ("px", "py")}),
               Link.bar("rocker", "O4", "B", "r4")],
        inputs=[Input.angle("crank")], guess={"B": (90, 70)})


def angled_slider_crank(driven="angle"):
    """Offset slider-crank whose guide is tilted by the parameter beta (radians here)."""
    inputs = [Input.angle("crank")] if driven == "angle" else [Input.slide("guide")]
    return Mechanism(parameters={"r": 50.0, "l": 180.0, "e": 20.0, "beta": 0.2},
                     ground={"O": (0, 0)},
                     links=[Link.bar("crank", "O", "A", "r"), Link.bar("rod", "A", "B", "l")],
                     slides=[Slide("B", "ground", through=(0, "e"), angle="beta", name="guide")],
                     inputs=inputs, guess={"B": (200, 50), "A": (30, 40)})


def test_fourbar_every_quantity_and_parameter():
    th = np.radians([10.0, 95.0, 200.0, 290.0])
    n, _ = check_all(coupler_fourbar(), {"crank.angle": th}, rates={"crank.angle": 2.0},
                     accs={"crank.angle": -3.0})
    assert n == 6 * len(all_quantities(coupler_fourbar()))


def test_slider_crank_with_a_tilted_guide():
    th = np.radians([20.0, 135.0, 250.0])
    check_all(angled_slider_crank(), {"crank.angle": th}, rates={"crank.angle": 1.5},
              accs={"crank.angle": 0.5})


def test_slide_input_drives_an_inverted_slider_crank():
    check_all(angled_slider_crank("slide"), {"guide.s": np.array([170.0, 200.0])},
              rates={"guide.s": 30.0}, accs={"guide.s": -4.0})


@pytest.mark.parametrize("example", ["fairbairn", "sixbar", "actuator_bellcrank"])
def test_example_mechanisms(example):
    """Slots in moving links, a ternary link given in local coordinates, a driven parameter."""
    sc = load(EXAMPLES / f"{example}.toml")
    st = sc.study
    inputs = {k: v[:: max(1, len(v) // 3)] for k, v in st.inputs.items()}
    check_all(sc.mechanism, inputs, rates=st.rates, accs=st.accelerations)


def test_a_parameter_used_nowhere_has_zero_sensitivity():
    m = Mechanism(parameters={"a": 1.0, "unused": 3.0}, ground={"A": (0, 0), "D": (4, 0)},
                  links=[Link.bar("crank", "A", "B", "a"), Link.bar("coupler", "B", "C", 3.5),
                         Link.bar("rocker", "D", "C", 3)],
                  inputs=[Input.angle("crank")], guess={"C": (3.6, 2.9)})
    sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 6, 5)},
                      report=["d(C.x)/d(unused)", "d(rocker.omega)/d(unused)", "d(C.x)/d(a)"])
    assert np.all(sw["d(C.x)/d(unused)"] == 0) and np.all(sw["d(rocker.omega)/d(unused)"] == 0)
    assert np.all(np.abs(sw["d(C.x)/d(a)"]) > 0)


def test_angle_sensitivities_are_not_wrapped():
    # A four-bar a thousand times smaller turns its rocker by about a thousand radians per
    # unit of crank length: the derivative must come out as is, not wrapped into (-pi, pi].
    s = 1e-3
    m = Mechanism(parameters={"a": 1.0 * s}, ground={"A": (0, 0), "D": (4 * s, 0)},
                  links=[Link.bar("crank", "A", "B", "a"), Link.bar("coupler", "B", "C", 3.5 * s),
                         Link.bar("rocker", "D", "C", 3 * s)],
                  inputs=[Input.angle("crank")], guess={"C": (3.6 * s, 2.9 * s)})
    th = np.array([0.5])
    sw = kincas.sweep(m, {"crank.angle": th}, report=["d(rocker.angle)/d(a)"])
    fd = central(m, {"crank.angle": th}, "a", ["rocker.angle"], None, None)["rocker.angle"]
    assert abs(sw["d(rocker.angle)/d(a)"][0]) > 10 * math.pi
    assert abs(sw["d(rocker.angle)/d(a)"][0] - fd[0]) < 1e-6 * abs(fd[0])


def test_python_helper_gives_an_array_per_quantity_and_parameter():
    m = coupler_fourbar()
    th = np.radians([30.0, 60.0])
    s = sensitivities(m, {"crank.angle": th}, of=["P.x", "rocker.angle"], to=["r2", "px"])
    assert s.matrix.shape == (2, 2, 2) and s.of == ["P.x", "rocker.angle"] and s.to == ["r2", "px"]
    fd = central(m, {"crank.angle": th}, "px", ["P.x"], None, None)["P.x"]
    assert np.abs(s["P.x", "px"] - fd).max() < 1e-7
    assert np.array_equal(s.matrix[:, 1, 0], s["rocker.angle", "r2"])
    assert s.ok.all()


# --- scenes: the unit rule (degrees per parameter unit), the CLI, the messages ---


def slider_scene(unit: str, beta: float, e: float = 20.0, th: float = 30.0, rate: float = 2.0):
    return f"""
title = "tilted slider-crank"
units = {{ length = "mm", angle = "{unit}", time = "s" }}
[parameters]
r = 50
l = 180
e = {e!r}
beta = {beta!r}
[ground]
O = [0, 0]
[links]
crank = {{ points = ["O", "A"], length = "r" }}
rod = {{ points = ["A", "B"], length = "l" }}
[[slides]]
name = "guide"
point = "B"
along = "ground"
line = {{ through = [0, "e"], angle = "beta" }}
[[inputs]]
angle = "crank"
value = {th!r}
rate = {rate!r}
[guess]
B = [200, 50]
[output]
report = ["B.x", "rod.angle", "rod.omega", "guide.s", "guide.v"]
sensitivity = {{ of = ["B.x", "rod.angle", "rod.omega", "guide.s", "guide.v"], to = ["beta", "e"] }}
"""


def run_json(capsys, tmp_path, text):
    path = tmp_path / "scene.toml"
    path.write_text(text, encoding="utf-8")
    capsys.readouterr()
    code = main(["solve", str(path), "--json"])
    out, err = capsys.readouterr()
    return code, (json.loads(out) if out.strip() else None), err


@pytest.mark.parametrize("unit", ["deg", "rad"])
def test_scene_sensitivities_in_the_scene_units(capsys, tmp_path, unit):
    """In a scene, d(Q)/d(p) is in Q's unit per p's unit: degrees per degree of a guide angle
    given in degrees, radians per mm in a radian scene. Checked against central differences
    of the values the CLI itself prints for re-solved scenes."""
    k = 1.0 if unit == "rad" else 180 / math.pi
    beta, th, rate = 0.2 * k, 0.5 * k, 2.0 * k
    code, doc, _ = run_json(capsys, tmp_path, slider_scene(unit, beta, th=th, rate=rate))
    assert code == 0 and doc["status"] == ["ok"]
    vals = {n: v[0] for n, v in doc["values"].items()}
    for p, v0 in (("beta", beta), ("e", 20.0)):
        h = 1e-4 * max(1.0, abs(v0))
        f = []
        for step in (-2, -1, 1, 2):
            kw = {"beta": beta, "e": 20.0}
            kw[p] = v0 + step * h
            _, d, _ = run_json(capsys, tmp_path, slider_scene(unit, kw["beta"], kw["e"], th, rate))
            f.append({n: v[0] for n, v in d["values"].items()})
        for q in ("B.x", "rod.angle", "rod.omega", "guide.s", "guide.v"):
            fd = (f[0][q] - 8 * f[1][q] + 8 * f[2][q] - f[3][q]) / (12 * h)
            assert abs(vals[f"d({q})/d({p})"] - fd) <= 1e-6 * max(1.0, abs(fd)), (unit, q, p)


def test_degree_and_radian_scenes_agree_by_the_unit_factors():
    k = 180 / math.pi
    deg = loads(slider_scene("deg", 0.2 * k, th=0.5 * k, rate=2.0 * k))
    rad = loads(slider_scene("rad", 0.2, th=0.5, rate=2.0))
    d = {n: v[0] for n, v in deg.user_values(deg.run()).items()}
    r = {n: v[0] for n, v in rad.user_values(rad.run()).items()}
    # d(length)/d(beta): mm per degree = mm per radian / k; d(angle)/d(e): deg/mm = k rad/mm;
    # d(angle)/d(beta): the same number in both; d(omega)/d(e): k per mm.
    assert d["d(B.x)/d(beta)"] == pytest.approx(r["d(B.x)/d(beta)"] / k, rel=1e-12)
    assert d["d(guide.v)/d(beta)"] == pytest.approx(r["d(guide.v)/d(beta)"] / k, rel=1e-12)
    assert d["d(rod.angle)/d(e)"] == pytest.approx(r["d(rod.angle)/d(e)"] * k, rel=1e-12)
    assert d["d(rod.angle)/d(beta)"] == pytest.approx(r["d(rod.angle)/d(beta)"], rel=1e-12)
    assert d["d(rod.omega)/d(e)"] == pytest.approx(r["d(rod.omega)/d(e)"] * k, rel=1e-12)


def test_bad_sensitivity_names_are_scene_errors(capsys, tmp_path):
    text = slider_scene("deg", 10.0).replace('to = ["beta", "e"]', 'to = ["beta", "nope"]')
    code, doc, err = run_json(capsys, tmp_path, text)
    assert code == 2 and doc is None
    assert "[output] sensitivity: to" in err and "nope" in err and "Traceback" not in err
