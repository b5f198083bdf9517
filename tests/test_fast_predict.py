"""The fast kernel's predictions (kincas/core/prediction.py): kP the cubic through the last two
solved poses with their tangents (Hermite's), kP5 the quintic through the last three. On a
dense sweep of a mechanism whose q(u) is not linear the cubic lands within STEP of the pose
where the second-order prediction misses by far more, and at ten times the step the quintic
does where the cubic misses: the kernel accepts the pose with kF alone, no Newton step. The
quintic runs only while it pays (dense sweeps keep the cubic); the compiled loop and both
forms of the virtual machine take the same decisions, and the answers are the closed forms'
(written here, not kincas's)."""
import numpy as np
import pytest

from kincas.core.kernel import STEP

from test_fast import check_residuals, fourbar, fourbar_closed
from test_fast_near import cache, runs, same_decisions  # noqa: F401 (cache: a fixture)


def predictions(q, T, h):
    """(second-order, third-order) predictions of q[k] from q[k-1], q[k-2] and their tangents
    T (per pose, d q / d theta) for equal steps h, written from their definitions: the
    second-order q0 + T0 h + (T0 - T1) h / 2; the cubic through (q1, T1) at -h and (q0, T0)
    at 0, evaluated at h."""
    q0, q1, T0, T1 = q[1:-1], q[:-2], T[1:-1], T[:-2]
    second = q0 + T0 * h + 0.5 * (T0 - T1) * h
    # cubic c0 + c1 t + c2 t^2 + c3 t^3 (t in steps): c0 = q0, c1 = T0 h, and at t = -1
    # q1 and T1 h; solved for c2, c3 by hand
    c1, a1 = T0 * h, T1 * h
    c3 = (a1 + c1) - 2 * (q0 - q1)  # from q(-1) = q1 and q'(-1) = a1
    c2 = q1 - q0 + c1 + c3
    return second, q0 + c1 + c2 + c3


def fourbar_angles(th, a, b, c, d):
    """The four-bar's unknowns (rocker angle, coupler angle) and their derivatives in the
    crank angle, from the closed form's C and its velocity at unit crank speed."""
    cf = fourbar_closed(th, a, b, c, d, w=1.0)
    Bx, By, Cx, Cy = a * np.cos(th), a * np.sin(th), cf["C.x"], cf["C.y"]
    vBx, vBy, vCx, vCy = -By, Bx, cf["C.vx"], cf["C.vy"]
    rk = np.arctan2(Cy, Cx - d)
    cp = np.arctan2(Cy - By, Cx - Bx)
    cross = lambda x, y, vx, vy: (x * vy - y * vx) / (x * x + y * y)
    return (np.stack([rk, cp], 1),
            np.stack([cross(Cx - d, Cy, vCx, vCy), cross(Cx - Bx, Cy - By, vCx - vBx, vCy - vBy)], 1))


def test_the_cubic_is_the_kernel_s_prediction_and_takes_dense_poses_without_newton(monkeypatch):
    a, b, c, d, w = 1.0, 3.45, 3.0, 4.0, 10.0
    th = np.linspace(0.3, 0.6, 1001)  # steps of 3e-4 rad
    h = th[1] - th[0]
    q, T = fourbar_angles(th, a, b, c, d)
    second, third = predictions(q, T, h)
    miss2, miss3 = np.abs(second - q[2:]).max(1), np.abs(third - q[2:]).max(1)
    assert miss2.min() > 30 * STEP and miss3.max() < 0.1 * STEP  # what the test is about
    m = fourbar(b=b)
    names = ["C.x", "C.y", "C.vx", "C.vy"]
    model, p, L, out = runs(m, names, th[:, None], [w], monkeypatch)
    same_decisions(out)
    run = out["compiled"]
    assert (run.iterations[3:] == 0).all()  # kF at the prediction, accepted
    assert run.correction[3:].max() < 0.1 * STEP
    cf = fourbar_closed(th, a, b, c, d, w=w)
    for i, name in enumerate(names):
        scale = L * (w if ".v" in name else 1.0)
        assert np.abs(run.values[i, 1:] - cf[name][1:]).max() <= 1e-12 * scale, name
    check_residuals(model, run, p, L, tol=1e-13)


