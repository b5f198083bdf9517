"""The HTML page, the SVG and the DXF as a new user opens them (issue [19]): the page shows
the title and the input's unit, plots with axes, tick values and units, a speed control, fits
the window it is opened in, and follows changes of #pose; the SVG imports at true scale (its
width and height in millimetres, its viewBox in the scene's units); the DXF names the points;
the planetary train's ring is a true circle of the ring's radius in every vector format."""
from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from conftest import EXAMPLES

SVG = "{http://www.w3.org/2000/svg}"


def _scene(name):
    from kincas.cli.scene import load
    sc = load(EXAMPLES / name)
    return sc, sc.run()


@pytest.fixture(scope="module")
def fourbar_page(tmp_path_factory):
    import kincas.cli
    path = tmp_path_factory.mktemp("pages") / "fourbar.html"
    assert kincas.cli.main(["solve", str(EXAMPLES / "fourbar_coupler.toml"), "--html", str(path)]) == 0
    return path


def test_page_data_carries_units_and_title():
    from kincas.views.html import page_data
    sc, sw = _scene("fourbar_coupler.toml")
    d = page_data(sc.mechanism, sw, sc)
    assert d["title"] == sc.study.title
    assert d["x"]["name"] == "crank.angle" and d["x"]["unit"] == "deg"
    units = {q["name"]: q["unit"] for q in d["quantities"]}
    assert units["P.x"] == "mm" and units["P.vx"] == "mm/s"
    assert d["caption"][1].endswith("°")  # crank.angle = 5°


# --- in a browser ---


def _driver_or_skip():
    import shutil
    from test_html import BROWSER, _driver
    if BROWSER is None or shutil.which("chromedriver") is None:
        pytest.skip("no headless Chromium with chromedriver on this machine")
    return _driver()


@pytest.fixture(scope="module")
def driver():
    d = _driver_or_skip()
    yield d
    d.quit()


RECORD = """
const rec = [], c = document.getElementById('plots').getContext('2d'), f = c.fillText.bind(c);
c.fillText = (t, x, y) => { rec.push(String(t)); f(t, x, y); };
window.dispatchEvent(new Event('resize'));
c.fillText = f;
return rec;
"""


def test_the_page_titles_and_labels_its_plots(fourbar_page, driver):
    from kincas.cli.scene import load
    driver.get(fourbar_page.as_uri())
    assert driver.find_element("id", "errors").text.strip() == ""
    sc = load(EXAMPLES / "fourbar_coupler.toml")
    assert driver.find_element("id", "title").text == sc.study.title
    assert "crank.angle in deg" in driver.find_element("id", "units").text
    assert driver.find_element("id", "speed").tag_name == "select"
    texts = driver.execute_script(RECORD)
    assert any(t.startswith("P.x [mm] = ") for t in texts)
    assert "crank.angle [deg]" in texts  # the x axis's title
    # the tick values of the crank angle's axis: round numbers over 0..360
    numbers = [float(t) for t in texts if re.fullmatch(r"-?\d+(\.\d+)?", t)]
    assert {0.0, 100.0, 200.0, 300.0} <= set(numbers) or {0.0, 90.0, 180.0, 270.0} <= set(numbers) \
        or {0.0, 50.0, 100.0, 150.0} <= set(numbers), texts[:60]


def test_the_page_fits_the_window_and_follows_the_hash(fourbar_page, driver):
    sizes = {}
    for w, h in ((1100, 700), (800, 600)):
        driver.set_window_size(w, h)
        driver.get(fourbar_page.as_uri() + "#pose=3")
        inner = driver.execute_script("return [window.innerWidth, window.innerHeight, "
                                      "document.documentElement.scrollWidth, document.documentElement.scrollHeight]")
        assert inner[2] <= inner[0] and inner[3] <= inner[1], inner  # nothing beyond the window
        sizes[w] = driver.execute_script("return document.getElementById('mech').width")
    assert sizes[800] < sizes[1100]  # the drawing follows the window
    body = driver.find_element("tag name", "body")
    assert body.get_attribute("data-pose") == "3"
    driver.execute_script("location.hash = '#pose=20'")
    import time
    for _ in range(50):
        if body.get_attribute("data-pose") == "20":
            break
        time.sleep(0.05)
    assert body.get_attribute("data-pose") == "20"
    driver.set_window_size(1100, 700)


