"""The fast sweep in casadi's virtual machine, when its kernel is not compiled.

The same arithmetic as the compiled C loop (kincas/core/kernel.py), `mapaccum` over chunks of
poses: `VirtualMachineSweep` is the part of `FastSweeper` (kincas/core/fast.py) that builds
the chunk functions, binds them to per-thread numpy buffers and runs a stretch of a
`FastRun` through them, stopping where the C loop would stop. `_Buffered` evaluates one
casadi Function straight between numpy arrays.

>>> import casadi as ca, numpy as np
>>> x = ca.SX.sym("x")
>>> out = np.zeros(1)
>>> _Buffered(ca.Function("twice", [x], [2 * x]))(np.array([1.5]), out)
>>> out
array([3.])
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import casadi as ca
import numpy as np

from .compiled import CHUNK
from .kernel import vm_step

if TYPE_CHECKING:
    from .fast_run import FastRun


VM_CHUNKS = (1, 8, 32, 128, CHUNK)  # poses per call of the virtual machine's sweep
# Above VM_SKIP instructions a kernel pass (40 chained four-bars: 10,500), the virtual machine
# skips the Newton steps after convergence and sizes its chunks to the poses left: a padded
# or wasted pose costs more than the switches' calls and the build of a chunk function per
# size (which grows with the size: 12 ms for 256 poses of a four-bar). Below (a four-bar:
# 240), one flat SX pose, and chunks of VM_FLAT poses, the last one padded: CHUNK for a
# stretch of at least 4 * CHUNK poses (fewer calls); a short sweep builds only 64 (3 ms).
VM_SKIP = 2_000
_ACC = 12  # the accumulated inputs and outputs of `vm_step`: the state's parts (`state_parts`, flags included)
VM_FLAT = 64


class VirtualMachineSweep:
    """`FastSweeper`'s virtual machine (its nq, nu, report, blocks, nj, functions, work,
    max_evals, lock and per-thread store): the same arithmetic as the compiled loop."""

    # --- the virtual machine: the same arithmetic, mapaccum over chunks of VM_CHUNKS poses ---
    def _vm_function(self, size: int) -> ca.Function:
        with self._lock:
            if getattr(self, "_vmF", None) is None:
                self._vmF = {}
            if size not in self._vmF:
                nu = self.nu
                kS = getattr(self, "_kS", None) or vm_step(*self.functions[:5], self.nq, nu, self.max_evals,
                                                           skip=self.work > VM_SKIP)
                self._kS = kS
                acc = kS.mapaccum("acc", size, list(range(_ACC)), list(range(_ACC)), {})
                x = [ca.MX.sym(f"x{i}", *kS.size_in(i)) for i in range(_ACC)]
                U, Ud, Udd = (ca.MX.sym(c, nu, size) for c in ("U", "Ud", "Udd"))
                p, L, t = ca.MX.sym("p", kS.size1_in(_ACC + 1)), ca.MX.sym("L"), ca.MX.sym("t", 5)
                Lb = self.functions[3](U[:, 0], p)  # the groups' lengths, as the C loop takes them
                rep = lambda a: ca.repmat(a, 1, size)
                self._vmF[size] = ca.Function("chunk", [*x, U, p, L, t, Ud, Udd],
                                              acc(*x, U, rep(p), rep(L), rep(t), Ud, Udd, rep(Lb)))
            return self._vmF[size]

    def _vm_buffers(self, size: int):
        """This thread's buffers bound to the chunk function of `size` poses (built on first use)."""
        vms = getattr(self._local, "vm", None)
        if vms is None:
            vms = self._local.vm = {}
        if size not in vms:
            nu, no, nm = self.nu, len(self.report), len(self.blocks) + 1
            F = self._vm_function(size)
            buf, call = F.buffer()
            scratch = [np.zeros((size, m)) for m in (*self.state_parts, 6, no, nm, nu, nu, nu)]
            for i, a in enumerate(scratch[:_ACC + 3]):
                buf.set_res(i, memoryview(a))
            vms[size] = (F, buf, call, scratch)  # buf holds raw pointers: keep it
        return vms[size]

    def _vm_advance(self, r: FastRun, start: int, stop: int, s: np.ndarray) -> int:
        # the state, its last entries `near` and `five` (the compiled loop's flags: try kF at
        # the prediction first; predict by the quintic)
        parts = np.split(s.copy(), np.cumsum(self.state_parts[:-1]))
        k, sized = start, self.work > VM_SKIP
        flat = CHUNK if stop - start >= 4 * CHUNK else VM_FLAT
        while k < stop:  # a large kernel: the smallest chunk that holds what is left (padded
            # poses cost too), and a short one first: the first pose of a stretch is the
            # likeliest to be rejected, and the chunk's later poses are computed all the same
            left = stop - k if k > start else min(stop - k, VM_CHUNKS[1])
            size = (next((c for c in VM_CHUNKS if c >= left), VM_CHUNKS[-1]) if sized
                    else flat)
            _, buf, call, (*state, Ic, Yc, Mc, Uc, Udc, Uddc) = self._vm_buffers(size)
            Qc = state[0]
            m = min(size, stop - k)
            for c, (a, st) in ((Uc, (r.U, 1)), (Udc, r.Ud), (Uddc, r.Udd)):
                c[:m], c[m:] = (a[k:k + m] if st else a), (a[k + m - 1] if st else a)  # pad
            for i, a in enumerate([*parts, Uc, r.p, r.L, r.thr, Udc, Uddc]):
                buf.set_arg(i, memoryview(a))
            call()
            ok = (Ic[:m, 5] > 0) & np.all(Ic[:m, 2:4] <= r.thr[2:4], axis=1)
            j = m if ok.all() else int(np.argmin(ok))
            e = min(j + 1, m)
            r.Q[k:k + e], r.info[:, k:k + e], r.values[:, k:k + e] = Qc[:e], Ic[:e, :5].T, Yc[:e].T
            r.measures[:, k:k + e] = Mc[:e].T
            if j < m:
                return k + j
            parts = [a[m - 1].copy() for a in state]
            k += m
        s[:] = np.concatenate(parts)  # where the compiled loop leaves it too
        return stop


class _Buffered:
    """A casadi Function evaluated straight between numpy arrays (about 1 us a call instead
    of 10-20 through DM). Its buffer holds raw pointers: one per thread, never shared."""

    def __init__(self, f: ca.Function):
        self.buf, self.call = f.buffer()
        self.n_in = f.n_in()

    def __call__(self, *arrays):
        keep = [np.ascontiguousarray(a, dtype=float) for a in arrays]
        for i, a in enumerate(keep[:self.n_in]):
            self.buf.set_arg(i, memoryview(a))
        for i, a in enumerate(keep[self.n_in:]):
            self.buf.set_res(i, memoryview(a))
        self.call()
        for a, b in zip(keep[self.n_in:], arrays[self.n_in:]):
            if a is not b:
                b[...] = a
