"""CasADi functions looped over many poses in compiled C, the library cached on disk.

`Library` code-generates casadi functions together with a hand-written C loop that calls
them, compiles the whole with the C compiler ($CC, else gcc or cc) and keeps the result in
the cache directory under a hash of its source, the compiler and casadi's version: a second
process, or a second run, loads it without compiling (kincas/core/c_library.py). `Backend`
decides when compiling is worth it and falls back to casadi's virtual machine, with a warning,
when it fails: a missing compiler never fails a user's solve. `QuantityEvaluator` is the simplest such loop: reported
quantities at N given poses (`kincas.fast` builds the sweep itself the same way).

>>> import casadi as ca
>>> x = ca.SX.sym("x")
>>> lib = Library("kincas_doc", [ca.Function("twice", [x], [2 * x])], "", {}, {})
>>> lib.path.suffix, len(lib.path.stem) > 20
('.so', True)
"""
from __future__ import annotations

import ctypes
import threading
import warnings

from .c_library import (MAX_CACHED, _LIBS, Library, cache_dir, compiling_disabled,  # noqa: F401 (their old home)
                        exiting, pair_sincos, trig_for)
from .cancel import held

import casadi as ca
import numpy as np

CHUNK = 256  # poses per call on the uncompiled (virtual machine) paths
COMPILE_MIN_POSES = 50_000  # compile=None compiles for fewer poses only if already cached


class Backend:
    """Chooses between a compiled `Library` and casadi's virtual machine.

    compile=True: compile when first needed; False (or $KINCAS_NO_COMPILE): never; None:
    compile when a call has COMPILE_MIN_POSES poses or more, or in the background once
    `start()` is called (repeated use: the caller decides), the virtual machine serving
    meanwhile. Whatever the policy but False, a library that is already built is used: found
    in the cache when first asked for, or loaded since by this process (another `Backend`
    of the same code, such as a sweep with compile=True after default ones). `make_library()` builds the `Library` (code
    generation only) when first asked.

    >>> Backend(False, None, "nothing").compiled(10**6) is None
    True
    """

    def __init__(self, compile, make_library, what: str):
        self.compile, self.make_library, self.what = compile, make_library, what
        self.library: Library | None = None
        self.lib: ctypes.CDLL | None = None
        self.failed = False
        self._lock = threading.Lock()
        self._thread: threading.Thread | None = None  # a compile in the background

    def start(self) -> None:
        """With compile=None, compile and load the library in a background thread (the C
        compiler runs outside the GIL); `compiled` answers None (the virtual machine) until
        it is loaded, and `Library.load` never loads a half-written file. Code generation is
        done here, in the caller's thread; nothing happens if compiling is off, failed,
        done or under way. The thread is a daemon: a process ending meanwhile (or on Ctrl-C)
        does not wait for the compiler; at exit the compiler is killed and its temporary
        folder removed (kincas/core/c_library.py `_Compiles`), the library is never renamed
        into the cache unfinished, and the file lock goes with the process."""
        if self._thread is not None or self.lib is not None or self.failed or self.compile is not None \
                or compiling_disabled():
            return
        with self._lock:
            if self._thread is not None or self.lib is not None or self.failed:
                return
            try:
                if self.library is None:
                    self.library = self.make_library()
            except Exception as e:
                return self._failed(e)
            self._thread = threading.Thread(target=self._load, name=f"kincas compile {self.what}",
                                            daemon=True)
            self._thread.start()

    def _load(self) -> None:
        try:
            lib = self.library.load()
        except Exception as e:
            if not exiting():  # ended at the process's exit: nothing to report
                self._failed(e)
        else:
            self.lib = lib  # one assignment: other threads see None or the loaded library

    def _failed(self, e) -> None:
        self.failed = True
        warnings.warn(f"kincas: could not compile the {self.what} ({e}); using the slower "
                      f"uncompiled path", RuntimeWarning, stacklevel=4)

    def compiled(self, n: int) -> ctypes.CDLL | None:
        """The loaded library to use for n poses, or None for the virtual machine."""
        if self.lib is not None or self.failed or self.compile is False or compiling_disabled():
            return self.lib
        with held(self._lock):  # one thread builds; the others wait (hearing Ctrl-C), then use it
            if self.lib is not None or self.failed:
                return self.lib
            try:  # a failed build must never fail a user's solve
                if self.library is None:
                    self.library = self.make_library()
                # one rule: a library this process has loaded (whoever built it: a sweep
                # with compile=True, a background compile) or that was in the cache is used
                if (self.compile or self.library.cached or n >= COMPILE_MIN_POSES
                        or str(self.library.path) in _LIBS):
                    self.lib = self.library.load()
            except Exception as e:
                self._failed(e)
        return self.lib


