"""Cam design (kincas/synthesis/cam_design.py, `kincas cam`): the motion laws against their
closed forms, pressure angle and radius of curvature against the pitch curve's geometry
computed here by differences, and the designed profile fed back into a scene reproducing
the motion law to 1e-9 of the lift."""
from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from conftest import run_cli

from kincas.synthesis.cam_design import Segment, design_cam, law, motion

SEGMENTS = [Segment("rise", 90, 20, "cycloidal"), Segment("dwell", 60),
            Segment("return", 120, 20, "polynomial345"), Segment("dwell", 90)]


@pytest.mark.parametrize("name,x,y", [
    ("cycloidal", 0.25, 0.25 - 1 / (2 * math.pi)),
    ("harmonic", 1 / 3, (1 - 0.5) / 2),
    ("polynomial345", 0.2, 10 * 0.008 - 15 * 0.0016 + 6 * 0.00032),
])
def test_laws_closed_forms_and_derivatives(name, x, y):
    assert float(law(name, x)[0]) == pytest.approx(y, abs=1e-15)
    assert float(law(name, 0.0)[0]) == 0 and float(law(name, 1.0)[0]) == pytest.approx(1, abs=1e-15)
    h = 1e-4
    f = [float(law(name, x + k * h)[0]) for k in (-2, -1, 0, 1, 2)]
    d1 = (f[0] - 8 * f[1] + 8 * f[3] - f[4]) / (12 * h)
    d2 = (-f[0] + 16 * f[1] - 30 * f[2] + 16 * f[3] - f[4]) / (12 * h * h)
    assert float(law(name, x)[1]) == pytest.approx(d1, abs=1e-9)
    assert float(law(name, x)[2]) == pytest.approx(d2, abs=1e-5)


