"""Gears, racks, cams and relative inputs beyond the examples: a polar (spline) cam against
scipy's periodic spline, velocities and accelerations against central differences of solved
positions, sensitivities to a gear radius and a cam radius against central differences of
solves, `modes` and `range`, the first pose's angles, and every bad field (exit 2 naming it).
"""
from __future__ import annotations

import copy
import math
import tomllib

import numpy as np
import pytest

from conftest import EXAMPLES, run_cli, write_scene

import kincas
from kincas import Input, Link, Mechanism, Slide
from kincas.errors import ModelError
from kincas.model import Cam, Circle, Gear, Polar, Rack

D = math.pi / 180


def scene(name):
    return tomllib.loads((EXAMPLES / f"{name}.toml").read_text(encoding="utf-8"))


# --- a polar profile: a radial knife-edge follower reads r(phi) off the spline ---

ANGLES = [0.0, 50.0, 100.0, 170.0, 220.0, 290.0]
RADII = [40.0, 46.0, 52.0, 47.0, 41.0, 38.0]


def polar_cam(radii=RADII, follower=None):
    """The profile turns about O; the knife F is kept on the y axis (two slides)."""
    return Mechanism(
        parameters={f"r{k}": v for k, v in enumerate(radii)},
        ground={"O": (0, 0)},
        links=[Link("cam", {"O": (0, 0), "K": (10, 0)}), Link("rod", {"F": (0, 0), "T": (0, 60)})],
        slides=[Slide("F", "ground", angle=math.pi / 2, name="s1"),
                Slide("T", "ground", angle=math.pi / 2, name="s2")],
        cams=[Cam("cam", "cam", Polar(np.radians(ANGLES), [f"r{k}" for k in range(len(radii))]),
                  knife="F")],
        inputs=[Input.angle("cam")], guess={"F": (0, 45), "T": (0, 105)})


def reference_radius(phi, radii=RADII):
    """scipy's periodic cubic spline through the profile, closed by repeating the first point."""
    from scipy.interpolate import CubicSpline
    a = np.radians(ANGLES)
    cs = CubicSpline(np.append(a, a[0] + 2 * np.pi), np.append(radii, radii[0]), bc_type="periodic")
    t = np.mod(phi - a[0], 2 * np.pi) + a[0]
    return cs(t), cs(t, 1), cs(t, 2)


def test_polar_profile_matches_scipy_periodic_spline():
    """The knife on the y axis touches the profile at body angle 90 deg - theta: F.y = r(pi/2 - theta),
    F.vy = -r' omega, F.ay = r'' omega^2 (omega = 1, alpha = 0)."""
    th = np.linspace(0, 2 * np.pi, 91)
    m = polar_cam()
    sw = kincas.sweep(m, {"cam.angle": th}, report=["F.y", "F.vy", "F.ay", "cam.phi", "cam.contact.y"])
    assert all(s == "ok" for s in sw.status)
    r, dr, ddr = reference_radius(np.pi / 2 - th)
    np.testing.assert_allclose(sw["F.y"], r, rtol=0, atol=1e-10 * 52)
    np.testing.assert_allclose(sw["cam.contact.y"], r, rtol=0, atol=1e-10 * 52)
    np.testing.assert_allclose(sw["F.vy"], -dr, rtol=0, atol=1e-9 * np.abs(dr).max())
    np.testing.assert_allclose(sw["F.ay"], ddr, rtol=0, atol=1e-8 * np.abs(ddr).max())
    phi = np.mod(np.pi / 2 - th + np.pi, 2 * np.pi) - np.pi
    assert np.all(np.abs(np.angle(np.exp(1j * (sw["cam.phi"] - phi)))) < 1e-12)


