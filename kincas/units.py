"""Units of quantities as the user wrote them, and numbers as JSON: helpers that the command
line, the writers and any front end share (no solver, no printing).

>>> json_list([1.0, float("nan"), 2.5])
[1.0, None, 2.5]
>>> unit_label({"length": "mm", "angle": "deg", "time": "s"}, None, "rocker.alpha")
'deg/s^2'
"""
from __future__ import annotations

import numpy as np

from .model.mechanism import Param
from .model.names import is_angular, parse_quantity

_ORDER = {"vx": 1, "vy": 1, "omega": 1, "v": 1, "ax": 2, "ay": 2, "alpha": 2, "a": 2,
          "jx": 3, "jy": 3, "jerk": 3}


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
    """A parameter's unit: the scene's angle unit where it gives a slide's angle, else length."""
    angular = mech is not None and any(
        isinstance(sl.angle, Param) and sl.angle.name == name and abs(sl.angle.scale) != 1
        for sl in mech.slides)
    return units.get("angle", "deg") if angular else units.get("length", "")


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
    base = A if is_angular(name, mech) else L  # input keys L.angle included
    order = _ORDER.get(attr, 0)
    return base + ("" if order == 0 else f"/{T}" if order == 1 else f"/{T}^{order}")
