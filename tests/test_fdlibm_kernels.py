"""The compiled kernels as users get them: sines and cosines by fdlibm's algorithm, inline or as
a function each use calls (kincas/core/c_source.py SINCOS_C; the rest of the suite compiles
libm's, tests/conftest.py).
The answers are the closed forms' to 1e-12 of the size, every pose closes its loops, and the
compiled sweep agrees with the virtual machine's (libm's sines) to rounding."""
from __future__ import annotations

import numpy as np
import pytest

import kincas
from kincas.core.c_library import Library, compiling_disabled
from kincas.core.fast import FastSweeper

from test_fast import FOURBAR_REPORT, check_residuals, first_pose, fourbar, fourbar_closed
from test_group_kernel import chain

pytestmark = pytest.mark.skipif(compiling_disabled(), reason="compiling disabled")


@pytest.fixture(autouse=True, params=["inline", "call"])
def fdlibm(request, monkeypatch, tmp_path):
    monkeypatch.delenv("KINCAS_LIBM_TRIG", raising=False)
    # (a four-bar's kernel calls fdlibm's by default, below INLINE_TRIG_UNKNOWNS; inline, forced)
    monkeypatch.setattr("kincas.core.c_library.INLINE_TRIG_UNKNOWNS", 1 if request.param == "inline" else 10 ** 6)
    monkeypatch.setenv("KINCAS_CACHE", str(tmp_path))
    monkeypatch.delenv("KINCAS_NO_COMPILE", raising=False)


def _runs(m, report, U, Ud):
    model, p, L, q0 = first_pose(m, U)
    fast = FastSweeper(model, report, compile=True)
    a = fast.run(U, p, L, q0, U[0], start=1, Ud=Ud)
    src = fast.backend.library.source
    assert "#define KINCAS_LIBM_TRIG" not in src  # fdlibm's, as users get it
    assert ("#define KINCAS_TRIG_CALL" in src) == (fast.nq < kincas.core.c_library.INLINE_TRIG_UNKNOWNS)
    b = FastSweeper(model, report, compile=False).run(U, p, L, q0, U[0], start=1, Ud=Ud)
    assert a.first_bad == b.first_bad == len(U)
    return model, p, L, a, b


@pytest.mark.parametrize("scale, offset", [(1.0, 0.0), (1e-6, 0.0), (1e6, 0.0), (1.0, 1e6)])
def test_fourbar_is_its_closed_form(scale, offset):
    a, b, c, d = (scale * v for v in (1.0, 3.5, 3.0, 4.0))
    m = fourbar(a, b, c, d, guess=(scale * 3.6, scale * 2.9))
    if offset:  # far from the origin: the whole drawing moved
        m = kincas.Mechanism(parameters={"a": a, "b": b, "c": c},
                             ground={"A": (offset, offset), "D": (offset + d, offset)},
                             links=[kincas.Link.bar("crank", "A", "B", "a"), kincas.Link.bar("coupler", "B", "C", "b"),
                                    kincas.Link.bar("rocker", "D", "C", "c")],
                             inputs=[kincas.Input.angle("crank")], guess={"C": (offset + 3.6, offset + 2.9)})
    th = np.linspace(0.3, 0.3 + 4 * np.pi, 1441)  # two turns, 0.5 deg steps
    model, p, L, run, vm = _runs(m, FOURBAR_REPORT, th[:, None], [3.0])
    cf = fourbar_closed(th, a, b, c, d, w=3.0)
    for i, name in enumerate(FOURBAR_REPORT):
        got = run.values[i, 1:] - (offset if name in ("C.x", "C.y") else 0.0)
        want = cf[name][1:]
        size = 1.0 if "angle" in name or "omega" in name else L
        size *= 3.0 if ("omega" in name or ".v" in name) else 1.0
        if name == "rocker.angle":
            err = np.abs(np.angle(np.exp(1j * (got - want)))).max()
        else:
            err = np.abs(got - want).max()
        # (a coordinate far out is itself rounded at its own size: an ulp of 1e6 is 1.2e-10)
        far = 4 * np.finfo(float).eps * offset if name in ("C.x", "C.y") else 0.0
        assert err <= 1e-12 * size + far, (name, err / size)
        assert np.abs(run.values[i, 1:] - vm.values[i, 1:]).max() <= 1e-13 * size + far, name  # to rounding
    check_residuals(model, run, p, L)


def test_long_chain_written_group_by_group_is_its_closed_form():
    n = 20  # the grouped kernel (kincas/core/group_kernel.py), the quintic prediction on
    m = chain(n)
    th = np.radians(np.linspace(60, 120, 361))
    model, p, L, run, vm = _runs(m, [f"T{n}.x", f"T{n}.y"], th[:, None], [1.0])
    assert run.sweeper.functions[1].is_a("MXFunction") and run.sweeper.functions[4] is not None
    # unit by unit: T_k on the circles |T_k - T_(k-1)| = 4 and |T_k - G_k| = 1, upper side
    prev = np.stack([np.cos(th), np.sin(th)])
    for k in range(1, n + 1):
        G = np.array([[4.0 * k], [0.0]])
        e = G - prev
        f = np.hypot(*e)
        x = (16 - 1 + f * f) / (2 * f)
        h = np.sqrt(16 - x * x)
        prev = prev + e / f * x + h * np.stack([-e[1], e[0]]) / f
    assert np.abs(run.values[0, 1:] - prev[0, 1:]).max() <= 1e-12 * L
    assert np.abs(run.values[1, 1:] - prev[1, 1:]).max() <= 1e-12 * L
    assert np.abs(run.Q[1:] - vm.Q[1:]).max() <= 1e-13
    check_residuals(model, run, p, L)


def test_small_kernels_call_fdlibms_sines_and_large_ones_have_them_inline(monkeypatch):
    monkeypatch.setattr("kincas.core.c_library.INLINE_TRIG_UNKNOWNS", 16)
    small = FastSweeper(kincas.model_of(fourbar()), ["C.x"], compile=True)
    large = FastSweeper(kincas.model_of(chain(8)), ["T8.x"], compile=True)
    assert small.nq < 16 <= large.nq
    assert small._library().source.startswith("#define KINCAS_TRIG_CALL 1\n")
    assert not large._library().source.startswith("#define KINCAS_")
    # the quantities' library of a long sweep's careful poses by the same rule
    from kincas.core.fast import evaluator_for
    assert evaluator_for(small.model, ["C.x"])._library().source.startswith("#define KINCAS_TRIG_CALL 1\n")
    assert not evaluator_for(large.model, ["T8.x"])._library().source.startswith("#define KINCAS_")
    monkeypatch.setenv("KINCAS_LIBM_TRIG", "1")  # libm's, whatever the size
    assert small._library().source.startswith("#define KINCAS_LIBM_TRIG 1\n")
    assert large._library().source.startswith("#define KINCAS_LIBM_TRIG 1\n")
    with pytest.raises(ValueError, match="trig"):
        Library("kincas_x", [], "", {}, {}, trig="fast")
