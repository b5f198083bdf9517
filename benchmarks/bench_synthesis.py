"""Path synthesis: kincas (IPOPT, exact derivatives, simultaneous formulation) against
pylinkage's particle-swarm optimiser, on the same target, sample inputs, bounds and start.

    python benchmarks/bench_synthesis.py [--quick]

The study is examples/synthesis_path.toml: six dimensions of a crank-rocker four-bar (ground,
crank, coupler, rocker, coupler point x and y) so that the coupler point passes near twelve
target points, one every 30 deg of the crank; objective: the sum of squared distances (mm^2).

* kincas: `kincas.cli.scene_optimize.run_scene` on the scene, timed whole (NLP construction, IPOPT,
  the checks of the answer: polishing, branch, sweep between samples). Also timed in a fresh
  process from `import kincas` (reading the scene and building the model included), and
  the first call in this process apart from later ones.
* pylinkage: `pylinkage.particle_swarm_optimization` (its documented PSO) with an evaluation
  function that sets the six dimensions (the ground pivot O4 as a coordinate, the others
  through `set_constraints`, the coupler point as the `FixedDyad` polar pair), simulates a
  full crank turn in 5 deg steps with `step_fast` (numba) and scores the same sum of squared
  distances at the twelve crank angles; unbuildable designs score infinity. Its swarm is
  seeded from numpy's global random state, not reproducibly, so several runs are shown.
  Budgets: its defaults (100 particles, 200 iterations) and five times the iterations.
  numba's compilation is done before timing (pylinkage's best case).

Each tool's answer is scored again by the other tool's kinematics (and by a closed form), so
the objectives compare like with like. Writes benchmarks/results_synthesis.md. Not a test.
"""
from __future__ import annotations

import argparse
import importlib
import math
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))

import kincas  # noqa: E402
from kincas.cli.scene_optimize import run_scene  # noqa: E402
from kincas.cli.scene import load  # noqa: E402

SCENE = ROOT / "examples" / "synthesis_path.toml"
STEP_DEG = 5.0  # pylinkage's crank step: the samples are every 6th step
NAMES = ["r1", "r2", "r3", "r4", "px", "py"]


# --- the study, read from the scene so both tools see the same numbers ---


def study():
    sc = load(SCENE)
    opt = sc.study.raw["optimize"]
    return dict(scene=sc, th=sc.study.inputs["crank.angle"], tx=np.array(opt["data"]["tx"]),
                ty=np.array(opt["data"]["ty"]), x0=np.array([sc.mechanism.parameter(n) for n in NAMES]),
                lo=np.array([opt["vary"][n][0] for n in NAMES], float),
                hi=np.array([opt["vary"][n][1] for n in NAMES], float))


def closed_form(th, r1, r2, r3, r4, px, py, sign=+1):
    """Coupler point by circle intersection (numpy): an independent scorer."""
    ax, ay = r2 * np.cos(th), r2 * np.sin(th)
    ex, ey = r1 - ax, -ay
    r = np.hypot(ex, ey)
    x = (r3 * r3 - r4 * r4 + r * r) / (2 * r)
    with np.errstate(invalid="ignore"):
        h = np.sqrt(r3 * r3 - x * x)
    bx, by = ax + (x * ex - sign * h * ey) / r, ay + (x * ey + sign * h * ex) / r
    c, s = (bx - ax) / r3, (by - ay) / r3
    return ax + c * px - s * py, ay + s * px + c * py


def score_closed(S, p):
    """The objective by the closed form, on the branch nearer the scene's: (value, branch)."""
    best = (math.inf, 0)
    for sign in (+1, -1):
        x, y = closed_form(S["th"], *p, sign=sign)
        v = float(np.sum((x - S["tx"]) ** 2 + (y - S["ty"]) ** 2))
        if np.isfinite(v) and v < best[0]:
            best = (v, sign)
    return best


def score_kincas(S, p):
    m = S["scene"].mechanism.with_parameters(**dict(zip(NAMES, map(float, p))))
    sw = kincas.sweep(m, {"crank.angle": S["th"]}, report=["P.x", "P.y"])
    if not all(s == "ok" for s in sw.status):
        return math.inf
    return float(np.sum((sw["P.x"] - S["tx"]) ** 2 + (sw["P.y"] - S["ty"]) ** 2))


# --- kincas ---


