"""Quantity names of a spatial mechanism (`C.z`, `rocker.omega_x`, `A.angle`, `pad.s`),
checked from the declarations alone (no solver), as kincas/model/names.py does in 2D.

>>> joint_attrs(("angle", "s"))["v"], joint_attrs(("s",))["jerk"]
(('s', 1), ('s', 3))
"""
from __future__ import annotations

POINT_Q3 = {f"{p}{c}": (i, k) for k, p in enumerate(("", "v", "a", "j")) for i, c in enumerate("xyz")}
SLIDE_Q = {"s": 0, "v": 1, "a": 2, "jerk": 3}
# a body's orientation and its rates: (kind, index)
BODY_Q = {**{f"q{c}": ("q", i) for i, c in enumerate("wxyz")},
          **{f"R{i + 1}{j + 1}": ("R", 3 * i + j) for i in range(3) for j in range(3)},
          **{f"omega_{c}": ("omega", i) for i, c in enumerate("xyz")},
          **{f"alpha_{c}": ("alpha", i) for i, c in enumerate("xyz")}}
ANGULAR = ({f"omega_{c}" for c in "xyz"} | {f"alpha_{c}" for c in "xyz"}
           | {f"{a}{k}" for a in ("angle", "omega", "alpha", "jerk") for k in "12"})


def joint_attrs(coords) -> dict[str, tuple[str, int]]:
    """attribute -> (coordinate, time derivative) for a joint with these coordinates: an angle
    gives angle/omega/alpha/jerk (angle1 -> angle1/omega1/...), a translation s gives
    s/v/a and jerk (where the joint has no angle), s1 -> s1/v1/a1/jerk1."""
    out = {}
    for c in coords:
        if c.startswith("angle"):
            k = c[5:]
            out.update({f"{a}{k}": (c, o) for o, a in enumerate(("angle", "omega", "alpha", "jerk"))})
        else:
            k = c[1:]
            out.update({f"{a}{k}": (c, o) for o, a in enumerate(("s", "v", "a", "jerk"))
                        if not (a == "jerk" and not k and "angle" in coords)})
    return out


def space_quantity(m, a: str, b: str) -> bool:
    """Whether `a.b` is a point, body, joint or slide quantity of the spatial mechanism m."""
    points = set(m.ground_points) | set(m.moving_points)
    if b in POINT_Q3 and a in points:
        return True
    if b in BODY_Q and a in {x.name for x in m.bodies if not x.two_point}:
        return True
    if a in {j.name for j in m.joints} and b in joint_attrs(m.joint(a).coordinates):
        return True
    return b in SLIDE_Q and a in {s.name for s in m.slides if s.on_line}


def linear_jerks(m) -> set[str]:
    """Objects whose `.jerk` is a length's: line slides, joints whose only coordinate kind is s."""
    out = {s.name for s in m.slides}
    return out | {j.name for j in m.joints if "angle" not in j.coordinates}


def space_report(m) -> list[str]:
    """The default report: every moving point's x, y, z and every joint coordinate."""
    out = [f"{p}.{c}" for p in m.moving_points for c in "xyz"]
    return out + [f"{j.name}.{c}" for j in m.joints for c in j.coordinates]
