"""Compiled libraries built and cached on disk: casadi functions code-generated with a C loop.

`Library` code-generates casadi functions together with a hand-written C driver that calls
them, pairs each angle's sine and cosine into one call (`pair_sincos`), keeps max and min
inline (`inline_minmax`), drops null-pointer tests that its driver makes needless
(`trust_pointers`; these rewrites: kincas/core/c_source.py), compiles the whole
with the C compiler ($CC, else gcc or cc) and keeps the result in the cache directory
(`cache_dir`) under a hash of its source, the compiler, its flags and casadi's version: a
second process, or a second run, loads it without compiling. The cache keeps the MAX_CACHED
most recently used libraries. When to compile is `kincas.core.compiled.Backend`'s choice.

>>> pair_sincos("  a1=sin(a0);").strip()
'a1=kincas_sin(a0);'
"""
from __future__ import annotations

import atexit
import contextlib
import ctypes
import hashlib
import os
import re
import shutil
import subprocess
import tempfile
import threading
import time
from pathlib import Path

from .c_source import _PRELUDE, inline_minmax, pair_sincos, trust_pointers  # noqa: F401 (pair_sincos, inline_minmax: their old home)
from .caches import Memo
from .cancel import WAIT, checkpoint

import casadi as ca

MAX_CACHED = 200  # libraries kept in the cache directory; the least recently used go first
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


# the line each choice of `Library`'s trig puts before the prelude (c_source.py SINCOS_C)
TRIG = {"inline": "", "call": "#define KINCAS_TRIG_CALL 1\n", "libm": "#define KINCAS_LIBM_TRIG 1\n"}
# From this many unknowns on, a kernel's library has fdlibm's sines and cosines inline
# (kincas/core/c_source.py SINCOS_C: 40 chained four-bars 25.0k -> 22.4k instructions a pose);
# below, as one function each use calls: inline, they double gcc's time on Jansen's leg (0.45
# -> 0.8 s of CPU) while a small mechanism's first sweeps wait in the virtual machine for its
# library (issue [15]: 1,000 first calls of Jansen's leg 0.73x -> 1.33x pylinkage's time);
# called, they compile as fast as libm's and keep most of the speed (four-bar, 360-pose
# compiled pass: libm's 69 us, fdlibm's called 60, inline 62).
INLINE_TRIG_UNKNOWNS = 16


def trig_for(unknowns: int) -> str:
    """`Library`'s trig for the library of a kernel of this many unknowns: "inline" from
    INLINE_TRIG_UNKNOWNS on, else "call" (one rule for the sweep, designs and quantity loops).

    >>> trig_for(2), trig_for(80)
    ('call', 'inline')
    """
    return "call" if unknowns < INLINE_TRIG_UNKNOWNS else "inline"


def libm_trig() -> bool:
    """$KINCAS_LIBM_TRIG set (to anything but 0): compiled code takes sin and cos from libm,
    as the virtual machine does (else fdlibm's: kincas/core/c_source.py SINCOS_C),
    so that both give the same numbers bit for bit."""
    return os.environ.get("KINCAS_LIBM_TRIG", "") not in ("", "0")


def compiling_disabled() -> bool:
    """$KINCAS_NO_COMPILE set (to anything but 0): always use the virtual machine."""
    return os.environ.get("KINCAS_NO_COMPILE", "") not in ("", "0")


