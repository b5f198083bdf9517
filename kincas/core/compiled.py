"""CasADi functions looped over many poses in compiled C, the library cached on disk.

`Library` code-generates casadi functions together with a hand-written C loop that calls
them, compiles the whole with the C compiler ($CC, else gcc or cc) and keeps the result in
the cache directory under a hash of its source, the compiler and casadi's version: a second
process, or a second run, loads it without compiling. `Backend` decides when compiling is
worth it and falls back to casadi's virtual machine, with a warning, when it fails: a missing
compiler never fails a user's solve. `QuantityEvaluator` is the simplest such loop: reported
quantities at N given poses (`kincas.fast` builds the sweep itself the same way).

>>> import casadi as ca
>>> x = ca.SX.sym("x")
>>> lib = Library("kincas_doc", [ca.Function("twice", [x], [2 * x])], "", {}, {})
>>> lib.path.suffix, len(lib.path.stem) > 20
('.so', True)
"""
from __future__ import annotations

import ctypes
import hashlib
import os
import re
import shutil
import subprocess
import tempfile
import threading
import time
import warnings
from pathlib import Path

from .caches import Memo
from .cancel import WAIT, checkpoint, held

import casadi as ca
import numpy as np

CHUNK = 256  # poses per call on the uncompiled (virtual machine) paths
MAX_CACHED = 200  # libraries kept in the cache directory; the least recently used go first
COMPILE_MIN_POSES = 50_000  # compile=None compiles for fewer poses only if already cached
# -Bsymbolic: each library's own symbols bind inside it; -fno-semantic-interposition lets the
# compiler inline the casadi functions into the C loop (about 15 % of a sweep's time); errno is
# never read. Without fast-math: IEEE arithmetic, NaN tests intact. _PLAIN: a second try.
_FLAGS = ["-O3", "-fno-semantic-interposition", "-fno-math-errno", "-shared", "-fPIC", "-Wl,-Bsymbolic"]
_PLAIN = ["-O2", "-shared", "-fPIC"]
# loaded libraries by path (the path holds the hash); threads of this process load (and
# compile) one at a time
_LIBS = Memo("compiled libraries", gate=threading.RLock())

try:
    import fcntl
except ImportError:  # not on POSIX: compiles may race, but os.replace keeps each load whole
    fcntl = None


# --- building and caching ---


def cache_dir() -> Path:
    """Where compiled libraries are kept: $KINCAS_CACHE, else $XDG_CACHE_HOME/kincas, else
    ~/.cache/kincas.

    >>> cache_dir().name == "kincas" or "KINCAS_CACHE" in os.environ
    True
    """
    if os.environ.get("KINCAS_CACHE"):
        return Path(os.environ["KINCAS_CACHE"])
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "kincas"


def compiling_disabled() -> bool:
    """$KINCAS_NO_COMPILE set (to anything but 0): always use the virtual machine."""
    return os.environ.get("KINCAS_NO_COMPILE", "") not in ("", "0")


class Library:
    """Casadi functions code-generated with a C driver, compiled once, cached on disk.

    `defines` become C macros ahead of the driver (SZ_ARG, SZ_RES, SZ_IW, SZ_W, the largest
    work sizes of the functions, are added); `signatures` gives the ctypes argument types of
    the driver's entry points (each returns an int). `cached` says whether it was found
    built; `times` the seconds spent generating, compiling and loading. `load()` raises on
    any failure.
    """

    def __init__(self, tag: str, functions: list[ca.Function], driver: str, defines: dict,
                 signatures: dict[str, list]):
        t0 = time.perf_counter()
        cg = ca.CodeGenerator(f"{tag}.c", {"with_header": False})
        for f in functions:
            cg.add(f)
        work = {"SZ_ARG": [f.sz_arg() for f in functions], "SZ_RES": [f.sz_res() for f in functions],
                "SZ_IW": [f.sz_iw() for f in functions], "SZ_W": [f.sz_w() for f in functions]}
        defines = {**{k: max([1, *v]) for k, v in work.items()}, **defines}
        self.source = (_PRELUDE + pair_sincos(cg.dump())
                       + "".join(f"#define {k} {v}\n" for k, v in defines.items()) + driver)
        self.cc = os.environ.get("CC") or shutil.which("gcc") or shutil.which("cc")
        key = hashlib.sha256("\n".join([self.source, str(self.cc), *_FLAGS, ca.__version__]).encode())
        self.path = cache_dir() / f"{tag}-{key.hexdigest()[:24]}.so"
        self.cached = str(self.path) in _LIBS or self.path.exists()
        self.signatures = signatures
        self.times = {"generate": time.perf_counter() - t0, "compile": 0.0, "load": 0.0}

    def load(self) -> ctypes.CDLL:
        """The loaded library, compiled first if it is not in the cache.

        Safe from several threads and processes at once: threads of a process take a lock,
        processes an exclusive `flock` on a lock file beside the library, and whoever gets it
        second finds the library built. A library is written under a temporary name and
        renamed into place, so nobody ever loads a half-written one."""
        return _LIBS.get_or_build(str(self.path), self._build)  # waiting, Ctrl-C is heard

    def _build(self) -> ctypes.CDLL:
        if not self.path.exists():
            self.path.parent.mkdir(parents=True, exist_ok=True)
            with _file_lock(self.path.with_suffix(".lock")):
                if not self.path.exists():  # another process may have built it meanwhile
                    self._compile()
                    _prune(self.path.parent)
        else:
            os.utime(self.path)  # recently used: pruned last
        t0 = time.perf_counter()
        lib = ctypes.CDLL(str(self.path))
        for name, args in self.signatures.items():
            getattr(lib, name).argtypes, getattr(lib, name).restype = args, ctypes.c_int
        self.times["load"] = time.perf_counter() - t0
        return lib

    def _compile(self):
        if self.cc is None:
            raise RuntimeError("no C compiler found (set CC)")
        t0 = time.perf_counter()
        self.path.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory(dir=self.path.parent) as tmp:
            src, out = Path(tmp) / "k.c", Path(tmp) / "k.so"
            src.write_text(self.source)
            for flags in (_FLAGS, _PLAIN):  # a compiler that lacks a flag still gets a try
                code, err = _run([self.cc, *flags, str(src), "-o", str(out), "-lm"], timeout=600)
                if code == 0:
                    break
            if code != 0:
                raise RuntimeError(f"{self.cc} failed: {err.strip()[-400:]}")
            os.replace(out, self.path)  # atomic: other processes see all of it or nothing
        self.times["compile"] = time.perf_counter() - t0


