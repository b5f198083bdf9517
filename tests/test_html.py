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


@needs_browser
def test_the_page_runs_and_shows_the_chosen_pose(page, tmp_path):
    pose = 10  # crank at 50 deg (73 poses over 360 deg)
    dom = browser(tmp_path, page.as_uri() + f"#pose={pose}", "--dump-dom")
    errors = re.search(r'<pre id="errors">(.*?)</pre>', dom, re.S)
    assert errors is not None and errors.group(1).strip() == "", dom[-2000:]
    assert "ERROR" not in re.search(r"<title>(.*?)</title>", dom).group(1)
    assert f'data-pose="{pose}"' in dom
    sx, ox, oy = map(float, re.search(r'data-transform="([^"]+)"', dom).group(1).split())

    from PIL import Image
    shots = {}
    for k in (pose, pose + 36):
        shot = tmp_path / f"pose{k}.png"
        browser(tmp_path, page.as_uri() + f"#pose={k}", f"--screenshot={shot}")
        shots[k] = Image.open(shot).convert("RGB")

    def crank_middle(k):  # closed form: crank O2A of 30 mm about the origin
        th = math.radians(5 * k)
        x, y = 15 * math.cos(th), 15 * math.sin(th)
        return round(ox + sx * x), round(oy - sx * y)

    def near(img, xy, colour, tol=40):
        x0, y0 = xy
        return any(max(abs(a - b) for a, b in zip(img.getpixel((x0 + dx, y0 + dy)), colour)) <= tol
                   for dx in (-1, 0, 1) for dy in (-1, 0, 1))

    assert near(shots[pose], crank_middle(pose), CRANK)
    assert near(shots[pose + 36], crank_middle(pose + 36), CRANK)
    # and not where the other pose has it: the picture moved with the slider
    assert not near(shots[pose], crank_middle(pose + 36), CRANK)
    assert not near(shots[pose + 36], crank_middle(pose), CRANK)
    # the cursor of the quantity plots is drawn (its red) in the plots' canvas, right of 640 px
    right = np.asarray(shots[pose])[:, 640:]
    assert ((right[..., 0] > 200) & (right[..., 1] < 80) & (right[..., 2] < 80)).sum() > 20
