"""Whole designs in one compiled call: first pose continued in the parameters, then swept.

`kincas.sweep_designs` solves one structure for many parameter sets. Everything a design
needs is done here in C, without the GIL, so that blocks of designs run on several threads
truly at once (a ctypes call releases the GIL):

1. its first pose is continued from the nominal design's solved first pose q0 (parameters
   p0) to its own parameters p along p(t) = p0 + t (p - p0), in steps of at most STEP times
   its size in every parameter: a predictor dq = -g_q^-1 g_p dp (a directional derivative,
   solved group by group), then Newton until its step is below KERNEL_NEAR (at most NEWTON steps);
   a step is kept only when max |g| / L <= ACCEPT and every Assur group's det g_q kept the
   nominal's sign (the assembly branch, group by group);
2. the kernel's state is made there (g_q's diagonal blocks, the tangent dq/du), and the
   fast pass of `kincas.sweep` (`kincas_sweep`, kincas/core/kernel.py: the same functions
   and checks) solves poses 0, 1, ... (pose 0 again, predicted where it is, so that its
   quantities come from the same pass) until one is rejected;
3. a rejected pose is tried again from the pose before in 2, 4, ..., 2^HALVINGS equal steps
   of the inputs, every step passing every test of the kernel (so, as in one step, each
   group's det g_q keeps its sign and no singular position lies between: the careful path
   halves its steps the same way, and lands on the same solution); then the fast pass goes
   on. Near a limit of the assembly the kernel rejects a step of the sweep where shorter
   ones pass: without this, every such pose went to the careful path, in Python.

Each design's result is the number of poses accepted from pose 0 (its poses and reported
quantities written in place), or -1 where its first pose could not be continued on the
nominal's branch. The caller finishes those designs on its careful path: nothing rejected
here is ever a wrong number, it is only slower. A second entry point, `kincas_designs`,
sweeps designs from first poses solved elsewhere (states given).

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(parameters={"a": 1.0}, ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", "a"), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)], inputs=[kincas.Input.angle("crank")])
>>> loop = designs_loop_for(kincas.model_of(m), ("C.y",), compile=False)
>>> loop.lib(10) is None, loop.sweeper.nq
(True, 2)
"""
from __future__ import annotations

import ctypes

import casadi as ca
import numpy as np

from .blocks import block_measures, block_solve, diagonal_blocks
from .compiled import Backend, Library, ptr, rows
from .fast import COMPILE_MAX, SWEEP_SIG, sweeper_for
from .kernel import KERNEL_NEAR
from .sweep_loop import SWEEP_C
from .tolerances import ACCEPT, PARAM_STEP as STEP  # largest parameter change per step, over the size
MAX_STEPS = 64  # continuation steps per design at most
NEWTON = 8  # Newton steps per continuation step at most
HALVINGS = 4  # a pose the kernel rejects is tried again in 2, 4, ..., 2^HALVINGS steps
_I, _V, _D = ctypes.c_longlong, ctypes.c_void_p, ctypes.c_double


# --- the casadi functions beyond the kernel's ---


def continuation_functions(sym, blocks) -> list[ca.Function]:
    """[kC, kV, kT]: kC(q, u, p, dp) = g_q^-1 g_p dp (the predictor, with a minus sign);
    kV(q, u, p, L) = (max |g| / L, sign of det of each group's block of g_q, columns scaled);
    kT(q, u, p) = (g_q's diagonal blocks, dq/du): the kernel's state at a solved pose."""
    q, u, p = ca.SX.sym("q", sym.nq), ca.SX.sym("u", sym.nu), ca.SX.sym("p", sym.np)
    dp, L = ca.SX.sym("dp", sym.np), ca.SX.sym("L")
    G = ca.Function("G", [sym.q, sym.u, sym.p], [sym.g, sym.Jq, sym.Ju])
    g, Jq, Ju = G(q, u, p)
    gp_dp = ca.jtimes(g, p, dp) if sym.np else ca.SX.zeros(g.shape)
    cs = ca.if_else(ca.DM(sym.is_length.astype(float)), 1, 1 / L)
    signs, _ = block_measures(Jq, cs, blocks)
    res = ca.mmax(ca.fabs(g)) / L + 0 * ca.sum1(g) if g.numel() else ca.SX(0)  # NaN kept
    d, o = ca.densify, {"cse": True}
    return [ca.Function("kC", [q, u, p, dp], [d(block_solve(Jq, gp_dp, blocks))], o),
            ca.Function("kV", [q, u, p, L], [d(ca.vertcat(res, signs))], o),
            ca.Function("kT", [q, u, p], [diagonal_blocks(Jq, blocks), d(-block_solve(Jq, Ju, blocks))], o)]


