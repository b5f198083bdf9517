"""The benchmark harness's own correctness (no timing here): its references agree with each
other and with the geometry, and its classification counts what it says it counts."""
from __future__ import annotations

import doctest
import importlib
import math
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("mpmath")  # the references' 30-digit arithmetic
pytest.importorskip("scipy")
BENCH = Path(__file__).resolve().parent.parent / "benchmarks"
sys.path.insert(0, str(BENCH))

import cases  # noqa: E402
from peers import Run  # noqa: E402
from peers.closed_form import reference, solve_numpy  # noqa: E402
from peers.measure import classify, errors  # noqa: E402
from peers.mp_newton import pairs  # noqa: E402
from peers.mp_newton import reference as newton_reference  # noqa: E402

SMALL = [cases.fourbar(12), cases.slider_crank(12), cases.jansen(12)]


def constraint_violation(case, P) -> float:
    """Largest |distance - length| / L over every link, and every slide point's distance from its line."""
    worst = 0.0
    for p, q, l in pairs(case):
        worst = max(worst, np.abs(np.linalg.norm(P[p] - P[q], axis=1) - l).max())
    for p, t, ang in case.slides:
        w = P[p] - np.asarray(case.ground[t])
        worst = max(worst, np.abs(w[:, 1] * math.cos(ang) - w[:, 0] * math.sin(ang)).max())
    return worst / case.size


@pytest.mark.parametrize("case", SMALL, ids=lambda c: c.name)
def test_closed_forms_keep_every_link_length(case):
    P, _ = reference(case)
    assert constraint_violation(case, P) < 1e-14


@pytest.mark.parametrize("case", SMALL, ids=lambda c: c.name)
def test_numpy_closed_form_agrees_with_the_30_digit_one(case):
    P, V = reference(case)
    Pn, Vn = solve_numpy(case)
    for p in case.moving:
        assert np.abs(Pn[p] - P[p]).max() < 1e-13 * case.size
        assert np.abs(Vn[p] - V[p]).max() < 1e-11 * case.size * case.omega


@pytest.mark.parametrize("case", SMALL, ids=lambda c: c.name)
def test_two_independent_references_agree(case):
    """The closed form and the 30-digit Newton method on the distance equations (the class-III
    reference) give the same positions and velocities on the dyad chains."""
    P, V = reference(case)
    Q, W = newton_reference(case)
    for p in case.moving:
        assert np.abs(Q[p] - P[p]).max() < 1e-15 * case.size
        assert np.abs(W[p] - V[p]).max() < 1e-14 * case.size * case.omega


@pytest.mark.parametrize("case", SMALL + [cases.class3(12)], ids=lambda c: c.name)
def test_reference_velocities_match_central_differences(case):
    h = 1e-6
    Pp, _ = reference(case.with_theta(case.theta + h))
    Pm, _ = reference(case.with_theta(case.theta - h))
    _, V = reference(case)
    for p in case.moving:
        fd = (Pp[p] - Pm[p]) / (2 * h) * case.omega
        assert np.abs(fd - V[p]).max() < 1e-7 * case.size * case.omega


def test_class3_reference_is_a_solution_of_the_triad():
    case = cases.class3(24)
    P, V = reference(case)
    assert np.isfinite(P["P1"]).all()
    assert constraint_violation(case, P) < 1e-14


def test_jansen_uses_the_published_lengths_and_walks():
    case = cases.jansen(72)
    P, _ = reference(case)
    lengths = sorted(x for _, _, ls in case.links for x in ls) + [case.crank[2]]
    assert sorted(lengths) == sorted(v for k, v in cases.JANSEN.items() if k not in "al")
    foot = P["F"]
    assert np.isfinite(foot).all()
    # the foot's path: a long, nearly flat bottom (the stride) and a lift well above it
    low = foot[:, 1] < foot[:, 1].min() + 0.5
    assert np.ptp(foot[low, 0]) > 30 and np.ptp(foot[:, 1]) > 10


def test_classify_counts_a_branch_jump_and_a_false_claim():
    case = cases.stiff_cases(36)[-1]  # the triple rocker: some poses do not assemble
    P, _ = reference(case)
    alt = [reference(case, steps=s)[0] for s in cases.alternatives(case)]
    other = next(O for O in alt if np.nanmax(np.abs(O["B"] - P["B"])) > 1e-3)
    ok = np.isfinite(P["B"]).all(axis=1)
    k = int(np.flatnonzero(ok & (np.linalg.norm(other["B"] - P["B"], axis=1) > 1e-3))[0])
    run_P = {p: P[p].copy() for p in case.outputs}
    run_P["B"][k] = other["B"][k]
    bad = int(np.flatnonzero(~ok)[0])
    run_P["A"][bad], run_P["B"][bad] = (0.0, 0.0), (1.0, 1.0)
    c = classify(case, Run(run_P, None, np.ones(case.theta.size, dtype=bool)), P, alt)
    assert (c["jumps"], c["false"], c["wrong"]) == (1, 1, 0)
    assert c["correct"] == ok.sum() - 1


