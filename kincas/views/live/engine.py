"""The live page's model of one mechanism being edited: its parameters, its ground points and its
inputs change one at a time, and each change re-solves the whole sweep at once and keeps the
assembly branch. What the page draws comes out as one JSON-ready dict (`Live.state`).

Speed: every sweep reuses one model. A mechanism's numeric ground coordinates are part of its
structure (a new structure is a new CasADi model), so they are *lifted* into hidden parameters
first (`_lift`): dragging a ground point then changes parameter values only, like a slider,
and `kincas.sweep` finds the structure's model and kernel already built (a four-bar's 361
poses in a few milliseconds).

Branch: each sweep starts from the points of the previous solved sweep's first pose (a
guess obeyed by `kincas.sweep`), and a new value of a fixed input is reached by continuation
(a short sweep from the old value to the new), so a change never jumps to another assembly.
A change that leaves nothing to assemble keeps its values and says so (`message`); the guess
stays the last solved one, so the next change that assembles again works.

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
>>> live = Live(Setting.of(m))
>>> live.drag("D", 4.5, 0.0)["message"], live.ground["D"]
('', (4.5, 0.0))
>>> s = live.state(); s["ok"].count(True), s["plot"]["x"]["name"]
(361, 'crank.angle')
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ...model.mechanism import Mechanism, Param
from ...results import Sweep
from .. import columns
from .drawing import _list
from .setting import Setting  # noqa: F401  (the page's setting of a bare mechanism)

HIDDEN = "_ground_"  # prefix of the lifted ground coordinates' parameter names
CONTINUATION = math.radians(3)  # largest step of an angle input between two continuation poses
PARTS = 60  # continuation steps over a slide's or parameter input's whole range


@dataclass
class _Handle:
    """Where a ground coordinate lives: coordinate = scale * parameter."""
    parameter: str
    scale: float


def _lift(m: Mechanism) -> tuple[Mechanism, dict]:
    """The mechanism with each numeric ground coordinate made a hidden parameter, and for each
    ground point its two handles (x, y)."""
    from ..poses import is_spatial
    if is_spatial(m):  # a spatial mechanism's ground is not dragged (docs/app.md): nothing lifted
        return m, {}
    params = dict(m.param_values)
    ground, handles = {}, {}
    for g, xy in m.ground:
        pair, hs = [], []
        for axis, c in zip("xy", xy):
            if isinstance(c, str):
                hs.append(_Handle(c, 1.0))
                pair.append(c)
            elif isinstance(c, Param):
                hs.append(_Handle(c.name, c.scale))
                pair.append(c)
            else:
                name = f"{HIDDEN}{g}_{axis}"
                while name in m.param_values:
                    name += "_"
                params[name] = float(c)
                hs.append(_Handle(name, 1.0))
                pair.append(name)
        ground[g], handles[g] = tuple(pair), tuple(hs)
    return replace(m, parameters=params, ground=ground), handles


@dataclass
class _Input:
    key: str
    kind: str
    values: np.ndarray  # radians inside; one value per pose (all equal for a fixed input)
    swept: bool
    angle: bool
    lo: float = 0.0  # a fixed input's slider range (radians inside)
    hi: float = 0.0
    user: float | None = None  # a fixed input's value as the user wrote it (the scene's units)


@dataclass
class Live:
    """One mechanism being edited live (see the module). `setting` is a scene (`Scene`) or a
    `Setting`; every method that changes something returns the new `state()`."""

    setting: object
    m: Mechanism = field(init=False)
    sweep: Sweep | None = field(init=False, default=None)
    message: str = field(init=False, default="")
    version: int = field(init=False, default=0)

    def __post_init__(self):
        sc = self.setting
        self.m, self.handles = _lift(sc.mechanism)
        self.hidden = {h.parameter for hs in self.handles.values() for h in hs if h.parameter.startswith(HIDDEN)}
        self.hidden &= set(self.m.param_values) - set(sc.mechanism.param_values)
        self.deg = bool(getattr(sc.study, "deg", False))
        self.report = list(sc.quantities)
        self.extra = self._motion_names()
        driven = {i.target for i in self.m.inputs if i.kind == "parameter"}
        self.free = [k for k in sc.mechanism.param_values if k not in driven]
        self.ranges = dict(getattr(sc.study, "ranges", {}) or {})
        for k in self.free:  # fixed once, so that a slider does not move under the mouse
            if k not in self.ranges:  # half to one and a half times the value (around 0: the size)
                v = self.m.param_values[k]
                span = abs(v) if v != 0 else self.m.size()
                self.ranges[k] = (v - 0.5 * span, v + 0.5 * span)
        self.inputs = []
        size = self.m.size()
        for inp in self.m.inputs:
            v = np.asarray(sc.study.inputs[inp.key], float)
            swept = bool(len(v) > 1 and np.ptp(v) > 0)
            ang = inp.kind == "angle" or (inp.kind == "joint" and inp.key.endswith(".angle"))
            half = math.pi if ang else size
            lo, hi = float(v[0]) - half, float(v[0]) + half
            if inp.kind == "parameter" and inp.target in self.ranges:
                lo, hi = self.ranges[inp.target]
            written = getattr(sc.study, "written", {}).get(inp.key)
            user = float(written[0]) if written is not None and not swept else None
            self.inputs.append(_Input(inp.key, inp.kind, v, swept, ang, lo, hi, user))
        self.guess0 = {p: tuple(map(self.m.value, xy)) for p, xy in self.m.guess} or None
        self.solve()

    # --- what can change ---

    @property
    def parameters(self) -> dict[str, float]:
        """The scene's parameters (not the hidden ground coordinates) as they are now."""
        return {k: v for k, v in self.m.param_values.items() if k not in self.hidden}

    @property
    def ground(self) -> dict[str, tuple[float, float]]:
        """Each ground point where it is now."""
        return {g: tuple(map(self.m.value, xy)) for g, xy in self.m.ground}

    def fixed(self) -> dict[str, float]:
        """The fixed inputs' values now, in the scene's units."""
        return {i.key: self._value(i) for i in self.inputs if not i.swept}

    def change(self, parameters: dict | None = None, inputs: dict | None = None) -> dict:
        """New parameter values (the scene's units) and fixed-input values (the scene's units:
        degrees where it says so); re-solves. Unknown names raise KeyError, non-numbers ValueError."""
        parameters, inputs = dict(parameters or {}), dict(inputs or {})
        for k, v in {**parameters, **inputs}.items():
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise ValueError(f"{k}: expected a finite number, got {v!r}")
        bad = [k for k in parameters if k not in self.free]
        fixed = {i.key: i for i in self.inputs if not i.swept}
        bad += [k for k in inputs if k not in fixed]
        if bad:
            raise KeyError(f"nothing to change called {', '.join(map(repr, bad))}")
        if parameters:
            self.m = self.m.with_parameters(**parameters)
        for k, v in inputs.items():
            inp = fixed[k]
            new = float(v) * (math.pi / 180 if inp.angle and self.deg else 1.0)
            self._continue(inp, new)
            inp.values, inp.user = np.full(len(inp.values), new), float(v)
        return self.solve()

    def drag(self, point: str, x: float, y: float) -> dict:
        """Point `point` dragged to (x, y): a ground point moves there (its coordinates' parameters
        change); a moving point takes the pose, or the fixed input's value, that brings it
        nearest (x, y)."""
        if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in (x, y)):
            raise ValueError(f"drag: expected finite coordinates, got {(x, y)!r}")
        from ..poses import is_spatial
        if is_spatial(self.m):
            raise ValueError("drag: points of a spatial mechanism are not dragged (in 3D the mouse turns the view)")
        if point in self.handles:
            values = {}
            for h, c in zip(self.handles[point], (x, y)):
                if h.scale != 0:
                    values[h.parameter] = float(c) / h.scale
            self.m = self.m.with_parameters(**values)
            return self.solve()
        if point not in self.m.moving_points:
            raise KeyError(f"drag: no point called {point!r}")
        return self._follow(point, np.array([x, y], float))

    def request(self, what: str, body: dict | None = None) -> dict:
        """Answer one request of the page (docs/app.md): "state", "change" ({"parameters":
        {...}, "inputs": {...}}) or "drag" ({"point", "x", "y"}). A request that cannot be
        honoured raises ValueError (or KeyError) with one line, and changes nothing."""
        body = {} if body is None else body
        if not isinstance(body, dict):
            raise ValueError("expected a JSON object")
        if what == "state":
            return self.state()
        if what == "change":
            extra = set(body) - {"parameters", "inputs"}
            if extra:
                raise ValueError(f"change: unknown field(s) {sorted(extra)}")
            p, i = body.get("parameters") or {}, body.get("inputs") or {}
            if not isinstance(p, dict) or not isinstance(i, dict):
                raise ValueError("change: parameters and inputs are objects name -> number")
            return self.change(p, i)
        if what == "drag":
            if not isinstance(body.get("point"), str):
                raise ValueError("drag: point: expected a point's name")
            return self.drag(body["point"], body.get("x"), body.get("y"))
        raise ValueError(f"no request called {what!r}")

    # --- solving ---

    def table(self) -> dict[str, np.ndarray]:
        """The inputs of the sweep now (radians inside)."""
        return {i.key: i.values for i in self.inputs}

    def solve(self) -> dict:
        """Sweep again from the last solved first pose; the new state."""
        from ...analysis.sweeps import sweep
        sw = sweep(self.m, self.table(), rates=self.setting.study.rates or None,
                   accelerations=self.setting.study.accelerations or None,
                   report=self.report + self.extra, guess=self.guess0)
        self.version += 1
        self.pose = None
        n, ok = len(sw), int(sw.ok.sum())
        if ok == 0:
            self.message = ("does not assemble here: no pose of the sweep can be put together "
                            "(change it back, or change something else)")
        elif ok < n:
            self.message = f"{n - ok} of {n} poses do not assemble (marked)"
        else:
            self.message = ""
        if ok:
            i = int(np.argmax(sw.ok))
            self.guess0 = self._points(sw, i)
        self.sweep = sw
        return self.state()

    def _points(self, sw: Sweep, i: int) -> dict:
        from ..poses import geometry
        geo = geometry(self.m, sw)
        return {p: tuple(map(float, geo.point(p)[i])) for p in self.m.moving_points}

    def _continue(self, inp: _Input, new: float) -> None:
        """Carry the guess from the input's old value to `new` along a short sweep (the other
        inputs at the first pose), so the branch is kept however far the slider jumped."""
        from ...analysis.sweeps import sweep
        old = float(inp.values[0])
        step = CONTINUATION if inp.angle else max(inp.hi - inp.lo, 1e-12) / PARTS
        n = int(min(400, max(2, math.ceil(abs(new - old) / step) + 1)))
        table = {i.key: np.full(n, i.values[0]) for i in self.inputs}
        table[inp.key] = np.linspace(old, new, n)
        sw = sweep(self.m, table, report=[], guess=self.guess0)
        if sw.ok[-1]:
            self.guess0 = self._points(sw, n - 1)

    def _follow(self, point: str, target: np.ndarray) -> dict:
        """The pose of the sweep (or the fixed input's value) nearest `target` for `point`."""
        from ..poses import geometry
        swept = [i for i in self.inputs if i.swept]
        if swept or not self.inputs:
            xy = geometry(self.m, self.sweep).point(point)
            d = np.hypot(*(xy - target).T)
            d[~np.isfinite(d)] = np.inf
            state = self.state()
            if np.isfinite(d).any():
                state["pose"] = self.pose = int(np.argmin(d))
            return state
        best = None
        from ...analysis.sweeps import sweep
        for inp in self.inputs:  # each fixed input, both ways from its value, on the branch
            v0 = float(inp.values[0])
            for end in (inp.lo, inp.hi):
                n = 91
                table = {i.key: np.full(n, i.values[0]) for i in self.inputs}
                table[inp.key] = np.linspace(v0, end, n)
                sw = sweep(self.m, table, report=[], guess=self.guess0)
                xy = geometry(self.m, sw).point(point)
                d = np.hypot(*(xy - target).T)
                run = np.cumprod(sw.ok).astype(bool)  # up to the first pose that fails
                d[~run | ~np.isfinite(d)] = np.inf
                k = int(np.argmin(d))
                if np.isfinite(d[k]) and (best is None or d[k] < best[0]):
                    best = (d[k], inp, table[inp.key][k])
        if best is None:
            return self.state()
        _, inp, v = best
        return self.change(inputs={inp.key: self._user(inp, v)})

    # --- what the page shows ---

    def _user(self, inp: _Input, v: float) -> float:
        return float(np.degrees(v)) if inp.angle and self.deg else float(v)

    def _value(self, inp: _Input) -> float:
        """A fixed input's value in the scene's units, as written where it was."""
        return inp.user if inp.user is not None else self._user(inp, inp.values[0])

    def _motion_names(self) -> list[str]:
        """The velocities the instant centres need: each moving link's angular velocity and
        the velocity of one of its points."""
        from ..poses import is_spatial
        out = []
        if is_spatial(self.m):  # no instant centres in space (a spatial body has an axis, not a point)
            return out
        for lk in self.m.links:
            pts = [p for p in lk.point_names if p in self.m.moving_points or p in dict(self.m.ground)]
            if pts:
                out += [f"{lk.name}.omega", f"{pts[0]}.vx", f"{pts[0]}.vy"]
        return [q for q in dict.fromkeys(out) if q not in self.report]

    def state(self) -> dict:
        """Everything the page draws and prints, JSON-ready (see docs/app.md)."""
        from .drawing import drawing
        sw, sc = self.sweep, replace(self.setting, mechanism=self.m) if hasattr(self.setting, "__dataclass_fields__") else self.setting
        inputs, values = columns.user_columns(sw, sc)
        values = {k: values[k] for k in self.report if k not in inputs}
        xkey, x = columns._abscissa(sw, inputs)
        units = sc.study.units
        drawn = drawing(self.m, sw, self.handles)
        return {
            "version": self.version, "title": getattr(sc.study, "title", "") or "kincas",
            "units": {"length": units.get("length", ""), "angle": units.get("angle", "rad")},
            "message": self.message, "pose": self.pose, "poses": len(sw),
            "parameters": [self._parameter(k, v) for k, v in self.parameters.items() if k in self.free],
            "inputs": [self._input_state(i, inputs) for i in self.inputs],
            "ok": [bool(v) for v in sw.ok], "status": [str(s) for s in sw.status],
            "flags": [f or None for f in sw.flags],
            "events": [{"pose": int(e["pose"]), "kind": str(e.get("kind", ""))} for e in sw.events],
            "drawing": drawn,
            "centres": drawn.pop("centres"),
            "plot": {"x": {"name": xkey or "pose", "unit": columns.quantity_unit(sc, xkey) if xkey else "",
                           "values": _list(x)},
                     "quantities": [{"name": k, "unit": columns.quantity_unit(sc, k), "values": _list(v)}
                                    for k, v in values.items()]},
        }

    def _parameter(self, k: str, v: float) -> dict:
        lo, hi = self.ranges[k]
        self.ranges[k] = lo, hi = min(lo, v), max(hi, v)  # a value typed beyond widens it
        return {"name": k, "value": v, "lo": lo, "hi": hi}

    def _input_state(self, i: _Input, inputs: dict) -> dict:
        unit = (self.setting.study.units.get("angle", "rad") if i.angle else
                self.setting.study.units.get("length", "") if i.kind == "slide" else "")
        out = {"key": i.key, "swept": i.swept, "unit": unit}
        if i.swept:
            out["values"] = _list(inputs[i.key])
        else:
            out.update(value=self._value(i), lo=self._user(i, i.lo), hi=self._user(i, i.hi))
        return out