@pytest.mark.parametrize("turn", [False, True])
def test_uneven_and_reversing_steps_keep_the_closed_form(monkeypatch, turn):
    """Steps that grow, shrink and (turn) go back: the cubic's extrapolation over l = (u -
    u0) / (u0 - u1) steps, l from 0.2 to 5 and -1, still lands on the branch."""
    a, b, c, d, w = 1.0, 3.45, 3.0, 4.0, 2.0
    steps = np.tile([1e-3, 5e-3, 1e-3, 2e-4, 1e-3], 40)
    if turn:
        steps[100:] *= -1
    th = 0.3 + np.r_[0.0, np.cumsum(steps)]
    model, p, L, out = runs(fourbar(b=b), ["C.x", "C.y", "C.vx", "C.vy"], th[:, None], [w], monkeypatch)
    same_decisions(out)
    run = out["compiled"]
    cf = fourbar_closed(th, a, b, c, d, w=w)
    for i, name in enumerate(["C.x", "C.y", "C.vx", "C.vy"]):
        scale = L * (w if ".v" in name else 1.0)
        assert np.abs(run.values[i, 1:] - cf[name][1:]).max() <= 1e-12 * scale, name
    check_residuals(model, run, p, L, tol=1e-13)


# --- the fifth-order prediction (kincas/core/prediction.py: kP5) ---


def hermite(nodes, values, slopes, t):
    """The polynomial through (node, value, slope) triples, at t: the confluent Vandermonde
    system solved by numpy (written here from the definition, not from kincas's formula)."""
    k = 2 * len(nodes)
    rows = [[x ** j for j in range(k)] for x in nodes] + [[j * x ** (j - 1) if j else 0.0 for j in range(k)] for x in nodes]
    rhs = np.stack([np.asarray(v, float) for v in (*values, *slopes)])
    coef = np.linalg.solve(np.array(rows), rhs.reshape(k, -1))
    return sum(c * t ** j for j, c in enumerate(coef)).reshape(rhs.shape[1:])


def test_kp5_is_the_quintic_through_three_poses_and_the_cubic_where_steps_are_uneven(monkeypatch):
    import casadi as ca
    from kincas.core.fast import FastSweeper
    from kincas.core.tolerances import QUINTIC_RATIO
    from test_fast import first_pose
    monkeypatch.setattr("kincas.core.kernel.QUINTIC_UNKNOWNS", 1)  # (a four-bar has 2)
    m = fourbar(b=3.45)
    model, p, L, q0 = first_pose(m, np.array([[0.3]]))
    # (a report of its own: the kernel functions are kept per model and report)
    kP, kP5 = (FastSweeper(model, ["C.x", "B.y"], compile=False).functions[i] for i in (0, 4))
    rng = np.random.default_rng(3)
    nq = model.sym.nq
    for trial in range(20):
        h0, ratio = rng.uniform(1e-3, 5e-2), rng.uniform(0.3, 2.5)
        u0, lam = 0.7, rng.uniform(0.2, 1.8)
        u1, u2, u = u0 - h0, u0 - h0 - ratio * h0, u0 + lam * h0
        # smooth made-up unknowns of u with their derivatives (exact), far above rounding
        f = lambda x: np.array([np.sin(2 * x) + x ** 5, np.exp(x) - 3 * x ** 4])[:nq]
        df = lambda x: np.array([2 * np.cos(2 * x) + 5 * x ** 4, np.exp(x) - 12 * x ** 3])[:nq]
        args = [f(u0), df(u0), [u0], [u], df(u1), [u1], f(u1), df(u2), [u2], f(u2), np.full(len(model.blocks), 4.0)]
        got, miss = (np.asarray(v).ravel() for v in kP5(*args))
        cub = np.asarray(kP(*args[:7])).ravel()
        want3 = hermite([u0, u1], [f(u0), f(u1)], [df(u0), df(u1)], u)
        np.testing.assert_allclose(cub, want3, rtol=0, atol=1e-11)  # kP: the cubic
        if QUINTIC_RATIO[0] <= ratio <= QUINTIC_RATIO[1]:
            want5 = hermite([u0, u1, u2], [f(u0), f(u1), f(u2)], [df(u0), df(u1), df(u2)], u)
            np.testing.assert_allclose(got, want5, rtol=0, atol=1e-11)
            assert np.abs(want5 - want3).max() > 1e-9  # a change, applied, and reported:
            np.testing.assert_allclose(miss[0], np.abs(want5 - want3).max(), rtol=1e-6)
        else:  # too uneven: the cubic, and nothing applied
            np.testing.assert_array_equal(got, cub)
            assert miss[0] == 0


