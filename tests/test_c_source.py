"""casadi's generated C without needless null-pointer tests (kincas/core/c_source.py
`trust_pointers`): a test is dropped only where no call can pass null, and the compiled
numbers are casadi's own, bit for bit."""
from __future__ import annotations

import ctypes
import re

import casadi as ca
import numpy as np
import pytest

from kincas.core.c_library import Library, compiling_disabled
from kincas.core.c_source import trust_pointers

_LOAD = r"arg\[{}\]\? arg\[{}\]\["
_STORE = r"if \(res\[{}\]!=0\)"


def _body(src: str, fn: str) -> str:
    """The text of static function `fn` (casadi_fN) in a generated source."""
    a = src.index(f"static int {fn}(")
    return src[a:src.index("\n}\n", a)]


def _functions():
    """f (SX) called twice from g (MX): once with every output wanted, once without its second
    one and with a structurally zero first input; h a switch between g and itself."""
    x, y = ca.SX.sym("x", 3), ca.SX.sym("y", 2)
    f = ca.Function("f", [x, y], [ca.sin(x) * ca.sum1(y), ca.cos(y) + 1], {"cse": True})
    a = ca.MX.sym("a", 3)
    first, second = f(ca.MX(3, 1), ca.vertcat(a[0], 0)), f(a, ca.vertcat(a[1], a[2]))
    g = ca.Function("g", [a], [first[0] + second[0], second[1]])
    c = ca.MX.sym("c")
    h = ca.Function("h", [c, a], [ca.Function.conditional("sw", [g], g)(c, a)[0]])
    return f, g, h


def _source(*fns) -> str:
    cg = ca.CodeGenerator("t.c", {"with_header": False})
    for fn in fns:
        cg.add(fn)
    return cg.dump()


def test_tests_kept_where_a_call_may_pass_null():
    f, g, h = _functions()
    src = _source(g)
    inner, outer = re.findall(r"static int (casadi_f\d+)\(", src)  # f first (g calls it)
    assert "=0;" in _body(src, outer)  # g's second call of f passes null for an output
    out = trust_pointers(src)
    fb = _body(out, inner)
    assert not re.search(_LOAD.format(r"\d+", r"\d+"), fb)  # both inputs: work vectors, never null
    assert re.search(_STORE.format(1), fb) and not re.search(_STORE.format(0), fb)
    # g itself: called by the C loop (the caller's promise): its tests all go
    assert not re.search(_LOAD.format(r"\d+", r"\d+"), _body(out, outer))
    # the unchanged lines are casadi's
    assert len(out.splitlines()) == len(src.splitlines())
    # a switch passes its own arguments on (arg+1): the callee keeps every test
    src = _source(h)
    out = trust_pointers(src)
    for fn in re.findall(r"static int (casadi_f\d+)\(", src):
        if f"{fn}(arg+1" in src:
            assert _body(out, fn) == _body(src, fn)


def test_passed_on_arguments_and_unknown_calls_keep_their_tests():
    sig = "/* k:(i0,i1)->(o0) */\nstatic int casadi_f0(const casadi_real** arg, casadi_real** res, casadi_int* iw, casadi_real* w, int mem) {\n"
    callee = sig + "  a0=arg[0]? arg[0][0] : 0;\n  a1=arg[1]? arg[1][0] : 0;\n  if (res[0]!=0) res[0][0]=(a0+a1);\n  return 0;\n}\n"
    caller = ("/* m:(i0,i1)->(o0) */\nstatic int casadi_f1(const casadi_real** arg, casadi_real** res, casadi_int* iw, casadi_real* w, int mem) {\n"
              "  arg1[0]=arg[1];\n  arg1[1]=w3;\n  res1[0]=w4;\n  if (casadi_f0(arg1, res1, iw, w, 0)) return 1;\n  return 0;\n}\n")
    out = trust_pointers(callee + caller)
    assert "a0=arg[0]? arg[0][0] : 0;" in out and "a1=arg[1][0];" in out and "  res[0][0]=(a0+a1);" in out
    odd = caller.replace("if (casadi_f0(arg1, res1, iw, w, 0)) return 1;", "casadi_f0(arg1, res1, iw, w, 1);")
    assert trust_pointers(callee + odd) == callee + odd


