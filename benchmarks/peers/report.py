"""RESULTS.md and its plots from the measurements of run.py (numbers in, markdown and PNGs out).

>>> fmt_t(2.5e-6), fmt_e(3.2e-12), fmt_e(float("nan"))
('2.50', '3.2e-12', '—')
"""
from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

from .measure import pareto

FLOOR = 1e-17  # errors below this (exact zeros) are drawn at it on log scales


def fmt_t(sec: float) -> str:
    """Seconds per pose as microseconds."""
    if not math.isfinite(sec):
        return "—"
    us = sec * 1e6
    return f"{us:.3g}" if us < 1 else f"{us:.2f}" if us < 100 else f"{us:.0f}"


def fmt_e(e: float) -> str:
    return "—" if not math.isfinite(e) else "0" if e == 0 else f"{e:.1e}"


def fmt_spread(t) -> str:
    lo, hi = t.spread
    return f"{fmt_t(t.median)} ({fmt_t(lo)}–{fmt_t(hi)})"


def combined(err) -> float:
    """The error plotted and ranked: the worse of position and velocity (position alone when
    the tool computes no velocities)."""
    pe, ve = err
    return pe if not math.isfinite(ve) else max(pe, ve)


def _ok(r) -> bool:
    return "t" in r and r["t"].error is None


# --- section 1 and 2 ---


def fronts(main: dict, kinds=("kincas",)) -> dict:
    """Per case, the labels on the Pareto front of (time per pose, combined error) among the
    tools of the given kinds, fastest first."""
    out = {}
    for name, res in main.items():
        labels = [lb for lb, r in res.items() if lb != "case" and _ok(r) and r["kind"] in kinds
                  and math.isfinite(combined(r["err"]))]
        pts = [(res[lb]["t"].median, max(combined(res[lb]["err"]), FLOOR)) for lb in labels]
        out[name] = [labels[i] for i in pareto(pts)]
    return out


