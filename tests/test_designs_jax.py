"""The JAX backend of `kincas.sweep_designs` (on JAX's CPU backend), against independent answers.

Every design of a small grid of four-bars and of slider-cranks is swept again by
`kincas.sweep` (one design at a time) and compared pose by pose; positions also against the
closed forms (circle-circle and line-circle intersections on the branch of the guess), and
the JAX pass must have done the work (not handed every pose to the CPU). A design that does
not assemble gets a status and nulls; a nominal design on the crossed branch keeps every
design on it. The translation of casadi into JAX is checked on a function with an awkward
constant and every comparison.
"""
from __future__ import annotations

import sys

import casadi as ca
import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism, Slide

pytest.importorskip("jax")
pytest.importorskip("jaxadi")

from kincas.analysis import designs_jax  # noqa: E402
from kincas.core import jax_backend  # noqa: E402

TH = np.linspace(0, 2 * np.pi, 73)
TOL = 1e-12
FOURBAR = ["C.x", "C.y", "rocker.angle", "C.vx", "C.vy", "rocker.omega"]  # one report: one compile


def fourbar(side=1):
    return Mechanism(parameters={"a2": 25.0, "a3": 62.25, "a4": 90.0, "a5": 70.0},
                     ground={"A": (0, 0), "D": ("a5", 0)},
                     links=[Link.bar("crank", "A", "B", "a2"), Link.bar("coupler", "B", "C", "a3"),
                            Link.bar("rocker", "D", "C", "a4")],
                     inputs=[Input.angle("crank")], guess={"C": (40, 80 * side)})


def fourbar_C(a2, a3, a4, a5, th, side):
    """Closed form: C on the circles about B (radius a3) and D (radius a4), on the side of
    the line B -> D that `side` names (+1: left)."""
    B = np.stack([a2 * np.cos(th), a2 * np.sin(th)], axis=1)
    D = np.array([a5, 0.0])
    e = D - B
    dist = np.hypot(e[:, 0], e[:, 1])
    x = (dist ** 2 + a3 ** 2 - a4 ** 2) / (2 * dist)
    h = np.sqrt(a3 ** 2 - x ** 2)
    n = e / dist[:, None]
    perp = np.stack([-n[:, 1], n[:, 0]], axis=1)
    return B + x[:, None] * n + side * h[:, None] * perp


def slider_crank():
    return Mechanism(parameters={"r": 50.0, "l": 180.0, "e": 20.0}, ground={"O": (0, 0)},
                     links=[Link.bar("crank", "O", "A", "r"), Link.bar("rod", "A", "B", "l")],
                     slides=[Slide("B", "ground", through=(0, "e"), angle=0.0, name="guide")],
                     inputs=[Input.angle("crank")], guess={"B": (200, 20)})


@pytest.fixture
def spy(monkeypatch):
    """The stops of every JAX pass (where it handed a design to the CPU)."""
    seen = []
    real = designs_jax.jax_pass

    def spying(job, todo, thr):
        stops = real(job, todo, thr)
        seen.append(np.asarray(stops))
        return stops
    monkeypatch.setattr(designs_jax, "jax_pass", spying)
    return seen


def same_as_sweep(m, r, X, names, report):
    """Each design of r equals kincas.sweep of that design (from the guess), pose by pose."""
    for d, row in enumerate(X):
        s = kincas.sweep(m.with_parameters(**dict(zip(names, row))), {"crank.angle": TH}, report=report)
        ok = np.array(s.ok)
        if not ok.all():  # the batched sweep stops at the first pose sweep could not solve
            first = int(np.argmin(ok))
            assert r.ok[d, :first].all() and not r.ok[d, first:].any()
        else:
            assert r.design_ok[d]
        both = r.ok[d]
        for q in report:
            scale = 1.0 if q.endswith(("angle", "omega")) else 100.0
            assert np.abs(r.values[q][d, both] - s[q][both]).max(initial=0.0) <= TOL * scale, (d, q)
            assert np.isnan(r.values[q][d, ~both]).all()


# --- values equal kincas.sweep design by design ---


