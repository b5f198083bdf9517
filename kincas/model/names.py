"""Quantity names (`C.x`, `rocker.omega`, `guide.s`, `d(C.y)/d(a)`): parsing and the plain
checks that need no solver.

A quantity is an object and an attribute: a point's coordinates and their rates, a link's
angle and its rates, a slide's coordinate and its rates, or a sensitivity d(Q)/d(p) of one of
them to a parameter. Other quantities (efforts, reactions, instant centres, curvature) are
defined by kincas.core's extensions, which check them against the built model.

>>> parse_quantity("d(C.y)/d(a)"), parse_quantity("rocker.omega")
(('sens', 'C.y', 'a'), ('plain', 'rocker', 'omega'))
"""
from __future__ import annotations

import re

# attribute -> (coordinate, derivative order) of a point; derivative order of a link's angle
# and of a slide's coordinate
POINT_Q = {"x": (0, 0), "y": (1, 0), "vx": (0, 1), "vy": (1, 1), "ax": (0, 2), "ay": (1, 2),
           "jx": (0, 3), "jy": (1, 3)}
LINK_Q = {"angle": 0, "omega": 1, "alpha": 2, "jerk": 3}
SLIDE_Q = {"s": 0, "v": 1, "a": 2, "jerk": 3}
ANGULAR_ATTRS = {"phi", "pressure"}  # cam quantities (kincas/core/joints.py) are angles too
# d(Q)/d(p), where Q may itself hold one level of brackets: d(effort(crank.angle))/d(a1)
SENS = re.compile(r"^d\((?P<q>(?:[^()]|\([^()]*\))+)\)/d\((?P<p>[^()]+)\)$")


def parse_quantity(name: str):
    """('sens', Q, p) for `d(Q)/d(p)`, else (kind, object, attribute) for `OBJ.attr`."""
    m = SENS.match(name)
    if m:
        return ("sens", m["q"], m["p"])
    obj, _, attr = name.rpartition(".")
    return ("plain", obj, attr)


_ORDERS = {**dict.fromkeys(("x", "y", "z", "s", "angle"), 0), **dict.fromkeys(("vx", "vy", "vz", "v", "omega"), 1),
           **dict.fromkeys(("ax", "ay", "az", "a", "alpha"), 2), **dict.fromkeys(("jx", "jy", "jz", "jerk"), 3)}
_ROTATION = re.compile(r"^(q[wxyz]|R[123][123])$")


def attr_base(attr: str) -> str:
    """A quantity attribute without its axis or coordinate number: `omega_x` -> `omega`,
    `alpha2` -> `alpha`, `vz` -> `vz` (2D and 3D names read alike).

    >>> attr_base("omega_x"), attr_base("alpha2"), attr_base("vz")
    ('omega', 'alpha', 'vz')
    """
    return attr.rstrip("0123456789").split("_")[0]


def derivative_order(attr: str) -> int | None:
    """How many times a quantity's attribute is differentiated in time: 0 for a position, an
    angle or a coordinate, 1 for a rate, 2 an acceleration, 3 a jerk; None where it has no
    time unit of its own (a quaternion or rotation-matrix entry, a cam's pressure angle...).
    2D and 3D names alike: `omega_x` and `omega1` are rates as `omega` is.

    >>> [derivative_order(a) for a in ("x", "vz", "omega_x", "alpha2", "jerk", "a1", "R11")]
    [0, 1, 1, 2, 3, 2, None]
    """
    return _ORDERS.get(attr_base(attr))


def is_rotation_entry(attr: str) -> bool:
    """Whether `attr` is an entry of a body's unit quaternion or rotation matrix (no unit).

    >>> is_rotation_entry("qw"), is_rotation_entry("R23"), is_rotation_entry("x")
    (True, True, False)
    """
    return _ROTATION.match(attr) is not None