def test_pressure_and_curvature_against_the_pitch_curve():
    """The pitch curve from its definition (the roller centre at (e, s0 + s) seen from the
    cam), its normal and radius of curvature by central differences in theta."""
    e, rb, rho = 8.0, 40.0, 10.0
    d = design_cam(SEGMENTS, rb, rho, e, points=720)
    s0 = math.sqrt((rb + rho) ** 2 - e * e)
    h = 1e-4

    def pitch(t):
        s = motion(SEGMENTS, np.mod(np.atleast_1d(t), 2 * math.pi))[0]
        c, si = np.cos(t), np.sin(t)
        return np.stack([c * e + si * (s0 + s), -si * e + c * (s0 + s)], axis=-1)
    t = d.theta[5::37] + 0.3 * (2 * math.pi / 720)  # inside segments, off the joins
    t = t[np.all([np.abs(t - math.radians(a)) > 1e-3 for a in (0, 90, 150, 270)], axis=0)]
    P = [pitch(t + k * h) for k in (-1, 0, 1)]
    d1, d2 = (P[2] - P[0]) / (2 * h), (P[2] - 2 * P[1] + P[0]) / h ** 2
    kappa = (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.hypot(*d1.T) ** 3
    ref = design_cam(SEGMENTS, rb, rho, e, points=720)
    # evaluate the design's formulas at the same angles through a design sampled there
    s, ds, dds = motion(SEGMENTS, t)
    # world normal of the pitch curve at the follower: the cam-frame normal turned by theta
    n_cam = np.stack([-d1[:, 1], d1[:, 0]], axis=1)
    c, si = np.cos(t), np.sin(t)
    n_world = np.stack([c * n_cam[:, 0] - si * n_cam[:, 1], si * n_cam[:, 0] + c * n_cam[:, 1]], axis=1)
    pressure = np.arctan2(np.abs(n_world[:, 0]), np.abs(n_world[:, 1]))  # against the y axis
    np.testing.assert_allclose(np.arctan(np.abs(ds - e) / (s0 + s)), pressure, atol=1e-7)
    # the design's own arrays at its sample angles, checked the same way
    k = np.arange(3, 720, 41)
    P = [pitch(ref.theta[k] + j * h) for j in (-1, 0, 1)]
    d1, d2 = (P[2] - P[0]) / (2 * h), (P[2] - 2 * P[1] + P[0]) / h ** 2
    kappa = (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.hypot(*d1.T) ** 3
    np.testing.assert_allclose(1 / ref.rho_pitch[k], -kappa, atol=1e-6 / (rb + rho))
    np.testing.assert_allclose(ref.pitch[k], P[1], atol=1e-12 * rb)
    np.testing.assert_allclose(np.hypot(*(ref.pitch - ref.profile).T), rho, rtol=1e-12)


def _scene(block: str, e: float, s0: float, follower_y: float) -> str:
    return f"""# the designed cam turning about O; the follower rod translates along x = {e}
[ground]
O = [0, 0]
[links]
shaft = {{ points = {{ O = [0, 0], K = [10, 0] }} }}
rod = {{ points = {{ F = [0, 0], T = [0, 60] }} }}
[[slides]]
name = "s1"
point = "F"
along = "ground"
line = {{ through = [{e}, 0], angle = 90 }}
[[slides]]
name = "s2"
point = "T"
along = "ground"
line = {{ through = [{e}, 0], angle = 90 }}
{block}
[[inputs]]
angle = "shaft"
sweep = {{ from = 0, to = 359, steps = 360 }}
[guess]
F = [{e}, {follower_y}]
T = [{e}, {follower_y + 60}]
[output]
report = ["F.y"]
"""


@pytest.mark.parametrize("rho", [0.0, 10.0], ids=["knife", "roller"])
def test_designed_profile_reproduces_the_motion_law(capsys, tmp_path, rho):
    e, rb = 8.0, 40.0
    design = tmp_path / "design.toml"
    segs = ", ".join(f'{{ motion = "{s.motion}", angle = {s.angle}, lift = {s.lift}, law = "{s.law}" }}'
                     for s in SEGMENTS)
    design.write_text(f"[cam_design]\nbase_radius = {rb}\nroller_radius = {rho}\noffset = {e}\n"
                      f"samples = 1440\nbody = \"shaft\"\nsegments = [{segs}]\n")
    code, out, err = run_cli(capsys, "cam", design, "--out", tmp_path / "profile.toml",
                             "--csv", tmp_path / "cam.csv")
    assert code == 0, err
    block = (tmp_path / "profile.toml").read_text()
    assert tomllib.loads(block)["cams"][0]["body"] == "shaft"
    s0 = math.sqrt((rb + rho) ** 2 - e * e)
    scene = tmp_path / "scene.toml"
    scene.write_text(_scene(block, e, s0, s0))
    code, out, err = run_cli(capsys, "solve", scene, "--json")
    assert code == 0, err
    th = np.radians(np.arange(360.0))  # every degree: knots and, with 1440 samples, only knots;
    s = motion(SEGMENTS, th)[0]
    np.testing.assert_allclose(np.array(out["values"]["F.y"]) - s0, s, rtol=0, atol=1e-9 * 20)
    # between the knots (a quarter of a sample step off them) the spline holds it too
    text = _scene(block, e, s0, s0).replace("sweep = { from = 0, to = 359, steps = 360 }",
                                            "sweep = { from = 0.0625, to = 359.0625, steps = 360 }")
    scene.write_text(text)
    code, out, err = run_cli(capsys, "solve", scene, "--json")
    assert code == 0, err
    s = motion(SEGMENTS, th + math.radians(0.0625))[0]
    np.testing.assert_allclose(np.array(out["values"]["F.y"]) - s0, s, rtol=0, atol=1e-9 * 20)
    rows = (tmp_path / "cam.csv").read_text().splitlines()
    assert len(rows) == 1441 and rows[0].startswith("theta [deg],s,")


def test_undercut_is_flagged(capsys, tmp_path):
    """A steep rise on a small base circle with a large roller: the pitch curve's radius of
    curvature falls below the roller's somewhere, and it is reported."""
    d = design_cam([Segment("rise", 40, 30, "harmonic"), Segment("return", 320, 30, "harmonic")], 10, 12)
    assert d.undercut.any()
    assert np.all(d.rho_pitch[d.undercut] <= 12)
    ok = design_cam(SEGMENTS, 40, 10, 8)
    assert not ok.undercut.any() and np.all(ok.rho_profile[ok.rho_pitch > 0] > 0)
    f = tmp_path / "c.toml"
    f.write_text('[cam_design]\nbase_radius = 10\nroller_radius = 12\nsegments = ['
                 '{ motion = "rise", angle = 40, lift = 30, law = "harmonic" },'
                 '{ motion = "return", angle = 320, lift = 30, law = "harmonic" }]\n')
    code, out, err = run_cli(capsys, "cam", f)
    assert code == 0 and "undercut" in out


@pytest.mark.parametrize("text,words", [
    ('base_radius = 40\nsegments = [{ motion = "rise", angle = 90, lift = 10 }]', ["segments", "360"]),
    ('base_radius = 40\nsegments = [{ motion = "rise", angle = 180, lift = 10 },'
     '{ motion = "return", angle = 180, lift = 5 }]', ["segments", "ends"]),
    ('base_radius = 40\nsegments = [{ motion = "lift", angle = 360, lift = 10 }]', ["segments[0].motion"]),
    ('base_radius = 40\nsegments = [{ motion = "rise", angle = 180, lift = 10, law = "spline" },'
     '{ motion = "return", angle = 180, lift = 10 }]', ["segments[0].law"]),
    ('base_radius = -4\nsegments = [{ motion = "dwell", angle = 360 }]', ["base_radius"]),
    ('base_radius = 40\noffset = 50\nsegments = [{ motion = "dwell", angle = 360 }]', ["offset"]),
    ('base_radius = 40\ncolour = 1\nsegments = [{ motion = "dwell", angle = 360 }]', ["colour"]),
])
def test_bad_cam_design_fields(capsys, tmp_path, text, words):
    f = tmp_path / "c.toml"
    f.write_text("[cam_design]\n" + text + "\n")
    code, out, err = run_cli(capsys, "cam", f)
    assert code == 2, err
    assert "[cam_design]" in err and all(w in err for w in words), err
