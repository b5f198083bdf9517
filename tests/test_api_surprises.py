"""The Python API as a new user tried it (issue [12]): arrays where the README says arrays,
containers that behave like containers, short reprs, the usual names exported."""
from __future__ import annotations

import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism


def fourbar(a=1.0):
    return Mechanism(parameters={"a": a}, ground={"A": (0, 0), "D": (4, 0)},
                     links=[Link.bar("crank", "A", "B", "a"), Link.bar("coupler", "B", "C", 3.5),
                            Link.bar("rocker", "D", "C", 3.0)],
                     inputs=[Input.angle("crank")], guess={"C": (3.6, 2.9)})


@pytest.fixture(scope="module")
def sw():
    # a = 2.8 cannot turn fully (|BD| = 6.8 > 3.5 + 3 at 180 deg): some poses have no assembly
    return kincas.sweep(fourbar(2.8), {"crank.angle": np.linspace(0, 2 * np.pi, 37)},
                        report=["C.x", "rocker.omega"])


def test_status_is_an_array_and_ok_a_mask(sw):
    assert isinstance(sw.status, np.ndarray) and sw.status.shape == (len(sw),)
    mask = sw.status == "ok"
    assert mask.dtype == bool and mask.tolist() == sw.ok.tolist()
    assert 0 < mask.sum() < len(sw)  # both kinds, so the comparison is tested
    assert np.isnan(sw["C.x"][~sw.ok]).all() and np.isfinite(sw["C.x"][sw.ok]).all()


def test_a_sweep_is_a_container_of_names(sw):
    assert "C.x" in sw and "crank.angle" in sw and "C.y" not in sw
    assert list(sw) == ["crank.angle", "C.x", "rocker.omega"]
    assert dict((k, sw[k]) for k in sw).keys() == {"crank.angle", "C.x", "rocker.omega"}


def test_repr_is_one_short_line_and_str_a_short_summary(sw):
    r = repr(sw)
    assert "\n" not in r and len(r) < 200, r
    assert "37 poses" in r
    s = str(sw)
    assert len(s.splitlines()) <= 12, s
    assert "37 poses" in s and "C.x" in s and "no assembly" in s
    pose = sw.pose(0)
    assert "\n" not in repr(pose) and len(repr(pose)) < 200


def test_sensitivity_by_its_quantity_name():
    s = kincas.sensitivities(fourbar(), {"crank.angle": np.array([0.0, np.pi])}, of=["C.x"], to=["a"])
    # closed form (see kincas.analysis.sensitivity): 1 - 1/2 + 3.25/18 and -1 + 1/2 - 3.25/50
    expect = [0.5 + 3.25 / 18, -0.5 - 3.25 / 50]
    assert s["d(C.x)/d(a)"] == pytest.approx(expect, abs=1e-12)
    assert s["C.x", "a"] == pytest.approx(expect, abs=1e-12)
    assert "d(C.x)/d(a)" in s and list(s) == ["d(C.x)/d(a)"]
    with pytest.raises(KeyError, match="d\\(C.y\\)/d\\(a\\)"):
        s["d(C.y)/d(a)"]


def test_the_usual_names_are_exported():
    from kincas import analyse, find_modes, input_range, optimize, sensitivities  # noqa: F401
    assert callable(optimize) and callable(analyse) and callable(find_modes)
    assert callable(input_range) and callable(sensitivities)
    for name in ("sensitivities", "analyse", "optimize", "find_modes", "input_range"):
        assert name in kincas.__all__
    import kincas.optimize as old_path  # the 0.1 module path still works, and stays callable
    assert hasattr(old_path, "Optimization") and callable(kincas.optimize)
    modes = kincas.find_modes(fourbar(), {"crank.angle": 0.5}, starts=32)
    assert len(modes) == 2  # a four-bar assembles two ways


def test_optimize_result_has_scipy_fields():
    # the crank length that puts C.x at 3.0 at crank angle 90 deg: one variable, a root
    m = fourbar()
    r = kincas.optimize(m, {"crank.angle": [np.pi / 2]}, vary={"a": (0.5, 1.5)},
                        minimize="sum((C.x - 3.0)^2)")
    assert r.success is r.ok and r.success
    assert r.x.shape == (1,) and r.x[0] == pytest.approx(r.parameters["a"])
    assert r.fun == r.objective and r.fun < 1e-12
    assert r.nit == r.iterations and isinstance(r.nit, int)
    assert isinstance(r.message, str) and isinstance(r.status, str)
    # independent check: with the crank at 90 deg B = (0, a), C on circles about B and D
    a = r.x[0]
    c_y = np.sqrt(3.0 ** 2 - (3.0 - 4.0) ** 2)
    assert np.hypot(3.0, c_y - a) == pytest.approx(3.5, abs=1e-8)
