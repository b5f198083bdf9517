"""Poses next to a limit (issue [14].5 and .7), against closed forms at 40 digits.

The non-Grashof four-bar crank a = 1, coupler b = 1.9, rocker c = 3, ground d = 4 reaches its
limit where coupler and rocker are in line, |BD| = b + c: cos t* = (a^2 + d^2 - (b + c)^2) /
(2 a d) (law of cosines in A, B, D).

What rounding allows there (the bound the tests hold the solver to). The loop closure g is
evaluated in floating point: at the exact pose it is not 0 but about eps times its terms,
eps L. A Newton that stops at rounding returns the exact pose of a slightly different input,
u + du, where g_u's part along the left null vector of g_q turns that residual into an
input: for this four-bar that part is d|BD|/dt = a d sin t / |BD|, so |du| <= eps L /
(d|BD|/dt) ("backward error": a fraction of an ulp of the loop size, moved onto the input).
Next to the limit everything follows from that du:
- C is off by |dC/dt| |du|, and |dC/dt| grows like delta^-1/2 (delta = t* - t): the
  position's conditioning; 1e-12 of the loop size is within rounding reach down to about
  delta = 1e-8, not closer (the input's own rounding, half an ulp of t, moves C by 1e-12
  of the loop size at 1e-8);
- the velocity is off, relatively, by |v'| / |v| |du| ~ |du| / (2 delta): v ~ delta^-1/2.
Before the fix, a pose 1e-8 short of the limit reached through one 1e-6 short was 5e-10 off
in C (Newton stopped at a residual of 1e-13 that, with sigma_min(g_q) ~ 1e-4, left 1e-9 in
the angles): 400 times the backward error bound.
"""
from __future__ import annotations

import mpmath as mp
import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism

mp.mp.dps = 40
EPS = np.finfo(float).eps
A_, B_, C_, D_ = 1.0, 1.9, 3.0, 4.0
FOURBAR = Mechanism(ground={"A": (0, 0), "D": (D_, 0)},
                    links=[Link.bar("crank", "A", "B", A_), Link.bar("coupler", "B", "C", B_),
                           Link.bar("rocker", "D", "C", C_)],
                    inputs=[Input.angle("crank")], guess={"C": (3.2, 2.5)})
L = FOURBAR.size()
# the limit of the float mechanism (mp.mpf of a float is its exact binary value)
T_LIM = mp.acos((mp.mpf(A_) ** 2 + mp.mpf(D_) ** 2 - (mp.mpf(B_) + mp.mpf(C_)) ** 2) / (2 * mp.mpf(A_) * mp.mpf(D_)))


def fourbar_exact(t):
    """(C, dC/dt, d2C/dt2 . dC/dt / |dC/dt|^2) at crank angle t, in mpmath.

    C by the law of cosines in triangle B, C, D: the angle psi at D between DB and DC has
    cos psi = (c^2 + |BD|^2 - b^2) / (2 c |BD|), and C lies on the guess's side (DB turned
    clockwise by psi). Velocity from |C - B| = b differentiated: with C = D + c (cos phi,
    sin phi), phi' = (C - B).B' / ((C - B).(c n)), n = (-sin phi, cos phi), B' = a (-sin t,
    cos t). The relative rate of change of |C'| (for the velocity's conditioning) by
    differentiating that closed form once more, numerically at 40 digits."""
    def pos(t):
        Bx, By = A_ * mp.cos(t), A_ * mp.sin(t)
        ex, ey = Bx - D_, By
        r = mp.sqrt(ex * ex + ey * ey)
        cpsi = (C_ ** 2 + r * r - mp.mpf(B_) ** 2) / (2 * C_ * r)
        spsi = mp.sqrt(max(1 - cpsi ** 2, mp.mpf(0)))
        ux, uy = ex / r, ey / r
        return mp.matrix([D_ + C_ * (ux * cpsi + uy * spsi), C_ * (uy * cpsi - ux * spsi)]), (Bx, By)

    def vel(t):
        C, (Bx, By) = pos(t)
        phi = mp.atan2(C[1], C[0] - D_)
        n = (-mp.sin(phi), mp.cos(phi))
        dB = (-A_ * mp.sin(t), A_ * mp.cos(t))
        w = (C[0] - Bx, C[1] - By)
        dphi = (w[0] * dB[0] + w[1] * dB[1]) / (C_ * (w[0] * n[0] + w[1] * n[1]))
        return mp.matrix([C_ * dphi * n[0], C_ * dphi * n[1]])

    t = mp.mpf(t)
    C, _ = pos(t)
    v = vel(t)
    dlog = mp.diff(lambda s: mp.norm(vel(s)), t) / mp.norm(v)
    return C, v, dlog