def test_the_quintic_takes_moderate_steps_without_newton_and_the_cubic_dense_ones(monkeypatch):
    monkeypatch.setattr("kincas.core.kernel.QUINTIC_UNKNOWNS", 1)  # (a four-bar has 2)
    a, b, c, d, w = 1.0, 3.45, 3.0, 4.0, 10.0
    names = ["C.x", "C.y", "C.vx", "C.vy"]
    for h, quintic_on in ((3e-3, True), (3e-4, False)):
        th = 0.3 + h * np.arange(401)
        q, T = fourbar_angles(th, a, b, c, d)
        cubic = predictions(q, T, h)[1]
        quint = hermite([0.0, -1.0, -2.0], [q[2:-1], q[1:-2], q[:-3]], [T[2:-1] * h, T[1:-2] * h, T[:-3] * h], 1.0)
        miss3, miss5 = np.abs(cubic[1:] - q[3:]).max(1), np.abs(quint - q[3:]).max(1)
        if quintic_on:
            assert miss3.min() > 5 * STEP and miss5.max() < 0.1 * STEP  # what the test is about
        # (a report of its own, "B.y" last: the kernel functions are kept per model and report)
        model, p, L, out = runs(fourbar(b=b), names + ["B.y"], th[:, None], [w], monkeypatch)
        same_decisions(out)
        run = out["compiled"]
        assert (run.iterations[5:] == 0).all()  # no Newton step: kF at the prediction, accepted
        assert bool(run._state[-1]) == quintic_on  # the quintic ran (and goes on) only where it paid
        cf = fourbar_closed(th, a, b, c, d, w=w)
        for i, name in enumerate(names):
            scale = L * (w if ".v" in name else 1.0)
            assert np.abs(run.values[i, 1:] - cf[name][1:]).max() <= 1e-12 * scale, name
        check_residuals(model, run, p, L, tol=1e-13)


def test_a_small_kernel_has_no_quintic_and_keeps_the_cubic(monkeypatch):
    """Below QUINTIC_UNKNOWNS unknowns the kernel is built without kP5 (its compile would cost
    more than it saves): the poses that the quintic would have taken without a Newton step take
    one, with the same answers."""
    from kincas.core.kernel import QUINTIC_UNKNOWNS
    a, b, c, d, w = 1.0, 3.45, 3.0, 4.0, 10.0
    th = 0.3 + 3e-3 * np.arange(201)
    names = ["C.x", "C.y", "C.vx", "C.vy"]
    model, p, L, out = runs(fourbar(b=b), names, th[:, None], [w], monkeypatch)
    assert model.sym.nq < QUINTIC_UNKNOWNS
    same_decisions(out)
    run = out["compiled"]
    assert run.sweeper.functions[4] is None and not run._state[-1]
    assert (run.iterations[5:] >= 1).all()  # the cubic misses these by more than STEP
    cf = fourbar_closed(th, a, b, c, d, w=w)
    for i, name in enumerate(names):
        scale = L * (w if ".v" in name else 1.0)
        assert np.abs(run.values[i, 1:] - cf[name][1:]).max() <= 1e-12 * scale, name