def _run(cmd, timeout: float) -> tuple[int, str]:
    """(exit status, standard error) of `cmd`; killed on Ctrl-C, even from a worker thread
    (kincas/core/cancel.py: a compile can take seconds, the exit must not wait for it)."""
    group = os.name == "posix"  # the compiler's own children (cc1, as) go with it
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=group)
    end = time.monotonic() + timeout
    try:
        while True:
            try:
                _, err = proc.communicate(timeout=WAIT)
                return proc.returncode, err
            except subprocess.TimeoutExpired:
                checkpoint()
                if time.monotonic() > end:
                    raise
    except BaseException:
        try:
            os.killpg(proc.pid, 9) if group else proc.kill()
        except OSError:
            pass
        proc.communicate()
        raise


class _file_lock:
    """An exclusive lock on a file, held between processes (a no-op without fcntl)."""

    def __init__(self, path: Path):
        self.path = path

    def __enter__(self):
        self.fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            while fcntl is not None:  # another process compiles: wait, hearing Ctrl-C
                try:
                    fcntl.flock(self.fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                    break
                except BlockingIOError:
                    checkpoint()
                    time.sleep(WAIT / 2)
        except BaseException:
            os.close(self.fd)
            raise
        return self

    def __exit__(self, *exc):
        if fcntl is not None:
            fcntl.flock(self.fd, fcntl.LOCK_UN)
        os.close(self.fd)


# --- sine and cosine of an angle in one call ---

_PRELUDE = """#define _GNU_SOURCE
#include <math.h>
#ifdef __GLIBC__
#define kincas_sincos(x, s, c) sincos(x, s, c)
#else
#define kincas_sincos(x, s, c) (*(s) = sin(x), *(c) = cos(x))
#endif
"""
_TRIG = re.compile(r"^(\s*)(a\w+)=(sin|cos)\((a\w+)\);$")


def pair_sincos(source: str) -> str:
    r"""Casadi's generated `x=sin(a); ... y=cos(a);` as one sincos call (glibc's, which gives
    the same values): each angle's sine and cosine cost one call. Most of a sweep's time is
    this trigonometry, and once the casadi functions are inlined into the C loop the
    compiler stops pairing them itself. A pair is joined only within one block and while
    `a` is not reassigned between; anything else is left as it is.

    >>> print(pair_sincos("  a1=sin(a0);\n  a2=(a1*a0);\n  a3=cos(a0);"))
      casadi_real kt0; kincas_sincos(a0, &a1, &kt0);
      a2=(a1*a0);
      a3=kt0;
    """
    lines, n = source.split("\n"), 0
    for i, line in enumerate(lines):
        m = _TRIG.match(line)
        if not m or m[2] == m[4]:  # x=sin(x): the angle is overwritten here
            continue
        indent, target, f, a = m.groups()
        for j in range(i + 1, len(lines)):
            mj = _TRIG.match(lines[j])
            if mj and mj[4] == a and mj[3] != f:
                s, c = (target, f"kt{n}") if f == "sin" else (f"kt{n}", target)
                lines[i] = f"{indent}casadi_real kt{n}; kincas_sincos({a}, &{s}, &{c});"
                lines[j] = f"{mj[1]}{mj[2]}=kt{n};"
                n += 1
                break
            if "{" in lines[j] or "}" in lines[j] or re.match(rf"^\s*{a}=", lines[j]):
                break
    return "\n".join(lines)


def _prune(folder: Path) -> None:
    """Remove the least recently used libraries beyond MAX_CACHED (a loaded one may go: its
    file stays open until the process ends)."""
    try:
        libs = sorted(folder.glob("kincas_*.so"), key=lambda f: f.stat().st_mtime)
        for f in libs[:max(0, len(libs) - MAX_CACHED)]:
            f.unlink(missing_ok=True)
            f.with_suffix(".lock").unlink(missing_ok=True)
    except OSError:  # another process pruned first: nothing lost
        pass


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
        done or under way. The thread is not a daemon: a process ending meanwhile waits for
        the compiler, and the next process finds the library cached."""
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
            self._thread = threading.Thread(target=self._load, name=f"kincas compile {self.what}")
            self._thread.start()

    def _load(self) -> None:
        try:
            lib = self.library.load()
        except Exception as e:
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
                       {"kincas_quantities": [_I, _V, _V, _I, _V, _V, _I, _V, _I, _V, _I]})

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
