"""Optimisation by IPOPT against independent answers.

Function generation against Freudenstein's exact three-point solution; path synthesis
against targets made by a closed-form four-bar (circle intersection, numpy only), and the
shipped example against central differences of its objective re-solved by kincas.sweep
(a local minimum: zero gradient inside the bounds, no better neighbour); the slider-crank
against its closed-form stroke and transmission angle, solved with scipy's brentq.
Designs that do not assemble, infeasible problems and bad sections must be reported.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

import kincas
from kincas import Input, Link, Mechanism, ModelError, Slide
from kincas.cli import main
from kincas.synthesis.expressions import parse
from kincas.cli.scene_optimize import run_scene
from kincas.synthesis.optimize import Constraint, Curve, optimize
from kincas.cli.scene import load, loads

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


# --- independent answers ---


def freudenstein(phi, psi, d):
    """Crank a, coupler b, rocker c through three precision points (radians), ground d:
    K1 cos(psi) - K2 cos(phi) + K3 = cos(phi - psi), K1 = d/a, K2 = d/c,
    K3 = (a^2 - b^2 + c^2 + d^2) / (2 a c)."""
    A = np.stack([np.cos(psi), -np.cos(phi), np.ones(3)], axis=1)
    K = np.linalg.solve(A, np.cos(phi - psi))
    a, c = d / K[0], d / K[1]
    return a, math.sqrt(a * a + c * c + d * d - 2 * a * c * K[2]), c


def coupler_point(th, r1, r2, r3, r4, px, py):
    """P of the four-bar O2 = (0, 0), O4 = (r1, 0), crank r2, coupler A-B r3 carrying P at
    (px, py) in its frame, rocker r4, branch with B above the line A-O4."""
    ax, ay = r2 * np.cos(th), r2 * np.sin(th)
    ex, ey = r1 - ax, -ay
    r = np.hypot(ex, ey)
    x = (r3 * r3 - r4 * r4 + r * r) / (2 * r)
    h = np.sqrt(r3 * r3 - x * x)
    bx, by = ax + (x * ex - h * ey) / r, ay + (x * ey + h * ex) / r
    c, s = (bx - ax) / r3, (by - ay) / r3
    return ax + c * px - s * py, ay + s * px + c * py


def fourbar(a, b, c, d=100.0, guess=(60.0, 110.0)):
    return Mechanism(parameters={"a": a, "b": b, "c": c}, ground={"O": (0, 0), "D": (d, 0)},
                     links=[Link.bar("crank", "O", "B", "a"), Link.bar("coupler", "B", "C", "b"),
                            Link.bar("rocker", "D", "C", "c")],
                     inputs=[Input.angle("crank")], guess={"C": guess})


def coupler_fourbar(r1=100.0, r2=30.0, r3=90.0, r4=80.0, px=30.0, py=50.0):
    return Mechanism(parameters={"r1": r1, "r2": r2, "r3": r3, "r4": r4, "px": px, "py": py},
                     ground={"O2": (0, 0), "O4": ("r1", 0)},
                     links=[Link.bar("crank", "O2", "A", "r2"),
                            Link("coupler", {"A": (0, 0), "B": ("r3", 0), "P": ("px", "py")}),
                            Link.bar("rocker", "O4", "B", "r4")],
                     inputs=[Input.angle("crank")], guess={"B": (90, 70)})


PATH_VARY = {"r1": (40, 200), "r2": (10, 60), "r3": (30, 200), "r4": (30, 200),
             "px": (-100, 150), "py": (-100, 150)}


# --- function generation ---


def test_freudenstein_three_points_exactly():
    phi = np.radians([40.0, 75.0, 110.0])
    psi = np.radians([70.0, 82.0, 100.0])
    a, b, c = freudenstein(phi, psi, 4.0)
    m = Mechanism(parameters={"a": 1.2 * a, "b": 0.9 * b, "c": 1.1 * c},
                  ground={"A": (0, 0), "D": (4.0, 0)},
                  links=[Link.bar("crank", "A", "B", "a"), Link.bar("coupler", "B", "C", "b"),
                         Link.bar("rocker", "D", "C", "c")],
                  inputs=[Input.angle("crank")], guess={"C": (2.8, 3.4)})
    r = optimize(m, {"crank.angle": phi}, vary={"a": (0.1, 10), "b": (0.1, 20), "c": (0.1, 20)},
                 minimize="sum((rocker.angle - psi)^2)", data={"psi": psi}, tol=1e-14)
    assert r.ok and r.converged and r.problems == []
    assert r.varied["a"] == pytest.approx(a, rel=1e-10)
    assert r.varied["b"] == pytest.approx(b, rel=1e-10)
    assert r.varied["c"] == pytest.approx(c, rel=1e-10)
    assert r.objective < 1e-24 and r.initial_objective > 1e-3
    # the optimised mechanism is a new value that solves to the precision points
    sw = kincas.sweep(r.mechanism, {"crank.angle": phi}, report=["rocker.angle"])
    assert np.abs(sw["rocker.angle"] - psi).max() < 1e-10
    assert m.parameter("a") == 1.2 * a  # the original is untouched


@pytest.mark.parametrize("unit", ["deg", "rad"])
def test_function_generation_example_in_both_units(capsys, unit):
    text = (EXAMPLES / "synthesis_function.toml").read_text(encoding="utf-8")
    sc = loads(text)
    opt = sc.study.raw["optimize"]
    phi, psi = np.radians(opt["samples"]), np.radians(opt["data"]["psi"])
    a, b, c = freudenstein(phi, psi, 100.0)
    if unit == "rad":  # the same study written in radians
        k = math.pi / 180
        lines = []
        for line in text.replace('angle = "deg"', 'angle = "rad"').splitlines():
            if line.startswith("samples = "):
                line = "samples = " + json.dumps(list(phi))
            elif line.startswith("data = "):
                line = "data = { psi = " + json.dumps(list(psi)) + " }"
            elif line.startswith("sweep = "):
                line = f"sweep = {{ from = {105 * k!r}, to = {195 * k!r}, steps = 31 }}"
            lines.append(line)
        text = "\n".join(lines)
        sc = loads(text)
        assert sc.study.units["angle"] == "rad" and sc.study.raw["optimize"]["data"]["psi"][0] < 2
    r = run_scene(sc)
    assert r.ok
    for name, v in (("a", a), ("b", b), ("c", c)):
        assert r.varied[name] == pytest.approx(v, rel=1e-8), name


# --- path synthesis ---


def test_path_synthesis_recovers_a_reachable_target():
    th = np.radians(np.arange(0.0, 360.0, 30.0))
    ref = dict(r1=120.0, r2=25.0, r3=100.0, r4=90.0, px=40.0, py=40.0)
    tx, ty = coupler_point(th, **ref)
    r = optimize(coupler_fourbar(), {"crank.angle": th}, vary=PATH_VARY,
                 minimize="sum((P.x - tx)^2 + (P.y - ty)^2)", data={"tx": tx, "ty": ty})
    assert r.ok and r.objective < 1e-16 and r.initial_objective > 1000
    for k, v in ref.items():
        assert r.varied[k] == pytest.approx(v, rel=1e-7), k
    # the optimised values through the closed form, not through kincas
    x, y = coupler_point(th, **r.varied)
    assert np.abs(x - tx).max() < 1e-7 and np.abs(y - ty).max() < 1e-7
    assert np.allclose(r.values["P.x"], tx, atol=1e-7)


def test_path_example_is_a_local_minimum_of_the_re_solved_objective():
    sc = load(EXAMPLES / "synthesis_path.toml")
    r = run_scene(sc)
    assert r.ok and r.objective < 0.05
    opt = sc.study.raw["optimize"]
    tx, ty = np.array(opt["data"]["tx"]), np.array(opt["data"]["ty"])
    th = sc.study.inputs["crank.angle"]

    def objective(**p):  # re-solved by kincas.sweep from the optimised branch
        m = r.mechanism.with_parameters(**p)
        sw = kincas.sweep(m, {"crank.angle": th}, report=["P.x", "P.y"])
        assert all(s == "ok" for s in sw.status)
        return float(np.sum((sw["P.x"] - tx) ** 2 + (sw["P.y"] - ty) ** 2))

    f0 = objective()
    assert f0 == pytest.approx(r.objective, rel=1e-9)
    # x, y of the closed form at the optimum agree with kincas's own report of it
    x, y = coupler_point(th, **r.varied)
    assert np.sum((x - tx) ** 2 + (y - ty) ** 2) == pytest.approx(f0, rel=1e-9)
    h = 1e-4
    for p, v in r.varied.items():
        lo, hi = PATH_VARY[p]
        if lo + 1e-6 < v < hi - 1e-6:
            g = (objective(**{p: v + h}) - objective(**{p: v - h})) / (2 * h)
            assert abs(g) < 1e-6, (p, g)  # zero gradient
        for step in (-1e-2, 1e-2):
            if lo <= v + step <= hi:
                assert objective(**{p: v + step}) >= f0  # no better neighbour


# --- slider-crank: stroke and transmission angle over the whole cycle ---


def stroke(r, l, e):
    return math.sqrt((l + r) ** 2 - e * e) - math.sqrt((l - r) ** 2 - e * e)


def test_slider_crank_stroke_and_transmission_angle_over_the_cycle():
    sc = load(EXAMPLES / "synthesis_slider.toml")
    r = run_scene(sc)
    assert r.ok
    e, S, mu = 20.0, 100.0, math.radians(40.0)
    # Closed form: both constraints active; worst transmission where sin(phi) = (r + e) / l
    r0 = brentq(lambda x: stroke(x, (x + e) / math.cos(mu), e) - S, 10, 100, xtol=1e-14)
    assert r.varied["r"] == pytest.approx(r0, rel=1e-9)
    assert r.varied["l"] == pytest.approx((r0 + e) / math.cos(mu), rel=1e-9)
    assert stroke(r.varied["r"], r.varied["l"], e) == pytest.approx(S, rel=1e-10)
    ext = {(x["kind"], x["expr"]): x for x in r.extremes}
    top = ext[("max", "slider.s")]
    assert top["value"] == pytest.approx(math.sqrt((r.varied["l"] + r.varied["r"]) ** 2 - e * e),
                                         rel=1e-10)
    worst = ext[("min", "90 - abs(rod.angle)")]
    assert worst["value"] == pytest.approx(40.0, abs=1e-8)
    assert worst["input"] == pytest.approx(1.5 * math.pi, abs=1e-6)  # crank at 270 deg


def test_per_sample_constraint_holds_at_every_sample():
    m = Mechanism(parameters={"r": 40.0, "l": 150.0, "e": 20.0}, ground={"O": (0, 0)},
                  links=[Link.bar("crank", "O", "A", "r"), Link.bar("rod", "A", "B", "l")],
                  slides=[Slide("B", "ground", through=(0, "e"), name="slider")],
                  inputs=[Input.angle("crank")], guess={"B": (180, 20)})
    th = np.radians(np.arange(0.0, 360.0, 15.0))
    r = optimize(m, {"crank.angle": th}, vary={"l": (50, 400)}, minimize="l",
                 constraints=[Constraint("90 - abs(rod.angle)", min=50.0)], deg=True)
    assert r.ok
    # the worst sample is the crank at 270 deg (a sample): sin(phi) = (r + e) / l
    assert r.varied["l"] == pytest.approx(60.0 / math.cos(math.radians(50.0)), rel=1e-9)
    v = r.constraints[0]["value"]
    assert len(v) == len(th) and v.min() >= 50.0 - 1e-9
    phi = np.arcsin((20.0 - 40.0 * np.sin(th)) / r.varied["l"])
    assert np.allclose(v, 90.0 - np.degrees(np.abs(phi)), atol=1e-8)


def test_an_extreme_that_moves_is_tracked_again_where_it_went():
    # E = B.y - t B.x = a (sin th - t cos th) over crank angles 0..120 deg: for t = 1 its
    # maximum is at the end of the range (120 deg); for t = -1 it is inside, at 45 deg,
    # a sqrt(1 + t^2). The optimiser moves t from 1 to -1, so the extreme it tracked at the
    # end is no longer the maximum: a second round must find it inside.
    m = Mechanism(parameters={"a": 1.0, "t": 1.0}, ground={"A": (0, 0), "D": (4, 0)},
                  links=[Link.bar("crank", "A", "B", "a"), Link.bar("coupler", "B", "C", 3.5),
                         Link.bar("rocker", "D", "C", 3)],
                  inputs=[Input.angle("crank")], guess={"C": (3.6, 2.9)})
    r = optimize(m, {"crank.angle": np.radians([0.0, 60.0, 120.0])}, vary={"t": (-2.0, 2.0)},
                 minimize="(t + 1)^2", constraints=[("max(B.y - t * B.x)", None, 10.0)])
    assert r.ok and r.info["rounds"] == 2
    assert r.varied["t"] == pytest.approx(-1.0, abs=1e-9)
    (e,) = r.extremes
    assert e["value"] == pytest.approx(math.sqrt(2.0), rel=1e-12)
    assert e["input"] == pytest.approx(math.pi / 4, abs=1e-9)
    assert r.mechanism.parameter("t") == pytest.approx(-1.0, abs=1e-9)


# --- designs that must not be called optimal ---


def test_a_design_that_cannot_turn_between_samples_is_reported():
    # samples at 0 and 360 deg only; the longest crank allowed cannot pass 180 deg
    m = fourbar(1.0, 3.5, 3.0, 4.0, guess=(3.6, 2.9))
    r = optimize(m, {"crank.angle": np.radians([0.0, 360.0])}, vary={"a": (0.5, 3.0)},
                 minimize="-a")
    assert r.converged and not r.ok
    assert r.varied["a"] == pytest.approx(3.0)
    assert any("does not assemble on the way to sample 2" in p for p in r.problems)
    assert r.message.startswith("not optimal")
    # told not to check the way between samples, the samples alone are fine
    assert optimize(m, {"crank.angle": np.radians([0.0, 360.0])}, vary={"a": (0.5, 3.0)},
                    minimize="-a", check_path=False).ok


def test_an_infeasible_problem_is_not_converged():
    sc = load(EXAMPLES / "synthesis_slider.toml")
    sc.study.raw["optimize"]["constraints"][0]["min"] = 1000.0
    sc.study.raw["optimize"]["constraints"][0]["max"] = 1000.0
    r = run_scene(sc)
    assert not r.converged and not r.ok and r.message.startswith("IPOPT")


# --- the expression language ---


@pytest.mark.parametrize("text, words", [
    ("__import__('os').system('true')", ["not allowed"]),
    ("sum(C.x) > 1", ["not allowed"]),
    ("lambda: 1", ["not allowed"]),
    ("C.x.y", ["not a quantity name"]),
    ("foo(C.x)", ["unknown function 'foo'"]),
    ("sum(sum(C.x))", ["inside"]),
    ("sum(C.x) + C.y", ["mixes values per sample with totals"]),
    ("C.x", ["wrap it in sum()"]),
    ("sum(C.zz)", ["C.zz"]),
    ("sum(C.x * zz)", ["unknown name 'zz'"]),
    ("max(C.x - tx)", ["data arrays"]),
    ("sum(C.x", ["cannot read"]),
])
def test_bad_expressions_name_the_field(text, words):
    m = fourbar(80, 110, 110)
    with pytest.raises(ModelError) as e:
        optimize(m, {"crank.angle": [2.0, 2.5]}, vary={"a": (10, 300)}, minimize=text,
                 data={"tx": [1.0, 2.0]})
    for w in words:
        assert w in str(e.value), str(e.value)
    assert "minimize" in str(e.value)


def test_power_by_caret_and_constants():
    e = parse("sum((C.x - 2)^2) * pi + a ** 2", "minimize")
    assert e.quantities == ["C.x"] and e.names == ["a"]


# --- the scene section and the command line ---


def run(capsys, path, *extra):
    capsys.readouterr()
    code = main(["optimize", str(path), *extra])
    out, err = capsys.readouterr()
    try:
        return code, json.loads(out), err
    except ValueError:
        return code, out, err


def test_cli_json_and_text(capsys):
    code, doc, _ = run(capsys, EXAMPLES / "synthesis_slider.toml", "--json")
    assert code == 0 and doc["ok"] and doc["status"] == "Solve_Succeeded"
    assert doc["varied"]["l"] == pytest.approx(doc["objective"])
    assert [c["satisfied"] for c in doc["constraints"]] == [True, True]
    worst = [x for x in doc["extremes"] if x["expr"] == "90 - abs(rod.angle)"][0]
    assert worst["input"]["crank.angle"] == pytest.approx(270.0, abs=1e-4)  # degrees
    code, out, _ = run(capsys, EXAMPLES / "synthesis_path.toml")
    assert code == 0 and "[parameters]" in out and "Solve_Succeeded" in out


def test_cli_exit_3_for_a_design_that_is_not_optimal(capsys, tmp_path):
    text = (EXAMPLES / "synthesis_slider.toml").read_text(encoding="utf-8")
    path = tmp_path / "bad.toml"
    path.write_text(text.replace("min = 100, max = 100", "min = 1000, max = 1000"), encoding="utf-8")
    code, doc, err = run(capsys, path, "--json")
    assert code == 3 and doc["ok"] is False and doc["converged"] is False


def test_constraints_as_array_of_tables(tmp_path):
    text = (EXAMPLES / "synthesis_slider.toml").read_text(encoding="utf-8")
    head, _ = text.split("constraints = [")
    text = head + ('[[optimize.constraints]]\nexpr = "max(slider.s) - min(slider.s)"\nmin = 100\n'
                   'max = 100\n\n[[optimize.constraints]]\nexpr = "min(90 - abs(rod.angle))"\n'
                   'min = 40\n')
    r = run_scene(loads(text))
    assert r.ok and r.varied["l"] == pytest.approx(88.9175227610, rel=1e-8)


@pytest.mark.parametrize("change, words", [
    (('vary = { r = [10, 100], l = [50, 400] }', 'vary = { zz = [1, 2] }'), ["[optimize] vary", "zz"]),
    (('vary = { r = [10, 100], l = [50, 400] }', 'vary = { r = [100, 10] }'), ["[optimize] vary", "r"]),
    (('vary = { r = [10, 100], l = [50, 400] }', 'vary = { r = [50, 100] }'), ["outside"]),
    (('minimize = "l"', 'minimize = "l +"'), ["[optimize] minimize"]),
    (('minimize = "l"', ''), ["[optimize] minimize: missing"]),
    (('minimize = "l"', 'minimize = "l"\ncolour = 1'), ["[optimize]", "colour"]),
    (('min = 40 }', 'min = "x" }'), ["[optimize] constraints[2]", "min"]),
    (('minimize = "l"', 'minimize = "sum((slider.s - t)^2)"\ndata = { t = [1, 2] }'),
     ["[optimize] data: t: 2 values for 37 samples"]),
    (('minimize = "l"', 'minimize = "l"\nsamples = "all"'), ["[optimize] samples"]),
])
def test_bad_sections_are_scene_errors(capsys, tmp_path, change, words):
    text = (EXAMPLES / "synthesis_slider.toml").read_text(encoding="utf-8")
    assert change[0] in text
    path = tmp_path / "bad.toml"
    path.write_text(text.replace(change[0], change[1]), encoding="utf-8")
    code, out, err = run(capsys, path)
    assert code == 2 and "Traceback" not in err
    for w in words:
        assert w in err, err


# --- path synthesis without timing: a curve whose inputs are fitted ---


def nearest_on_curve(targets, **dims):
    """Distance from each target to the closed-form coupler curve, on a fine grid of the
    whole turn (NaN where that four-bar does not assemble)."""
    th = np.linspace(0.0, 2 * np.pi, 200001)
    with np.errstate(invalid="ignore"):
        x, y = coupler_point(th, **dims)
    d2 = (targets[:, None, 0] - x) ** 2 + (targets[:, None, 1] - y) ** 2
    return np.sqrt(np.nanmin(d2, axis=1))


def test_curve_targets_without_timing_are_reached_exactly():
    ref = dict(r1=120.0, r2=25.0, r3=100.0, r4=90.0, px=40.0, py=40.0)
    # irregular inputs, starting in mid-turn; the optimiser is not told them
    hidden = np.radians([200.0, 214, 239, 263, 280, 307, 331, 352, 371, 384, 418, 457, 491, 520])
    tx, ty = coupler_point(hidden, **ref)
    start = coupler_fourbar(r1=110, r2=35, r3=80, r4=95, px=20, py=60)  # perturbed design
    r = optimize(start, Curve("P", np.c_[tx, ty]), vary=PATH_VARY)
    assert r.ok and r.converged and r.problems == []
    assert r.objective < 1e-14 and r.initial_objective > 1000
    u = r.inputs["crank.angle"]
    assert np.all(np.diff(u) >= 0) and u[-1] - u[0] <= 2 * np.pi  # in order, within a turn
    # through every target: the closed form at the fitted inputs and the fitted dimensions
    x, y = coupler_point(u, **r.varied)
    assert np.abs(x - tx).max() < 1e-7 and np.abs(y - ty).max() < 1e-7
    assert np.abs(r.info["curve"]["distances"]).max() < 1e-7
    # and kincas.sweep of the optimised mechanism through the fitted inputs
    sw = kincas.sweep(r.mechanism, {"crank.angle": u}, report=["P.x", "P.y"])
    assert all(s == "ok" for s in sw.status)
    assert np.abs(sw["P.x"] - tx).max() < 1e-7 and np.abs(sw["P.y"] - ty).max() < 1e-7
    # the four-bar whose curve it is, and the inputs at which it passes (modulo a turn)
    for k, v in ref.items():
        assert r.varied[k] == pytest.approx(v, rel=1e-6), k
    assert np.abs(np.angle(np.exp(1j * (u - hidden)))).max() < 1e-6


def test_curve_in_the_other_direction_is_fitted_decreasing():
    ref = dict(r1=120.0, r2=25.0, r3=100.0, r4=90.0, px=40.0, py=40.0)
    hidden = np.radians([100.0, 70, 52, 20, -10, -45, -90, -120, -170])  # crank runs backwards
    tx, ty = coupler_point(hidden, **ref)
    r = optimize(coupler_fourbar(), Curve("P", np.c_[tx, ty]), vary=PATH_VARY)
    assert r.ok and r.objective < 1e-14
    u = r.inputs["crank.angle"]
    assert np.all(np.diff(u) <= 0)
    x, y = coupler_point(u, **r.varied)
    assert np.hypot(x - tx, y - ty).max() < 1e-7


def test_unreachable_curve_leaves_a_positive_objective():
    # |P| <= r2 + hypot(px, py) <= 40 + hypot(60, 60): a circle around (0, 160) is out of
    # reach, so the objective is at least sum (|T_i| - reach)^2 for any design in the bounds
    vary = {"r1": (40, 200), "r2": (10, 40), "r3": (30, 200), "r4": (30, 200),
            "px": (-60, 60), "py": (-60, 60)}
    a = np.radians(np.arange(0.0, 360.0, 30.0))
    T = np.c_[20 * np.cos(a), 160 + 20 * np.sin(a)]
    r = optimize(coupler_fourbar(), Curve("P", T, order="free"), vary=vary)
    assert r.ok and r.converged
    bound = np.sum((np.hypot(T[:, 0], T[:, 1]) - (40 + math.hypot(60, 60))) ** 2)
    assert r.objective > bound > 1000
    # the objective is what the closed form gives at the fitted inputs ...
    u = r.inputs["crank.angle"]
    x, y = coupler_point(u, **r.varied)
    d = np.hypot(x - T[:, 0], y - T[:, 1])
    assert np.sum(d * d) == pytest.approx(r.objective, rel=1e-10)
    assert np.allclose(r.info["curve"]["distances"], d, rtol=1e-9)
    # ... and each fitted input is the nearest point of the optimised curve to its target
    assert np.abs(d - nearest_on_curve(T, **r.varied)).max() < 1e-6


def test_curve_example_fits_the_nearest_curve(capsys):
    code, doc, _ = run(capsys, EXAMPLES / "synthesis_curve.toml", "--json")
    assert code == 0 and doc["ok"]
    T = np.array(doc["curve"]["targets"])
    u = np.radians(doc["curve"]["inputs"]["crank.angle"])  # reported in degrees
    x, y = coupler_point(u, **doc["varied"])
    d = np.hypot(x - T[:, 0], y - T[:, 1])
    assert np.sum(d * d) == pytest.approx(doc["objective"], rel=1e-9)
    assert np.allclose(doc["curve"]["distances"], d, rtol=1e-8)
    assert 1 < doc["objective"] < doc["initial_objective"]
    # nearest: no point of the optimised coupler curve is closer to any target
    assert np.abs(d - nearest_on_curve(T, **doc["varied"])).max() < 1e-5
    code, out, _ = run(capsys, EXAMPLES / "synthesis_curve.toml")
    assert code == 0 and "crank.angle (fitted)" in out and "[parameters]" in out


@pytest.mark.parametrize("change, words", [
    (('point = "P"', 'point = "Z"'), ["[optimize] curve: point", "'Z'"]),
    (('point = "P"', ''), ["[optimize] curve: point: missing"]),
    (('[[20.0, 40.0],', '[[20.0, 40.0, 1],'), ["[optimize] curve: targets[1]", "[20.0, 40.0, 1]"]),
    (('order = "auto"', 'order = "sideways"'), ["[optimize] curve: order", "sideways"]),
    (('order = "auto"', 'order = "auto"\nwithin = [360, 0]'), ["[optimize] curve: within", "[360, 0]"]),
    (('order = "auto"', 'order = "auto"\ncolour = 1'), ["[optimize] curve", "colour"]),
    (('[optimize.curve]', 'samples = [0, 90]\n\n[optimize.curve]'), ["[optimize] samples: not with curve"]),
    (('[optimize.curve]', 'minimize = "max(P.x)"\n\n[optimize.curve]'), ["[optimize] minimize: max()/min()", "curve"]),
    (('[optimize.curve]', 'data = { t = [1, 2] }\n\n[optimize.curve]'), ["[optimize] data: t: 2 values for 12 samples"]),
])
def test_bad_curve_sections_are_scene_errors(capsys, tmp_path, change, words):
    text = (EXAMPLES / "synthesis_curve.toml").read_text(encoding="utf-8")
    assert change[0] in text
    path = tmp_path / "bad.toml"
    path.write_text(text.replace(change[0], change[1], 1), encoding="utf-8")
    code, out, err = run(capsys, path)
    assert code == 2 and "Traceback" not in err
    for w in words:
        assert w in err, err
