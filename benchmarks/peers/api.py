"""What users call, timed: `kincas.sweep` with its defaults and `kincas solve` (the command, a
subprocess) beside the vectorised numpy closed form, pylinkage's numba loop, scipy `fsolve`
and python-solvespace, at 360, 3,600 and 100,000 poses, positions and velocities.

For each case the longest sweep runs first in this process, so its setup is the *cold* one
(the symbolic model built, the kernel generated and compiled into an empty cache); the other
lengths are *cached starts* (the structure's library already built), as a user's second call
is. `kincas solve --json` is timed as a user runs it: a new process each time, reading the
scene and writing the JSON (to a pipe), with one compiled-code cache per case: empty before
the longest sweep's first run (cold), then holding what that run compiled (cached). Every
ratio of the report comes from this one run.

>>> import cases
>>> scene = scene_text(cases.to_kincas(cases.fourbar(8)), cases.fourbar(8), ["B.x"])
>>> "[[inputs]]" in scene and "steps = 8" in scene
True
"""
from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

LENGTHS = (100_000, 3_600, 360)  # the longest first: its first call is the cold setup
CASES = ("fourbar", "slider_crank", "jansen")
SLOW_PER_POSE = 5e-6  # a peer slower than this per pose is timed once at 100,000 poses


# --- a case as a scene file for `kincas solve` ---


def _num(v) -> str:
    return repr(float(v))


def scene_text(m, case, report) -> str:
    """The scene of a benchmark case (links in local coordinates, angles in degrees)."""
    n = len(case.theta)
    first, last = math.degrees(case.theta[0]), math.degrees(case.theta[-1])
    lines = [f'title = "{case.title}"', 'units = { length = "m", angle = "deg", time = "s" }', "[ground]"]
    lines += [f"{g} = [{_num(x)}, {_num(y)}]" for g, (x, y) in m.ground]
    lines += ["[links]"]
    for lk in m.links:
        pts = ", ".join(f"{p} = [{_num(x)}, {_num(y)}]" for p, (x, y) in lk.points)
        lines.append(f"{lk.name} = {{ points = {{ {pts} }} }}")
    for sl in m.slides:
        tx, ty = sl.through
        lines += ["[[slides]]", f'point = "{sl.point}"', f'along = "{sl.along}"', f'name = "{sl.name}"',
                  f"line = {{ through = [{_num(tx)}, {_num(ty)}], angle = {_num(math.degrees(float(sl.angle)))} }}"]
    lines += ["[[inputs]]", 'angle = "crank"', f"sweep = {{ from = {first!r}, to = {last!r}, steps = {n} }}",
              f"rate = {_num(math.degrees(case.omega))}", "[guess]"]
    lines += [f"{k} = [{_num(x)}, {_num(y)}]" for k, (x, y) in m.guess]
    lines += ["[output]", f"report = {json.dumps(report)}"]
    return "\n".join(lines) + "\n"


def time_cli(scene: Path, cache: Path, runs: int) -> tuple[float, list[float], int]:
    """(cold seconds, cached seconds per run, poses solved) of `kincas solve --json`, each a
    new process; the cache starts empty."""
    env = {**os.environ, "KINCAS_CACHE": str(cache)}
    env.pop("KINCAS_NO_COMPILE", None)
    cmd = [sys.executable, "-m", "kincas", "solve", str(scene), "--json"]
    times, solved = [], 0
    for _ in range(runs + 1):
        t0 = time.perf_counter()
        p = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=900)
        times.append(time.perf_counter() - t0)
        if p.returncode not in (0, 3):
            raise RuntimeError(f"kincas solve exit {p.returncode}: {p.stderr.strip()[-300:]}")
        solved = sum(s == "ok" for s in json.loads(p.stdout)["status"])
    return times[0], times[1:], solved


# --- the study ---


