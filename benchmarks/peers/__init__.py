"""The tools the benchmarks run, each behind one small interface, and what they return.

Every tool module defines
    NAME                      a label for the tables;
    available() -> str | None None when it imports, else the error (then it is reported, not dropped);
    supports(case) -> str | None  None when it can express the case, else why not;
    prepare(case) -> run      all setup (building, compiling); `run()` then solves every pose of
                              `case.theta` from the case's guess and returns a `Run`.
The harness times `prepare` plus a first `run()` as setup (compile, JIT, warm-up) and then
several further `run()` calls, each a whole sweep including the tool's Python overhead.

>>> r = Run({"B": np.zeros((2, 2))}, None, np.array([True, False]))
>>> r.n, r.has_velocity
(2, False)
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class Run:
    """A tool's answer for a sweep: positions (N, 2) of every compared point, velocities (N, 2)
    or None when the tool computes none, and which poses the tool says it solved."""

    P: dict
    V: dict | None
    ok: np.ndarray

    @property
    def n(self) -> int:
        return len(self.ok)

    @property
    def has_velocity(self) -> bool:
        return self.V is not None


def crank_velocity(case, theta):
    """Velocity of the crank's tip: omega x (tip - pivot), with the pivot fixed."""
    _, _, r = case.crank
    return case.omega * r * np.stack([-np.sin(theta), np.cos(theta)], axis=-1)


def module_available(name: str) -> str | None:
    """None when `import name` works, else the error as one line."""
    import importlib
    try:
        importlib.import_module(name)
        return None
    except Exception as e:  # any failure to import is reported as it is
        return f"{type(e).__name__}: {e}".splitlines()[0]
