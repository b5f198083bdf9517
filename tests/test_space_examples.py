"""The spatial examples (examples/space_*.toml) through `kincas solve --json`, against closed
forms written here; and a spatial scene's mistakes, each one line naming section and field,
exit 2."""
import math
import tomllib

import numpy as np
import pytest
from conftest import EXAMPLES, run_cli, write_scene

SPACE = sorted(EXAMPLES.glob("space_*.toml"))


_SOLVED: dict = {}  # each example solved once for the tests of this file


def solve(capsys, path):
    if path not in _SOLVED:
        code, out, err = run_cli(capsys, "solve", path, "--json")
        assert code == 0, err
        assert out["status"] == ["ok"] * len(out["status"])
        _SOLVED[path] = ({k: np.array(v, float) for k, v in out["values"].items()},
                         {k: np.array(v, float) for k, v in out["inputs"].items()})
    return _SOLVED[path]


def wrap_deg(a):
    return (np.asarray(a) + 180) % 360 - 180


def test_every_spatial_example_is_described_and_solves(capsys):
    assert len(SPACE) == 10  # + space_stewart_40 (Dietmaier: tests/test_certify_space.py); the bump steer optimisation
    for path in SPACE:
        text = path.read_text(encoding="utf-8")
        assert text.startswith("#") and tomllib.loads(text)["space"] == "3d"
        solve(capsys, path)


def test_double_cardan_turns_its_output_exactly_with_its_input(capsys):
    v, u = solve(capsys, EXAMPLES / "space_double_cardan.toml")
    assert np.abs(wrap_deg(v["out.angle"] - u["in.angle"])).max() < 1e-9
    assert np.allclose(v["out.omega"], 1.0, rtol=1e-10)


def test_bennett_example_keeps_th3_equal_to_minus_th1(capsys):
    v, u = solve(capsys, EXAMPLES / "space_bennett.toml")
    assert np.abs(wrap_deg(v["O3.angle"] + u["O1.angle"])).max() < 1e-9
    assert np.abs(wrap_deg(v["O4.angle"] + v["O2.angle"])).max() < 1e-9
    # tan(th1/2) tan(th2/2) = sin((b + a)/2) / sin((b - a)/2), th1 = 1 rad + the input
    k = math.sin(math.radians(55)) / math.sin(math.radians(15))
    th1 = 1.0 + np.radians(u["O1.angle"])
    th2 = 2 * np.arctan(k / np.tan(th1 / 2))
    assert np.abs(wrap_deg(v["O2.angle"] - np.degrees(th2 - th2[0]))).max() < 1e-9


def test_stewart_platform_heaves_as_its_equal_legs_grow(capsys):
    scene = tomllib.loads((EXAMPLES / "space_stewart.toml").read_text())
    v, u = solve(capsys, EXAMPLES / "space_stewart.toml")
    B1 = np.array(scene["ground"]["B1"])
    P1 = np.array(scene["links"]["platform"]["points"]["P1"])
    horiz = np.linalg.norm((P1 - B1)[:2])  # unchanged by a straight rise
    assert np.allclose(v["P1.z"], np.sqrt(u["l1"] ** 2 - horiz ** 2), rtol=0, atol=1e-10)
    assert np.allclose(v["P1.vz"], u["l1"] / v["P1.z"], rtol=1e-9)  # rate 1 of every leg
    assert np.abs(v["platform.qz"]).max() < 1e-12


def test_delta_plate_height_against_its_closed_form(capsys):
    v, u = solve(capsys, EXAMPLES / "space_delta.toml")
    Rb, La, rp, Lb = 100.0, 80.0, 30.0, 200.0
    th = np.radians(u["O1.angle"])
    # an arm turned th about its tangent: its end at O + La (cos th e - sin th z)
    z = -La * np.sin(th) - np.sqrt(Lb ** 2 - (Rb + La * np.cos(th) - rp) ** 2)
    assert np.allclose(v["P1.z"], z, rtol=0, atol=1e-10)
    assert np.allclose(v["P1.x"], rp, atol=1e-10) and np.allclose(v["plate.qw"], 1.0, atol=1e-13)


