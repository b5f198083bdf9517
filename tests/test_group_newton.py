"""The careful Newton solves each Assur group on its own, measured against its own size.

A far point elsewhere in the drawing (an unused ground point at x = 1e5) must not loosen the
accuracy of a four-bar: before, tolerances were relative to the whole drawing's size and the
error grew from 1e-15 to 1e-9. The closed form below is independent of kincas.
"""
from __future__ import annotations

import numpy as np
import pytest

import kincas

A_, B_, C_, D_ = 1.0, 3.5, 3.0, 4.0  # crank, coupler, rocker, ground


def fourbar(far=None) -> kincas.Mechanism:
    ground = {"A": (0, 0), "D": (D_, 0)}
    if far is not None:
        ground["Far"] = far
    return kincas.Mechanism(
        ground=ground, inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)},
        links=[kincas.Link.bar("crank", "A", "B", A_), kincas.Link.bar("coupler", "B", "C", B_),
               kincas.Link.bar("rocker", "D", "C", C_)])


def closed_form(t):
    """C above the diagonal BD: the intersection of circles (B, coupler) and (D, rocker)."""
    B = np.stack([A_ * np.cos(t), A_ * np.sin(t)])
    e = np.array([[D_], [0.0]]) - B
    f = np.hypot(*e)
    x = (B_ ** 2 - C_ ** 2 + f ** 2) / (2 * f)
    h = np.sqrt(B_ ** 2 - x ** 2)
    return B + e / f * x + h * np.stack([-e[1], e[0]]) / f


@pytest.mark.parametrize("far", [None, (1e5, 0.0), (-3e7, 2e7)])
@pytest.mark.parametrize("method", ["careful", "fast"])
def test_far_unused_point_keeps_the_fourbar_accurate(far, method):
    t = np.linspace(0, 2 * np.pi, 37)
    s = kincas.sweep(fourbar(far), {"crank.angle": t}, report=["C.x", "C.y"], method=method)
    assert all(st == "ok" for st in s.status)
    err = np.abs(np.array([s["C.x"], s["C.y"]]) - closed_form(t)).max()
    assert err < 1e-13 * B_, err


def test_single_pose_solve_far_point():
    pose = kincas.solve(fourbar((1e5, 0.0)), {"crank.angle": 0.4}, report=["C.x", "C.y"])
    C = closed_form(np.array([0.4]))[:, 0]
    assert abs(pose["C.x"] - C[0]) < 1e-13 * B_ and abs(pose["C.y"] - C[1]) < 1e-13 * B_
