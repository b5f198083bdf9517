"""Tolerance analysis against independent answers.

The first-order std is checked against central differences of re-solved poses; the Monte
Carlo against the same random draws pushed through a closed-form four-bar (circle
intersection, numpy only), so the vectorised Newton solves are checked sample by sample in
their statistics; the count of samples that cannot assemble against the closed form's own
count; a quantity exactly linear in a parameter against the sample std of the draws.
"""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism, ModelError, Slide
from kincas.cli import main
from kincas.analysis.tolerance import analyse


def fourbar(a=1.0, b=3.5, c=3.0, d=4.0, guess=(3.6, 2.9)):
    return Mechanism(parameters={"a": a, "b": b, "c": c, "d": d},
                     ground={"A": (0, 0), "D": ("d", 0)},
                     links=[Link.bar("crank", "A", "B", "a"), Link.bar("coupler", "B", "C", "b"),
                            Link.bar("rocker", "D", "C", "c")],
                     inputs=[Input.angle("crank")], guess={"C": guess})


def closed_fourbar(th, a, b, c, d, sign=+1):
    """C (x, y) and the rocker angle by circle intersection; NaN where it cannot close.
    Arrays broadcast: th over poses, a..d over samples."""
    bx, by = a * np.cos(th), a * np.sin(th)
    ex, ey = d - bx, -by
    r = np.hypot(ex, ey)
    x = (b * b - c * c + r * r) / (2 * r)
    with np.errstate(invalid="ignore"):
        h = np.sqrt(b * b - x * x)
    cx = bx + (x * ex - sign * h * ey) / r
    cy = by + (x * ey + sign * h * ex) / r
    return cx, cy, np.arctan2(cy, cx - d), b * b - x * x


def draws(std, samples, seed):
    """The draws analyse() makes: one row per sample, one column per parameter in std."""
    sig = np.array(list(std.values()))
    return np.random.default_rng(seed).standard_normal((samples, len(std))) * sig


def test_first_order_std_from_central_differences():
    m = fourbar()
    th = np.radians([20.0, 100.0, 230.0])
    std = {"a": 0.01, "b": 0.03, "c": 0.02, "d": 0.05}
    r = analyse(m, {"crank.angle": th}, std, report=["C.x", "C.y", "rocker.angle", "rocker.omega"],
                draws=50, seed=0, rates={"crank.angle": 3.0})
    var = {n: np.zeros(3) for n in r.names}
    for p, s in std.items():
        h = 1e-5
        f = [kincas.sweep(m.with_parameters(**{p: m.parameter(p) + k * h}), {"crank.angle": th},
                          rates={"crank.angle": 3.0}, report=r.names) for k in (-1, 1)]
        for n in r.names:
            var[n] += ((f[1][n] - f[0][n]) / (2 * h) * s) ** 2
    for n in r.names:
        assert np.allclose(r.first_order[n], np.sqrt(var[n]), rtol=1e-7, atol=0), n


def test_monte_carlo_equals_the_closed_form_on_the_same_draws():
    m = fourbar()
    th = np.radians(np.arange(0.0, 360.0, 30.0))
    std = {"a": 0.02, "b": 0.05, "c": 0.05, "d": 0.05}
    n = 3000
    r = analyse(m, {"crank.angle": th}, std, report=["C.x", "C.y", "rocker.angle"],
                draws=n, seed=7)
    assert r.status.tolist() == ["ok"] * len(th) and r.failed.tolist() == [0] * len(th)
    dp = draws(std, n, 7)
    a, b, c, d = (1.0 + dp[:, 0], 3.5 + dp[:, 1], 3.0 + dp[:, 2], 4.0 + dp[:, 3])
    cx, cy, psi, _ = closed_fourbar(th[:, None], a, b, c, d)
    cx0, cy0, psi0, _ = closed_fourbar(th, 1.0, 3.5, 3.0, 4.0)
    assert np.allclose(r.nominal["C.x"], cx0, atol=1e-12)
    for name, v in (("C.x", cx), ("C.y", cy), ("rocker.angle", psi)):
        ref = v.std(axis=1, ddof=1)
        assert np.allclose(r.monte_carlo[name], ref, rtol=1e-9, atol=1e-13), name
    assert np.allclose(r.mean_shift["C.y"], (cy - cy0[:, None]).mean(axis=1), atol=1e-12)
    # and the two answers agree within the sampling error here (small tolerances)
    assert r.agrees()
    assert np.all(np.abs(r.agreement["C.y"] - 1) < 5 * r.standard_error)


