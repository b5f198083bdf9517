"""Design studies and batched sweeps over designs, against independent answers.

Every design of a small grid is swept again by `kincas.sweep` (one design at a time, from the
guess) and its report expressions are computed here with numpy; the rocker's swing of a
crank-rocker against its closed form (the extremes where crank and coupler are collinear);
Latin hypercube samples against their strata; `[study]` fields that are wrong exit 2 naming
the field.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism
from kincas.synthesis.study import grid_designs, latin_hypercube
from conftest import EXAMPLES, run_cli

TH = np.linspace(0, 2 * np.pi, 73)


def fourbar(a=25.0, b=62.25, c=90.0, d=70.0):
    return Mechanism(parameters={"a2": a, "a3": b, "a4": c, "a5": d},
                     ground={"A": (0, 0), "D": ("a5", 0)},
                     links=[Link.bar("crank", "A", "B", "a2"), Link.bar("coupler", "B", "C", "a3"),
                            Link.bar("rocker", "D", "C", "a4")],
                     inputs=[Input.angle("crank")], guess={"C": (40, 80)})


def swing(a, b, c, d):
    """Closed form: the rocker's swing of a crank-rocker, between the poses where crank and
    coupler are collinear (A to C = b - a and b + a), by the law of cosines at D."""
    at_d = lambda r: math.acos((d * d + c * c - r * r) / (2 * d * c))
    return abs(at_d(b + a) - at_d(b - a))


# --- the batched sweep equals kincas.sweep design by design ---


@pytest.mark.parametrize("compile", [False, True])
def test_sweep_designs_equals_sweep_per_design(compile):
    m = fourbar()
    X = grid_designs([(80, 100), (60, 80)], [4, 3])  # includes designs that do not assemble
    r = kincas.sweep_designs(m, X, {"crank.angle": TH}, names=["a4", "a5"],
                             report=["C.x", "C.y", "rocker.omega"], compile=compile, workers=2)
    assert r.values["C.y"].shape == (12, len(TH))
    for d, (a4, a5) in enumerate(X):
        s = kincas.sweep(m.with_parameters(a4=a4, a5=a5), {"crank.angle": TH},
                         report=["C.x", "C.y", "rocker.omega"])
        ok = np.array(s.ok)
        if ok.all():
            assert r.design_ok[d]
        else:  # the first pose sweep could not reach: the design stops there
            first = int(np.argmin(ok))
            assert r.ok[d, :first].all() and not r.ok[d, first]
        both = r.ok[d]
        assert ok[both].all()
        for q in ("C.x", "C.y", "rocker.omega"):
            assert np.allclose(r.values[q][d, both], s[q][both], rtol=0, atol=1e-9)
            assert np.isnan(r.values[q][d, ~both]).all()
    assert (~r.design_ok).sum() == 1  # a4 - a5 = 40 > 37.25: not Grashof (a4 = 100, a5 = 60)
    assert r.failure(int(np.flatnonzero(~r.design_ok)[0]))[0] == "no assembly"


def test_study_values_equal_expressions_of_each_sweep():
    m = fourbar()
    rep = ["max(rocker.angle) - min(rocker.angle)", "max(C.y)", "mean(C.x) / a5", "a4 - a5"]
    r = kincas.study(m, {"a4": (84, 100), "a5": (60, 72)}, {"crank.angle": TH}, rep,
                     grid=(5, 4), degrees=True, workers=2, chunk=3)
    assert r.params.shape == (20, 2) and list(r.values) == rep
    for d, (a4, a5) in enumerate(r.params):
        s = kincas.sweep(m.with_parameters(a4=a4, a5=a5), {"crank.angle": TH},
                         report=["rocker.angle", "C.x", "C.y"])
        if not all(s.ok):
            assert r.status[d].startswith("no assembly at crank.angle = ")
            assert all(np.isnan(r.values[t][d]) for t in rep)
            continue
        assert r.status[d] == "ok"
        rock = np.degrees(s["rocker.angle"])
        want = [rock.max() - rock.min(), s["C.y"].max(), s["C.x"].mean() / a5, a4 - a5]
        assert np.allclose([r.values[t][d] for t in rep], want, rtol=1e-11, atol=1e-9)
        # and the swing against the closed form (sampled every 5 degrees: within 0.05 deg)
        assert abs(r.values[rep[0]][d] - math.degrees(swing(25, 62.25, a4, a5))) < 0.05
    assert (~r.ok).sum() == 1  # a4 - a5 > 37.25 only at (100, 60)


def test_study_status_on_the_first_pose_and_later():
    # A non-Grashof design that assembles at the first pose and fails later, mid-sweep.
    m = fourbar(a=30, b=50, c=45, d=70)  # 30 + 70 > 50 + 45: the crank cannot turn fully
    r = kincas.study(m, {"a4": (45, 45.5)}, {"crank.angle": TH}, ["max(C.y)"], grid=[2],
                     degrees=True)
    s = kincas.sweep(m, {"crank.angle": TH}, report=["C.y"])
    first = int(np.argmin(s.ok))
    assert first > 0
    assert r.status[0] == f"no assembly at crank.angle = {math.degrees(TH[first]):.6g}"


def test_latin_hypercube_is_stratified():
    n = 50
    X = latin_hypercube([(2.0, 4.0), (-1.0, 1.0), (10, 10.5)], n, seed=7)
    lo, hi = np.array([2.0, -1.0, 10]), np.array([4.0, 1.0, 10.5])
    strata = np.floor((X - lo) / (hi - lo) * n).astype(int)
    for j in range(3):  # exactly one sample in each stratum of each dimension
        assert sorted(strata[:, j].tolist()) == list(range(n))
    assert np.array_equal(X, latin_hypercube([(2.0, 4.0), (-1.0, 1.0), (10, 10.5)], n, seed=7))
    assert not np.array_equal(X, latin_hypercube([(2.0, 4.0), (-1.0, 1.0), (10, 10.5)], n, seed=8))


# --- the command line ---

SCENE = (EXAMPLES / "study_fourbar.toml").read_text()


def _with_study(tmp_path, section: str):
    text = SCENE[:SCENE.index("[study]")] + section
    text = text.replace("steps = 360", "steps = 37")
    p = tmp_path / "s.toml"
    p.write_text(text)
    return p


def test_cli_writes_one_row_per_design(tmp_path, capsys):
    p = _with_study(tmp_path, '[study]\nvary = { a4 = [95, 100], a5 = [60, 62] }\ngrid = [3, 2]\n'
                              'report = ["max(C.y)", "max(rocker.angle) - min(rocker.angle)"]\n')
    out = tmp_path / "r.csv"
    code, text, err = run_cli(capsys, "study", p, "--out", out, "--no-progress")
    assert code == 3, err  # a4 - a5 > 37.25: (97.5, 60), (100, 60), (100, 62) do not assemble
    import csv
    rows = list(csv.DictReader(out.open()))
    assert list(rows[0]) == ["a4", "a5", "status", "max(C.y)", "max(rocker.angle) - min(rocker.angle)"]
    assert len(rows) == 6 and [float(r["a4"]) for r in rows] == [95, 95, 97.5, 97.5, 100, 100]
    bad = [r for r in rows if r["status"] != "ok"]
    assert [(float(r["a4"]), float(r["a5"])) for r in bad] == [(97.5, 60), (100, 60), (100, 62)]
    assert all(r["max(C.y)"] == "" for r in bad)
    good = rows[1]
    s = kincas.sweep(fourbar(c=95, d=62), {"crank.angle": np.radians(np.linspace(0, 359, 37))},
                     report=["C.y", "rocker.angle"])
    assert float(good["max(C.y)"]) == pytest.approx(s["C.y"].max(), abs=1e-9)
    assert float(good["max(rocker.angle) - min(rocker.angle)"]) == pytest.approx(
        np.degrees(np.ptp(s["rocker.angle"])), abs=1e-9)


def test_cli_netcdf_and_parquet(tmp_path, capsys):
    xr = pytest.importorskip("xarray")
    pd = pytest.importorskip("pandas")
    pytest.importorskip("pyarrow")
    p = _with_study(tmp_path, '[study]\nvary = { a4 = [85, 95] }\nsamples = 5\nseed = 3\n'
                              'report = ["max(C.y)"]\n')
    code, _, err = run_cli(capsys, "study", p, "--out", tmp_path / "r.nc", "--plot", tmp_path / "m.png")
    assert code == 0, err
    ds = xr.open_dataset(tmp_path / "r.nc")
    assert ds["max(C.y)"].dims == ("design",) and ds.sizes["design"] == 5
    assert list(ds["status"].values) == ["ok"] * 5
    assert (tmp_path / "m.png").stat().st_size > 1000
    code, _, err = run_cli(capsys, "study", p, "--out", tmp_path / "r.parquet")
    df = pd.read_parquet(tmp_path / "r.parquet")
    assert list(df.columns) == ["a4", "status", "max(C.y)"]
    assert np.allclose(df["max(C.y)"], ds["max(C.y)"].values, rtol=0, atol=0)


@pytest.mark.parametrize("section, field", [
    ('vary = { a9 = [1, 2] }\ngrid = [3]\nreport = ["max(C.y)"]', "[study] vary: a9"),
    ('vary = { a4 = [2, 1] }\ngrid = [3]\nreport = ["max(C.y)"]', "[study] vary: a4"),
    ('vary = { a4 = [80, 90] }\ngrid = [3, 3]\nreport = ["max(C.y)"]', "[study] grid"),
    ('vary = { a4 = [80, 90] }\nreport = ["max(C.y)"]', "[study] grid, samples"),
    ('vary = { a4 = [80, 90] }\ngrid = [3]\nsamples = 4\nreport = ["max(C.y)"]', "[study] grid, samples"),
    ('vary = { a4 = [80, 90] }\nsamples = 0\nreport = ["max(C.y)"]', "[study] samples"),
    ('vary = { a4 = [80, 90] }\nsamples = 4\nseed = -1\nreport = ["max(C.y)"]', "[study] seed"),
    ('vary = { a4 = [80, 90] }\ngrid = [3]', "[study] report: missing"),
    ('vary = { a4 = [80, 90] }\ngrid = [3]\nreport = ["C.y"]', "[study] report: 'C.y' has a value per pose"),
    ('vary = { a4 = [80, 90] }\ngrid = [3]\nreport = ["max(Z.y)"]', "[study] report"),
    ('vary = { a4 = [80, 90] }\ngrid = [3]\nreport = ["max(C.y) + foo"]', "'foo' is not a parameter"),
    ('vary = { a4 = [80, 90] }\ngrid = [3]\nreport = ["max(C.y)"]\nsteps = 3', "[study]: unknown field 'steps'"),
])
def test_cli_bad_study_fields_exit_2(tmp_path, capsys, section, field):
    p = _with_study(tmp_path, "[study]\n" + section + "\n")
    code, _, err = run_cli(capsys, "study", p)
    assert code == 2 and field in err and "Traceback" not in err, err


def test_cli_bad_options_exit_2(tmp_path, capsys):
    p = _with_study(tmp_path, '[study]\nvary = { a4 = [85, 95] }\ngrid = [2]\nreport = ["max(C.y)"]\n')
    code, _, err = run_cli(capsys, "study", p, "--out", tmp_path / "r.xlsx")
    assert code == 2 and "--out" in err
    code, _, err = run_cli(capsys, "study", tmp_path / "missing.toml")
    assert code == 2
    p2 = tmp_path / "none.toml"
    p2.write_text(SCENE[:SCENE.index("[study]")])
    code, _, err = run_cli(capsys, "study", p2)
    assert code == 2 and "[study]" in err


def test_threads_give_the_numbers_of_one_thread_compiled():
    # Blocks of designs in the compiled kernel on two threads at once, against one thread and
    # against kincas.sweep: nothing that one C call reads may be shared or freed under it.
    m = fourbar()
    args = (m, {"a4": (84, 96), "a5": (62, 70)}, {"crank.angle": np.linspace(0, 2 * np.pi, 361)},
            ["max(C.y)", "mean(rocker.omega)"])
    one = kincas.study(*args, designs=24, seed=2, workers=1, compile=True)
    two = kincas.study(*args, designs=24, seed=2, workers=2, chunk=3, compile=True)
    assert one.status == two.status and one.ok.all()
    for t in args[3]:
        assert np.array_equal(one.values[t], two.values[t])
    a4, a5 = two.params[5]
    s = kincas.sweep(m.with_parameters(a4=a4, a5=a5), args[2], report=["C.y"])
    assert two.values["max(C.y)"][5] == pytest.approx(s["C.y"].max(), abs=1e-10)


def test_gaps_resume_finishes_a_design_as_kincas_sweep_does():
    # A crank that cannot turn fully: the sweep loses the assembly and finds it again.
    m = fourbar(a=30, b=50, c=45, d=70)
    stop = kincas.sweep_designs(m, {"a4": [45.0, 45.2]}, {"crank.angle": TH}, report=["C.y"])
    res = kincas.sweep_designs(m, {"a4": [45.0, 45.2]}, {"crank.angle": TH}, report=["C.y"],
                               gaps="resume")
    for d, a4 in enumerate([45.0, 45.2]):
        s = kincas.sweep(m.with_parameters(a4=a4), {"crank.angle": TH}, report=["C.y"])
        ok = np.array(s.ok)
        first = int(np.argmin(ok))
        assert 0 < first and ok[first:].any()  # a gap, then solved poses again
        assert stop.ok[d, :first].all() and not stop.ok[d, first:].any()
        assert (stop.status[d, first + 1:] == "not solved").all()
        assert np.array_equal(res.ok[d], ok)
        assert np.allclose(res.values["C.y"][d, ok], s["C.y"][ok], rtol=0, atol=1e-9)
