"""Springs, force arrows and instant centres in every picture (issue [19]): a spring is drawn
between its two points (the toggle clamp's was missing); with `forces`, loads, springs'
pulls, efforts and reactions are arrows ending at their points, and with `centres` each link's
instant centre is marked. Checked against closed forms written here: a crank O-A under a
force F at A has the reaction -F at O and the effort torque -(A - O) x F; a four-bar coupler's
instant centre is where the lines O2A and O4B cross; a spring pulls with k (d - d0)."""
from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import kincas
from kincas import Input, Link, Load, Mechanism

pytest.importorskip("matplotlib")

F = (3.0, -10.0)
TH = np.radians([30.0, 100.0, 200.0])


def crank_under_load():
    return Mechanism(ground={"O": (0, 0)}, links=[Link.bar("crank", "O", "A", 2.0)],
                     inputs=[Input.angle("crank")], loads=[Load.force("A", F)])


def fourbar():
    return Mechanism(ground={"O2": (0, 0), "O4": (4, 0)},
                     links=[Link.bar("crank", "O2", "A", 1), Link.bar("coupler", "A", "B", 3.5),
                            Link.bar("rocker", "O4", "B", 3)],
                     inputs=[Input.angle("crank")], guess={"B": (3.6, 2.9)})


def toggle():
    from kincas.cli.scene import load
    sc = load("examples/forces_toggle.toml")
    return sc, sc.run()


def _cross(u, v):
    return u[0] * v[1] - u[1] * v[0]


def _line_cross(p1, p2, q1, q2):
    d1, d2 = p2 - p1, q2 - q1
    t = _cross(q1 - p1, d2) / _cross(d1, d2)
    return p1 + t * d1


# --- the format-free overlay ---


def test_overlay_reaction_and_effort_closed_form():
    from kincas.views.forces import overlay
    m = crank_under_load()
    sw = kincas.sweep(m, {"crank.angle": TH})
    ov = overlay(m, sw, centres=False)
    r = {a.label: a for a in ov.arrows}["reaction(O, crank)"]
    # the ground holds the crank against F: R = -F at O, whatever the angle
    np.testing.assert_allclose(r.vec, np.tile(-np.array(F), (3, 1)), atol=1e-9)
    np.testing.assert_allclose(r.at, 0.0, atol=1e-12)
    load = {a.label: a for a in ov.arrows}["load at A"]
    np.testing.assert_allclose(load.vec, np.tile(F, (3, 1)))
    np.testing.assert_allclose(load.at, 2 * np.stack([np.cos(TH), np.sin(TH)], axis=1), atol=1e-12)
    (t,) = [t for t in ov.torques if t.label == "effort(crank.angle)"]
    ax, ay = 2 * np.cos(TH), 2 * np.sin(TH)
    np.testing.assert_allclose(t.value, -(ax * F[1] - ay * F[0]), atol=1e-9)


