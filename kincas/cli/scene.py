"""TOML scene files (see docs/scene-format.md) -> a Mechanism and the study to run on it.

Degrees live only here and in the CLI: angles in the file (line angles, angle inputs, their
rates) are converted to radians, and angular results back to the scene's unit. Every problem
in a scene is gathered into one `SceneError` naming the section and the field.

>>> sc = loads('''
... [ground]
... A = [0, 0]
... D = [4, 0]
... [links]
... crank = { points = ["A", "B"], length = 1 }
... coupler = { points = ["B", "C"], length = 3.5 }
... rocker = { points = ["D", "C"], length = 3 }
... [[inputs]]
... angle = "crank"
... value = 90
... [guess]
... C = [3.6, 2.9]
... ''')
>>> out = sc.run()
>>> out.status.tolist(), round(float(sc.user_values(out)["rocker.angle"][0]), 4)
(['ok'], 109.7303)
"""
from __future__ import annotations

import math
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import KincasError, SceneError
from ..model.mechanism import GROUND, Link, Mechanism, Param, Slide
from ..results import Sweep
from .scene_params import LARGEST, ParameterReader
from .scene_study import StudyReader
from ..model.names import is_angle_name

SECTIONS = {"title", "space", "units", "parameters", "ground", "links", "slides", "inputs", "guess",
            "output", "optimize", "tolerance", "gravity", "loads", "study", "gears", "racks",
            "cams", "cam_design", "simulate", "data"}


@dataclass
class Study:
    """What to run: input values per pose (radians inside), rates, what to report."""

    title: str
    units: dict[str, str]
    inputs: dict[str, np.ndarray]
    rates: dict[str, float]
    accelerations: dict[str, float]
    report: list[str]
    sensitivity: list[str] = field(default_factory=list)
    written: dict[str, np.ndarray] = field(default_factory=dict)  # inputs as the file gives them
    jerks: dict[str, float] = field(default_factory=dict)  # the inputs' third derivatives
    raw: dict = field(default_factory=dict, repr=False)  # the parsed TOML, for extensions
    # parameter -> (lo, hi), from `{ value = v, range = [lo, hi] }` in [parameters]
    ranges: dict[str, tuple[float, float]] = field(default_factory=dict)
    # free inputs, loads' expressions, [data], [simulate] (kincas/cli/scene_simulate.py)
    simulation: dict = field(default_factory=dict)

    @property
    def deg(self) -> bool:
        return self.units.get("angle", "deg") == "deg"


