"""Threads and processes at once: every sweep gives exactly its one-thread answer.

Four different four-bars are swept at the same time from four threads (careful path and
the default path), and from two processes; each result must equal, bit for bit, the same
sweep run alone, and match the closed form of its four-bar.
"""
from __future__ import annotations

import json
import subprocess
import sys
import threading

import numpy as np
import pytest

from conftest import ROOT

import kincas

# crank a, coupler b, rocker c, ground d: all Grashof crank-rockers (a shortest, a + max <= rest)
DIMS = [(1.0, 3.5, 3.0, 4.0), (1.2, 3.0, 2.8, 3.5), (0.8, 4.0, 3.5, 4.2), (1.5, 5.0, 4.5, 5.5)]
U = np.linspace(0.0, 2 * np.pi, 61)


def fourbar(a, b, c, d) -> kincas.Mechanism:
    """Lengths as parameters: the four mechanisms share one structure (one cached model)."""
    return kincas.Mechanism(
        parameters={"a": a, "b": b, "c": c, "d": d},
        ground={"A": (0, 0), "D": ("d", 0)},
        links=[kincas.Link.bar("crank", "A", "B", "a"), kincas.Link.bar("coupler", "B", "C", "b"),
               kincas.Link.bar("rocker", "D", "C", "c")],
        inputs=[kincas.Input.angle("crank")], guess={"C": (d - 0.3 * c, 0.9 * c)})


def closed_form(a, b, c, d, t):
    """C of the four-bar on the branch above the diagonal BD (the guess's)."""
    B = np.stack([a * np.cos(t), a * np.sin(t)])
    D = np.array([[d], [0.0]])
    e = D - B
    f = np.hypot(*e)
    x = (b * b - c * c + f * f) / (2 * f)  # along BD from B
    h = np.sqrt(b * b - x * x)
    n = np.stack([-e[1], e[0]]) / f  # left normal of B -> D
    return B + e / f * x + h * n


def run(dims, method):
    s = kincas.sweep(fourbar(*dims), {"crank.angle": U}, rates={"crank.angle": 1.0},
                     report=["C.x", "C.y", "rocker.omega"], method=method)
    assert all(st == "ok" for st in s.status)
    return np.array([s["C.x"], s["C.y"], s["rocker.omega"]])


# (the fast path's own threads and processes, compiled: tests/test_fast_threads.py)
@pytest.mark.parametrize("method", ["careful", "fast"])
def test_four_threads_four_fourbars(method):
    alone = [run(d, method) for d in DIMS]
    for d, r in zip(DIMS, alone):
        assert np.abs(r[:2] - closed_form(*d, U)).max() < 1e-12 * d[3]
    rounds = 4 if method == "careful" else 8
    results, errors = {}, []

    def work(i):
        try:
            results[i] = [run(DIMS[i], method) for _ in range(rounds)]
        except Exception as e:  # pragma: no cover - reported below
            errors.append(e)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(len(DIMS))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    wrong = sum(not np.array_equal(r, alone[i]) for i in results for r in results[i])
    assert wrong == 0, f"{wrong} of {rounds * len(DIMS)} threaded sweeps differ from their one-thread answer"


_CHILD = """
import json, sys
import numpy as np
sys.path.insert(0, {tests!r})
from test_threads import DIMS, run
out = [run(DIMS[{i}], m).tolist() for m in ("careful", "fast") for _ in range(3)]
print(json.dumps(out))
"""


def test_two_processes_at_once():
    procs = [subprocess.Popen([sys.executable, "-c", _CHILD.format(tests=str(ROOT / "tests"), i=i)],
                              stdout=subprocess.PIPE, text=True, cwd=ROOT) for i in (0, 3)]
    outs = [json.loads(p.communicate(timeout=300)[0]) for p in procs]
    for i, out in zip((0, 3), outs):
        for r in out:
            r = np.array(r)
            assert np.abs(r[:2] - closed_form(*DIMS[i], U)).max() < 1e-12 * DIMS[i][3]
        assert all(np.array_equal(np.array(r), np.array(out[0])) for r in out[:3])


def _in_threads(fn, args):
    """fn(arg) for every arg, each in its own thread, all at once; the results in order."""
    out, errors = [None] * len(args), []

    def work(i):
        try:
            out[i] = fn(args[i])
        except Exception as e:  # pragma: no cover - reported below
            errors.append(e)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(len(args))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    return out


def test_modes_and_tolerance_from_threads():
    from kincas.analysis.modes import find_modes
    from kincas.analysis.tolerance import analyse

    def modes(d):
        return np.array([md.q for md in find_modes(fourbar(*d), {"crank.angle": 0.7}, starts=48)])

    def tol(d):
        r = analyse(fourbar(*d), {"crank.angle": U[:7]}, std={"a": 0.01, "b": 0.01},
                    report=["C.y"], draws=200, seed=3)
        return np.concatenate([r.monte_carlo["C.y"], r.first_order["C.y"]])

    for fn in (modes, tol):
        alone = [fn(d) for d in DIMS]
        together = _in_threads(fn, DIMS * 2)
        assert all(np.array_equal(t, alone[i % len(DIMS)]) for i, t in enumerate(together))
    # the two modes of each four-bar: C above and below the diagonal BD, as the closed form
    for d in DIMS:
        C = closed_form(*d, np.array([0.7]))[:, 0]
        m = fourbar(*d)
        ys = sorted(md.points["C"][1] for md in find_modes(m, {"crank.angle": 0.7}, starts=48))
        assert abs(ys[-1] - C[1]) < 1e-12 * d[3]