def backward_bound(t):
    """The input error that a residual of eps L amounts to: eps L / (d|BD|/dt)."""
    t = mp.mpf(t)
    r = mp.sqrt((D_ - mp.cos(t)) ** 2 + mp.sin(t) ** 2)
    return EPS * L / float(A_ * D_ * mp.sin(t) / r)


def check_near_limit(sw, U):
    """Every regular pose (no flag) within the rounding bounds of the module's text; every
    flagged pose with null velocities."""
    assert sw.ok.all()
    for k, t in enumerate(U):
        if sw.flags[k] is not None:
            assert np.isnan(sw["C.vx"][k]) and np.isnan(sw["C.vy"][k])
            continue
        C, v, dlog = fourbar_exact(t)
        delta = float(T_LIM - mp.mpf(t))
        du = backward_bound(t)
        speed = float(mp.norm(v))
        err = float(mp.sqrt((sw["C.x"][k] - C[0]) ** 2 + (sw["C.y"][k] - C[1]) ** 2))
        assert err <= speed * du + 4 * EPS * L, (delta, err)
        if delta >= 1e-7:
            assert err <= 1e-12 * L, (delta, err)
        verr = float(mp.sqrt((sw["C.vx"][k] - v[0]) ** 2 + (sw["C.vy"][k] - v[1]) ** 2)) / speed
        assert verr <= abs(float(dlog)) * du + 64 * EPS, (delta, verr)


PATHS = {
    "1e-6 then 1e-8": [1e-6, 1e-8],
    "1e-8 directly": [1e-8],
    "decades": [1e-2, 1e-4, 1e-6, 1e-8],
    "geometric": list(np.geomspace(1e-3, 1e-9, 25)),
    "linear": list(np.linspace(1e-3, 1e-8, 30)),
}


@pytest.mark.parametrize("method", ["fast", "careful"])
@pytest.mark.parametrize("path", sorted(PATHS))
def test_fourbar_next_to_its_limit_to_rounding_whatever_the_path(path, method):
    U = np.array([float(T_LIM - mp.mpf(d)) for d in PATHS[path]])
    sw = kincas.sweep(FOURBAR, {"crank.angle": U}, report=["C.x", "C.y", "C.vx", "C.vy"], method=method)
    assert np.all(sw.residual <= 1e-12)
    check_near_limit(sw, U)
    if path == "1e-6 then 1e-8":  # the case, to the target
        C, _, _ = fourbar_exact(U[-1])
        assert abs(sw["C.x"][-1] - C[0]) <= 1e-12 * L and abs(sw["C.y"][-1] - C[1]) <= 1e-12 * L


def test_newton_onto_a_double_root_stops_at_rounding():
    """The core Newton on x^2 - d = 0 with d = 1e-16 (roots +-1e-8, g' = 2e-8 there):
    a residual of 1e-13 is reached 5e-6 from the root, where the old rule stopped; Newton
    goes on while its steps shrink and ends where rounding of g (~1e-32) allows, far
    closer than that."""
    from kincas.core.newton import newton
    d = 1e-16
    F = lambda x: (np.array([x[0] * x[0] - d]), np.array([[2 * x[0]]]))
    r = newton(F, np.array([1e-3]), np.ones(1), np.ones(1))
    assert r.ok and abs(r.x[0] - 1e-8) <= 1e-8 * 1e-12


# --- item 7: crossings inside one step, and poses a hair past a limit ---


def fourbar(b):
    return Mechanism(ground={"A": (0, 0), "D": (D_, 0)},
                     links=[Link.bar("crank", "A", "B", A_), Link.bar("coupler", "B", "C", b),
                            Link.bar("rocker", "D", "C", C_)],
                     inputs=[Input.angle("crank")], guess={"C": (3.2, 2.5)})


def gap_edges(b):
    """The crank angles (in (0, 2 pi)) where |BD| = b + c: no assembly between them."""
    t = float(mp.acos((A_ ** 2 + D_ ** 2 - (mp.mpf(b) + C_) ** 2) / (2 * A_ * D_)))
    return t, 2 * np.pi - t