def plot_error_time(main: dict, front: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(13, 10))
    every = list(dict.fromkeys(lb for res in main.values() for lb in res if lb != "case"))
    cmap = plt.get_cmap("tab20")
    color = {lb: cmap(i % 20) for i, lb in enumerate(every)}  # one colour per tool in every panel
    for ax, (name, res) in zip(axes.flat, main.items()):
        labels = [lb for lb, r in res.items() if lb != "case" and _ok(r) and math.isfinite(combined(r["err"]))]
        for lb in labels:
            r = res[lb]
            x, y = r["t"].median * 1e6, max(combined(r["err"]), FLOOR)
            kin = r["kind"] == "kincas"
            ax.scatter([x], [y], marker="o" if kin else "s", s=60, label=lb,
                       facecolors=color[lb] if kin else "none", edgecolors=color[lb], linewidths=1.5)
        fr = [(res[lb]["t"].median * 1e6, max(combined(res[lb]["err"]), FLOOR)) for lb in front[name]]
        if fr:
            xs, ys = zip(*fr)
            ax.step(xs, ys, where="post", color="k", lw=1, ls="--", label="Pareto front of kincas's methods")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(res["case"].title)
        ax.set_xlabel("time per pose (µs, median)")
        ax.set_ylabel("worst error (position / L, velocity / ωL)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6.5, loc="best")
    fig.suptitle("Error against run time: kincas methods (filled), peers (hollow)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main_tables(main: dict, front: dict) -> list[str]:
    overall = fronts(main, ("kincas", "peer"))
    out = []
    for name, res in main.items():
        case = res["case"]
        base = res.get("closed form, numpy (vectorised)", {})
        ref_t = base["t"].median if _ok(base) else float("nan")
        kin = res.get("sweep (default)", {})
        kin_t = kin["t"].median if _ok(kin) else float("nan")
        out += [f"### {case.title} ({case.name}: {len(case.theta)} poses, size L = {case.size:g})", "",
                "| tool / method | µs per pose: median (min–max) | × closed form | × kincas sweep | setup s "
                "| worst position error / L | worst velocity error / ωL | poses solved | kincas Pareto |",
                "|---|---|---|---|---|---|---|---|---|"]
        for lb, r in res.items():
            if lb == "case":
                continue
            who = lb if r["kind"] == "kincas" else f"*{lb}*"
            if not _ok(r):
                why = r.get("why") or r["t"].error
                out.append(f"| {who} | not run: {why} | | | | | | | |")
                continue
            t = r["t"]
            ratio = lambda b: f"{t.median / b:.3g}" if math.isfinite(b) and b > 0 else "—"
            mark = f"#{front[name].index(lb) + 1}" if lb in front[name] else ""
            out.append(f"| {who} | {fmt_spread(t)} | {ratio(ref_t)} | {ratio(kin_t)} | {t.setup:.2f} "
                       f"| {fmt_e(r['err'][0])} | {fmt_e(r['err'][1])} | {int(t.run.ok.sum())}/{r['poses']} | {mark} |")
        out += ["", "Pareto front of kincas's methods (fastest first): **" + " → ".join(front[name]) + "**. "
                "Of all tools: " + " → ".join(overall[name]) + ".", ""]
    return out


def plot_throughput(main: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(main)
    tools = [lb for lb in next(iter(main.values())) if lb != "case"]
    fig, ax = plt.subplots(figsize=(12, 7))
    h = 0.8 / len(names)
    for j, name in enumerate(names):
        res = main[name]
        vals = [res[lb]["t"].median * 1e6 if lb in res and _ok(res[lb]) else np.nan for lb in tools]
        ax.barh(np.arange(len(tools)) + j * h, vals, height=h, label=res["case"].title)
    ax.set_yticks(np.arange(len(tools)) + 0.4 - h / 2)
    ax.set_yticklabels(tools, fontsize=8)
    ax.invert_yaxis()
    ax.set_xscale("log")
    ax.set_xlabel("time per pose (µs, median; shorter is faster; no bar: not run)")
    ax.grid(True, axis="x", which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def headline(main: dict) -> list[str]:
    """Ratios of the fastest kincas sweep against each peer, per case, from the same run."""
    lines = []
    for name, res in main.items():
        sweeps = [lb for lb, r in res.items() if lb.startswith("sweep") and _ok(r)]
        if not sweeps:
            continue
        best = min(sweeps, key=lambda lb: res[lb]["t"].median)
        tb = res[best]["t"].median
        parts = []
        for lb, r in res.items():
            if lb != "case" and r["kind"] == "peer" and _ok(r):
                q = r["t"].median / tb
                parts.append(f"{lb}: {q:.3g}× kincas's time" if q >= 1 else f"{lb}: {1 / q:.3g}× faster")
        lines.append(f"- **{res['case'].title}**: kincas `{best}` {fmt_t(tb)} µs/pose "
                     f"(error {fmt_e(combined(res[best]['err']))}); " + "; ".join(parts) + ".")
    return lines


# --- section 3 ---


def stability_tables(stab: dict) -> list[str]:
    out = []
    for name, res in stab.items():
        case = res["case"]
        out += [f"### {case.title} ({name}: {len(case.theta)} poses)", "",
                "| tool | solved / assemblable | correct | branch jumps | wrong | missed | false | "
                "worst error / L (correct poses) | µs/pose |",
                "|---|---|---|---|---|---|---|---|---|"]
        for lb, r in res.items():
            if lb == "case":
                continue
            if "why" in r or r["c"] is None:
                out.append(f"| {lb} | not run: {r.get('why') or r['t'].error} | | | | | | | |")
                continue
            c = r["c"]
            out.append(f"| {lb} | {c['claimed']} / {c['assemble']} | {c['correct']} | {c['jumps']} | {c['wrong']} "
                       f"| {c['missed']} | {c['false']} | {fmt_e(c['worst'])} | {fmt_t(r['t'].median)} |")
        out.append("")
    return out


# --- section 4 ---


def growth_table(growth: dict) -> list[str]:
    sizes = list(growth)
    tools = [lb for lb in growth[sizes[0]] if lb not in ("compile", "case")]
    out = ["| four-bars N | unknowns | kincas.model_of s | " + " | ".join(f"{lb} µs/pose (setup s)" for lb in tools) + " |",
           "|---|---|---|" + "---|" * len(tools)]
    for n in sizes:
        res = growth[n]
        cells = [f"{fmt_spread(res[lb]['t'])} ({res[lb]['t'].setup:.2f})" if _ok(res[lb])
                 else f"failed: {res[lb]['t'].error}" for lb in tools]
        out.append(f"| {n} | {2 * n} | {res['compile']:.2f} | " + " | ".join(cells) + " |")
    worst = max((combined(growth[n][lb]["err"]) for n in sizes for lb in tools if _ok(growth[n][lb])
                 and math.isfinite(combined(growth[n][lb]["err"]))), default=float("nan"))
    return out + ["", f"Worst error of any tool at any size against the closed form: {fmt_e(worst)}."]


def plot_growth(growth: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sizes = list(growth)
    tools = [lb for lb in growth[sizes[0]] if lb not in ("compile", "case")]
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(13, 5))
    for lb in tools:
        y = [growth[n][lb]["t"].median * 1e6 if _ok(growth[n][lb]) else np.nan for n in sizes]
        a1.plot(sizes, y, "o-", label=lb)
        if lb.startswith("sweep"):
            a2.plot(sizes, [growth[n][lb]["t"].setup if _ok(growth[n][lb]) else np.nan for n in sizes],
                    "o-", label=f"{lb}: first call (setup)")
    a2.plot(sizes, [growth[n]["compile"] for n in sizes], "ks--", label="kincas.model_of (symbolic model)")
    for ax, yl in ((a1, "time per pose (µs, median)"), (a2, "seconds")):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("chained four-bars N (2N unknowns)")
        ax.set_ylabel(yl)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    a1.set_title("per-pose cost")
    a2.set_title("compile / setup time")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# --- the document ---

NOTES = """\
- **Timing.** Each tool's whole sweep is one timed call, Python overhead included. The first
  call (after building: kincas's symbolic model and compiled code, pylinkage's numba JIT,
  SolveSpace's sketch) is the *setup* column and is not in the per-pose times; then several
  further calls (up to {repeats}; at least 3 unless a call is slow), each from the case's
  guess. Shown: the median time per pose and, in brackets, the fastest and slowest call. The
  machine is shared by 2 cores: treat times as ±30 %, ratios from the same run as better.
  kincas's compiled code is built into a fresh cache directory for every run.
- **Errors.** Worst over the compared points (their positions and velocities) and the poses
  the tool solved; positions relative to the size L, velocities to ωL. References: the
  closed form of each dyad chain (successive circle intersections, velocities from the
  differentiated distance equations) evaluated in mpmath at 30 digits; for the class-III
  triad, Newton's method on the distance equations at 30 digits, converged to 1e-25 L.
  Both are written independently of kincas (`peers/closed_form.py`, `peers/mp_newton.py`).
- **Peers, as documented.** scipy `fsolve` with its default tolerances, warm-started from the
  previous pose, on the distance equations (velocities from the same Jacobian, by hand);
  pylinkage through `Linkage.step_fast_with_kinematics` with numba (its README's fast path),
  dyads only; python-solvespace's solve loop (`set_params` on a dragged hand point, `solve()`
  warm from the last pose; it gives no velocities, so its error is positions only); the
  `mechanism` package's `Mechanism.iterate()` on vector loops (fsolve inside).
- **kincas settings.** `newton per pose, tol T` sets kincas's module setting
  `kincas.core.numeric.TOL` (Newton's target residual / L) for that run; `IPOPT per pose` runs
  on every {stride}th pose only (it is slow); `solve per pose` passes the previous pose's
  points as the guess. Sweep options that this kincas does not have are listed, not faked.
- **Stability.** A pose is *correct* within {match:g} L of the reference branch, a *branch
  jump* when it matches the mechanism's other assembly instead, *wrong* when it matches
  neither; *missed*: assembles but not solved; *false*: claimed where nothing assembles.
  The reference branch is the one the sweep starts on (for the parallelogram: the
  parallelogram, through both change points); for the triple rocker, both assemblies meet
  at each limit, so coming back on the other one is a convention, not an error.
"""


def write_report(out: Path, *, quick, cfg, installs, machine, main, stability, growth, others, seconds,
                 api=None):
    from . import kincas_runs as kr
    from .measure import MATCH

    out.mkdir(parents=True, exist_ok=True)
    front = fronts(main)
    plot_error_time(main, front, out / "bench_error_time.png")
    plot_throughput(main, out / "bench_throughput.png")
    plot_growth(growth, out / "bench_growth.png")
    _, missing = kr.methods()
    L = ["# kincas benchmarks", "",
         f"Written by `python benchmarks/run.py{' --quick' if quick else ''}` on "
         f"{time.strftime('%Y-%m-%d %H:%M')} in {seconds:.0f} s. " + machine[0] + ".", "", machine[1] + ".", ""]
    if quick:
        L += ["> **Quick run**: few poses and repeats; the numbers are a smoke test, not results.", ""]
    if api:
        from .api import api_tables
        L += ["## Headline: what users call", "",
              "`kincas.sweep` with its defaults (positions and velocities of every compared point, the "
              "singular-position pass included) and `kincas solve --json` (a new process per run, scene "
              "read and JSON written), against the peers on the same poses, medians of one run. Setup "
              "(building, compiling) is apart: the longest sweep of each case ran first, so its setup is "
              "the cold one (empty compiled-code cache) and the shorter ones are cached starts.", ""]
        L += api_tables(api)
    L += ["## Fastest kincas option per case", "", "The fastest kincas sweep option against each peer, "
          "same mechanism, poses and outputs, same run (medians):", ""] + headline(main) + [""]
    L += ["## Peers", "", "| requirement | status |", "|---|---|"]
    L += [f"| `{req}` | {'installed' if err is None else 'NOT AVAILABLE: ' + err} |" for req, err in installs.items()]
    L += ["", "## 1. Error against run time", "",
          "Every kincas method and setting as a point (worst error against time per pose); peers in "
          "italics and as hollow markers for scale. The Pareto front is named under each table.", "",
          "![error against time](bench_error_time.png)", ""]
    if missing:
        L += ["kincas options not available in this version (not measured): " +
              "; ".join(f"`{lb}` ({why})" for lb, why in missing) + ".", ""]
    L += ["## 2. Sweep throughput against peers", "",
          "The tables below hold section 2 too: each peer's time per pose next to its error, as ratios "
          "to the vectorised closed form (the limit for dyad chains) and to kincas's default sweep.", "",
          "![throughput](bench_throughput.png)", ""] + main_tables(main, front)
    L += ["## 3. Stability: stiff and extreme cases", ""] + stability_tables(stability)
    L += ["## 4. Growth with the mechanism's size", "",
          "N four-bars chained through shared links (each rocker is the next crank; rockers 1.1 and 1 "
          "in turn, couplers 4 between pivots 4 apart: no unit is a parallelogram, so the closed form, "
          "like every dyad method, intersects two circles per unit), "
          f"{cfg['chain_poses']} poses over 60–120°, 2N unknowns. The `mechanism` package is left out "
          "here (its Python vector loops make the large sizes cost minutes); the others are all the "
          "general solvers of section 2 and the closed form.", "",
          "![growth](bench_growth.png)", ""] + growth_table(growth) + [""]
    if others:
        L += ["## Other benchmarks", ""]
        for name, status, text in others:
            L += [f"### {name} ({status})", "", text.strip() or "(no output)", ""]
    L += ["## How these numbers were measured", "",
          NOTES.format(repeats=cfg["repeats"], stride=kr.IPOPT_STRIDE, match=MATCH)]
    (out / "RESULTS.md").write_text("\n".join(L) + "\n", encoding="utf-8")
