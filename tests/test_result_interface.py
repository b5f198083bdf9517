"""Every result of a public kincas function implements kincas.result_base.Result: `ok`,
`summary()`, a one-line repr, and `to_pandas(length=...)` / `to_xarray(length=...)` whose
numbers are the result's own (checked here against closed forms of a crank O-A of length a:
A.x = a cos t, A.y = a sin t, d(A.x)/d(a) = cos t)."""
import inspect
import math

import numpy as np
import pytest

import kincas
from kincas.result_base import Result

pd = pytest.importorskip("pandas")
xr = pytest.importorskip("xarray")

T = [0.0, 0.5]
CLOSED = {"A.x": lambda a, t: a * math.cos(t), "A.y": lambda a, t: a * math.sin(t)}


def crank(a=2.0):
    return kincas.Mechanism(parameters={"a": a}, ground={"O": (0, 0)},
                            links=[kincas.Link.bar("crank", "O", "A", "a")],
                            inputs=[kincas.Input.angle("crank")])


def four_bar():
    return kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
                            links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
                                   kincas.Link.bar("rocker", "D", "C", 3)],
                            inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})


# each public function of kincas.__all__ that returns a result, called on a tiny example
EXAMPLES = {
    "solve": lambda: kincas.solve(crank(), {"crank.angle": T[1]}, report=["A.x", "A.y"]),
    "sweep": lambda: kincas.sweep(crank(), {"crank.angle": T}, report=["A.x", "A.y"]),
    "sweep_designs": lambda: kincas.sweep_designs(crank(), {"a": [1.0, 3.0]}, {"crank.angle": T},
                                                  report=["A.x"]),
    "study": lambda: kincas.study(crank(), {"a": (1.0, 3.0)}, {"crank.angle": T}, ["max(A.x)"],
                                  grid=[2], workers=1),
    "sensitivities": lambda: kincas.sensitivities(crank(), {"crank.angle": T}, of=["A.x"], to=["a"]),
    "analyse": lambda: kincas.analyse(crank(), {"crank.angle": T}, {"a": 0.01}, ["A.x"], draws=20),
    "optimize": lambda: kincas.optimize(crank(), {"crank.angle": T}, {"a": (1.0, 3.0)}, "sum((A.x - 1.5)^2)"),
    "find_modes": lambda: kincas.find_modes(four_bar(), {"crank.angle": 0.5}, starts=32),
    # certified where msolve is installed (kincas[certify]), else the multistart
    "modes": lambda: kincas.modes(four_bar(), {"crank.angle": 0.5}, certify=_certify_available()),
    "input_range": lambda: kincas.input_range(four_bar(), {"crank.angle": 0.5}),
    # a wheel of inertia 1 under a torque of 2: its angle is t^2
    "simulate": lambda: kincas.simulate(kincas.Mechanism(
        parameters={"a": 2.0, "T": 2.0}, ground={"O": (0, 0)}, loads=[kincas.Load.torque("crank", "T")],
        links=[kincas.Link.bar("crank", "O", "A", "a", inertia=1.0)], inputs=[kincas.Input.angle("crank")]),
        1.0, 3, report=["A.x", "A.y"]),
}


def _certify_available():
    from kincas.analysis.certify_msolve import available
    return available()


# public functions that return no result (a compiled model)
NOT_RESULTS = {"model_of", "compile", "widget"}  # widget: a Jupyter widget, no result


def test_every_public_function_is_classified():
    public = {n for n in kincas.__all__ if inspect.isfunction(getattr(kincas, n))
              or (callable(getattr(kincas, n)) and not inspect.isclass(getattr(kincas, n)))}
    assert public - NOT_RESULTS == set(EXAMPLES), "a public function's result is not tested here"


def test_public_result_classes_implement_the_interface():
    classes = [getattr(kincas, n) for n in kincas.__all__ if inspect.isclass(getattr(kincas, n))
               and n in ("Pose", "Sweep")]
    assert classes and all(issubclass(c, Result) for c in classes)
    with pytest.raises(TypeError):  # an incomplete result cannot be made
        type("Half", (Result,), {"summary": lambda self: ""})()