@pytest.mark.parametrize("method", ["fast", "careful"])
def test_a_gap_inside_one_step_is_flagged_and_located(method):
    """b = 1.999: |BD| exceeds b + c = 4.999 for |t - pi| < 0.05. Steps of 0.13 rad put the
    whole gap inside one step, between two solved poses: both limits are located to the
    law of cosines, the poses on either side flagged "limit", and the pose after the gap is
    a "resume" (before, the sweep went straight on: nothing said)."""
    lo, hi = gap_edges(1.999)
    th = np.r_[lo - 0.02 - 0.13 * np.arange(5, 0, -1), lo - 0.02, hi + 0.03 + 0.13 * np.arange(4)]
    k = 5  # the pose before the gap
    sw = kincas.sweep(fourbar(1.999), {"crank.angle": th}, report=["C.x", "C.y", "C.vx"], method=method)
    assert sw.ok.all() and np.all(sw.residual <= 1e-12)
    assert sw.flags[k] == "limit" and sw.flags[k + 1] == "limit"
    assert all(f is None for i, f in enumerate(sw.flags) if i not in (k, k + 1))
    limits = sorted(e["inputs"]["crank.angle"] for e in sw.events if e["kind"] == "limit")
    assert len(limits) == 2 and abs(limits[0] - lo) < 1e-9 and abs(limits[1] - hi) < 1e-9
    assert [e["pose"] for e in sw.events if e["kind"] == "resume"] == [k + 1]


@pytest.mark.parametrize("b", [1.9995, 1.9999])
def test_every_gap_a_coarse_sweep_steps_over_is_flagged(b):
    """Five turns in steps of 7.3 degrees over gaps of 4.1 and 1.8 degrees: wherever a gap
    falls inside one step between two solved poses (the law of cosines says where), a limit
    event lies in that step."""
    lo, hi = gap_edges(b)
    th = 0.3 + np.radians(7.3) * np.arange(250)
    sw = kincas.sweep(fourbar(b), {"crank.angle": th}, report=["C.x"])
    crossings = 0
    for k in range(len(th) - 1):
        a0, a1 = th[k] % (2 * np.pi), th[k + 1] % (2 * np.pi)
        if not (sw.ok[k] and sw.ok[k + 1] and a0 < lo and hi < a1):
            continue
        crossings += 1
        assert any(e["kind"] == "limit" and th[k] <= e["inputs"]["crank.angle"] <= th[k + 1] for e in sw.events), k
        assert sw.flags[k] and sw.flags[k + 1]
    assert crossings >= 3


SLIDER = Mechanism(ground={"O": (0, 0)},
                   links=[Link.bar("crank", "O", "A", 1), Link.bar("rod", "A", "B", 1)],
                   slides=[kincas.Slide("B", "ground", through=(0, 0.5), name="slider")],
                   inputs=[Input.angle("crank")], guess={"B": (1.0, 0.5)})


@pytest.mark.parametrize("method", ["fast", "careful"])
@pytest.mark.parametrize("past", [1e-15, 1e-14, 1e-13, 1e-12])
def test_a_hair_past_a_limit_is_no_ordinary_pose(past, method):
    """Slider-crank r = l = 1, slide y = 0.5: B is reachable while sin t >= -0.5, so the crank
    turning down stops at t* = -pi/6 (rod square to the slide). Past it by 1e-15 .. 1e-12 no
    assembly exists; the residual of the nearest pose is below ACCEPT all the same. So the
    pose is either "no assembly", or solved within reach of the limit: flagged "limit", its
    velocities null (before: "ok", unflagged, B.vx ~ 1e7) and B at the limit's position
    to sqrt(past) (the rod's angle moves by sqrt(2 past) per past)."""
    t_lim = -mp.pi / 6
    u = float(t_lim - mp.mpf(past))
    assert t_lim - mp.mpf(u) > 0  # past it, as a float
    sw = kincas.sweep(SLIDER, {"crank.angle": [0.0, -0.3, -0.5, u]},
                      report=["B.x", "B.vx", "rod.omega"], method=method)
    if sw.status[-1] == "ok":
        assert sw.flags[-1] == "limit"
        assert np.isnan(sw["B.vx"][-1]) and np.isnan(sw["rod.omega"][-1])
        assert abs(sw["B.x"][-1] - float(mp.cos(t_lim))) <= 1e-6
        assert any(e["kind"] == "limit" and e["pose"] == 3 for e in sw.events)
    else:
        assert sw.status[-1] == "no assembly"
    assert sw.status[:3].tolist() == ["ok"] * 3 and all(f is None for f in sw.flags[:3])
