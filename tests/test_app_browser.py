"""`kincas app` in a real browser (headless Chromium through selenium and chromedriver): the page
loads without console errors, a slider moved re-solves and prints the numbers `kincas.solve`
gives, a ground point dragged with the mouse moves the ground, and the downloaded scene solves
to the numbers printed. Skipped where no browser, driver or selenium is installed (Debian:
apt-get install chromium chromium-driver; pip install selenium)."""
from __future__ import annotations

import json
import math
import shutil
import time
import urllib.request

import numpy as np
import pytest

import kincas
from kincas.cli.scene import load, loads
from conftest import ROOT

pytest.importorskip("starlette", reason="kincas[app] is not installed")
webdriver = pytest.importorskip("selenium.webdriver", reason="selenium is not installed")
BROWSER = next((shutil.which(b) for b in ("chromium", "chromium-browser", "google-chrome") if shutil.which(b)), None)
DRIVER = shutil.which("chromedriver")
pytestmark = pytest.mark.skipif(BROWSER is None or DRIVER is None,
                                reason="no Chromium and chromedriver here (Debian: apt-get install chromium chromium-driver)")

from test_app import FOURBAR, serve  # noqa: E402


@pytest.fixture(scope="module")
def browser(tmp_path_factory):
    from selenium.webdriver.chrome.service import Service
    downloads = tmp_path_factory.mktemp("downloads")
    o = webdriver.ChromeOptions()
    for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
              "--window-size=1400,1000"):
        o.add_argument(a)
    o.binary_location = BROWSER
    o.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    o.add_experimental_option("prefs", {"download.default_directory": str(downloads),
                                        "download.prompt_for_download": False})
    try:
        d = webdriver.Chrome(service=Service(DRIVER), options=o)
    except Exception as e:  # a browser that cannot start here is no failure of kincas
        pytest.skip(f"Chromium does not start: {str(e).splitlines()[0]}")
    d.downloads = downloads
    yield d
    d.quit()


@pytest.fixture(scope="module")
def server():
    """One server for these tests (each test reads what it needs of the scene as it is now)."""
    proc, url, _ = serve(FOURBAR)
    try:
        yield url
    finally:
        proc.terminate()
        proc.wait(timeout=10)


@pytest.fixture
def page(browser, server):
    browser.get_log("browser")  # (what an earlier test left is not this one's)
    browser.get(server)
    settle(browser)
    yield browser, server


def scene_now(url):
    """The scene as the server holds it now (its TOML download, read back)."""
    with urllib.request.urlopen(url + "api/scene.toml", timeout=30) as r:
        return loads(r.read().decode("utf-8"))


def state_now(url):
    with urllib.request.urlopen(url + "api/state", timeout=30) as r:
        return json.load(r)


def settle(d, after: int = 0, timeout: float = 20):
    """Wait until the page shows a state newer than `after` and has no request out."""
    app = d.find_element("id", "kincas-app")
    end = time.time() + timeout
    while time.time() < end:
        v = app.get_attribute("data-version")
        if v and int(v) > after and app.get_attribute("data-busy") == "0":
            return int(v)
        time.sleep(0.05)
    raise AssertionError(f"the page did not settle: version {app.get_attribute('data-version')}, "
                         f"errors {d.find_element('id', 'errors').text!r}")


def printed(d, name) -> float:
    return float(d.find_element("css selector", f'td[data-name="{name}"]').get_attribute("data-value"))


def severe(d) -> list:
    return [e for e in d.get_log("browser") if e["level"] == "SEVERE"]


def test_the_page_loads_without_console_errors(page):
    d, _ = page
    assert not severe(d)
    assert d.find_element("id", "errors").text == ""
    assert d.title == "Four-bar coupler curve"
    assert d.find_elements("css selector", 'input[data-parameter="r2"]')
    assert printed(d, "crank.angle") == 0


def test_a_slider_moved_prints_what_kincas_solve_gives(page):
    from selenium.webdriver.common.keys import Keys
    d, url = page
    v0 = settle(d)
    before = scene_now(url).mechanism.param_values["r2"]
    slider = d.find_element("css selector", 'input[data-parameter="r2"]')
    slider.send_keys(*[Keys.ARROW_RIGHT] * 8)
    settle(d, v0)
    r2 = float(slider.get_property("value"))
    assert r2 > before
    pose = d.find_element("css selector", "input.k-pose")
    pose.send_keys(*[Keys.ARROW_RIGHT] * 10)  # pose 10: the crank at 50 degrees
    angle = printed(d, "crank.angle")
    assert angle == 50
    sc = scene_now(url)
    assert sc.mechanism.param_values["r2"] == r2
    want = kincas.solve(sc.mechanism, {"crank.angle": math.radians(angle)},
                        rates=sc.study.rates, report=["P.x", "P.y", "rocker.omega"])
    for name in ("P.x", "P.y"):
        assert printed(d, name) == pytest.approx(float(want[name]), rel=1e-9, abs=1e-9)
    assert printed(d, "rocker.omega") == pytest.approx(math.degrees(float(want["rocker.omega"])), rel=1e-9)
    assert not severe(d)


