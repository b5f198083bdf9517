"""What the live page draws of a sweep, as JSON-ready lists: the bodies, the slides' guides, the
gears', racks' and cams' curves, every point at every pose (from `kincas.views.picture`, so
the page draws what the other pictures draw), the loads as arrows, and each link's instant
centre of rotation relative to the ground.

The instant centre I of a link turning at angular velocity w, one of whose points P moves at
velocity v: v = w k x (P - I), so P - I = (v_y, -v_x) / w and I = (P_x - v_y / w, P_y + v_x / w).
A link that does not turn (w = 0) translates: its centre is at infinity (None).

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
>>> sw = kincas.sweep(m, {"crank.angle": [0.5]},
...                   report=["crank.omega", "A.vx", "A.vy", "coupler.omega", "B.vx", "B.vy"])
>>> [round(c, 9) for c in instant_centres(m, sw)["crank"][0]]   # the crank turns about A
[0.0, 0.0]
"""
from __future__ import annotations

import math

import numpy as np

from ...model.mechanism import Mechanism
from ...results import Sweep
from ..picture import INK, picture

FAR = 50  # instant centres farther than this many mechanism sizes are drawn as at infinity


def _plain(v):
    """A JSON number, None for NaN or infinity."""
    v = float(v)
    return v if math.isfinite(v) else None


def _list(a) -> list:
    """A nested list of JSON numbers (None where not finite)."""
    a = np.asarray(a, float)
    if a.ndim == 0:
        return _plain(a)
    out = a.round(12).tolist() if a.size else a.tolist()
    if np.isfinite(a).all():
        return out
    return _nulls(out)


def _nulls(v):
    if isinstance(v, list):
        return [_nulls(x) for x in v]
    return v if math.isfinite(v) else None


def drawing(m: Mechanism, sw: Sweep, handles: dict) -> dict:
    """Names, points per pose, bodies, guides, joint curves, loads; `draggable` lists the ground
    points (they move the ground) and the moving points (they move the input). A spatial
    mechanism's points, loads and weights stay in space: the page projects them with its camera."""
    n = len(sw)
    from ..poses import is_spatial
    space = is_spatial(m)  # a spatial mechanism's points stay in space: the page turns them
    pic = picture(m, sw, paths=[], world=space)
    joints = None
    if m.gears or m.racks or m.cams:  # coarse curves per pose (the page stays small)
        colours = {b.name: b.colour for b in pic.bodies}
        joints = [[{"colour": "#c0392b" if len(a) == 1 else colours.get(body, INK), "pts": _list(a)}
                   for _, body, a in pic.joint_curves(i, 41)] for i in range(n)]
    return {
        "names": pic.names, "xy": _list(pic.xy), "r": float(pic.r), "box": _list(pic.box()),
        "ground": pic.ground, "moving": [pic.names.index(p) for p in m.moving_points if p in pic.names],
        "bodies": [{"name": b.name, "ring": b.ring, "colour": b.colour, "driven": b.driven}
                   for b in pic.bodies],
        "guides": [{"name": g.name, "point": g.point, "ground": g.ground, "colour": g.colour,
                    "lo": g.lo, "hi": g.hi, "through": _list(g.through), "direction": _list(g.direction)}
                   for g in pic.guides],
        "joints": None if space else joints, "space": space, **(_camera() if space else {}),
        "loads": _space_loads(m, sw, pic) if space else _loads(m, sw, pic), "forces": forces(m, sw, pic.names),
        "centres": {} if space else instant_centres(m, sw, pic.names, pic.xy),
    }


def _camera() -> dict:
    """The camera a spatial mechanism opens in (isometric, turning about z; views/html3d.py)."""
    from ..html3d import camera
    c = camera("iso")
    return {"camera": c["camera"], "up": c["up"]}


