"""A spatial scene (`space = "3d"`, docs/scene-format.md "Spatial mechanisms") -> a
`SpatialMechanism` and its study. Read by the same reader as a planar scene
(kincas/cli/scene.py: numbers, parameters, inputs, output), with 3D points, bodies, joints and
slides; every problem gathered into one `SceneError` naming the section and the field.

>>> from kincas.cli.scene import loads
>>> sc = loads('''
... space = "3d"
... [ground]
... O = [0, 0, 0]
... [links]
... arm = { points = { O = [0, 0, 0], P = [2, 0, 0] } }
... [[joints]]
... type = "revolute"
... point = "O"
... axis = [0, 0, 1]
... [[inputs]]
... joint = "O"
... value = 90
... [output]
... report = ["P.y", "O.angle"]
... ''')
>>> out = sc.run()
>>> {k: round(float(v[0]), 9) for k, v in sc.user_values(out).items()}
{'P.y': 2.0, 'O.angle': 90.0}
"""
from __future__ import annotations

from ..errors import KincasError, ModelError, SceneError
from ..model.loads import Load
from ..model.mechanism import GROUND, Input
from ..model.space import SpatialMechanism
from ..model.space_parts import JOINT_TYPES, Body, Joint, SpatialSlide

SPACE_SECTIONS = {"title", "space", "units", "parameters", "ground", "links", "joints", "slides",
                  "inputs", "guess", "output", "optimize", "tolerance", "study"}
PLANAR_ONLY = {"gears": "gears", "racks": "racks", "cams": "cams", "cam_design": "cam design"}
SPACE_SECTIONS |= {"gravity", "loads", "simulate", "data"}  # motion under forces (docs/simulate.md)


INPUT_KINDS = ("joint", "parameter", "slide")


def read_space(reader, scene_type, study_type):
    """The Scene of a spatial document, read by the planar scene reader `reader` (its problems
    list, numbers and parameters, `[[inputs]]` and `[output]`) with the 3D sections below;
    `scene_type` and `study_type` are kincas/cli/scene.py's Scene and Study."""
    return _Space(reader).scene(scene_type, study_type)


