"""Warm per-call cost of `kincas.sweep` beside pylinkage's numba loop and the numpy closed form,
measured in one process, interleaved (so the machine's load hits all three alike).

    python benchmarks/bench_overhead.py [--repeats 40] [--poses 360,3600] [--wall]
    python benchmarks/bench_overhead.py --against /work/main   # another checkout's kincas beside
    python benchmarks/bench_overhead.py --first-use 1,100,1000  # fresh processes, empty cache

Each tool solves the same case (positions and velocities of the compared points) once as
warm-up (compiles, JIT), then `repeats` times in turn; the table gives the median us per pose
and kincas's time over each peer's. Times are the process's CPU time (`time.process_time`):
on a shared machine the wall clock also counts other processes' turns; `--wall` for it.
`--first-use` instead runs each tool in a fresh process, kincas's cache of compiled libraries
empty (numba's, which holds pylinkage's compiled loop, as it is), and gives the wall time from the tool's setup to the end of the 1st,
100th, ... call of a 360-pose sweep, compiles and JIT included (kincas compiles its kernel
in a background thread from its second sweep on, the virtual machine serving meanwhile). Prints only: benchmarks/run.py writes RESULTS.md.
"""
from __future__ import annotations

import argparse
import contextlib
import importlib
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]

import cases  # noqa: E402
from peers import closed_form, kincas_runs, pylinkage_peer  # noqa: E402
from peers.measure import errors  # noqa: E402

CASES = {"fourbar": cases.fourbar, "jansen": cases.jansen,
         "chain10": lambda n: cases.chain(10, n), "chain40": lambda n: cases.chain(40, n)}


@contextlib.contextmanager
def as_kincas(module):
    """`import kincas` gives `module` meanwhile (the harness's builders import it by name)."""
    old = sys.modules["kincas"]
    sys.modules["kincas"] = module
    try:
        yield
    finally:
        sys.modules["kincas"] = old


def load_against(checkout: str):
    """The kincas package of another checkout, imported as `kincas_against` (its modules
    import each other relatively, so a copy under another name is a package of its own)."""
    tmp = Path(tempfile.mkdtemp(prefix="kincas-against-"))
    shutil.copytree(Path(checkout) / "kincas", tmp / "kincas_against")
    sys.path.insert(0, str(tmp))
    return importlib.import_module("kincas_against")


def tools(case, against=None):
    out = {"kincas": kincas_runs.prepare_method(case, "sweep (default)")}
    if against is not None:
        with as_kincas(against):
            kincas_runs.prepare_method(case, "sweep, method=fast, compile=True")()
            out["against"] = kincas_runs.prepare_method(case, "sweep (default)")
    if pylinkage_peer.available() is None and pylinkage_peer.supports(case) is None:
        out["pylinkage"] = pylinkage_peer.prepare(case)
    out["closed form"] = closed_form.prepare(case)
    return out


def agreement(case, answers) -> float:
    """The worst difference between the tools' answers (warm-up calls) and the closed form's
    at 30 digits, positions over L and velocities over omega L, inf if a tool left a pose
    unsolved: every tool timed here must have solved the same sweep."""
    P, V = closed_form.reference(case) if len(case.theta) <= 400 else closed_form.solve_numpy(case)
    worst = 0.0
    for run in answers.values():
        if not run.ok.all():
            return float("inf")
        worst = max(worst, *errors(case, run, P, V))
    return worst


def measure(case, repeats, clock=time.process_time, against=None):
    """{tool: median us per pose}, and "agree": `agreement` of their answers."""
    runs = tools(case, against)
    kincas_runs.prepare_method(case, "sweep, method=fast, compile=True")()  # the library, as a
    # second process finds it cached (the default sweeps use it from then on)
    answers = {}
    for k, f in runs.items():  # warm-up: JIT, caches
        f()
        answers[k] = f()
    times = {k: [] for k in runs}
    for _ in range(repeats):
        for k, f in runs.items():
            t0 = clock()
            f()
            times[k].append(clock() - t0)
    n = len(case.theta)
    return {**{k: 1e6 * statistics.median(v) / n for k, v in times.items()}, "agree": agreement(case, answers)}