class Library:
    """Casadi functions code-generated with a C driver, compiled once, cached on disk.

    `defines` become C macros ahead of the driver (SZ_ARG, SZ_RES, SZ_IW, SZ_W, the largest
    work sizes of the functions, are added); `signatures` gives the ctypes argument types of
    the driver's entry points (each returns an int). `trusted`: the driver passes a pointer
    for every input and output (with entries) of every function it calls, so the functions
    are compiled without casadi's null-pointer tests where no call of theirs needs them
    (kincas/core/c_source.py `trust_pointers`). `trig`: how sines and cosines are computed
    (c_source.py SINCOS_C): "inline", fdlibm's algorithm at every use; "call", the same
    algorithm as one function that each use calls (compiles as fast as libm's calls, most of
    the inline speed); "libm", libm's calls, as the virtual machine (also wherever
    $KINCAS_LIBM_TRIG is set). `cached` says whether it was found built; `times` the seconds
    spent generating, compiling and loading. `load()` raises on any failure.
    """

    def __init__(self, tag: str, functions: list[ca.Function], driver: str, defines: dict,
                 signatures: dict[str, list], trusted: bool = False, trig: str = "inline"):
        t0 = time.perf_counter()
        cg = ca.CodeGenerator(f"{tag}.c", {"with_header": False})
        for f in functions:
            cg.add(f)
        work = {"SZ_ARG": [f.sz_arg() for f in functions], "SZ_RES": [f.sz_res() for f in functions],
                "SZ_IW": [f.sz_iw() for f in functions], "SZ_W": [f.sz_w() for f in functions]}
        defines = {**{k: max([1, *v]) for k, v in work.items()}, **defines}
        code = inline_minmax(pair_sincos(cg.dump()))
        if trig not in TRIG:
            raise ValueError(f"trig: {trig!r} is not one of {', '.join(TRIG)}")
        trig = "libm" if libm_trig() else trig
        self.source = (TRIG[trig] + _PRELUDE
                       + (trust_pointers(code) if trusted else code)
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
        with _Compiles.folder(self.path.parent) as tmp:
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


class _Compiles:
    """The compilers running in this process and their temporary folders, ended at exit.

    A background compile runs on a daemon thread, so the interpreter never waits for it; at
    exit (normal, or after Ctrl-C) `end_all` kills every compiler still running (with its
    process group: cc1, as) and removes their folders, and no compiler starts after it. The
    library is only ever renamed into place whole, so the cache never holds part of one."""

    lock = threading.Lock()
    running: dict = {}  # pid -> Popen
    folders: set = set()
    exiting = False

    @classmethod
    @contextlib.contextmanager
    def folder(cls, parent: Path):
        with cls.lock:
            if cls.exiting:
                raise RuntimeError("the process is exiting")
            tmp = tempfile.mkdtemp(dir=parent)
            cls.folders.add(tmp)
        try:
            yield tmp
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
            with cls.lock:
                cls.folders.discard(tmp)

    @classmethod
    def start(cls, cmd, group: bool) -> subprocess.Popen:
        with cls.lock:
            if cls.exiting:
                raise RuntimeError("the process is exiting")
            proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                    start_new_session=group)
            cls.running[proc.pid] = proc
            return proc

    @classmethod
    def end_all(cls) -> None:
        with cls.lock:
            cls.exiting = True
            procs, folders = list(cls.running.values()), list(cls.folders)
        for proc in procs:
            _kill(proc)
        for tmp in folders:
            shutil.rmtree(tmp, ignore_errors=True)


atexit.register(_Compiles.end_all)  # runs before daemon threads are frozen


def exiting() -> bool:
    """Whether this process is exiting (its compiles were ended: their failure is no news)."""
    return _Compiles.exiting


def _kill(proc) -> None:
    try:
        os.killpg(proc.pid, 9) if os.name == "posix" else proc.kill()
    except OSError:
        pass


def _run(cmd, timeout: float) -> tuple[int, str]:
    """(exit status, standard error) of `cmd`; killed on Ctrl-C, even from a worker thread
    (kincas/core/cancel.py: a compile can take seconds, the exit must not wait for it), and
    at the process's exit (`_Compiles`)."""
    group = os.name == "posix"  # the compiler's own children (cc1, as) go with it
    proc = _Compiles.start(cmd, group)
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
        _kill(proc)
        proc.communicate()
        raise
    finally:
        with _Compiles.lock:
            _Compiles.running.pop(proc.pid, None)


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