def test_spatial_slider_crank_against_its_quadratic(capsys):
    scene = tomllib.loads((EXAMPLES / "space_slider_crank.toml").read_text())
    v, u = solve(capsys, EXAMPLES / "space_slider_crank.toml")
    C0 = np.array(scene["links"]["slider"]["points"]["C"])
    d = np.array(scene["joints"][1]["axis"])
    Lr, r = scene["links"]["rod"]["length"], 40.0
    th = np.radians(u["A.angle"])
    B = np.stack([r * np.cos(th), r * np.sin(th), 0 * th], axis=1)
    b = (C0 - B) @ d  # |C0 + s d - B|^2 = Lr^2: s^2 + 2 b s + c = 0
    c = np.einsum("ij,ij->i", C0 - B, C0 - B) - Lr ** 2
    s = -b + np.sqrt(b * b - c)
    assert np.allclose(v["slide.s"], s, rtol=0, atol=1e-9)
    h = 1e-6  # slide.v per degree of crank (rate 1 deg/s), by central differences
    sp = lambda t: (lambda B: -(C0 - B) @ d + np.sqrt(((C0 - B) @ d) ** 2 - (C0 - B) @ (C0 - B) + Lr ** 2))(
        np.array([r * math.cos(t), r * math.sin(t), 0.0]))
    dv = [(sp(t + h) - sp(t - h)) / (2 * h) * math.pi / 180 for t in th[:5]]
    assert np.allclose(v["slide.v"][:5], dv, rtol=1e-6)


def test_suspension_keeps_its_links(capsys):
    scene = tomllib.loads((EXAMPLES / "space_suspension.toml").read_text())
    v, _ = solve(capsys, EXAMPLES / "space_suspension.toml")
    up = scene["links"]["upright"]["points"]
    W0, LB0 = np.array(up["W"]), np.array(up["LB"])
    col = np.stack([v["upright.R12"], v["upright.R22"], v["upright.R32"]], axis=1)
    assert np.allclose(np.linalg.norm(col, axis=1), 1.0, atol=1e-12)
    W = np.stack([v["W.x"], v["W.y"], v["W.z"]], axis=1)
    assert np.all(np.diff(v["W.z"]) > 0)  # the wheel rises through its travel
    camber = np.degrees(np.arctan2(col[:, 2], col[:, 1]))
    assert np.abs(camber).max() < 5  # a few degrees, as suspensions do
    assert np.all(np.abs(v["LB.z"] - LB0[2]) <= np.linalg.norm(LB0 - np.array(scene["ground"]["LA"])))
    assert np.all(np.linalg.norm(W - W0, axis=1) < 200)


SCENE = '''space = "3d"
[ground]
A = [0, 0, 0]
D = [100, 40, 30]
[links]
crank = { points = { A = [0, 0, 0], B = [15, 0, 0] } }
coupler = { points = ["B", "C"], length = 125 }
rocker = { points = { D = [100, 40, 30], C = [100, 40, 90] } }
[[joints]]
type = "revolute"
point = "A"
axis = [0, 0, 1]
[[joints]]
type = "revolute"
point = "D"
axis = [1, 0, 0]
[[inputs]]
joint = "A"
value = 10
'''


@pytest.mark.parametrize("edit, words", [
    (('axis = [1, 0, 0]', 'axis = [1, 0, 0]\n[[joints]]\ntype = "universal"\npoint = "C"\naxes = [[1, 0, 0], [1, 1, 0]]'),
     "axes: the two axes are not perpendicular"),
    (('axis = [1, 0, 0]', 'axis = [1, 0, 0]\n[[joints]]\ntype = "revolute"\npoint = "B"\naxis = [0, 0, 1]\nbodies = ["crank", "coupler"]'),
     "two-point bar"),
    (('[[inputs]]', '[[gears]]\nlinks = ["crank", "rocker"]\nradii = [1, 2]\n[[inputs]]'), "[gears]: gears stay planar"),
    (('coupler = { points = ["B", "C"], length = 125 }', 'coupler = { points = ["B", "M"], length = 60 }\nc2 = { points = ["M", "C"], length = 70 }'),
     "[guess] M: missing"),
    (('joint = "A"', 'joint = "Z"'), "[[inputs]] 1: joint: unknown joint 'Z'"),
    (('joint = "A"', 'joint = "A.s"'), "a revolute joint's coordinates are ['A.angle']"),
    (('axis = [0, 0, 1]', 'axis = [0, 0, 0]'), "[[joints]] A: axis: [0, 0, 0] has no direction"),
    (('D = [100, 40, 30]\n[links]', 'D = [100, 40]\n[links]'), "[ground] D: expected [x, y, z]"),
])
def test_spatial_scene_mistakes_are_one_line_naming_the_field(capsys, tmp_path, edit, words):
    text = SCENE.replace(*edit)
    assert text != SCENE
    code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, text))
    assert code == 2, err
    assert words in err and "Traceback" not in err


def test_spatial_scene_solves_and_names_inputs_by_coordinate(capsys, tmp_path):
    code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, SCENE), "--json")
    assert code == 0, err
    assert list(out["inputs"]) == ["A.angle"] and out["status"] == ["ok"]
    assert set(out["values"]) == {"B.x", "B.y", "B.z", "C.x", "C.y", "C.z", "A.angle", "D.angle"}
    assert abs(out["values"]["A.angle"][0] - 10) < 1e-9
