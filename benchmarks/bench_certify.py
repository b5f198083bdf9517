"""Certified assembly modes (msolve) beside the multistart search: time per case, and how
often the multistart misses a mode that the certificate proves exists.

    python benchmarks/bench_certify.py [--quick]

For each case (planar and spatial; the overconstrained spatial ones with float axes through
their square subsystems, kincas/analysis/certify_over.py) and a few poses along its sweep: `kincas.modes(m, u, certify=True)` (wall time:
msolve is another process, so CPU time of this one would not count it), and the multistart
`find_modes` with 16, 64 and 512 starts over several seeds: its median wall time and the
fraction of (pose, seed) runs whose count is below the certified one. Writes
benchmarks/results_certify.md (benchmarks/run.py collects it).
"""
from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE.parents[0])]

import kincas  # noqa: E402
import kincas.cli.scene  # noqa: E402
from kincas.analysis import certify_msolve  # noqa: E402
from kincas.analysis.modes import find_modes  # noqa: E402

EX = HERE.parent / "examples"


def group44():
    """The Assur group 4.4 of tests/test_certify.py (10 real assemblies of 56 complex): no
    input, one pose."""
    sys.path.insert(0, str(HERE.parent / "tests"))
    from test_certify import group44 as build
    return build(), None, [None]


def scene(name):
    if name == "group44":
        return group44()
    sc = kincas.cli.scene.load(EX / f"{name}.toml")
    if len(sc.study.inputs) > 1:  # several inputs (Stewart's six legs): the scene's one pose
        return sc.mechanism, "all", [{k: float(v[0]) for k, v in sc.study.inputs.items()}]
    key, values = next(iter(sc.study.inputs.items()))
    return sc.mechanism, key, [float(v) for v in values]


CASES = {  # name: (mechanism, input key, poses to try)
    "four-bar (fourbar_coupler)": "fourbar_coupler",
    "slider in a slot (fairbairn)": "fairbairn",
    "Watt-type six-bar + slider (sixbar)": "sixbar",
    "Stephenson III (stephenson3)": "stephenson3",
    "Assur triad / 3-RPR (assur_triad)": "assur_triad",
    "class-IV eight-bar (eightbar)": "eightbar",
    "V-twin, two slides at 45 deg (vtwin)": "vtwin",
    "Assur group 4.4 (tests/test_certify.py)": "group44",
    "spatial RSSR (space_rssr)": "space_rssr",
    "spatial slider-crank (space_slider_crank)": "space_slider_crank",
    "double Cardan shaft (space_double_cardan)": "space_double_cardan",
    "spherical four-bar, float axes (space_spherical_fourbar)": "space_spherical_fourbar",
    "Bennett linkage, float axes (space_bennett)": "space_bennett",
    "Stewart-Gough, Dietmaier's 40 (space_stewart_40)": "space_stewart_40",
}


def timed(f):
    t0 = time.perf_counter()
    out = f()
    return out, time.perf_counter() - t0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="two poses, two seeds")
    ap.add_argument("--only", default="", help="only the cases whose label contains this text")
    args = ap.parse_args(argv)
    if not certify_msolve.available():
        print('msolve is not installed: pip install "kincas[certify]"')
        return 0
    poses, seeds = (2, 2) if args.quick else (5, 5)
    starts_list = (16, 64, 512)
    rows = []
    for label, name in CASES.items():
        if args.only not in label:
            continue
        m, key, values = scene(name)
        picks = values if key == "all" else sorted(
            {values[int(k * (len(values) - 1) / max(poses - 1, 1))] for k in range(poses)},
            key=lambda v: (v is None, v or 0))
        t_cert, counts, misses = [], [], {s: 0 for s in starts_list}
        t_multi = {s: [] for s in starts_list}
        for v in picks:
            at = None if key is None else v if key == "all" else {key: v}
            found, t = timed(lambda: kincas.modes(m, at, certify=True))
            t_cert.append(t)
            counts.append(found.count)
            for s in starts_list:
                for seed in range(seeds):
                    got, t = timed(lambda: find_modes(m, at, starts=s, seed=seed))
                    t_multi[s].append(t)
                    misses[s] += len(got) < found.count
        runs = len(picks) * seeds
        rows.append((label, sorted(set(counts)), statistics.median(t_cert),
                     {s: (statistics.median(t_multi[s]), misses[s], runs) for s in starts_list}))
        print(label, rows[-1], flush=True)
    lines = ["# Certified assembly modes (msolve) against the multistart search", "",
             f"{poses} poses along each example's sweep (the Assur group 4.4: its one pose); multistart over {seeds} seeds per pose. "
             f"Wall times (median, seconds) on a shared {os.cpu_count()}-core machine; msolve with one "
             f"thread. \"missed\": runs whose count fell below the certified count.", "",
             "| case | certified counts | certify (s) | " +
             " | ".join(f"{s} starts (s) | missed" for s in starts_list) + " |",
             "|---|---|---|" + "---|---|" * len(starts_list)]
    for label, counts, tc, multi in rows:
        cells = " | ".join(f"{t:.3f} | {mi}/{n}" for t, mi, n in (multi[s] for s in starts_list))
        lines.append(f"| {label} | {', '.join(map(str, counts))} | {tc:.3f} | {cells} |")
    lines += ["", "The certified time includes writing the polynomials, msolve's run (a separate "
              "process, started per call) and the Newton refinement of every mode; a singular pose "
              "would add two more msolve runs (the split count)."]
    if args.only:  # a partial run: printed, the results file kept
        print("\n".join(lines))
        return 0
    (HERE / "results_certify.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
