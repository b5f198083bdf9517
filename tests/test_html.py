"""`kincas solve --html`: one self-contained page, tested in a real browser (headless
Chromium): it loads without a JavaScript error, and at a chosen pose the crank is drawn where
the closed form puts it (pixels checked at its computed position)."""
from __future__ import annotations

import math
import re
import shutil
import subprocess

import numpy as np
import pytest

from conftest import EXAMPLES, run_cli

BROWSER = next((shutil.which(b) for b in ("chromium", "chromium-browser", "google-chrome")
                if shutil.which(b)), None)
needs_browser = pytest.mark.skipif(
    BROWSER is None, reason="no headless Chromium on this machine (Debian: apt-get install chromium)")
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--force-device-scale-factor=1", "--hide-scrollbars", "--window-size=1100,700"]
CRANK = (0x1F, 0x77, 0xB4)  # the first link's colour


def browser(tmp_path, url, *extra):
    profile = tmp_path / f"profile{len(list(tmp_path.glob('profile*')))}"
    out = subprocess.run([BROWSER, *FLAGS, f"--user-data-dir={profile}", *extra, url],
                         capture_output=True, text=True, timeout=120)
    return out.stdout


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("html")
    path = tmp / "fourbar.html"
    import kincas.cli
    code = kincas.cli.main(["solve", str(EXAMPLES / "fourbar_coupler.toml"), "--html", str(path)])
    assert code == 0
    return path


def test_the_page_is_self_contained(page):
    text = page.read_text(encoding="utf-8")
    assert "<script src" not in text and "<link" not in text
    assert not re.search(r"(https?:)?//[a-z0-9.-]+\.[a-z]{2,}/", text)  # no address to fetch
    assert 'id="slider"' in text and 'id="play"' in text


def _driver():
    """A headless Chromium driven by selenium (the transform and the screenshot from one
    window: the command line's --dump-dom and --screenshot lay the page out in different sizes)."""
    webdriver = pytest.importorskip("selenium.webdriver")
    driver_path = shutil.which("chromedriver")
    if driver_path is None:
        pytest.skip("no chromedriver on this machine (Debian: apt-get install chromium-driver)")
    opts = webdriver.ChromeOptions()
    opts.binary_location = BROWSER
    for f in FLAGS:
        opts.add_argument(f)
    return webdriver.Chrome(options=opts, service=webdriver.ChromeService(executable_path=driver_path))


@pytest.fixture(scope="module")
def driver():
    if BROWSER is None:
        pytest.skip("no headless Chromium on this machine (Debian: apt-get install chromium)")
    d = _driver()
    yield d
    d.quit()


def _shot(driver, url):
    """(errors, data-pose, (sx, ox, oy), the page as an RGB image) after loading `url`."""
    import io
    from PIL import Image
    driver.get("about:blank")
    driver.get(url)
    body = driver.find_element("tag name", "body")
    errors = driver.find_element("id", "errors").text
    sx, ox, oy = map(float, body.get_attribute("data-transform").split())
    img = Image.open(io.BytesIO(driver.get_screenshot_as_png())).convert("RGB")
    return errors, body.get_attribute("data-pose"), (sx, ox, oy), img


def near(img, xy, colour, tol=40):
    x0, y0 = xy
    return any(max(abs(a - b) for a, b in zip(img.getpixel((x0 + dx, y0 + dy)), colour)) <= tol
               for dx in (-1, 0, 1) for dy in (-1, 0, 1))


@needs_browser
def test_the_page_runs_and_shows_the_chosen_pose(page, driver):
    pose = 10  # crank at 50 deg (73 poses over 360 deg)
    shots = {}
    for k in (pose, pose + 36):
        errors, shown, transform, img = _shot(driver, page.as_uri() + f"#pose={k}")
        assert errors.strip() == "" and "ERROR" not in driver.title
        assert shown == str(k)
        shots[k] = transform, img

    def crank_middle(k):  # closed form: crank O2A of 30 mm about the origin
        sx, ox, oy = shots[k][0]
        th = math.radians(5 * k)
        x, y = 15 * math.cos(th), 15 * math.sin(th)
        return round(ox + sx * x), round(oy - sx * y)

    assert near(shots[pose][1], crank_middle(pose), CRANK)
    assert near(shots[pose + 36][1], crank_middle(pose + 36), CRANK)
    # and not where the other pose has it: the picture moved with the slider
    assert not near(shots[pose][1], crank_middle(pose + 36), CRANK)
    assert not near(shots[pose + 36][1], crank_middle(pose), CRANK)
    # the cursor of the quantity plots is drawn (its red) in the plots' canvas, on the right
    left = int(driver.execute_script("return document.getElementById('plots').getBoundingClientRect().left"))
    right = np.asarray(shots[pose][1])[:, left:]
    assert ((right[..., 0] > 200) & (right[..., 1] < 80) & (right[..., 2] < 80)).sum() > 20
