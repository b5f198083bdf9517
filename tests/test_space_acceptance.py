"""Scenes written from the contract alone (docs/scene-format.md, "Spatial mechanisms"), as an
outsider's acceptance scene would be, each against a closed form written here.

Cylindrical, prismatic and planar joints whose point is ALSO listed in `[ground]`, as a
scene written from the contract does when it leaves `bodies` out ("it may be left out when
exactly two bodies (the ground counting as one) carry `point`; then the first is the
ground"). The point then belongs to the second body (it slides along the ground's line or
plane); it once also stayed glued to the ground's copy, a ball joint on top of the slide, and
the scene was refused as over-constrained. Checked against closed forms written here."""
from __future__ import annotations

import math

import numpy as np
import pytest

from kincas.analysis import certify_msolve

import kincas
from conftest import EXAMPLES, run_cli, write_scene

SLIDER = """
title = "spatial slider-crank, slot point listed in [ground]"
space = "3d"
[ground]
O = [0, 0, 0]
G = [50, 0, 20]
[links]
crank = { points = { O = [0, 0, 0], A = [10, 0, 0] } }
rod = { points = ["A", "B"], length = 45 }
piston = { points = { G = [50, 0, 20], B = [50, 0, 20] } }
[[joints]]
type = "revolute"
point = "O"
axis = [0, 0, 1]
[[joints]]
type = "prismatic"
name = "slot"
point = "G"
axis = [0.6, 0, 0.8]
[[inputs]]
joint = "O"
sweep = { from = 0, to = 360, steps = 13 }
[output]
report = ["slot.s", "slot.v", "G.x", "G.z", "B.x", "B.z"]
"""


def slider_closed_form(th):
    """B = G + s d on the line, |B - A| = 45 with A = 10 (cos th, sin th, 0): the root of
    s^2 + 2 s d.(G - A) + |G - A|^2 - 45^2 = 0 near s = 0; ds/dth by implicit differentiation."""
    d, G = np.array([0.6, 0, 0.8]), np.array([50.0, 0, 20])
    A = 10 * np.array([math.cos(th), math.sin(th), 0.0])
    dA = 10 * np.array([-math.sin(th), math.cos(th), 0.0])
    b = d @ (G - A)
    s = -b + math.sqrt(b * b - ((G - A) @ (G - A) - 45 ** 2))
    B = G + s * d
    ds = ((B - A) @ dA) / ((B - A) @ d)  # d/dth |B - A|^2 = 0
    return s, ds, B


def test_prismatic_point_listed_in_ground_slides(tmp_path, capsys):
    code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, SLIDER), "--json")
    assert code == 0, err
    assert out["status"] == ["ok"] * 13 and len(out["inputs"]["O.angle"]) == 13
    for k, deg in enumerate(out["inputs"]["O.angle"]):
        s, ds, B = slider_closed_form(math.radians(deg))
        v = {name: col[k] for name, col in out["values"].items()}
        assert abs(v["slot.s"] - s) < 1e-12 * 50
        assert abs(v["slot.v"] - ds * math.pi / 180) < 1e-12 * 50  # input rate 1 deg/s
        assert abs(v["G.x"] - B[0]) < 1e-12 * 50 and abs(v["G.z"] - B[2]) < 1e-12 * 50
        assert abs(v["B.x"] - B[0]) < 1e-12 * 50 and abs(v["B.z"] - B[2]) < 1e-12 * 50


CYLINDER = """
title = "a sleeve on a fixed column, its point listed in [ground]"
space = "3d"
[ground]
X = [1, 0, 0]
[links]
sleeve = { points = { X = [1, 0, 0], P = [2, 1, 0.5] } }
[[joints]]
type = "cylindrical"
name = "c"
point = "X"
axis = [0, 0, 1]
[[inputs]]
joint = "c.angle"
sweep = { from = 17, to = -160, steps = 4 }
[[inputs]]
joint = "c.s"
sweep = { from = 0.5, to = 2, steps = 4 }
[output]
report = ["P.x", "P.y", "P.z", "X.z"]
"""