ANGLE_ATTRS = ("angle", "angle1", "angle2")  # a link's or joint's angle; a universal joint's two


def is_angle_name(name: str) -> bool:
    """Whether an input key or quantity name is an angle itself (not a rate): `crank.angle`,
    `A/B.angle`, a joint's `J.angle`, a universal joint's `J.angle1` and `J.angle2`. The one
    test for converting to degrees, wrapping to a turn and labelling an input's unit (a
    parameter input's key has no dot: a length).

    >>> is_angle_name("crank.angle"), is_angle_name("x.angle1"), is_angle_name("x.omega1"), is_angle_name("l1")
    (True, True, False, False)
    """
    obj, dot, attr = name.rpartition(".")
    return bool(dot) and attr in ANGLE_ATTRS and not name.startswith("d(")


def is_angular(name: str, mech=None) -> bool:
    """Whether a quantity is an angle or an angle's rate (converted to degrees at the edge).
    `S.jerk` of a slide is a length's: give the mechanism to tell it from a link's `L.jerk`.

    >>> is_angular("rocker.omega"), is_angular("C.vx"), is_angular("d(crank.angle)/d(a)")
    (True, False, True)
    """
    kind, a, b = parse_quantity(name)
    if kind == "sens":
        return is_angular(a, mech)
    if getattr(mech, "space", "2d") == "3d":
        from .space_names import ANGULAR, linear_jerks
        if b == "jerk" and a in linear_jerks(mech):
            return False
        return b in LINK_Q or b in ANGULAR
    if b == "jerk" and mech is not None and a in {s.name for s in mech.slides}:
        return False
    if mech is None:  # no mechanism to ask: a 3D rate's name (omega_x) is an angle's too
        from .space_names import ANGULAR
        if b in ANGULAR and not b.startswith("jerk"):
            return True
    return b in LINK_Q or b in ANGULAR_ATTRS


def plain_quantity(m, name: str) -> bool:
    """Whether `name` is a point, link or slide quantity of `m` (or a sensitivity of one to a
    parameter that no input drives): checked from the declarations alone.

    >>> from kincas.model import Mechanism, Link, Input
    >>> m = Mechanism(ground={"A": (0, 0), "D": (4, 0)}, parameters={"c": 3.0},
    ...     links=[Link.bar("crank", "A", "B", 1), Link.bar("coupler", "B", "C", 3.5),
    ...            Link.bar("rocker", "D", "C", "c")], inputs=[Input.angle("crank")])
    >>> [plain_quantity(m, n) for n in ("C.vx", "rocker.alpha", "d(C.y)/d(c)", "E.x", "C.s")]
    [True, True, True, False, False]
    """
    kind, a, b = parse_quantity(name)
    if kind == "sens":
        driven = {i.target for i in m.inputs if i.kind == "parameter"}
        return plain_quantity(m, a) and b in m.param_values and b not in driven
    if getattr(m, "space", "2d") == "3d":
        from .space_names import space_quantity
        return space_quantity(m, a, b)
    points = set(m.ground_points) | {p for lk in m.links for p in lk.point_names}
    return ((b in POINT_Q and a in points) or (b in LINK_Q and a in {lk.name for lk in m.links})
            or (b in SLIDE_Q and a in {s.name for s in m.slides}))


def default_report(m) -> list[str]:
    """What a solve reports when asked for nothing: positions of all moving points and angles
    of all links.

    >>> from kincas.model import Mechanism, Link, Input
    >>> default_report(Mechanism(ground={"O": (0, 0)}, links=[Link.bar("crank", "O", "A", 1)],
    ...                          inputs=[Input.angle("crank")]))
    ['A.x', 'A.y', 'crank.angle']
    """
    if getattr(m, "space", "2d") == "3d":
        from .space_names import space_report
        return space_report(m)
    return [f"{p}.{c}" for p in m.moving_points for c in "xy"] + [f"{lk.name}.angle" for lk in m.links]
