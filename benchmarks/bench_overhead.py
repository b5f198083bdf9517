"""Warm per-call cost of `kincas.sweep` beside pylinkage's numba loop and the numpy closed form,
measured in one process, interleaved (so the machine's load hits all three alike).

    python benchmarks/bench_overhead.py [--repeats 40] [--poses 360,3600]

Each tool solves the same case (positions and velocities of the compared points) once as
warm-up (compiles, JIT), then `repeats` times in turn; the table gives the median us per pose
and kincas's time over each peer's. Prints only: benchmarks/run.py writes RESULTS.md.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]

import cases  # noqa: E402
from peers import closed_form, kincas_runs, pylinkage_peer  # noqa: E402

CASES = {"fourbar": cases.fourbar, "jansen": cases.jansen,
         "chain10": lambda n: cases.chain(10, n), "chain40": lambda n: cases.chain(40, n)}


def tools(case):
    out = {"kincas": kincas_runs.prepare_method(case, "sweep (default)")}
    if pylinkage_peer.available() is None and pylinkage_peer.supports(case) is None:
        out["pylinkage"] = pylinkage_peer.prepare(case)
    out["closed form"] = closed_form.prepare(case)
    return out


def measure(case, repeats):
    runs = tools(case)
    for f in runs.values():  # warm-up: compiles, JIT, caches
        f()
        f()
    times = {k: [] for k in runs}
    for _ in range(repeats):
        for k, f in runs.items():
            t0 = time.perf_counter()
            f()
            times[k].append(time.perf_counter() - t0)
    n = len(case.theta)
    return {k: 1e6 * statistics.median(v) / n for k, v in times.items()}


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=40)
    ap.add_argument("--poses", default="360,3600")
    ap.add_argument("--cases", default=",".join(CASES))
    a = ap.parse_args(argv)
    print(f"{'case':10} {'poses':>7} {'kincas us/pose':>15} {'pylinkage':>10} {'closed':>8} {'x pyl':>6} {'x closed':>8}")
    for name in a.cases.split(","):
        for n in map(int, a.poses.split(",")):
            case = CASES[name](n)
            if len(case.theta) != n:
                case = case.with_theta(cases.sweep_angles(n))
            t = measure(case, a.repeats if n <= 4000 else max(3, a.repeats // 10))
            k, pl, cf = t["kincas"], t.get("pylinkage", float("nan")), t["closed form"]
            print(f"{name:10} {n:7d} {k:15.3f} {pl:10.3f} {cf:8.3f} {k / pl:6.2f} {k / cf:8.2f}", flush=True)


if __name__ == "__main__":
    main()