def test_cylindrical_point_listed_in_ground_turns_and_slides(tmp_path, capsys):
    code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, CYLINDER), "--json")
    assert code == 0, err
    X0, P0 = np.array([1.0, 0, 0]), np.array([2.0, 1, 0.5])
    assert out["status"] == ["ok"] * 4
    for k in range(4):
        th, s = math.radians(out["inputs"]["c.angle"][k]), out["inputs"]["c.s"][k]
        c, sn = math.cos(th), math.sin(th)
        want = X0 + np.array([[c, -sn, 0], [sn, c, 0], [0, 0, 1]]) @ (P0 - X0) + [0, 0, s]
        v = {name: col[k] for name, col in out["values"].items()}
        assert np.allclose([v["P.x"], v["P.y"], v["P.z"]], want, atol=1e-12)
        assert abs(v["X.z"] - s) < 1e-12


@pytest.mark.skipif(not certify_msolve.available(), reason='msolve not installed (pip install "kincas[certify]")')
def test_certified_count_of_the_slider_with_its_point_in_ground(tmp_path, capsys):
    """Two assemblies at 0 deg: the two real roots of the slider's quadratic (its discriminant
    b^2 - c > 0 at A = (10, 0, 0)); once certified as none (the ground's copy held the point)."""
    G, A, d = np.array([50.0, 0, 20]), np.array([10.0, 0, 0]), np.array([0.6, 0, 0.8])
    b, c = d @ (G - A), (G - A) @ (G - A) - 45 ** 2
    want = 2 if b * b - c > 0 else 0
    code, out, err = run_cli(capsys, "modes", write_scene(tmp_path, SLIDER), "--certify", "--json")
    assert code == 0, err
    assert out["certified"] is True and out["count"] == want == 2
    s_roots = sorted(-b + k * math.sqrt(b * b - c) for k in (-1, 1))
    got = sorted((np.array(m["points"]["G"]) - G) @ d for m in out["modes"])
    assert np.allclose(got, s_roots, atol=1e-9)


def test_pictures_of_the_slider_with_its_point_in_ground(tmp_path, capsys):
    scene = write_scene(tmp_path, SLIDER)
    code, _, err = run_cli(capsys, "solve", scene, "--svg", tmp_path / "s.svg", "--html", tmp_path / "s.html")
    assert code == 0, err
    assert (tmp_path / "s.svg").stat().st_size > 0 and (tmp_path / "s.html").stat().st_size > 0


def test_a_bars_rotation_is_refused_saying_why(tmp_path, capsys):
    """A two-point bar's spin is not a freedom: it has no rotation to report; the line says so."""
    for q in ("rod.qw", "rod.omega_x", "rod.R11"):
        scene = write_scene(tmp_path, SLIDER.replace('report = ["slot.s"', f'report = ["{q}", "slot.s"'))
        code, _, err = run_cli(capsys, "solve", scene)
        assert code == 2 and "Traceback" not in err, err
        assert q in err and "two-point bar" in err and "[output] report" in err, err


BARS = """
title = "point on a plane held by two bars of which one is driven in length"
space = "3d"
[parameters]
l1 = 5
[ground]
A = [0, 0, 0]
B = [6, 0, 0]
[links]
b1 = { points = ["A", "P"], length = "l1" }
b2 = { points = ["B", "P"], length = 5 }
[[slides]]
name = "floor"
point = "P"
along = "ground"
plane = { through = [0, 0, 1], normal = [0, 0, 1] }
[[inputs]]
parameter = "l1"
sweep = { from = 4, to = 6, steps = 5 }
[guess]
P = [3, 4, 1]
[output]
report = ["P.x", "P.y", "P.z", "P.vx", "P.vy"]
"""


def test_a_parameter_input_with_a_plane_slide_and_a_point_of_bars(tmp_path, capsys):
    """P on the plane z = 1 with |AP| = l1 and |BP| = 5: x = (l1^2 + 11) / 12 and
    y = sqrt(l1^2 - x^2 - 1); dx/dl1 = l1 / 6. Once a traceback (a 3D slide has no angle, read
    when labelling the parameter input's unit). Its range: the plane's circle about B of radius
    sqrt(24) meets A's sphere while the in-plane distance d from (0, 0, 1) is 6 -+ sqrt(24),
    l1 = sqrt(d^2 + 1)."""
    scene = write_scene(tmp_path, BARS)
    code, out, err = run_cli(capsys, "solve", scene, "--json")
    assert code == 0, err
    for k, l1 in enumerate(out["inputs"]["l1"]):
        x = (l1 ** 2 + 11) / 12
        v = {name: col[k] for name, col in out["values"].items()}
        assert abs(v["P.x"] - x) < 1e-12 and abs(v["P.z"] - 1) < 1e-12
        assert abs(v["P.y"] - math.sqrt(l1 ** 2 - x * x - 1)) < 1e-12
        assert abs(v["P.vx"] - l1 / 6) < 1e-12
    code, out, err = run_cli(capsys, "range", scene, "--json")
    assert code == 0, err
    lo, hi = (math.sqrt(d * d + 1) for d in (6 - math.sqrt(24), 6 + math.sqrt(24)))
    r = out["ranges"]["l1"]
    assert abs(r["from"] - lo) < 1e-9 and abs(r["to"] - hi) < 1e-9, r
    code, out, err = run_cli(capsys, "modes", scene)
    assert code == 0 and "angles:" not in out, out  # no angle to show: no empty "angles:" line


