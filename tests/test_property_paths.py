"""Property tests on random mechanisms (tests/random_mechanisms.py): the ways of solving one
sweep agree.

- Threads: the same sweeps run from four threads at once give bit-identical results.
- Compiled against careful: the fast pass (compiled to C, and in CasADi's virtual machine)
  against the careful path (continuation and Newton), to a few ulps times the conditioning.
- CLI against Python: the mechanism written as a scene file, `kincas solve --json`, against
  `kincas.sweep` on the same mechanism.
"""
from __future__ import annotations

import threading

import numpy as np
import pytest

import random_mechanisms as rm
from conftest import run_cli, write_scene

N = rm.count(6)
EPS = np.finfo(float).eps


def test_four_threads_give_bit_identical_sweeps():
    cases = [rm.case(f, s) for f in rm.FAMILIES for s in range(min(N, 2))]
    alone = [rm.solved(c) for c in cases]
    results, errors = {}, []

    def work(i):
        try:
            k = 7 * i % len(cases)
            order = cases[k:] + cases[:k]  # every thread runs every case, from its own start
            results[i] = {(c.family, c.seed): c.sweep(c.report_motion()) for c in order}
        except Exception as e:  # pragma: no cover - reported below
            errors.append(e)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    bad = []
    for i, got in results.items():
        for c, ref in zip(cases, alone):
            sw = got[(c.family, c.seed)]
            diff = [k for k in ref.values if not np.array_equal(ref[k], sw[k], equal_nan=True)]
            if diff or not np.array_equal(ref.status, sw.status):
                bad.append(f"thread {i}: {c.label}: {diff[:4]} differ from the one-thread sweep")
    assert not bad, "\n".join(bad)


def agreement_errors(c, a, b, what) -> list[str]:
    """a and b should agree to a few ulps times the conditioning: positions to 64 ulps of the
    coordinates' magnitude (the generator keeps the scaled Jacobian's smallest singular value
    above 0.03, so an ulp of the residual moves a position by at most ~33 ulps), each
    derivative order to the same relative amount of its natural scale times (1 + offset), and
    4 times more per order (each order's right-hand side gathers the lower orders' errors)."""
    sc = rm.natural_scales(c)
    far = 1 + c.offset
    order = {"x": 0, "y": 0, "s": 0, "angle": 0, "vx": 1, "vy": 1, "v": 1, "omega": 1,
             "ax": 2, "ay": 2, "a": 2, "alpha": 2, "jx": 3, "jy": 3, "jerk": 3}
    bad = []
    if not (a.ok.all() and b.ok.all()):
        return [f"{what}: poses not solved: {a.status.tolist()} / {b.status.tolist()}"]
    for k in a.values:
        obj, attr = k.rsplit(".", 1)
        kind = "angle" if attr in ("angle", "omega", "alpha", "jerk") else "length"
        tol = 64 * EPS * far * sc[kind][order[attr]] * 33 * 4 ** order[attr]
        err = np.abs(a[k] - b[k]).max()
        if kind == "angle" and attr == "angle":
            err = np.abs(np.angle(np.exp(1j * (a[k] - b[k])))).max()
        if not err <= tol:
            bad.append(f"{what}: {k} differs by {err / sc[kind][order[attr]]:.2e} of its scale "
                       f"(allowed {tol / sc[kind][order[attr]]:.1e})")
    return bad


COMPILED = ("fourbar_grashof", "quick_return", "triad", "five_bar")  # gcc: ~2 s a structure


@pytest.mark.parametrize("family", rm.FAMILIES)
def test_fast_pass_against_the_careful_path(family, monkeypatch):
    # the compiled loop held to its virtual-machine form bit for bit: both with libm's sines
    # (compiled kernels take fdlibm's otherwise, within an ulp: kincas/core/c_source.py)
    monkeypatch.setenv("KINCAS_LIBM_TRIG", "1")
    failures = []
    for c in rm.cases(family, N):
        careful = rm.solved(c, method="careful")
        vm = rm.solved(c, compile=False)
        failures += [f"{c.label}: {b}" for b in agreement_errors(c, vm, careful, "virtual machine")]
        if family in COMPILED and c.seed < 3:
            fast = rm.solved(c, compile=True)
            failures += [f"{c.label}: {b}" for b in agreement_errors(c, fast, careful, "compiled")]
            if not all(np.array_equal(fast[k], vm[k]) for k in fast.values):
                failures.append(f"{c.label}: the compiled loop differs from its virtual-machine form")
    assert not failures, "\n".join(failures)


@pytest.mark.parametrize("family", rm.FAMILIES)
def test_cli_json_against_python(family, capsys, tmp_path):
    failures = []
    for c in rm.cases(family, min(N, 2)):
        report = c.report_motion() + c.report_forces()
        path = write_scene(tmp_path, c.scene(report), f"{family}_{c.seed}.toml")
        code, out, err = run_cli(capsys, "solve", path, "--json")
        if code != 0 or not isinstance(out, dict):
            failures.append(f"{c.label}: kincas solve exited {code}: {err.strip()[:300]}")
            continue
        py = rm.solved(c, "forces")
        if out["status"] != py.status.tolist():
            failures.append(f"{c.label}: status {out['status']} against {py.status.tolist()}")
        for k in c.keys:
            if not np.array_equal(np.asarray(out["inputs"][k], float), c.inputs[k]):
                failures.append(f"{c.label}: the scene's sweep of {k} is not the Python one")
        for k in report:
            got = np.array([np.nan if v is None else v for v in out["values"][k]], float)
            want = py[k]
            # the CLI writes values within 1e-11 of a quantity's scale as 0 (kincas/cli/numbers.py)
            tol = 1e-11 * max(np.abs(want).max(), 1e-300) + 1e-12 * np.abs(want)
            if not np.all(np.abs(got - want) <= tol):
                failures.append(f"{c.label}: {k}: CLI {got.tolist()} against Python {want.tolist()}")
    assert not failures, "\n".join(failures)