def test_overlay_instant_centre_is_where_the_rockers_lines_cross():
    from kincas.views.forces import overlay
    m = fourbar()
    sw = kincas.sweep(m, {"crank.angle": TH}, report=["A.x", "A.y", "B.x", "B.y"])
    ov = overlay(m, sw, forces=False)
    c = dict(ov.centres)
    for i in range(3):
        A = np.array([sw.values["A.x"][i], sw.values["A.y"][i]])
        B = np.array([sw.values["B.x"][i], sw.values["B.y"][i]])
        want = _line_cross(np.zeros(2), A, np.array([4.0, 0.0]), B)
        np.testing.assert_allclose(c["coupler"][i], want, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(c["crank"][i], 0.0, atol=1e-9)  # about its pivot


# --- springs in every picture ---


def test_the_toggle_spring_is_drawn_in_the_png():
    from matplotlib.figure import Figure
    sc, sw = toggle()
    ax = kincas.plot.draw(sc.mechanism, sw, 0, ax=Figure().subplots())
    (line,) = [ln for ln in ax.lines if ln.get_label() == "spring S-P"]
    x, y = line.get_data()
    P = [sw.values["coupler.angle"][0]]  # P is 40 mm along the coupler from A
    from kincas.views.poses import geometry
    g = geometry(sc.mechanism, sw)
    np.testing.assert_allclose((x[0], y[0]), g.point("S")[0], atol=1e-9)
    np.testing.assert_allclose((x[-1], y[-1]), g.point("P")[0], atol=1e-9)
    assert len(x) > 8 and P  # a zigzag, not a straight line


def test_springs_in_svg_dxf_and_html(tmp_path):
    from kincas.views.html import page_data
    from kincas.views.svg import svg_text
    sc, sw = toggle()
    m = sc.mechanism
    from kincas.views.poses import geometry
    g = geometry(m, sw)
    S, P = g.point("S")[0], g.point("P")[0]
    root = ET.fromstring(svg_text(m, sw, 0))
    (el,) = [e for e in root.iter() if e.get("data-spring") == "spring S-P"]
    pts = np.array([[float(v) for v in p.split(",")] for p in el.get("points").split()])
    np.testing.assert_allclose(pts[0], S, atol=1e-3)
    np.testing.assert_allclose(pts[-1], P, atol=1e-3)
    data = page_data(m, sw, sc)
    (sp,) = data["springs"]
    assert [data["names"][sp["a"]], data["names"][sp["b"]]] == ["S", "P"]
    ezdxf = pytest.importorskip("ezdxf")
    from kincas.views.dxf import write_dxf
    write_dxf(tmp_path / "t.dxf", m, sw, 0)
    doc = ezdxf.readfile(tmp_path / "t.dxf")
    (pl,) = doc.modelspace().query('LWPOLYLINE[layer=="springs"]')
    xy = np.array([p[:2] for p in pl.get_points()])
    np.testing.assert_allclose(xy[0], S, atol=1e-9)
    np.testing.assert_allclose(xy[-1], P, atol=1e-9)


# --- arrows and centres, when asked ---


def _arrow_svg(root, label):
    (el,) = [e for e in root.iter() if e.get("data-force") == label]
    pts = np.array([[float(v) for v in p.split(",")] for p in el.get("points").split()])
    return pts, float(el.get("data-value-x")), float(el.get("data-value-y"))


def test_svg_arrows_point_as_the_forces_act():
    from kincas.views.svg import svg_text
    m = crank_under_load()
    sw = kincas.sweep(m, {"crank.angle": TH})
    plain = svg_text(m, sw, 1)
    assert "data-force" not in plain  # only when asked
    root = ET.fromstring(svg_text(m, sw, 1, forces=True))
    pts, fx, fy = _arrow_svg(root, "reaction(O, crank)")
    assert (fx, fy) == pytest.approx((-F[0], -F[1]), abs=1e-6)
    d = pts[-1] - pts[0]  # tail to head: along -F, ending at O
    assert np.allclose(pts[-1], 0, atol=1e-3)
    assert np.dot(d, -np.array(F)) / np.hypot(*d) / np.hypot(*F) == pytest.approx(1, abs=1e-6)
    pts, fx, fy = _arrow_svg(root, "load at A")
    A = 2 * np.array([math.cos(TH[1]), math.sin(TH[1])])
    assert np.allclose(pts[-1], A, atol=1e-3) and (fx, fy) == pytest.approx(F)


def test_png_draws_arrows_and_centres_when_asked():
    from matplotlib.figure import Figure
    m = fourbar()
    sw = kincas.sweep(m, {"crank.angle": TH}, report=["A.x", "A.y", "B.x", "B.y"])
    ax = kincas.plot.draw(m, sw, 1, ax=Figure().subplots(), centres=True)
    (cross,) = [ln for ln in ax.lines if ln.get_label() == "instant centre coupler"]
    A = np.array([sw.values["A.x"][1], sw.values["A.y"][1]])
    B = np.array([sw.values["B.x"][1], sw.values["B.y"][1]])
    want = _line_cross(np.zeros(2), A, np.array([4.0, 0.0]), B)
    np.testing.assert_allclose(np.ravel(cross.get_data()), want, rtol=1e-9)
    m2 = crank_under_load()
    sw2 = kincas.sweep(m2, {"crank.angle": TH})
    ax2 = kincas.plot.draw(m2, sw2, 0, ax=Figure().subplots(), forces=True)
    labels = {a.get_label() for a in ax2.patches} | {ln.get_label() for ln in ax2.lines}
    assert {"reaction(O, crank)", "load at A", "effort(crank.angle)"} <= labels


def test_html_and_dxf_carry_the_arrows(tmp_path):
    from kincas.views.html import page_data
    m = crank_under_load()
    sw = kincas.sweep(m, {"crank.angle": TH})
    data = page_data(m, sw, forces=True, centres=True)
    arrows = {a["label"]: a for a in data["forces"][2]}
    head = np.array(arrows["reaction(O, crank)"]["pts"][-1])
    tail = np.array(arrows["reaction(O, crank)"]["pts"][0])
    assert np.allclose(head, 0, atol=1e-6) and _cross(head - tail, -np.array(F)) == pytest.approx(0, abs=1e-6)
    assert "forces" not in page_data(m, sw) or not any(page_data(m, sw)["forces"])
    ezdxf = pytest.importorskip("ezdxf")
    from kincas.views.dxf import write_dxf
    write_dxf(tmp_path / "f.dxf", m, sw, 0, forces=True)
    doc = ezdxf.readfile(tmp_path / "f.dxf")
    assert len(doc.modelspace().query('LWPOLYLINE[layer=="forces"]')) >= 3


def test_cli_forces_and_centres_flags(tmp_path, capsys):
    from conftest import run_cli
    out = tmp_path / "t.svg"
    code, _, err = run_cli(capsys, "solve", "examples/forces_toggle.toml", "--svg", out, "--forces", "--centres")
    assert code == 0, err
    text = out.read_text()
    assert 'data-force="effort(crank.angle)"' in text and 'data-centre="coupler"' in text
    assert re.search(r'data-spring="spring S-P"', text)


def test_the_animation_moves_the_arrows(tmp_path):
    from matplotlib.figure import Figure
    from kincas.views.draw_forces import OverlayArtists  # noqa: F401  (what the frames move)
    from kincas.views.forces import overlay
    from kincas.views.plot import Drawing, geometry
    m = crank_under_load()
    sw = kincas.sweep(m, {"crank.angle": TH})
    d = Drawing(Figure().subplots(), m, geometry(m, sw), [], True, "", None, overlay(m, sw))
    ends = []
    for i in range(3):
        d.update(i)
        line, _ = d.overlay.arrows["load at A"]
        ends.append(np.array(line.get_data())[:, -1])  # the head: at A, which turns with the crank
    np.testing.assert_allclose(ends, 2 * np.stack([np.cos(TH), np.sin(TH)], axis=1), atol=1e-9)
    from kincas.views.animation import animate
    assert animate(m, sw, tmp_path / "a.gif", frames=3, size=(2, 1.5), dpi=40, forces=True, centres=True) == 3


def test_forces_without_a_picture_is_one_line(capsys):
    from conftest import run_cli
    code, _, err = run_cli(capsys, "solve", "examples/forces_toggle.toml", "--forces")
    assert code == 2 and "--forces" in err and len(err.strip().splitlines()) == 1, err


@pytest.mark.parametrize("example", ["whitworth.toml", "slider_crank.toml", "fairbairn.toml"])
def test_svg_names_keep_off_the_blocks(example):
    """In the SVG, no name's text box (estimated from its font size: 0.6 em a letter, 0.75 em
    tall, placed by its anchor and baseline) overlaps a slide's block."""
    from matplotlib.path import Path
    from matplotlib.transforms import Bbox
    from kincas.cli.scene import load
    from kincas.views.svg import svg_text
    sc = load(f"examples/{example}")
    sw = sc.run()
    ns = "{http://www.w3.org/2000/svg}"
    hits = []
    for i in range(0, len(sw), max(1, len(sw) // 8)):
        root = ET.fromstring(svg_text(sc.mechanism, sw, i))
        blocks = [Path(np.array([[float(v) for v in p.split(",")] for p in e.get("points").split()]))
                  for e in root.iter(ns + "polygon") if e.get("data-block")]
        (g,) = [e for e in root.iter(ns + "g") if e.get("id") == "labels"]
        fs = float(g.get("font-size"))
        anchor, base = g.get("text-anchor", "start"), g.get("dominant-baseline", "alphabetic")
        for t in g.iter(ns + "text"):
            x, y = float(t.get("x")), -float(t.get("y"))  # back to the world's y
            w, h = 0.6 * fs * len(t.text), 0.75 * fs
            x0 = x - w / 2 if anchor == "middle" else x
            y0 = y - h / 2 if base == "central" else y
            box = Bbox([[x0, y0], [x0 + w, y0 + h]])
            hits += [(i, t.text) for p in blocks if p.intersects_bbox(box, filled=True)]
    assert not hits