@dataclass
class Scene:
    mechanism: Mechanism
    study: Study

    @property
    def quantities(self) -> list[str]:
        return self.study.report + [q for q in self.study.sensitivity if q not in self.study.report]

    def run(self, **kw) -> Sweep:
        """Sweep the mechanism as the scene says. The Sweep is Python's: angles in RADIANS
        whatever the scene's unit (like every kincas result); `user_inputs(sweep)` and
        `user_values(sweep)` give the numbers in the scene's units, as `kincas solve` prints."""
        from ..analysis.expression_loads import sweep_with_expressions  # casadi stays out of parsing
        st = self.study
        if any(st.jerks.values()):
            kw.setdefault("jerks", st.jerks)
        sw = sweep_with_expressions(self.mechanism, st.inputs, self.load_expressions(),
                                    angle=math.pi / 180 if st.deg else 1.0, rates=st.rates,
                                    accelerations=st.accelerations, report=self.quantities, **kw)
        sw.info["display"] = self.display(sw)  # Jupyter shows it in the scene's units
        return sw

    def display(self, sw: Sweep) -> dict:
        """How a display shows the sweep in the scene's units (plain data, kept in
        `Sweep.info["display"]`): each name's unit label, and the names in degrees."""
        from ..model.names import is_angular
        from ..views.columns import quantity_unit
        deg = [k for k in sw.inputs if is_angle_name(k)] + [k for k in sw.values if is_angular(k, self.mechanism)]
        return {"units": dict(self.study.units), "degrees": deg if self.study.deg else [],
                "labels": {k: quantity_unit(self, k) for k in [*sw.inputs, *sw.values]}}

    def load_expressions(self) -> dict:
        """Loads written as expressions of the state: hidden parameter -> LoadExpression,
        each named where the scene wrote it (a sweep evaluates them at each pose's state)."""
        from ..core.motion_loads import LoadExpression
        sim = self.study.simulation
        return {k: LoadExpression(t, sim["where"][k], sim["data"])
                for k, t in (sim.get("expressions") or {}).items()}

    def refuse_jerks(self, texts, where: str) -> None:
        """Only `kincas solve` passes the inputs' `jerk` on; elsewhere they would be taken as 0,
        so a jerk quantity there with a nonzero input jerk is refused rather than wrong."""
        import re
        if any(self.study.jerks.values()) and any(re.search(r"\.(jx|jy|jerk)\b", str(t)) for t in texts):
            raise SceneError(f"{where}: a jerk quantity with a nonzero input `jerk`: only "
                             f"`kincas solve` takes the inputs' jerks (here they would be 0)")

    def user_inputs(self, s: Sweep) -> dict[str, np.ndarray]:
        """Input values in the scene's units: the numbers as written, not through radians."""
        out = {}
        for k, v in s.inputs.items():
            user, w = self._to_user(k, v, angle=is_angle_name(k)), self.study.written.get(k)
            same = w is not None and w.shape == user.shape and np.allclose(user, w, rtol=1e-12, atol=0)
            out[k] = w if same else user
        return out

    def user_values(self, s: Sweep) -> dict[str, np.ndarray]:
        """Reported quantities in the scene's units (degrees where the scene says so)."""
        from ..model.names import is_angular
        return {k: self._to_user(k, v, angle=is_angular(k, self.mechanism)) for k, v in s.values.items()}

    def _to_user(self, name, v, angle):
        # A parameter used as an angle stays in the scene's unit inside, so d(Q)/d(p) is
        # already per degree of p; only the quantity's own angle unit is converted here.
        return np.degrees(v) if angle and self.study.deg else np.asarray(v, float)


LEAN = 1000  # more unused parameters than this are left out of the model
_WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_\-]*")


def mentioned(doc) -> set[str]:
    """Every name a parsed TOML value could refer to a parameter by: its tables' keys and the
    words of its strings (with and without their hyphens: `a-b` may be a name or a - b).

    >>> sorted(mentioned({"links": {"crank": {"length": "a-b"}}, "report": ["d(C.x)/d(r)"]}))
    ['C', 'a', 'a-b', 'b', 'crank', 'd', 'length', 'links', 'r', 'report', 'x']
    """
    out: set[str] = set()
    todo = [doc]
    while todo:
        v = todo.pop()
        if isinstance(v, dict):
            out.update(k for k in v if isinstance(k, str))
            todo.extend(v.values())
        elif isinstance(v, list):
            todo.extend(v)
        elif isinstance(v, str):
            for w in _WORD.findall(v):
                out.add(w)
                out.update(w.split("-"))
    return out


def load(path: str | Path) -> Scene:
    """Read a scene file. Raises SceneError (naming section and field) when it is malformed."""
    try:
        data = Path(path).read_bytes()
    except OSError as e:
        raise SceneError(f"scene: cannot read {str(path)!r}: {e.strerror or e}") from None
    try:
        text = data.decode("utf-8-sig")  # a byte-order mark, as some editors write, is accepted
    except UnicodeDecodeError as e:
        raise SceneError(f"scene: {str(path)!r} is not UTF-8 text (byte 0x{data[e.start]:02x} at "
                         f"offset {e.start}): save it as UTF-8") from None
    return loads(text)


def loads(text: str) -> Scene:
    """Parse a scene from TOML text (refused before parsing if its entries alone would not
    fit in memory: TOML's parser takes about 5 kB per `name = value`)."""
    from . import bounds
    n = bounds.scene_entries(text)
    try:
        bounds.check_total(f"scene: about {n:,} entries (`name = value`)", n * bounds.PER_ENTRY,
                           "declare fewer (parameters that nothing uses can go)")
    except ValueError as e:
        raise SceneError(str(e)) from None
    try:
        doc = tomllib.loads(text.removeprefix("\ufeff"))
    except tomllib.TOMLDecodeError as e:
        raise SceneError(f"scene: not valid TOML: {e}") from None
    return _Reader(doc).scene()


# --- reading, with every problem gathered ---


