"""The one kind of cache of kincas: a bounded, locked memo (`Memo`), and `clear_all()`.

Every cache of the package (the model of each structure, the redundant-joint decision of each
mechanism, the loaded compiled libraries, the lock of each model, the Functions each `Model`
derives) is a `Memo` owned by one module, which alone writes into it: through
`get_or_build(key, build)`, which runs `build()` at most once per key while the key is kept,
however many threads ask at once (the others wait for the first, hearing Ctrl-C, see
kincas/core/cancel.py). Reads and writes of the table take a short lock; a build runs outside
it, behind a gate: by default one gate per key (builds of different keys run side by side), or
one gate for every key (`gate=`, when builds must not overlap, e.g. CasADi building symbols of
one model). Gates are reentrant, so a build may ask its memo for other keys. Beyond `bound`
entries the oldest inserted goes first (first in, first out; a hit does not refresh it).

>>> m = Memo(bound=2)
>>> calls = []
>>> [m.get_or_build(k, lambda k=k: calls.append(k) or k * 10) for k in (1, 1, 2, 3)]
[10, 10, 20, 30]
>>> calls, 1 in m, len(m)
([1, 2, 3], False, 2)
"""
from __future__ import annotations

import threading
import weakref

from .cancel import held

_MISSING = object()
_NAMED: "dict[str, Memo]" = {}  # the module-level caches that clear_all() empties
_NAMED_LOCK = threading.Lock()


class Memo:
    """A table key -> value built once per key, safe from several threads and re-entrant.

    Parameters
    ----------
    name : str, optional
        Registers the memo under this name for `clear_all()` (module-level caches).
    bound : int, optional
        Most entries kept; the oldest inserted is dropped beyond it. None: no bound.
    weak : bool
        Keys held weakly (an entry goes with its key); no bound then.
    gate : lock, optional
        One reentrant lock that every build goes through (builds never overlap); by default
        each key has its own.

    Examples
    --------
    >>> m = Memo()
    >>> m.get_or_build("a", lambda: 1), m.get("a"), m.get("b", 0)
    (1, 1, 0)
    >>> m.clear(); "a" in m
    False
    """

    def __init__(self, name: str | None = None, bound: int | None = None, weak: bool = False,
                 gate=None):
        self.name, self.bound = name, bound
        self._d = weakref.WeakKeyDictionary() if weak else {}
        self._lock = threading.Lock()  # guards _d and _gates, held only for a look or a write
        self._gate = gate
        self._gates: dict = {}  # key -> the reentrant lock held by the thread building it
        if name is not None:
            with _NAMED_LOCK:
                _NAMED[name] = self

    def get(self, key, default=None):
        """The value kept for `key`, else `default` (builds nothing)."""
        with self._lock:
            return self._d.get(key, default)

    def peek(self, key, default=None):
        """`get` without taking the lock, for a look-up on a warm path: one dict look-up is
        one step under the GIL, and entries are only added or removed whole (under the
        lock), so a reader sees an entry or its absence, never half of one. Not for a weak
        memo (its look-up runs Python code)."""
        return self._d.get(key, default)

    def __contains__(self, key) -> bool:
        with self._lock:
            return key in self._d

    def __len__(self) -> int:
        with self._lock:
            return len(self._d)

    def clear(self) -> None:
        """Forget every entry (values already handed out stay valid)."""
        with self._lock:
            self._d.clear()

    def get_or_build(self, key, build):
        """The value kept for `key`; else `build()`, kept and returned. Threads asking for a
        key being built wait for it, so `build` runs once (again only if it raised)."""
        with self._lock:
            value = self._d.get(key, _MISSING)
            if value is not _MISSING:
                return value
            gate = self._gate or self._gates.setdefault(key, threading.RLock())
        with held(gate):
            with self._lock:  # built while this thread waited at the gate?
                value = self._d.get(key, _MISSING)
            try:
                if value is _MISSING:
                    value = build()
                    with self._lock:
                        self._d[key] = value
                        if self.bound is not None:
                            while len(self._d) > self.bound:
                                self._d.pop(next(iter(self._d)))
            finally:  # kept (or failed): the next caller needs no gate; those waiting hold it
                with self._lock:
                    if self._gates.get(key) is gate:
                        del self._gates[key]
        return value


def clear_all() -> None:
    """Empty every named module-level cache (models by structure, redundant-joint decisions,
    loaded libraries): the next use builds afresh, as in a new process (libraries compiled to
    disk stay there). For tests and benchmarks of first use.

    >>> clear_all()
    """
    with _NAMED_LOCK:
        memos = list(_NAMED.values())
    for memo in memos:
        memo.clear()