class _Space:
    """The 3D sections, read into a planar scene reader's problems (see the module's text)."""

    def __init__(self, r):
        self.r = r
        r.INPUT_KINDS = INPUT_KINDS  # the reader's [[inputs]] take joints, named here
        r.make_input = self.make_input
        self.joint_list = []

    def __getattr__(self, name):  # err, num, value, fields, table, array, inputs, output, ...
        return getattr(self.r, name)

    def xyz(self, where, v):
        if not isinstance(v, list) or len(v) != 3:
            self.err(f"{where}: expected [x, y, z], got {v!r}")
            return (0.0, 0.0, 0.0)
        return tuple(self.num(where, c) for c in v)

    def direction(self, where, v):
        """A direction: three plain numbers (not parameters), not all zero."""
        if not isinstance(v, list) or len(v) != 3 or not all(
                isinstance(c, (int, float)) and not isinstance(c, bool) for c in v):
            self.err(f"{where}: expected a direction [x, y, z] of three numbers, got {v!r}")
            return None
        if not any(v):
            self.err(f"{where}: [0, 0, 0] has no direction")
            return None
        return tuple(float(c) for c in v)

    def scene(self, Scene, Study):
        doc = self.doc
        for k in doc:
            if k in PLANAR_ONLY:
                self.err(f"[{k}]: {PLANAR_ONLY[k]} stay planar in this version: a spatial scene "
                         f"(space = \"3d\") cannot declare them")
            elif k not in SPACE_SECTIONS:
                self.err(f"scene: unknown section or key {k!r} (expected {sorted(SPACE_SECTIONS)})")
        title = self.title_and_parameters()
        ground = {k: self.xyz(f"[ground] {k}", v) for k, v in self.table("ground").items()}
        if GROUND in ground:
            self.err("[ground] ground: the name `ground` means the fixed frame")
        bodies = [b for b in (self.link(k, v) for k, v in self.table("links").items()) if b]
        self.joint_list = [j for j in (self.joint(i, t) for i, t in enumerate(self.array("joints"))) if j]
        slides = [s for s in (self.slide(i, t) for i, t in enumerate(self.array("slides"))) if s]
        inputs, values, rates, accs, written = self.inputs()
        gravity = self.xyz("gravity", doc["gravity"]) if "gravity" in doc else (0.0, 0.0, 0.0)
        loads = self.loads()
        from . import scene_simulate
        simulation = scene_simulate.read(self.r, doc, {b.name for b in bodies}, inputs)
        guess = {k: self.xyz(f"[guess] {k}", v) for k, v in self.table("guess").items()}
        report, sens = self.output()
        if not bodies and not self.problems:
            self.err("[links]: none declared: a mechanism needs at least one moving body")
        if self.problems:
            raise SceneError(self.problems)
        try:
            m = SpatialMechanism(parameters=self.lean_parameters(), ground=ground, bodies=bodies,
                                 joints=self.joint_list, slides=slides, inputs=inputs, guess=guess,
                                 gravity=gravity, loads=loads)
        except KincasError as e:
            raise SceneError(e.problems) from None
        if report is None:
            from ..model.names import default_report
            report = default_report(m)
        # inputs are keyed by their coordinate: "A" -> "A.angle"
        keys = dict(zip([i.key for i in inputs], [i.key for i in m.inputs]))
        values, rates, accs, written = ({keys.get(k, k): v for k, v in d.items()}
                                        for d in (values, rates, accs, written))
        self.r.jerks = {keys.get(k, k): v for k, v in self.jerks.items()}
        self.check_quantities(m, report, sens)
        study = Study(title=title if isinstance(title, str) else "", units=self.units,
                      inputs=values, rates=rates, accelerations=accs, report=report,
                      sensitivity=sens, written=written, raw=doc, jerks=self.jerks,
                      ranges=self.ranges, simulation=simulation)
        return Scene(m, study)

    def link(self, name, t):
        where = f"[links] {name}"
        if not isinstance(t, dict) or "points" not in t:
            self.err(f"{where}: points: missing (a body is {{ points = {{ P = [x, y, z], ... }} }} "
                     f"or a bar {{ points = [\"P\", \"Q\"], length = L }})")
            return None
        pts = t["points"]
        inertia = {}
        if "mass" in t:
            inertia["mass"] = self.num(f"{where}: mass", t["mass"])
        if "cg" in t:
            inertia["cg"] = self.xyz(f"{where}: cg", t["cg"])
        if "inertia" in t:
            inertia["inertia"] = self.tensor(f"{where}: inertia", t["inertia"])
        if isinstance(pts, list):
            self.fields(where, t, {"points", "length", "mass"})
            if len(pts) != 2 or not all(isinstance(p, str) for p in pts):
                self.err(f"{where}: points: the two-point form takes two point names")
                return None
            if "length" not in t:
                self.err(f"{where}: length: missing (the two-point form needs a length)")
                return None
            return Body.bar(name, pts[0], pts[1], self.num(f"{where}: length", t["length"]))._with(**inertia)
        if isinstance(pts, dict):
            self.fields(where, t, {"points", "mass", "cg", "inertia"})
            if not pts:
                self.err(f"{where}: points: a body needs at least one point")
                return None
            return Body(name, {p: self.xyz(f"{where}: points.{p}", v) for p, v in pts.items()}, **inertia)
        self.err(f"{where}: points: expected a table of points as drawn or a list of two names")
        return None

    def tensor(self, where, v):
        """An inertia: a number, [Ixx, Iyy, Izz] or a 3 x 3 list (numbers or parameters)."""
        if isinstance(v, list) and len(v) == 3 and all(isinstance(r, list) for r in v):
            if not all(len(r) == 3 for r in v):
                self.err(f"{where}: expected a number, [Ixx, Iyy, Izz] or a 3 x 3 list")
                return 0.0
            return [[self.num(where, c) for c in r] for r in v]
        if isinstance(v, list):
            return list(self.xyz(where, v))
        return self.num(where, v)

    def loads(self):
        """[[loads]]: point + force = [fx, fy, fz], link + torque = [tx, ty, tz], or a spring."""
        out = []
        kinds = {"point": ("force",), "link": ("torque",), "spring": ("stiffness", "free_length")}
        for i, t in enumerate(self.array("loads")):
            where = f"[[loads]] {i + 1}"
            kind = [k for k in kinds if k in t]
            if len(kind) != 1 or any(f not in t for f in kinds[kind[0]]):
                self.err(f"{where}: give a point with its force [fx, fy, fz], a link with its torque "
                         f"[tx, ty, tz], or a spring with stiffness and free_length")
                continue
            kind = kind[0]
            self.fields(where, t, {kind, *kinds[kind]})
            if kind == "spring":
                pts = t["spring"]
                if not (isinstance(pts, list) and len(pts) == 2 and all(isinstance(p, str) for p in pts)):
                    self.err(f"{where}: spring: expected two point names [\"A\", \"B\"]")
                    continue
                out.append(Load.spring(pts[0], pts[1], self.num(f"{where}: stiffness", t["stiffness"]),
                                       self.num(f"{where}: free_length", t["free_length"])))
            elif not isinstance(t[kind], str):
                self.err(f"{where}: {kind}: expected a name")
            else:
                field = kinds[kind][0]
                out.append(Load("force" if kind == "point" else "torque", at=t[kind],
                                value=self.components(where, i + 1, field, t[field])))
        return out

    def components(self, where, index, field, v):
        """[x, y, z] of a load: numbers, parameters or expressions of the state (a hidden
        parameter each, evaluated along a motion: kincas/cli/scene_simulate.py)."""
        from .scene_simulate import component
        if not isinstance(v, list) or len(v) != 3:
            self.err(f"{where}: {field}: expected [x, y, z], got {v!r}")
            return (0.0, 0.0, 0.0)
        return tuple(component(self.r, where, index, f"{field}_{c}", x) for c, x in zip("xyz", v))

    def joint(self, i, t):
        where = f"[[joints]] {t.get('name', t.get('point', i + 1))}"
        self.fields(where, t, {"type", "point", "axis", "axes", "bodies", "name"})
        kind, point = t.get("type"), t.get("point")
        if kind not in JOINT_TYPES:
            self.err(f"{where}: type: expected one of {list(JOINT_TYPES)}, got {kind!r}")
            return None
        if not isinstance(point, str):
            self.err(f"{where}: point: missing or not a name")
            return None
        axis = self.direction(f"{where}: axis", t["axis"]) if "axis" in t else None
        axes = None
        if "axes" in t:
            a = t["axes"]
            if not isinstance(a, list) or len(a) != 2:
                self.err(f"{where}: axes: expected two axes [[x, y, z], [x, y, z]]")
                return None
            axes = tuple(self.direction(f"{where}: axes[{k}]", v) for k, v in enumerate(a))
            if None in axes:
                return None
        bodies = t.get("bodies")
        if bodies is not None and not (isinstance(bodies, list) and all(isinstance(b, str) for b in bodies)):
            self.err(f"{where}: bodies: expected [\"first\", \"second\"]")
            return None
        name = t.get("name", "")
        if not isinstance(name, str):
            self.err(f"{where}: name: expected a name")
            return None
        try:
            return Joint(kind, point, axis=axis, axes=axes, bodies=None if bodies is None else tuple(bodies),
                         name=name)
        except ModelError as e:
            for msg in e.problems:
                self.err(msg)
            return None

    def slide(self, i, t):
        where = f"[[slides]] {t.get('name', t.get('point', i + 1))}"
        self.fields(where, t, {"name", "point", "along", "line", "plane"})
        for k in ("point", "along"):
            if not isinstance(t.get(k), str):
                self.err(f"{where}: {k}: missing or not a name")
                return None
        if ("line" in t) == ("plane" in t):
            self.err(f"{where}: give either line = {{ through, direction }} or plane = {{ through, normal }}")
            return None
        kind = "line" if "line" in t else "plane"
        spec = t[kind]
        other = "direction" if kind == "line" else "normal"
        if not isinstance(spec, dict) or other not in spec:
            self.err(f"{where}: {kind}: expected {{ through = [x, y, z], {other} = [x, y, z] }}")
            return None
        self.fields(f"{where}: {kind}", spec, {"through", other})
        through = self.xyz(f"{where}: {kind}.through", spec.get("through", [0, 0, 0]))
        d = self.direction(f"{where}: {kind}.{other}", spec[other])
        if d is None:
            return None
        return SpatialSlide(t["point"], t["along"], through, name=str(t.get("name", "")),
                            **{other: d})

    def make_input(self, kind, name, where):
        """A joint input keyed by its coordinate ("A" -> "A.angle"), from `[[joints]]`."""
        if kind != "joint":
            return Input(kind, name)
        jname, _, coord = name.partition(".")
        joints = {j.name: j for j in self.joint_list}
        if jname not in joints:
            self.err(f"{where}: joint: unknown joint {jname!r} (a joint is named by `name`, "
                     f"default its point)")
            return None
        coords = joints[jname].coordinates
        if not coord and len(coords) == 1:
            coord = coords[0]
        if coord not in coords:
            self.err(f"{where}: joint: {name!r}: a {joints[jname].type} joint's coordinates are "
                     f"{[f'{jname}.{c}' for c in coords]}")
            return None
        return Input("joint", f"{jname}.{coord}")