def test_polar_radius_sensitivity_against_central_differences():
    """d(F.y)/d(r2) and d(F.vy)/d(r2): exact, against solves with r2 +- h."""
    th, h = np.linspace(0.1, 6.0, 13), 1e-4
    m = polar_cam()
    names = ["F.y", "F.vy", "d(F.y)/d(r2)", "d(F.vy)/d(r2)"]
    sw = kincas.sweep(m, {"cam.angle": th}, report=names)
    up = kincas.sweep(m.with_parameters(r2=RADII[2] + h), {"cam.angle": th}, report=names[:2])
    dn = kincas.sweep(m.with_parameters(r2=RADII[2] - h), {"cam.angle": th}, report=names[:2])
    for q in ("F.y", "F.vy"):
        fd = (up[q] - dn[q]) / (2 * h)
        np.testing.assert_allclose(sw[f"d({q})/d(r2)"], fd, rtol=0, atol=1e-6 * max(1, np.abs(fd).max()))


# --- velocities and accelerations against central differences of solved positions ---


def _differences(m, key, u, names, h=1e-4):
    f = [kincas.sweep(m, {key: u + j * h}, report=names) for j in (-2, -1, 0, 1, 2)]
    out = {}
    for n in names:
        g = [s[n] for s in f]
        if n.endswith(".angle"):  # unwrap across the five samples at each pose
            g = [g[2] + np.angle(np.exp(1j * (x - g[2]))) for x in g]
        out[n] = ((g[0] - 8 * g[1] + 8 * g[3] - g[4]) / (12 * h),
                  (-g[0] + 16 * g[1] - 30 * g[2] + 16 * g[3] - g[4]) / (12 * h * h))
    return out


@pytest.mark.parametrize("example,rates", [
    ("roller_cam", {"arm.angle": ("arm.omega", "arm.alpha"), "F.x": ("F.vx", "F.ax")}),
    ("flat_tappet", {"F.y": ("F.vy", "F.ay"), "cam.contact.x": ("cam.contact.vx", "cam.contact.ax")}),
    ("rack_fourbar", {"rocker.angle": ("rocker.omega", "rocker.alpha"), "R1.x": ("R1.vx", "R1.ax")}),
    ("planetary", {"planet.angle": ("planet.omega", "planet.alpha"), "M.y": ("M.vy", "M.ay")}),
])
def test_rates_against_differences_of_solved_positions(example, rates):
    from kincas.cli.scene import load
    m = load(EXAMPLES / f"{example}.toml").mechanism
    key = m.inputs[0].key
    u = np.radians(np.linspace(5, 175, 9))
    diffs = _differences(m, key, u, list(rates))
    sw = kincas.sweep(m, {key: u}, report=[n for pair in rates.values() for n in pair])
    for n, (v, a) in rates.items():
        fv, fa = diffs[n]
        np.testing.assert_allclose(sw[v], fv, rtol=0, atol=1e-7 * max(1.0, np.abs(fv).max()))
        np.testing.assert_allclose(sw[a], fa, rtol=0, atol=1e-5 * max(1.0, np.abs(fa).max()))


# --- sensitivities to a gear radius and a cam radius ---


def belt_fivebar(r1=20.0):
    """The geared five-bar with a belt (no centre-distance check), so a pulley radius can vary."""
    return Mechanism(parameters={"r1": r1, "r2": 40.0}, ground={"A": (0, 0), "D": (60, 0)},
                     links=[Link.bar("crank1", "A", "B", 25), Link.bar("crank2", "D", "C", 30),
                            Link.bar("left", "B", "P", 90), Link.bar("right", "C", "P", 90)],
                     gears=[Gear(("crank1", "crank2"), ("r1", "r2"), belt=True)],
                     inputs=[Input.angle("crank1")], guess={"C": (90, 0), "P": (40, 85)})


def test_gear_radius_sensitivity_against_central_differences():
    th, h = np.radians(np.linspace(10, 350, 12)), 1e-5
    names = ["P.x", "P.vy", "crank2.angle"]
    sens = [f"d({n})/d(r1)" for n in names]
    sw = kincas.sweep(belt_fivebar(), {"crank1.angle": th}, report=names + sens)
    up = kincas.sweep(belt_fivebar(20 + h), {"crank1.angle": th}, report=names)
    dn = kincas.sweep(belt_fivebar(20 - h), {"crank1.angle": th}, report=names)
    # a belt turns both pulleys the same way: crank2 = (r1 / r2) crank1
    np.testing.assert_allclose(sw["d(crank2.angle)/d(r1)"], th / 40, rtol=1e-12)
    for n in names:
        fd = (up[n] - dn[n]) / (2 * h)
        np.testing.assert_allclose(sw[f"d({n})/d(r1)"], fd, rtol=0, atol=1e-6 * max(1, np.abs(fd).max()))


