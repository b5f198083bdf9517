"""Units of quantities as the user wrote them, and numbers as JSON: helpers that the command
line, the writers and any front end share (no solver, no printing).

>>> json_list([1.0, float("nan"), 2.5])
[1.0, None, 2.5]
>>> unit_label({"length": "mm", "angle": "deg", "time": "s"}, None, "rocker.alpha")
'deg/s^2'
>>> parse_rate("3000 rpm", "deg", "s")
18000.0
"""
from __future__ import annotations

import math
import re

import numpy as np

from .model.mechanism import Param
from .model.names import derivative_order, is_angular, is_rotation_entry, parse_quantity



def json_list(v) -> list:
    """An array as a list for JSON, None where a value is not finite (JSON has no NaN: null
    where a pose was not solved)."""
    v = np.asarray(v, dtype=float)
    out = v.tolist()
    if not np.isfinite(v).all():
        for i in np.flatnonzero(~np.isfinite(v)):
            out[i] = None
    return out


def param_unit(units: dict, mech, name: str) -> str:
    """A parameter's unit: the scene's angle unit where it gives a slide's angle; its mass,
    force labels where it gives a link's mass or inertia, a load's force or torque, a spring's
    stiffness; else length."""
    angular = mech is not None and any(
        isinstance(a, Param) and a.name == name and abs(a.scale) != 1
        for a in (getattr(sl, "angle", None) for sl in mech.slides))  # (a 3D slide has none)
    if angular:
        return units.get("angle", "deg")
    L = units.get("length", "")
    role = _role(mech, name) if mech is not None else None
    if role is None:
        return L
    F, M = units.get("force") or "force", units.get("mass") or "mass"
    return {"mass": M, "inertia": f"{M}·{L}^2" if L else M, "force": F,
            "torque": f"{F}·{L}" if L else F, "stiffness": f"{F}/{L}" if L else F}[role]


def _role(mech, name: str) -> str | None:
    """What a parameter gives in the mechanism's inertia and loads, if anything."""
    def named(v) -> bool:
        return (isinstance(v, str) and v.lstrip("-") == name) or (isinstance(v, Param) and v.name == name)
    for lk in mech.links:
        i = getattr(lk, "inertial", None)
        if i is not None and named(i.mass):
            return "mass"
        if i is not None and named(i.inertia):
            return "inertia"
    for ld in getattr(mech, "loads", ()):
        if ld.kind == "force" and any(named(v) for v in ld.value):
            return "force"
        if ld.kind == "torque" and named(ld.value):
            return "torque"
        if ld.kind == "spring" and named(ld.stiffness):
            return "stiffness"
    return None


def unit_label(units: dict, mech, name: str, extra=None) -> str:
    """The unit of quantity `name` in a scene's `units` ({"length", "angle", "time"}):
    'mm/s' for a point's velocity, 'deg' for an angle, 'mm per a' for a sensitivity.
    `mech` (the mechanism, or None) tells driven parameters and slides' jerks apart;
    `extra(name, length_unit)` gives the unit of other quantities (forces...), or None."""
    L, A, T = units.get("length", ""), units.get("angle", "deg"), units.get("time", "s")
    kind, obj, attr = parse_quantity(name)
    if kind == "sens":  # Q's unit per the parameter's: mm/mm, deg/mm
        uq, up = unit_label(units, mech, obj, extra), param_unit(units, mech, attr)
        return f"{uq or '1'}/{up}" if up else (f"{uq} per {attr}" if uq else "")
    if name == "t" and (mech is None or name not in mech.param_values):  # a simulation's time
        return T
    if mech is not None and name in mech.param_values:  # a driven parameter: a length, or an angle
        return param_unit(units, mech, name)
    other = extra(name, L) if extra is not None else None
    if other is not None:
        return other
    if kind != "sens" and attr is not None and is_rotation_entry(attr):
        return ""  # a quaternion's or rotation matrix's entry is a pure number
    base = A if is_angular(name, mech) else L  # input keys L.angle included
    order = derivative_order(attr) or 0 if attr else 0
    return base + ("" if order == 0 else f"/{T}" if order == 1 else f"/{T}^{order}")


# --- rates written with their own unit: "3000 rpm", "50 rad/s", "10 deg/s^2" ---

# Each unit's size in SI (radians, seconds, metres): a value v in unit u is v * size(u) in SI,
# and v * size(u) / size(scene's unit) in the scene's.
ANGLES = {"rad": 1.0, "deg": math.pi / 180, "°": math.pi / 180, "rev": 2 * math.pi,
          "turn": 2 * math.pi, "grad": math.pi / 200}
TIMES = {"s": 1.0, "ms": 1e-3, "min": 60.0, "h": 3600.0}
LENGTHS = {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "dm": 0.1, "km": 1e3, "um": 1e-6, "µm": 1e-6,
           "in": 0.0254, "ft": 0.3048}
