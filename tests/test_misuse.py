"""Python misuse (issue [14], item 14): every wrong argument gets kincas's own error naming
the argument, never a raw IndexError, TypeError, ValueError or AttributeError from inside;
numpy scalars are numbers wherever numbers are taken."""
from __future__ import annotations

import math

import numpy as np
import pytest

import kincas
from kincas import Input, Link, Load, Mechanism, ModelError

A, D = (0, 0), (4, 0)


def links(crank=1.0):
    return [Link.bar("crank", "A", "B", crank), Link.bar("coupler", "B", "C", 3.5),
            Link.bar("rocker", "D", "C", 3.0)]


def fourbar(**kw):
    d = dict(parameters={"a": 1.0}, ground={"A": A, "D": D}, links=links("a"),
             inputs=[Input.angle("crank")], guess={"C": (3.6, 2.9)})
    d.update(kw)
    return Mechanism(**d)


M = fourbar()
U = np.linspace(0.0, 1.0, 5)


def refused(match, f, *a, **kw):
    """f(*a, **kw) raises kincas's ModelError (and only that) with `match` in its message."""
    with pytest.raises(ModelError) as e:
        f(*a, **kw)
    assert match in str(e.value), str(e.value)
    return str(e.value)


# --- sweep() and solve() arguments ---


def test_an_empty_sweep_is_refused_naming_the_input():
    refused("crank.angle", kincas.sweep, M, {"crank.angle": []})
    refused("inputs", kincas.sweep, M, [])


@pytest.mark.parametrize("arg", ["rates", "accelerations", "jerks"])
def test_derivatives_of_the_wrong_length_are_refused(arg):
    msg = refused(arg, kincas.sweep, M, {"crank.angle": U}, report=["C.jx"],
                  **{arg: {"crank.angle": [1.0, 2.0]}})
    assert "2" in msg and "5" in msg  # the two lengths


@pytest.mark.parametrize("report", [[3], ["C.x", None], [("C", "x")]])
def test_report_entries_must_be_names(report):
    refused("report", kincas.sweep, M, U, report=report)


def test_a_report_given_as_one_name_is_that_name():
    sw = kincas.sweep(M, U, report="C.x")
    assert list(sw.values) == ["C.x"]


@pytest.mark.parametrize("guess", [{"C": 5}, {"C": (1, 2, 3)}, {"C": "near"}, {"C": (np.nan, 1.0)},
                                   {"C": (1.0, math.inf)}])
def test_a_malformed_guess_per_call_is_refused(guess):
    refused("guess", kincas.sweep, M, U, guess=guess)


def test_unknown_points_in_a_guess_are_named():
    msg = refused("guess", kincas.sweep, M, U, guess={"Z": (1.0, 1.0), "C": (3.6, 2.9), "Y": (0, 0)})
    assert "Z" in msg and "Y" in msg
    refused("A", kincas.solve, M, 0.5, guess={"A": (0.0, 0.0)})  # a ground point is fixed


@pytest.mark.parametrize("values", ["abc", ["0.1", "x"], {"crank.angle": "abc"}, {"crank.angle": [0.1, None]},
                                    {"crank.angle": [[0.1, 0.2]]}])
def test_inputs_that_are_not_numbers_are_refused(values):
    refused("inputs", kincas.sweep, M, values)


def test_rates_that_are_not_numbers_are_refused():
    refused("rates", kincas.sweep, M, U, rates={"crank.angle": "fast"})


def test_solve_is_one_pose():
    msg = refused("solve", kincas.solve, M, {"crank.angle": [0.1, 0.2]})
    assert "kincas.sweep" in msg
    refused("rates", kincas.solve, M, 0.1, rates={"crank.angle": [1.0, 2.0]})


def test_numpy_scalars_are_inputs():
    q = kincas.solve(M, np.float32(0.5), report=["B.x"])
    assert q["B.x"] == pytest.approx(math.cos(np.float32(0.5)), abs=1e-15)
    assert kincas.solve(M, {"crank.angle": np.int64(1)}, report=["B.y"])["B.y"] == pytest.approx(math.sin(1.0), abs=1e-15)


# --- the declarations ---


def test_with_parameters_takes_numbers_only():
    refused("[parameters] a", M.with_parameters, a="x")
    refused("[parameters] a", M.with_parameters, a=[1.0])
    refused("[parameters] a", fourbar, parameters={"a": "x"})
    assert M.with_parameters(a=np.int64(2)).parameter("a") == 2.0
    assert M.with_parameters(a=np.float32(1.5)).parameter("a") == 1.5


@pytest.mark.parametrize("kw, where", [
    (dict(ground={"A": (0, 0, 0), "D": D}), "[ground] A"),
    (dict(ground={"A": 0, "D": D}), "[ground] A"),
    (dict(ground=["A", "D"]), "ground"),
    (dict(guess={"C": (1, 2, 3)}), "[guess] C"),
    (dict(guess={"C": 3.6}), "[guess] C"),
    (dict(gravity=(0, -9.81, 0)), "gravity"),
    (dict(gravity=9.81), "gravity"),
    (dict(parameters=[1.0, 2.0]), "parameters"),
])
def test_wrong_shapes_are_named(kw, where):
    refused(where, fourbar, **kw)


def test_a_force_of_the_wrong_shape_is_named():
    refused("force", Load.force, "C", (1, 2, 3))
    refused("force", Load.force, "C", 5.0)


def test_link_points_of_the_wrong_shape_are_named():
    refused("[links] plate", Link, "plate", {"A": (0, 0), "P": (1, 2, 3)})
    refused("[links] plate", Link, "plate", "AB")


@pytest.mark.parametrize("kw, where", [
    (dict(links="crank"), "links"), (dict(links=["crank", "coupler"]), "links"),
    (dict(inputs="crank.angle"), "inputs"), (dict(inputs=["crank"]), "inputs"),
    (dict(slides=["B"]), "slides"), (dict(loads=[("C", (0, 1))]), "loads"),
])
def test_parts_given_as_strings_are_refused(kw, where):
    msg = refused(where, fourbar, **kw)
    assert "kincas." in msg  # says what to give (kincas.Link, kincas.Input, ...)


def test_an_input_must_name_its_target():
    refused("[[inputs]] 1", fourbar, inputs=[Input.angle(3)])


@pytest.mark.parametrize("num", [np.int64(1), np.int32(1), np.float32(1.0), np.float64(1.0), np.uint8(1)])
def test_numpy_scalars_are_numbers_in_declarations(num):
    m = fourbar(parameters={"a": num}, ground={"A": (np.int64(0), num - num), "D": (np.float32(4), 0)},
                links=links(num), guess={"C": (np.float32(3.6), np.int64(3))})
    m2 = fourbar(parameters={"a": 1.0}, links=links(1.0))
    q, q2 = (kincas.solve(x, 0.5, report=["C.x", "C.y"]) for x in (m, m2))
    assert q.status == "ok" and q["C.x"] == q2["C.x"] and q["C.y"] == q2["C.y"]
    assert isinstance(m.parameter("a"), float)
    m3 = fourbar(links=[Link.bar("crank", "A", "B", "a", mass=np.float32(2)), *links()[1:]],
                 gravity=(np.int64(0), np.float32(-9.81)), loads=[Load.force("C", (np.int64(1), 0))])
    assert m3.gravity[1] == pytest.approx(-9.81, rel=1e-7)
