"""Fast sweeps: each pose predicted along the tangent and corrected by Newton, in compiled C.

The careful path (`kincas.solve`) spends about 70 us per pose in Python. Here one call solves
a whole stretch of a sweep: pose k is predicted from the last solved pose along the exact
tangent, q_pred = q_prev + dq/du (u_k - u_prev) with dq/du = -g_q^-1 g_u, plus a second-order
term from how the tangent changed since the pose before, then corrected by Newton,
q <- q - g_q^-1 g, until the next step would be negligible (on a dense sweep the prediction
usually is already). A pose is *accepted* only when it is verified in the same pass:

- residual: max |g| / L <= RESIDUAL (the careful path's acceptance);
- converged: the Newton step that would follow, |g_q^-1 g| (radians, lengths / L) <= STEP;
- same branch: M = J_prev^-1 J with J = g_q. If ||D^-1 (M - I) D|| < 1 (D scales lengths by
  L), every matrix on the segment from I to M is invertible, so det M > 0: det g_q kept its
  sign and no singular position lies between the two poses. The test fails near a singular
  position too (J_prev^-1 grows), where fixed-step kernels jump branch silently;
- small correction: ||D^-1 (q - q_pred)|| <= CORRECTION.

The pass stops at the first pose that fails (every later pose would start from it); the
caller re-solves that pose carefully and restarts the pass after it (`FastRun.advance`: a
call, not a recompilation; `FastSweeper.sweep` runs that loop). The reported quantities are
computed in the same pass, sharing the trigonometry of the last Newton evaluation. Compiled
(see `kincas.compiled`): the casadi functions are code-generated and driven by a small C loop,
the library cached on disk. Without a compiler, or with KINCAS_NO_COMPILE=1, the same
arithmetic runs in casadi's virtual machine, `mapaccum` over chunks of CHUNK poses.

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)], inputs=[kincas.Input.angle("crank")])
>>> model, U = kincas.compile(m), np.linspace(0, 2 * np.pi, 721)[:, None]
>>> q0 = model.newton(model.initial_q(U[0], [], {"C": (3.6, 2.9)}, 5), U[0], [], 5).q
>>> run = FastSweeper(model, compile=False).run(U, [], 5.0, q0, U[0], start=1)
>>> run.first_bad, bool(run.residual[1:].max() < 1e-13)
(721, True)
"""
from __future__ import annotations

import ctypes
import weakref

import casadi as ca
import numpy as np

from .compiled import CHUNK, Backend, Library, QuantityEvaluator, ptr, rows, table

RESIDUAL = 1e-10  # as the careful path's ACCEPT: max |g| / L
STEP = 1e-13  # the next Newton step (radians, or lengths / L): the error left in q
JAC_CHANGE = 0.9  # sum |entries of D^-1 (J_prev^-1 J - I) D| (below 1 keeps det's sign)
CORRECTION = 0.25  # ||D^-1 (q - q_pred)||_1: Newton may not wander far from the prediction
MAX_EVALS = 5  # residual evaluations per pose: at the prediction and after up to 4 steps
# Kernel size, in casadi instructions, beyond which compiling costs more than it saves: gcc
# -O3 took 1.7 s at 11k instructions, 13 s at 39k and 200 s (3.5 GB) at 150k.
COMPILE_MAX = 40_000
# Beyond this size the virtual machine is slower than the careful path (measured on chains
# of four-bars: equal near 7k instructions, twice as slow at 11k).
VM_MAX = 6_000
INFO = ("residual", "step", "jac_change", "correction", "evaluations")
BLOCK = 65536  # poses per call when a progress callback wants news


# --- the casadi functions: prediction, Newton evaluation, acceptance measures ---