# --- numpy arrays handed to C without copies ---


def ptr(a: np.ndarray, offset: int = 0) -> int:
    """The address of a float64 array's element `offset` (C order). (From the array
    interface: `a.ctypes.data` builds a ctypes object per call, about twice the time.)"""
    return a.__array_interface__["data"][0] + 8 * offset


def table(a, width: int) -> np.ndarray:
    """An (n, width) float64 table from a table, or from a flat array when width is 1.

    >>> table([1.0, 2.0], 1).shape, table(np.zeros((3, 0)), 0).shape
    ((2, 1), (3, 0))
    """
    a = np.asarray(a, dtype=float)
    return a if a.ndim == 2 and a.shape[1] == width else a.reshape(-1, width)


def rows(a, n: int, width: int) -> tuple[np.ndarray, int]:
    """(array, row stride in elements) of an (n, width) float64 table given as a table or
    as one row for every pose (stride 0): no copy unless the table is not C-contiguous.

    >>> rows([1.0, 2.0], 5, 2)[1], rows(np.zeros((5, 2)), 5, 2)[1]
    (0, 2)
    """
    a = np.asarray(a, dtype=float)
    if width == 0:
        return np.zeros(0), 0
    if a.ndim == 1 and a.shape[0] == width:
        return np.ascontiguousarray(a), 0
    a = np.broadcast_to(a.reshape(-1, width), (n, width))
    if a.strides[0] == 0:
        return np.ascontiguousarray(a[0] if n else np.zeros(width)), 0
    return np.ascontiguousarray(a), width


# --- the reported quantities at given poses ---

_QUANT_C = """
int kincas_quantities(casadi_int n, const casadi_real* Q, const casadi_real* U, casadi_int su,
                      const casadi_real* p, const casadi_real* Ud, casadi_int sud,
                      const casadi_real* Udd, casadi_int sudd, casadi_real* out, casadi_int ld) {
  const casadi_real* arg[SZ_ARG]; casadi_real* res[SZ_RES]; casadi_int iw[SZ_IW]; casadi_real w[SZ_W];
  casadi_real y[NO > 0 ? NO : 1];
  casadi_int k, i;
  for (k = 0; k < n; ++k) {
    arg[0] = Q + k*NQ; arg[1] = U + k*su; arg[2] = p; arg[3] = Ud + k*sud; arg[4] = Udd + k*sudd;
    res[0] = y;
    if (kQ(arg, res, iw, w, 0)) return (int) k;
    for (i = 0; i < NO; ++i) out[i*ld + k] = y[i];
  }
  return (int) n;
}
"""
_I, _V = ctypes.c_longlong, ctypes.c_void_p


