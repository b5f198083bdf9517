"""A picture of a sweep in which no pose is solved still draws (nothing): a body of three or
more points has no solved pose to take its outline from, and used to raise numpy's
"All-NaN slice" ValueError (the live page worked around it)."""
from __future__ import annotations

import numpy as np

import kincas
from kincas.views.picture import picture


def ternary_fourbar(ground_gap: float) -> kincas.Mechanism:
    """A four-bar with a triangular coupler B-C-P; with a ground gap of 20 it cannot close."""
    return kincas.Mechanism(
        ground={"A": (0, 0), "D": (ground_gap, 0)},
        links=[kincas.Link.bar("crank", "A", "B", 1),
               kincas.Link("coupler", {"B": (0, 0), "C": (3.5, 0), "P": (1.5, 1.0)}),
               kincas.Link.bar("rocker", "D", "C", 3)],
        inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})


def test_a_sweep_with_no_solved_pose_draws_without_raising():
    m = ternary_fourbar(20.0)  # 1 + 3.5 + 3 < 20: nothing assembles
    sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 1, 4)})
    assert not sw.ok.any()
    pic = picture(m, sw, paths=[])
    moving = [pic.names.index(p) for p in "BCP"]
    assert np.isnan(pic.xy[:, moving]).all() and np.isfinite(pic.xy[:, pic.ground]).all()
    coupler = next(b for b in pic.bodies if b.name == "coupler")
    names = [pic.names[k] for k in coupler.ring]
    assert len(names) >= 2 and set(names) <= {"B", "C", "P"}


def test_the_same_body_is_a_triangle_when_a_pose_is_solved():
    m = ternary_fourbar(4.0)
    sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 1, 4)})
    assert sw.ok.all()
    coupler = next(b for b in picture(m, sw, paths=[]).bodies if b.name == "coupler")
    assert sorted(coupler.ring) == sorted(picture(m, sw, paths=[]).names.index(p) for p in "BCP")
