"""The live page of `kincas app` and `kincas.widget`: the model being edited (`engine`), what
it draws (`drawing`), and the page's own script and styles (`app.js`, `app.css`, `page.html`,
shipped in the package: the page makes no request beyond the server that served it).

>>> "kincas" in asset("page.html") and "function" in asset("app.js")
True
"""
from __future__ import annotations

from importlib import resources

ASSETS = ("page.html", "app.js", "app.css")


def asset(name: str) -> str:
    """The text of one of the page's files (`ASSETS`); `app.js` starts with the camera that turns
    a spatial mechanism with the mouse (views/orbit.js, shared with the spatial `--html` page)
    and the shapes every page draws alike (views/draw.js, shared with the `--html` pages)."""
    if name not in ASSETS:
        raise KeyError(name)
    text = resources.files(__name__).joinpath(name).read_text(encoding="utf-8")
    if name == "app.js":
        from ..html import DRAW_JS
        from ..html3d import ORBIT_JS
        text = ORBIT_JS + DRAW_JS + text
    return text