def test_fourbars_equal_sweep_closed_form_and_unassembled_designs_get_status(spy):
    m = fourbar()
    X = np.array([[a4, a5] for a4 in (80.0, 90.0, 100.0) for a5 in (60.0, 70.0)] + [[90.0, 200.0]])
    rep = FOURBAR
    r = kincas.sweep_designs(m, X, {"crank.angle": TH}, names=["a4", "a5"], report=rep,
                             backend="jax", workers=2)
    same_as_sweep(m, r, X, ["a4", "a5"], rep)
    for d, (a4, a5) in enumerate(X):
        ok = r.ok[d]
        C = fourbar_C(25.0, 62.25, a4, a5, TH[ok], side=1)  # the guess: C left of B -> D
        assert np.abs(r.values["C.x"][d, ok] - C[:, 0]).max(initial=0.0) <= TOL * 100
        assert np.abs(r.values["C.y"][d, ok] - C[:, 1]).max(initial=0.0) <= TOL * 100
    # a4 - a5 = 40 > a3 - a2 = 37.25: not Grashof, the crank cannot turn; a5 = 200: never (B to D >= 175 > a3 + a4)
    bad = {int(d) for d in np.flatnonzero(~r.design_ok)}
    assert bad == {4, 6}
    assert r.failure(4)[0] == "no assembly" and r.failure(6) == ("no assembly", 0)
    assert np.isnan(r.values["C.y"][6]).all() and (r.status[6] == "no assembly").sum() == 1
    ds = r.to_xarray()
    assert ds["C.x"].dims == ("design", "pose") and ds["status"].shape == (7, len(TH))
    # the JAX pass did the work: of the 5 designs assembled at pose 0, 4 it swept whole (the
    # compiled kernel too hands (90, 60)'s second pose, 5 degrees on, to the careful path)
    stops = np.concatenate(spy)
    assert len(stops) == 5 and (stops == len(TH)).sum() >= 4


def test_slider_cranks_equal_sweep_and_closed_form(spy):
    m = slider_crank()
    X = np.array([[r_, e] for r_ in (40.0, 50.0, 60.0) for e in (0.0, 20.0, -15.0)])
    rep = ["B.x", "guide.s", "rod.angle", "B.vx", "rod.omega"]
    r = kincas.sweep_designs(m, X, {"crank.angle": TH}, names=["r", "e"], report=rep, backend="jax")
    assert r.design_ok.all()
    same_as_sweep(m, r, X, ["r", "e"], rep)
    for d, (r_, e) in enumerate(X):  # B on the line y = e, right of the crank pin
        x = r_ * np.cos(TH) + np.sqrt(180.0 ** 2 - (e - r_ * np.sin(TH)) ** 2)
        assert np.abs(r.values["B.x"][d] - x).max(initial=0.0) <= TOL * 240
    assert (np.concatenate(spy) == len(TH)).all()


def test_nominal_on_the_crossed_branch_keeps_every_design_on_it():
    m = fourbar(side=-1)  # C below: the other assembly of the same four-bar
    X = np.array([[85.0, 65.0], [90.0, 70.0], [95.0, 72.0]])
    r = kincas.sweep_designs(m, X, {"crank.angle": TH}, names=["a4", "a5"], report=FOURBAR,
                             backend="jax")
    assert r.design_ok.all()
    for d, (a4, a5) in enumerate(X):
        C = fourbar_C(25.0, 62.25, a4, a5, TH, side=-1)  # C right of B -> D: below the ground line
        assert np.abs(r.values["C.x"][d] - C[:, 0]).max(initial=0.0) <= TOL * 100
        assert np.abs(r.values["C.y"][d] - C[:, 1]).max(initial=0.0) <= TOL * 100
    assert (r.values["C.y"] < 0).all()


# --- the translation and the user's mistakes ---


def test_translation_keeps_constants_exact_and_comparisons_numeric():
    x = ca.SX.sym("x", 3)
    c = 1.2345678901234567e-9
    e = ca.vertcat(x[0] * c, ca.if_else(x[1] > 0.5, ca.sin(x[2]), ca.cos(x[2])),
                   (x[0] < x[1]) + (x[1] < x[2]), ca.logic_and(x[0] > 0, x[2] >= 1) * 3.0,
                   ca.atan2(x[1], -x[2]), ca.fmax(x[0], x[2]) ** 2.5)
    f = ca.Function("f", [x], [e])
    import jax
    jf = jax.jit(jax_backend.to_jax(f))
    for v in ([0.3, 0.7, 1.2], [0.9, 0.2, -0.4]):
        with jax_backend.x64():
            got = np.asarray(jf(np.array(v))[0])
        want = np.asarray(f(v)).ravel()
        assert got.dtype == np.float64
        assert np.array_equal(got[[0, 2, 3]], want[[0, 2, 3]])  # exact: one rounding each
        assert np.allclose(got, want, rtol=1e-15, atol=0)


