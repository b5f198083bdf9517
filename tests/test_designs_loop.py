"""The compiled loop over whole designs (kincas/core/designs_kernel.py) and its fallbacks.

Designs that the loop cannot finish (no assembly at the first pose, the assembly lost
mid-sweep) must go to the careful path and come back with a status and null values, while
their neighbours keep their numbers: each is checked against `kincas.sweep` of that design
alone and against the loop-closure equations (|BC| = a3, |DC| = a4) written here. Two
threads must give the numbers of one, bit for bit.
"""
from __future__ import annotations

import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism
from kincas.core import designs_kernel

TH = np.linspace(np.pi / 2, np.pi / 2 + 2 * np.pi, 73)  # from 90 deg: B above the ground
REPORT = ["B.x", "B.y", "C.x", "C.y", "rocker.omega"]
NAMES = ["a2", "a4", "a5"]
DESIGNS = np.array([[25.0, 90.0, 70.0],    # the nominal
                    [35.0, 90.0, 70.0],    # Grashof: a full turn
                    [45.0, 90.0, 70.0],    # 45 + 90 > 62.25 + 70: lost near crank angle 0
                    [25.0, 10.0, 100.0],   # |AD| - ... : C out of reach at every crank angle
                    [30.0, 85.0, 72.0]])   # Grashof


def fourbar():
    return Mechanism(parameters={"a2": 25.0, "a3": 62.25, "a4": 90.0, "a5": 70.0},
                     ground={"A": (0, 0), "D": ("a5", 0)},
                     links=[Link.bar("crank", "A", "B", "a2"), Link.bar("coupler", "B", "C", "a3"),
                            Link.bar("rocker", "D", "C", "a4")],
                     inputs=[Input.angle("crank")], guess={"C": (40, 80)})


@pytest.fixture
def loop_stops(monkeypatch):
    """What the compiled loop returned for each design, collected over a call."""
    seen = []
    full = designs_kernel.DesignsLoop.full

    def spy(self, *args):
        out = full(self, *args)
        seen.append(out.copy())
        return out
    monkeypatch.setattr(designs_kernel.DesignsLoop, "full", spy)
    return seen


def test_rejected_designs_fall_back_and_neighbours_keep_their_numbers(loop_stops):
    m = fourbar()
    r = kincas.sweep_designs(m, DESIGNS, {"crank.angle": TH}, names=NAMES, report=REPORT,
                             compile=True, workers=1)
    stops = np.concatenate(loop_stops)
    n = len(TH)
    assert stops[3] == -1  # no first pose: to the careful path
    assert 0 < stops[2] < n  # lost mid-sweep: the careful path takes the rejected pose
    assert stops[0] == n and (stops[[1, 4]] > 0).all()  # the others' first poses in the loop
    # the design out of reach: status and null values at every pose
    assert r.status[3, 0] == "no assembly" and (r.status[3, 1:] == "not solved").all()
    assert all(np.isnan(r.values[q][3]).all() for q in REPORT)
    for d, (a2, a4, a5) in enumerate(DESIGNS):
        s = kincas.sweep(m.with_parameters(a2=a2, a4=a4, a5=a5), {"crank.angle": TH}, report=REPORT)
        ok = np.array(s.ok)
        if d == 2:  # stops where kincas.sweep first fails; "not solved" after it
            first = int(np.argmin(ok))
            assert 0 < first < n and r.ok[d, :first].all()
            # the poses near the limit, which the kernel rejects in one step, are reached in
            # shorter ones inside the loop: it stops only where there is no assembly
            assert stops[d] == first
            assert r.status[d, first] == "no assembly" and not r.ok[d, first:].any()
        elif d != 3:
            assert ok.all() and r.design_ok[d]
        both = r.ok[d]
        for q in REPORT:
            assert np.allclose(r.values[q][d, both], s[q][both], rtol=0, atol=1e-9)
            assert np.isnan(r.values[q][d, ~both]).all()
        # loop closure, independently of kincas: |BC| = a3 and |DC| = a4 at every solved pose
        bx, by, cx, cy = (r.values[q][d, both] for q in REPORT[:4])
        assert np.allclose(np.hypot(cx - bx, cy - by), 62.25, rtol=0, atol=1e-11)
        assert np.allclose(np.hypot(cx - a5, cy), a4, rtol=0, atol=1e-11)
        assert np.allclose(np.hypot(bx, by), a2, rtol=0, atol=1e-11)


def test_loop_equals_the_uncompiled_path():
    m = fourbar()
    kw = dict(names=NAMES, report=REPORT, workers=1)
    a = kincas.sweep_designs(m, DESIGNS, {"crank.angle": TH}, compile=True, **kw)
    b = kincas.sweep_designs(m, DESIGNS, {"crank.angle": TH}, compile=False, **kw)
    assert np.array_equal(a.code, b.code)
    for q in REPORT:
        assert np.allclose(a.values[q], b.values[q], rtol=0, atol=1e-9, equal_nan=True)


def test_two_threads_give_the_numbers_of_one_bit_for_bit(loop_stops):
    m = fourbar()
    rng = np.random.default_rng(3)
    X = np.vstack([DESIGNS, DESIGNS[[0]] + rng.uniform(-3, 3, (35, 3))])
    th = np.linspace(0, 2 * np.pi, 181)
    one = kincas.sweep_designs(m, X, {"crank.angle": th}, names=NAMES, report=REPORT,
                               compile=True, workers=1)
    calls = len(loop_stops)
    two = kincas.sweep_designs(m, X, {"crank.angle": th}, names=NAMES, report=REPORT,
                               compile=True, workers=2)
    assert len(loop_stops) - calls > 2  # several blocks: on two threads at once
    assert np.array_equal(one.code, two.code) and (one.code == 0).sum() > 30 * 181
    for q in REPORT:
        assert np.array_equal(one.values[q], two.values[q], equal_nan=True)


def test_monte_carlo_chunks_on_two_threads_equal_one_thread_and_a_numpy_reference():
    # 2,100 samples: two chunks of the executor, merged pairwise; on 1 and 2 threads.
    from kincas.analysis.tolerance import analyse

    m = fourbar()
    th = np.linspace(0, 2 * np.pi, 37)
    std = {"a2": 0.05, "a4": 0.05, "a5": 0.05}
    one = analyse(m, {"crank.angle": th}, std, ["C.y", "rocker.angle"], draws=2100, seed=5, workers=1)
    two = analyse(m, {"crank.angle": th}, std, ["C.y", "rocker.angle"], draws=2100, seed=5, workers=2)
    for q in ("C.y", "rocker.angle"):
        assert np.array_equal(one.monte_carlo[q], two.monte_carlo[q])
        assert np.array_equal(one.mean_shift[q], two.mean_shift[q])
    # the same draws swept here design by design in one batch, std and mean in one pass of numpy
    rng = np.random.default_rng(5)
    dp = rng.standard_normal((2100, 3)) * np.array([0.05, 0.05, 0.05])
    X = np.array([25.0, 90.0, 70.0]) + dp
    r = kincas.sweep_designs(m, X, {"crank.angle": th}, names=["a2", "a4", "a5"], report=["C.y"],
                             compile=True, workers=1)
    assert r.design_ok.all()
    nominal = kincas.sweep(m, {"crank.angle": th}, report=["C.y"])["C.y"]
    d = r.values["C.y"] - nominal
    assert np.allclose(one.monte_carlo["C.y"], d.std(axis=0, ddof=1), rtol=1e-9, atol=1e-13)
    assert np.allclose(one.mean_shift["C.y"], d.mean(axis=0), rtol=1e-7, atol=1e-13)
