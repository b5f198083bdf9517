"""Sweep methods as pluggable objects (issue [15]): `method=kincas.Fast(compile)` and
`kincas.Careful()` are the strings "fast"/"careful" of 0.1 (one code path: bit-identical
sweeps), a subclass of `kincas.SweepMethod` is what the sweep calls, and a wrong `method`
gets kincas's own error naming it. Every sweep here is checked against the closed-form
circle intersection written below, not only against another sweep."""
import warnings

import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism

TH = np.linspace(0, 2 * np.pi, 73)
REPORT = ["C.x", "C.y", "rocker.omega"]


@pytest.fixture(scope="module")
def m():
    return Mechanism(ground={"A": (0, 0), "D": (4, 0)},
                     links=[Link.bar("crank", "A", "B", 1.0), Link.bar("coupler", "B", "C", 3.5),
                            Link.bar("rocker", "D", "C", 3.0)],
                     inputs=[Input.angle("crank")], guess={"C": (3.6, 2.9)})


def closed_C(th):  # C on the circles |C - B| = 3.5 and |C - D| = 3, the upper assembly
    Bx, By = np.cos(th), np.sin(th)
    ex, ey = 4 - Bx, -By
    r = np.hypot(ex, ey)
    x = (3.5 ** 2 - 9 + r * r) / (2 * r)
    h = np.sqrt(3.5 ** 2 - x * x)
    return Bx + (x * ex - h * ey) / r, By + (x * ey + h * ex) / r


def same(a, b):
    Cx, Cy = closed_C(TH)
    assert a.ok.all() and np.abs(a["C.x"] - Cx).max() < 1e-12 and np.abs(a["C.y"] - Cy).max() < 1e-12
    assert a.info == b.info and list(a.status) == list(b.status)
    for k in REPORT:
        assert np.array_equal(a[k], b[k]), k  # bit-identical, not merely close
    assert np.array_equal(a.q, b.q) and np.array_equal(a.residual, b.residual)
    assert np.array_equal(a.iterations, b.iterations)


@pytest.mark.parametrize("obj, string, compile", [
    (kincas.Careful(), "careful", None),
    (kincas.Fast(compile=False), "fast", False),
    (kincas.Fast(), "fast", None),
])
def test_objects_give_the_strings_sweeps(m, obj, string, compile):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the strings stay, silently
        a = kincas.sweep(m, {"crank.angle": TH}, report=REPORT, method=obj)
        b = kincas.sweep(m, {"crank.angle": TH}, report=REPORT, method=string, compile=compile)
    same(a, b)
    if string == "careful":
        assert a.info["fast pass"] is None
    if compile is False:
        assert a.info["fast pass"] == "virtual machine"


def test_a_subclass_of_the_abc_is_called(m):
    seen = []

    class FastThenCount(kincas.SweepMethod):
        def sweep(self, problem):
            seen.append((problem.n, tuple(problem.report)))
            run = problem.fast_pass(False)
            return run if run is not None else problem.careful_pass()

    a = kincas.sweep(m, {"crank.angle": TH}, report=REPORT, method=FastThenCount())
    assert seen == [(len(TH), tuple(REPORT))]
    same(a, kincas.sweep(m, {"crank.angle": TH}, report=REPORT, method="fast", compile=False))


def test_the_abc_needs_its_method():
    with pytest.raises(TypeError):
        kincas.SweepMethod()

    class Nothing(kincas.SweepMethod):
        pass

    with pytest.raises(TypeError):
        Nothing()


@pytest.mark.parametrize("bad", ["quick", None, 3, kincas.Fast, np.array(["fast"])])
def test_a_wrong_method_names_method(m, bad):
    with pytest.raises(kincas.ModelError, match=r"^method: "):
        kincas.sweep(m, {"crank.angle": TH}, method=bad)


def test_compile_beside_a_method_object_names_compile(m):
    with pytest.raises(kincas.ModelError, match=r"^compile: .*kincas\.Fast\(compile=True\)"):
        kincas.sweep(m, {"crank.angle": TH}, method=kincas.Fast(), compile=True)


def test_the_objects_compare_and_print_as_written():
    assert kincas.Fast(compile=False) == kincas.Fast(compile=False) != kincas.Fast()
    assert kincas.Careful() == kincas.Careful() != kincas.Fast()
    assert repr(kincas.Fast(compile=True)) == "kincas.Fast(compile=True)"
    assert repr(kincas.Careful()) == "kincas.Careful()"
