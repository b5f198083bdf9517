"""One scene being edited by `kincas app`: the live model of its mechanism (kincas/views/live/
engine.py) and the scene file written back with the edits (its parameters, its ground points'
numeric coordinates, its fixed inputs' values), everything else as the file had it, its
comments too where the edited lines can be rewritten in place (kincas/cli/scene_toml.py).

Requests come from the server's threads: one lock serialises them (each is a few milliseconds).

>>> sc = Session.from_text('''
... [parameters]
... r = { value = 1, range = [0.5, 1.5] }
... [ground]
... A = [0, 0]
... D = [4, 0]
... [links]
... crank = { points = ["A", "B"], length = "r" }
... coupler = { points = ["B", "C"], length = 3.5 }
... rocker = { points = ["D", "C"], length = 3 }
... [[inputs]]
... angle = "crank"
... sweep = { from = 0, to = 360, steps = 361 }
... [guess]
... C = [3.6, 2.9]
... ''')
>>> s = sc.request("change", {"parameters": {"r": 1.25}})
>>> s["message"], s["parameters"][0]["value"], s["parameters"][0]["lo"]
('', 1.25, 0.5)
>>> _ = sc.request("drag", {"point": "D", "x": 4.5, "y": 0})
>>> import tomllib; doc = tomllib.loads(sc.toml())
>>> doc["parameters"]["r"], doc["ground"]["D"]
({'value': 1.25, 'range': [0.5, 1.5]}, [4.5, 0])
"""
from __future__ import annotations

import copy
import threading

from ..errors import KincasError
from ..model.mechanism import Input
from .scene import Scene, loads
from .scene_toml import dumps, edited, number


class RequestError(ValueError):
    """A request the session cannot honour (its message goes back to the page)."""


class Session:
    """The scene `scene` (parsed from the document `doc`) being edited."""

    def __init__(self, scene: Scene, name: str = "scene.toml", text: str | None = None):
        from ..views.live.engine import Live
        self.scene, self.name, self.text = scene, name, text  # text: the file, comments and all
        self.live = Live(scene)
        self.lock = threading.Lock()

    @classmethod
    def from_text(cls, text: str, name: str = "scene.toml") -> "Session":
        return cls(loads(text), name, text)

    def request(self, what: str, body: dict | None = None) -> dict:
        """Answer one request of the page (docs/app.md): "state", "change" or "drag"."""
        with self.lock:
            try:
                return self.live.request(what, body)
            except (KeyError, ValueError, TypeError, KincasError) as e:
                raise RequestError(str(e.args[0]) if isinstance(e, KeyError) and e.args else str(e)) from None

    def toml(self) -> str:
        """The scene with its edits, as TOML text (reads back to the edited mechanism)."""
        with self.lock:
            doc = copy.deepcopy(self.scene.study.raw)
            live = self.live
            params = doc.get("parameters", {})
            for k, v in live.parameters.items():
                if k in params:
                    old = params[k]
                    if isinstance(old, dict):
                        old["value"] = number(v, old.get("value"))
                    else:
                        params[k] = number(v, old)
            ground = doc.get("ground", {})
            for g, xy in live.ground.items():
                old = ground.get(g)
                if isinstance(old, list) and len(old) == 2:
                    ground[g] = [c if isinstance(c, str) else number(new, c) for c, new in zip(old, xy)]
            fixed = live.fixed()
            entries = doc.get("inputs", [])
            # the scene's [[inputs]] in order are the mechanism's inputs (a spatial `joint = "A"`
            # is keyed by its coordinate, `A.angle`, which only the mechanism knows)
            keys = [i.key for i in self.scene.mechanism.inputs]
            for n, t in enumerate(entries):
                kind = next((k for k in ("angle", "parameter", "slide") if k in t), None)
                key = keys[n] if len(keys) == len(entries) else (Input(kind, t[kind]).key if kind else None)
                if key in fixed and "value" in t:
                    t["value"] = number(fixed[key], t["value"])
            if self.text is None:
                return dumps(doc)
            return edited(self.text.removeprefix("\ufeff"), self.scene.study.raw, doc)