def test_cam_radius_sensitivity_against_closed_form_and_differences(capsys, tmp_path):
    """Eccentric cam: y = e sin th + sqrt(R^2 - e^2 cos^2 th), dy/dR = R / sqrt(...)."""
    sc = scene("eccentric_cam")
    sc["output"] = {"report": ["F.y"], "sensitivity": {"of": ["F.y", "F.vy"], "to": ["R", "e"]}}
    code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, sc), "--json")
    assert code == 0, err
    th = np.radians(np.linspace(0, 360, 37))
    root = np.sqrt(1600 - 100 * np.cos(th) ** 2)
    np.testing.assert_allclose(out["values"]["d(F.y)/d(R)"], 40 / root, rtol=1e-10)
    np.testing.assert_allclose(out["values"]["d(F.y)/d(e)"], np.sin(th) - 10 * np.cos(th) ** 2 / root,
                               atol=1e-10)
    h = 1e-5  # F.vy per degree: its sensitivity against differences of solves
    vals = []
    for R in (40 + h, 40 - h):
        s2 = copy.deepcopy(sc)
        s2["parameters"]["R"] = R
        s2["output"] = {"report": ["F.vy"]}
        vals.append(np.array(run_cli(capsys, "solve", write_scene(tmp_path, s2), "--json")[1]["values"]["F.vy"]))
    fd = (vals[0] - vals[1]) / (2 * h)
    np.testing.assert_allclose(out["values"]["d(F.vy)/d(R)"], fd, atol=1e-8)


# --- modes and range with joints ---


def test_modes_of_a_cam(capsys):
    """Knife edge on the circle: above or below the disc, the rod upright or turned over."""
    code, out, err = run_cli(capsys, "modes", EXAMPLES / "eccentric_cam.toml", "--json")
    assert code == 0, err
    y = math.sqrt(40 ** 2 - 10 ** 2)
    got = sorted((round(md["points"]["F"][1], 9), round(md["angles"]["rod"]) % 360) for md in out["modes"])
    assert got == sorted([(-round(y, 9), 0), (-round(y, 9), 180), (round(y, 9), 0), (round(y, 9), 180)])


def test_range_of_a_knife_offset_from_the_disc(capsys, tmp_path):
    """The follower's line x = 45 meets the disc (centre 10 (cos th, sin th), radius 40) only
    while 10 cos th >= 5: the cam turns between -60 and 60 degrees."""
    sc = scene("eccentric_cam")
    for s in sc["slides"]:
        s["line"] = {"through": [45, 0], "angle": 90}
    sc["guess"] = {"F": [45, 5], "T": [45, 65]}
    code, out, err = run_cli(capsys, "range", write_scene(tmp_path, sc), "--json")
    assert code == 0, err
    r = out["ranges"]["cam.angle"]
    assert r["from"] == pytest.approx(-60, abs=1e-7) and r["to"] == pytest.approx(60, abs=1e-7)
    # a follower that leaves the profile is "no assembly" in a sweep, like any other pose
    code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, sc), "--json")
    assert code == 3
    u = np.linspace(0, 360, 37)
    reach = 10 * np.cos(np.radians(u)) >= 5 - 1e-12
    assert [s == "ok" for s in out["status"]] == reach.tolist()


# --- relative inputs, the first pose's angles ---


