"""Fast sweeps: each pose predicted along the tangent and corrected by Newton, in compiled C.

The careful path (`kincas.solve`) spends about 70 us per pose in Python. Here one call solves
a whole stretch of a sweep: pose k is predicted from the last solved pose along the exact
tangent, q_pred = q_prev + dq/du (u_k - u_prev) with dq/du = -g_q^-1 g_u, plus second- and
third-order terms from the pose before and its tangent (the cubic through both poses with
both tangents; where it pays, the quintic through three: kincas/core/prediction.py), then
corrected by Newton,
q <- q - g_q^-1 g, until the next step would be negligible (on a dense sweep the prediction
usually is already). A pose is *accepted* only when it is verified in the same pass:

- residual: max |g| / L <= RESIDUAL (the careful path's acceptance), each equation against
  its own Assur group's length L (`Structure.block_lengths`), as on the careful path;
- converged: the Newton step that would follow, |g_q^-1 g| (radians, lengths / L) <= STEP;
- same branch: M = J_prev^-1 J with J = g_q. If ||D^-1 (M - I) D|| < 1 (D scales lengths by
  L), every matrix on the segment from I to M is invertible, so det M > 0: det g_q kept its
  sign and no singular position lies between the two poses. The test fails near a singular
  position too (J_prev^-1 grows), where fixed-step kernels jump branch silently;
- small correction: ||D^-1 (q - q_pred)||_1 <= CORRECTION in every Assur group.

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
>>> model, U = kincas.model_of(m), np.linspace(0, 2 * np.pi, 721)[:, None]
>>> q0 = model.newton(model.initial_q(U[0], [], {"C": (3.6, 2.9)}, 5), U[0], [], 5).q
>>> run = FastSweeper(model, compile=False).run(U, [], 5.0, q0, U[0], start=1)
>>> run.first_bad, bool(run.residual[1:].max() < 1e-13)
(721, True)
"""
from __future__ import annotations

import ctypes
import threading

import casadi as ca
import numpy as np

from .blocks import diagonal_size, numeric_signs
from .compiled import CHUNK, Backend, Library, QuantityEvaluator  # noqa: F401 (CHUNK: its old home)
from .c_library import trig_for
from .fast_run import INFO, WHOLE_C, WHOLE_SIGS, FastRun, _moved_within, _rows, _take, _ticks  # noqa: F401 (INFO, _rows: their old home)
from .fast_vm import VM_CHUNKS, VM_FLAT, VM_SKIP, VirtualMachineSweep, _Buffered  # noqa: F401
from .group_kernel import kernel_sizes
from .kernel import (CORRECTION, JAC_CHANGE, MAX_EVALS, KERNEL_NEAR, QUINTIC_ON, QUINTIC_TRY, RESIDUAL,  # noqa: F401
                     STEP, kernel_functions, state_function)
from .sweep_loop import SWEEP_C, loop_trig

# Kernel size, in casadi instructions, beyond which compiling costs more than it saves: gcc
# -O3 took 1.7 s at 11k instructions, 13 s at 39k and 200 s (3.5 GB) at 150k.
COMPILE_MAX = 40_000
# Beyond this size the virtual machine would be slower than the careful path. Since the kernel
# solves group by group it grows linearly, and on 40 chained four-bars (7.9k instructions) the
# virtual machine took 0.3 ms a pose against 26 ms on the careful path: only a far larger
# kernel could lose (and it is never compiled either).
VM_MAX = 200_000
# With compile=None, a sweeper compiles its kernel in the background once it is used again: at
# its BACKGROUND_CALLS-th sweep when its sweeps add up to BACKGROUND_MIN_POSES poses, or once
# they add up to BACKGROUND_POSES (one long sweep, or many short ones). The virtual machine
# costs ~2-10 us a pose more than the compiled loop (a four-bar, Jansen's leg), compiling a
# small kernel 0.3-1 s of a background thread (the C compiler runs outside the GIL): a
# mechanism swept again is likely swept many times (a user's loop, an optimiser), and
# started at its second sweep the compile lands while the virtual machine serves. A one-off
# sweep (`kincas solve`) compiles nothing, nor does a structure swept again only briefly (a
# test suite sweeping hundreds of structures a few times each). Started earlier, at the start
# of the first sweep, it was slower (Jansen's leg, fresh processes, 1,000 sweeps of 360 poses:
# 1.14x the time, 1.25x for the first sweep; median of 4 interleaved pairs, loaded machine):
# the compiler competes with the first sweep's own building; and in a loop the end of the
# first sweep is the start of the second, where it starts now.
BACKGROUND_CALLS = 2
BACKGROUND_MIN_POSES = 500
BACKGROUND_POSES = 20_000
FEW_UNKNOWNS = 16  # up to this many unknowns, a first pose's correction is summed in Python
BLOCK = 65536  # poses per call when a progress callback wants news
_I, _V = ctypes.c_longlong, ctypes.c_void_p
# kincas_sweep's C signature (SWEEP_C): every library that links the loop declares it so
SWEEP_SIG = [_I, _V, _V, _V, _V, _I, _V, _V, _V, _I, _V, _I, _V, _I, _V, _V]