@pytest.mark.skipif(compiling_disabled(), reason="compiling disabled")
def test_compiled_without_the_tests_gives_casadis_numbers(monkeypatch):
    monkeypatch.setenv("KINCAS_LIBM_TRIG", "1")  # (casadi's sines: libm's)
    f, g, h = _functions()
    driver = """
int kincas_gh(const casadi_real* c, const casadi_real* a, casadi_real* o) {
  const casadi_real* arg[SZ_ARG]; casadi_real* res[SZ_RES]; casadi_int iw[SZ_IW]; casadi_real w[SZ_W];
  arg[0] = a; res[0] = o; res[1] = o + 3;
  if (g(arg, res, iw, w, 0)) return 1;
  arg[0] = c; arg[1] = a; res[0] = o + 5;
  return h(arg, res, iw, w, 0);
}
"""
    _V = ctypes.c_void_p
    try:
        lib = Library("kincas_test_trust", [g, h], driver, {}, {"kincas_gh": [_V, _V, _V]}, trusted=True).load()
    except (RuntimeError, OSError) as e:
        pytest.skip(f"no working C compiler: {e}")
    rng = np.random.default_rng(3)
    for _ in range(20):
        a, c, o = rng.normal(size=3), np.array([float(rng.integers(0, 2))]), np.zeros(8)
        assert lib.kincas_gh(c.ctypes.data, a.ctypes.data, o.ctypes.data) == 0
        want = np.concatenate([np.asarray(v).ravel() for v in (*g(a), h(c[0], a))])
        assert np.array_equal(o, want)


SINCOS_DRIVER = """
int kincas_test_trig(casadi_int n, const double* x, double* out) {
  casadi_int k;
  for (k = 0; k < n; ++k) {
    kincas_sincos(x[k], out + 6*k, out + 6*k + 1);
    out[6*k + 2] = kincas_sin(x[k]); out[6*k + 3] = kincas_cos(x[k]);
    kincas_sincos_inline(x[k], out + 6*k + 4, out + 6*k + 5);  /* the compiled loop's form */
  }
  return 0;
}
"""


@pytest.mark.skipif(compiling_disabled(), reason="compiling disabled")
@pytest.mark.parametrize("trig", ["inline", "call"])
def test_compiled_sines_and_cosines_are_within_an_ulp(monkeypatch, trig):
    # the compiled kernels' sin and cos (fdlibm's, kincas/core/c_source.py SINCOS_C, inline
    # and as a function each use calls) against
    # 40-digit mpmath: angles of mechanisms (a few turns, many turns), next to multiples of
    # pi/2 (where the reduction cancels), tiny and huge ones, and what libm answers itself
    mpmath = pytest.importorskip("mpmath")
    monkeypatch.delenv("KINCAS_LIBM_TRIG", raising=False)
    _V, _I = ctypes.c_void_p, ctypes.c_longlong
    try:
        built = Library("kincas_test_trig", [], SINCOS_DRIVER, {}, {"kincas_test_trig": [_I, _V, _V]}, trig=trig)
        lib = built.load()
    except (RuntimeError, OSError) as e:
        pytest.skip(f"no working C compiler: {e}")
    rng = np.random.default_rng(11)
    halves = np.array([k * np.pi / 2 for k in range(-40, 41)])
    x = np.concatenate([rng.uniform(-4, 4, 800), rng.uniform(-200, 200, 600), rng.uniform(-1e6, 1e6, 200),
                        10.0 ** rng.uniform(-300, 6, 300) * rng.choice([-1, 1], 300),
                        halves, np.nextafter(halves, np.inf), np.nextafter(halves, -np.inf),
                        [np.pi / 4, np.nextafter(np.pi / 4, 1), 5e-324, 1e-310, 1.6e6, 1.7e6, 1e22, 3.0e300]])
    assert ("#define KINCAS_TRIG_CALL" in built.source) == (trig == "call")
    out = np.empty((len(x), 6))
    assert lib.kincas_test_trig(len(x), x.ctypes.data, out.ctypes.data) == 0
    assert np.array_equal(out[:, 0], out[:, 2]) and np.array_equal(out[:, 1], out[:, 3])  # one arithmetic
    assert np.array_equal(out[:, 0], out[:, 4]) and np.array_equal(out[:, 1], out[:, 5])  # inline or called
    mpmath.mp.dps = 40
    for xi, (s, c, *_) in zip(x, out):
        for got, ref in ((s, mpmath.sin(mpmath.mpf(float(xi)))), (c, mpmath.cos(mpmath.mpf(float(xi))))):
            ulp = np.spacing(abs(float(ref))) if float(ref) else 5e-324
            assert float(abs(mpmath.mpf(float(got)) - ref)) <= ulp, (xi, got)
    special = np.array([0.0, -0.0, np.inf, -np.inf, np.nan])
    out = np.empty((len(special), 6))
    lib.kincas_test_trig(len(special), special.ctypes.data, out.ctypes.data)
    assert np.signbit(out[1, 0]) and out[1, 1] == 1 and out[0, 0] == 0 and not np.signbit(out[0, 0])
    assert np.isnan(out[2:, :]).all()