@pytest.mark.parametrize("name", sorted(EXAMPLES))
def test_result_round_trips(name):
    r = EXAMPLES[name]()
    assert isinstance(r, Result), type(r)
    assert np.all(r.ok), r
    text = repr(r)
    assert "\n" not in text and text.startswith(f"<{type(r).__name__}") or isinstance(r, list)
    assert r.summary()
    df, ds = r.to_pandas(length="mm"), r.to_xarray(length="mm")
    assert isinstance(df, pd.DataFrame) and isinstance(ds, xr.Dataset)
    sig = [(inspect.signature(f).parameters["length"].default, inspect.signature(f).parameters["angle"].default)
           for f in (type(r).to_pandas, type(r).to_xarray)]
    assert sig == [("", "rad"), ("", "rad")]
    assert isinstance(r.to_pandas(angle="deg"), pd.DataFrame) and isinstance(r.to_xarray(angle="deg"), xr.Dataset)
    with pytest.raises(kincas.ModelError, match="angle: expected 'rad' or 'deg'"):
        r.to_pandas(angle="grad")
    if name in ("solve", "sweep"):
        ts = T[1:] if name == "solve" else T
        for q, f in CLOSED.items():
            assert np.allclose(df[q].to_numpy(), [f(2.0, t) for t in ts], rtol=0, atol=1e-12)
            assert np.allclose(ds[q].values, [f(2.0, t) for t in ts], rtol=0, atol=1e-12)
            assert df.attrs["units"][q] == ds[q].attrs["units"] == "mm"
        deg, dsd = r.to_pandas(angle="deg"), r.to_xarray(angle="deg")
        assert np.allclose(deg.index.to_numpy(), [t * 180 / math.pi for t in ts], rtol=1e-15)
        assert np.allclose(dsd["crank.angle"].values, [t * 180 / math.pi for t in ts], rtol=1e-15)
        assert deg.attrs["units"]["crank.angle"] == dsd["crank.angle"].attrs["units"] == "deg"
        assert np.array_equal(deg["A.x"], df["A.x"])  # lengths untouched
    if name == "sweep_designs":
        for d, a in enumerate([1.0, 3.0]):
            for k, t in enumerate(T):
                assert abs(df.loc[(d, k), "A.x"] - a * math.cos(t)) < 1e-12
                assert abs(float(ds["A.x"][d, k]) - a * math.cos(t)) < 1e-12
        assert df.attrs["units"]["a"] == "mm" and ds["a"].attrs["units"] == "mm"
    if name == "study":
        assert np.allclose(df["max(A.x)"], [1.0, 3.0]) and np.allclose(df["a"], [1.0, 3.0])
        assert np.allclose(ds["max(A.x)"].values, [1.0, 3.0]) and df.attrs["units"]["a"] == "mm"
    if name == "sensitivities":
        assert np.allclose(df["d(A.x)/d(a)"], np.cos(T), rtol=0, atol=1e-12)
        assert np.allclose(ds["d(A.x)/d(a)"].values, np.cos(T), rtol=0, atol=1e-12)
    if name == "analyse":  # first order: std(A.x) = |cos t| 0.01
        assert np.allclose(df["std A.x"], 0.01 * np.abs(np.cos(T)), rtol=1e-9)
    if name == "optimize":  # minimum of (a - 1.5)^2 + (a cos 0.5 - 1.5)^2
        c = math.cos(0.5)
        assert abs(r.varied["a"] - 1.5 * (1 + c) / (1 + c * c)) < 1e-6
    if name == "modes":
        assert len(df) == 2 and ds.sizes["mode"] == 2 and r.certified == _certify_available()
    if name == "find_modes":  # a four-bar's link angles, in degrees on request
        assert np.allclose(r.to_pandas(angle="deg")["rocker.angle"], np.degrees(df["rocker.angle"]), rtol=1e-15)
        assert len(df) == 2 and ds.sizes["mode"] == 2 and r[0] is list(r)[0]  # still a list
    if name == "simulate":  # along the dimension `time`: A = a (cos t^2, sin t^2)
        ts = np.array([0.0, 0.5, 1.0])
        assert np.allclose(df["A.x"].to_numpy(), 2 * np.cos(ts ** 2), rtol=0, atol=1e-9)
        assert np.allclose(ds["A.y"].values, 2 * np.sin(ts ** 2), rtol=0, atol=1e-9)
        assert ds["A.x"].dims == ("time",) and df.index.name == "time"
        assert np.allclose(r.to_pandas(angle="deg")["crank.omega"], np.degrees(2 * ts), rtol=1e-9)
    if name == "input_range":
        assert r.full_turn and len(df) == 0 and ds.attrs["full_turn"] == 1


def test_tolerance_spreads_of_angles_in_degrees():
    # first order, the spread of an angle scales by 180/pi and a length's does not
    r = kincas.analyse(four_bar_a(), {"crank.angle": [0.0, 0.5]}, {"a": 0.01}, ["rocker.angle", "C.x"], draws=20)
    rad, deg = r.to_pandas(), r.to_pandas(angle="deg")
    assert np.allclose(deg["std rocker.angle"], rad["std rocker.angle"] * 180 / math.pi, rtol=1e-15)
    assert np.array_equal(deg["std C.x"], rad["std C.x"])
    x, y = r.to_xarray(), r.to_xarray(angle="deg")
    assert np.allclose(y.first_order.values, x.first_order.values * [180 / math.pi, 1.0], rtol=1e-15)
    assert list(y["units"].values) == ["deg", ""]


def four_bar_a():
    return kincas.Mechanism(parameters={"a": 1.0}, ground={"A": (0, 0), "D": (4, 0)},
                            links=[kincas.Link.bar("crank", "A", "B", "a"), kincas.Link.bar("coupler", "B", "C", 3.5),
                                   kincas.Link.bar("rocker", "D", "C", 3)],
                            inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
