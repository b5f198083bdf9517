"""One word per meaning of 'samples' (issue [15]), for the names the keywords left: a
tolerance analysis counts `draws` (ToleranceAnalysis.draws, `kincas tolerance --draws`), an
optimisation keeps the `inputs` it posed (Optimization.inputs), a designed cam is computed at
`points` cam angles (design_cam(points=)). 0.1's spellings still work one release, with a
DeprecationWarning (a note on stderr for the command line) naming the new one; the scene
keys (`[tolerance] samples`, `[cam_design] samples`) are the contract and unchanged."""
import json
import math
import warnings

import numpy as np
import pytest

import kincas
from kincas.cli.app import main
from kincas.synthesis.cam_design import Segment, design_cam
from test_public_names import _crank  # a crank of length a = 2


def test_a_tolerance_analysis_counts_draws_and_samples_warns():
    r = kincas.analyse(_crank(), {"crank.angle": [0.3]}, {"a": 0.01}, ["A.x"], draws=30, seed=2)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert r.draws == 30 and "30 draws" in repr(r)
        assert r.standard_error == pytest.approx(1 / math.sqrt(58), rel=1e-15)  # 1 / sqrt(2 (n - 1))
    with pytest.warns(DeprecationWarning, match=r"ToleranceAnalysis\.samples is deprecated: use ToleranceAnalysis\.draws"):
        assert r.samples == 30
    assert r.to_pandas().attrs["draws"] == 30


def test_an_optimization_keeps_its_inputs_and_samples_warns():
    # the minimum of (a cos 0.5 - 1)^2 is at a = 1 / cos 0.5
    r = kincas.optimize(_crank(), {"crank.angle": [0.5]}, {"a": (1.0, 3.0)}, "sum((A.x - 1)^2)")
    assert r.ok and abs(r.varied["a"] - 1 / math.cos(0.5)) < 1e-8
    assert r.inputs["crank.angle"].tolist() == [0.5]
    with pytest.warns(DeprecationWarning, match=r"Optimization\.samples is deprecated: use Optimization\.inputs"):
        assert r.samples is r.inputs


def test_a_cam_is_computed_at_points_and_samples_warns():
    segs = [Segment("rise", 180, 10, "harmonic"), Segment("return", 180, 10, "harmonic")]
    d = design_cam(segs, 40, points=360)
    with pytest.warns(DeprecationWarning, match=r"design_cam\(samples=...\) is deprecated: use design_cam\(points=...\)"):
        old = design_cam(segs, 40, samples=360)
    assert len(d.theta) == len(old.theta) == 360 and np.array_equal(d.profile, old.profile)
    # a harmonic rise of 10 over half a turn: s = 5 (1 - cos theta)
    assert np.abs(d.s - 5 * (1 - np.cos(d.theta))).max() < 1e-12
    assert len(design_cam(segs, 40, 0.0, 0.0, 720).theta) == 720  # positionally, as before


SCENE = """title = "crank"
units = {{ length = "mm", angle = "deg", time = "s" }}
[parameters]
a = 2.0
[ground]
O = [0, 0]
[links]
crank = {{ points = ["O", "A"], length = "a" }}
[[inputs]]
angle = "crank"
sweep = {{ from = 0, to = 30, steps = 2 }}
[output]
report = ["A.x"]
[tolerance]
std = {{ a = 0.01 }}
samples = {n}
"""


def test_the_command_line_counts_draws_and_samples_still_works(capsys, tmp_path):
    path = tmp_path / "tol.toml"
    path.write_text(SCENE.format(n=50), encoding="utf-8")
    capsys.readouterr()
    assert main(["tolerance", str(path), "--json", "--draws", "40"]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out)["samples"] == 40 and not err  # the output keeps the scene's word
    assert main(["tolerance", str(path), "--json", "--samples", "30"]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out)["samples"] == 30 and err.strip().splitlines() == [
        "kincas: --samples is deprecated: use --draws (the old option goes in the next release)"]
    assert main(["tolerance", str(path), "--json"]) == 0
    assert json.loads(capsys.readouterr()[0])["samples"] == 50  # the scene's [tolerance] samples
    assert main(["tolerance", str(path), "--draws", "40", "--samples", "30"]) == 2
    err = capsys.readouterr()[1].strip().splitlines()
    assert len(err) == 1 and "--draws, --samples" in err[0]