def test_a_ground_point_dragged_with_the_mouse_moves_the_ground(page):
    from selenium.webdriver import ActionChains
    d, url = page
    v0 = settle(d)
    app = d.find_element("id", "kincas-app")
    canvas = d.find_element("css selector", "canvas.k-mech")
    sx, ox, oy = map(float, app.get_attribute("data-transform").split())
    rect = d.execute_script("const r = arguments[0].getBoundingClientRect(); return [r.width, r.height, arguments[0].width];", canvas)
    css = rect[0] / rect[2]  # CSS pixels per canvas pixel
    # O4 = (r1, y): its canvas pixel, as an offset from the canvas's centre in CSS pixels
    st = state_now(url)
    x0, y0 = np.array(st["drawing"]["xy"], float)[0, st["drawing"]["names"].index("O4")]
    px, py = (ox + sx * x0) * css - rect[0] / 2, (oy - sx * y0) * css - rect[1] / 2
    ActionChains(d).move_to_element_with_offset(canvas, round(px), round(py)).click_and_hold() \
        .move_by_offset(20, 0).move_by_offset(20, 0).release().perform()
    settle(d, v0)
    st = state_now(url)
    r1 = next(p["value"] for p in st["parameters"] if p["name"] == "r1")
    moved = 40 / (css * sx)  # 40 CSS pixels in the world's units
    assert r1 == pytest.approx(x0 + moved, abs=2 / (css * sx))
    o4 = np.array(st["drawing"]["xy"], float)[:, st["drawing"]["names"].index("O4")]
    np.testing.assert_allclose(o4[:, 0], r1)
    assert all(st["ok"]) and not severe(d)


def test_the_downloaded_scene_solves_to_the_numbers_printed(page):
    from selenium.webdriver.common.keys import Keys
    d, _ = page
    v0 = settle(d)
    before = scene_now(page[1]).mechanism.param_values["px"]
    d.find_element("css selector", 'input[data-parameter="px"]').send_keys(*[Keys.ARROW_LEFT] * 6)
    settle(d, v0)
    shown = printed(d, "P.x")
    path = d.downloads / "fourbar_coupler.toml"
    path.unlink(missing_ok=True)
    d.find_element("css selector", "a.k-download").click()
    end = time.time() + 20
    while not path.exists() and time.time() < end:
        time.sleep(0.1)
    assert path.exists(), sorted(p.name for p in d.downloads.iterdir())
    sc = loads(path.read_text(encoding="utf-8"))
    assert sc.mechanism.param_values["px"] < before
    out = sc.run()
    assert sc.user_values(out)["P.x"][0] == pytest.approx(shown, rel=1e-9, abs=1e-9)


WIDGET_HOST = """
const [esm, done] = [arguments[0], arguments[arguments.length - 1]];
const handlers = [];
const model = {  // a stand-in for the widget's model: its messages carried to the server's API
  on(what, f) { handlers.push(f); }, off() {},
  send(m) {
    const r = m.name === "state" ? fetch("api/state")
      : fetch("api/" + m.name, {method: "POST", headers: {"Content-Type": "application/json"}, body: JSON.stringify(m.body)});
    r.then(x => x.json()).then(ok => handlers.forEach(f => f({id: m.id, ok})));
  },
};
const el = document.createElement("div");
el.id = "widget"; document.body.append(el);
import(URL.createObjectURL(new Blob([esm], {type: "text/javascript"})))
  .then(mod => { mod.default.render({model, el}); done("rendered"); }, e => done("failed: " + e));
"""


def test_the_widget_script_renders_as_an_es_module(page):
    pytest.importorskip("anywidget", reason="anywidget (kincas[app]) is not installed")
    d, _ = page
    esm = kincas.widget(load(FOURBAR))._esm
    assert d.execute_async_script(WIDGET_HOST, esm) == "rendered"
    w = d.find_element("id", "widget")
    end = time.time() + 20
    while w.get_attribute("data-version") in (None, "") and time.time() < end:
        time.sleep(0.05)
    assert w.get_attribute("data-version")
    cell = w.find_element("css selector", 'td[data-name="P.x"]')
    assert float(cell.get_attribute("data-value")) == printed(d, "P.x")
    assert not w.find_element("css selector", "a.k-download").is_displayed()  # no scene file there
    assert not severe(d)


def test_a_spatial_scene_loads_in_3d_and_a_drag_turns_the_view(browser):
    """The RSSR page loads without console errors; a mouse drag on the mechanism turns the
    camera (data-camera) and keeps it orthonormal, and re-solves nothing (points are not dragged)."""
    from selenium.webdriver import ActionChains
    proc, url, _ = serve(ROOT / "examples" / "space_rssr.toml")
    try:
        browser.get_log("browser")
        browser.get(url)
        v0 = settle(browser)
        assert not severe(browser) and browser.find_element("id", "errors").text == ""
        app = browser.find_element("id", "kincas-app")
        cam0 = np.array(json.loads(app.get_attribute("data-camera")))
        np.testing.assert_allclose(cam0[2], np.ones(3) / math.sqrt(3), atol=1e-9)  # isometric
        canvas = browser.find_element("css selector", "canvas.k-mech")
        ActionChains(browser).move_to_element(canvas).click_and_hold().move_by_offset(40, 0) \
            .move_by_offset(40, 10).release().perform()
        cam1 = np.array(json.loads(app.get_attribute("data-camera")))
        assert np.abs(cam1 - cam0).max() > 0.1
        np.testing.assert_allclose(cam1 @ cam1.T, np.eye(3), atol=1e-9)
        assert np.isclose(np.linalg.det(cam1), 1)
        assert int(app.get_attribute("data-version")) == v0 and not severe(browser)
    finally:
        proc.terminate()
        proc.wait(timeout=10)