def _kernel_functions(sym, qf: ca.Function | None) -> list[ca.Function]:
    """kP (predict), kE (at q: Newton step, J, tangent, residual and step size, quantities)
    and kC (Jacobian change, correction). Outputs dense, so that C can index them.

    The prediction is of second order: with the tangents T0 at the last pose (input u0) and
    T1 at the one before (u1), dT = T0 - T1 ~ H[u0 - u1, .] for the second derivative H of
    q(u), so along a step u - u0 = l (u0 - u1), H[u - u0, u - u0] ~ l dT (u - u0); its error
    is O(h^3) on a straight sweep and still O(h^2) where the sweep turns."""
    nq, nu = sym.nq, sym.nu
    q, qp, J, J0 = ca.SX.sym("q", nq), ca.SX.sym("qp", nq), ca.SX.sym("J", nq, nq), ca.SX.sym("J0", nq, nq)
    T0, u0, u = ca.SX.sym("T0", nq, nu), ca.SX.sym("u0", nu), ca.SX.sym("u", nu)
    T1, u1 = ca.SX.sym("T1", nq, nu), ca.SX.sym("u1", nu)
    du, dup = u - u0, u0 - u1
    lam = ca.if_else(ca.dot(dup, dup) > 0, ca.dot(du, dup) / ca.dot(dup, dup), 0)
    pred = q + ca.mtimes(T0, du) + 0.5 * lam * ca.mtimes(T0 - T1, du)
    p, L, ud, udd = ca.SX.sym("p", sym.np), ca.SX.sym("L"), ca.SX.sym("ud", nu), ca.SX.sym("udd", nu)
    D = ca.if_else(ca.DM(sym.is_length.astype(float)), L, 1)  # the scale of each unknown
    g, Jq, Ju = ca.Function("G", [sym.q, sym.u, sym.p], [sym.g, sym.Jq, sym.Ju])(q, u, p)
    sol = ca.solve(Jq, ca.horzcat(g, Ju))  # one factorisation: Newton step and tangent
    rs = ca.vertcat(ca.mmax(ca.fabs(g)) / L, ca.norm_1(sol[:, 0] / D))  # a sum keeps NaNs
    y = ca.densify(qf(q, u, p, ud, udd)) if qf is not None else ca.SX(0, 1)
    # J0 and J arrive dense, but have g_q's sparsity: projecting them onto it keeps the
    # symbolic solve as sparse as g_q's structure (a chain of loops: block triangular)
    # instead of a dense n^3 expression.
    sp = sym.Jq.sparsity()
    Js, J0s = ca.project(J, sp), ca.project(J0, sp)
    M = (ca.solve(J0s, Js) - ca.DM.eye(nq)) * ca.repmat(D.T, nq, 1) / ca.repmat(D, 1, nq)
    mc = ca.vertcat(ca.sum1(ca.sum2(ca.fabs(M))), ca.norm_1((q - qp) / D))
    d, o = ca.densify, {"cse": True}  # cse: one sin and cos per angle, shared by everything
    return [ca.Function("kP", [q, T0, u0, u, T1, u1], [d(pred)], o),
            ca.Function("kE", [q, u, p, L, ud, udd], [d(sol[:, 0]), d(Jq), d(-sol[:, 1:]), rs, y], o),
            ca.Function("kC", [J0, J, qp, q, L], [mc], o)]


def _vm_step(kP, kE, kC, nq, nu, max_evals) -> ca.Function:
    """One pose with a fixed number of evaluations for the virtual machine: once converged,
    q stays put, so it ends where the compiled loop stops (the same arithmetic)."""
    q0, J0, T0, u0 = ca.SX.sym("q0", nq), ca.SX.sym("J0", nq, nq), ca.SX.sym("T0", nq, nu), ca.SX.sym("u0", nu)
    u, p, L, thr = ca.SX.sym("u", nu), ca.SX.sym("p", kE.size1_in(2)), ca.SX.sym("L"), ca.SX.sym("t", 4)
    ud, udd, T1, u1 = ca.SX.sym("ud", nu), ca.SX.sym("udd", nu), ca.SX.sym("T1", nq, nu), ca.SX.sym("u1", nu)
    q = qp = kP(q0, T0, u0, u, T1, u1)
    done, evals = ca.SX(0), ca.SX(0)
    for i in range(max_evals):
        dq, J, T, rs, y = kE(q, u, p, L, ud, udd)
        evals += 1 - done
        done = ca.logic_or(done, ca.logic_and(rs[0] <= thr[0], rs[1] <= thr[1]))
        if i < max_evals - 1:
            q = ca.if_else(done, q, q - dq)
    info = ca.vertcat(rs, kC(J0, J, qp, q, L), evals)
    return ca.Function("kS", [q0, J0, T0, u0, T1, u1, u, p, L, thr, ud, udd], [q, J, T, u, T0, u0, info, y])


# --- the C loop around them (NQ, NU, NO: sizes; state s = q, J, T = dq/du, u at the last
# pose, then T and u at the one before; matrices column-major) ---

