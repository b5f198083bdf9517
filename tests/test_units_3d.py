"""Units of the 3D quantity names (scene-format.md, "Quantities in 3D"): a point's z and its
rates, a body's angular velocity and acceleration, numbered joint coordinates, and the pure
numbers of a rotation (quaternion and matrix entries). Each label is written out here by hand
from the contract's table: length/time^k for a point's k-th derivative, angle/time^k for a
rotation's, nothing for a rotation entry."""
import pytest

import kincas
from kincas.frames import unit_of
from kincas.units import unit_label

U = {"length": "mm", "angle": "deg", "time": "s"}
EXPECTED = {"C.z": "mm", "C.vz": "mm/s", "C.az": "mm/s^2", "C.jz": "mm/s^3",
            "rocker.omega_x": "deg/s", "rocker.omega_z": "deg/s", "rocker.alpha_y": "deg/s^2",
            "rocker.qw": "", "rocker.qz": "", "rocker.R11": "", "rocker.R23": "",
            "C.vx": "mm/s", "A.angle": "deg", "A.omega": "deg/s"}


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_unit_labels_of_spatial_quantities(name):
    m = kincas.scene.load("examples/space_rssr.toml").mechanism
    assert unit_label(U, m, name) == EXPECTED[name]
    assert unit_label(U, None, name) == EXPECTED[name]   # without the mechanism as well
    assert unit_of(name, "mm", "deg") == EXPECTED[name]  # the pandas/xarray attrs


def test_numbered_joint_rates_carry_their_time_unit():
    assert unit_of("cross.omega1", "mm", "deg") == "deg/s"
    assert unit_of("cross.alpha2", "mm", "deg") == "deg/s^2"
    assert unit_of("pad.v1", "mm", "deg") == "mm/s"


def test_cli_header_of_a_spatial_scene_names_rates_per_time(tmp_path):
    from kincas.cli.app import main
    import contextlib, io
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(["solve", "examples/space_double_cardan.toml"])
    assert code == 0
    header = buf.getvalue().splitlines()[2]
    assert "mid.omega_x [deg/s]" in header and "out.omega [deg/s]" in header


@pytest.mark.parametrize("name,want", [("shaking.x", "N"), ("shaking.y", "N"), ("shaking.z", "N"),
                                       ("shaking.mx", "N·m"), ("shaking.my", "N·m"), ("shaking.mz", "N·m"),
                                       ("shaking.moment", "N·m")])
def test_shaking_forces_and_moments_are_forces_not_lengths(name, want):
    """shaking.z read as a point's z once got the length unit (and shaking.m* too)."""
    from types import SimpleNamespace
    from kincas.views.columns import quantity_unit
    sc = SimpleNamespace(study=SimpleNamespace(units={"length": "m", "angle": "deg", "time": "s", "force": "N"}),
                         mechanism=None)
    assert quantity_unit(sc, name) == want
    assert unit_of(name, "m", "deg") == ""  # pandas/xarray: no force unit is known there
