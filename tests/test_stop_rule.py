"""The careful and the fast (compiled) paths stop by one rule (issue [8].2): converged when
the next Newton step is negligible, and that step is applied. So both end where quadratic
convergence puts them, at rounding: a few ulps of the mechanism's size from the closed form,
and from each other. (Before, the careful path stopped at the residual that passed its test:
1.9e-13 off on this slider-crank, against 3e-16 for the fast path.)"""
from __future__ import annotations

import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism, Slide

EPS = np.finfo(float).eps
T = np.linspace(0, 2 * np.pi, 361)


def fourbar_c(t, a=1.0, b=3.5, c=3.0, d=4.0):
    """C of a four-bar (A = 0, D = (d, 0)) by the intersection of the circles about B and D."""
    B = np.stack([a * np.cos(t), a * np.sin(t)], 1)
    v = np.array([d, 0.0]) - B
    r = np.hypot(v[:, 0], v[:, 1])
    x = (r ** 2 + b ** 2 - c ** 2) / (2 * r)
    e = v / r[:, None]
    n = np.stack([-e[:, 1], e[:, 0]], 1)
    return B + x[:, None] * e + np.sqrt(b ** 2 - x ** 2)[:, None] * n


def slider_b(t, r=1.0, l=3.0, e=0.5):
    """B of an offset slider-crank (slide along y = e): x = r cos t + sqrt(l^2 - (r sin t - e)^2)."""
    return np.stack([r * np.cos(t) + np.sqrt(l ** 2 - (r * np.sin(t) - e) ** 2), np.full_like(t, e)], 1)


CASES = {
    "four-bar": (Mechanism(ground={"A": (0, 0), "D": (4, 0)},
                           links=[Link.bar("crank", "A", "B", 1), Link.bar("coupler", "B", "C", 3.5),
                                  Link.bar("rocker", "D", "C", 3.0)],
                           inputs=[Input.angle("crank")], guess={"C": (3.6, 2.9)}), "C", fourbar_c(T)),
    "slider-crank": (Mechanism(ground={"O": (0, 0)},
                               links=[Link.bar("crank", "O", "A", 1), Link.bar("rod", "A", "B", 3)],
                               slides=[Slide("B", "ground", through=(0, 0.5), name="slider")],
                               inputs=[Input.angle("crank")], guess={"B": (3.5, 0.5)}), "B", slider_b(T)),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_careful_and_fast_stop_at_rounding(case):
    m, point, exact = CASES[case]
    size = m.size()
    got = {}
    for method in ("careful", "fast"):
        sw = kincas.sweep(m, {"crank.angle": T}, method=method, report=[f"{point}.x", f"{point}.y"])
        assert sw.ok.all(), method
        got[method] = np.stack([sw[f"{point}.x"], sw[f"{point}.y"]], 1)
        err = np.abs(got[method] - exact).max() / size
        assert err <= 8 * EPS, f"{method}: {err:.2g} of the size from the closed form"
    assert np.abs(got["careful"] - got["fast"]).max() / size <= 8 * EPS


def test_newton_applies_the_negligible_last_step():
    """The core Newton on x^2 = 2 from a start whose residual already passes 1e-13 of the
    old rule: it still takes the last step, and lands on sqrt(2) to an ulp."""
    from kincas.core.newton import newton
    F = lambda x: (np.array([x[0] ** 2 - 2.0]), np.array([[2 * x[0]]]))
    x0 = np.array([2 ** 0.5 + 2e-14])  # residual ~ 5.7e-14 < TOL, error 2e-14
    r = newton(F, x0, np.ones(1), np.ones(1))
    assert r.ok and abs(r.x[0] - 2 ** 0.5) <= EPS * 2 ** 0.5
