"""The sines and cosines the compiled sweep's loop hands a flat kernel (kincas/core/sweep_loop.py):

- the lifted kN and kF compute, from the sines and cosines of their unknowns and inputs, the
  same numbers as the kernel itself, bit for bit;
- the loop's turn of a pair by a Newton step (TRIG_C `ks_step`) is the sine and cosine of the
  new angle to rounding (30-digit mpmath), over the steps it turns and the ones it takes afresh;
- flat kernels take them, kernels written group by group do not;
- the sweeps that use them are the closed form's, with coarse steps (Newton's first step
  above the turn's reach) and fine ones."""
from __future__ import annotations

import ctypes

import casadi as ca
import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism, Slide
from kincas.core.c_library import Library, compiling_disabled
from kincas.core.fast import FastSweeper
from kincas.core.lifting import trig_pairs
from kincas.core.sweep_loop import TRIG_C, loop_trig

from test_fast import FOURBAR_REPORT, check_residuals, first_pose, fourbar, fourbar_closed, slider_closed
from test_group_kernel import chain

FIVE_BAR = Mechanism(ground={"A": (0, 0), "E": (2, 0)},
                     links=[Link.bar("c1", "A", "B", 1), Link.bar("c2", "E", "D", 1),
                            Link.bar("l1", "B", "C", 2.5), Link.bar("l2", "D", "C", 2.5)],
                     inputs=[Input.angle("c1"), Input.angle("c2")], guess={"C": (1, 2.3)})
SLIDER = Mechanism(ground={"O": (0, 0)}, links=[Link.bar("crank", "O", "A", 1.0), Link.bar("rod", "A", "B", 3.2)],
                   slides=[Slide("B", "ground", through=(0, 0.4), name="guide")],
                   inputs=[Input.angle("crank")], guess={"B": (4.2, 0.4)})


def _values(f, rng):
    """Random values for every input of f (positive, so that lengths and scales are)."""
    return [rng.uniform(0.2, 3.0, f.sparsity_in(i).nnz()) for i in range(f.n_in())]


@pytest.mark.parametrize("m, report, ntq, ntu", [(fourbar(), FOURBAR_REPORT, 2, 1),
                                                 (FIVE_BAR, ["C.x", "C.vy"], 2, 2),
                                                 (SLIDER, ["B.x", "B.vx"], 1, 1)])
def test_lifted_kernel_computes_the_kernel_from_its_sines_and_cosines(m, report, ntq, ntu):
    kN, kF, kL, kW = FastSweeper(kincas.model_of(m), report, compile=False).compiled_functions
    kNt, kFt, macros = loop_trig(kN, kF, libm=False)
    assert loop_trig(kN, kF, libm=True) == (kN, kF, {})  # libm's sines: the VM's numbers bit for bit
    assert (macros["KS_NTQ"], macros["KS_NTU"]) == (ntq, ntu)  # (the slider's length: no sine)
    pairs = trig_pairs([kN, kF], (0, 1))
    assert kNt.n_in() == kN.n_in() + 1 and kFt.n_in() == kF.n_in() + 1
    x = ca.SX.sym("x")
    sincos = ca.Function("sc", [x], [ca.sin(x), ca.cos(x)])  # as the kernel takes them
    rng = np.random.default_rng(7)
    for f, ft in ((kN, kNt), (kF, kFt)):
        for _ in range(5):
            a = _values(f, rng)
            t = np.concatenate([[float(v) for v in sincos(a[i][j])] for i, j in pairs])
            want, got = f(*a), ft(*a, t)
            want, got = (want,) if f.n_out() == 1 else want, (got,) if f.n_out() == 1 else got
            for w, g in zip(want, got):
                assert np.array_equal(np.asarray(w), np.asarray(g), equal_nan=True), f.name()
        # with wrong sines, other numbers: the lifted function reads t, not its own
        assert not np.array_equal(np.asarray(ft(*a, t + 0.1)[0]), np.asarray(f(*a)[0]))


def test_grouped_kernels_keep_their_own_and_tall_or_trigless_ones_take_none():
    long = FastSweeper(kincas.model_of(chain(20)), ["T20.x"], compile=False).compiled_functions
    assert long[0].is_a("MXFunction")
    kN, kF, macros = loop_trig(long[0], long[1], libm=False)
    assert macros == {} and kN is long[0] and kF is long[1]
    x = ca.SX.sym("x", 2)
    plain = ca.Function("kN", [x], [x * x])
    assert loop_trig(plain, plain, libm=False)[2] == {}


DRIVER = """
int kincas_turn(casadi_real* q, const casadi_real* dq, casadi_real* t) { ks_step(q, dq, t); return 0; }
"""