def test_relative_input_from_python():
    m = Mechanism(ground={"S": (0, 0)}, links=[Link.bar("upper", "S", "E", 3), Link.bar("fore", "E", "H", 2)],
                  inputs=[Input.angle("upper"), Input.relative("fore", "upper")], guess={"H": (5, 0)})
    r = kincas.solve(m, {"upper.angle": 0.3, "fore/upper.angle": 2.0}, rates={"fore/upper.angle": 0.5},
                     report=["H.x", "fore.angle", "fore.omega", "fore/upper.omega"])
    assert r["H.x"] == pytest.approx(3 * math.cos(0.3) + 2 * math.cos(2.3), abs=1e-12)
    assert r["fore.omega"] == pytest.approx(1.5, abs=1e-12)  # the upper arm's default rate 1 + 0.5
    assert r["fore/upper.omega"] == pytest.approx(0.5, abs=1e-12)


def test_gear_phase_and_input_angles_as_given(capsys, tmp_path):
    """theta2 = -k theta1 + phase with the driven crank's angle as the input gives it (a
    sweep from 360 deg is not taken back to 0): crank2 = -(360..380) / 2 + 30."""
    sc = scene("geared_fivebar")
    sc["gears"][0]["phase"] = 30
    sc["inputs"][0]["sweep"] = {"from": 360, "to": 380, "steps": 3}
    sc["guess"] = {"C": [60 + 30 * math.cos(-150 * D), 30 * math.sin(-150 * D)], "P": [20, 85]}
    sc["output"] = {"report": ["crank2.angle", "crank2/crank1.angle"]}
    code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, sc), "--json")
    assert code == 0, err
    np.testing.assert_allclose(out["values"]["crank2.angle"], [-150, -155, -160], atol=1e-9)
    # theta2 - theta1 = -510, -525, -540 deg, wrapped
    np.testing.assert_allclose(out["values"]["crank2/crank1.angle"], [-150, -165, 180], atol=1e-9)


# --- bad fields: exit 2 naming them ---


def _bad(capsys, tmp_path, sc, *words):
    code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, sc), "--json")
    assert code == 2, (code, err)
    assert "Traceback" not in err
    for w in words:
        assert w in err, (w, err)


def test_wrong_centre_distance(capsys, tmp_path):
    sc = scene("planetary")
    sc["parameters"]["rr"] = 61  # |61 - 15| = 46, but the arm puts the centres 45 apart
    _bad(capsys, tmp_path, sc, "[[gears]] planet_ring", "radii", "gears[1].radii")


def test_wrong_centre_distance_external(capsys, tmp_path):
    sc = scene("geared_fivebar")
    sc["parameters"]["r1"] = 21
    _bad(capsys, tmp_path, sc, "[[gears]] mesh", "radii", "r1 + r2")


def test_belt_has_no_distance_check(capsys, tmp_path):
    sc = scene("geared_fivebar")
    sc["parameters"]["r1"] = 21
    sc["gears"][0]["belt"] = True
    code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, sc), "--json")
    assert code == 0, err


def _polar_scene(angles, radii, roller=None):
    sc = scene("eccentric_cam")
    sc["cams"][0]["profile"] = {"polar": {"angles": angles, "radii": radii}}
    if roller is not None:
        del sc["cams"][0]["follower"]
        sc["cams"][0]["roller"] = {"center": "F", "radius": roller}
    return sc


@pytest.mark.parametrize("angles,words", [
    ([0, 90, 80, 270], ["profile.polar.angles", "increase"]),
    ([0, 120, 240, 360], ["profile.polar.angles", "turn"]),
    ([0, 90], ["profile.polar.angles"]),
])
def test_bad_polar_angles(capsys, tmp_path, angles, words):
    _bad(capsys, tmp_path, _polar_scene(angles, [40] * len(angles)), "[[cams]] cam", *words)


