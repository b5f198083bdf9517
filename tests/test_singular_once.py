"""One singular-position locator and one Newton (issue [15]): `polish_singular` (the pose at
fixed inputs where a group is singular) solves the same extended system as `locate_singular`
(kincas/core/limits.py), with the same null-direction routine and kincas/core/newton.py's
stopping rule; `scatter.newton_starts` and the designs' batched loop stop by that rule too.
Answers against closed forms in mpmath.

The four-bar crank a = 1, coupler b = 1.9, rocker c = 3, ground d = 4 is singular where
coupler and rocker are in line: C = D + c (B - D) / |B - D|, at crank angle t* with
cos t* = (a^2 + d^2 - (b + c)^2) / (2 a d).
"""
from __future__ import annotations

import mpmath as mp
import numpy as np

from kincas import Input, Link, Mechanism
from kincas.core.limits import locate_singular, null_direction, polish_singular, scaled_jacobians
from kincas.core.numeric import compile
from test_near_limits import B_, C_, D_, FOURBAR, L, T_LIM  # the same four-bar

P = np.zeros(0)


def in_line(t):
    """C with coupler and rocker in line, the crank at t (float t, exactly, in mpmath)."""
    t = mp.mpf(t)
    bx, by = mp.cos(t), mp.sin(t)
    r = mp.sqrt((bx - D_) ** 2 + by ** 2)
    return D_ + C_ * (bx - D_) / r, C_ * by / r


def point_c(model, q, u):
    return model.points(q, u, P)[:, FOURBAR.moving_points.index("C")]


def solved(model, t):
    u = np.array([t])
    return model.newton(model.initial_q(u, P, dict(FOURBAR.guess), L), u, P, L).q, u


def test_polish_onto_the_singular_position_at_fixed_inputs():
    model = compile(FOURBAR)
    t = float(T_LIM)
    q, u = solved(model, t - 1e-4)  # an ordinary pose nearby, then the input at the limit
    got = polish_singular(model, q, u + 1e-4, P, L, [0])
    assert got is not None
    cx, cy = in_line(t)
    c = point_c(model, got, u + 1e-4)
    assert abs(c[0] - float(cx)) <= 1e-13 * L and abs(c[1] - float(cy)) <= 1e-13 * L
    assert np.abs(model.residual(got, u + 1e-4, P)).max() <= 1e-15 * L * 4


def test_polish_refuses_a_pose_only_near_one():
    model = compile(FOURBAR)
    for delta in (1e-3, 1e-6, 1e-9):
        q, u = solved(model, float(T_LIM) - delta)
        assert polish_singular(model, q, u, P, L, [0]) is None, delta


def test_locate_and_polish_agree():
    """locate_singular moves the input to t*, polish_singular then stays there."""
    model = compile(FOURBAR)
    q, u = solved(model, 2.6)
    q1, u1, s = locate_singular(model, q, u, P, L, [1.0])
    assert abs(u1[0] - float(T_LIM)) <= 1e-14
    q2 = polish_singular(model, q1, u1, P, L, [0])
    assert q2 is not None and np.abs(q2 - q1).max() <= 1e-12


def test_null_direction_is_the_null_vector():
    model = compile(FOURBAR)
    q1, u1, _ = locate_singular(model, *solved(model, 2.6), P, L, [1.0])
    J, _ = scaled_jacobians(model, q1, u1, P, L)
    cq = model.column_scale(L)
    rows, cols = np.arange(model.ng), np.arange(model.nq)
    v = null_direction(J, rows, cols, cq)
    assert np.abs(model.jac(q1, u1, P) @ v).max() <= 1e-12 * np.abs(v).max() * L


def assemblies(t):
    """The two positions of C at crank angle t (circles about B, radius b, and D, radius c)."""
    t = mp.mpf(t)
    bx, by = mp.cos(t), mp.sin(t)
    dx, dy = D_ - bx, -by
    d = mp.sqrt(dx * dx + dy * dy)
    x = (d * d + B_ ** 2 - C_ ** 2) / (2 * d)
    h = mp.sqrt(B_ ** 2 - x * x)
    return [(float(bx + (x * dx - s * h * dy) / d), float(by + (x * dy + s * h * dx) / d)) for s in (1, -1)]


def test_newton_starts_end_on_the_assemblies():
    """Scattered starts, the batched Newton with the one stopping rule: every start that it
    solves lies on one of the two assemblies to rounding, both are found, and a start
    stops as soon as its step is negligible (never more iterations than the careful Newton
    needs plus one)."""
    from kincas.core.scatter import newton_starts
    model = compile(FOURBAR)
    u = np.array([0.9])
    rng = np.random.default_rng(3)
    Q = rng.uniform(-np.pi, np.pi, (40, model.nq))
    X, r = newton_starts(model, Q, u, P, 60)
    ok = np.isfinite(r) & (r <= 1e-12)
    assert ok.sum() >= 10
    exact = assemblies(0.9)
    found = set()
    for x in X[ok]:
        c = point_c(model, x, u)
        k = int(np.argmin([np.hypot(c[0] - e[0], c[1] - e[1]) for e in exact]))
        assert np.hypot(c[0] - exact[k][0], c[1] - exact[k][1]) <= 1e-13 * L
        found.add(k)
    assert found == {0, 1}
    # ... and stops: 60 iterations allowed, a converged start stays put afterwards
    X2, r2 = newton_starts(model, X[ok], u, P, 60)
    assert np.abs(X2 - X[ok]).max() <= 1e-13


def test_designs_without_a_compiler_on_the_closed_form():
    """The designs' batched loops (continuation in the parameters for the first poses, the
    fast pass over the poses), stopping by the one rule: C of every pose of every design on
    the circle intersection nearest the nominal's branch, to 1e-12 of the size."""
    import kincas
    m = Mechanism(parameters={"a2": 25.0, "a3": 62.25, "a4": 90.0, "a5": 70.0},
                  ground={"A": (0, 0), "D": ("a5", 0)},
                  links=[Link.bar("crank", "A", "B", "a2"), Link.bar("coupler", "B", "C", "a3"),
                         Link.bar("rocker", "D", "C", "a4")],
                  inputs=[Input.angle("crank")], guess={"C": (40, 80)})
    designs = np.array([[25.0, 90.0, 70.0], [35.0, 90.0, 70.0], [30.0, 85.0, 72.0], [28.0, 88.0, 66.0]])
    th = np.linspace(np.pi / 2, np.pi / 2 + 2 * np.pi, 37)
    r = kincas.sweep_designs(m, designs, {"crank.angle": th}, names=["a2", "a4", "a5"],
                             report=["C.x", "C.y"], compile=False, workers=1)
    assert r.design_ok.all()
    for d, (a2, a4, a5) in enumerate(designs):
        for k, t in enumerate(th):
            bx, by = a2 * mp.cos(t), a2 * mp.sin(t)
            dx, dy = a5 - bx, -by
            dd = mp.sqrt(dx * dx + dy * dy)
            x = (dd * dd + mp.mpf(62.25) ** 2 - mp.mpf(a4) ** 2) / (2 * dd)
            h = mp.sqrt(mp.mpf(62.25) ** 2 - x * x)
            c = (bx + (x * dx - h * dy) / dd, by + (x * dy + h * dx) / dd)  # C above BD: the guess's side
            size = max(a5, a2 + 62.25, a4)
            assert abs(r.values["C.x"][d, k] - float(c[0])) <= 1e-12 * size, (d, k)
            assert abs(r.values["C.y"][d, k] - float(c[1])) <= 1e-12 * size, (d, k)
