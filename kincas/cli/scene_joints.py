"""Reading `[[gears]]`, `[[racks]]` and `[[cams]]` of a scene (docs/scene-format.md).

Called by the scene reader (`kincas.cli.scene._Reader`), whose `num`, `value`, `xy`,
`fields` and `err` gather every problem naming its section and field; angles are read in
the scene's unit and kept in radians.

>>> from kincas.cli.scene import loads
>>> sc = loads('''
... [ground]
... A = [0, 0]
... B = [45, 0]
... [links]
... g1 = { points = ["A", "P"], length = 30 }
... g2 = { points = ["B", "Q"], length = 15 }
... [[gears]]
... links = ["g1", "g2"]
... radii = [30, 15]
... [[inputs]]
... angle = "g1"
... value = 30
... [guess]
... P = [30, 0]
... ''')
>>> round(float(sc.user_values(sc.run())["g2.angle"][0]), 9)
-60.0
"""
from __future__ import annotations

import math

from ..model.joints import Cam, Circle, Gear, Polar, Rack


def read(r) -> tuple[list[Gear], list[Rack], list[Cam]]:
    """The gears, racks and cams of the scene read by `r` (a scene `_Reader`)."""
    gears = [g for i, t in enumerate(r.array("gears")) if (g := _gear(r, i, t))]
    racks = [x for i, t in enumerate(r.array("racks")) if (x := _rack(r, i, t))]
    cams = [c for i, t in enumerate(r.array("cams")) if (c := _cam(r, i, t))]
    return gears, racks, cams


def _names(r, where, t, key, n):
    v = t.get(key)
    if not isinstance(v, list) or len(v) != n or not all(isinstance(x, str) for x in v):
        r.err(f"{where}: {key}: expected {n} names")
        return None
    return v


def _flag(r, where, t, key):
    v = t.get(key, False)
    if not isinstance(v, bool):
        r.err(f"{where}: {key}: expected true or false")
        return False
    return v


def _gear(r, i, t):
    where = f"[[gears]] {t.get('name', i + 1)}"
    r.fields(where, t, {"name", "links", "radii", "internal", "belt", "carrier", "phase"})
    links = _names(r, where, t, "links", 2)
    radii = t.get("radii")
    if not isinstance(radii, list) or len(radii) != 2:
        r.err(f"{where}: radii: expected [r1, r2]")
        radii = None
    carrier = t.get("carrier", "ground")
    if not isinstance(carrier, str):
        r.err(f"{where}: carrier: expected a body's name")
    internal, belt = _flag(r, where, t, "internal"), _flag(r, where, t, "belt")
    phase = r.num(f"{where}: phase", t.get("phase", 0.0), angle=True)
    if links is None or radii is None or not isinstance(carrier, str):
        return None
    return Gear(tuple(links), tuple(r.num(f"{where}: radii", v) for v in radii), internal=internal,
                belt=belt, carrier=carrier, phase=phase, name=str(t.get("name", "")))


def _rack(r, i, t):
    where = f"[[racks]] {t.get('name', i + 1)}"
    r.fields(where, t, {"name", "pinion", "radius", "slide", "teeth", "offset"})
    for k in ("pinion", "slide"):
        if not isinstance(t.get(k), str):
            r.err(f"{where}: {k}: missing or not a name")
            return None
    if "radius" not in t:
        r.err(f"{where}: radius: missing")
        return None
    teeth = t.get("teeth", "right")
    if teeth not in ("right", "left"):
        r.err(f"{where}: teeth: {teeth!r} is neither \"right\" nor \"left\"")
    return Rack(t["pinion"], r.num(f"{where}: radius", t["radius"]), t["slide"], teeth=str(teeth),
                offset=r.num(f"{where}: offset", t.get("offset", 0.0)), name=str(t.get("name", "")))


def _cam(r, i, t):
    name = t.get("name", f"cam{i + 1}")
    where = f"[[cams]] {name}"
    r.fields(where, t, {"name", "body", "profile", "follower", "roller", "flat"})
    if not isinstance(name, str):
        r.err(f"{where}: name: expected a string")
        return None
    if not isinstance(t.get("body"), str):
        r.err(f"{where}: body: missing or not a name (a link or \"ground\")")
        return None
    profile = _profile(r, where, t.get("profile"))
    follower = _follower(r, where, t)
    if profile is None or follower is None:
        return None
    return Cam(name, t["body"], profile, **follower)


def _profile(r, where, p):
    if not isinstance(p, dict) or len(p) != 1 or not set(p) <= {"circle", "polar"}:
        r.err(f"{where}: profile: expected {{ circle = {{ center = [x, y], radius = r }} }} "
              f"or {{ polar = {{ angles = [...], radii = [...] }} }}")
        return None
    (kind, spec), = p.items()
    w = f"{where}: profile.{kind}"
    if not isinstance(spec, dict):
        r.err(f"{w}: expected a table")
        return None
    if kind == "circle":
        r.fields(w, spec, {"center", "radius"})
        if "radius" not in spec:
            r.err(f"{w}.radius: missing")
            return None
        return Circle(r.xy(f"{w}.center", spec.get("center", [0.0, 0.0])), r.num(f"{w}.radius", spec["radius"]))
    r.fields(w, spec, {"angles", "radii"})
    ang, rad = spec.get("angles"), spec.get("radii")
    if not isinstance(ang, list) or not isinstance(rad, list):
        r.err(f"{w}: expected angles = [...] and radii = [...] (lists of the same length)")
        return None
    k = math.pi / 180 if r.deg else 1.0
    return Polar(tuple(r.value(f"{w}.angles", a) * k for a in ang),
                 tuple(r.num(f"{w}.radii", v) for v in rad))


def _follower(r, where, t):
    """`follower = "F"` (knife edge), `roller = { center, radius }` or `flat = "link"`; the
    same three may also be written inside `follower = { ... }`."""
    spec = dict(t)
    if isinstance(t.get("follower"), dict):
        spec = {k: v for k, v in t.items() if k != "follower"}
        inner = t["follower"]
        r.fields(f"{where}: follower", inner, {"knife", "roller", "flat"})
        spec.update({("follower" if k == "knife" else k): v for k, v in inner.items()})
    given = [k for k in ("follower", "roller", "flat") if k in spec]
    if len(given) != 1:
        r.err(f"{where}: follower: give exactly one of follower = \"POINT\" (knife edge), "
              f"roller = {{ center = \"POINT\", radius = r }} or flat = \"LINK\"")
        return None
    kind, v = given[0], spec[given[0]]
    if kind == "roller":
        if not isinstance(v, dict) or not isinstance(v.get("center"), str) or "radius" not in v:
            r.err(f"{where}: roller: expected {{ center = \"POINT\", radius = r }}")
            return None
        r.fields(f"{where}: roller", v, {"center", "radius"})
        return {"roller": v["center"], "roller_radius": r.num(f"{where}: roller.radius", v["radius"])}
    if not isinstance(v, str):
        r.err(f"{where}: {kind}: expected a name")
        return None
    return {"knife": v} if kind == "follower" else {"flat": v}