def test_unknown_backend_and_missing_jax_are_one_line_errors(monkeypatch):
    m, U = fourbar(), {"crank.angle": TH}
    with pytest.raises(kincas.ModelError, match="backend: 'gpu'"):
        kincas.sweep_designs(m, {"a4": [90.0]}, U, backend="gpu")
    monkeypatch.setitem(sys.modules, "jaxadi", None)  # as if not installed
    assert not jax_backend.available()
    with pytest.raises(kincas.ModelError, match=r"kincas\[gpu\]"):
        kincas.sweep_designs(slider_crank(), {"r": [45.0]}, U, report=["B.y"], backend="jax")


# --- kincas study --backend jax ---


def test_cli_study_backend_jax_writes_the_rows_of_the_casadi_backend(tmp_path, capsys, monkeypatch):
    import csv

    from conftest import EXAMPLES, run_cli
    text = (EXAMPLES / "study_fourbar.toml").read_text()
    text = text[:text.index("[study]")].replace("to = 359, steps = 360", "to = 360, steps = 73")
    # the quantities of FOURBAR in its order: the JAX functions of the tests above serve
    text += ('[study]\nvary = { a4 = [90, 100], a5 = [60, 70] }\ngrid = [3, 2]\nreport = ["max(C.x)", '
             '"max(C.y)", "max(rocker.angle) - min(rocker.angle)", "max(C.vx)", "max(C.vy)", "max(rocker.omega)"]\n')
    p = tmp_path / "s.toml"
    p.write_text(text)
    rows = {}
    for backend in ("casadi", "jax"):
        out = tmp_path / f"{backend}.csv"
        code, _, err = run_cli(capsys, "study", p, "--out", out, "--no-progress", "--backend", backend)
        assert code == 3, err  # (100, 60): a4 - a5 > 37.25, the crank cannot turn
        rows[backend] = list(csv.DictReader(out.open()))
    assert [r["status"] for r in rows["jax"]] == [r["status"] for r in rows["casadi"]]
    assert sum(r["status"] != "ok" for r in rows["jax"]) == 1
    for a, b in zip(rows["casadi"], rows["jax"]):
        for k, v in a.items():
            if k != "status":
                assert (v == "" and b[k] == "") or abs(float(v) - float(b[k])) <= 1e-10 * max(1.0, abs(float(v)))
    code, _, err = run_cli(capsys, "study", p, "--backend", "gpu")
    assert code == 2 and "--backend" in err
    from kincas.cli import study as cli_study
    monkeypatch.setattr(cli_study, "_has", lambda mod: mod not in ("jax", "jaxadi"))
    code, _, err = run_cli(capsys, "study", p, "--backend", "jax")
    assert code == 2 and "kincas[gpu]" in err and len(err.strip().splitlines()) == 1


def test_poses_the_jax_pass_cannot_verify_are_finished_on_the_cpu_on_the_branch(spy):
    # A rod 1e-7 longer than the crank: the two assemblies pass 2e-2 apart near 90 and 270 deg,
    # where g_q is nearly singular; the JAX pass hands those poses to the careful path, which
    # keeps the branch of the guess (B right of the crank pin).
    m = slider_crank()
    X = np.array([[50.0, 50.0 + 5e-6, 0.0], [50.0, 50.0 + 1e-5, 0.0]])
    r = kincas.sweep_designs(m, X, {"crank.angle": TH}, names=["r", "l", "e"], report=["B.x", "guide.s"],
                             backend="jax")
    assert r.design_ok.all()
    stops = np.concatenate(spy)
    assert (stops < len(TH)).all()  # handed over, not taken from the JAX pass
    for d, (r_, l_, _) in enumerate(X):
        x = r_ * np.cos(TH) + np.sqrt(l_ ** 2 - (r_ * np.sin(TH)) ** 2)
        assert np.abs(r.values["B.x"][d] - x).max() <= 1e-8 * (r_ + l_)