def study_api(cfg, log) -> dict:
    """{case: {poses: {tool: Timing-like dict}}}, and the thread scaling of the sweep."""
    import cases
    from peers import closed_form, fsolve_peer, kincas_runs as kr, pylinkage_peer, solvespace_peer
    from peers.closed_form import reference
    from peers.measure import errors, time_tool

    peers = [("numpy closed form", closed_form, {}), ("pylinkage (numba)", pylinkage_peer, {}),
             ("scipy fsolve", fsolve_peer, {"jacobian": True}), ("python-solvespace", solvespace_peer, {})]
    out: dict = {}
    for name in CASES:
        res = out[name] = {}
        cache = Path(tempfile.mkdtemp(prefix=f"kincas-cli-{name}-"))
        for n in cfg["api_lengths"]:
            case = getattr(cases, name)(n)
            P, V = reference(case)
            row = res[n] = {"title": case.title}
            t = time_tool(lambda: kr.prepare_method(case, "sweep (default)"), cfg["api_repeats"])
            row["kincas.sweep"] = {"t": t, "err": errors(case, t.run, P, V) if t.error is None else None}
            log(f"  {name:13s} {n:7d} kincas.sweep {t.median * 1e6:9.3f} us/pose, setup {t.setup:.2f} s")
            for lb, mod, kw in peers:
                why = mod.available() or mod.supports(case)
                if why:
                    row[lb] = {"why": why}
                    continue
                reps = cfg["api_repeats"] if n < 50_000 or lb in ("numpy closed form", "pylinkage (numba)") else 1
                tp = time_tool(lambda: mod.prepare(case, **kw), reps, budget=10.0)
                row[lb] = {"t": tp, "err": errors(case, tp.run, P, V) if tp.error is None else None}
                log(f"  {name:13s} {n:7d} {lb:18s} {tp.median * 1e6:9.3f} us/pose")
            row["kincas solve"] = _cli(case, cfg, log, name, n, cache)
    out["threads"] = thread_scaling(cfg, log)
    return out


def _cli(case, cfg, log, name, n, cache: Path) -> dict:
    """`kincas solve --json` on the case's scene; `cache` is the case's compiled-code cache,
    empty before its longest sweep (cold) and holding that run's library for the others."""
    import cases
    m = cases.to_kincas(case)
    with tempfile.TemporaryDirectory() as tmp:
        scene = Path(tmp) / f"{name}.toml"
        scene.write_text(scene_text(m, case, cases.kincas_report(case)))
        try:
            cold, cached, solved = time_cli(scene, cache, cfg["cli_runs"])
        except Exception as e:  # reported, not raised
            log(f"  {name:13s} {n:7d} kincas solve: {e}")
            return {"error": str(e)[:200]}
    log(f"  {name:13s} {n:7d} kincas solve  first {cold:.2f} s, next {min(cached):.3f} s")
    return {"cold": cold, "cached": float(np.median(cached)), "solved": solved, "poses": n}


def thread_scaling(cfg, log) -> dict:
    """A batch of 8 four-bar sweeps (3,600 poses, different lengths) from 1 and from 4 threads."""
    import cases
    import kincas

    ms = [cases.to_kincas(cases.fourbar(3600, scale=1.0 + 0.01 * i)) for i in range(8)]
    theta = cases.fourbar(3600).theta
    rep = ["B.x", "B.y", "B.vx", "B.vy"]
    one = lambda m: kincas.sweep(m, {"crank.angle": theta}, report=rep)
    for m in ms:
        one(m)  # each structure built and its kernel loaded

    def batch(threads):
        todo = list(ms) * 4
        lock = threading.Lock()

        def work():
            while True:
                with lock:
                    if not todo:
                        return
                    m = todo.pop()
                one(m)
        ts = [threading.Thread(target=work) for _ in range(threads)]
        t0 = time.perf_counter()
        for t in ts:
            t.start()
        for t in ts:
            t.join()
        return time.perf_counter() - t0
    t1, t4 = min(batch(1) for _ in range(3)), min(batch(4) for _ in range(3))
    log(f"  threads: 32 sweeps, 1 thread {t1:.3f} s, 4 threads {t4:.3f} s")
    return {"one": t1, "four": t4, "sweeps": 32, "poses": 3600, "cores": os.cpu_count()}


# --- the report ---