def test_too_few_inputs_on_a_cylinder_listed_in_ground_says_the_count(tmp_path, capsys):
    """A cylindrical joint has two freedoms; one input is one short. The count once held the
    ground's copy of the point as a ball (3 equations): the declaration let it through and the
    solver said '7 unknowns but 6 equations'. 7 unknowns (one body), 5 equations (its norm and
    the joint's 4): 2 freedoms."""
    scene = write_scene(tmp_path, CYLINDER.replace('[[inputs]]\njoint = "c.s"\nsweep = { from = 0.5, to = 2, steps = 4 }\n', ""))
    code, _, err = run_cli(capsys, "solve", scene)
    assert code == 2 and "Traceback" not in err, err
    assert "[inputs]" in err and "2 degree(s) of freedom" in err and "1 input(s)" in err, err


CARDAN = """
title = "single Cardan joint, shafts at 30 deg, driven by the cross's angle"
space = "3d"
units = { length = "mm", angle = "deg", time = "s" }
[ground]
A = [0, 0, 0]
[links]
s1 = { points = { A = [0, 0, 0], K = [0, 0, 0], P = [-100, 0, 0] } }
s2 = { points = { K = [0, 0, 0], Q = [86.60254037844386, 50, 0] } }
[[joints]]
type = "revolute"
name = "in"
point = "A"
axis = [1, 0, 0]
[[joints]]
type = "universal"
name = "x"
point = "K"
axes = [[0, 1, 0], [0, 0, 1]]
[[joints]]
type = "revolute"
name = "out"
point = "Q"
axis = [0.8660254037844386, 0.5, 0]
bodies = ["ground", "s2"]
[[inputs]]
joint = "x.angle1"
sweep = { from = 0, to = 20, steps = 3 }
rate = 2
[output]
report = ["in.angle", "out.angle", "x.angle1", "x.omega1"]
"""


def test_a_universal_joints_angle_as_input_is_in_degrees_everywhere(tmp_path, capsys):
    """`joint = "x.angle1"` drives an angle: its values, rate and range are in the scene's
    degrees (they were shown in radians, the range labelled mm). The cross turns about the
    input yoke's axis by at most the shafts' angle: limits at -30 and 30 deg. The reported
    x.angle1 equals the input, x.omega1 its rate."""
    scene = write_scene(tmp_path, CARDAN)
    code, out, err = run_cli(capsys, "solve", scene, "--json")
    assert code == 0, err
    assert np.allclose(out["inputs"]["x.angle1"], [0, 10, 20], atol=1e-12)
    assert out["rates"]["x.angle1"] == 2
    assert np.allclose(out["values"]["x.angle1"], [0, 10, 20], atol=1e-9)
    assert np.allclose(out["values"]["x.omega1"], 2, atol=1e-9)
    code, text, err = run_cli(capsys, "solve", scene)
    assert code == 0 and "x.angle1 rate 2 deg/s" in text, text
    assert text.splitlines()[4].split()[0] == "10", text
    code, out, err = run_cli(capsys, "range", scene, "--json")
    assert code == 0, err
    r = out["ranges"]["x.angle1"]
    assert abs(r["from"] + 30) < 1e-7 and abs(r["to"] - 30) < 1e-7, r
    code, text, err = run_cli(capsys, "range", scene)
    assert "deg" in text and "mm" not in text, text


def test_groups_are_named_by_the_bodies_they_place():
    """A hung body's unknown is its joint's coordinate (`D.angle`): the group it forms is
    still named by the body (events and resumes say "group rocker"), not by the joint."""
    for name, want in [("space_rssr", [("rocker",)]), ("space_suspension", [("upper", "upright")])]:
        model = kincas.model_of(kincas.scene.load(EXAMPLES / f"{name}.toml").mechanism)
        assert [b.links for b in model.blocks] == want, name
