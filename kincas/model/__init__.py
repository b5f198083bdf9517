"""Declarations of a mechanism as immutable values: names, structure and mobility checks.

No casadi and no solving here: see `kincas.core` for that.
"""
from .joints import Cam, Circle, Gear, Polar, Rack
from .loads import Inertia, Load
from .mechanism import GROUND, Input, Link, Mechanism, Num, Param, Slide, Structure, as_param

__all__ = ["Cam", "Circle", "Gear", "Polar", "Rack", "Inertia", "Load", "GROUND", "Input", "Link",
           "Mechanism", "Num", "Param", "Slide", "Structure", "as_param"]
