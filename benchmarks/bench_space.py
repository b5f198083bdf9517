"""Spatial mechanisms (issue [16]): speed against the planar core, forward kinematics, errors
against closed forms, and python-solvespace's 3D solver side by side.

    python benchmarks/bench_space.py

Measures, warm (models built and kernels compiled by a first run), medians of 5 runs:
1. an RSSR (crank about z, rocker about x, a coupler bar) swept through 3,600 poses by
   `kincas.sweep(..., compile=True)` (both fast passes compiled to C), against the planar
   four-bar of the same pose count: time per pose and
   their ratio (target: within 3x);
2. Stewart-Gough forward kinematics (examples/space_stewart.toml): one pose from a nearby
   guess, called as `kincas.solve(m, {"l1": l, ..., "l6": l}, guess=pose_before)` with the
   six legs 2 mm longer than at the guess (target: under 1 ms); error against the closed
   form of equal legs (the platform rises straight up: z = sqrt(l^2 - d^2));
3. worst position/angle error against closed forms: the RSSR's rocker angle solved by hand
   (a sin phi + b cos phi = c), the double Cardan (out.angle = in.angle), Bennett's linkage
   (th3 = -th1 in examples/space_bennett.toml), the tall ones through the fast pass;
4. python-solvespace (3D points, distance constraints) on the same RSSR: C from |C - D| = R,
   |C - D'| = sqrt(R^2 + 1) (D' = D + x: C in the rocker's plane) and |C - B| = lc, with B
   dragged to the crank's position, each pose solved from the last; time and error.
Writes benchmarks/results_space.md. Not a test: nothing here asserts.
"""
from __future__ import annotations

import math
import os
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))

import kincas  # noqa: E402
from kincas import Body, Input, Joint, SpatialMechanism  # noqa: E402
from kincas.cli.scene import load  # noqa: E402

N = 3600
R_CRANK, R_ROCK, LC, D = 15.0, 60.0, 125.0, np.array([100.0, 40.0, 30.0])


def rssr():
    return SpatialMechanism(
        ground={"A": (0.0, 0.0, 0.0), "D": tuple(D)},
        bodies=[Body("crank", {"A": (0.0, 0.0, 0.0), "B": (R_CRANK, 0.0, 0.0)}), Body.bar("coupler", "B", "C", LC),
                Body("rocker", {"D": tuple(D), "C": tuple(D + (0, 0, R_ROCK))})],
        joints=[Joint("revolute", "A", axis=(0, 0, 1)), Joint("revolute", "D", axis=(1, 0, 0))],
        inputs=[Input.joint("A")])


def rssr_by_hand(th):
    """The rocker's angle phi (C = D + R (0, -sin phi, cos phi)) from |B - C| = lc:
    a sin phi + b cos phi = c, the root on the drawing's branch (phi = 0 at th = 0)."""
    bx, by = R_CRANK * np.cos(th), R_CRANK * np.sin(th)
    a, b = -2 * R_ROCK * (D[1] - by), 2 * R_ROCK * D[2]
    c = LC ** 2 - (D[0] - bx) ** 2 - (D[1] - by) ** 2 - D[2] ** 2 - R_ROCK ** 2
    roots = [np.arctan2(a, b) + s * np.arccos(c / np.hypot(a, b)) for s in (1, -1)]
    r0 = [np.angle(np.exp(1j * r[0])) for r in roots]
    return roots[int(np.argmin(np.abs(r0)))]


def fourbar():
    return kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
                            links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
                                   kincas.Link.bar("rocker", "D", "C", 3)],
                            inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})


def timed(f, runs=5):
    f()  # warm: models, kernels, compiled libraries
    ts = []
    for _ in range(runs):
        t = time.perf_counter()
        out = f()
        ts.append(time.perf_counter() - t)
    return float(np.median(ts)), out


def wrap(a):
    return np.angle(np.exp(1j * np.asarray(a, float)))


def sweeps():
    th = np.linspace(0, 2 * np.pi, N)
    m3, m2 = rssr(), fourbar()
    t3, s3 = timed(lambda: kincas.sweep(m3, {"A.angle": th}, report=["C.x", "C.y", "C.z"], compile=True))
    t2, s2 = timed(lambda: kincas.sweep(m2, {"crank.angle": th}, report=["C.x", "C.y"], compile=True))
    phi = rssr_by_hand(th)
    C = D[None, :] + R_ROCK * np.stack([0 * phi, -np.sin(phi), np.cos(phi)], 1)
    err = np.abs(np.stack([s3["C.x"], s3["C.y"], s3["C.z"]], 1) - C).max() / LC
    return t3, t2, s3.info.get("fast pass"), s2.info.get("fast pass"), err, th, C