# --- the C loop (NQ, NU, NO, NJ, NP, NG sizes; c = STEP, MAX_STEPS, NEWTON, ACCEPT, KERNEL_NEAR) ---

_LOOP_C = """
/* q <- design p's first pose, continued from (q0, p0) at u0; 0 if it leaves the branch */
static int kincas_first_pose(const casadi_real* u0, const casadi_real* p0, const casadi_real* p,
                             casadi_real L, const casadi_real* q0, const casadi_real* sign0,
                             const casadi_real* c, casadi_real* q) {
  const casadi_real* arg[SZ_ARG]; casadi_real* res[SZ_RES]; casadi_int iw[SZ_IW]; casadi_real w[SZ_W];
  casadi_real pc[NP > 0 ? NP : 1], pt[NP > 0 ? NP : 1], dp[NP > 0 ? NP : 1], dq[NQ], rs[2], v[1 + NG];
  casadi_real Lb[NG > 0 ? NG : 1], big = 0;
  casadi_int i, j, it, k, steps;
  for (j = 0; j < NP; ++j) if (fabs(p[j] - p0[j]) > big) big = fabs(p[j] - p0[j]);
  big = ceil(big / (c[0] * L));
  steps = big < 1 ? 1 : big > c[1] ? (casadi_int) c[1] : (casadi_int) big;
  for (i = 0; i < NQ; ++i) q[i] = q0[i];
  for (j = 0; j < NP; ++j) pc[j] = p0[j];
  for (it = 1; it <= steps; ++it) {
    for (j = 0; j < NP; ++j) {
      pt[j] = p0[j] + (p[j] - p0[j]) * ((casadi_real) it / (casadi_real) steps);
      dp[j] = pt[j] - pc[j];
    }
    arg[0] = q; arg[1] = u0; arg[2] = pc; arg[3] = dp; res[0] = dq;  /* along the tangent */
    if (kC(arg, res, iw, w, 0)) return 0;
    for (i = 0; i < NQ; ++i) q[i] -= dq[i];
    arg[0] = u0; arg[1] = pt; res[0] = Lb;  /* each group's length at p(t), for kN's tests */
    if (kL(arg, res, iw, w, 0)) return 0;
    for (k = 0; k < (casadi_int) c[2]; ++k) {  /* Newton at p(t) */
      arg[0] = q; arg[1] = u0; arg[2] = pt; arg[3] = Lb; res[0] = dq; res[1] = rs;
      if (kN(arg, res, iw, w, 0)) return 0;
      for (i = 0; i < NQ; ++i) q[i] -= dq[i];
      if (rs[1] <= c[4]) break;
    }
    arg[0] = q; arg[1] = u0; arg[2] = pt; arg[3] = &L; res[0] = v;
    if (kV(arg, res, iw, w, 0)) return 0;
    if (!(v[0] <= c[3])) return 0;  /* also NaN */
    for (i = 0; i < NG; ++i) if (v[1 + i] != sign0[i]) return 0;
    for (i = 0; i < NQ; ++i) if (!(q[i] - q[i] == 0)) return 0;  /* not finite */
    for (j = 0; j < NP; ++j) pc[j] = pt[j];
  }
  return 1;
}

/* Pose k again from the state s at pose k - 1 (the kernel rejected it in one step), in 2, 4,
   ..., 2^HALVINGS equal steps of the inputs, each accepted by every test of the kernel; on
   success its unknowns and quantities (rates ud, udd of pose k) go to qk and vk (stride ld)
   and s is the state at pose k, else s is left as it was and 0 is returned. */
static int kincas_substeps(casadi_int k, const casadi_real* U, const casadi_real* p,
                           const casadi_real* L, const casadi_real* thr, casadi_int max_evals,
                           casadi_real* s, const casadi_real* ud, const casadi_real* udd,
                           casadi_real* qk, casadi_real* vk, casadi_int ld) {
  casadi_real s0[NS], Us[NU*SUB], Qs[NQ*SUB], Vs[(NO > 0 ? NO : 1)*SUB], Is[5*SUB];
  casadi_int h, m, j, i;
  for (i = 0; i < NS; ++i) s0[i] = s[i];
  for (h = 1; h <= HALVINGS; ++h) {
    m = (casadi_int) 1 << h;
    s[KS_NEAR] = s[KS_FIVE] = 0;  /* shorter steps: the last prediction's quality says nothing */
    for (j = 0; j < m; ++j) for (i = 0; i < NU; ++i)  /* the last one is pose k's input exactly */
      Us[j*NU + i] = j == m - 1 ? U[k*NU + i]
                   : U[(k - 1)*NU + i] + (U[k*NU + i] - U[(k - 1)*NU + i]) * ((casadi_real) (j + 1) / m);
    if (kincas_sweep(m, Us, p, L, thr, max_evals, s, Qs, Is, m, ud, 0, udd, 0, Vs, 0) == m) {
      for (i = 0; i < NQ; ++i) qk[i] = Qs[(m - 1)*NQ + i];
      for (i = 0; i < NO; ++i) vk[i*ld] = Vs[i*m + m - 1];
      return 1;
    }
    for (i = 0; i < NS; ++i) s[i] = s0[i];
  }
  return 0;
}

/* Designs 0..nd-1 (parameters P, sizes Ls): first pose from (q0, p0, L0) at U[0], then poses
   0..n-1 by kincas_sweep. stops[d]: poses accepted from 0, or -1 (first pose not continued).
   info: scratch of 5 n. Q (nd, n, NQ) and vals (nd, NO, n) written in place. */
int kincas_designs_full(casadi_int nd, casadi_int n, const casadi_real* U, const casadi_real* P,
                        const casadi_real* Ls, const casadi_real* q0, const casadi_real* p0,
                        const casadi_real* L0, const casadi_real* c, const casadi_real* thr,
                        casadi_int max_evals, casadi_real* Q, casadi_real* info,
                        const casadi_real* Ud, casadi_int sud, const casadi_real* Udd,
                        casadi_int sudd, casadi_real* vals, casadi_real* stops) {
  const casadi_real* arg[SZ_ARG]; casadi_real* res[SZ_RES]; casadi_int iw[SZ_IW]; casadi_real w[SZ_W];
  casadi_real s[NS], sign0[1 + NG];
  casadi_int d, i, k, a;
  arg[0] = q0; arg[1] = U; arg[2] = p0; arg[3] = L0; res[0] = sign0;
  if (kV(arg, res, iw, w, 0)) return -1;
  for (i = 0; i < NG; ++i) if (!(sign0[1 + i] != 0)) return -1;  /* nominal near singular */
  for (d = 0; d < nd; ++d) {
    const casadi_real* p = P + d*NP;
    casadi_real* q = Q + d*n*NQ;
    stops[d] = -1;
    if (!kincas_first_pose(U, p0, p, Ls[d], q0, sign0 + 1, c, q)) continue;
    arg[0] = q; arg[1] = U; arg[2] = p; res[0] = s + NQ; res[1] = s + NQ + NJ;
    if (kT(arg, res, iw, w, 0)) continue;
    for (i = 0; i < NQ; ++i) s[i] = q[i];
    for (i = 0; i < NU; ++i) s[KS_T0 + NQ*NU + i] = U[i];
    for (i = 0; i < NQ*NU + NU; ++i)  /* the poses before: this one (predictions start linear) */
      s[KS_T1 + i] = s[KS_T2 + i] = s[KS_T0 + i];
    for (i = 0; i < NQ; ++i) s[KS_Q1 + i] = s[KS_Q2 + i] = q[i];
    s[KS_NEAR] = s[KS_FIVE] = 0;
    k = kincas_sweep(n, U, p, Ls + d, thr, max_evals, s, q, info, n, Ud, sud, Udd, sudd, vals + d*NO*n, 0);
    while (k > 0 && k < n && kincas_substeps(k, U, p, Ls + d, thr, max_evals, s, Ud + k*sud,
                                             Udd + k*sudd, q + k*NQ, vals + d*NO*n + k, n)) {
      a = k + 1;  /* pose k reached in shorter steps: the kernel goes on from it */
      k = a + kincas_sweep(n - a, U + a*NU, p, Ls + d, thr, max_evals, s, q + a*NQ, info, n,
                           Ud + a*sud, sud, Udd + a*sudd, sudd, vals + d*NO*n + a, 0);
    }
    stops[d] = (casadi_real) k;
  }
  return (int) nd;
}

/* Design d's poses 1..n-1 from its state row S[d] (its first pose solved elsewhere). */
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
                         vals + d*NO*n + 1, 0);
    stops[d] = (casadi_real) (k + 1);
  }
  return (int) nd;
}
"""
_FULL_SIG = [_I, _I, _V, _V, _V, _V, _V, _V, _V, _V, _I, _V, _V, _V, _I, _V, _I, _V, _V]
_DESIGNS_SIG = [_I, _I, _V, _V, _I, _V, _V, _I, _V, _I, _V, _V, _V, _I, _V, _I, _V, _V]


