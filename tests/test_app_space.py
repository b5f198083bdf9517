"""`kincas app` and `kincas.widget` on a spatial scene: the state carries the points in space
(the page turns them), a parameter change re-solves as `kincas.sweep` does on
`with_parameters`, the edited scene's TOML reads back to the same mechanism, and points are not
dragged in 3D (the mouse turns the view). Browser: tests/test_app_browser.py."""
from __future__ import annotations

import numpy as np
import pytest

import kincas
from kincas.cli.scene import loads
from conftest import ROOT

pytest.importorskip("starlette", reason="kincas[app] is not installed")
from kincas.cli.serve_scene import Session  # noqa: E402

RSSR = ROOT / "examples" / "space_rssr.toml"


def rssr_text(length: float = 125) -> str:
    """examples/space_rssr.toml with its coupler's length a parameter L."""
    text = RSSR.read_text(encoding="utf-8")
    text = text.replace('length = 125 }', 'length = "L" }')
    return text.replace("[ground]", f"[parameters]\nL = {length}\n\n[ground]")


def column(state, name):
    q = next(q for q in state["plot"]["quantities"] if q["name"] == name)
    return np.array([np.nan if v is None else v for v in q["values"]], float)


def test_the_state_of_a_spatial_scene_keeps_its_points_in_space():
    sc = loads(rssr_text())
    st = Session(sc, "rssr.toml", rssr_text()).live.state()
    d = st["drawing"]
    assert d["space"] and len(d["camera"]) == 3 and d["up"] == 2
    xy = np.array(d["xy"], float)
    assert xy.shape == (361, 4, 3) and all(st["ok"])
    b, c = (xy[:, d["names"].index(p)] for p in "BC")
    np.testing.assert_allclose(np.linalg.norm(c - b, axis=1), 125, rtol=1e-9)  # the coupler's length
    np.testing.assert_allclose(np.linalg.norm(b, axis=1), 15, rtol=1e-9)       # the crank's radius
    assert [p["name"] for p in st["parameters"]] == ["L"]
    assert d["forces"] == [] and d["loads"] == [] and st["centres"] == {}


def test_a_parameter_change_on_a_spatial_scene_solves_as_sweep_on_with_parameters():
    sc = loads(rssr_text())
    s = Session(sc, "rssr.toml", rssr_text())
    st = s.request("change", {"parameters": {"L": 118}})
    want = kincas.sweep(sc.mechanism.with_parameters(L=118), sc.study.inputs, report=["C.z", "D.angle"])
    assert all(st["ok"]) and want.ok.all()
    np.testing.assert_allclose(column(st, "C.z"), want["C.z"], rtol=1e-9, atol=1e-9)
    xy = np.array(st["drawing"]["xy"], float)
    b, c = (xy[:, st["drawing"]["names"].index(p)] for p in "BC")
    np.testing.assert_allclose(np.linalg.norm(c - b, axis=1), 118, rtol=1e-9)
    back = loads(s.toml())  # the edited scene reads back to the same mechanism
    assert back.mechanism.param_values["L"] == 118
    again = kincas.sweep(back.mechanism, back.study.inputs, report=["C.z"])
    np.testing.assert_allclose(again["C.z"], want["C.z"], rtol=1e-9, atol=1e-9)


def test_points_of_a_spatial_scene_are_not_dragged():
    s = Session(loads(rssr_text()), "rssr.toml", rssr_text())
    with pytest.raises(Exception, match="3D|space|spatial"):
        s.request("drag", {"point": "D", "x": 1.0, "y": 2.0})


def test_the_widget_shows_a_spatial_mechanism():
    pytest.importorskip("anywidget", reason="anywidget (kincas[app]) is not installed")
    sc = loads(rssr_text())
    w = kincas.widget(sc.mechanism)
    assert "kOrbit" in w._esm
    st = w.live.state()
    assert st["drawing"]["space"] and np.array(st["drawing"]["xy"], float).shape[2] == 3


def test_a_fixed_joint_input_edited_in_the_page_is_written_back_to_the_toml():
    """A spatial scene's fixed input on a joint (`joint = "A"`) edited by its slider is saved
    in the downloaded scene: the exported TOML solves the new crank angle, not the old one."""
    text = RSSR.read_text(encoding="utf-8").replace("sweep = { from = 0, to = 360, steps = 361 }", "value = 30")
    sess = Session(loads(text), "rssr.toml", text)
    (key,) = sess.live.fixed()
    sess.request("change", {"inputs": {key: 75}})
    again = loads(sess.toml())
    (k2,) = again.study.inputs
    np.testing.assert_allclose(np.degrees(np.asarray(again.study.inputs[k2], float)), [75.0], atol=1e-9)


def test_a_spatial_page_gets_its_loads_and_weights_in_space():
    """The live page projects what it is given: a force as its vector in space, a torque as a
    moment vector, each body's weight m g at its centre of gravity carried by the body's motion
    (here a plate turning about z by theta: its cg, off the plate's plane, at Rz(theta) cg)."""
    text = """
space = "3d"
units = { length = "mm", angle = "deg", time = "s" }
gravity = [0, 0, -9810]
[ground]
O = [0, 0, 0]
[links]
plate = { points = { O = [0, 0, 0], P = [100, 0, 0], R = [0, 30, 0] }, mass = 0.002, cg = [50, 10, 5] }
[[joints]]
type = "revolute"
point = "O"
axis = [0, 0, 1]
[[loads]]
point = "P"
force = [0, -10, -20]
[[loads]]
link = "plate"
torque = [0, 0, 7]
[[inputs]]
joint = "O"
sweep = { from = 0, to = 90, steps = 4 }
[output]
report = ["effort(O.angle)"]
"""
    d = Session(loads(text), "plate.toml", text).live.state()["drawing"]
    by = {ld["kind"]: ld for ld in d["loads"]}
    assert by["force"]["vector"] == [0, -10, -20] and d["names"][by["force"]["point"]] == "P"
    assert by["moment"]["vector"] == [0, 0, 7] and d["names"][by["moment"]["point"]] == "O"
    np.testing.assert_allclose(by["weight"]["vector"], [0, 0, -0.002 * 9810], rtol=1e-12)
    th = np.radians([0, 30, 60, 90])
    want = np.stack([50 * np.cos(th) - 10 * np.sin(th), 50 * np.sin(th) + 10 * np.cos(th), np.full(4, 5.0)], axis=1)
    np.testing.assert_allclose(np.array(by["weight"]["at"], float), want, atol=1e-9)
    (eff,) = d["forces"]
    assert eff["kind"] == "effort" and d["names"][eff["point"]] == "O" and len(eff["values"]) == 4