def test_errors_are_relative_and_ignore_unsolved_poses():
    case = cases.fourbar(6)
    P, V = reference(case)
    run = Run({p: P[p] + [case.size * 1e-9, 0] for p in case.outputs},
              {p: V[p].copy() for p in case.outputs}, np.array([True] * 5 + [False]))
    run.P["B"][5] += 1.0  # an unsolved pose's values do not count
    pe, ve = errors(case, run, P, V)
    assert pe == pytest.approx(1e-9, rel=1e-5) and ve == 0.0


@pytest.mark.parametrize("module", ["cases", "peers", "peers.closed_form", "peers.mp_newton", "peers.measure",
                                    "peers.report", "peers.fsolve_peer", "peers.kincas_runs",
                                    "peers.solvespace_peer", "peers.mechanism_peer"])
def test_doctests_of_the_harness(module):
    mod = importlib.import_module(module)
    if hasattr(mod, "available") and mod.available() is not None:
        pytest.skip(f"{module}: its peer is not installed")
    result = doctest.testmod(mod)
    assert result.failed == 0 and result.attempted > 0


# --- the cases of issue [9] (stability section) ---

BRANCH = {c.name: c for c in cases.branch_cases()}


@pytest.mark.parametrize("name", sorted(BRANCH))
def test_issue9_cases_keep_every_length_where_they_assemble(name):
    case = BRANCH[name]
    P, _ = reference(case)
    ok = np.all([np.isfinite(P[p]).all(axis=1) for p in case.moving], axis=0)
    assert ok.sum() >= 5
    assert constraint_violation(case, {k: v[ok] for k, v in P.items()}) < 1e-14
    # every alternative assembly keeps them too (where it assembles)
    for steps in cases.alternatives(case)[:8]:
        Q, _ = solve_numpy(case, steps=steps)
        fine = np.all([np.isfinite(Q[p]).all(axis=1) for p in case.moving], axis=0)
        if fine.any():
            assert constraint_violation(case, {k: v[fine] for k, v in Q.items()}) < 1e-12


@pytest.mark.parametrize("name", ["antiparallelogram_30deg", "watt2_gaps", "stephenson3_gaps"])
def test_issue9_velocities_match_central_differences(name):
    case, h = BRANCH[name], 1e-6
    Pp, _ = reference(case.with_theta(case.theta + h))
    Pm, _ = reference(case.with_theta(case.theta - h))
    _, V = reference(case)
    for p in case.moving:
        fd = (Pp[p] - Pm[p]) / (2 * h) * case.omega
        fine = np.isfinite(fd).all(axis=1) & np.isfinite(V[p]).all(axis=1)
        assert fine.sum() >= 5
        assert np.abs(fd[fine] - V[p][fine]).max() < 1e-6 * case.size * case.omega


def test_antiparallelogram_is_the_crossed_coupler():
    # the parallelogram point B + (d, 0) reflected across the line B -> D, written here again
    case = BRANCH["antiparallelogram_30deg"]
    P, _ = reference(case)
    B, D = P["A"], np.array([4.0, 0.0])
    e = (D - B) / np.linalg.norm(D - B, axis=1)[:, None]
    w = np.array([4.0, 0.0])
    C = B + 2 * (w * e).sum(1)[:, None] * e - w
    assert np.abs(P["C"] - C).max() < 1e-14 * case.size
    assert np.abs(P["C"] - (B + w)).max() > 1.0  # not the parallelogram
    # one of the two alternatives is the parallelogram at each pose
    alts = [solve_numpy(case, steps=s)[0]["C"] for s in cases.alternatives(case)]
    near = np.min([np.linalg.norm(a - (B + w), axis=1) for a in alts], axis=0)
    assert near.max() < 1e-12 * case.size


def test_chain_is_no_parallelogram_and_stays_far_from_change_points():
    """The growth and overhead chains (benchmarks/cases.py `chain`): every unit a four-bar
    whose crank and rocker differ (no shortcut: each point a circle-circle intersection),
    assembled at every driven angle with the coupler and the rocker at least 50 deg from in
    line, and the numpy closed form equal to the 30-digit one."""
    case = cases.chain(40, 241)
    assert all(st[0] == "rrr" for st in case.steps)
    lengths = {p: ls[0] for _, p, ls in case.links}
    prev_r = case.crank[2]
    for k in range(1, 41):
        r = lengths[(f"G{k}", f"T{k}")]
        assert abs(r - prev_r) > 0.1  # crank and rocker of unit k differ
        prev_r = r
    P, _ = solve_numpy(case)
    prev = P["A"]
    for k in range(1, 41):
        T, G = P[f"T{k}"], np.array(case.ground[f"G{k}"])
        assert np.isfinite(T).all()
        u, v = T - prev, T - G
        sin_t = (u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]) / np.linalg.norm(u, axis=1) / np.linalg.norm(v, axis=1)
        assert np.abs(sin_t).min() > math.sin(math.radians(50)), k
        prev = T
    assert constraint_violation(case, P) < 1e-13
    small = cases.chain(40, 5)
    Pr, Vr = reference(small)
    Pn, Vn = solve_numpy(small)
    for p in small.moving:
        assert np.abs(Pn[p] - Pr[p]).max() < 1e-13 * small.size
        assert np.abs(Vn[p] - Vr[p]).max() < 1e-11 * small.size * small.omega
