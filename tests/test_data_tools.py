"""Results in the data tools people use (issue [12]): pandas DataFrames and xarray Datasets
from sweeps, tolerance analyses, assembly modes and optimisations, checked against the
results' own arrays and a closed form."""
from __future__ import annotations

import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism

pd = pytest.importorskip("pandas")
xr = pytest.importorskip("xarray")


def fourbar(a=1.0):
    return Mechanism(parameters={"a": a}, ground={"A": (0, 0), "D": (4, 0)},
                     links=[Link.bar("crank", "A", "B", "a"), Link.bar("coupler", "B", "C", 3.5),
                            Link.bar("rocker", "D", "C", 3.0)],
                     inputs=[Input.angle("crank")], guess={"C": (3.6, 2.9)})


@pytest.fixture(scope="module")
def sw():
    return kincas.sweep(fourbar(2.8), {"crank.angle": np.linspace(0, 2 * np.pi, 37)},
                        report=["B.x", "C.x", "rocker.omega"])


def test_sweep_to_pandas(sw):
    df = sw.to_pandas()
    assert len(df) == len(sw) and df.index.name == "crank.angle"
    assert np.array_equal(df.index.to_numpy(), sw["crank.angle"])
    assert list(df.columns[:3]) == ["B.x", "C.x", "rocker.omega"]
    assert {"status", "flag"} <= set(df.columns)
    assert (df["status"] == "ok").to_numpy().tolist() == sw.ok.tolist()
    # B = (a cos t, a sin t): a closed form, checked in the frame
    t = df.index.to_numpy()
    assert np.allclose(df["B.x"].to_numpy()[sw.ok], 2.8 * np.cos(t[sw.ok]), atol=1e-12)
    assert df["C.x"].isna().to_numpy().tolist() == (~sw.ok).tolist()
    assert df.attrs["units"]["rocker.omega"] == "rad/s" and df.attrs["units"]["crank.angle"] == "rad"


def test_sweep_to_xarray(sw):
    ds = sw.to_xarray(length="mm")
    assert ds.sizes["pose"] == len(sw)
    assert np.array_equal(ds["crank.angle"].to_numpy(), sw["crank.angle"])
    assert np.array_equal(ds["C.x"].to_numpy(), sw["C.x"], equal_nan=True)
    assert ds["C.x"].attrs["units"] == "mm" and ds["rocker.omega"].attrs["units"] == "rad/s"
    assert ds["status"].to_numpy().tolist() == sw.status.tolist()
    assert ds["ok"].to_numpy().tolist() == sw.ok.tolist()


def test_two_inputs_are_a_multiindex():
    m = Mechanism(parameters={"a": 1.0}, ground={"A": (0, 0), "D": (4, 0)},
                  links=[Link.bar("crank", "A", "B", "a"), Link.bar("coupler", "B", "C", 3.5),
                         Link.bar("rocker", "D", "C", 3.0)],
                  inputs=[Input.angle("crank"), Input.parameter("a")], guess={"C": (3.6, 2.9)})
    s = kincas.sweep(m, {"crank.angle": np.linspace(0, 1, 5), "a": np.linspace(1, 1.2, 5)},
                     report=["B.y"])
    df = s.to_pandas()
    assert list(df.index.names) == ["crank.angle", "a"]
    t, a = (df.index.get_level_values(k).to_numpy() for k in ("crank.angle", "a"))
    assert np.allclose(df["B.y"].to_numpy(), a * np.sin(t), atol=1e-12)


def test_tolerance_to_pandas_and_xarray():
    r = kincas.analyse(fourbar(), {"crank.angle": np.linspace(0, 1, 4)}, std={"a": 0.01},
                       report=["B.x"], draws=200, seed=1)
    df = r.to_pandas()
    assert len(df) == 4 and df.index.name == "crank.angle"
    # B.x = a cos t: first-order std = 0.01 |cos t|
    t = df.index.to_numpy()
    assert np.allclose(df["std B.x"].to_numpy(), 0.01 * np.abs(np.cos(t)), rtol=1e-9)
    assert np.array_equal(df["mc B.x"].to_numpy(), r.monte_carlo["B.x"])
    assert {"status", "failed"} <= set(df.columns)
    ds = r.to_xarray()
    assert ds["first_order"].dims == ("pose", "quantity")
    assert ds["first_order"].sel(quantity="B.x").to_numpy() == pytest.approx(r.first_order["B.x"])


def test_modes_to_pandas_and_xarray():
    modes = kincas.find_modes(fourbar(), {"crank.angle": 0.5}, starts=32)
    df = modes.to_pandas()
    assert len(df) == 2 and {"C.x", "C.y", "residual", "orientation", "from_guess"} <= set(df.columns)
    # both assemblies keep |BC| = 3.5 and |DC| = 3
    bx, by = np.cos(0.5), np.sin(0.5)
    assert np.allclose(np.hypot(df["C.x"] - bx, df["C.y"] - by), 3.5, atol=1e-10)
    assert np.allclose(np.hypot(df["C.x"] - 4, df["C.y"]), 3.0, atol=1e-10)
    assert modes.to_xarray().sizes["mode"] == 2


def test_optimize_to_pandas_and_xarray():
    r = kincas.optimize(fourbar(), {"crank.angle": [np.pi / 2, np.pi / 3]}, vary={"a": (0.5, 1.5)},
                        minimize="sum((C.x - 3.0)^2)")
    df = r.to_pandas()
    assert len(df) == 2 and df.index.name == "crank.angle"
    assert np.array_equal(df["C.x"].to_numpy(), r.values["C.x"])
    assert df.attrs["parameters"]["a"] == r.parameters["a"]
    ds = r.to_xarray()
    assert ds.sizes["sample"] == 2 and ds.attrs["parameter a"] == r.parameters["a"]


def test_missing_pandas_is_one_line(sw, monkeypatch):
    import sys
    monkeypatch.setitem(sys.modules, "pandas", None)  # as if not installed: import fails
    monkeypatch.setitem(sys.modules, "xarray", None)
    with pytest.raises(ModuleNotFoundError, match=r'pip install "kincas\[data\]"'):
        sw.to_pandas()
    with pytest.raises(ModuleNotFoundError, match=r'pip install "kincas\[data\]"'):
        sw.to_xarray()
