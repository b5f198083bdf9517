"""The fast kernel measures each Assur group against that group's own length.

A four-bar drawn beside an unused ground point at x = 1e5 has a drawing 1e5 long, but its
one group (coupler and rocker, hung on the crank) is 3.5 long: its largest body. The kernel's
residual must be max |g| / 3.5, as on the careful path, not max |g| / 1e5 (which loosened its
tests 3e4 times). Checked at a pose where the residual is far from rounding: one Newton step
from the first pose's linear prediction, computed here in numpy from the careful path's own
g and g_q, then compared with what the kernel reports for that pose.
"""
from __future__ import annotations

import numpy as np
import pytest

import kincas
from kincas.core.fast import FastSweeper

GROUP = 3.5  # the coupler: the longest body the group's loop passes through


def fourbar(far):
    return kincas.Mechanism(
        ground={"A": (0, 0), "D": (4, 0), "Far": far}, inputs=[kincas.Input.angle("crank")],
        guess={"C": (3.6, 2.9)},
        links=[kincas.Link.bar("crank", "A", "B", 1.0), kincas.Link.bar("coupler", "B", "C", 3.5),
               kincas.Link.bar("rocker", "D", "C", 3.0)])


def one_step_residual(model, q0, u0, u1, p):
    """max |g| after one Newton step from the linear prediction q0 + dq/du (u1 - u0)."""
    q = q0 + model.tangent(q0, u0, p) @ (u1 - u0)
    g, J = model.resjac(q, u1, p)
    q = q - np.linalg.solve(J, g)
    return np.abs(model.residual(q, u1, p)).max()


@pytest.mark.parametrize("compile", [False, True])
def test_kernel_residual_is_relative_to_the_group(compile):
    m = fourbar((1e5, 0.0))
    assert m.size() > 1e4  # the drawing is long, the group is not
    model = kincas.model_of(m)
    p = np.array([v for _, v in m.parameters], dtype=float)
    U = np.array([[0.3], [0.6]])  # a long step: one Newton step leaves a visible residual
    q0 = model.newton(model.initial_q(U[0], p, dict(m.guess), m.size()), U[0], p).q
    sw = FastSweeper(model, compile=compile, max_evals=1)
    run = sw.run(U, p, m.size(), q0, U[0], start=1)
    g = one_step_residual(model, q0, U[0], U[1], p)
    assert 1e-9 < g < 1e-3  # far from rounding, and Newton was converging
    assert run.residual[1] == pytest.approx(g / GROUP, rel=1e-6)


def test_group_lengths_in_casadi_match_the_careful_path():
    """The kernel's lengths (casadi) and the careful path's (numpy) are the same numbers."""
    m = fourbar((1e5, 0.0))
    model = kincas.model_of(m)
    p = np.array([v for _, v in m.parameters], dtype=float)
    u = np.array([0.3])
    local, ground = (a.ravel() for a in model._geometry(u, p))
    numeric = model.structure.block_lengths(local, ground)
    symbolic = np.asarray(model.structure.length_function()(u, p)).ravel()
    assert numeric.tolist() == [GROUP]
    np.testing.assert_allclose(symbolic, numeric, rtol=1e-15)