class QuantityEvaluator:
    """Named quantities at N solved poses, only what they need built: a C loop over the
    compiled quantity function (cached like the sweep kernel), else casadi's `map` over
    chunks of CHUNK poses, bound to numpy buffers.

    >>> import numpy as np, kincas
    >>> m = kincas.Mechanism(ground={"A": (0, 0)}, links=[kincas.Link.bar("crank", "A", "B", 2)],
    ...     inputs=[kincas.Input.angle("crank")])
    >>> ev = QuantityEvaluator(kincas.model_of(m), ["B.y", "B.vx"], compile=False)
    >>> ev.evaluate(np.zeros((2, 0)), np.array([[0.0], [np.pi / 2]]), [], Ud=[3.0]).round(12)
    array([[ 0.,  2.],
           [-0., -6.]])
    """

    def __init__(self, model, names, *, compile=None):
        self.names, self.nq, self.nu = tuple(names), model.sym.nq, model.sym.nu
        f = model.quantity_function(self.names)
        ins = f.sx_in()
        self.f = ca.Function("kQ", ins, [ca.densify(f(*ins))], {"cse": True})
        self.no = self.f.size1_out(0)
        self._local, self._lock = threading.local(), threading.Lock()  # VM buffers per thread
        self.backend = Backend(compile, self._library, "quantity evaluator")

    def _library(self) -> Library:
        return Library("kincas_quantities", [self.f], _QUANT_C, {"NQ": self.nq, "NO": self.no},
                       {"kincas_quantities": [_I, _V, _V, _I, _V, _V, _I, _V, _I, _V, _I]}, trusted=True,
                       trig=trig_for(self.nq))

    def evaluate(self, Q, U, p, Ud=None, Udd=None, ok=None) -> np.ndarray:
        """(len(names), N) values at the poses (Q (N, nq), U (N, nu) tables; rates Ud and
        accelerations Udd tables or one row, default 1 and 0); NaN where `ok` is False."""
        U = table(U, self.nu)
        n = U.shape[0]
        Q = np.ascontiguousarray(np.broadcast_to(table(Q, self.nq), (n, self.nq)))
        U, su = rows(U, n, self.nu)
        Ud, sud = rows(np.ones(self.nu) if Ud is None else Ud, n, self.nu)
        Udd, sudd = rows(np.zeros(self.nu) if Udd is None else Udd, n, self.nu)
        p = np.ascontiguousarray(np.asarray(p, dtype=float).ravel())
        out = np.empty((self.no, n))
        lib = self.backend.compiled(n) if n and self.no else None
        if lib is not None:
            lib.kincas_quantities(n, ptr(Q), ptr(U), su, ptr(p), ptr(Ud), sud, ptr(Udd), sudd,
                                  ptr(out), n)
        elif n and self.no:
            self._vm_evaluate(Q, (U, su), p, (Ud, sud), (Udd, sudd), out)
        if ok is not None:
            out[:, ~np.asarray(ok, dtype=bool)] = np.nan
        return out

    def _vm_evaluate(self, Q, U, p, Ud, Udd, out):
        vm = getattr(self._local, "vm", None)
        if vm is None:
            with self._lock:
                if getattr(self, "_map", None) is None:  # p is the same for every pose
                    self._map = self.f.map("qmap", "serial", CHUNK, [2], [])
            buf, call = self._map.buffer()
            scratch = [np.zeros((CHUNK, m)) for m in (self.nq, self.nu, self.nu, self.nu, self.no)]
            buf.set_res(0, memoryview(scratch[-1]))
            vm = self._local.vm = (buf, call, scratch)  # buf holds raw pointers: keep it
        buf, call, (Qc, Uc, Udc, Uddc, Oc) = vm
        n = Q.shape[0]
        for k in range(0, n, CHUNK):
            m = min(CHUNK, n - k)
            for c, (a, st) in ((Qc, (Q, 1)), (Uc, U), (Udc, Ud), (Uddc, Udd)):
                c[:m], c[m:] = (a[k:k + m] if st else a), (a[k + m - 1] if st else a)  # pad
            for i, a in enumerate((Qc, Uc, p, Udc, Uddc)):
                buf.set_arg(i, memoryview(a))
            call()
            out[:, k:k + m] = Oc[:m].T
