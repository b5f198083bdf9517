"""The work of one `sweep_designs` call (kincas/analysis/designs.py): the arrays of every
design and pose, and the stages that fill them: first poses by continuation in the
parameters from the nominal design (batched numpy, or inside the compiled loop), the poses by
the fast pass (compiled blocks of designs on threads, or batched numpy without a compiler),
the careful path for what those reject, and the batched helpers they share.
"""
from __future__ import annotations

import math
import threading
import time

import numpy as np

from ..core import branch
from ..core.assembly import modes
from ..core.batch import BatchEvaluator, batched_solve as _solve, model_lock as _lock
from ..core.cancel import checkpoint
from ..core.compiled import ptr, rows
from ..core.designs_kernel import designs_loop_for
from ..core.fast import FastRun
from ..core.newton import stop_rule
from ..core.tolerances import CAREFUL_DEPTH
from .continuation import _continue, walk_parameters
from .executor import map_threads

OK, NO_ASSEMBLY, NOT_SOLVED, BRANCH_LOST, NO_MESH = 0, 1, 2, 3, 4
STATUS = ("ok", "no assembly", "not solved", "branch lost", "gears do not mesh")
BLOCK = 32  # designs per C call (a thread's unit of work) on the careful designs' path
BLOCK_POSES = 65536  # poses per such call at most (fewer designs when they have many poses)
FULL_BLOCK = 256  # designs per thread's part of the whole-designs loop at most
# The whole-designs loop's calls: the first of FIRST_CALL poses, the next sized by its speed to
# last about CALL_SECONDS (Ctrl-C is heard at once, but the call under way runs to its end)
FIRST_CALL, CALL_SECONDS = 8192, 0.1


