"""Multistart synthesis: distinct optima found from starts drawn in the bounds, each checked
against kincas.sweep at its own design (an independent solve), and the command line."""
from __future__ import annotations

import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism
from kincas.synthesis.multistart import multistart
from conftest import EXAMPLES, run_cli


def fourbar():
    return Mechanism(parameters={"d": 4.0}, ground={"A": (0, 0), "D": ("d", 0)},
                     links=[Link.bar("crank", "A", "B", 1), Link.bar("coupler", "B", "C", 3.5),
                            Link.bar("rocker", "D", "C", 3)],
                     inputs=[Input.angle("crank")], guess={"C": (3.6, 2.9)})


def test_two_distinct_optima_each_solving_the_target():
    # C.y at crank angle 0.5 rises then falls with the ground length d: the target 2.9 is
    # met twice in [2, 6]; one start finds one of them, several starts find both.
    m = fourbar()
    r = multistart(m, {"crank.angle": np.array([0.5])}, {"d": (2.0, 6.0)}, "sum((C.y - 2.9)^2)",
                   starts=6, seed=0)
    assert r.runs == 6 and len(r.optima) == 2
    ds = sorted(o.varied["d"] for o in r.optima)
    assert ds[1] - ds[0] > 1.0
    for d in ds:  # independently: the sweep of that design puts C at y = 2.9
        s = kincas.sweep(m.with_parameters(d=d), {"crank.angle": np.array([0.5])}, report=["C.y"])
        assert s["C.y"][0] == pytest.approx(2.9, abs=1e-8)
    assert r.optima[0].objective <= r.optima[1].objective
    one = multistart(m, {"crank.angle": np.array([0.5])}, {"d": (2.0, 6.0)},
                     "sum((C.y - 2.9)^2)", starts=1, seed=0)
    assert len(one.optima) == 1


def test_a_wrong_objective_is_an_error_not_failed_starts():
    with pytest.raises(kincas.ModelError, match="minimize"):
        multistart(fourbar(), {"crank.angle": np.array([0.5, 0.6])}, {"d": (2.0, 6.0)},
                   "(C.y - 2.9)^2", starts=2)


def test_cli_starts(capsys):
    scene = EXAMPLES / "synthesis_function.toml"
    code, doc, err = run_cli(capsys, "optimize", scene, "--starts", "3", "--json")
    assert code == 0, err
    assert doc["starts"] == 3 and 1 <= len(doc["optima"]) <= 3 and doc["passed"] >= 1
    best = doc["optima"][0]
    assert best["ok"] and best["objective"] <= min(o["objective"] for o in doc["optima"])
    single = run_cli(capsys, "optimize", scene, "--json")[1]  # the one-start answer is among them
    assert any(all(abs(o["varied"][k] - v) < 1e-5 * abs(v) for k, v in single["varied"].items())
               for o in doc["optima"])
    code, _, err = run_cli(capsys, "optimize", scene, "--starts", "0")
    assert code == 2 and "--starts" in err
