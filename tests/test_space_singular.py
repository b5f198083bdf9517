"""Spatial mechanisms at and near singular positions: a tall (redundant) system swept into a
limit, and the careful path's watch of spatial groups (issue [16]).

Every expected number is independent of kincas: the spherical four-bar's limit and its
output point from spherical trigonometry, the RSSR's limit from its closed form (test_space).
"""
import numpy as np
import pytest

import kincas
from kincas import Body, Input, Joint, SpatialMechanism
from test_space import D, R_CRANK, R_ROCK, rssr, rssr_closed

# --- a spherical four-bar (a tall system: Gruebler's count -2) swept into its limit ---
# arcs on the unit sphere: crank A1 (from its axis z to B), coupler A2 (B to C), output
# A3 (its axis a4 to C), frame A4 (z to a4)
RS = 100.0
A1, A2, A3, A4 = np.radians([50.0, 60.0, 45.0, 40.0])
TH0 = np.radians(90.0)  # the crank's azimuth in the drawing (input angle 0)
AX4 = np.array([np.sin(A4), 0.0, np.cos(A4)])


def b_hat(th):
    return np.array([np.sin(A1) * np.cos(th), np.sin(A1) * np.sin(th), np.cos(A1)])


def c_hat(th, sign=1.0):
    """C / RS from C.B = cos A2, C.a4 = cos A3, |C| = 1: C = x B + y a4 + z (B x a4)."""
    b = b_hat(th)
    g = b @ AX4
    x, y = np.linalg.solve([[1.0, g], [g, 1.0]], [np.cos(A2), np.cos(A3)])
    n, v = np.cross(b, AX4), x * b + y * AX4
    return v + sign * np.sqrt(max(1.0 - v @ v, 0.0) / (n @ n)) * n


def spherical_fourbar():
    t = lambda v: tuple(float(c) for c in v)
    B0, C0 = RS * b_hat(TH0), RS * c_hat(TH0)
    return SpatialMechanism(
        ground={"O": (0.0, 0.0, 0.0)},
        bodies=[Body("crank", {"O": (0, 0, 0), "B": t(B0)}), Body("coupler", {"B": t(B0), "C": t(C0)}),
                Body("output", {"O": (0, 0, 0), "C": t(C0)})],
        joints=[Joint("revolute", "O", axis=(0, 0, 1), bodies=("ground", "crank"), name="input"),
                Joint("revolute", "O", axis=t(AX4), bodies=("ground", "output"), name="out"),
                Joint("revolute", "B", axis=t(B0 / RS)), Joint("revolute", "C", axis=t(C0 / RS))],
        inputs=[Input.joint("input")], guess={"C": t(C0)})


@pytest.mark.parametrize("method", ["fast", "careful"])
def test_tall_spherical_fourbar_swept_into_its_limit(method):
    # The crank's tip B lies at arc d from the output's axis, cos d = cos A1 cos A4 + sin A1
    # sin A4 cos th; the coupler and output reach C only while d >= |A2 - A3|: the limit
    # (coupler and output folded onto one great circle, g_q loses rank beyond its three
    # redundant rows) is at cos th* = (cos(A2 - A3) - cos A1 cos A4) / (sin A1 sin A4).
    m = spherical_fourbar()
    assert not kincas.model_of(m).square  # tall: redundant joints
    th_star = np.arccos((np.cos(A2 - A3) - np.cos(A1) * np.cos(A4)) / (np.sin(A1) * np.sin(A4)))
    u_star = th_star - TH0
    u = np.linspace(0.0, -np.pi / 2, 91)[:78]  # 74 poses before the limit, 4 beyond it
    assert u[74] > u_star > u[75]
    names = ["B.x", "B.y", "B.z", "C.x", "C.y", "C.z"]
    s = kincas.sweep(m, {"input.angle": u}, report=names, method=method)
    ok = s.ok
    assert ok[:75].all() and not ok[75:].any()
    assert set(s.status[75:]) == {"no assembly"} and np.isnan(s["C.x"][75:]).all()  # null, with a reason
    # the limit flagged at the last pose before it and located at th* (closed form)
    lim = [e for e in s.events if e["kind"] == "limit"]
    assert len(lim) == 1 and lim[0]["pose"] == 74
    assert abs(lim[0]["inputs"]["input.angle"] - u_star) < 1e-9
    assert s.flags[74] == "limit" and not any(s.flags[:74])
    # every solved pose on the drawing's branch (no silent change to the mirror assembly),
    # and closing its loops: independent residuals from the reported points
    B = np.stack([s[n] for n in names[:3]], 1)[ok]
    C = np.stack([s[n] for n in names[3:]], 1)[ok]
    assert np.abs(C - RS * np.array([c_hat(TH0 + v) for v in u[ok]])).max() < 1e-10 * RS
    assert np.abs(B - RS * np.array([b_hat(TH0 + v) for v in u[ok]])).max() < 1e-10 * RS
    res = np.abs(np.concatenate([
        np.linalg.norm(C, axis=1) / RS - 1, (B * C).sum(1) / RS ** 2 - np.cos(A2),
        C @ AX4 / RS - np.cos(A3), B[:, 2] / RS - np.cos(A1)]))
    assert res.max() < 1e-12 and np.nanmax(s.residual[ok]) < 1e-12