def cold_kincas():
    """Seconds for import + scene + optimise in a fresh process (interpreter start excluded)."""
    code = ("import time; t = time.perf_counter(); from kincas.cli.scene import load; "
            "from kincas.cli.scene_optimize import run_scene; r = run_scene(load(%r)); "
            "print(time.perf_counter() - t)" % str(SCENE))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    return float(out.stdout.split()[-1]) if out.returncode == 0 else math.nan


def run_kincas(S, repeats):
    cold = cold_kincas()
    t = time.perf_counter()
    r = run_scene(S["scene"])
    first = time.perf_counter() - t
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        r = run_scene(S["scene"])
        times.append(time.perf_counter() - t)
    p = np.array([r.parameters[n] for n in NAMES])
    return dict(r=r, p=p, first=first, times=times, cold=cold)


# --- pylinkage ---


def ensure_pylinkage():
    """Import pylinkage, installing it with pip if missing; (module, error)."""
    try:
        return importlib.import_module("pylinkage"), None
    except ImportError:
        pass
    p = subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--disable-pip-version-check",
                        "pylinkage[numba]"], capture_output=True, text=True, timeout=900)
    if p.returncode != 0:
        return None, "pip install pylinkage failed: " + (p.stderr.strip().splitlines() or ["?"])[-1]
    try:
        return importlib.import_module("pylinkage"), None
    except ImportError as e:
        return None, f"pylinkage installed but does not import: {e}"


def build_pylinkage(S):
    """The scene's four-bar in pylinkage's components, and its evaluation function."""
    from pylinkage import Crank, FixedDyad, Ground, RRRDyad
    from pylinkage.simulation import Linkage

    r1, r2, r3, r4, px, py = S["x0"]
    step = math.radians(STEP_DEG)
    every = round(math.degrees(S["th"][1] - S["th"][0]) / STEP_DEG)
    n = every * len(S["th"])
    O2, O4 = Ground(0.0, 0.0, name="O2"), Ground(r1, 0.0, name="O4")
    crank = Crank(O2, r2, angular_velocity=step, initial_angle=float(S["th"][0]) - step, name="A")
    guess = S["scene"].mechanism.guess[0][1]  # B's guess: the branch
    B = RRRDyad(crank.output, O4, r3, r4, x=float(guess[0]), y=float(guess[1]), name="B")
    P = FixedDyad(crank.output, B, math.hypot(px, py), math.atan2(py, px), name="P")
    linkage = Linkage([O2, O4, crank, B, P], name="synthesis_path")
    linkage.compile()
    start = [c.position for c in linkage.components]
    tx, ty = S["tx"], S["ty"]

    def simulate(params, init_pos):
        r1, r2, r3, r4, px, py = params
        pos = list(init_pos)
        pos[1] = (r1, 0.0)  # the ground pivot O4 is a coordinate, not a constraint
        linkage.set_coords(pos)
        linkage.set_constraints([r2, r3, r4, math.hypot(px, py), math.atan2(py, px)])
        return linkage.step_fast(iterations=n)[::every]

    def evaluate(linkage_, params, init_pos):  # the PSO's fitness: lower is better
        pts = simulate(params, init_pos)[:, 4]
        v = float(np.sum((pts[:, 0] - tx) ** 2 + (pts[:, 1] - ty) ** 2))
        return v if math.isfinite(v) else math.inf

    return linkage, evaluate, simulate, start


def run_pso(pl, S, linkage, evaluate, particles, iterations):
    t = time.perf_counter()
    ens = pl.particle_swarm_optimization(
        evaluate, linkage, center=S["x0"], dimensions=6, n_particles=particles,
        iterations=iterations, bounds=(S["lo"], S["hi"]), order_relation=min, verbose=False)
    dt = time.perf_counter() - t
    p = np.asarray(ens.dimensions[0], float)
    return dict(p=p, time=dt, score=float(ens.scores["score"][0]), evals=particles * (iterations + 1))


