"""Public names are consistent: each result type goes by one name (what it holds, as Sweep
and Pose), reachable as `kincas.<Name>`; 0.1's names still work one release, with a
DeprecationWarning that names the new one; new names never warn."""
import importlib
import math
import warnings

import pytest

import kincas
from kincas.result_base import RENAMED, TYPES, Result

HOMES = {"StudyResult": "kincas.synthesis.study", "ToleranceResult": "kincas.analysis.tolerance",
         "OptimizeResult": "kincas.synthesis.optimize", "MultistartResult": "kincas.synthesis.multistart"}


def test_each_result_type_has_one_name_and_the_interface():
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a current name never warns
        for name in TYPES:
            cls = getattr(kincas, name)
            assert cls.__name__ == name
            assert name == "Result" or issubclass(cls, Result), name
    assert not any(n.endswith("Result") for n in TYPES if n != "Result")  # one scheme


@pytest.mark.parametrize("old", sorted(RENAMED))
def test_old_names_warn_and_still_work(old):
    new = RENAMED[old]
    with pytest.warns(DeprecationWarning, match=rf"kincas\.{old} is deprecated: use kincas\.{new}"):
        top = getattr(kincas, old)
    module = importlib.import_module(HOMES[old])
    with pytest.warns(DeprecationWarning, match=rf"{HOMES[old]}\.{old} .* use {HOMES[old]}\.{new}"):
        inner = getattr(module, old)
    assert top is inner is getattr(kincas, new)


def test_unknown_names_still_raise_attribute_error():
    with pytest.raises(AttributeError):
        kincas.NoSuchResult
    with pytest.raises(AttributeError):
        importlib.import_module("kincas.synthesis.study").NoSuchResult


def test_find_modes_returns_modes_a_list_old_code_indexes():
    m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
                         links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
                                kincas.Link.bar("rocker", "D", "C", 3)],
                         inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
    modes = kincas.find_modes(m, {"crank.angle": 0.5}, starts=32)
    assert isinstance(modes, kincas.Modes) and isinstance(modes, list) and modes.ok
    ys = sorted(md.points["C"][1] for md in modes)
    assert modes[0] is list(modes)[0] and len(modes[-2:]) == 2
    # independent: C on the circles |C - B| = 3.5 and |C - D| = 3, B = (cos .5, sin .5)
    import math
    bx, by = math.cos(0.5), math.sin(0.5)
    for y in ys:
        x = next(md.points["C"][0] for md in modes if md.points["C"][1] == y)
        assert abs(math.hypot(x - bx, y - by) - 3.5) < 1e-10 and abs(math.hypot(x - 4, y) - 3) < 1e-10


def test_compile_is_deprecated_for_model_of():
    import numpy as np
    with pytest.warns(DeprecationWarning, match=r"kincas\.compile is deprecated: use kincas\.model_of"):
        old = kincas.compile
    assert old is kincas.model_of and "compile" not in kincas.__all__
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        exec("from kincas import *", {})  # the star import names only current names
    # it still works: a crank O-A of length 2 at angle 0 puts A at (2, 0)
    m = kincas.Mechanism(ground={"O": (0, 0)}, links=[kincas.Link.bar("crank", "O", "A", 2)],
                         inputs=[kincas.Input.angle("crank")])
    with pytest.warns(DeprecationWarning):
        model = kincas.compile(m)
    sol = model.newton(model.initial_q(np.zeros(1), np.zeros(0), {}, 2.0), np.zeros(1), np.zeros(0), 2.0)
    assert sol.ok


def _crank():
    return kincas.Mechanism(parameters={"a": 2.0}, ground={"O": (0, 0)},
                            links=[kincas.Link.bar("crank", "O", "A", "a")],
                            inputs=[kincas.Input.angle("crank")])


def test_analyse_counts_draws_and_the_old_samples_keyword_warns():
    # first order: std(A.x) = |cos t| sigma, whatever the count of draws
    new = kincas.analyse(_crank(), {"crank.angle": [0.3]}, {"a": 0.01}, ["A.x"], draws=30, seed=2)
    with pytest.warns(DeprecationWarning, match=r"analyse\(samples=...\) is deprecated: use analyse\(draws=...\)"):
        old = kincas.analyse(_crank(), {"crank.angle": [0.3]}, {"a": 0.01}, ["A.x"], samples=30, seed=2)
    assert abs(new.first_order["A.x"][0] - 0.01 * math.cos(0.3)) < 1e-15
    assert new.draws == old.draws == 30 and new.monte_carlo["A.x"][0] == old.monte_carlo["A.x"][0]
    with pytest.raises(kincas.ModelError, match="draws: given twice"):
        kincas.analyse(_crank(), {"crank.angle": [0.3]}, {"a": 0.01}, ["A.x"], draws=30, samples=40)