PER_MINUTE = {"rpm": ("rev", "min"), "rps": ("rev", "s")}  # a turn rate as one word
_NUMBER = re.compile(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*?)\s*$")
_KIND = {1: "a rate", 2: "an acceleration", 3: "a jerk"}


def is_quantity_text(v) -> bool:
    """Whether `v` is a number written with a unit ("3000 rpm"), not a parameter's name
    (names cannot start with a digit or a sign)."""
    return isinstance(v, str) and _NUMBER.match(v) is not None and bool(_NUMBER.match(v)[2])


def parse_rate(text: str, angle_unit: str = "deg", time_unit: str = "s", *, order: int = 1,
               length_unit: str | None = None, angular: bool = True, where: str = "rate") -> float:
    """A rate (or, `order` 2 and 3, an acceleration or a jerk) written with its own unit,
    converted to the scene's units: `angle_unit`/`time_unit`^order for an angular input,
    `length_unit`/`time_unit`^order for a length (`angular=False`).

    Angles: rad, deg (or °), rev (or turn), grad; `rpm` and `rps` are rev/min and rev/s;
    times: s, ms, min, h; lengths: m, mm, cm, dm, km, um, in, ft. Powers as `s^2`, `s²`
    or `s2`. A bare number is taken in the scene's units.

    Parameters
    ----------
    text : str
        "3000 rpm", "50 rad/s", "10 deg/s^2", "0.2 m/s", "120 rpm/s".
    angle_unit, time_unit : str
        The scene's units ("deg" or "rad"; "s", "ms", "min" or "h").
    order : int
        1 for a rate, 2 for an acceleration, 3 for a jerk.
    length_unit : str, optional
        The scene's length unit, for a length's rate.
    angular : bool
        Whether the quantity is an angle's (else a length's).
    where : str
        The field, named in the error ("[[inputs]] crank.angle: rate").

    Returns
    -------
    float
        The value in the scene's units.

    Raises
    ------
    ValueError
        One line naming `where`, the text and what was expected.

    Examples
    --------
    >>> parse_rate("50 rad/s", "deg", "s") == 50 * 180 / math.pi
    True
    >>> parse_rate("10 deg/s^2", "rad", "s", order=2) == math.radians(10)
    True
    >>> parse_rate("0.2 m/s", length_unit="mm", angular=False)
    200.0
    """
    what = "angle" if angular else "length"
    want = f"{'deg' if angular else (length_unit or 'mm')}/s" + ("" if order == 1 else f"^{order}")
    example = f"such as '50 {want}'" + (" or '3000 rpm'" if angular and order == 1 else "")

    article = lambda w: "an" if w == "angle" else "a"  # noqa: E731
    per = lambda k: "per s" if k == 1 else f"per s^{k}"  # noqa: E731

    def fail(why: str):
        raise ValueError(f"{where}: {text!r}: {why} (expected {_KIND.get(order, 'a rate')} of "
                         f"{article(what)} {what} {example})")
    m = _NUMBER.match(str(text)) if isinstance(text, str) else None
    if m is None:
        fail("not a number with a unit")
    value, unit = float(m[1]), m[2].replace(" ", "").replace("²", "^2").replace("³", "^3")
    if not unit:
        return value
    head, *under = unit.split("/")
    power = 0
    size = 1.0
    if head in PER_MINUTE:
        a, t = PER_MINUTE[head]
        top, size, power = "angle", ANGLES[a] / TIMES[t], 1
    elif head in ANGLES:
        top, size = "angle", ANGLES[head]
    elif head in LENGTHS:
        top, size = "length", LENGTHS[head]
    else:
        fail(f"unknown unit {head!r}")
    for t in under:
        name, _, p = t.partition("^")
        if not _:
            name, p = re.match(r"(.*?)(\d*)$", t).groups()
        if name not in TIMES or (p and not p.isdigit()):
            fail(f"unknown unit {t!r} (times: {', '.join(TIMES)})")
        k = int(p or 1)
        size, power = size / TIMES[name] ** k, power + k
    if top != what:
        fail(f"{unit} is the rate of {article(top)} {top}, not of {article(what)} {what}")
    if power != order:
        fail(f"{unit} is {per(power)}, not {per(order)}")
    if time_unit not in TIMES:
        fail(f"the scene's time unit {time_unit!r} is not one of {', '.join(TIMES)}")
    if angular:
        if angle_unit not in ANGLES:
            fail(f"the scene's angle unit {angle_unit!r} is not one of {', '.join(ANGLES)}")
        scene = ANGLES[angle_unit]
    else:
        if not length_unit or length_unit not in LENGTHS:
            fail(f"the scene's length unit {length_unit!r} is not one of {', '.join(LENGTHS)}: "
                 "write the number in the scene's units")
        scene = LENGTHS[length_unit]
    return value * size * TIMES[time_unit] ** order / scene
