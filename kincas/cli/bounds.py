"""Sizes a run can afford: a typo such as `steps = 1000000000` or `grid = [10000, 10000]` is
refused up front (before any array is made, within a second), naming the field, the memory
it would take and the way round, instead of taking the machine.

The estimates are the peak memory a command adds to the Python process that imported kincas
(its resident set, as `getrusage` measures it), fitted to measurements (tests/test_sizes.py
checks them within 2x at small sizes):

- `kincas solve`: per pose, its unknowns and every reported value kept as numpy and then as
  Python numbers for the table (about 18 bytes a value) or the JSON (about 90: the list of
  floats and its text at once);
- `kincas tolerance`: the drawn parameters (8 bytes each, three copies), and the chunks of
  2,048 samples in flight on each worker with their values at every pose; the samples are
  reduced chunk by chunk, so 100,000 samples x 360 poses take about 100 MB;
- `kincas study`: per design its parameters and results (~100 bytes), the chunks in flight,
  and what the allocator keeps of the chunks' pose arrays (about 4 bytes a design-pose, at
  most three times the chunks in flight);
- a scene file: about 5 kB per `name = value` entry (TOML's parser, the model).

The budget is a quarter of the memory the system says is available, at most 2 GB (a typo
must not take a shared machine), or `$KINCAS_MEMORY` (such as `16GB`).

>>> per_pose(nq=5, reports=5) < per_pose(nq=5, reports=5, json=True) < 2000
True
>>> check("[[inputs]] crank.angle: sweep.steps", 10, 1000)           # fine: nothing raised
>>> try:
...     check("[[inputs]] crank.angle: sweep.steps", 10 ** 9, 1000, budget=2 ** 33)
... except ValueError as e:
...     print(e)
[[inputs]] crank.angle: sweep.steps: 1000000000 would take about 1000 GB of memory, more than the 8.6 GB this run may use: use fewer, or set KINCAS_MEMORY=1250GB to allow it
"""
from __future__ import annotations

import contextlib
import contextvars
import math
import os

BASE = 10e6  # a command's fixed part beyond the imports: the model, its compiled kernel
CHUNK = 2048  # samples per chunk of `kincas tolerance` (kincas/analysis/tolerance.py)
STUDY_CHUNK = 2048  # most designs per chunk of `kincas study` on local threads
PER_ENTRY = 5000  # bytes per `name = value` of a scene: tomllib's tables, the model's names
_json = contextvars.ContextVar("kincas_json_output", default=False)


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


@contextlib.contextmanager
def json_output(on: bool):
    """Within: `per_pose` counts the JSON's cost of a value (`kincas solve --json`)."""
    token = _json.set(bool(on))
    try:
        yield
    finally:
        _json.reset(token)


def per_pose(nq: int, reports: int, inputs: int = 1, json: bool | None = None) -> int:
    """Bytes `kincas solve` keeps per pose: unknowns and work arrays (16 bytes per unknown)
    and each reported value and input, as numpy and on its way to text (18 bytes) or to JSON
    (90 bytes; default: as `json_output` says)."""
    json = _json.get() if json is None else json
    each = 90 if json else 18
    return (200 if json else 120) + 16 * nq + each * (reports + inputs)


def per_sample(nq: int, reports: int, varied: int, poses: int = 1) -> int:
    """Bytes per scattered start of `kincas modes`/`optimize --starts` (all kept at once):
    the start, the solve's Jacobian and work arrays."""
    return 8 * (poses * (nq + reports + 2) + 3 * nq * nq + 10 * nq + 2 * varied) + 100


def tolerance_bytes(samples: int, poses: int, nq: int, reports: int, varied: int,
                    workers: int = 2) -> float:
    """Peak bytes of `kincas tolerance`: the draws (three copies of samples x varied), the
    nominal sweep, and one chunk of samples x poses per busy worker (each output and unknown
    at every pose, and the good flags)."""
    chunk = min(samples, CHUNK)
    busy = min(workers, math.ceil(samples / CHUNK))
    return (BASE + samples * (24 * varied + 16) + poses * per_pose(nq, reports, json=False)
            + busy * chunk * poses * (8 * (reports + nq) + 8))


def study_bytes(designs: int, poses: int, nq: int, quantities: int, varied: int,
                reports: int, workers: int = 2) -> float:
    """Peak bytes of `kincas study`: per design its parameters (the grid and its meshgrid),
    index, status and report values, gathered and written (~48 + 16 per parameter and per
    report, twice); the chunks in flight (each quantity and unknown at every pose); what the
    allocator keeps of the chunks' arrays as they come and go (4 bytes a design-pose, measured,
    at most three times the chunks in flight)."""
    chunk = max(1, min(STUDY_CHUNK, math.ceil(designs / max(workers, 1))))
    flight = min(workers, math.ceil(designs / chunk)) * chunk * poses * 8 * (quantities + nq + 2)
    kept = min(4.0 * designs * poses, 3 * flight)
    return BASE + 2 * designs * (48 + 16 * varied + 16 * reports) + flight + kept


def scene_entries(text: str) -> int:
    """An upper bound of the `name = value` entries of a scene's text, counted before it is
    parsed (its "=" signs: a few in comments or expressions do not matter at this scale).

    >>> scene_entries('crank = { points = ["A", "B"], length = 2 }')
    3
    """
    return text.count("=")


def check(field: str, count: int, each: float, budget: float | None = None) -> None:
    """Raise ValueError naming `field` when `count` items of `each` bytes exceed the budget
    (default: a quarter of the available memory: the run's other arrays, and the machine's
    other users, need the rest)."""
    check_total(f"{field}: {count}", float(count) * each, "use fewer", budget)


def check_total(what: str, need: float, fix: str, budget: float | None = None) -> None:
    """Raise ValueError when `need` bytes exceed the budget: one line naming `what` and the
    figure, the budget, and the two ways round (`fix`, or KINCAS_MEMORY)."""
    budget = default_budget() if budget is None else budget
    if need > budget:
        raise ValueError(f"{what} would take about {_gb(need)} of memory, more than the "
                         f"{_gb(budget)} this run may use: {fix}, or set "
                         f"KINCAS_MEMORY={_gb(need * 1.25).replace(' ', '')} to allow it")


def _gb(n: float) -> str:
    g = n / 1e9
    if g < 0.1:
        return f"{max(n / 1e6, 1):.0f} MB"
    return f"{g:.2g} GB" if g < 10 else f"{g:.0f} GB"