def test_study_counts_designs_and_the_old_samples_keyword_warns():
    import numpy as np
    args = (_crank(), {"a": (1.0, 3.0)}, {"crank.angle": [0.0, 0.5]}, ["max(A.x)"])
    new = kincas.study(*args, designs=4, seed=1, workers=1)
    with pytest.warns(DeprecationWarning, match=r"study\(samples=...\) is deprecated: use study\(designs=...\)"):
        old = kincas.study(*args, samples=4, seed=1, workers=1)
    a = new.params[:, 0]
    assert np.array_equal(a, old.params[:, 0]) and len(a) == 4
    assert sorted(np.floor((a - 1.0) / 0.5).astype(int)) == [0, 1, 2, 3]  # one per stratum
    assert np.allclose(new.values["max(A.x)"], a, rtol=0, atol=1e-12)  # A.x = a cos t, largest at t = 0


def test_optimize_takes_inputs_and_the_old_samples_keyword_warns():
    # the minimum of (a cos 0.5 - 1)^2 is at a = 1 / cos 0.5
    kw = {"vary": {"a": (1.0, 3.0)}, "minimize": "sum((A.x - 1)^2)"}
    new = kincas.optimize(_crank(), inputs={"crank.angle": [0.5]}, **kw)
    with pytest.warns(DeprecationWarning, match=r"optimize\(samples=...\) is deprecated: use optimize\(inputs=...\)"):
        old = kincas.optimize(_crank(), samples={"crank.angle": [0.5]}, **kw)
    positional = kincas.optimize(_crank(), {"crank.angle": [0.5]}, kw["vary"], kw["minimize"])
    for r in (new, old, positional):
        assert r.ok and abs(r.varied["a"] - 1 / math.cos(0.5)) < 1e-8
    with pytest.raises(kincas.ModelError, match="inputs: missing"):
        kincas.optimize(_crank(), **kw)


def test_newton_ignores_L_as_documented():
    import numpy as np
    m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
                         links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
                                kincas.Link.bar("rocker", "D", "C", 3)],
                         inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
    model, u, p = kincas.model_of(m), np.array([0.5]), np.zeros(0)
    q0 = model.initial_q(u, p, dict(m.guess), m.size()) + 0.05  # off the solution
    sols = [model.newton(q0, u, p)] + [model.newton(q0, u, p, L) for L in (None, 1e-9, 1.0, 1e9)]
    sols.append(model.newton(q0, u, p, L=7.0, max_iter=60))
    assert all(s.ok for s in sols)
    assert all(np.array_equal(s.q, sols[0].q) and s.residual == sols[0].residual for s in sols)


@pytest.mark.parametrize("old", sorted(importlib.import_module("kincas._aliases").OLD))
def test_old_module_paths_warn_naming_the_new_one(old, monkeypatch):
    from kincas import _aliases
    new = f"kincas.{_aliases.OLD[old]}"
    real = importlib.import_module(new)
    import sys
    monkeypatch.delitem(sys.modules, f"kincas.{old}", raising=False)  # a first import again
    monkeypatch.delitem(vars(kincas), old, raising=False)
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        mod = importlib.import_module(f"kincas.{old}")
        attr = getattr(kincas, old)
    assert mod is real and attr is real and real.__spec__.name == new
    texts = [str(w.message) for w in seen if issubclass(w.category, DeprecationWarning)]
    if old in _aliases.QUIET:  # the function kincas.optimize, the README's scene and drawings
        assert not texts
    else:
        assert texts == [f"kincas.{old} moved to {new}; the old path goes in the next release"]
        monkeypatch.delitem(vars(kincas), old, raising=False)
        with pytest.warns(DeprecationWarning, match=f"kincas.{old} moved to {new}"):
            getattr(kincas, old)  # the attribute, without an import, warns too
