"""The fast kernel's third-order prediction (kincas/core/kernel.py, kP): the cubic through the
last two solved poses with their tangents (Hermite's). On a dense sweep of a mechanism whose
q(u) is not linear it lands within STEP of the pose where the second-order prediction misses
by far more, so the kernel accepts the pose with kF alone, no Newton step; the compiled loop
and both forms of the virtual machine take the same decisions, and the answers are the closed
forms' (written here, not kincas's)."""
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
