"""Sizes a run can afford: a typo such as `steps = 1000000000` is refused up front, naming the
field and the memory it would take, instead of taking the machine.

The estimates count what a run keeps per item (a pose of a sweep, a Monte-Carlo sample, a
scattered start): its unknowns, their Jacobian and work arrays, the reported values as numpy
and as Python numbers for the printed table or JSON. They are measured orders of magnitude
(a Fairbairn guide pose, 5 unknowns and 5 reports, takes about 1 kB through `kincas solve`),
compared with the run's budget: a quarter of the memory the system says is available, at
most 2 GB (a typo must not take a shared machine), or `$KINCAS_MEMORY` (such as `16GB`).

>>> per_pose(nq=5, reports=5) < 2000
True
>>> check("[[inputs]] crank.angle: sweep.steps", 10, 1000)           # fine: nothing raised
>>> try:
...     check("[[inputs]] crank.angle: sweep.steps", 10 ** 9, 1000, budget=2 ** 33)
... except ValueError as e:
...     print(e)
[[inputs]] crank.angle: sweep.steps: 1000000000 would take about 1000 GB of memory, more than the 8.6 GB this run may use (set KINCAS_MEMORY to allow more); use fewer
"""
from __future__ import annotations

import os


def available_bytes() -> float:
    """Memory the system reports as available (MemAvailable), else its physical memory."""
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024
    except OSError:
        pass
    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return 8.0 * 2 ** 30


def default_budget() -> float:
    """Bytes a run may take: $KINCAS_MEMORY (`16GB`, `500MB`, or bytes), else a quarter of
    the available memory, at most 2 GB."""
    text = os.environ.get("KINCAS_MEMORY", "").strip().upper().replace(" ", "")
    for suffix, k in (("GB", 1e9), ("MB", 1e6), ("G", 1e9), ("M", 1e6), ("", 1.0)):
        if text.endswith(suffix):
            try:
                return float(text[:len(text) - len(suffix)] if suffix else text) * k
            except ValueError:
                break
    return min(available_bytes() / 4, 2e9)


def per_pose(nq: int, reports: int, inputs: int = 1) -> int:
    """Bytes a sweep keeps per pose: unknowns, Jacobian and work arrays (8 bytes each), and
    every reported value and input also as a Python float on its way to text."""
    return 8 * (nq * nq + 6 * nq + 4 * (reports + inputs)) + 100 * (reports + inputs) + 200


def per_sample(nq: int, reports: int, varied: int, poses: int = 1) -> int:
    """Bytes per Monte-Carlo sample (or per scattered start): its parameter draw, and at each
    pose its unknowns, residual, determinant and reported values (kept for every pose), with
    the Jacobian and work arrays of the solve."""
    return 8 * (poses * (nq + reports + 2) + 3 * nq * nq + 10 * nq + 2 * varied) + 100


def check(field: str, count: int, each: int, budget: float | None = None) -> None:
    """Raise ValueError naming `field` when `count` items of `each` bytes exceed the budget
    (default: a quarter of the available memory: the run's other arrays, and the machine's
    other users, need the rest)."""
    budget = default_budget() if budget is None else budget
    need = float(count) * each
    if need > budget:
        raise ValueError(f"{field}: {count} would take about {_gb(need)} of memory, more than "
                         f"the {_gb(budget)} this run may use (set KINCAS_MEMORY to allow more); use fewer")


def _gb(n: float) -> str:
    g = n / 1e9
    return f"{g:.2g} GB" if g < 10 else f"{g:.0f} GB"
