"""Measuring a tool on a case: time per pose (median and spread of several runs), errors
against the reference, and, for the stiff cases, what each pose turned out to be.

Errors are relative: positions to the case's size L, velocities to omega L, worst over the
compared points and the poses the tool says it solved (and that assemble). A pose is
*correct* when every compared point is within MATCH L of the reference; a *branch jump* when
instead it matches another assembly of the mechanism; *wrong* when it matches none; *missed*
when the mechanism assembles there but the tool says it did not solve it; *false* when the
tool claims a pose where the mechanism does not assemble.

>>> pareto([(1.0, 1e-3), (2.0, 1e-9), (3.0, 1e-6), (0.5, 1e-2)])
[3, 0, 1]
"""
from __future__ import annotations

import time
import traceback
from dataclasses import dataclass, field

import numpy as np

MATCH = 1e-6  # a pose matches an assembly when every compared point is this close (times L)


@dataclass
class Timing:
    """Setup (prepare + first run: compile, JIT, warm-up) and per-pose times of further runs."""

    setup: float = float("nan")
    per_pose: list = field(default_factory=list)
    run: object = None  # the last Run
    error: str | None = None

    @property
    def median(self) -> float:
        return float(np.median(self.per_pose)) if self.per_pose else float("nan")

    @property
    def spread(self) -> tuple[float, float]:
        return (min(self.per_pose), max(self.per_pose)) if self.per_pose else (float("nan"),) * 2


def time_tool(prepare, repeats: int, budget: float = 20.0) -> Timing:
    """Time `prepare()` + one run as setup, then up to `repeats` runs (at least 3 when they fit
    in `budget` seconds). Any exception is recorded as the tool's error, not raised."""
    t = Timing()
    try:
        t0 = time.perf_counter()
        run = prepare()
        t.run = run()
        t.setup = time.perf_counter() - t0
        n = t.run.n
        spent = 0.0
        for i in range(repeats):
            if i >= 3 and spent > budget:
                break
            t0 = time.perf_counter()
            t.run = run()
            dt = time.perf_counter() - t0
            spent += dt
            t.per_pose.append(dt / n)
    except Exception as e:  # a tool that breaks is reported with its error
        t.error = f"{type(e).__name__}: {e}".splitlines()[0][:200]
        t.trace = traceback.format_exc()
    return t


def errors(case, run, P, V, rows=slice(None)) -> tuple[float, float]:
    """(worst position error / L, worst velocity error / (omega L)) over the solved poses;
    NaN when there is nothing to compare (velocity: the tool computes none)."""
    L, om = case.size, abs(case.omega)
    ok = run.ok.copy()
    for p in case.outputs:
        ok &= np.isfinite(P[p][rows]).all(axis=1) & np.isfinite(run.P[p]).all(axis=1)
    if not ok.any():
        return float("nan"), float("nan")
    pe = max(np.abs(run.P[p][ok] - P[p][rows][ok]).max() for p in case.outputs) / L
    ve = float("nan")
    if run.V is not None:
        ve = max(np.abs(run.V[p][ok] - V[p][rows][ok]).max() for p in case.outputs) / (om * L)
    return float(pe), float(ve)


def distance(case, run, P) -> np.ndarray:
    """Per pose, the largest distance / L between the tool's and P's compared points."""
    d = np.zeros(run.n)
    for p in case.outputs:  # np.maximum, not fmax: a point that is NaN on either side is no match
        d = np.maximum(d, np.linalg.norm(run.P[p] - P[p], axis=1))
    return d / case.size


def classify(case, run, P, others: list) -> dict:
    """Counts of correct, jump, wrong, missed and false poses, and the worst error of the
    correct ones. `others` lists the positions of the mechanism's other assemblies."""
    assembles = np.all([np.isfinite(P[p]).all(axis=1) for p in case.outputs], axis=0)
    claimed = run.ok & np.all([np.isfinite(run.P[p]).all(axis=1) for p in case.outputs], axis=0)
    with np.errstate(invalid="ignore"):
        d_ref = np.where(assembles, distance(case, run, P), np.inf)
        d_oth = np.min([np.nan_to_num(distance(case, run, O), nan=np.inf) for O in others] or
                       [np.full(run.n, np.inf)], axis=0)
    correct = claimed & (d_ref <= MATCH)
    jump = claimed & ~correct & (d_oth <= MATCH)
    good = claimed & assembles
    return {"poses": run.n, "assemble": int(assembles.sum()), "claimed": int(claimed.sum()),
            "correct": int(correct.sum()), "jumps": int(jump.sum()),
            "wrong": int((good & ~correct & ~jump).sum()), "missed": int((assembles & ~claimed).sum()),
            "false": int((claimed & ~assembles).sum()),
            "worst": float(d_ref[correct].max()) if correct.any() else float("nan")}


def pareto(points) -> list[int]:
    """Indices of the points (time, error) that no other point beats in both, fastest first."""
    order = sorted(range(len(points)), key=lambda i: (points[i][0], points[i][1]))
    front, best = [], np.inf
    for i in order:
        if points[i][1] < best:
            front.append(i)
            best = points[i][1]
    return front
