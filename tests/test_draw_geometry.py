"""Evolutes and centrodes drawn by `--plot --evolute P --centrodes L` (kincas/views/draw_geometry.py):
the curves' defining properties, and the CLI's options."""
from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("matplotlib")

import kincas
from kincas.views.draw_geometry import curves
from conftest import EXAMPLES, run_cli


def fourbar():
    return kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
                            links=[kincas.Link.bar("crank", "A", "B", 1),
                                   kincas.Link("coupler", {"B": (0, 0), "C": (3.5, 0), "E": (1.2, 0.8)}),
                                   kincas.Link.bar("rocker", "D", "C", 3)],
                            inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})


def test_centrodes_roll_on_each_other_and_the_evolute_is_a_radius_away():
    m = fourbar()
    sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 2 * np.pi, 61)}, rates=1.3,
                      report=["E.x", "E.y", "E.curvature"])
    for pose in (0, 17, 40):
        got = curves(m, sw, pose, evolute=["E"], centrodes=["coupler", "crank"])
        fixed, moving = got["coupler fixed centrode"], got["coupler moving centrode"]
        # the two centrodes touch at the instant centre of the drawn pose
        assert np.allclose(moving[pose], fixed[pose], atol=1e-9 * np.abs(fixed[pose]).max())
        # a link turning about a ground pivot: both centrodes are the pivot itself
        assert np.allclose(got["crank fixed centrode"], 0, atol=1e-12)
        assert np.allclose(got["crank moving centrode"], 0, atol=1e-12)
    ev = curves(m, sw, 0, evolute=["E"])["E evolute"]
    radius = np.hypot(ev[:, 0] - sw["E.x"], ev[:, 1] - sw["E.y"])
    assert np.allclose(radius, 1 / np.abs(sw["E.curvature"]), rtol=1e-9)


def test_plot_with_evolute_and_centrodes(capsys, tmp_path):
    scene = EXAMPLES / "forces_coupler_curve.toml"
    out = tmp_path / "geo.png"
    code, _, err = run_cli(capsys, "solve", scene, "--plot", out, "--evolute", "P", "--centrodes", "coupler")
    assert code == 0, err
    assert out.stat().st_size > 1000 and "Traceback" not in err
    code, _, err = run_cli(capsys, "solve", scene, "--plot", out, "--evolute", "Z")
    assert code == 2 and "--evolute: unknown point" in err
    code, _, err = run_cli(capsys, "solve", scene, "--plot", out, "--centrodes", "nolink")
    assert code == 2 and "--centrodes: unknown link" in err
    code, _, err = run_cli(capsys, "solve", scene, "--centrodes", "coupler")
    assert code == 2 and "give --plot" in err
