"""Many designs of one structure at once: batched evaluation and one compiled call per block.

A *design* is one set of parameter values for a compiled model (`kincas.compile(m)`: the
structure is built once, the parameters stay numeric inputs). Two tools live here:

* `BatchEvaluator`: g, g_q, g_u, g_p and the reported quantities at many (q, u, p) columns
  in one mapped CasADi call each, and damped-free Newton steps for all of them with numpy's
  batched linear algebra (no symbolic inverse, so it scales with the mechanism);
* `DesignKernel`: the fast sweep kernel of `kincas.core.fast` (the same casadi functions and
  the same C loop, `kincas_sweep`) with one more C entry point, `kincas_designs`, that sweeps
  a block of designs one after the other in a single call. A ctypes call releases the GIL and
  the loop keeps its work arrays on its own stack, so blocks of designs run on several
  threads at once when each has its own output rows.

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(parameters={"a": 1.0}, ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", "a"), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)], inputs=[kincas.Input.angle("crank")])
>>> ev = BatchEvaluator(kincas.compile(m))
>>> g, J, Ju, Jp = ev.derivatives(np.zeros((2, 2)), np.zeros((2, 1)), np.array([[1.0], [2.0]]))
>>> g.shape, J.shape, Jp[:, :, 0].round(6).tolist()
((2, 2), (2, 2, 2), [[1.0, 0.0], [1.0, 0.0]])
"""
from __future__ import annotations

import ctypes

import casadi as ca
import numpy as np

from .compiled import Backend, Library
from .fast import sweeper_for
from .kernel import SWEEP_C as _SWEEP_C

_I, _V = ctypes.c_longlong, ctypes.c_void_p

# --- the C loop over designs: design d's poses 1..n-1 from its state row S[d] ---

_DESIGNS_C = """
int kincas_designs(casadi_int nd, casadi_int n, const casadi_real* U, const casadi_real* P,
                   casadi_int np_, const casadi_real* Ls, const casadi_real* thr,
                   casadi_int max_evals, casadi_real* S, casadi_int ns, casadi_real* Q,
                   casadi_real* info, const casadi_real* Ud, casadi_int sud,
                   const casadi_real* Udd, casadi_int sudd, casadi_real* vals,
                   casadi_real* stops) {
  casadi_int d;
  for (d = 0; d < nd; ++d) {
    int k = kincas_sweep(n - 1, U + NU, P + d*np_, Ls + d, thr, max_evals, S + d*ns,
                         Q + d*n*NQ + NQ, info + d*5*n + 1, n, Ud + sud, sud, Udd + sudd, sudd,
                         vals + d*(NO > 0 ? NO : 0)*n + 1, 0);
    stops[d] = (casadi_real) (k + 1);
  }
  return (int) nd;
}
"""
_SWEEP_SIG = [_I, _V, _V, _V, _V, _I, _V, _V, _V, _I, _V, _I, _V, _I, _V, _V]
_DESIGNS_SIG = [_I, _I, _V, _V, _I, _V, _V, _I, _V, _I, _V, _V, _V, _I, _V, _I, _V, _V]


class DesignKernel:
    """The compiled sweep kernel of a model and report, with a loop over designs.

    `lib(n)` is the loaded library for n poses in all (None: no compiler, or not worth it,
    as `kincas.core.compiled.Backend` decides); `sweeper` is the `FastSweeper` whose
    functions it compiles (and whose virtual-machine path serves when there is no library).
    """

    def __init__(self, model, report=(), compile=None):
        self.sweeper = sweeper_for(model, tuple(report), compile)
        self.nq, self.nu, self.no = model.nq, model.nu, len(tuple(report))
        self.backend = Backend(compile, self._library, "design sweep kernel")

    def _library(self) -> Library:
        return Library("kincas_designs", self.sweeper.functions, _SWEEP_C + _DESIGNS_C,
                       {"NQ": self.nq, "NU": self.nu, "NO": self.no,
                        "NM": len(self.sweeper.blocks) + 1, "NJ": self.sweeper.nj},
                       {"kincas_sweep": _SWEEP_SIG, "kincas_designs": _DESIGNS_SIG})

    def lib(self, n: int):
        if self.sweeper.size > 40_000:  # as FastSweeper.worth_it: too large to compile
            return None
        return self.backend.compiled(n)


# --- g and its derivatives at many columns ---


class BatchEvaluator:
    """Residuals, Jacobians and quantities at N columns (q, u, p) of one model, mapped.

    Arrays are numpy, one row per column: Q (N, nq), U (N, nu), P (N, np). Not shared
    between threads (the mapped functions are, and casadi's call is re-entrant)."""

    def __init__(self, model):
        self.model, sym = model, model.sym
        self.nq, self.nu, self.np = sym.nq, sym.nu, sym.np
        d = ca.densify
        self._f = ca.Function("derivs", [sym.q, sym.u, sym.p],
                              [d(sym.g), d(sym.Jq), d(sym.Ju), d(ca.jacobian(sym.g, sym.p))])
        self._maps: dict = {}

    def _mapped(self, f, n):
        key = (f.name(), n)
        if key not in self._maps:
            self._maps[key] = f.map(n)
        return self._maps[key]

    def derivatives(self, Q, U, P):
        """g (N, ng), g_q (N, ng, nq), g_u (N, ng, nu), g_p (N, ng, np)."""
        n = Q.shape[0]
        if n == 0:
            sym = self.model.sym
            return (np.zeros((0, sym.ng)), np.zeros((0, sym.ng, self.nq)),
                    np.zeros((0, sym.ng, self.nu)), np.zeros((0, sym.ng, self.np)))
        outs = self._mapped(self._f, n)(np.asarray(Q, float).T, np.asarray(U, float).T,
                                        np.asarray(P, float).T)
        g = np.asarray(outs[0]).T
        mats = []
        for a, w in zip(outs[1:], (self.nq, self.nu, self.np)):
            a = np.asarray(a)  # (ng, n * w): column blocks per design
            mats.append(a.reshape(a.shape[0], n, w).transpose(1, 0, 2))
        return (g, *mats)

    def quantities(self, names, Q, U, P, Ud, Udd) -> np.ndarray:
        """(len(names), N) quantities at N solved columns, each with its own parameters."""
        n = Q.shape[0]
        if n == 0 or not names:
            return np.zeros((len(names), n))
        f = self.model.quantity_function(tuple(names))
        return np.asarray(self._mapped(f, n)(Q.T, U.T, P.T, Ud.T, Udd.T))
