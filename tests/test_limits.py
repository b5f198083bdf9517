"""Limits located by the one Newton (kincas/core/limits.py on kincas/core/newton.py),
against the law of cosines: a crank-rocker driven at its rocker turns back where crank and
coupler are in line, |AC| = b -+ a, so the rocker's angle there is pi - phi with
cos(phi) = (d^2 + c^2 - (b -+ a)^2) / (2 c d) (triangle A D C)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from kincas import Input, Link, Mechanism
from kincas.analysis.singular import input_range
from kincas.core.limits import locate_singular
from kincas.core.numeric import compile

A, B, C, D = 1.0, 3.5, 3.0, 4.0  # crank, coupler, rocker, ground: a Grashof crank-rocker
EXACT = sorted(math.pi - math.acos((D * D + C * C - e * e) / (2 * C * D)) for e in (B - A, B + A))
M = Mechanism(ground={"A": (0, 0), "D": (D, 0)},
              links=[Link.bar("crank", "A", "B", A), Link.bar("coupler", "B", "C", B),
                     Link.bar("rocker", "D", "C", C)],
              inputs=[Input.angle("rocker")], guess={"B": (0.7, -0.7), "C": (2.48, 2.59)})


def test_range_of_the_rocker_by_the_law_of_cosines():
    r = input_range(M, {"rocker.angle": 2.1})
    assert not r.full_turn
    assert [k for k, _ in r.limits] == ["limit", "limit"]
    assert abs(r.low - EXACT[0]) < 1e-12 and abs(r.high - EXACT[1]) < 1e-12
    assert [abs(u - e) < 1e-12 for (_, u), e in zip(r.limits, EXACT)] == [True, True]


@pytest.mark.parametrize("end", [0, 1])
def test_locate_from_a_pose_short_of_the_limit(end):
    """From 0.05 rad short of each limit, one call: the input, the pose on g = 0, and crank
    and coupler in line there, all to rounding."""
    model = compile(M)
    u = np.array([EXACT[end] + (0.05 if end == 0 else -0.05)])
    q0 = model.initial_q(u, np.zeros(0), dict(M.guess), M.size())
    sol = model.newton(q0, u, np.zeros(0), M.size())
    assert sol.ok
    q, ul, s = locate_singular(model, sol.q, u, np.zeros(0), M.size(), [1.0 if end else -1.0])
    assert abs(ul[0] - EXACT[end]) < 1e-12
    assert np.abs(model.residual(q, ul, np.zeros(0))).max() < 1e-13 * M.size()
    pts = dict(zip(M.moving_points, model.points(q, ul, np.zeros(0)).T))
    assert abs(np.hypot(*pts["C"]) - (B + A if end == 0 else B - A)) < 1e-12