def test_linear_output_has_the_draws_own_spread():
    # B.y of a slider-crank is exactly the guide's offset e, whatever the crank does.
    m = Mechanism(parameters={"r": 50.0, "l": 180.0, "e": 20.0}, ground={"O": (0, 0)},
                  links=[Link.bar("crank", "O", "A", "r"), Link.bar("rod", "A", "B", "l")],
                  slides=[Slide("B", "ground", through=(0, "e"), name="guide")],
                  inputs=[Input.angle("crank")], guess={"B": (220, 20)})
    std = {"r": 0.1, "l": 0.2, "e": 0.3}
    r = analyse(m, {"crank.angle": np.radians([0.0, 75.0, 160.0])}, std,
                report=["B.y", "guide.s"], draws=500, seed=11)
    e = draws(std, 500, 11)[:, 2]
    assert np.allclose(r.first_order["B.y"], 0.3, rtol=1e-12)
    assert np.allclose(r.monte_carlo["B.y"], e.std(ddof=1), rtol=1e-10)
    # at crank angle 0, B.x = r + sqrt(l^2 - e^2): an independent first-order std
    s0 = math.sqrt(0.1 ** 2 + (180 / math.sqrt(180 ** 2 - 400) * 0.2) ** 2
                   + (20 / math.sqrt(180 ** 2 - 400) * 0.3) ** 2)
    assert r.first_order["guide.s"][0] == pytest.approx(s0, rel=1e-12)


def test_samples_that_cannot_assemble_are_counted_and_left_out():
    # Non-Grashof four-bar (1, 1.9, 3, 4) near its limit: some drawn mechanisms cannot close.
    m = fourbar(1.0, 1.9, 3.0, 4.0, guess=(3.2, 2.5))
    th = np.radians([120.0, 145.0, 150.5])  # the limit is at 151.2 deg
    std = {"a": 0.02, "b": 0.02, "c": 0.02, "d": 0.02}
    n = 1000
    r = analyse(m, {"crank.angle": th}, std, report=["C.y"], draws=n, seed=3)
    assert r.status.tolist() == ["ok"] * 3
    dp = draws(std, n, 3)
    pars = (1.0 + dp[:, 0], 1.9 + dp[:, 1], 3.0 + dp[:, 2], 4.0 + dp[:, 3])
    _, cy, _, disc = closed_fourbar(th[:, None], *pars)
    impossible = (disc < 0).sum(axis=1)
    ambiguous = (np.abs(disc) < 1e-4).sum(axis=1)  # next to the limit either branch is fair
    assert impossible[-1] > 0 and impossible[0] == 0
    assert np.all(r.failed >= impossible - ambiguous) and np.all(r.failed <= impossible + ambiguous)
    k = 0  # no failures there: the statistics are the closed form's
    assert r.monte_carlo["C.y"][k] == pytest.approx(cy[k].std(ddof=1), rel=1e-9)
    k = 2  # failures there: the statistics use the assembled samples only
    good = disc[k] >= 1e-4
    if r.failed[k] == impossible[k]:
        assert r.monte_carlo["C.y"][k] == pytest.approx(cy[k][disc[k] >= 0].std(ddof=1), rel=1e-6)
    assert np.isfinite(r.monte_carlo["C.y"][k]) and good.sum() > 2


def test_bad_arguments_name_the_field():
    m = fourbar()
    with pytest.raises(ModelError) as e:
        analyse(m, {"crank.angle": [0.0]}, {"zz": 0.1, "a": -1.0}, draws=1)
    text = str(e.value)
    assert "zz" in text and "a: expected a standard deviation" in text and "draws" in text


# --- the command line ---

