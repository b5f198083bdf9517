"""The fast kernel on chained mechanisms (runs of groups, kincas/core/group_kernel.py) gives
the closed forms' positions and velocities, and the careful path's poses, branches and flags.

A chain here: a crank O-A (length 1), then n dyads, dyad k placing T_k at distance c from
T_{k-1} (T_0 = A) and r from the ground pivot G_k = (4k, 0), on the left of T_{k-1} -> G_k.
Its closed form (written here, not kincas's): T_k is the intersection of two circles, and its
velocity solves the two differentiated distance equations by Cramer's rule."""
from __future__ import annotations

import math

import numpy as np
import pytest

import kincas
from kincas.core.fast import sweeper_for
from kincas.core.kernel import GROUP_RUN, GROUPS_APART


def _unit(v, k):
    """Unit k's length: v, or v's entries in turn."""
    return v[(k - 1) % len(v)] if np.ndim(v) else v


def chain(n, c, r, t0, scale=1.0, origin=(0.0, 0.0)):
    """(c, r: one length for every unit, or lengths taken in turn; every length times
    `scale`, every point moved by `origin`)."""
    ox, oy = origin
    links = [kincas.Link.bar("crank", "O", "A", scale)]
    for k in range(1, n + 1):
        links += [kincas.Link.bar(f"cp{k}", "A" if k == 1 else f"T{k - 1}", f"T{k}", scale * _unit(c, k)),
                  kincas.Link.bar(f"rk{k}", f"G{k}", f"T{k}", scale * _unit(r, k))]
    ground = {"O": (ox, oy), **{f"G{k}": (ox + 4.0 * k * scale, oy) for k in range(1, n + 1)}}
    P, _ = closed_form(n, c, r, np.array([t0]), 1.0, scale, origin)
    guess = {f"T{k}": tuple(P[k][0]) for k in range(1, n + 1)}
    return kincas.Mechanism(ground=ground, links=links, inputs=[kincas.Input.angle("crank")], guess=guess)


def closed_form(n, c, r, t, w, scale=1.0, origin=(0.0, 0.0)):
    """{k: (N, 2)} positions and velocities of T_k (k = 0: A) at crank angles t, rate w."""
    o = np.asarray(origin, dtype=float)
    P = {0: o + scale * np.stack([np.cos(t), np.sin(t)], 1)}
    V = {0: w * scale * np.stack([-np.sin(t), np.cos(t)], 1)}
    for k in range(1, n + 1):
        c_, r_ = scale * _unit(c, k), scale * _unit(r, k)
        A1, V1, A2 = P[k - 1], V[k - 1], o + np.array([4.0 * k * scale, 0.0])
        d_ = A2 - A1
        d = np.hypot(d_[:, 0], d_[:, 1])
        e = d_ / d[:, None]
        along = (d * d + c_ * c_ - r_ * r_) / (2 * d)
        h = np.sqrt(c_ * c_ - along * along)
        T = A1 + along[:, None] * e + h[:, None] * np.stack([-e[:, 1], e[:, 0]], 1)  # on the left
        a, b = T - A1, T - A2  # (T - A1).(V - V1) = 0, (T - A2).V = 0
        ra, det = (a * V1).sum(1), a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
        V[k] = np.stack([ra * b[:, 1], -b[:, 0] * ra], 1) / det[:, None]
        P[k] = T
    return P, V


def names(n):
    return [f"T{k}.{q}" for k in range(1, n + 1) for q in ("x", "y", "vx", "vy")]


@pytest.mark.parametrize("compile", [True, False])
def test_chain_in_runs_of_groups_matches_the_closed_form(compile):
    # not a parallelogram: q(u) is not linear, Newton corrects every pose; the last run of
    # groups is shorter than the others
    n = GROUPS_APART + GROUP_RUN // 2
    c, r, w = 4.0, 1.05, 2.0
    t = np.radians(np.linspace(60, 120, 181))
    m = chain(n, c, r, t[0])
    model = kincas.model_of(m)
    assert sweeper_for(model, tuple(names(n)), compile).functions[2].is_a("MXFunction")  # in runs
    P, V = closed_form(n, c, r, t, w)
    assert all(np.isfinite(P[k]).all() for k in P)  # assembles everywhere: a fair test
    sw = kincas.sweep(m, {"crank.angle": t}, rates={"crank.angle": w}, report=names(n), compile=compile)
    assert sw.ok.all() and all(f is None for f in sw.flags)
    size = 4.0 * n
    for k in range(1, n + 1):
        got = np.stack([sw[f"T{k}.x"], sw[f"T{k}.y"]], 1)
        assert np.abs(got - P[k]).max() <= 1e-12 * size, k
        vel = np.stack([sw[f"T{k}.vx"], sw[f"T{k}.vy"]], 1)
        assert np.abs(vel - V[k]).max() <= 1e-11 * np.abs(V[k]).max(), k


