"""Many designs at once (issue [13]): a study on 1 and 2 workers, tolerance Monte Carlo.

    python benchmarks/bench_designs.py [--quick]

Measures, in one run so that the ratios compare like with like on a shared machine:
1. `kincas.study` of the contract's example (examples/study_fourbar.toml: a 41 x 41 grid of a
   four-bar over 360 crank angles, 605,160 poses) on 1 and on 2 worker threads, repeats
   interleaved; wall time and CPU time (all threads of the process) of each, so that the
   speed-up can be told apart from the machine being busy: CPU / wall is how many cores the
   run actually got. Beside it, the same study's cost per pose against `kincas.sweep` of one
   design of 360 poses per pose (issue [8]'s single sweep);
2. tolerance Monte Carlo (`kincas.analysis.tolerance.analyse`, the `kincas tolerance` path)
   of the same four-bar: 100,000 samples x 360 poses, std 0.05 mm on its four lengths, on
   every core and on one.
The load average is printed with each part (other processes share the machine). Target
(issue [13]): 2 workers at least 1.6x faster than 1; the Monte Carlo under 10 s.
Writes benchmarks/results_designs.md. Not a test: nothing here asserts.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))

import kincas  # noqa: E402
from kincas.analysis.tolerance import analyse  # noqa: E402
from kincas.cli.scene import load  # noqa: E402

SCENE = ROOT / "examples" / "study_fourbar.toml"
STD = {"a2": 0.05, "a3": 0.05, "a4": 0.05, "a5": 0.05}  # mm


def timed(f):
    """(wall seconds, CPU seconds of every thread of this process, result)."""
    w, c = time.perf_counter(), time.process_time()
    out = f()
    return time.perf_counter() - w, time.process_time() - c, out


def load_avg() -> str:
    try:
        return "load average %.1f %.1f %.1f" % os.getloadavg()
    except OSError:
        return "load average unknown"


def control(k: int, total: int = 16):
    """A fixed amount of GIL-free work (numpy's sine over a million numbers, `total` times)
    split over k threads: what the machine gives a perfectly parallel program right now."""
    import threading

    x = np.linspace(0.0, 1.0, 1_000_000)

    def work(m):
        y = np.empty_like(x)
        for _ in range(m):
            np.sin(x, out=y)
    ts = [threading.Thread(target=work, args=(total // k,)) for _ in range(k)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()


def gil_free_share(run) -> float:
    """The share of run()'s wall time spent in the compiled designs loop (a ctypes call: the
    GIL released). Both parts slow alike when the machine is busy, so the share holds."""
    from kincas.core import designs_kernel as dk

    full, spent = dk.DesignsLoop.full, [0.0]

    def timed_full(self, *a):
        t = time.perf_counter()
        try:
            return full(self, *a)
        finally:
            spent[0] += time.perf_counter() - t
    dk.DesignsLoop.full = timed_full
    try:
        wall = timed(run)[0]
    finally:
        dk.DesignsLoop.full = full
    return spent[0] / wall


def study_part(repeats: int, lines: list[str]):
    sc = load(SCENE)
    m, raw = sc.mechanism, sc.study.raw["study"]
    vary = {k: tuple(v) for k, v in raw["vary"].items()}
    inputs = sc.study.inputs
    n_pose = len(next(iter(inputs.values())))
    run = lambda w: kincas.study(m, vary, inputs, raw["report"], grid=raw["grid"], degrees=True,
                                 workers=w, compile=True)
    t_first, _, r = timed(lambda: run(1))  # compiles (or loads) the designs loop
    nd = len(r.status)
    times = {1: [], 2: [], "c1": [], "c2": []}
    before = load_avg()
    for _ in range(repeats):
        for w in (1, 2):
            wall, cpu, _ = timed(lambda: run(w))
            times[w].append((wall, cpu))
            wall, cpu, _ = timed(lambda: control(w))
            times[f"c{w}"].append((wall, cpu))
    f = float(np.median([gil_free_share(lambda: run(1)) for _ in range(3)]))
    amdahl = 1 / ((1 - f) + f / 2)
    sweep = lambda: kincas.sweep(m, inputs, report=["rocker.angle", "C.y"])
    sweep()
    t_sweep = np.median([timed(sweep)[0] for _ in range(max(5, repeats))])
    med = {w: np.median(np.array(v), axis=0) for w, v in times.items()}
    ratio, ratio_c = med[1][0] / med[2][0], med["c1"][0] / med["c2"][0]
    lines += ["\n## Study: 1 worker against 2",
              f"`kincas study` of {SCENE.name}: {nd} designs x {n_pose} poses = {nd * n_pose:,} poses "
              f"({sum(s == 'ok' for s in r.status)} assemble at every pose), {repeats} interleaved "
              f"repeats, medians. First call (compiling or loading the loop): {t_first:.2f} s. "
              f"{before} before, {load_avg()} after.\n",
              "| workers | wall s | CPU s | CPU / wall | us per pose (wall) |", "|---|---|---|---|---|"]
    for w in (1, 2):
        wall, cpu = med[w]
        lines.append(f"| {w} | {wall:.3f} | {cpu:.3f} | {cpu / wall:.2f} | {wall / (nd * n_pose) * 1e6:.3f} |")
    lines += ["\nControl, interleaved with it: a fixed amount of GIL-free numpy work (sine of a "
              "million numbers, 16 times) on 1 and 2 threads.\n",
              "| threads | wall s | CPU s | CPU / wall |", "|---|---|---|---|"]
    for w in (1, 2):
        wall, cpu = med[f"c{w}"]
        lines.append(f"| {w} | {wall:.3f} | {cpu:.3f} | {cpu / wall:.2f} |")
    lines += [f"\n2 workers against 1: **{ratio:.2f}x** faster (target 1.6x), while the control "
              f"got {ratio_c:.2f}x from a second thread in the same minutes: the study reached "
              f"{ratio / ratio_c:.0%} of what the machine gave a perfectly parallel program. On one worker "
              f"{f:.0%} of the wall time is spent in the compiled loop without the GIL: on two free "
              f"cores that predicts {amdahl:.2f}x (Amdahl). Linux here groups the CPU by session "
              f"(sched_autogroup_enabled = {_autogroup()}): while other sessions keep the cores "
              f"busy, a process gets its session's share whatever its number of threads, and the "
              f"measured ratio stays near 1 (CPU / wall of the 2-worker run shows it).",
              f"Per pose, the study "
              f"on one worker costs {med[1][0] / (nd * n_pose) * 1e6:.3f} us against "
              f"{t_sweep / n_pose * 1e6:.3f} us for `kincas.sweep` of one design ({n_pose} poses)."]
    print(f"study: 1 worker {med[1][0]:.3f} s (CPU {med[1][1]:.3f}), 2 workers {med[2][0]:.3f} s "
          f"(CPU {med[2][1]:.3f}): {ratio:.2f}x (control {ratio_c:.2f}x); GIL-free share {f:.0%} (Amdahl on 2 cores "
          f"{amdahl:.2f}x); {load_avg()}")
    return ratio


def tolerance_part(samples: int, one_worker_samples: int, lines: list[str]):
    sc = load(SCENE)
    m, inputs = sc.mechanism, sc.study.inputs
    n_pose = len(next(iter(inputs.values())))
    report = ["C.x", "C.y", "rocker.angle"]
    analyse(m, inputs, STD, report, draws=200)  # compiled loop loaded
    lines += ["\n## Tolerance Monte Carlo",
              f"`analyse` (the `kincas tolerance` path) of {SCENE.name}, std 0.05 mm on a2..a5, "
              f"report {report}, {n_pose} poses.\n",
              "| samples | workers | wall s | CPU s | CPU / wall | failed samples | load before |",
              "|---|---|---|---|---|---|---|"]
    out = {}
    for n, w in ((samples, None), (one_worker_samples, 1)):
        before = load_avg().split()[-3]
        wall, cpu, r = timed(lambda: analyse(m, inputs, STD, report, draws=n, workers=w))
        out[w] = wall
        if w == 1:
            out["cpu"] = cpu * samples / n  # scaled to `samples` when fewer were run
        lines.append(f"| {n:,} | {w or os.cpu_count()} | {wall:.2f} | {cpu:.2f} | {cpu / wall:.2f} | "
                     f"{int(r.failed.max())} | {before} |")
        print(f"tolerance: {n:,} samples x {n_pose} poses on {w or 'all'} workers: {wall:.2f} s "
              f"(CPU {cpu:.2f} s); {load_avg()}")
    f = gil_free_share(lambda: analyse(m, inputs, STD, report, draws=20_000, workers=1))
    cpu1 = out["cpu"]
    lines.append(f"\n{samples:,} samples x {n_pose} poses in **{out[None]:.2f} s** (target: under 10 s), "
                 f"{cpu1:.1f} s of CPU time on one worker. There {f:.0%} of the wall time is spent in "
                 f"the compiled loop without the GIL (20,000 samples): on two free cores that "
                 f"predicts about {cpu1 * ((1 - f) + f / 2):.1f} s (Amdahl).")
    print(f"tolerance: GIL-free share {f:.0%}: on two free cores about {cpu1 * ((1 - f) + f / 2):.1f} s")


def _autogroup() -> str:
    try:
        return Path("/proc/sys/kernel/sched_autogroup_enabled").read_text().strip()
    except OSError:
        return "unknown"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats, Monte Carlo on one worker smaller")
    args = ap.parse_args(argv)
    repeats, one = (3, 20_000) if args.quick else (7, 100_000)
    lines = ["# Many designs at once (benchmarks/bench_designs.py)\n",
             f"Run {time.strftime('%Y-%m-%d %H:%M')}{' (--quick)' if args.quick else ''} on a shared "
             f"{os.cpu_count()}-core machine: compare ratios from this run; CPU / wall says how many "
             f"cores a run got (under 2 on two workers: the machine was busy or the work waited)."]
    study_part(repeats, lines)
    tolerance_part(100_000, one, lines)
    (HERE / "results_designs.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    print(f"wrote {HERE / 'results_designs.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