class _Reader(StudyReader, ParameterReader):
    def __init__(self, doc: dict):
        self.doc, self.problems = doc, []
        units = doc.get("units", {})
        self.deg = True
        if not isinstance(units, dict):
            self.err("[units]: expected a table like { length = \"mm\", angle = \"deg\" }")
            units = {}
        elif units.get("angle", "deg") not in ("deg", "rad"):
            self.err(f"[units] angle: {units['angle']!r} is neither \"deg\" nor \"rad\"")
        else:
            self.deg = units.get("angle", "deg") == "deg"
        self.units = {"length": "", "angle": "deg", "time": "s",
                      **{k: str(v) for k, v in units.items()}} if isinstance(units, dict) else {}
        self.params = {}
        self.jerks: dict[str, float] = {}
        self.bad_params = set()  # reported once, where declared; not again where used
        self.ranges: dict[str, tuple[float, float]] = {}  # [parameters] ranges, for sliders
        self.free: list[str] = []  # inputs moved by the forces
        self.expressions: dict[str, tuple[str, str]] = {}  # hidden parameter -> (text, where)

    def err(self, msg: str):
        self.problems.append(msg)

    def table(self, name) -> dict:
        t = self.doc.get(name, {})
        if not isinstance(t, dict):
            self.err(f"[{name}]: expected a table")
            return {}
        return t

    def num(self, where: str, v, angle=False):
        """A number or a parameter's name; angles converted to radians."""
        k = math.pi / 180 if angle and self.deg else 1.0
        if isinstance(v, str):
            # "-d": minus parameter d (names cannot start with "-", so this is unambiguous)
            name, sign = (v[1:], -1.0) if v.startswith("-") else (v, 1.0)
            if name not in self.params:
                if name not in self.bad_params:
                    self.err(f"{where}: unknown parameter {name!r}")
                return 0.0
            return Param(name, sign * k) if sign * k != 1.0 else name
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            self.err(f"{where}: expected a number or a parameter's name, got {v!r}")
            return 0.0
        if not math.isfinite(v):
            self.err(f"{where}: {v} is not a finite number")
            return 0.0
        if abs(v) > LARGEST:
            self.err(f"{where}: {v:g} is too large (at most {LARGEST:g}: lengths are squared)")
            return 0.0
        return float(v) * k

    def value(self, where, v, angle=False) -> float:
        """A plain float (parameter names resolved to their values)."""
        x = self.num(where, v, angle)
        if isinstance(x, (str, Param)):
            p = x if isinstance(x, Param) else Param(x)
            return p.scale * self.params[p.name]
        return x

    def xy(self, where, v, angle=False):
        if not isinstance(v, list) or len(v) != 2:
            self.err(f"{where}: expected [x, y], got {v!r}")
            return (0.0, 0.0)
        return (self.num(where, v[0]), self.num(where, v[1]))

    def fields(self, where, t: dict, allowed: set[str]):
        for k in t:
            if k not in allowed:
                self.err(f"{where}: unknown field {k!r} (expected one of {sorted(allowed)})")

    # --- sections ---
    def scene(self) -> Scene:
        doc = self.doc
        space = doc.get("space", "2d")
        if space == "3d":  # a spatial scene: kincas/cli/scene_space.py
            from .scene_space import read_space
            return read_space(self, Scene, Study)
        if space != "2d":
            self.err(f"space: expected \"2d\" or \"3d\", got {space!r}")
        for k in doc:
            if k not in SECTIONS:
                self.err(f"scene: unknown section or key {k!r} (expected {sorted(SECTIONS)})")
        title = self.title_and_parameters()
        ground = {k: self.xy(f"[ground] {k}", v) for k, v in self.table("ground").items()}
        if GROUND in ground:
            self.err("[ground] ground: the name `ground` means the fixed frame")
        links = [self.link(k, v) for k, v in self.table("links").items()]
        slides = [self.slide(i, s) for i, s in enumerate(self.array("slides"))]
        from .scene_joints import read as read_joints
        gears, racks, cams = read_joints(self)
        inputs, values, rates, accs, written = self.inputs()
        from . import scene_loads
        grav, loads = scene_loads.gravity(self, doc), scene_loads.read_loads(self)
        from . import scene_simulate
        simulation = scene_simulate.read(self, doc, {lk.name for lk in links if lk}, inputs)
        guess = {k: self.xy(f"[guess] {k}", v) for k, v in self.table("guess").items()}
        report, sens = self.output()
        if not self.doc.get("links"):
            self.err("[links]: none declared: a mechanism needs at least one moving link "
                     "(see docs/scene-format.md)")
        if self.problems:
            raise SceneError(self.problems)
        try:
            m = Mechanism(parameters=self.lean_parameters(), ground=ground, links=[lk for lk in links if lk],
                          slides=slides, inputs=inputs, guess=guess, gravity=grav, loads=loads,
                          gears=gears, racks=racks, cams=cams)
        except KincasError as e:
            raise SceneError(e.problems) from None
        if report is None:
            from ..model.names import default_report
            report = default_report(m)
        self.check_quantities(m, report, sens)
        study = Study(title=title if isinstance(title, str) else "", units=self.units,
                      inputs=values, rates=rates, accelerations=accs, report=report,
                      sensitivity=sens, written=written, raw=doc, jerks=self.jerks,
                      ranges=self.ranges, simulation=simulation)
        return Scene(m, study)

    def lean_parameters(self) -> dict:
        """The parameters the model is built with: all of them, unless more than LEAN are
        named nowhere else in the scene (no field, expression, key or report mentions them):
        those are left out, since every parameter is a symbol of the model and thousands of
        unused ones cost seconds and memory for nothing."""
        if len(self.params) <= LEAN:
            return self.params
        used = mentioned({k: v for k, v in self.doc.items() if k != "parameters"})
        unused = [k for k in self.params if k not in used]
        if len(unused) <= LEAN:
            return self.params
        return {k: v for k, v in self.params.items() if k in used}

    def array(self, name) -> list[dict]:
        v = self.doc.get(name, [])
        if not isinstance(v, list) or not all(isinstance(x, dict) for x in v):
            self.err(f"[[{name}]]: expected an array of tables ([[{name}]] blocks)")
            return []
        return v

    def link(self, name, t):
        where = f"[links] {name}"
        if not isinstance(t, dict) or "points" not in t:
            self.err(f"{where}: points: missing (a link is {{ points = [\"P\", \"Q\"], length = L }} "
                     f"or {{ points = {{ P = [x, y], ... }} }})")
            return None
        from .scene_loads import LINK_FIELDS, link_inertia
        pts, inertia = t["points"], link_inertia(self, where, t)
        if isinstance(pts, list):
            self.fields(where, t, {"points", "length"} | LINK_FIELDS)
            if len(pts) != 2 or not all(isinstance(p, str) for p in pts):
                self.err(f"{where}: points: the two-point form takes two point names")
                return None
            if "length" not in t:
                self.err(f"{where}: length: missing (the two-point form needs a length)")
                return None
            return Link.bar(name, pts[0], pts[1], self.num(f"{where}: length", t["length"]), **inertia)
        if isinstance(pts, dict):
            self.fields(where, t, {"points"} | LINK_FIELDS)
            if "length" in t:
                self.err(f"{where}: length: only the two-point form takes a length")
            return Link(name, {p: self.xy(f"{where}: points.{p}", xy) for p, xy in pts.items()}, **inertia)
        self.err(f"{where}: points: expected a list of two names or a table of local coordinates")
        return None

    def slide(self, i, t):
        where = f"[[slides]] {t.get('name', i + 1)}"
        self.fields(where, t, {"name", "point", "along", "line"})
        for k in ("point", "along"):
            if not isinstance(t.get(k), str):
                self.err(f"{where}: {k}: missing or not a name")
        line = t.get("line", {})
        if not isinstance(line, dict):
            self.err(f"{where}: line: expected {{ through = [x, y], angle = a }}")
            line = {}
        self.fields(f"{where}: line", line, {"through", "angle"})
        through = self.xy(f"{where}: line.through", line.get("through", [0.0, 0.0]))
        angle = self.num(f"{where}: line.angle", line.get("angle", 0.0), angle=True)
        return Slide(point=str(t.get("point", "")), along=str(t.get("along", "")),
                     through=through, angle=angle, name=str(t.get("name", "")))
