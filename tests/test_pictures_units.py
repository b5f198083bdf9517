"""Units that read as people write them (scene format v3): `units.force` and `units.mass`
label efforts, reactions and shaking forces; an input's `rate`, `acceleration` and `jerk` may
be a string with its own unit ("3000 rpm", "50 rad/s", "10 deg/s^2"), converted to the
scene's units. Every conversion factor below is written out here, independent of kincas."""
from __future__ import annotations

import math
import subprocess
import sys

import pytest

import kincas

from kincas.cli.scene import loads
from kincas.errors import SceneError
from kincas.units import parse_rate

DEG = 180 / math.pi  # degrees per radian

CRANK = """
units = {{ length = "{L}", angle = "{A}", time = "{T}" }}
[ground]
A = [0, 0]
[links]
crank = {{ points = ["A", "B"], length = 1 }}
[[inputs]]
angle = "crank"
sweep = {{ from = 0, to = 90, steps = 3 }}
{extra}
[output]
report = ["B.x"]
"""


def scene(extra, L="mm", A="deg", T="s"):
    return loads(CRANK.format(extra=extra, L=L, A=A, T=T))


@pytest.mark.parametrize("text, angle, time, order, expected", [
    ("3000 rpm", "deg", "s", 1, 3000 * 360 / 60),             # rev/min -> deg/s
    ("3000 rpm", "rad", "s", 1, 3000 * 2 * math.pi / 60),
    ("50 rad/s", "deg", "s", 1, 50 * DEG),
    ("50 rad/s", "rad", "min", 1, 50 * 60),
    ("10 deg/s^2", "rad", "s", 2, 10 / DEG),
    ("10 deg/s²", "deg", "ms", 2, 10 * 1e-6),                 # per ms^2: a millionth
    ("-2.5e1 deg/s", "deg", "s", 1, -25.0),
    ("2 rev/s", "deg", "s", 1, 720.0),
    ("1 rps", "rad", "s", 1, 2 * math.pi),
    ("120 rpm/s", "deg", "s", 2, 120 * 6.0),                   # rpm per second: 6 deg/s per rpm
    ("7 deg/s^3", "deg", "s", 3, 7.0),
    ("90 deg/min", "deg", "s", 1, 1.5),
])
def test_angular_rates(text, angle, time, order, expected):
    assert parse_rate(text, angle, time, order=order) == pytest.approx(expected, rel=1e-14)


@pytest.mark.parametrize("text, length, order, expected", [
    ("0.5 m/s", "mm", 1, 500.0),
    ("3 in/s", "mm", 1, 76.2),
    ("2 mm/s^2", "m", 2, 0.002),
    ("12 cm/s", "cm", 1, 12.0),
])
def test_length_rates(text, length, order, expected):
    assert parse_rate(text, "deg", "s", order=order, length_unit=length, angular=False) \
        == pytest.approx(expected, rel=1e-14)


@pytest.mark.parametrize("text, kw, words", [
    ("3000 furlongs/s", {}, ["rate", "furlongs"]),
    ("10 deg/s^2", {}, ["rate", "deg/s^2", "per s"]),           # an acceleration where a rate goes
    ("50 rad/s", {"order": 2, "where": "acceleration"}, ["acceleration", "rad/s"]),
    ("fast", {}, ["rate", "fast"]),
    ("5 mm/s", {}, ["rate", "mm/s", "angle"]),                 # a length rate for an angle input
    ("5 rad/s", {"angular": False, "length_unit": "mm"}, ["rate", "rad/s", "length"]),
    ("5 m/s", {"angular": False, "length_unit": ""}, ["rate", "length"]),
])
def test_bad_units_are_one_line_naming_the_field(text, kw, words):
    with pytest.raises(ValueError) as e:
        parse_rate(text, "deg", "s", **kw)
    msg = str(e.value)
    assert "\n" not in msg and all(w in msg for w in words), msg


def test_a_scene_converts_its_inputs_rates():
    sc = scene('rate = "3000 rpm"\nacceleration = "10 rad/s^2"\njerk = "1 rev/s^3"')
    k = "crank.angle"
    # inside: radians; 3000 rpm = 3000 * 2 pi / 60 rad/s
    assert sc.study.rates[k] == pytest.approx(3000 * 2 * math.pi / 60, rel=1e-14)
    assert sc.study.accelerations[k] == pytest.approx(10.0, rel=1e-14)
    sw = kincas.sweep(sc.mechanism, sc.study.inputs, rates=sc.study.rates, report=["B.vx", "B.vy"])
    # B turns on a unit circle: |v_B| = omega * 1
    assert sw.ok.all()
    assert (sw.values["B.vx"] ** 2 + sw.values["B.vy"] ** 2) ** 0.5 == pytest.approx(100 * math.pi, rel=1e-12)


def test_a_slide_rate_in_other_length_units():
    sc = loads("""
units = { length = "mm" }
[ground]
O = [0, 0]
[links]
crank = { points = ["O", "A"], length = 10 }
rod = { points = ["A", "B"], length = 30 }
[[slides]]
point = "B"
along = "ground"
name = "slider"
[[inputs]]
slide = "slider"
sweep = { from = 25, to = 35, steps = 3 }
rate = "0.2 m/s"
[guess]
A = [10, 0]
""")
    assert sc.study.rates["slider.s"] == pytest.approx(200.0, rel=1e-14)


def test_a_parameter_name_still_works_as_a_rate():
    sc = loads(CRANK.format(L="mm", A="deg", T="s", extra='rate = "w"').replace(
        "[ground]", "[parameters]\nw = 90\n[ground]"))
    assert sc.study.rates["crank.angle"] == pytest.approx(math.pi / 2, rel=1e-14)


def test_a_bad_unit_in_a_scene_names_the_input_and_field(tmp_path):
    with pytest.raises(SceneError) as e:
        scene('rate = "3000 rpms"')
    assert "[[inputs]] crank.angle: rate" in str(e.value) and "rpms" in str(e.value)
    path = tmp_path / "bad.toml"
    path.write_text(CRANK.format(L="mm", A="deg", T="s", extra='acceleration = "3 m/s^2"'))
    r = subprocess.run([sys.executable, "-m", "kincas", "solve", str(path)], capture_output=True, text=True)
    assert r.returncode == 2
    line = [ln for ln in r.stderr.splitlines() if "acceleration" in ln]
    assert line and "[[inputs]] crank.angle: acceleration" in line[0], r.stderr


def test_force_and_mass_labels():
    from kincas.views.columns import quantity_unit
    sc = loads(open("examples/forces_toggle.toml").read().replace(
        'force = "N" }', 'force = "N", mass = "kg" }'))
    assert quantity_unit(sc, "effort(crank.angle)") == "N·mm"  # a torque
    assert quantity_unit(sc, "reaction(B, rocker).x") == "N"
    assert quantity_unit(sc, "rocker.omega") == "deg/s"
    plain = loads(open("examples/forces_toggle.toml").read().replace(', force = "N"', ''))
    assert quantity_unit(plain, "reaction(B, rocker).x") == "force"  # no label: the word


def test_force_label_in_the_printed_table(tmp_path):
    path = tmp_path / "toggle.toml"
    path.write_text(open("examples/forces_toggle.toml").read().replace('time = "s" }', 'time = "s", force = "N" }'))
    r = subprocess.run([sys.executable, "-m", "kincas", "solve", str(path)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "N·mm" in r.stdout and "force" not in r.stdout.replace("forces", ""), r.stdout[:800]