# Why a target above can fail, from profiles taken while the targets were worked on (issue [8]):
# the ratios are this run's, the causes are what was measured behind them.
WHY_NOT = (
    "Where a target is not met, measured: at 360 poses a call costs a fixed 100-200 µs of "
    "Python around the compiled pass (the mechanism's memoised placement looked up, the "
    "result's arrays, the singular-position and resume checks), which pylinkage's numba loop "
    "does not pay (its whole 360-pose four-bar is about 200 µs). At 3,600 and 100,000 poses "
    "what is left is the compiled kernel itself: it runs Newton on g(q) = 0 (a prediction "
    "along the exact tangent, two corrector steps, the tangent's own solve, the Jacobian-change "
    "and singular-position measures of every Assur group), against the closed form's one square "
    "root per dyad; section \"Other benchmarks\" (bench_sweep.py) shows the kernel alone at "
    "about 2-4x the closed form on the four-bar, whose closed form is the cheapest of the three.")




def _us(t) -> float:
    return t.median * 1e6


def api_tables(res: dict) -> list[str]:
    """The headline tables: per case and length, us per pose and ratios; then the targets."""
    L = []
    verdicts = []
    for name in CASES:
        if name not in res:
            continue
        rows = res[name]
        title = next(iter(rows.values()))["title"]
        L += [f"### {title}", "",
              "| poses | `kincas.sweep` µs/pose | × numpy closed form | × pylinkage (numba) | sweep setup s "
              "| `kincas solve` µs/pose (cached; first run s) | numpy closed form | pylinkage (numba) | scipy fsolve "
              "| python-solvespace | sweep worst error (pos / L, vel / ωL) |", "|---|" + "---|" * 10]
        for n in sorted(rows):
            row = rows[n]
            ks = row["kincas.sweep"]["t"]
            cf, pl = row.get("numpy closed form", {}).get("t"), row.get("pylinkage (numba)", {}).get("t")
            cli = row.get("kincas solve", {})
            r_cf = _us(ks) / _us(cf) if cf is not None and cf.error is None else float("nan")
            r_pl = _us(ks) / _us(pl) if pl is not None and pl.error is None else float("nan")
            cells = []
            for lb in ("numpy closed form", "pylinkage (numba)", "scipy fsolve", "python-solvespace"):
                r = row.get(lb, {})
                cells.append(f"{_us(r['t']):.3g}" if "t" in r and r["t"].error is None else
                             ("—" if "t" not in r else "error"))
            c = (f"{cli['cached'] / n * 1e6:.3g} ({cli['cold']:.2f} s)" if "cached" in cli else
                 cli.get("error", "—"))
            err = row["kincas.sweep"]["err"]
            e = f"{err[0]:.1e}, {err[1]:.1e}" if err else "—"
            L.append(f"| {n:,} | **{_us(ks):.3g}** | {r_cf:.2f} | {r_pl:.2f} | {ks.setup:.2f} | {c} | "
                     + " | ".join(cells) + f" | {e} |")
            limit = 3.0 if n < 1000 else 2.0
            verdicts.append((title, n, r_cf, limit, r_pl))
        L.append("")
    L += ["### Targets of issue [8] (this run)", "",
          "| case | poses | sweep × closed form (target) | met | sweep × pylinkage (target ≤ 1) | met |",
          "|---|---|---|---|---|---|"]
    for title, n, r_cf, limit, r_pl in verdicts:
        L.append(f"| {title} | {n:,} | {r_cf:.2f} (≤ {limit:g}) | {'yes' if r_cf <= limit else '**no**'} "
                 f"| {r_pl:.2f} | {'yes' if r_pl <= 1 else '**no**'} |")
    if any(r_cf > limit or r_pl > 1 for _, _, r_cf, limit, r_pl in verdicts):
        L += ["", WHY_NOT]
    th = res.get("threads")
    if th:
        L += ["", f"Threads: {th['sweeps']} sweeps of {th['poses']:,} poses (8 four-bars of different "
              f"lengths) took {th['one']:.3f} s from one thread and {th['four']:.3f} s from four "
              f"({th['one'] / th['four']:.2f}× faster; {th['cores']} cores shared with other work)."]
    return L + [""]