def test_roller_too_large_for_the_concave_part(capsys, tmp_path):
    """r = 35 + 15 cos 2 phi is concave near 90 and 270 deg (r^2 + 2 r'^2 - r r'' < 0 there:
    400 - 1200 at 90 deg): a roller of 30 cannot follow it; one of 2 can."""
    a = np.arange(0, 360, 15.0)
    r = (35 + 15 * np.cos(2 * np.radians(a))).tolist()
    _bad(capsys, tmp_path, _polar_scene(a.tolist(), r, roller=30), "[[cams]] cam", "roller.radius")
    from kincas.model.joints import concave_radius
    rho = concave_radius(np.radians(a), r)
    # at 90 deg exactly: (r^2 + r'^2)^1.5 / |r^2 + 2 r'^2 - r r''| = 20^3 / 800 = 10 for the
    # cosine; the spline through 24 points is within a few per cent of it
    assert 9 < rho <= 10.5


@pytest.mark.parametrize("change,words", [
    (lambda s: s["gears"][0].update(links=["crank1", "nope"]), ["[[gears]] mesh", "links", "nope"]),
    (lambda s: s["gears"][0].update(radii=[20]), ["[[gears]] mesh", "radii"]),
    (lambda s: s["gears"][0].update(internal=True, belt=True), ["[[gears]] mesh", "belt"]),
    (lambda s: s["gears"][0].update(carrier="nope"), ["[[gears]] mesh", "carrier"]),
    (lambda s: s["gears"][0].update(radii=[-20, 40]), ["[[gears]] mesh", "radii", "positive"]),
    (lambda s: s["gears"][0].update(colour="red"), ["[[gears]] mesh", "colour"]),
])
def test_bad_gear_fields(capsys, tmp_path, change, words):
    sc = scene("geared_fivebar")
    change(sc)
    _bad(capsys, tmp_path, sc, *words)


@pytest.mark.parametrize("change,words", [
    (lambda s: s["racks"][0].update(teeth="up"), ["[[racks]] 1", "teeth"]),
    (lambda s: s["racks"][0].update(slide="nope"), ["[[racks]] 1", "slide", "nope"]),
    (lambda s: s["racks"][0].update(slide="guide"), ["[[racks]] 1", "slide", "pinion's centre"]),
    (lambda s: s["racks"][0].update(pinion="nope"), ["[[racks]] 1", "pinion"]),
    (lambda s: s["links"].update(pinion={"points": {"T": [0, 0], "G": [20, 0]}}),
     ["[[racks]] 1", "slide", "origin"]),
    (lambda s: s["racks"][0].pop("radius"), ["[[racks]] 1", "radius"]),
])
def test_bad_rack_fields(capsys, tmp_path, change, words):
    sc = scene("rack_fourbar")
    change(sc)
    _bad(capsys, tmp_path, sc, *words)


@pytest.mark.parametrize("change,words", [
    (lambda s: s["cams"][0].update(body="nope"), ["[[cams]] cam", "body"]),
    (lambda s: s["cams"][0].update(follower="nope"), ["[[cams]] cam", "follower", "nope"]),
    (lambda s: s["cams"][0].update(flat="rod"), ["[[cams]] cam", "follower"]),
    (lambda s: s["cams"][0].update(profile={"square": {}}), ["[[cams]] cam", "profile"]),
    (lambda s: s["cams"][0].update(profile={"circle": {"center": [0, 0], "radius": -3}}),
     ["[[cams]] cam", "profile.circle.radius"]),
    (lambda s: s["cams"][0].update(follower="K"), ["[[cams]] cam", "own body"]),
])
def test_bad_cam_fields(capsys, tmp_path, change, words):
    sc = scene("eccentric_cam")
    change(sc)
    _bad(capsys, tmp_path, sc, *words)


def test_bad_relative_input(capsys, tmp_path):
    sc = scene("elbow_arm")
    sc["inputs"][1]["angle"] = "forearm/nope"
    _bad(capsys, tmp_path, sc, "[[inputs]]", "nope")


def test_model_errors_from_python():
    with pytest.raises(ModelError, match="rack"):
        Mechanism(ground={"G": (0, 0)}, links=[Link.bar("p", "G", "T", 1)],
                  racks=[Rack("p", 1.0, "nope")], inputs=[Input.angle("p")])
    with pytest.raises(ModelError, match="profile.circle.radius"):
        Mechanism(ground={"O": (0, 0)}, links=[Link.bar("c", "O", "K", 1), Link.bar("a", "O", "F", 2)],
                  cams=[Cam("k", "c", Circle((0, 0), 0.0), knife="F")], inputs=[Input.angle("c")])