@pytest.mark.skipif(compiling_disabled(), reason="compiling disabled")
def test_a_newton_step_turns_the_sine_and_cosine_to_rounding(tmp_path, monkeypatch):
    mp = pytest.importorskip("mpmath")
    monkeypatch.setenv("KINCAS_CACHE", str(tmp_path))
    _V = ctypes.c_void_p
    try:
        lib = Library("kincas_test_turn", [], TRIG_C + DRIVER,
                      {"NQ": 1, "KS_NTQ": 1, "KS_NTU": 0, "KS_TRIG_Q_AT": "{0}", "KS_TRIG_U_AT": "{0}"},
                      {"kincas_turn": [_V, _V, _V]}).load()
    except RuntimeError as e:  # no compiler here
        pytest.skip(str(e))
    mp.mp.dps = 30
    rng = np.random.default_rng(3)
    worst = 0.0
    for q0 in [0.3, -2.9, 1.5707963267948966, 3.1, 1e-9, 40.0, -1e5]:
        # from the reach of the Taylor series down to a rounding-sized step, both signs, and
        # beyond it (sine and cosine afresh)
        for d in np.concatenate([np.geomspace(1e-15, 1e-3, 40), rng.uniform(1e-3, 0.5, 5)]):
            for step in (d, -d):
                q, dq = np.array([q0]), np.array([step])
                t = np.array([float(mp.sin(q0)), float(mp.cos(q0))])
                assert lib.kincas_turn(q.ctypes.data, dq.ctypes.data, t.ctypes.data) == 0
                assert q[0] == q0 - step  # q moved as the loop's other unknowns are
                want = (mp.sin(mp.mpf(q[0])), mp.cos(mp.mpf(q[0])))
                err = max(abs(float(t[k] - want[k])) for k in (0, 1))
                worst = max(worst, err)
    assert worst <= 3.5e-16  # a couple of rounding errors of numbers of size 1 (2^-52 = 2.2e-16)
    q, dq, t = np.array([0.5]), np.array([np.nan]), np.array([0.4, 0.9])
    lib.kincas_turn(q.ctypes.data, dq.ctypes.data, t.ctypes.data)
    assert np.isnan(t).all()  # a NaN step: NaN sines, as libm gives them


@pytest.mark.skipif(compiling_disabled(), reason="compiling disabled")
@pytest.mark.parametrize("n", [25, 361, 5001])  # 15 deg steps (Newton's first step beyond the
# turn's reach: afresh), 1 deg, 0.07 deg (the prediction within a rounding of the answer)
def test_sweeps_that_take_the_loops_sines_are_the_closed_form(n, tmp_path, monkeypatch):
    monkeypatch.setenv("KINCAS_CACHE", str(tmp_path))
    monkeypatch.delenv("KINCAS_LIBM_TRIG", raising=False)  # (fdlibm's, as users get them)
    monkeypatch.delenv("KINCAS_NO_COMPILE", raising=False)
    a, b, c, d = 1.0, 3.5, 3.0, 4.0
    th = np.linspace(0.3, 0.3 + 2 * np.pi, n)
    U = th[:, None]
    model, p, L, q0 = first_pose(fourbar(a, b, c, d), U)
    fast = FastSweeper(model, FOURBAR_REPORT, compile=True)
    run = fast.run(U, p, L, q0, U[0], start=1, Ud=[2.0])
    assert "#define KS_NTQ 2" in fast.backend.library.source  # the loop's sines, this kernel's
    vm = FastSweeper(model, FOURBAR_REPORT, compile=False).run(U, p, L, q0, U[0], start=1, Ud=[2.0])
    assert np.abs(run.Q[1:] - vm.Q[1:]).max() <= 1e-14  # the virtual machine's, to rounding
    assert run.first_bad == n
    if n == 25:
        assert run.iterations[1:].max() >= 2  # (steps long enough for Newton to take some)
    cf = fourbar_closed(th, a, b, c, d, w=2.0)
    for i, name in enumerate(FOURBAR_REPORT):
        err = np.abs(np.angle(np.exp(1j * (run.values[i, 1:] - cf[name][1:])))) if name == "rocker.angle" \
            else np.abs(run.values[i, 1:] - cf[name][1:])
        scale = (1.0 if "angle" in name or "omega" in name else L) * (2.0 if "omega" in name or ".v" in name else 1.0)
        assert err.max() <= 1e-12 * scale, name
    check_residuals(model, run, p, L)
    # the slider-crank: a length among the unknowns (no sine), the rod's angle turned
    model, p, L, q0 = first_pose(SLIDER, U)
    run = FastSweeper(model, ["B.x", "B.vx"], compile=True).run(U, p, L, q0, U[0], start=1, Ud=[2.0])
    assert run.first_bad == n
    cf = slider_closed(th, 1.0, 3.2, 0.4, 2.0, 0.0)
    assert np.abs(run.values[0, 1:] - cf["B.x"][1:]).max() <= 1e-12 * L
    assert np.abs(run.values[1, 1:] - cf["B.vx"][1:]).max() <= 2e-12 * L
    check_residuals(model, run, p, L)