def test_fourbar_through_its_change_points_matches_the_closed_form():
    # the parallelogram 1, 4, 1, 4 through 180, 360, 540 deg (change points: every pivot in
    # line), poses on them and beside them; C = D + (cos t, sin t), velocity w (-sin t, cos t)
    t = np.radians(np.r_[np.linspace(30, 570, 217), 180.0 + 1e-7, 360.0 - 1e-7])
    t.sort()
    w = 1.5
    m = chain(1, 4.0, 1.0, t[0])
    sw = kincas.sweep(m, {"crank.angle": t}, rates={"crank.angle": w}, report=names(1), compile=True)
    assert sw.info["fast pass"] == "compiled" and sw.ok.all()
    P = np.stack([4.0 + np.cos(t), np.sin(t)], 1)
    V = w * np.stack([-np.sin(t), np.cos(t)], 1)
    at = np.array([f == "change point" for f in sw.flags])
    turn = np.degrees(t) / 180.0
    assert np.array_equal(at, np.abs(turn - np.round(turn)) < 1e-8)  # on the change points, 1e-7 deg beside
    err = np.abs(np.stack([sw["T1.x"], sw["T1.y"]], 1) - P).max(1)
    assert err[~at].max() <= 1e-12 * 4.0
    # a pose 1e-7 deg from a change point is a double root to rounding: Newton (the careful
    # path's, which flagged poses go to) ends sqrt(rounding) away, on the branch
    assert err[at].max() <= 1e-8 * 4.0
    vel = np.stack([sw["T1.vx"], sw["T1.vy"]], 1)
    assert np.abs(vel[~at] - V[~at]).max() <= 1e-11 * w
    assert np.all(np.isnan(vel[at]) | (np.abs(vel[at] - V[at]) <= 1e-6 * w))  # the branch's, or null


@pytest.mark.parametrize("c, r, lo, hi", [(4.0, 1.0, 150.0, 210.0), (4.0, 1.05, 60.0, 120.0)])
def test_kernel_and_careful_path_agree_on_every_pose_of_a_chain(c, r, lo, hi):
    # the parallelogram chain through 180 deg (every group at a change point at once), and a
    # chain that Newton must correct: the same poses, branches (det's sign per group), flags
    n = GROUPS_APART + 1
    t = np.radians(np.linspace(lo, hi, 25))
    m = chain(n, c, r, t[0])
    fast = kincas.sweep(m, {"crank.angle": t}, report=names(n), compile=True)
    careful = kincas.sweep(m, {"crank.angle": t}, report=names(n), method="careful")
    assert fast.info["fast pass"] == "compiled"
    assert list(fast.status) == list(careful.status) and list(fast.flags) == list(careful.flags)
    assert [(e["kind"], e["pose"]) for e in fast.events] == [(e["kind"], e["pose"]) for e in careful.events]
    ok = fast.ok
    assert np.abs(fast.q[ok] - careful.q[ok]).max() <= 1e-12 * 4.0 * n
    model = kincas.model_of(m)
    p = np.zeros(0)
    for k in np.flatnonzero(ok):
        if fast.flags[k] is None:
            J1, J2 = (model.jac(q[k], t[k:k + 1], p) for q in (fast.q, careful.q))
            for b in model.blocks:
                s1 = np.sign(np.linalg.det(J1[np.ix_(b.rows, b.cols)]))
                assert s1 == np.sign(np.linalg.det(J2[np.ix_(b.rows, b.cols)])) != 0
    for name in names(n):
        a, b = fast[name][ok], careful[name][ok]
        both = np.isfinite(a) & np.isfinite(b)
        assert np.array_equal(np.isfinite(a), np.isfinite(b)), name
        assert np.abs(a[both] - b[both]).max(initial=0.0) <= 1e-9 * max(1.0, np.abs(b[both]).max(initial=0.0)), name
    if r == 1.0:
        assert fast.flags[12] == "change point" and math.isclose(t[12], math.pi)


@pytest.mark.parametrize("scale, origin", [(1e-6, (0.0, 0.0)), (1e6, (0.0, 0.0)), (1.0, (1e6, -1e6)),
                                           (1e-6, (1e-3, 2e-3))])
def test_chain_of_four_bars_that_are_no_parallelograms_at_any_scale(scale, origin, monkeypatch):
    """The benchmarks' chain (rockers 1.1 and 1 in turn, couplers 4, pivots 4 apart: every
    point a circle intersection), tiny, huge, and far from the origin (1e6 away with links of
    1: positions carry 6 fewer digits, relative to the size), written group by group: every
    pose taken by the kernel, with its third-order prediction taking the dense poses with no
    Newton step, at the closed form's positions and velocities."""
    monkeypatch.setattr("kincas.core.kernel.GROUPS_APART", 4)  # in runs of groups, compiled fast
    n, w = 6, 3.0
    t = np.radians(np.linspace(60, 120, 3601))
    rk = (1.1, 1.0)
    m = chain(n, 4.0, rk, t[0], scale, origin)
    P, V = closed_form(n, 4.0, rk, t, w, scale, origin)
    assert all(np.isfinite(P[k]).all() for k in P)
    assert sweeper_for(kincas.model_of(m), tuple(names(n)), True).functions[2].is_a("MXFunction")
    sw = kincas.sweep(m, {"crank.angle": t}, rates={"crank.angle": w}, report=names(n), compile=True)
    assert sw.info["fast pass"] == "compiled" and sw.ok.all() and all(f is None for f in sw.flags)
    size = 4.0 * n * scale
    far = 1.0 + math.hypot(*origin) / size  # rounding of coordinates that large
    for k in range(1, n + 1):
        got = np.stack([sw[f"T{k}.x"], sw[f"T{k}.y"]], 1)
        assert np.abs(got - P[k]).max() <= 1e-12 * size * far, k
        vel = np.stack([sw[f"T{k}.vx"], sw[f"T{k}.vy"]], 1)
        assert np.abs(vel - V[k]).max() <= 1e-11 * np.abs(V[k]).max() * far, k
    assert (sw.iterations[3:] == 0).mean() > 0.9  # kF at the prediction (see test_fast_predict.py)
