"""Scene reading of loads and inertia: top-level `gravity`, `mass`/`inertia`/`cg` on links,
and `[[loads]]` (forces at points, torques on links, springs between points).

Numbers are used as written; a torque, a stiffness, a mass are not angles, so nothing here is
converted to radians. Problems are reported through the reader, naming section and field.

>>> from kincas.cli.scene import loads
>>> sc = loads('''
... gravity = [0, -9.81]
... [ground]
... A = [0, 0]
... D = [4, 0]
... [links]
... crank = { points = ["A", "B"], length = 2, mass = 3 }
... coupler = { points = ["B", "C"], length = 3.5 }
... rocker = { points = ["D", "C"], length = 3.5 }
... [[loads]]
... link = "rocker"
... torque = 0
... [[inputs]]
... angle = "crank"
... value = 0
... rate = 0
... [guess]
... C = [4, 3]
... [output]
... report = ["effort(crank.angle)"]
... ''')
>>> round(float(sc.run().values["effort(crank.angle)"][0]), 6)   # its weight 3*9.81 at 1 from A
29.43
"""
from __future__ import annotations

from ..model.loads import Load
from .scene_simulate import component  # a component may be an expression of the state

LINK_FIELDS = {"mass", "inertia", "cg"}
_KINDS = {"point": ("force",), "link": ("torque",), "spring": ("stiffness", "free_length")}


def link_inertia(reader, where: str, t: dict) -> dict:
    """Keyword arguments mass/inertia/cg of a link's table (those given)."""
    out = {}
    for k in ("mass", "inertia"):
        if k in t:
            out[k] = reader.num(f"{where}: {k}", t[k])
    if "cg" in t:
        out["cg"] = reader.xy(f"{where}: cg", t["cg"])
    return out


def gravity(reader, doc: dict):
    if "gravity" not in doc:
        return (0.0, 0.0)
    return reader.xy("gravity", doc["gravity"])


def read_loads(reader) -> list[Load]:
    out = []
    for i, t in enumerate(reader.array("loads")):
        where = f"[[loads]] {i + 1}"
        kinds = [k for k in _KINDS if k in t]
        if len(kinds) != 1:
            reader.err(f"{where}: give exactly one of point (with force), link (with torque) "
                       f"or spring (with stiffness and free_length)")
            continue
        kind = kinds[0]
        reader.fields(where, t, {kind, *_KINDS[kind]})
        missing = [f for f in _KINDS[kind] if f not in t]
        if missing:
            reader.err(f"{where}: {missing[0]}: missing")
            continue
        if kind == "point":
            if not isinstance(t["point"], str):
                reader.err(f"{where}: point: expected a point's name")
                continue
            f = t["force"]
            if not isinstance(f, list) or len(f) != 2:
                reader.err(f"{where}: force: expected [x, y], got {f!r}")
                continue
            out.append(Load.force(t["point"], (component(reader, where, i + 1, "force_x", f[0]),
                                               component(reader, where, i + 1, "force_y", f[1]))))
        elif kind == "link":
            if not isinstance(t["link"], str):
                reader.err(f"{where}: link: expected a link's name")
                continue
            out.append(Load.torque(t["link"], component(reader, where, i + 1, "torque", t["torque"])))
        else:
            pts = t["spring"]
            if not (isinstance(pts, list) and len(pts) == 2 and all(isinstance(p, str) for p in pts)):
                reader.err(f"{where}: spring: expected two point names [\"A\", \"B\"]")
                continue
            out.append(Load.spring(pts[0], pts[1], reader.num(f"{where}: stiffness", t["stiffness"]),
                                   reader.num(f"{where}: free_length", t["free_length"])))
    return out
