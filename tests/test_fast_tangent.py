"""The fast kernel reports velocities from the tangent it computes for the prediction,
q' = (dq/du) u', instead of solving g_q q' = -g_u u' through the chain again
(kincas/core/kernel.py). Checked on chains of parallelogram four-bars (flat kernel below
GROUPS_APART groups, grouped above), swept at a rate w = 2.5: every rocker tip T_k moves as
G_k + (cos t, sin t), velocity w (-sin t, cos t), acceleration -w^2 (cos t, sin t) (closed
form), and the kernel's numbers equal the careful path's evaluation at the same poses.
"""
from __future__ import annotations

import numpy as np
import pytest

import kincas
from kincas.core.compiled import QuantityEvaluator
from kincas.core.fast import FastSweeper
from kincas.core.kernel import GROUPS_APART

from test_group_kernel import chain


@pytest.mark.parametrize("n", [3, GROUPS_APART + 2])
def test_velocities_from_the_tangent(n):
    m, w = chain(n), 2.5
    names = [f"T{k}.{c}" for k in (1, n) for c in ("vx", "vy", "ax", "y")] + [f"rk{n}.omega"]
    model = kincas.model_of(m)
    t = np.linspace(0.3, 2.8, 241)  # (the parallelograms fold at 0 and pi)
    U, Ud = t[:, None], np.full((len(t), 1), w)
    q0 = model.newton(model.initial_q(U[0], [], dict(m.guess), 5.0), U[0], [], 5.0).q
    fast = FastSweeper(model, names, compile=False)
    run = fast.run(U, [], 5.0, q0, U[0], Ud=Ud, Udd=np.zeros_like(Ud))
    assert run.first_bad == len(t)
    got = dict(zip(names, run.values))
    for k in (1, n):
        np.testing.assert_allclose(got[f"T{k}.vx"], -w * np.sin(t), rtol=0, atol=1e-11)
        np.testing.assert_allclose(got[f"T{k}.vy"], w * np.cos(t), rtol=0, atol=1e-11)
        np.testing.assert_allclose(got[f"T{k}.ax"], -w * w * np.cos(t), rtol=0, atol=1e-10)
        np.testing.assert_allclose(got[f"T{k}.y"], np.sin(t), rtol=0, atol=1e-12)
    np.testing.assert_allclose(got[f"rk{n}.omega"], w, rtol=0, atol=1e-11)
    careful = QuantityEvaluator(model, names, compile=False).evaluate(run.Q, U, [], Ud, np.zeros_like(Ud))
    np.testing.assert_allclose(run.values, careful, rtol=0, atol=1e-11)