# --- the sweep driver ---


class FastSweeper(VirtualMachineSweep):
    """Whole sweeps of one compiled model (`kincas.model_of(m)`), any parameter values.

    `report` lists the quantities computed with each pose (only what they need is built).
    `run(U, p, L, q_start, u_start)` solves U[start:] from a solved pose; `sweep(U, p, L,
    careful)` solves every pose, handing those the fast pass rejects to `careful`.
    `backend.library.times` says how long generating, compiling and loading took.
    A sweeper may be used from several threads at once: each call works in its own arrays
    (the compiled kernel, which runs without the GIL, writes only those), the virtual
    machine's buffers are per thread, and what is built once is built under a lock.
    """

    def __init__(self, model, report=(), *, compile=None, max_evals: int = MAX_EVALS):
        self.model, self.sym, self.report = model, model.sym, tuple(report)
        self.nq, self.nu, self.max_evals = model.sym.nq, model.sym.nu, int(max_evals)
        model.quantity_function(self.report)  # names checked here
        self.blocks = _model_blocks(model)
        self._group_of = np.full(self.nq, len(self.blocks), dtype=np.intp)  # each unknown's group
        for i, b in enumerate(self.blocks):
            self._group_of[np.asarray(b.cols, dtype=np.intp)] = i
        self._groups = self._group_of.tolist()
        # (for `_moved_within` summing in Python: None where every unknown is in the one group)
        self._groups_few = None if len(self.blocks) == 1 and not any(self._groups) else self._groups
        self.nj = diagonal_size(self.blocks)  # g_q's diagonal blocks, all the state keeps of it
        self.state_size = sum(self.state_parts)
        self._functions, self._size, self._poses, self._calls = None, None, 0, 0  # swept so far
        self._lock = threading.RLock()
        self._layouts: dict = {}  # where each part of a run's block starts, per sizes (kincas/core/fast_run.py)
        self._local = threading.local()  # the virtual machine's buffers, one set per thread
        self.backend = Backend(compile, self._library, "fast sweep kernel")

    @property
    def size(self) -> int:
        """The kernel's C code size in casadi instructions (what compiling costs: a
        function shared by several Assur groups counts once, kincas/core/group_kernel.py)."""
        if self._size is None:
            code, self._work = kernel_sizes([f for f in self.functions[:5] if f is not None])
            self._size = code  # set last: another thread reads _work once it sees _size
        return self._size

    @property
    def work(self) -> int:
        """Instructions evaluated per kernel pass (what running it costs)."""
        self.size
        return self._work

    def worth_it(self, n: int) -> bool:
        """Whether the fast pass pays for n poses: compiled (when its size allows: a larger
        kernel is never compiled), or small enough for the virtual machine to beat the
        careful path."""
        if self.backend.compile is not False and self.size > COMPILE_MAX:
            self.backend.compile = False
        return self.backend.compiled(n) is not None or self.work <= VM_MAX

    @property
    def functions(self) -> list[ca.Function]:
        """kP, kN, kF, kL, kP5, kW (kincas/core/kernel.py), built when first needed, once per model
        and report: the sweepers of one kernel with different `compile` settings share them,
        so they generate the same C code (the same library)."""
        if self._functions is None:
            self._functions = self.model.memo(
                ("kernel", self.report),
                lambda: kernel_functions(self.sym, self.blocks, self.report, self.model.structure))
        return self._functions

    @property
    def compiled_functions(self) -> list[ca.Function]:
        """The kernel's functions that its C code holds: kN, kF, kL and kW (the C loop forms
        the predictions of kP and kP5 itself from kW's scalars, kincas/core/kernel.py)."""
        kP, kN, kF, kL, kP5, kW = self.functions
        return [kN, kF, kL, kW]

    def _library(self) -> Library:
        kN, kF, kL, kW = self.compiled_functions
        kN, kF, trig = loop_trig(kN, kF)  # (a flat kernel's sines and cosines from the loop)
        return Library("kincas_sweep", [kN, kF, kL, kW], SWEEP_C + WHOLE_C, {**self.sweep_macros(), **trig},
                       {"kincas_sweep": SWEEP_SIG, **WHOLE_SIGS}, trusted=True, trig=self.trig)

    @property
    def trig(self) -> str:
        """How the compiled kernel computes sines and cosines (c_library.Library's `trig`,
        by `trig_for` its number of unknowns)."""
        return trig_for(self.nq)

    def sweep_macros(self) -> dict:
        """The sizes SWEEP_C is compiled with (kincas/core/sweep_loop.py)."""
        return {"NQ": self.nq, "NU": self.nu, "NO": len(self.report), "NM": len(self.blocks) + 1,
                "NJ": self.nj, "QUINTIC_ON": repr(float(QUINTIC_ON)),
                "QUINTIC_TRY": repr(float(QUINTIC_TRY)), "HAVE_KP5": int(self.functions[4] is not None),
                "KS_LENGTHS_ANY": int(bool(np.any(self.sym.is_length))), "KS_LENGTHS": self._lengths_of()}

    def _lengths_of(self) -> str:
        """SWEEP_C's KS_LENGTHS: per unknown, the group whose length scales it, -1 an angle."""
        if not self.nq:
            return "{0}"
        return "{" + ", ".join(str(g if length else -1) for g, length in zip(self._groups, self.sym.is_length)) + "}"

    @property
    def state_parts(self) -> tuple:
        """The sizes of the kernel state's parts, in order (`state`; SWEEP_C's offsets):
        q, J (g_q's diagonal blocks), T, u at the last pose, then T, u, q at the pose before
        and at the one before that, then the flags near and five."""
        nq, nu = self.nq, self.nu
        return (nq, self.nj, nq * nu, nu, nq * nu, nu, nq, nq * nu, nu, nq, 1, 1)

    def state(self, q, u, p, out=None) -> np.ndarray:
        """(q, J, T = dq/du, u, T, u, q, T, u, q, near, five) at a solved pose, matrices
        column-major as in casadi (the second and third T, u, q stand for the poses before:
        the first prediction is linear; near = 0: Newton from the first prediction; five =
        0: by the cubic), in `out` if given. At a singular start T is not finite, and the
        next pose fails the branch test."""
        nq, nu, nj = self.nq, self.nu, self.nj
        s = np.empty(self.state_size) if out is None else out
        s[:nq], s[nq + nj + nq * nu:][:nu] = np.ravel(q), np.ravel(u)
        f = self._state_call()
        f(s[:nq], s[nq + nj + nq * nu:][:nu], np.ravel(p), s[nq:nq + nj], s[nq + nj:][:nq * nu])
        back = nq + nj + nq * nu + nu  # where the pose before starts: (T, u, q), then again
        for at in (back, back + nq * nu + nu + nq):
            s[at:at + nq * nu + nu] = s[nq + nj:back]
            s[at + nq * nu + nu:][:nq] = s[:nq]
        s[-2:] = 0.0
        return s

    def state_rows(self, q, Jd, T, u) -> np.ndarray:
        """(N, state_size): the states (as `state` makes one) of N solved poses, given their
        unknowns q (N, nq), g_q's diagonal blocks Jd (N, nj, as `diagonal` gives them),
        tangents T (N, nq * nu, each column-major) and inputs u (N, nu)."""
        before = np.concatenate([T, u, q], axis=1)  # the poses before: this one
        return np.concatenate([q, Jd, T, u, before, before, np.zeros((len(q), 2))], axis=1)

    def diagonal(self, J: np.ndarray) -> np.ndarray:
        """(N, nj): the diagonal blocks of N matrices g_q (N, nq, nq), as the state keeps them."""
        parts = [J[:, b.rows][:, :, b.cols].transpose(0, 2, 1).reshape(len(J), -1) for b in self.blocks]
        return np.concatenate(parts, axis=1) if parts else np.zeros((len(J), 0))

    def _state_call(self) -> "_Buffered":
        f = getattr(self._local, "state", None)
        if f is None:
            with self._lock:
                if getattr(self, "_kT", None) is None:
                    self._kT = state_function(self.sym, self.blocks)
            f = self._local.state = _Buffered(self._kT)
        return f

    def measures(self, sol, u, p, L) -> np.ndarray:
        """The kernel's singular measures (signs per group, then sigma) at a solved pose."""
        J = sol.J if getattr(sol, "J", None) is not None else self.model.jac(sol.q, u, p)
        Js = J * self.model.column_scale(L)
        signs = numeric_signs(Js[None], self.blocks)[0]
        sv = np.linalg.svd(Js, compute_uv=False) if Js.size else np.ones(1)
        return np.r_[signs, sv[-1] / max(1.0, sv[0])]

    def run(self, U, p, L, q_start, u_start, start: int = 0, Ud=None, Udd=None) -> FastRun:
        """Poses U[start:] (an (N, nu) table) from the solved pose (q_start, u_start)."""
        r = FastRun(self, U, p, L, Ud, Udd)
        k = r.advance(start, q_start, u_start)
        for a in (r.Q, r.info.T, r.values.T, r.measures.T):  # not reached
            a[:start], a[k + 1:] = np.nan, np.nan
        r.summarised = False  # (the measures before `start` were not the loop's)
        return r

    def sweep(self, U, p, L, careful, Ud=None, Udd=None, progress=None, first=None) -> FastRun:
        """Every pose of U: the fast pass wherever it is accepted, else `careful(k, j, run)`
        -> a solution with q, residual, iterations, ok, where j is the last solved pose (None
        while none is; its unknowns are run.Q[j]); the fast pass restarts after each. Between
        two consecutive fast poses det g_q keeps its sign (see the module's text). With no
        unknowns or no inputs, every pose goes to `careful`.

        `first(k)`, if given, places pose k while no pose is solved yet: a `Placement`
        (kincas/analysis/prepared.py) of the unknowns the careful path would start Newton from
        (the guessed points) and each unknown's scale in its own group, or None. The kernel
        then solves pose k from q0 (`_from_guess`), and the careful path only where the
        kernel's answer is not certainly the careful path's."""
        r = FastRun(self, U, p, L, Ud, Udd)
        self._poses, self._calls = self._poses + r.n, self._calls + 1
        if (self._poses >= BACKGROUND_POSES or self._calls >= BACKGROUND_CALLS and self._poses >= BACKGROUND_MIN_POSES) \
                and self.backend.lib is None and self.size <= COMPILE_MAX:  # worth compiling now
            self.backend.start()  # (compile=None only; the virtual machine serves meanwhile)
        k, last, going = 0, None, False  # going: the last block ended with no rejection

        tick = None if progress is None else _ticks(progress, r.n)  # (a closure made here
        # would make cells of `progress` and `r` at every call)
        while k < r.n:
            if last is not None and self.nq and self.nu:
                stop = r.n if progress is None else k + BLOCK
                bad = r.advance(k, *((None, None) if going else (r.Q[last], r.U[last])), stop)
                last, going = (bad - 1 if bad > k else last), bad == min(stop, r.n)
                if tick is not None:
                    tick(k, bad)
                k = bad
                if going or k == r.n:
                    continue
            if last is None and first is not None and self.nq and self.nu:
                stop = r.n if progress is None else k + BLOCK
                bad = self._from_guess(r, k, first(k), stop)
                if bad > k:  # the kernel solved pose k from the placed guess, and went on
                    last, going = bad - 1, bad == min(stop, r.n)
                    if tick is not None:
                        tick(k, bad)
                    k = bad
                    if going or k == r.n:
                        continue  # else pose k was rejected: the careful path, as after any pass
            sol = careful(k, last, r)
            r.record(k, sol)
            if sol.ok and last is None and self.nq and self.nu and self._again(r, k):
                last, going, k = k, True, k + 1  # the kernel took the pose over: go on from it
            else:
                last, k, going = (k if sol.ok else last), k + 1, False
            if tick is not None:
                tick(k - 1, k)
        slow = np.flatnonzero(r.solved & ~r.accepted) if r.recorded and self.report else ()
        if len(slow):
            ev = evaluator_for(self.model, self.report)
            r.values[:, slow] = ev.evaluate(r.Q[slow], r.U[slow], r.p, _take(r.Ud, slow), _take(r.Udd, slow))
        if progress is not None:
            progress(r.n, r.n)
        r.attempted = True  # every pose: Newton's steps counted at each (no NaN to mend)
        return r

    def _from_guess(self, r: FastRun, k: int, placed, stop: int) -> int:
        """Pose k (no pose solved before it) by the kernel's Newton from the placed guess
        q0, and the poses after it from there; returns where that pass stopped (k: pose k is
        left to the careful path, with nothing of this attempt kept).

        Pose k is accepted when it passes every test of any pose (residual, converged,
        Jacobian change against g_q at q0 below JAC_CHANGE per group, correction) and, per
        Assur group, (a) its block's determinant has the same sign, not zero, at q0 and at
        the solution, and (b) the correction |q - q0| (each unknown over its scale in its
        own group, `Model.scales`) sums to at most CORRECTION. Then Newton stayed within
        one group mode's neighbourhood of q0 with every block invertible on the way (the
        Jacobian test), where the careful path's damped Newton from q0 converges to the
        same root: the guess chooses the branch, as it does on the careful path."""
        if placed is None:
            return k
        q0, qs = placed.q0, placed.qs
        if placed.kernel is None:  # the state at q0 and its groups' signs, once per placement
            s = self.state(q0, r.U[k], r.p)
            s.flags.writeable = False
            before = _diagonal_signs(s[self.nq:self.nq + self.nj], self.blocks)
            # q0 and 1 / qs as Python numbers: the correction of a few unknowns summed in
            # Python costs a third of numpy's calls for it (many: as numpy arrays)
            w = 1.0 / qs
            w.flags.writeable = False
            few = self.nq <= FEW_UNKNOWNS
            placed.kernel = (s, before.tolist(), bool((before != 0).all()), q0.tolist() if few else q0,
                             w.tolist() if few else w)
        s, before, regular, q0s, inv_qs = placed.kernel
        if not regular:  # a group singular at q0: its mode is not the guess's to choose
            r._s = None
            return k
        st = r._s = r._state
        st[:] = s
        bad = r.advance(k, None, None, stop)
        if bad > k and r.modes_at(k) == before and _moved_within(r.Q[k], q0s, inv_qs, self._groups_few,
                                                                   self._group_of, len(self.blocks)):
            return bad
        r._s, r.summarised = None, False  # nothing of this attempt is kept: the careful path starts afresh
        r.Q[k:bad + 1] = r.values[:, k:bad + 1] = r.measures[:, k:bad + 1] = np.nan
        r.accepted[k:bad + 1] = r.solved[k:bad + 1] = False
        return k

    def _again(self, r: FastRun, k: int) -> bool:
        """Re-solve the first carefully solved pose k in the kernel (predicted where it is,
        so Newton stops at once): its quantities and measures then come from the same pass,
        not from a separate evaluation. False, with the careful record kept, if rejected."""
        kept = r.Q[k].copy(), r.info[:, k].copy(), r.measures[:, k].copy()
        if r.advance(k, r.Q[k], r.U[k], k + 1) == k + 1:
            return True
        r.Q[k], r.info[:, k], r.measures[:, k] = kept
        r.solved[k] = True
        return False


