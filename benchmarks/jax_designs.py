"""The JAX backend of `kincas.sweep_designs` against the compiled C path, per pose.

    python benchmarks/jax_designs.py [--designs 10000] [--poses 360] [--repeat 3]

The crank-rocker four-bar of the study example (a2 = 25, a3 = 62.25, a4, a5 varied over a
grid of Grashof designs: a4 in [84, 96], a5 in [62, 72]), swept over a full crank turn and
reporting C.x, C.y, the rocker's angle and angular velocity. Timed, each a median of
`--repeat` runs after a first call (compilation: the C library from its disk cache, JAX's jit)
timed apart:

* `casadi`: `sweep_designs(..., compile=True)` on every core (the compiled C loop over
  designs, its blocks on threads);
* `jax`: `sweep_designs(..., backend="jax")` (first poses and the poses JAX rejects on the
  CPU, as in the call users make), and the JAX pass alone (`JaxDesigns.run` on the same
  states).

JAX here runs on its CPU backend (no GPU on this machine). Both give the same values (the
largest difference is printed). Writes benchmarks/results_jax.md. Not a test.
"""
from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

import kincas  # noqa: E402
from kincas import Input, Link, Mechanism  # noqa: E402

REPORT = ["C.x", "C.y", "rocker.angle", "rocker.omega"]


def fourbar():
    return Mechanism(parameters={"a2": 25.0, "a3": 62.25, "a4": 90.0, "a5": 70.0},
                     ground={"A": (0, 0), "D": ("a5", 0)},
                     links=[Link.bar("crank", "A", "B", "a2"), Link.bar("coupler", "B", "C", "a3"),
                            Link.bar("rocker", "D", "C", "a4")],
                     inputs=[Input.angle("crank")], guess={"C": (40, 80)})


def timed(fn, repeat):
    """(result, first call's wall time, median wall time, (min, max), median CPU time of
    this process: on a shared machine the CPU time says what the work costs)."""
    t0 = time.perf_counter()
    out = fn()
    first = time.perf_counter() - t0
    times, cpu = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        fn()
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return out, first, statistics.median(times), (min(times), max(times)), statistics.median(cpu)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--designs", type=int, default=10_000)
    ap.add_argument("--poses", type=int, default=360)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args(argv)
    load = os.getloadavg()[0]
    import jax

    from kincas.core.jax_backend import jax_designs

    side = int(round(np.sqrt(a.designs)))
    a4, a5 = np.meshgrid(np.linspace(84, 96, side), np.linspace(62, 72, a.designs // side))
    params = {"a4": a4.ravel(), "a5": a5.ravel()}
    nd, n = len(params["a4"]), a.poses
    U = {"crank.angle": np.linspace(0, 2 * np.pi, n, endpoint=False)}
    m = fourbar()
    rows = []
    r_c, *t = timed(lambda: kincas.sweep_designs(m, params, U, report=REPORT, compile=True), a.repeat)
    rows.append(("casadi, compiled C loop, %d threads" % os.cpu_count(), *t))
    r_j, *t = timed(lambda: kincas.sweep_designs(m, params, U, report=REPORT, backend="jax"), a.repeat)
    rows.append(("jax (CPU backend), whole call", *t))

    # the JAX pass alone, from the states the call starts from
    from kincas.analysis import designs_jax
    states = {}
    real = designs_jax.jax_pass

    def keep(job, todo, thr):
        states.update(job=job, todo=todo, thr=thr)
        return real(job, todo, thr)
    designs_jax.jax_pass = keep
    kincas.sweep_designs(m, params, U, report=REPORT, backend="jax")
    designs_jax.jax_pass = real
    job, todo, thr = states["job"], states["todo"], states["thr"]
    jd = jax_designs(job.model, tuple(job.report))
    run = lambda: jd.run(job.S[todo], job.U, job.P[todo], job.Ls[todo], job.Ud, job.Udd, thr)
    (_, _, _, stops), *t = timed(run, a.repeat)
    rows.append(("jax (CPU backend), the JAX pass alone", *t))

    diff = max(float(np.nanmax(np.abs(r_c.values[q] - r_j.values[q]))) for q in REPORT)
    same = bool((r_c.code == r_j.code).all())
    lines = [f"# JAX backend of sweep_designs, measured on CPU ({time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())})",
             "", f"{nd:,} designs x {n} poses = {nd * n:,} poses of a four-bar; "
             f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores (shared), "
             f"jax {jax.__version__} on {jax.devices()[0].platform}; median of {a.repeat} after a first call.",
             f"Load average before the run: {load:.1f} (other jobs share the cores: the CPU "
             "time of this process is the steadier measure of the work).",
             "", "| path | first call (s) | median wall (s) | spread (s) | wall per pose (ns) | CPU per pose (ns) |",
             "|---|---|---|---|---|---|"]
    for name, first, med, (lo, hi), cpu in rows:
        lines.append(f"| {name} | {first:.2f} | {med:.2f} | {lo:.2f}-{hi:.2f} | {med / (nd * n) * 1e9:.0f} "
                     f"| {cpu / (nd * n) * 1e9:.0f} |")
    lines += ["", f"Designs the JAX pass swept whole: {(stops == n).sum():,} of {len(stops):,}; "
              f"same statuses as the C path: {same}; largest difference of a value: {diff:.2g}."]
    text = "\n".join(lines) + "\n"
    print(text)
    (HERE / "results_jax.md").write_text(text)


if __name__ == "__main__":
    main()