def first_use(tool: str, name: str, calls: list[int]) -> list[float]:
    """Seconds from setup to the end of each of `calls` (cumulative) in a fresh process."""
    import json
    import os
    import subprocess
    code = f"""
import sys, time, json
sys.path[:0] = {[str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]!r}
import bench_overhead as b
from peers import kincas_runs, pylinkage_peer
case = b.CASES[{name!r}](360)
{"import kincas" if tool == "kincas" else "import pylinkage, numba"}
t0 = time.perf_counter()
run = kincas_runs.prepare_method(case, "sweep (default)") if {tool!r} == "kincas" else pylinkage_peer.prepare(case)
out, k = [], 0
for c in {sorted(calls)!r}:
    while k < c:
        run()
        k += 1
    out.append(time.perf_counter() - t0)
print(json.dumps(out))
"""
    with tempfile.TemporaryDirectory() as tmp:
        env = {**os.environ, "KINCAS_CACHE": tmp}  # (numba's cache as installed: a user's
        # first process compiles pylinkage's loop, ~10 s here, once per installation)
        env.pop("KINCAS_NO_COMPILE", None)
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                              timeout=3600)
    if done.returncode:
        raise RuntimeError(done.stderr.strip()[-400:])
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=40)
    ap.add_argument("--poses", default="360,3600")
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--wall", action="store_true", help="wall-clock time instead of CPU time")
    ap.add_argument("--against", help="a checkout whose kincas is timed beside this one")
    ap.add_argument("--first-use", help="calls (e.g. 1,100,1000): fresh processes, empty cache")
    ap.add_argument("--report", action="store_true",
                    help="both regimes (warm at 360, 3,600 and 100,000 poses; first use at 1, 100 and "
                         "1,000 calls) written to results_overhead.md for benchmarks/run.py "
                         "(the default without arguments)")
    argv = sys.argv[1:] if argv is None else argv
    a = ap.parse_args(argv)
    if a.report or not argv:
        return report()
    if a.first_use:
        calls = sorted(map(int, a.first_use.split(",")))
        print(f"{'case':10} {'tool':10} " + " ".join(f"{str(c) + ' calls s':>13}" for c in calls))
        for name in a.cases.split(","):
            got = {t: first_use(t, name, calls) for t in ("kincas", "pylinkage")}
            for t, v in got.items():
                print(f"{name:10} {t:10} " + " ".join(f"{x:13.3f}" for x in v), flush=True)
            print(f"{name:10} {'x':10} " + " ".join(f"{a_ / b_:13.2f}" for a_, b_ in zip(*got.values())))
        return
    import kincas  # noqa: F401  (this checkout's, before any other is loaded)
    against = load_against(a.against) if a.against else None
    print(f"{'case':10} {'poses':>7} {'kincas us/pose':>15} {'pylinkage':>10} {'closed':>8} {'x pyl':>6} "
          f"{'x closed':>8} {'agree':>8}" + (f" {'against':>8} {'x against':>9}" if against else ""))
    for name in a.cases.split(","):
        for n in map(int, a.poses.split(",")):
            case = CASES[name](n)
            if len(case.theta) != n:
                case = case.with_theta(cases.sweep_angles(n))
            t = measure(case, a.repeats if n <= 4000 else max(3, a.repeats // 10),
                        time.perf_counter if a.wall else time.process_time, against)
            k, pl, cf = t["kincas"], t.get("pylinkage", float("nan")), t["closed form"]
            extra = f" {t['against']:8.3f} {k / t['against']:9.2f}" if against else ""
            print(f"{name:10} {n:7d} {k:15.3f} {pl:10.3f} {cf:8.3f} {k / pl:6.2f} {k / cf:8.2f} {t['agree']:8.1e}{extra}",
                  flush=True)


def report(path: Path = Path(__file__).resolve().parent / "results_overhead.md") -> None:
    """Both regimes side by side, as markdown beside this file (benchmarks/run.py quotes it)."""
    import kincas  # noqa: F401  (this checkout's)
    lines = ["# What users call: `kincas.sweep` per call, warm and on first use", "",
             "Warm: CPU time per pose, median of interleaved calls in one process (the library built "
             "first); positions and velocities of the compared points. First use: wall time in a fresh "
             "process with kincas's cache empty, from setup to the end of the n-th 360-pose sweep "
             "(compiles and JIT included; numba's cache as installed). Agreement: the worst difference of any "
             "tool's positions (over L) or velocities (over ωL) from the closed form at 30 digits (numpy's beyond "
             "400 poses), every pose solved by every tool.", "",
             "| case | poses | kincas µs/pose | pylinkage (numba) | closed form (numpy) | × pylinkage | × closed form | agreement |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for name in CASES:
        for n in (360, 3_600, 100_000):
            case = CASES[name](n)
            if len(case.theta) != n:
                case = case.with_theta(cases.sweep_angles(n))
            t = measure(case, 40 if n <= 4000 else 5)
            k, pl, cf = t["kincas"], t.get("pylinkage", float("nan")), t["closed form"]
            lines.append(f"| {name} | {n:,} | {k:.3f} | {pl:.3f} | {cf:.3f} | {k / pl:.2f} | {k / cf:.2f} | {t['agree']:.1e} |")
            print(lines[-1], flush=True)
    calls = [1, 100, 1000]
    lines += ["", "| case | tool | " + " | ".join(f"{c:,} calls (s)" for c in calls) + " |",
              "|---|---|" + "---:|" * len(calls)]
    for name in ("fourbar", "jansen"):
        got = {t: first_use(t, name, calls) for t in ("kincas", "pylinkage")}
        for t, v in got.items():
            lines.append(f"| {name} | {t} | " + " | ".join(f"{x:.3f}" for x in v) + " |")
        lines.append(f"| {name} | kincas ÷ pylinkage | " + " | ".join(
            f"{a_ / b_:.2f}" for a_, b_ in zip(*got.values())) + " |")
        print("\n".join(lines[-3:]), flush=True)
    tmp = path.with_suffix(".md.tmp")
    tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    tmp.replace(path)


if __name__ == "__main__":
    main()