def stewart():
    sc = load(ROOT / "examples" / "space_stewart.toml")
    m = sc.mechanism
    keys = [i.key for i in m.inputs]
    l0 = m.parameter("l1") if hasattr(m, "parameter") else 135.24716657845602
    pose0 = kincas.solve(m, {k: l0 for k in keys}, report=[f"P{i}.{c}" for i in range(1, 7) for c in "xyz"])
    guess = {f"P{i}": tuple(pose0[f"P{i}.{c}"] for c in "xyz") for i in range(1, 7)}
    l1 = l0 + 2.0
    t, pose = timed(lambda: kincas.solve(m, {k: l1 for k in keys}, guess=guess, report=["P1.x", "P1.y", "P1.z"]), 9)
    # equal legs: the platform rises straight up, each P keeps its horizontal distance d to
    # its B; z = sqrt(l^2 - d^2)
    B1, P1 = np.array([97.81476007338057, -20.791169081775934, 0.0]), np.array([40.14783638153149, -44.588689528643656, 120.0])
    d2 = float(np.sum((P1[:2] - B1[:2]) ** 2))
    z = math.sqrt(l1 ** 2 - d2)
    err = max(abs(pose["P1.z"] - z), abs(pose["P1.x"] - P1[0]), abs(pose["P1.y"] - P1[1])) / l1
    return t, err, l0


def closed_forms():
    out = {}
    m = load(ROOT / "examples" / "space_double_cardan.toml").mechanism
    th = np.linspace(0, 2 * np.pi, 361)
    s = kincas.sweep(m, {m.inputs[0].key: th}, report=["out.angle"])
    out["double Cardan (out.angle = in.angle)"] = (float(np.abs(wrap(s["out.angle"] - th)).max()), s.info.get("fast pass"))
    m = load(ROOT / "examples" / "space_bennett.toml").mechanism
    u = np.radians(np.linspace(0, 100, 361))
    s = kincas.sweep(m, {m.inputs[0].key: u}, report=["O1.angle", "O3.angle"])
    out["Bennett (th3 = -th1)"] = (float(np.abs(wrap(s["O3.angle"] + s["O1.angle"])).max()), s.info.get("fast pass"))
    return out


def solvespace(th, C_true):
    try:
        from python_solvespace import Entity, ResultFlag, SolverSystem
    except ImportError as e:
        return None, None, f"not installed ({e})"
    def run():
        S = SolverSystem()
        wp = Entity.FREE_IN_3D
        d, d1 = S.add_point_3d(*D), S.add_point_3d(*(D + (1, 0, 0)))
        S.dragged(d, wp), S.dragged(d1, wp)
        b = S.add_point_3d(R_CRANK, 0.0, 0.0)
        S.dragged(b, wp)
        c = S.add_point_3d(*(D + (0, 0, R_ROCK)))
        S.distance(c, d, R_ROCK, wp), S.distance(c, d1, math.sqrt(R_ROCK ** 2 + 1), wp), S.distance(c, b, LC, wp)
        out = np.full((len(th), 3), np.nan)
        for k, t in enumerate(th):
            S.set_params(b.params, (R_CRANK * math.cos(t), R_CRANK * math.sin(t), 0.0))
            if S.solve() == ResultFlag.OKAY:
                out[k] = S.params(c.params)
        return out
    t, C = timed(run, 3)
    return t, float(np.nanmax(np.abs(C - C_true)) / LC), "ok" if np.isfinite(C).all() else "some poses failed"


def main():
    load_avg = os.getloadavg()[0]
    t3, t2, f3, f2, err3, th, C = sweeps()
    tst, est, l0 = stewart()
    cf = closed_forms()
    tss, ess, sss = solvespace(th, C)
    lines = ["# Spatial mechanisms: speed and accuracy (benchmarks/bench_space.py)", "",
             f"Warm medians; load average {load_avg:.1f} on {os.cpu_count()} cores (other processes share the machine).", "",
             "| case | time | per pose | error | notes |", "|---|---|---|---|---|",
             f"| RSSR sweep, {N} poses (kincas.sweep, compiled) | {t3 * 1e3:.1f} ms | {t3 / N * 1e6:.2f} us | {err3:.1e} (C vs by hand, /lc) | fast pass: {f3} |",
             f"| planar four-bar sweep, {N} poses (compiled) | {t2 * 1e3:.1f} ms | {t2 / N * 1e6:.2f} us | | fast pass: {f2} |",
             f"| ratio RSSR / four-bar per pose | {t3 / t2:.2f}x | | | target within 3x |",
             f"| Stewart-Gough FK, one pose (kincas.solve with guess) | {tst * 1e3:.2f} ms | | {est:.1e} (P1 vs sqrt(l^2 - d^2), /l) | legs {l0:.2f} -> {l0 + 2:.2f} mm; target < 1 ms |"]
    for name, (e, f) in cf.items():
        lines.append(f"| {name}, 361 poses | | | {e:.1e} rad | fast pass: {f} |")
    if tss is None:
        lines.append(f"| python-solvespace RSSR | | | | {sss} |")
    else:
        lines.append(f"| python-solvespace RSSR, {N} poses (3D points, distances) | {tss * 1e3:.1f} ms | {tss / N * 1e6:.2f} us | {ess:.1e} (/lc) | {sss}; {tss / t3:.1f}x kincas's time |")
    lines += ["", "Stewart-Gough call: `kincas.solve(m, {\"l1\": l, ..., \"l6\": l}, guess={\"P1\": (x, y, z), ...})`,",
              "the guess the platform's points at the pose before (legs 2 mm shorter)."]
    text = "\n".join(lines) + "\n"
    (HERE / "results_space.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