# --- the report ---


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer PSO runs and repeats")
    args = ap.parse_args()
    S = study()
    runs = 2 if args.quick else 5
    K = run_kincas(S, repeats=3 if args.quick else 10)
    kin_med = float(np.median(K["times"]))
    lines = ["# Path synthesis benchmark (benchmarks/bench_synthesis.py)", "",
             f"Run {time.strftime('%Y-%m-%d %H:%M')}{' (--quick)' if args.quick else ''} on "
             f"{platform.machine()}, {platform.python_version()}, a shared 2-core machine (times "
             f"vary by about ±30 %; compare within this run).", "",
             f"Study: `examples/synthesis_path.toml`, six dimensions of a four-bar, coupler point "
             f"through {len(S['th'])} targets at crank angles every "
             f"{math.degrees(S['th'][1] - S['th'][0]):g} deg; objective = sum of squared distances "
             f"(mm²); same bounds and the same starting design for both tools. The initial "
             f"design scores {score_closed(S, S['x0'])[0]:.6g} mm².", ""]
    pl, err = ensure_pylinkage()
    rows = [("kincas `optimize` (IPOPT, exact derivatives)",
             "fresh process: import, read the scene, build the model, optimise",
             K["r"].objective, score_closed(S, K["p"]), K["cold"], "-"),
            ("kincas `optimize` (IPOPT, exact derivatives)", "first call in the process",
             K["r"].objective, score_closed(S, K["p"]), K["first"], "-"),
            ("kincas `optimize` (IPOPT, exact derivatives)", f"later calls, median of {len(K['times'])}",
             K["r"].objective, score_closed(S, K["p"]), kin_med, "-")]
    pso = {}
    if pl is None:
        lines += [f"**pylinkage could not be run**: {err}", ""]
    else:
        linkage, evaluate, simulate, start = build_pylinkage(S)
        ver = getattr(pl, "__version__", "?")
        # the two kinematics agree on the initial design (same objective definition)
        f_pl0 = evaluate(linkage, list(S["x0"]), start)
        lines += [f"pylinkage {ver}: PSO through `particle_swarm_optimization`, fitness by "
                  f"`step_fast` (numba) over a full turn in {STEP_DEG:g} deg steps. Initial design "
                  f"scored by pylinkage: {f_pl0:.6g} mm² (by kincas: "
                  f"{score_kincas(S, S['x0']):.6g}).", ""]
        evaluate(linkage, list(S["x0"]), start)  # numba compiled before timing
        for particles, iterations in ((100, 200), (100, 1000)):
            res = [run_pso(pl, S, linkage, evaluate, particles, iterations) for _ in range(runs)]
            pso[(particles, iterations)] = res
            for i, r in enumerate(res):
                rows.append((f"pylinkage PSO, {particles} particles x {iterations} iterations",
                             f"run {i + 1} of {runs} ({r['evals']:,} evaluations)", r["score"],
                             score_closed(S, r["p"]), r["time"],
                             f"{score_kincas(S, r['p']):.6g}"))
        # kincas's design scored by pylinkage's simulation
        f_pl = evaluate(linkage, list(K["p"]), start)
        lines += [f"kincas's optimum scored by pylinkage's own simulation: {f_pl:.6g} mm² "
                  f"(kincas: {K['r'].objective:.6g}).", ""]
    lines += ["| tool | run | objective (mm², its own) | closed-form score (branch) | wall time (s) "
              "| scored by kincas.sweep |", "|---|---|---|---|---|---|"]
    for tool, run, obj, (cf, sign), t, ks in rows:
        lines.append(f"| {tool} | {run} | {obj:.6g} | {cf:.6g} ({'+' if sign > 0 else '-'}) "
                     f"| {t:.3f} | {ks} |")
    lines += ["", f"kincas: IPOPT status `{K['r'].status}`, {K['r'].iterations} iterations, checks "
              f"passed: {K['r'].ok}; optimised dimensions "
              + ", ".join(f"{n} = {v:.4f}" for n, v in zip(NAMES, K["p"])) + ".", ""]
    if pso:
        lines += ["## Verdict (target: a better objective in a tenth of the time)", ""]
        for (particles, iterations), res in pso.items():
            best = min(r["score"] for r in res)
            med_obj = float(np.median([r["score"] for r in res]))
            med_t = float(np.median([r["time"] for r in res]))
            lines.append(
                f"- PSO {particles} x {iterations}: median objective {med_obj:.4g} (best of {len(res)}: "
                f"{best:.4g}) in {med_t:.2f} s median. kincas: {K['r'].objective:.4g} in "
                f"{kin_med:.3f} s (fresh process {K['cold']:.2f} s): objective "
                f"{'better' if K['r'].objective < best else 'NOT better'} than the best PSO run, "
                f"time {med_t / kin_med:.0f}x shorter (fresh process: {med_t / K['cold']:.1f}x); "
                f"target {'met' if K['r'].objective < best and med_t >= 10 * kin_med else 'NOT met'}"
                f"{'' if med_t >= 10 * K['cold'] else ' (not counting a fresh process)'}.")
        lines.append("")
    (HERE / "results_synthesis.md").write_text("\n".join(lines), encoding="utf-8")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