_SWEEP_C = """
int kincas_sweep(casadi_int n, const casadi_real* U, const casadi_real* p, const casadi_real* L,
                 const casadi_real* thr, casadi_int max_evals, casadi_real* s, casadi_real* Q,
                 casadi_real* info, casadi_int ld, const casadi_real* Ud, casadi_int sud,
                 const casadi_real* Udd, casadi_int sudd, casadi_real* vals, casadi_real* Jout) {
  const casadi_real* arg[SZ_ARG]; casadi_real* res[SZ_RES]; casadi_int iw[SZ_IW]; casadi_real w[SZ_W];
  casadi_real qp[NQ], q[NQ], dq[NQ], J[NQ*NQ], T[NQ*NU], rs[2], mc[2], y[NO > 0 ? NO : 1];
  casadi_int k, i, it;
  for (k = 0; k < n; ++k) {
    const casadi_real* u = U + k*NU;
    int conv = 0;
    arg[0] = s; arg[1] = s + NQ + NQ*NQ; arg[2] = s + NQ + NQ*NQ + NQ*NU; arg[3] = u;
    arg[4] = s + NQ + NQ*NQ + NQ*NU + NU; arg[5] = s + NQ + NQ*NQ + 2*NQ*NU + NU; res[0] = qp;
    if (kP(arg, res, iw, w, 0)) break;
    for (i = 0; i < NQ; ++i) q[i] = qp[i];
    for (it = 1; ; ++it) {  /* Newton until the next step is negligible */
      arg[0] = q; arg[1] = u; arg[2] = p; arg[3] = L; arg[4] = Ud + k*sud; arg[5] = Udd + k*sudd;
      res[0] = dq; res[1] = J; res[2] = T; res[3] = rs; res[4] = y;
      if (kE(arg, res, iw, w, 0)) break;
      if (rs[0] <= thr[0] && rs[1] <= thr[1]) { conv = 1; break; }
      if (it >= max_evals) break;
      for (i = 0; i < NQ; ++i) q[i] -= dq[i];
    }
    arg[0] = s + NQ; arg[1] = J; arg[2] = qp; arg[3] = q; arg[4] = L; res[0] = mc;
    if (kC(arg, res, iw, w, 0)) break;
    for (i = 0; i < NQ; ++i) Q[k*NQ + i] = q[i];
    for (i = 0; i < NO; ++i) vals[i*ld + k] = y[i];  /* one contiguous row per quantity */
    if (Jout) for (i = 0; i < NQ*NQ; ++i) Jout[k*NQ*NQ + i] = J[i];
    info[k] = rs[0]; info[ld + k] = rs[1]; info[2*ld + k] = mc[0]; info[3*ld + k] = mc[1];
    info[4*ld + k] = (casadi_real) it;
    if (!(conv && mc[0] <= thr[2] && mc[1] <= thr[3])) break;
    for (i = 0; i < NQ*NU + NU; ++i) s[NQ + NQ*NQ + NQ*NU + NU + i] = s[NQ + NQ*NQ + i];
    for (i = 0; i < NQ; ++i) s[i] = q[i];
    for (i = 0; i < NQ*NQ; ++i) s[NQ + i] = J[i];
    for (i = 0; i < NQ*NU; ++i) s[NQ + NQ*NQ + i] = T[i];
    for (i = 0; i < NU; ++i) s[NQ + NQ*NQ + NQ*NU + i] = u[i];
  }
  return (int) k;
}
"""

_I, _V = ctypes.c_longlong, ctypes.c_void_p


# --- the sweep driver ---


