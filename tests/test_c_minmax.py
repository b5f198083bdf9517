"""The compiled libraries' max and min (kincas/core/c_library.py `inline_minmax`) give C99's
fmax / fmin: a NaN argument gives the other one, two NaNs a NaN. The kernel's tests rely on
it: `_max_abs` (kincas/core/group_kernel.py) adds 0 * sum(v) so that a NaN anywhere fails
the pose, which a maximum that dropped or kept NaNs differently would change."""
from __future__ import annotations

import ctypes

import casadi as ca
import numpy as np
import pytest

from kincas.core.c_library import Library, compiling_disabled, inline_minmax

DRIVER = """
int kincas_minmax(const casadi_real* x, const casadi_real* y, casadi_real* out) {
  const casadi_real* arg[SZ_ARG]; casadi_real* res[SZ_RES]; casadi_int iw[SZ_IW]; casadi_real w[SZ_W];
  arg[0] = x; arg[1] = y; res[0] = out;
  return mm(arg, res, iw, w, 0);
}
"""


def test_helpers_call_the_inline_versions():
    x, y = ca.SX.sym("x"), ca.SX.sym("y")
    f = ca.Function("mm", [x, y], [ca.vertcat(ca.fmax(x, y), ca.fmin(x, y))])
    cg = ca.CodeGenerator("t.c", {"with_header": False})
    cg.add(f)
    src = inline_minmax(cg.dump())
    assert "kincas_fmax(x, y)" in src and "kincas_fmin(x, y)" in src
    assert "return fmax(" not in src and "return fmin(" not in src


@pytest.mark.skipif(compiling_disabled(), reason="compiling disabled")
def test_compiled_max_and_min_follow_c99():
    x, y = ca.SX.sym("x", 3), ca.SX.sym("y", 3)
    f = ca.Function("mm", [x, y], [ca.vertcat(ca.fmax(x, y), ca.fmin(x, y), ca.mmax(x), ca.mmin(y))])
    _V = ctypes.c_void_p
    try:
        lib = Library("kincas_test_minmax", [f], DRIVER, {}, {"kincas_minmax": [_V, _V, _V]}).load()
    except RuntimeError as e:  # no compiler here
        pytest.skip(str(e))
    nan = np.nan
    cases = [([1.0, -2.0, 0.5], [0.5, -3.0, 0.5]), ([nan, 1.0, -1.0], [2.0, nan, nan]),
             ([nan, nan, nan], [nan, 4.0, nan]), ([-0.0, 7.0, -7.0], [0.0, nan, 3.0])]
    for a, b in cases:
        a, b, out = np.array(a), np.array(b), np.empty(8)
        assert lib.kincas_minmax(a.ctypes.data, b.ctypes.data, out.ctypes.data) == 0
        want = np.r_[np.fmax(a, b), np.fmin(a, b), np.fmax.reduce(a), np.fmin.reduce(b)]
        np.testing.assert_array_equal(out, want)  # NaN where both are NaN, else the number
        assert np.array_equal(out, np.asarray(f(a, b)).ravel(), equal_nan=True)  # casadi's VM alike
    # every pair of special and ordinary values, each in both places (the C form is one
    # condition, `(y != y || x > y) ? x : y`: a NaN on either side must give the other)
    special = [nan, -np.inf, -1.5, -0.0, 0.0, 1e-300, 2.0, np.inf]
    for x in special:
        for y in special:
            a, b, out = np.array([x, y, x]), np.array([y, x, nan]), np.empty(8)
            assert lib.kincas_minmax(a.ctypes.data, b.ctypes.data, out.ctypes.data) == 0
            want = np.r_[np.fmax(a, b), np.fmin(a, b), np.fmax.reduce(a), np.fmin.reduce(b)]
            np.testing.assert_array_equal(out, want, err_msg=f"max/min of {x!r}, {y!r}")
