"""Jupyter's displays (issue [12]): a Mechanism draws its first pose as SVG, a Sweep shows a
short summary with small plots; repr stays one line."""
from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism

SVG = "{http://www.w3.org/2000/svg}"


def fourbar(guess):
    return Mechanism(ground={"A": (0, 0), "D": (4, 0)},
                     links=[Link.bar("crank", "A", "B", 1), Link.bar("coupler", "B", "C", 3.5),
                            Link.bar("rocker", "D", "C", 3)],
                     inputs=[Input.angle("crank")], guess=guess)


@pytest.mark.parametrize("guess,theta", [({"C": (3.6, 2.9)}, 0.0),
                                         ({"B": (0, 1), "C": (3.6, 2.9)}, math.pi / 2)])
def test_a_mechanism_draws_its_first_pose(guess, theta):
    m = fourbar(guess)
    root = ET.fromstring(m._repr_svg_())
    pts = {c.get("data-point"): (float(c.get("cx")), float(c.get("cy"))) for c in root.iter(SVG + "circle")}
    # closed form: B on the crank at theta; C on the circles about B (3.5) and D (3), upper branch
    b = np.array([math.cos(theta), math.sin(theta)])
    d = np.array([4.0, 0.0])
    bd = np.linalg.norm(d - b)
    along = (3.5 ** 2 - 3 ** 2 + bd ** 2) / (2 * bd)
    u = (d - b) / bd
    c = b + along * u + math.sqrt(3.5 ** 2 - along ** 2) * np.array([-u[1], u[0]])
    assert pts["B"] == pytest.approx(tuple(b), abs=1e-9)
    assert pts["C"] == pytest.approx(tuple(c), abs=1e-9)
    assert "\n" not in repr(m)


def test_a_sweep_shows_a_summary_with_plots():
    m = fourbar({"C": (3.6, 2.9)})
    sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 2 * np.pi, 37)}, report=["C.x", "rocker.angle"])
    html = sw._repr_html_()
    assert "37 poses, 37 solved" in html and html.count("<svg") == 2 and "C.x" in html
    assert "\n" not in repr(sw)