def forces(m: Mechanism, sw: Sweep, names: list[str]) -> list[dict]:
    """The reported reactions at pins, as arrows per pose ({point, label, vectors}), and the
    reported efforts of angle inputs, as torques per pose ({point, label, values}) at the
    driven link's first point, of parameter inputs that drive an actuator's length, as arrows
    along it at its far end (kind "effort-arrow"). A slide's reaction acts at the slide's point."""
    from ...core.dynamics import _EFFORT, _REACTION
    from ..forces import actuator
    from ..poses import is_spatial
    out, v = [], sw.values
    if is_spatial(m):  # an effort of a joint's angle, at the joint's point (the page turns it)
        for name in v:
            e = _EFFORT.match(name)
            obj, _, attr = e["key"].rpartition(".") if e else ("", "", "")
            if attr == "angle" and obj in names:
                out.append({"kind": "effort", "point": names.index(obj), "label": name, "values": _list(v[name])})
        return out
    for name in v:
        r = _REACTION.match(name)
        if r and r["attr"] == "x" and name[:-1] + "y" in v:
            a = r["a"]
            point = a if r["b"] else next((sl.point for sl in m.slides if sl.name == a), None)
            if point in names:
                xy = np.stack([np.asarray(v[name], float), np.asarray(v[name[:-1] + "y"], float)], axis=1)
                out.append({"kind": "reaction", "point": names.index(point), "label": name[:-2],
                            "vectors": _list(xy)})
        e = _EFFORT.match(name)
        if e and e["key"].endswith(".angle"):
            lk = next((lk for lk in m.links if f"{lk.name}.angle" == e["key"]), None)
            if lk is not None and lk.point_names[0] in names:
                out.append({"kind": "effort", "point": names.index(lk.point_names[0]), "label": name,
                            "values": _list(v[name])})
        inp = next((i for i in m.inputs if e and i.key == e["key"] and i.kind == "parameter"), None)
        ends = actuator(m, inp.target) if inp is not None else None
        if ends is not None and all(p in names for p in ends):
            from ..poses import geometry
            p, q = (geometry(m, sw).point(e) for e in ends)
            with np.errstate(invalid="ignore", divide="ignore"):
                u = (q - p) / np.hypot(*(q - p).T)[:, None]
            out.append({"kind": "effort-arrow", "point": names.index(ends[1]), "label": name,
                        "vectors": _list(np.asarray(v[name], float)[:, None] * u)})
    return out


def _loads(m: Mechanism, sw: Sweep, pic) -> list[dict]:
    """Each force load as {point, vector} and each spring as {points}; torques as {link,
    value} (the page draws an arc about the link's first point); each link's weight as
    {at: per pose [x, y], vector} (views/forces.weights)."""
    from ..forces import weights
    from ..poses import geometry
    out = [{"kind": "weight", "label": w.label, "at": _list(w.at), "vector": _list(w.vec[0])}
           for w in weights(m, geometry(m, sw))]
    for ld in m.loads:
        if ld.kind == "force" and ld.at in pic.names:
            out.append({"kind": "force", "point": pic.names.index(ld.at),
                        "vector": [m.value(ld.value[0]), m.value(ld.value[1])]})
        elif ld.kind == "spring" and all(p in pic.names for p in ld.points):
            out.append({"kind": "spring", "points": [pic.names.index(p) for p in ld.points]})
        elif ld.kind == "torque":
            lk = next((lk for lk in m.links if lk.name == ld.at), None)
            if lk is not None:
                out.append({"kind": "torque", "point": pic.names.index(lk.point_names[0]),
                            "value": m.value(ld.value)})
    return out


def _space_loads(m, sw: Sweep, pic) -> list[dict]:
    """A spatial mechanism's loads in space (the page projects them as it turns): each force as
    {point, vector [x, y, z]}, each torque as {kind "moment", point: the body's first point,
    vector}, each spring as {points}, each body's weight as {at: per pose [x, y, z], vector}."""
    from ..forces import space_weights
    from ..poses import geometry
    out = [{"kind": "weight", "label": w.label, "at": _list(w.at), "vector": _list(w.vec[0])}
           for w in space_weights(m, geometry(m, sw))]
    bodies = {b.name: b for b in m.links}
    for ld in m.loads:
        if ld.kind == "force" and ld.at in pic.names:
            out.append({"kind": "force", "point": pic.names.index(ld.at), "vector": [m.value(c) for c in ld.value]})
        elif ld.kind == "spring" and all(p in pic.names for p in ld.points):
            out.append({"kind": "spring", "points": [pic.names.index(p) for p in ld.points]})
        elif ld.kind == "torque" and ld.at in bodies and bodies[ld.at].point_names[0] in pic.names:
            out.append({"kind": "moment", "point": pic.names.index(bodies[ld.at].point_names[0]),
                        "vector": [m.value(c) for c in ld.value]})
    return out


def instant_centres(m: Mechanism, sw: Sweep, names=None, xy=None) -> dict[str, list]:
    """Link -> per pose its instant centre [x, y] relative to the ground (None where the
    link translates, or the centre is too far to draw, or the pose is not solved); the
    points' positions `xy` (pose, point, 2) in the order of `names` when already at hand."""
    if xy is None:
        from ..poses import geometry
        geo = geometry(m, sw)
        names, xy = geo.names, geo.xy
    far = FAR * m.size()
    out = {}
    for lk in m.links:
        w = sw.values.get(f"{lk.name}.omega")
        p = next((q for q in lk.point_names if f"{q}.vx" in sw.values), None)
        if w is None or p is None:
            continue
        at = xy[:, list(names).index(p)]
        vx, vy = np.asarray(sw.values[f"{p}.vx"], float), np.asarray(sw.values[f"{p}.vy"], float)
        w = np.asarray(w, float)
        with np.errstate(divide="ignore", invalid="ignore"):
            c = np.stack([at[:, 0] - vy / w, at[:, 1] + vx / w], axis=1)
            c[~(np.hypot(*(c - at).T) <= far)] = np.nan  # (NaN compares false: dropped too)
        out[lk.name] = [None if v is None or None in v else v for v in _list(c)]
    return out