# --- true scale, labels, round circles ---


def test_svg_imports_at_true_scale(tmp_path):
    from kincas.views.svg import svg_text
    sc, sw = _scene("fourbar_coupler.toml")
    root = ET.fromstring(svg_text(sc.mechanism, sw, 0, scene=sc))
    x0, y0, w, h = map(float, root.get("viewBox").split())
    assert root.get("width") == f"{w:.10g}mm" and root.get("height") == f"{h:.10g}mm"
    # a scene in metres: the same drawing, 1000 mm to the metre
    text = (EXAMPLES / "fourbar_coupler.toml").read_text().replace('length = "mm"', 'length = "m"')
    from kincas.cli.scene import loads
    scm = loads(text)
    rootm = ET.fromstring(svg_text(scm.mechanism, scm.run(), 0, scene=scm))
    _, _, wm, hm = map(float, rootm.get("viewBox").split())
    assert float(rootm.get("width")[:-2]) == pytest.approx(1000 * wm) and rootm.get("width").endswith("mm")
    # no unit: a plain picture, no claim of a scale
    plain = ET.fromstring(svg_text(sc.mechanism, sw, 0))
    assert re.fullmatch(r"[\d.]+", plain.get("width"))


def test_dxf_names_the_points(tmp_path):
    ezdxf = pytest.importorskip("ezdxf")
    from kincas.views.dxf import write_dxf
    from kincas.views.poses import geometry
    sc, sw = _scene("fourbar_coupler.toml")
    write_dxf(tmp_path / "f.dxf", sc.mechanism, sw, 0)
    texts = ezdxf.readfile(tmp_path / "f.dxf").modelspace().query('TEXT[layer=="labels"]')
    names = {t.dxf.text: np.array(tuple(t.get_placement()[1])[:2]) for t in texts}
    g = geometry(sc.mechanism, sw)
    assert set(names) == set(g.names)
    for n, at in names.items():  # beside its point: a few units of size away
        d = np.hypot(*(at - g.point(n)[0]))
        assert 1.0 < d < 30.0, (n, d)


def test_the_ring_gear_is_a_true_circle():
    from kincas.views.html import page_data
    from kincas.views.svg import svg_text
    sc, sw = _scene("planetary.toml")
    rr = 60.0  # examples/planetary.toml: the ring's pitch radius
    root = ET.fromstring(svg_text(sc.mechanism, sw, 0, scene=sc))
    rings = [c for c in root.iter(SVG + "circle") if c.get("data-joint", "").startswith("planet_ring")]
    assert any(abs(float(c.get("r")) - rr) < 1e-6 and abs(float(c.get("cx"))) < 1e-6 for c in rings)
    d = page_data(sc.mechanism, sw, sc)
    circles = [c["circle"] for c in d["joints"][0] if "circle" in c]
    assert any(abs(c[2] - rr) < 1e-6 for c in circles)


def test_study_map_has_units_on_axes_and_colour_bars(tmp_path, monkeypatch):
    pytest.importorskip("matplotlib")
    from kincas.views import mapplot
    seen = {}

    def keep(fig, path, **kw):  # the figure as drawn, before it is written
        seen["fig"] = fig
    monkeypatch.setattr("kincas.views.atomic.savefig", keep)
    text = (EXAMPLES / "study_fourbar.toml").read_text().replace("grid = [41, 41]", "grid = [4, 3]")
    scene = tmp_path / "s.toml"
    scene.write_text(text)
    import kincas.cli
    assert kincas.cli.main(["study", str(scene), "--plot", str(tmp_path / "m.png"), "--no-progress"]) in (0, 3)
    fig = seen["fig"]
    panels = [a for a in fig.axes if a.get_xlabel()]
    assert [a.get_xlabel() for a in panels] == ["a4 [mm]", "a4 [mm]"]
    assert panels[0].get_ylabel() == "a5 [mm]"
    bars = sorted(a.get_ylabel() for a in fig.axes if not a.get_xlabel())
    assert bars == ["max(C.y) [mm]", "max(rocker.angle) - min(rocker.angle) [deg]"]
    assert mapplot is not None
