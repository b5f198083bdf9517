"""Jupyter as a new user sees it (issue [19]): a mechanism that does not assemble shows a
message, not a tall blank picture; a Sweep run from a scene shows its values in the scene's
units (degrees where the scene says so), with their units."""
from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from kincas import Input, Link, Mechanism
from conftest import EXAMPLES


def test_a_mechanism_that_does_not_assemble_says_so():
    # the ground pivots 40 apart, the crank, coupler and rocker 1 + 3.5 + 3: no assembly
    m = Mechanism(ground={"A": (0, 0), "D": (0, 40)},
                  links=[Link.bar("crank", "A", "B", 1), Link.bar("coupler", "B", "C", 3.5),
                         Link.bar("rocker", "D", "C", 3)],
                  inputs=[Input.angle("crank")], guess={"C": (3.6, 2.9)})
    svg = m._repr_svg_()
    root = ET.fromstring(svg)
    assert float(root.get("height")) < 100 and float(root.get("width")) <= 420
    assert "does not assemble" in "".join(root.itertext())


def test_a_scene_sweep_shows_degrees():
    from kincas.cli.scene import load
    sc = load(EXAMPLES / "forces_toggle.toml")
    sw = sc.run()
    html = sw._repr_html_()
    rad = np.asarray(sw.values["rocker.angle"], float)
    lo, hi = np.degrees(rad.min()), np.degrees(rad.max())  # the independent conversion
    assert f"{lo:.4g} to {hi:.4g} deg" in html, html
    assert "against crank.angle (120 to 20 deg)" in html
    w = np.degrees(np.asarray(sw.values["rocker.omega"], float))
    assert f"{w.min():.4g} to {w.max():.4g} deg/s" in html
    # a Sweep made in Python stays in radians, as it holds them
    import kincas
    plain = kincas.sweep(sc.mechanism, sc.study.inputs, report=["rocker.angle"])._repr_html_()
    assert f"{rad.min():.4g} to {rad.max():.4g}" in plain