class DesignsLoop:
    """The compiled loop over designs of a model and report (see the module's text).

    `lib(n)` is the loaded library for n poses in all (None: no compiler, or not worth it,
    as `kincas.core.compiled.Backend` decides); `sweeper` is the `FastSweeper` whose kernel
    it compiles (its virtual machine serves when there is no library). Safe from several
    threads: each call writes only the rows it is given.
    """

    def __init__(self, model, report=(), compile=None):
        self.model = model
        self.sweeper = sweeper_for(model, tuple(report), compile)
        self.nq, self.nu, self.no, self.np = model.nq, model.nu, len(tuple(report)), model.sym.np
        self.ng = len(self.sweeper.blocks)
        self.backend = Backend(compile, self._library, "design sweep kernel")

    def _library(self) -> Library:
        sw = self.sweeper
        fns = [*sw.compiled_functions, *continuation_functions(self.model.sym, sw.blocks)]
        return Library("kincas_designs", fns, SWEEP_C + _LOOP_C,
                       {**sw.sweep_macros(), "NP": self.np, "NG": self.ng, "NS": sw.state_size,
                        "HALVINGS": HALVINGS, "SUB": 2 ** HALVINGS},
                       {"kincas_sweep": SWEEP_SIG, "kincas_designs_full": _FULL_SIG,
                        "kincas_designs": _DESIGNS_SIG}, trusted=True, trig=sw.trig)

    def lib(self, n: int):
        """The loaded library for n poses in all, or None (see the class's text)."""
        if self.sweeper.size > COMPILE_MAX:  # as FastSweeper.worth_it: too large to compile
            return None
        return self.backend.compiled(n)

    def full(self, lib, U, P, Ls, q0, p0, L0, Q, vals, Ud, Udd, thr) -> np.ndarray:
        """Designs P (nd, np) with sizes Ls from the nominal's first pose q0 (p0, L0) over
        the poses U (n, nu): Q (nd, n, nq) and vals (nd, no, n), C-contiguous, written in
        place; returns poses accepted from 0 per design (-1: first pose not continued)."""
        nd, n = P.shape[0], U.shape[0]
        stops = np.full(nd, -1.0)
        if nd == 0:
            return stops.astype(int)
        (Udv, sud), (Uddv, sudd) = rows(Ud, n, self.nu), rows(Udd, n, self.nu)
        info = np.empty(5 * n)
        c = np.array([STEP, MAX_STEPS, NEWTON, ACCEPT, KERNEL_NEAR])
        q0, p0 = np.ascontiguousarray(q0, dtype=float), np.ascontiguousarray(p0, dtype=float)
        L0 = np.array([float(L0)])
        lib.kincas_designs_full(nd, n, ptr(U), ptr(P), ptr(Ls), ptr(q0), ptr(p0), ptr(L0), ptr(c),
                                ptr(thr), self.sweeper.max_evals, ptr(Q), ptr(info), ptr(Udv), sud,
                                ptr(Uddv), sudd, ptr(vals), ptr(stops))
        return stops.astype(int)


def designs_loop_for(model, report=(), compile=None) -> DesignsLoop:
    """The `DesignsLoop` of a compiled model and report (kept as long as the model is)."""
    return model.memo(("designs_loop", tuple(report), compile),
                      lambda: DesignsLoop(model, tuple(report), compile))