class FastRun:
    """The arrays of one sweep, bound once; `advance` solves a stretch of it per call.

    `Q` (N, nq): the unknowns, NaN where not solved; `values` (len(report), N): the reported
    quantities; `info` (5, N): per pose attempted, the measures named in INFO; `accepted`:
    the poses the fast pass accepted; `solved`: by either path (`FastSweeper.sweep` fills
    it); `first_bad`: where the last `advance` stopped. The arrays are not initialised
    (filling 100,000 rows with NaN costs more than solving them): rows that no `advance` or
    `record` reached are NaN only after `run` or `sweep` returns.
    """

    def __init__(self, sweeper: "FastSweeper", U, p, L, Ud=None, Udd=None, jacobians=False):
        self.sweeper, nq, nu = sweeper, sweeper.nq, sweeper.nu
        self.U = np.ascontiguousarray(table(U, nu))
        self.n = n = self.U.shape[0]
        self.Ud = rows(np.ones(nu) if Ud is None else Ud, n, nu)
        self.Udd = rows(np.zeros(nu) if Udd is None else Udd, n, nu)
        self.p = np.ascontiguousarray(np.asarray(p, dtype=float).ravel())
        self.L = np.array([float(L)])
        self.Q, self.info = np.empty((n, nq)), np.empty((5, n))
        self.values = np.empty((len(sweeper.report), n))
        self.J = np.empty((n, nq * nq)) if jacobians else None  # g_q per pose, column-major
        self.accepted, self.solved = np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
        self.thr = np.array([RESIDUAL, STEP, JAC_CHANGE, CORRECTION])
        self.first_bad, self._s = 0, None

    residual = property(lambda self: self.info[0], doc="max |g| / L at each pose")
    step = property(lambda self: self.info[1], doc="the Newton step that would follow")
    jac_change = property(lambda self: self.info[2], doc="sum |D^-1 (J_prev^-1 J - I) D|")
    correction = property(lambda self: self.info[3], doc="||D^-1 (q - q_pred)||_1")
    iterations = property(lambda self: np.nan_to_num(self.info[4], nan=1.0).astype(int) - 1,
                          doc="Newton steps taken at each pose")

    @property
    def jacobian(self) -> np.ndarray:
        """g_q at each pose, (N, nq, nq) (with `jacobians=True`; NaN where not solved)."""
        nq = self.sweeper.nq
        return self.J.reshape(self.n, nq, nq).transpose(0, 2, 1)  # n: also with no unknowns

    def advance(self, start: int, q_last, u_last, stop: int | None = None) -> int:
        """Solve poses start, start + 1, ... (before `stop`, default N) from the solved pose
        (q_last, u_last) until one is rejected, and return its index (`stop` if none was).
        The poses before it are accepted; the rejected pose keeps its `info` (why) and NaN in
        `Q` and `values`. q_last None: go on from where the last call stopped, unrejected."""
        sw, stop = self.sweeper, self.n if stop is None else min(stop, self.n)
        if start >= stop or not (sw.nq and sw.nu):  # nothing to predict: all careful
            return min(start, stop)
        if q_last is not None or self._s is None:
            self._s = sw.state(q_last, u_last, self.p)
        s = self._s  # the C loop leaves the last accepted pose's state in it
        lib = sw.backend.compiled(self.n)
        if lib is not None:
            (Ud, sud), (Udd, sudd) = self.Ud, self.Udd
            k = start + lib.kincas_sweep(
                stop - start, ptr(self.U, start * sw.nu), ptr(self.p), ptr(self.L), ptr(self.thr),
                sw.max_evals, ptr(s), ptr(self.Q, start * sw.nq), ptr(self.info, start), self.n,
                ptr(Ud, start * sud), sud, ptr(Udd, start * sudd), sudd, ptr(self.values, start),
                None if self.J is None else ptr(self.J, start * sw.nq * sw.nq))
        else:
            k = sw._vm_advance(self, start, stop, s)
        self.accepted[start:k] = self.solved[start:k] = True
        if k < stop:
            self.Q[k] = self.values[:, k] = np.nan
            if self.J is not None:
                self.J[k] = np.nan
        self.first_bad = k
        return k

    def record(self, k: int, sol) -> None:
        """Store a carefully solved pose (an object with q, residual, iterations, ok)."""
        self.solved[k] = bool(sol.ok)
        self.Q[k], self.values[:, k] = (sol.q if sol.ok else np.nan), np.nan  # values: see sweep
        if self.J is not None:
            J = getattr(sol, "J", None)
            if sol.ok and J is None:
                J = np.asarray(self.sweeper.sym.f_resjac(sol.q, self.U[k], self.p)[1])
            self.J[k] = np.ravel(J, order="F") if sol.ok else np.nan
        self.info[:, k] = [sol.residual, np.nan, np.nan, np.nan, sol.iterations + 1]