def _diagonal_signs(d: np.ndarray, blocks) -> np.ndarray:
    """The signs of the determinants of g_q's diagonal blocks, given as the state keeps them
    (`diagonal_blocks`: each block's entries column-major, one block after another)."""
    out, at = np.empty(len(blocks)), 0
    for i, b in enumerate(blocks):
        n, m = len(b.cols), len(b.rows)
        A = d[at:at + m * n]
        at += m * n
        if m > n:  # tall (redundant joints): no mode, +1 as the kernel gives it
            out[i] = 1.0
            continue
        det = A[0] if n == 1 else A[0] * A[3] - A[1] * A[2] if n == 2 else np.linalg.det(A.reshape(n, n))
        out[i] = np.sign(det)
    return out



def _model_blocks(model):
    """The model's Assur groups as blocks of g_q, in solve order."""
    return list(model.blocks)


# --- one sweeper per compiled model and report (kept by the model: `Model.memo`) ---


def sweeper_for(model, report=(), compile=None) -> FastSweeper:
    """The `FastSweeper` of a compiled model and report (kept as long as the model is);
    `compile`: None (compile when cached or long), True or False."""
    return model.memo(("sweep", tuple(report), compile),
                      lambda: FastSweeper(model, report, compile=compile))


def evaluator_for(model, names) -> QuantityEvaluator:
    """The `QuantityEvaluator` of a compiled model for these quantity names."""
    return model.memo(("eval", tuple(names)), lambda: QuantityEvaluator(model, names))