CROSSING = """
title = "two cranks crossing in the isometric view"
space = "3d"
units = { length = "mm", angle = "deg", time = "s" }
gravity = [0, 0, -9810]

[ground]
ON = [90, 40, 10]
OF = [0, 0, 0]

[links]   # `near` is declared (and was drawn) first, though it is the nearer of the two
near = { points = { ON = [90, 40, 10], QN = [90, 40, 70] } }
far  = { points = { OF = [0, 0, 0], PF = [100, 0, 0] }, mass = 0.001 }

[[joints]]
type = "revolute"
point = "ON"
axis = [1, 0, 0]
[[joints]]
type = "revolute"
point = "OF"
axis = [0, 0, 1]

[[loads]]
point = "PF"
force = [0, -10, -20]

[[inputs]]
joint = "ON"
value = 0
[[inputs]]
joint = "OF"
value = 0

[output]
report = ["PF.x", "effort(OF.angle)"]
"""

PIXEL = "const c = arguments[0].getContext('2d'); return Array.from(c.getImageData(arguments[1], arguments[2], 1, 1).data);"


def _rgb(hexa: str) -> np.ndarray:
    return np.array([int(hexa[k:k + 2], 16) for k in (1, 3, 5)], float)


def _near_colour(d, canvas, xy, colour, r=2) -> bool:
    """Whether a pixel within r of canvas pixel xy has `colour` (antialiasing aside)."""
    want = _rgb(colour)
    for dx in range(-r, r + 1):
        for dy in range(-r, r + 1):
            px = d.execute_script(PIXEL, canvas, int(round(xy[0])) + dx, int(round(xy[1])) + dy)
            if np.abs(np.array(px[:3], float) - want).max() < 30:
                return True
    return False


def test_a_spatial_page_draws_nearer_links_over_farther_ones_and_the_force_arrows(browser, tmp_path):
    """Painter's order by mean depth: where the two bars cross on the screen the nearer one's
    colour shows, whatever their order in the scene. With `forces` ticked, the load on PF is an
    arrow along its projected direction (drawn like the links: the camera's rows)."""
    scene = tmp_path / "crossing.toml"
    scene.write_text(CROSSING, encoding="utf-8")
    proc, url, _ = serve(scene)
    try:
        browser.get_log("browser")
        browser.get(url)
        settle(browser)
        app = browser.find_element("id", "kincas-app")
        canvas = browser.find_element("css selector", "canvas.k-mech")
        D = state_now(url)["drawing"]
        cam = np.array(json.loads(app.get_attribute("data-camera")))
        sx, ox, oy = map(float, app.get_attribute("data-transform").split())
        c = np.mean(np.array(D["box"], float), axis=0)
        world = np.array(D["xy"], float)[0]
        at = {n: world[k] for k, n in enumerate(D["names"])}

        def pixel(p):
            x, y = cam[:2] @ (np.asarray(p, float) - c)
            return np.array([ox + sx * x, oy - sx * y])

        # where the bars cross on the screen: F(s) = N(t), and N is nearer there
        a, b, p, q = pixel(at["OF"]), pixel(at["PF"]), pixel(at["ON"]), pixel(at["QN"])
        s, t = np.linalg.solve(np.stack([b - a, -(q - p)], axis=1), p - a)
        assert 0.2 < s < 0.8 and 0.2 < t < 0.8
        depth = lambda w: -cam[2] @ (w - c)  # noqa: E731
        assert depth(at["ON"] + t * (at["QN"] - at["ON"])) < depth(at["OF"] + s * (at["PF"] - at["OF"]))
        colour = {bd["name"]: bd["colour"] for bd in D["bodies"]}
        cross = a + s * (b - a)
        assert _near_colour(browser, canvas, cross, colour["near"], r=0)
        assert not _near_colour(browser, canvas, cross, colour["far"], r=0)
        # the load's arrow: from PF along the projected force, 12 % of the canvas long
        f = cam[:2] @ np.array([0.0, -10, -20])
        u = np.array([f[0], -f[1]]) / np.hypot(*f)
        mid = b + 0.06 * min(canvas.get_property("width"), canvas.get_property("height")) * u
        assert not _near_colour(browser, canvas, mid, "#c0392b")
        browser.find_element("css selector", "input.k-forces").click()
        assert _near_colour(browser, canvas, mid, "#c0392b")
        assert not severe(browser)
    finally:
        proc.terminate()
        proc.wait(timeout=10)