class FastSweeper:
    """Whole sweeps of one compiled model (`kincas.compile(m)`), any parameter values.

    `report` lists the quantities computed with each pose (only what they need is built).
    `run(U, p, L, q_start, u_start)` solves U[start:] from a solved pose; `sweep(U, p, L,
    careful)` solves every pose, handing those the fast pass rejects to `careful`.
    `backend.library.times` says how long generating, compiling and loading took.
    """

    def __init__(self, model, report=(), *, compile=None, max_evals: int = MAX_EVALS):
        self.model, self.sym, self.report = model, model.sym, tuple(report)
        self.nq, self.nu, self.max_evals = model.sym.nq, model.sym.nu, int(max_evals)
        self._qf = model.quantity_function(self.report) if self.report else None  # names checked
        self._functions = None
        self._vm = None
        self.backend = Backend(compile, self._library, "fast sweep kernel")

    @property
    def size(self) -> int:
        """The kernel's size in casadi instructions (what compiling and running cost)."""
        return sum(fn.n_instructions() for fn in self.functions)

    def worth_it(self, n: int) -> bool:
        """Whether the fast pass pays for n poses: compiled (when its size allows: a larger
        kernel is never compiled), or small enough for the virtual machine to beat the
        careful path."""
        if self.size > COMPILE_MAX and self.backend.compile is not False:
            self.backend.compile = False
        return self.backend.compiled(n) is not None or self.size <= VM_MAX

    @property
    def functions(self) -> list[ca.Function]:
        """kP, kE, kC (built when first needed)."""
        if self._functions is None:
            self._functions = _kernel_functions(self.sym, self._qf)
        return self._functions

    def _library(self) -> Library:
        return Library("kincas_sweep", self.functions, _SWEEP_C,
                       {"NQ": self.nq, "NU": self.nu, "NO": len(self.report)},
                       {"kincas_sweep": [_I, _V, _V, _V, _V, _I, _V, _V, _V, _I, _V, _I, _V, _I, _V, _V]})

    def state(self, q, u, p) -> np.ndarray:
        """(q, J, T = dq/du, u, T, u) at a solved pose, matrices column-major as in casadi
        (the second T, u stand for the pose before: the first prediction is linear)."""
        _, J, Ju = (np.asarray(a) for a in self.sym.f_tangent(q, u, p))
        try:
            T = np.linalg.solve(J, -Ju)
        except np.linalg.LinAlgError:  # a singular start: the next pose fails the branch test
            T = np.full_like(Ju, np.nan)
        T, u = T.ravel(order="F"), np.ravel(u)
        return np.concatenate([np.ravel(q), J.ravel(order="F"), T, u, T, u])

    def run(self, U, p, L, q_start, u_start, start: int = 0, Ud=None, Udd=None,
            jacobians=False) -> FastRun:
        """Poses U[start:] (an (N, nu) table) from the solved pose (q_start, u_start)."""
        r = FastRun(self, U, p, L, Ud, Udd, jacobians)
        k = r.advance(start, q_start, u_start)
        for a in (r.Q, r.info.T, r.values.T) + (() if r.J is None else (r.J,)):  # not reached
            a[:start], a[k + 1:] = np.nan, np.nan
        return r

    def sweep(self, U, p, L, careful, Ud=None, Udd=None, progress=None, jacobians=False) -> FastRun:
        """Every pose of U: the fast pass wherever it is accepted, else `careful(k, j, run)`
        -> a solution with q, residual, iterations, ok, where j is the last solved pose (None
        while none is; its unknowns are run.Q[j]); the fast pass restarts after each. Between
        two consecutive fast poses det g_q keeps its sign (see the module's text). With no
        unknowns or no inputs, every pose goes to `careful`."""
        r = FastRun(self, U, p, L, Ud, Udd, jacobians)
        k, last, going = 0, None, False  # going: the last block ended with no rejection

        def tick(a, b):  # news at every 256th pose passed, as the careful path gives it
            if progress is not None and b // 256 > a // 256:
                progress(b - b % 256, r.n)
        if progress is not None:
            progress(0, r.n)
        while k < r.n:
            if last is not None and self.nq and self.nu:
                stop = r.n if progress is None else k + BLOCK
                bad = r.advance(k, *((None, None) if going else (r.Q[last], r.U[last])), stop)
                last, going = (bad - 1 if bad > k else last), bad == min(stop, r.n)
                tick(k, bad)
                k = bad
                if going or k == r.n:
                    continue
            sol = careful(k, last, r)
            r.record(k, sol)
            last, k, going = (k if sol.ok else last), k + 1, False
            tick(k - 1, k)
        slow = np.flatnonzero(r.solved & ~r.accepted)
        if self.report and slow.size:
            ev = evaluator_for(self.model, self.report)
            r.values[:, slow] = ev.evaluate(r.Q[slow], r.U[slow], r.p, _take(r.Ud, slow), _take(r.Udd, slow))
        if progress is not None:
            progress(r.n, r.n)
        return r

    # --- the virtual machine: the same arithmetic, mapaccum over CHUNK poses ---
    def _vm_advance(self, r: FastRun, start: int, stop: int, s: np.ndarray) -> int:
        nq, nu, no = self.nq, self.nu, len(self.report)
        if self._vm is None:
            kS = _vm_step(*self.functions, nq, nu, self.max_evals)
            acc = kS.mapaccum("acc", CHUNK, [0, 1, 2, 3, 4, 5], [0, 1, 2, 3, 4, 5], {})
            x = [ca.MX.sym(f"x{i}", *kS.size_in(i)) for i in range(6)]
            U, Ud, Udd = (ca.MX.sym(c, nu, CHUNK) for c in ("U", "Ud", "Udd"))
            p, L, t = ca.MX.sym("p", kS.size1_in(7)), ca.MX.sym("L"), ca.MX.sym("t", 4)
            rep = lambda a: ca.repmat(a, 1, CHUNK)
            F = ca.Function("chunk", [*x, U, p, L, t, Ud, Udd], acc(*x, U, rep(p), rep(L), rep(t), Ud, Udd))
            buf, call = F.buffer()
            scratch = [np.zeros((CHUNK, m)) for m in (nq, nq * nq, nq * nu, nu, nq * nu, nu, 5, no, nu, nu, nu)]
            for i, a in enumerate(scratch[:8]):
                buf.set_res(i, memoryview(a))
            self._vm = (F, buf, call, scratch)  # buf holds raw pointers: keep it referenced
        _, buf, call, (Qc, Jc, Tc, Uo, T1c, U1c, Ic, Yc, Uc, Udc, Uddc) = self._vm
        parts = np.split(s.copy(), np.cumsum([nq, nq * nq, nq * nu, nu, nq * nu]))
        k = start
        while k < stop:
            m = min(CHUNK, stop - k)
            for c, (a, st) in ((Uc, (r.U, 1)), (Udc, r.Ud), (Uddc, r.Udd)):
                c[:m], c[m:] = (a[k:k + m] if st else a), (a[k + m - 1] if st else a)  # pad
            for i, a in enumerate([*parts, Uc, r.p, r.L, r.thr, Udc, Uddc]):
                buf.set_arg(i, memoryview(a))
            call()
            ok = np.all(Ic[:m, :4] <= r.thr, axis=1)
            j = m if ok.all() else int(np.argmin(ok))
            e = min(j + 1, m)
            r.Q[k:k + e], r.info[:, k:k + e], r.values[:, k:k + e] = Qc[:e], Ic[:e].T, Yc[:e].T
            if r.J is not None:
                r.J[k:k + e] = Jc[:e]
            if j < m:
                return k + j
            parts = [a[m - 1].copy() for a in (Qc, Jc, Tc, Uo, T1c, U1c)]
            k += m
        s[:] = np.concatenate(parts)  # where the compiled loop leaves it too
        return stop


def _take(table, idx):
    a, stride = table
    return a if stride == 0 else a[idx]


# --- one sweeper per compiled model and report ---

_MEMO: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def sweeper_for(model, report=(), compile=None) -> FastSweeper:
    """The `FastSweeper` of a compiled model and report (kept as long as the model is);
    `compile`: None (compile when cached or long), True or False."""
    memo = _MEMO.setdefault(model, {})
    key = ("sweep", tuple(report), compile)
    if key not in memo:
        memo[key] = FastSweeper(model, report, compile=compile)
    return memo[key]


def evaluator_for(model, names) -> QuantityEvaluator:
    """The `QuantityEvaluator` of a compiled model for these quantity names."""
    memo = _MEMO.setdefault(model, {})
    if ("eval", tuple(names)) not in memo:
        memo[("eval", tuple(names))] = QuantityEvaluator(model, names)
    return memo[("eval", tuple(names))]