# --- pictures ---


def _line(ax, label):
    found = [ln for ln in ax.lines if ln.get_label() == label]
    assert found, (label, [ln.get_label() for ln in ax.lines])
    return np.asarray(found[0].get_xydata(), float)


def test_pictures_of_gears_racks_and_cams():
    pytest.importorskip("matplotlib")
    from matplotlib.figure import Figure
    from kincas.views.plot import draw
    from kincas.cli.scene import load

    def drawn(name, pose, report):
        sc = load(EXAMPLES / f"{name}.toml")
        sw = kincas.sweep(sc.mechanism, sc.study.inputs, report=report)
        return draw(sc.mechanism, sw, pose=pose, ax=Figure().subplots()), sw

    # planetary: the planet's pitch circle (radius 15) about C, the ring's (60) about O
    ax, sw = drawn("planetary", 5, ["C.x", "C.y"])
    circles = [xy for ln in ax.lines if ln.get_label() == "planet_ring pitch circle"
               for xy in [np.asarray(ln.get_xydata())]]
    centre = np.array([sw["C.x"][5], sw["C.y"][5]])
    radii = sorted(float(np.hypot(*(xy - xy[:-1].mean(axis=0)).T).mean()) for xy in circles)  # closed: one point twice
    assert radii == pytest.approx([15, 60], abs=1e-9)
    assert any(np.allclose(np.hypot(*(xy - centre).T), 15) for xy in circles)
    # rack: the pitch line 20 below the pinion's path y = 20, that is y = 0
    ax, _ = drawn("rack_fourbar", 3, [])
    np.testing.assert_allclose(_line(ax, "rack pitch line")[:, 1], 0, atol=1e-9)
    # roller cam: the contact dot where kincas puts it, the roller's circle about F
    ax, sw = drawn("roller_cam", 7, ["cam.contact.x", "cam.contact.y", "F.x", "F.y"])
    np.testing.assert_allclose(_line(ax, "cam contact")[0], [sw["cam.contact.x"][7], sw["cam.contact.y"][7]])
    roller = _line(ax, "cam roller") - [sw["F.x"][7], sw["F.y"][7]]
    np.testing.assert_allclose(np.hypot(*roller.T), 10, atol=1e-9)
    # flat face: along the tappet's x axis (horizontal) through the contact point
    ax, sw = drawn("flat_tappet", 4, ["cam.contact.y"])
    np.testing.assert_allclose(_line(ax, "cam face")[:, 1], sw["cam.contact.y"][4], atol=1e-9)


def test_vector_pictures_draw_the_joints():
    """SVG: the planet's pitch circle (15) about C among the `data-joint` circles (true circles
    since issue [19]); DXF: the roller's circle (10 about F) on layer "joints"."""
    import xml.etree.ElementTree as ET
    from kincas.cli.scene import load
    from kincas.views.svg import svg_text
    sc = load(EXAMPLES / "planetary.toml")
    sw = kincas.sweep(sc.mechanism, sc.study.inputs, report=["C.x", "C.y"])
    root = ET.fromstring(svg_text(sc.mechanism, sw, pose=4))
    circles = [e for e in root.iter("{http://www.w3.org/2000/svg}circle") if e.get("data-joint")]
    c = np.array([sw["C.x"][4], sw["C.y"][4]])
    assert any(e.get("data-joint") == "planet_ring pitch circle" and abs(float(e.get("r")) - 15) < 1e-8
               and np.allclose([float(e.get("cx")), float(e.get("cy"))], c, atol=1e-8) for e in circles)
    pytest.importorskip("ezdxf")
    from kincas.views.dxf import dxf_document
    sc = load(EXAMPLES / "roller_cam.toml")
    sw = kincas.sweep(sc.mechanism, sc.study.inputs, report=["F.x", "F.y"])
    doc = dxf_document(sc.mechanism, sw, pose=2)
    rings = doc.modelspace().query('CIRCLE[layer=="joints"]')
    f = np.array([sw["F.x"][2], sw["F.y"][2]])
    assert any(abs(e.dxf.radius - 10) < 1e-8 and np.allclose(tuple(e.dxf.center)[:2], f, atol=1e-8) for e in rings)