class _Job:
    """The arrays of one call of `sweep_designs` and its three stages."""

    def __init__(self, model, m, report, U, Ud, Udd, P, Ls, guess, compile, progress=None):
        self.model, self.m, self.report, self.guess = model, m, report, guess
        self.U, self.Ud, self.Udd, self.P, self.Ls = U, Ud, Udd, P, Ls
        nd, n, nq = P.shape[0], U.shape[0], model.nq
        self.Q = np.empty((nd, n, nq))  # meaningful where code is OK
        self.vals = np.empty((nd, len(report), n))  # NaN where not OK: see fill_values
        self.code = np.full((nd, n), NOT_SOLVED, dtype=np.int8)
        self.fast = np.zeros((nd, n), dtype=bool)  # values computed by the kernel
        self.kernel = (designs_loop_for(model, tuple(report), compile)
                       if model.square and model.nq and model.nu else None)
        self.S = np.full((nd, self.kernel.sweeper.state_size if self.kernel else 0), np.nan)  # kernel states
        self.progress, self.done, self._tick = progress, 0, threading.Lock()
        self.backend = "casadi"  # or "jax": the poses' fast pass (kincas/analysis/designs_jax.py)

    def _news(self, k: int):
        """k more designs are finished."""
        if self.progress is not None:
            with self._tick:
                self.done += k
                self.progress(self.done, self.P.shape[0])

    # --- 0. whole designs in one compiled call each block, on threads ---
    def whole_designs(self, nominal, p0, L0, workers) -> np.ndarray:
        """Every design in the compiled loop (kincas/core/designs_kernel.py): its first pose
        continued from the nominal's, then its poses, without the GIL. Designs it leaves
        before the end are finished here (careful pose, then the kernel again); returns the
        designs whose first pose it could not continue (for `first_poses`)."""
        nd, n = self.P.shape[0], self.U.shape[0]
        todo = np.arange(nd)
        whole = self.kernel is not None and nominal is not None and self.backend == "casadi"
        lib = self.kernel.lib(nd * n) if whole else None
        if lib is None or not nominal.ok or nd == 0:
            return todo
        thr, q0 = _thresholds(), np.ascontiguousarray(nominal.q)
        # one part on one thread (each return waits for the GIL: fewer is faster beside
        # other threads running Python), else about four parts per thread; `run` cuts a part
        # into calls of about CALL_SECONDS
        size = nd if workers == 1 else max(1, min(FULL_BLOCK, math.ceil(nd / (4 * workers))))
        parts = [(a, min(a + size, nd)) for a in range(0, nd, size)]
        stops = np.full(nd, -1)

        def run(part):
            # in calls of about CALL_SECONDS each (Ctrl-C waits for the one under way), sized
            # by the speed of the calls before; a design's numbers do not depend on its call
            a, end = part
            k = max(1, FIRST_CALL // n)
            while a < end:
                checkpoint()
                b = min(end, a + k)
                t = time.perf_counter()
                stops[a:b] = self.kernel.full(lib, self.U, self.P[a:b], self.Ls[a:b], q0, p0, L0,
                                              self.Q[a:b], self.vals[a:b], self.Ud, self.Udd, thr)
                k = _next_call(k, b - a, time.perf_counter() - t)
                for d in a + np.flatnonzero((stops[a:b] > 0) & (stops[a:b] < n)):  # rare: careful
                    self.code[d, :stops[d]], self.fast[d, :stops[d]] = OK, True
                    self._finish(lib, int(d), int(stops[d]))
                self._news(int(np.sum(stops[a:b] > 0)))
                a = b
        if workers > 1 and len(parts) > 1:
            map_threads(run, parts, workers)
        else:
            for part in parts:
                run(part)
        whole = stops == n
        self.code[whole], self.fast[whole] = OK, True
        return np.flatnonzero(stops <= 0)

    def check_gears(self):
        """A design whose gear centres are not r1 + r2 (or |r2 - r1|) apart at its first
        solved pose is refused as a scene would be (kincas/core/joints.py): every pose of it
        gets the status "gears do not mesh" and no values."""
        if not self.m.gears:
            return
        from ..core.joints import first_pose_problems
        for d in range(self.P.shape[0]):
            solved = np.flatnonzero(self.code[d] == OK)
            if solved.size and first_pose_problems(self.model, self.Q[d, solved[0]], self.U[solved[0]],
                                                   self.P[d], self.Ls[d]):
                self.code[d], self.vals[d] = NO_MESH, np.nan

    # --- 1. first poses: continuation in the parameters from the nominal design ---
    def first_poses(self, nominal, p0, L0, idx):
        """First poses of the designs `idx`, all together (numpy), from the nominal's."""
        model, u0 = self.model, self.U[0]
        if not len(idx):
            return
        sign0 = _modes(model, nominal.J, L0) if nominal.ok else None
        ok = np.zeros(len(idx), dtype=bool)
        if nominal.ok and model.nq:
            ok = self._continue_in_parameters(idx, nominal.q, p0, sign0)
        elif nominal.ok:  # nothing to solve for: every design assembles as the nominal
            ok[:] = True
        for j in np.flatnonzero(~ok):  # Newton from the guess, on the nominal's branch
            d = idx[j]
            q = model.initial_q(u0, self.P[d], self.guess, self.Ls[d])
            sol = model.newton(q, u0, self.P[d], self.Ls[d])
            if sol.ok and branch.kept(sign0, _modes(model, sol.J, self.Ls[d])):
                self.Q[d, 0], ok[j] = sol.q, True
            else:
                self.code[d, 0] = BRANCH_LOST if sol.ok else NO_ASSEMBLY
        idx = idx[ok]
        self.code[idx, 0] = OK
        if self.kernel is not None and len(idx):  # the fast pass's starting states, batched
            u = np.repeat(self.U[:1], len(idx), axis=0)
            _, J, Ju, _ = BatchEvaluator(model).derivatives(self.Q[idx, 0], u, self.P[idx])
            T = -_solve(J, Ju)
            cm = lambda a: a.transpose(0, 2, 1).reshape(len(idx), -1)  # column-major rows
            Jd = self.kernel.sweeper.diagonal(J)  # g_q's diagonal blocks, as the kernel keeps them
            self.S[idx] = self.kernel.sweeper.state_rows(self.Q[idx, 0], Jd, cm(T), u)

    def _continue_in_parameters(self, idx, q0, p0, sign0) -> np.ndarray:
        """Whether each design of `idx` was continued from the nominal's first pose (q0 at
        the parameters p0) to its own parameters (its first pose then in self.Q)."""
        walks = walk_parameters(self.model, self.U[0], q0, p0, self.P[idx], self.Ls[idx], sign0,
                                self.kernel.sweeper.blocks if self.kernel else None)
        ok = np.array([w.ok for w in walks], dtype=bool)
        if ok.any():
            self.Q[idx[ok], 0] = np.stack([w.at for w, good in zip(walks, ok) if good])
        return ok

    # --- 2. the poses: compiled blocks of designs on threads, careful where rejected ---
    def sweep_all(self, workers, rest):
        """The designs `rest` (first poses from `first_poses`) over the poses."""
        n = self.U.shape[0]
        todo = rest[self.code[rest, 0] == OK]
        self._news(len(rest) - len(todo))
        lib = self.kernel.lib(len(todo) * n) if self.kernel is not None and n > 1 else None
        size = max(1, min(BLOCK, BLOCK_POSES // n))  # a short call, for Ctrl-C
        blocks = [todo[i:i + size] for i in range(0, len(todo), size)]
        batched = lib is None and self.kernel is not None and n > 1
        if batched:  # no compiled kernel: all designs advance together, pose by pose
            blocks = [todo]
        jax_stops = None
        if self.backend == "jax" and self.kernel is not None and n > 1:
            from .designs_jax import jax_pass  # the fast pass in JAX, then as after the kernel's
            jax_stops = dict(zip(todo.tolist(), jax_pass(self, todo, _thresholds())))

        def run(block):
            checkpoint()
            if jax_stops is not None:
                stops = [jax_stops[int(d)] for d in block]
            elif lib is not None:
                stops = self._kernel_block(lib, block)
            elif batched:
                stops = self._batched_pass(block)
            else:  # no fast pass (no unknowns, or no inputs): the careful path
                stops = np.ones(len(block), dtype=int)
            for d, k in zip(block, stops):
                self._finish(lib, int(d), int(k))
            self._news(len(block))
        if workers > 1 and len(blocks) > 1 and lib is not None:
            map_threads(run, blocks, workers)
        else:
            for b in blocks:
                run(b)

    def _batched_pass(self, todo) -> np.ndarray:
        """The fast pass without a compiler: every design of `todo` advanced pose by pose
        together (mapped CasADi evaluations, numpy's batched solves), each pose predicted
        along the tangent and corrected by Newton, and accepted by the kernel's own tests
        (residual, the next step, det g_q's sign by the Jacobian-change bound, the size of
        the correction). Returns each design's first rejected pose (n if none)."""
        from ..core import fast
        model, U, n = self.model, self.U, self.U.shape[0]
        ev = BatchEvaluator(model)
        stops = np.full(len(todo), n)
        live = np.arange(len(todo))  # positions in todo still advancing
        d = todo
        D = np.where(model.is_length[None, :], self.Ls[d][:, None], 1.0)
        q = self.Q[d, 0]
        _, J, Ju, _ = ev.derivatives(q, np.repeat(U[:1], len(d), 0), self.P[d])
        T = -_solve(J, Ju)
        for k in range(1, n):
            checkpoint()  # Ctrl-C, when this runs on a worker thread
            if not len(live):
                break
            d, Dl = todo[live], D[live]
            uk, pk, Lk = np.repeat(U[k:k + 1], len(d), 0), self.P[d], self.Ls[d]
            pred = q + np.einsum("dij,j->di", T, U[k] - U[k - 1])
            x, conv = pred.copy(), np.zeros(len(d), dtype=bool)
            for it in range(fast.MAX_EVALS):
                g, Jk, Juk, _ = ev.derivatives(x, uk, pk)
                dx = _solve(Jk, g)
                # the one stopping rule (kincas/core/newton.py), with the kernel's thresholds:
                # solved and the next step negligible, which is applied
                now = stop_rule(np.abs(g).max(axis=1) / Lk, np.abs(dx / Dl).max(axis=1),
                                accept=fast.RESIDUAL, tol=fast.STEP)[0] & ~conv
                x = np.where(conv[:, None], x, x - dx)
                conv |= now
                if conv.all() or it == fast.MAX_EVALS - 1:
                    break
            with np.errstate(all="ignore"):
                M = (_solve(J, Jk) - np.eye(model.nq)) * Dl[:, None, :] / Dl[:, :, None]
                good = (conv & (np.abs(M).sum(axis=(1, 2)) <= fast.JAC_CHANGE)
                        & (np.abs((x - pred) / Dl).sum(axis=1) <= fast.CORRECTION))
            self.Q[d[good], k], self.code[d[good], k] = x[good], OK
            stops[live[~good]] = k
            live, q, J = live[good], x[good], Jk[good]
            T = -_solve(J, Juk[good])
        return stops

    def _kernel_block(self, lib, block) -> np.ndarray:
        """One C call: the designs of `block` from their first poses, until each is rejected."""
        sw, n, nq, nu = self.kernel.sweeper, self.U.shape[0], self.model.nq, self.model.nu
        nb = len(block)
        S = np.ascontiguousarray(self.S[block])
        P, Ls = np.ascontiguousarray(self.P[block]), np.ascontiguousarray(self.Ls[block])
        Q, info = np.empty((nb, n, nq)), np.empty((nb, 5, n))  # info: the kernel's, unused
        vals, stops = np.empty((nb, len(self.report), n)), np.empty(nb)
        (Ud, sud), (Udd, sudd) = rows(self.Ud, n, nu), rows(self.Udd, n, nu)
        thr = _thresholds()  # referenced until the call returns: C reads it by address
        lib.kincas_designs(nb, n, ptr(self.U), ptr(P), P.shape[1], ptr(Ls), ptr(thr), sw.max_evals,
                           ptr(S), S.shape[1], ptr(Q), ptr(info), ptr(Ud), sud, ptr(Udd), sudd,
                           ptr(vals), ptr(stops))
        stops = stops.astype(int)
        for j, d in enumerate(block):
            k = stops[j]  # poses 1..k-1 accepted; k rejected (if < n)
            self.Q[d, 1:k], self.vals[d, :, 1:k] = Q[j, 1:k], vals[j, :, 1:k]
            self.code[d, 1:k], self.fast[d, 1:k] = OK, True
        return stops

    def _finish(self, lib, d: int, k: int):
        """Design d from pose k on (poses before k solved): careful pose, then the fast pass
        again, until the end or a pose that cannot be reached."""
        model, U, n, p, L = self.model, self.U, self.U.shape[0], self.P[d], self.Ls[d]
        while k < n:
            checkpoint()
            with _lock(model):
                prev = (self.Q[d, k - 2], U[k - 2]) if k >= 2 else None
                sol = _continue(model, self.Q[d, k - 1], U[k - 1], U[k], p, L, depth=CAREFUL_DEPTH, prev=prev)
                if sol is None or not sol.ok:
                    lost = model.newton(self.Q[d, k - 1], U[k], p, L).ok
                    self.code[d, k] = BRANCH_LOST if lost else NO_ASSEMBLY
                    return
                self.Q[d, k], self.code[d, k] = sol.q, OK
            k = self._fast_from(lib, d, k)

    def _fast_from(self, lib, d: int, j: int) -> int:
        """The fast pass for design d from its solved pose j; returns the pose it stopped at
        (the poses between are solved)."""
        n = self.U.shape[0]
        if j + 1 >= n or self.kernel is None:
            return j + 1
        if lib is not None:
            stop = self._kernel_from(lib, d, j)
        else:  # the virtual machine: its buffers are the sweeper's, so one at a time
            with _lock(self.model):
                run = FastRun(self.kernel.sweeper, self.U, self.P[d], self.Ls[d], self.Ud, self.Udd)
                stop = run.advance(j + 1, self.Q[d, j], self.U[j])
            sl = slice(j + 1, stop)
            self.Q[d, sl], self.vals[d, :, sl] = run.Q[sl], run.values[:, sl]
        self.code[d, j + 1:stop], self.fast[d, j + 1:stop] = OK, True
        return stop

    def _kernel_from(self, lib, d, k) -> int:
        """The fast pass for design d from its solved pose k; returns the pose it stopped at."""
        sw, n, nq, nu = self.kernel.sweeper, self.U.shape[0], self.model.nq, self.model.nu
        with _lock(self.model):
            s = sw.state(self.Q[d, k], self.U[k], self.P[d])
        thr = _thresholds()
        p, L = np.ascontiguousarray(self.P[d]), np.array([self.Ls[d]])
        Q, info, vals = np.empty((n, nq)), np.empty((5, n)), np.empty((len(self.report), n))
        (Ud, sud), (Udd, sudd) = rows(self.Ud, n, nu), rows(self.Udd, n, nu)
        a = k + 1
        got = lib.kincas_sweep(n - a, ptr(self.U, a * nu), ptr(p), ptr(L), ptr(thr), sw.max_evals,
                               ptr(s), ptr(Q, a * nq), ptr(info, a), n, ptr(Ud, a * sud), sud,
                               ptr(Udd, a * sudd), sudd, ptr(vals, a), None)
        stop = a + got
        self.Q[d, a:stop], self.vals[d, :, a:stop] = Q[a:stop], vals[:, a:stop]
        return stop

    # --- 3. what is left: gaps resumed by kincas.sweep, values at careful poses ---
    def resume_gaps(self, names):
        from .sweeps import sweep

        m, model = self.m, self.model
        pnames = [k for k, _ in m.parameters]
        for d in np.flatnonzero((self.code[:, 0] == OK) & (self.code != OK).any(axis=1)):
            md = m.with_parameters(**dict(zip(pnames, self.P[d])))
            with _lock(model):
                pts = model.points(self.Q[d, 0], self.U[0], self.P[d])
                g = {nm: tuple(pts[:, j]) for j, nm in enumerate(m.moving_points)}
                keys = [i.key for i in m.inputs]
                sw = sweep(md, {k: self.U[:, j] for j, k in enumerate(keys)},
                           rates={k: self.Ud[:, j] for j, k in enumerate(keys)},
                           accelerations={k: self.Udd[:, j] for j, k in enumerate(keys)},
                           report=self.report, guess=g)
            self.Q[d] = sw.q
            self.code[d] = np.where(sw.ok, OK, NO_ASSEMBLY)
            self.vals[d] = np.stack([sw[nm] for nm in self.report]) if self.report else self.vals[d]
            self.fast[d] = True  # values filled

    def fill_values(self):
        """Quantities at the poses solved on the careful path; NaN (and unknowns NaN) where
        a pose is not solved."""
        bad = self.code != OK
        self.vals.transpose(0, 2, 1)[bad] = np.nan
        self.Q[bad] = np.nan
        d, k = np.nonzero(~bad & ~self.fast)
        if not len(d) or not self.report:
            return
        ev = BatchEvaluator(self.model)
        with _lock(self.model):
            self.vals[d, :, k] = ev.quantities(self.report, self.Q[d, k], self.U[k], self.P[d],
                                               self.Ud[k], self.Udd[k]).T


def _next_call(k: int, done: int, seconds: float) -> int:
    """Designs in the next call: CALL_SECONDS at the speed of the last call (`done` designs
    in `seconds`), growing at most eightfold a call (a first call may be slow to warm up)."""
    rate = done / max(seconds, 1e-6)
    return int(max(1, min(8 * k, rate * CALL_SECONDS)))


def _modes(model, J, L) -> np.ndarray:
    """Each Assur group's mode (sign of its block's det, 0 near singular) at one pose."""
    return modes(model, J, L)[0] if model.square else np.zeros(0)


def _thresholds() -> np.ndarray:
    """The fast pass's acceptance thresholds, as `FastRun` sets them."""
    from ..core import fast
    return np.array([fast.RESIDUAL, fast.STEP, fast.JAC_CHANGE, fast.CORRECTION, fast.KERNEL_NEAR])

