"""Smaller rough edges of issue [14], item 15: a sweep's names once each, a DataFrame whose
index can be reset, `kincas cam --json` with what the docs promise (and the cam's jerk), the
README's study example as it runs, example comments naming options that exist, and the
reserved name `ground`."""
from __future__ import annotations

import math
import re

import numpy as np
import pytest

import kincas
from conftest import EXAMPLES, ROOT, run_cli
from kincas import Input, Link, Mechanism


def fourbar():
    return Mechanism(ground={"A": (0, 0), "D": (4, 0)},
                     links=[Link.bar("crank", "A", "B", 1.0), Link.bar("coupler", "B", "C", 3.5),
                            Link.bar("rocker", "D", "C", 3.0)],
                     inputs=[Input.angle("crank")], guess={"C": (3.6, 2.9)})


@pytest.fixture(scope="module")
def sw():
    # the default report has every link's angle, the input's link too; past pi the reported
    # angle is wrapped and the input is not
    return kincas.sweep(fourbar(), {"crank.angle": np.linspace(0, 2 * np.pi, 9)})


def test_a_sweeps_names_are_listed_once(sw):
    assert "crank.angle" in sw.values  # the case of the issue: reported and an input
    names = list(sw)
    assert len(names) == len(set(names)) and names[0] == "crank.angle"
    assert names == sw.keys() and set(names) == set(sw.inputs) | set(sw.values)
    pose = sw.pose(0)
    assert len(list(pose)) == len(set(pose))


def test_to_pandas_index_and_columns_do_not_clash(sw):
    pytest.importorskip("pandas")
    df = sw.to_pandas()
    flat = df.reset_index()  # failed: an index and a column both named crank.angle
    assert list(flat.columns).count("crank.angle") == 1
    # the column is the input as given (unwrapped): 0 .. 2 pi
    assert np.allclose(flat["crank.angle"], np.linspace(0, 2 * np.pi, 9), rtol=0, atol=0)
    # as in to_xarray, the reported (wrapped) copy of the input is not a second column
    assert not [c for c in df.columns if c.startswith("crank.angle")]
    assert np.allclose(flat["rocker.angle"], sw["rocker.angle"], rtol=0, atol=0)


def test_to_xarray_has_the_input_once(sw):
    pytest.importorskip("xarray")
    ds = sw.to_xarray()
    assert ds.sizes["pose"] == 9 and np.array_equal(ds["crank.angle"].values, sw.inputs["crank.angle"])


# --- kincas cam ---

CAM = """units = {{ angle = "{unit}" }}
[cam_design]
base_radius = 40
samples = 360
segments = [{{ motion = "rise", angle = {b}, lift = 12, law = "harmonic" }},
            {{ motion = "dwell", angle = {d} }},
            {{ motion = "return", angle = {b}, lift = 12, law = "harmonic" }},
            {{ motion = "dwell", angle = {d} }}]
"""


@pytest.mark.parametrize("unit", ["deg", "rad"])
def test_cam_json_has_the_derivatives_the_profile_and_the_jerk(tmp_path, capsys, unit):
    k = math.pi / 180 if unit == "deg" else 1.0  # radians per scene unit
    b, d = (120, 60) if unit == "deg" else (2 * math.pi / 3, math.pi / 3)
    p = tmp_path / "cam.toml"
    p.write_text(CAM.format(unit=unit, b=b, d=d))
    code, out, err = run_cli(capsys, "cam", p, "--json")
    assert code == 0, err
    th = np.asarray(out["theta"]) * k  # radians
    beta, h = 2 * math.pi / 3, 12.0
    rise = th < beta
    x = th[rise] / beta
    # the harmonic rise in closed form, per scene unit of cam angle
    s1 = h * math.pi / (2 * beta) * np.sin(math.pi * x) * k
    s2 = h * math.pi ** 2 / (2 * beta ** 2) * np.cos(math.pi * x) * k ** 2
    s3 = -h * math.pi ** 3 / (2 * beta ** 3) * np.sin(math.pi * x) * k ** 3
    assert np.allclose(np.asarray(out["ds/dtheta"])[rise], s1, rtol=1e-12, atol=1e-12 * abs(s1).max())
    assert np.allclose(np.asarray(out["d2s/dtheta2"])[rise], s2, rtol=1e-12, atol=1e-12 * abs(s2).max())
    assert np.allclose(np.asarray(out["d3s/dtheta3"])[rise], s3, rtol=1e-12, atol=1e-12 * abs(s3).max())
    dwell = (th > beta + 1e-9) & (th < beta + math.pi / 3 - 1e-9)
    assert np.all(np.asarray(out["d3s/dtheta3"])[dwell] == 0)
    # a knife edge in line: the profile point is R(-theta) (0, 40 + s)
    s = np.asarray(out["s"])
    assert np.allclose(out["profile"]["x"], np.sin(th) * (40 + s), atol=1e-12)
    assert np.allclose(out["profile"]["y"], np.cos(th) * (40 + s), atol=1e-12)
    assert out["units"]["d3s/dtheta3"] == f"length/{unit}^3"
    code, text, err = run_cli(capsys, "cam", p)
    jerk = re.search(r"largest \|d3s/dtheta3\| ([0-9.e+-]+)", text)
    assert jerk, text
    assert float(jerk.group(1)) == pytest.approx(h * math.pi ** 3 / (2 * beta ** 3) * k ** 3, rel=1e-3)