SCENE = """# four-bar with tolerances
title = "tolerance test"
units = {{ length = "mm", angle = "{unit}", time = "s" }}
[parameters]
a = 10
b = 35
c = 30
d = 40
[ground]
A = [0, 0]
D = ["d", 0]
[links]
crank = {{ points = ["A", "B"], length = "a" }}
coupler = {{ points = ["B", "C"], length = "b" }}
rocker = {{ points = ["D", "C"], length = "c" }}
[[inputs]]
angle = "crank"
sweep = {{ from = 0, to = {turn}, steps = 5 }}
[guess]
C = [36, 29]
[output]
report = ["C.y", "rocker.angle"]
[tolerance]
{body}
"""


def cli(capsys, tmp_path, body, *extra, unit="deg"):
    turn = 360 if unit == "deg" else 2 * math.pi
    path = tmp_path / "tol.toml"
    path.write_text(SCENE.format(unit=unit, turn=turn, body=body), encoding="utf-8")
    capsys.readouterr()
    code = main(["tolerance", str(path), *extra])
    out, err = capsys.readouterr()
    try:
        return code, json.loads(out), err
    except ValueError:
        return code, out, err


@pytest.mark.parametrize("unit", ["deg", "rad"])
def test_cli_json_in_scene_units(capsys, tmp_path, unit):
    code, doc, _ = cli(capsys, tmp_path, 'std = { a = 0.05, c = 0.1 }\nsamples = 400\nseed = 2',
                       "--json", unit=unit)
    assert code == 0 and doc["samples"] == 400 and doc["failed"] == [0] * 5
    th = np.linspace(0, 2 * np.pi, 5)
    dp = draws({"a": 0.05, "c": 0.1}, 400, 2)
    _, cy, psi, _ = closed_fourbar(th[:, None], 10 + dp[:, 0], 35.0, 30 + dp[:, 1], 40.0)
    k = 180 / math.pi if unit == "deg" else 1.0
    assert np.allclose(doc["monte_carlo"]["C.y"], cy.std(axis=1, ddof=1), rtol=1e-9)
    assert np.allclose(doc["monte_carlo"]["rocker.angle"], k * psi.std(axis=1, ddof=1), rtol=1e-9)
    assert doc["agrees"] is True and set(doc) >= {"first_order", "nominal", "agreement", "status"}


def test_cli_text_and_command_line_overrides(capsys, tmp_path):
    code, out, _ = cli(capsys, tmp_path, "std = { a = 0.05 }", "--samples", "300", "--seed", "5")
    assert code == 0 and "300 samples (seed 5)" in out and "std C.y [mm]" in out
    assert "mc rocker.angle [deg]" in out and "agree" in out


@pytest.mark.parametrize("body, words", [
    ("std = { zz = 0.1 }", ["[tolerance] std", "zz"]),
    ("std = { a = -0.1 }", ["[tolerance] std", "a"]),
    ("std = { a = 0.1 }\nsamples = 1", ["[tolerance] samples"]),
    ("std = { a = 0.1 }\nreport = [\"C.zz\"]", ["[tolerance] report", "C.zz"]),
    ("std = { a = 0.1 }\ncolour = 3", ["[tolerance]", "colour"]),
    ("samples = 10", ["[tolerance] std: missing"]),
])
def test_cli_scene_errors(capsys, tmp_path, body, words):
    code, out, err = cli(capsys, tmp_path, body)
    assert code == 2 and "Traceback" not in err
    for w in words:
        assert w in err


def test_cli_exit_3_when_samples_do_not_assemble(capsys, tmp_path):
    # a near-toggle design: a 2 mm spread on the coupler makes some samples impossible
    text = "std = { b = 2.0 }\nsamples = 200"
    path = tmp_path / "tol.toml"
    path.write_text(SCENE.format(unit="deg", turn=360, body=text).replace("b = 35", "b = 19")
                    .replace("from = 0, to = 360, steps = 5", "from = 120, to = 150, steps = 3")
                    .replace("C = [36, 29]", "C = [32, 25]"), encoding="utf-8")
    capsys.readouterr()
    code = main(["tolerance", str(path), "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert code == 3 and doc["status"] == ["ok"] * 3 and sum(doc["failed"]) > 0
