"""`--svg` and `--dxf`: vector drawings read back (SVG as XML, DXF with ezdxf), their
coordinates checked against the offset slider-crank's closed form."""
from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from conftest import EXAMPLES, run_cli

SVG = "{http://www.w3.org/2000/svg}"
R, L, E = 50.0, 180.0, 20.0  # examples/slider_crank.toml: crank, rod, offset


def closed_form(deg):
    th = math.radians(deg)
    a = (R * math.cos(th), R * math.sin(th))
    b = (a[0] + math.sqrt(L ** 2 - (E - a[1]) ** 2), E)
    return a, b


@pytest.mark.parametrize("pose", [0, 7, 40])
def test_svg_read_back(capsys, tmp_path, pose):
    out = tmp_path / "s.svg"
    code, _, err = run_cli(capsys, "solve", EXAMPLES / "slider_crank.toml", "--svg", out, "--pose", pose)
    assert code == 0, err
    root = ET.parse(out).getroot()
    a, b = closed_form(5 * pose)
    pts = {c.get("data-point"): (float(c.get("cx")), float(c.get("cy"))) for c in root.iter(SVG + "circle")}
    assert pts["A"] == pytest.approx(a, abs=1e-7) and pts["B"] == pytest.approx(b, abs=1e-7)
    assert pts["O"] == (0.0, 0.0)
    rod = next(e for e in root.iter(SVG + "line") if e.get("data-link") == "rod")
    ends = [(float(rod.get("x1")), float(rod.get("y1"))), (float(rod.get("x2")), float(rod.get("y2")))]
    assert ends[0] == pytest.approx(a, abs=1e-7) and ends[1] == pytest.approx(b, abs=1e-7)
    # the paths: A's runs round its circle, B's stays on the guide line y = e
    path_a = [e for e in root.iter(SVG + "polyline") if e.get("data-path") == "A"]
    xy = np.array([[float(v) for v in p.split(",")] for e in path_a for p in e.get("points").split()])
    assert np.allclose(np.hypot(*xy.T), R, atol=1e-7) and len(xy) > 73  # densified by the solver
    path_b = [e for e in root.iter(SVG + "polyline") if e.get("data-path") == "B"]
    yb = [float(p.split(",")[1]) for e in path_b for p in e.get("points").split()]
    assert np.allclose(yb, E, atol=1e-7)


def test_dxf_read_back(capsys, tmp_path):
    ezdxf = pytest.importorskip("ezdxf")
    out = tmp_path / "s.dxf"
    code, _, err = run_cli(capsys, "solve", EXAMPLES / "slider_crank.toml", "--dxf", out, "--pose", 7)
    assert code == 0, err
    doc = ezdxf.readfile(out)
    msp = doc.modelspace()
    a, b = closed_form(35)
    assert {"crank", "rod", "ground", "paths", "slides"} <= {ly.dxf.name for ly in doc.layers}
    crank, = msp.query('LINE[layer=="crank"]')
    rod, = msp.query('LINE[layer=="rod"]')
    assert tuple(crank.dxf.start)[:2] == pytest.approx((0, 0), abs=1e-9)
    assert tuple(crank.dxf.end)[:2] == pytest.approx(a, abs=1e-7)
    assert tuple(rod.dxf.start)[:2] == pytest.approx(a, abs=1e-7)
    assert tuple(rod.dxf.end)[:2] == pytest.approx(b, abs=1e-7)
    paths = msp.query('LWPOLYLINE[layer=="paths"]')
    pts = np.array([p[:2] for e in paths for p in e.get_points()])
    on_circle = np.isclose(np.hypot(*pts.T), R, atol=1e-7)
    on_guide = np.isclose(pts[:, 1], E, atol=1e-7)
    assert (on_circle | on_guide).all() and on_circle.sum() > 73
    assert doc.units == 4  # millimetres, from the scene's units
    guide = msp.query('LINE[layer=="ground"]')
    assert all(abs(g.dxf.start[1] - E) < 1e-9 and abs(g.dxf.end[1] - E) < 1e-9 for g in guide)


def test_svg_and_dxf_from_python(tmp_path):
    import kincas
    from kincas.views.svg import svg_text
    sc = kincas.scene.load(EXAMPLES / "slider_crank.toml")
    sw = sc.run()
    root = ET.fromstring(svg_text(sc.mechanism, sw, pose=0))
    pts = {c.get("data-point"): float(c.get("cx")) for c in root.iter(SVG + "circle")}
    assert pts["A"] == pytest.approx(R, abs=1e-9)


def test_dxf_without_ezdxf_is_one_line(capsys, tmp_path, monkeypatch):
    import sys
    monkeypatch.setitem(sys.modules, "ezdxf", None)
    code, _, err = run_cli(capsys, "solve", EXAMPLES / "slider_crank.toml", "--dxf", tmp_path / "x.dxf")
    assert code == 2 and 'pip install "kincas[cad]"' in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("steps,flags,fine", [(13, ("png", "svg", "html", "dxf"), [12 * 17 + 1]),  # 16 between poses
                                              (73, ("png", "svg", "html", "dxf"), [72 * 5 + 1]),  # 4 between
                                              (73, ("png",), [])])
def test_pictures_share_one_solve_of_their_paths(capsys, tmp_path, monkeypatch, steps, flags, fine):
    """--plot, --svg, --html and --dxf draw from the sweep already solved; the extra poses
    that smooth their paths are solved once for all of them (as many as the most demanding
    needs: about 360 points a path for a drawing, 4 between two poses for vector pictures),
    and a drawing of more than 60 poses is drawn as it is."""
    pytest.importorskip("matplotlib")
    pytest.importorskip("ezdxf")
    import kincas.analysis.sweeps as sweeps
    from conftest import write_scene
    calls, real = [], sweeps.sweep

    def counted(*a, **k):
        calls.append(len(next(iter(a[1].values()))))
        return real(*a, **k)
    monkeypatch.setattr(sweeps, "sweep", counted)
    text = (EXAMPLES / "slider_crank.toml").read_text(encoding="utf-8").replace("steps = 73", f"steps = {steps}")
    out = {k: tmp_path / f"x.{k}" for k in flags}
    flag = {"png": "--plot", "svg": "--svg", "html": "--html", "dxf": "--dxf"}
    code, _, err = run_cli(capsys, "solve", write_scene(tmp_path, text),
                           *[a for k in flags for a in (flag[k], out[k])])
    assert code == 0, err
    assert calls == [steps] + fine  # the sweep, then at most one solve of the paths
    if "svg" not in flags:
        return
    root = ET.parse(out["svg"]).getroot()
    (path_a,) = [e for e in root.iter(SVG + "polyline") if e.get("data-path") == "A"]
    xy = np.array([[float(v) for v in p.split(",")] for p in path_a.get("points").split()])
    assert len(xy) == fine[0]  # the shared paths
    assert np.allclose(np.hypot(xy[:, 0], xy[:, 1]), R, atol=1e-6)  # solved: on the crank's circle