def test_cam_csv_has_the_jerk(tmp_path, capsys):
    p = tmp_path / "cam.toml"
    p.write_text(CAM.format(unit="deg", b=120, d=60))
    code, _, err = run_cli(capsys, "cam", p, "--csv", tmp_path / "c.csv")
    assert code == 0, err
    head = (tmp_path / "c.csv").read_text().splitlines()[0]
    assert "d3s/dtheta3 [per deg^3]" in head


def test_cam_docs_name_the_json_fields():
    docs = (ROOT / "docs" / "scene-format.md").read_text()
    part = docs[docs.index("## Extension: `[cam_design]` and `kincas cam`"):]
    for field in ("ds/dtheta", "d2s/dtheta2", "d3s/dtheta3", "profile.x"):
        assert field in part, field


# --- the README's study example, the examples' comments ---


def test_readme_says_what_the_study_example_does():
    """41 x 41 grid over a4 in [80, 100], a5 in [60, 80] (steps of 0.5): the crank turns fully
    (Grashof, crank shortest) iff 25 + max(a4, a5) <= 62.25 + min(a4, a5), i.e. a4 - a5 <= 37.25
    here, so the designs with i - j >= 35 (i, j their grid indices) do not assemble."""
    a4, a5 = np.meshgrid(np.linspace(80, 100, 41), np.linspace(60, 80, 41), indexing="ij")
    bad = int((25 + np.maximum(a4, a5) > 62.25 + np.minimum(a4, a5)).sum())
    assert bad == 21
    text = (ROOT / "README.md").read_text()
    line = next(ln for ln in text.splitlines() if "study examples/study_fourbar.toml" in ln)
    assert "map.png" in line
    para = text[text.index("## Many designs at once"):text.index("![The rocker")]
    assert f"{bad} of 1,681" in para and "exit status 3" in para and "map.png" in para


def test_study_says_it_wrote_the_map(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    text = (EXAMPLES / "study_fourbar.toml").read_text().replace("steps = 360", "steps = 13")
    text = text.replace("grid = [41, 41]", "grid = [2, 2]")
    p = tmp_path / "s.toml"
    p.write_text(text)
    code, out, err = run_cli(capsys, "study", p, "--plot", tmp_path / "map.png", "--no-progress")
    assert code == 3, err  # (100, 60) does not assemble: 100 - 60 > 37.25
    assert f"wrote {tmp_path / 'map.png'}" in out
    assert (tmp_path / "map.png").stat().st_size > 1000


def test_example_comments_name_options_that_exist():
    from kincas.cli.app import COMMANDS, _parser
    known = {}
    for cmd in ["solve", *COMMANDS]:
        ap = _parser([cmd])
        sub = next(a for a in ap._actions if a.dest == "command").choices[cmd]
        known[cmd] = {o for a in sub._actions for o in a.option_strings}
    wrong = []
    for f in sorted(EXAMPLES.glob("*.toml")):
        comments = " ".join(ln.split("#", 1)[1] for ln in f.read_text().splitlines() if "#" in ln)
        for cmd, rest in re.findall(r"kincas (\w+)([^`]*)`?", comments):
            if cmd in known:
                wrong += [(f.name, cmd, o) for o in re.findall(r"(--[a-z][a-z-]*)", rest)
                          if o not in known[cmd]]
    assert not wrong, wrong


# --- the name ground ---


def test_a_link_named_ground_is_told_why():
    with pytest.raises(kincas.ModelError, match='"ground" is reserved') as e:
        Mechanism(ground={"A": (0, 0)}, links=[Link.bar("ground", "A", "B", 1)],
                  inputs=[Input.angle("ground")])
    assert "not a valid" not in str(e.value)


def test_a_scene_link_named_ground_is_told_why(tmp_path, capsys):
    p = tmp_path / "g.toml"
    p.write_text('[ground]\nA = [0, 0]\n[links]\nground = { points = ["A", "B"], length = 1 }\n'
                 '[[inputs]]\nangle = "ground"\nvalue = 0\n')
    code, _, err = run_cli(capsys, "solve", p)
    assert code == 2 and '"ground" is reserved' in err, err


@pytest.mark.parametrize("name", ["cycloidal", "harmonic", "polynomial345"])
def test_each_laws_jerk_is_the_derivative_of_its_acceleration(name):
    from kincas.synthesis.cam_design import law
    x, h = np.array([0.13, 0.4, 0.77]), 1e-5
    d = (law(name, x + h)[2] - law(name, x - h)[2]) / (2 * h)  # central difference, tests only
    assert np.allclose(law(name, x, jerk=True)[3], d, rtol=1e-7, atol=1e-6)