def test_html_page_draws_the_cam(tmp_path):
    """The --html page of the roller cam runs without a JavaScript error and shows the
    contact point (red) where kincas puts it."""
    import shutil
    from test_html import BROWSER, _driver, _shot
    if BROWSER is None or shutil.which("chromedriver") is None:
        pytest.skip("no headless Chromium with chromedriver on this machine")
    page = tmp_path / "cam.html"
    import kincas.cli
    assert kincas.cli.main(["solve", str(EXAMPLES / "roller_cam.toml"), "--html", str(page)]) == 0
    pose = 6
    driver = _driver()
    try:
        errors, _, (sx, ox, oy), img = _shot(driver, page.as_uri() + f"#pose={pose}")
    finally:
        driver.quit()
    assert errors.strip() == ""
    from kincas.cli.scene import load
    sc = load(EXAMPLES / "roller_cam.toml")
    sw = kincas.sweep(sc.mechanism, sc.study.inputs, report=["cam.contact.x", "cam.contact.y"])
    x, y = sw["cam.contact.x"][pose], sw["cam.contact.y"][pose]
    px, py = round(ox + sx * x), round(oy - sx * y)
    assert any(max(abs(a - b) for a, b in zip(img.getpixel((px + dx, py + dy)), (0xC0, 0x39, 0x2B))) <= 40
               for dx in (-1, 0, 1) for dy in (-1, 0, 1))


def test_optimize_a_cam_eccentricity(capsys, tmp_path):
    """`kincas optimize` through a cam: the eccentricity giving the roller's centre a 30 mm
    rise and fall over the turn (optimize locates the extremes between samples), checked with
    the closed form (circle intersections) on a fine grid."""
    sc = scene("roller_cam")
    sc["optimize"] = {"vary": {"e": [5, 25]}, "minimize": "(max(F.y) - min(F.y) - 30)^2"}
    code, out, err = run_cli(capsys, "optimize", write_scene(tmp_path, sc), "--json")
    assert code == 0 and out["ok"], err
    e = out["varied"]["e"]
    th = np.linspace(0, 2 * np.pi, 720001)
    c = e * np.stack([np.cos(th), np.sin(th)])
    A = np.array([[60.0], [60.0]])
    d = c - A
    L = np.hypot(*d)
    a = (55 ** 2 - 50 ** 2 + L * L) / (2 * L)
    h = np.sqrt(55 ** 2 - a * a)
    n = np.stack([-d[1], d[0]]) / L
    F = A + a * d / L - h * n
    assert np.ptp(F[1]) == pytest.approx(30, abs=1e-6)


def test_study_refuses_designs_whose_gears_do_not_mesh(capsys, tmp_path):
    """`kincas study` over the ring's radius: only rr = 60 (|60 - 15| = 45, the arm) meshes;
    its arm turns at a third of the sun's rate 3 (Willis)."""
    import csv
    sc = scene("planetary")
    sc["study"] = {"vary": {"rr": [59, 61]}, "grid": [3], "report": ["max(arm.omega)"]}
    out_csv = tmp_path / "study.csv"
    code, out, err = run_cli(capsys, "study", write_scene(tmp_path, sc), "--out", out_csv)
    rows = list(csv.DictReader(open(out_csv, encoding="utf-8")))
    assert [r["status"].split(" at ")[0] for r in rows] == ["gears do not mesh", "ok", "gears do not mesh"]
    assert float(rows[1]["max(arm.omega)"]) == pytest.approx(1.0, abs=1e-12)
    assert rows[0]["max(arm.omega)"] in ("", "nan")