# --- the careful path's watch of spatial groups ---


def _count_searches(monkeypatch):
    import kincas.analysis.singular as singular
    calls, locate = [0], singular.locate_singular

    def counted(*a, **k):
        calls[0] += 1
        return locate(*a, **k)
    monkeypatch.setattr(singular, "locate_singular", counted)
    return calls


def test_rssr_far_from_singular_positions_is_not_searched_at_every_step(monkeypatch):
    # The RSSR of test_space transmits poorly (the coupler 17-29 deg from the rocker's
    # motion at C): its rocker group's watch measure stays near 0.2-0.4, below WATCH, at
    # every pose, yet no singular position is anywhere near (a crank-rocker: the closed form
    # has a real root at every crank angle). The careful path searched one at every step
    # (locate_singular per step: ~10 s for 360 poses); a spatial group is searched only where
    # the step could reach a singular block (kincas/analysis/watch.py: within_reach).
    from kincas.analysis.continuation import watch_conditioning
    from kincas.core.tolerances import WATCH
    m = rssr()
    model = kincas.model_of(m)
    th = np.linspace(0, 2 * np.pi, 73)
    calls = _count_searches(monkeypatch)
    s = kincas.sweep(m, {"A.angle": th}, report=["C.y", "C.z"], method="careful")
    assert s.ok.all() and not any(s.flags) and not s.events
    phi = rssr_closed(th)
    assert np.abs(s["C.y"] - (D[1] - R_ROCK * np.sin(phi))).max() < 1e-10 * R_ROCK
    p = np.array([v for _, v in m.parameters], float)
    w = watch_conditioning(model, np.array([model.jac(q, np.array([t]), p) for q, t in zip(s.q, th)]), m.size())
    assert (w.min(axis=1) < WATCH).all()  # every pose under the old rule's watch
    assert calls[0] == 0


def test_watch_still_searches_a_step_ending_next_to_a_limit(monkeypatch):
    # With a 140 mm coupler the RSSR's rocker meets a limit where c / rho = 1 in the closed
    # form (test_space.rssr_closed): a careful sweep finds it at its closed-form place, and
    # the step into the last pose before it is within reach of the singular block.
    from kincas.analysis.watch import within_reach
    from scipy.optimize import brentq
    lc = 140.0
    m = rssr(lc=lc)
    model = kincas.model_of(m)

    def ratio(t):
        a, b = -2 * R_ROCK * (D[1] - R_CRANK * np.sin(t)), 2 * R_ROCK * D[2]
        c = lc ** 2 - (D[0] - R_CRANK * np.cos(t)) ** 2 - (D[1] - R_CRANK * np.sin(t)) ** 2 - D[2] ** 2 - R_ROCK ** 2
        return c / np.hypot(a, b) - 1.0
    grid = np.linspace(0.0, 2 * np.pi, 721)
    r = ratio(grid)  # c / rho - 1 < 0: the rocker reaches C
    up = int(np.flatnonzero((r[:-1] < 0) & (r[1:] >= 0))[0])  # assemblies end as th grows
    t_star = brentq(ratio, grid[up], grid[up + 1], xtol=1e-15)
    th = np.linspace(t_star - 0.5, t_star + 0.02, 27)  # 26 poses before it, one beyond
    s = kincas.sweep(m, {"A.angle": th}, report=["C.y"], method="careful")
    lim = [e for e in s.events if e["kind"] == "limit"]
    assert lim, s.events
    k = lim[0]["pose"]
    assert s.ok[:26].all() and not s.ok[26] and k == 25 and s.flags[25] == "limit"
    assert abs(lim[0]["inputs"]["A.angle"] - t_star) < 1e-8
    j = k - 1
    J = [model.jac(s.q[i], np.array([th[i]]), np.array([lc])) for i in (j, k)]
    rocker = max(range(len(model.blocks)), key=lambda i: len(model.blocks[i].cols))
    assert within_reach(model, J[0], J[1], m.size(), rocker)
    assert np.isfinite(s["C.y"][s.ok]).all() and np.isnan(s["C.y"][~s.ok]).all()
