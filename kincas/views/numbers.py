"""Numbers as a reader sees them: values that are zero to the accuracy of the solve are
written as 0, not as rounding noise (`2.44929e-15`, `-0`).

The solver's positions are right to about 1e-12 of the mechanism's size, velocities and
accelerations to rounding of their natural scale, so a value smaller than `EPS` times that
scale (or times the largest value of its column, if larger) carries no information beyond
"zero". The scale of a quantity follows from its kind: the mechanism's size L for positions
and slide coordinates, one radian (in the scene's angle unit) for angles, times the fastest
input's angular rate w for velocities (w^2 + its angular acceleration for accelerations);
a length input's rate counts as rate / L. A sensitivity d(Q)/d(p) has Q's scale over L.

>>> import numpy as np
>>> snap(np.array([50.0, 3.06e-15, -1e-20, -2.0]), scale=50.0).tolist()
[50.0, 0.0, 0.0, -2.0]
"""
from __future__ import annotations

import math

import numpy as np

from ..model.names import is_angle_name

EPS = 1e-11  # relative to a quantity's scale: below it, a value is zero to the solve's accuracy



def snap(v, scale: float) -> np.ndarray:
    """v with every entry within EPS of max(scale, max |v|) set to +0 (NaN kept)."""
    v = np.asarray(v, dtype=float)
    finite = np.isfinite(v)
    top = float(np.abs(v[finite]).max()) if finite.any() else 0.0
    tol = EPS * max(scale, top)
    out = np.where(np.abs(v) <= tol, 0.0, v)
    return out + 0.0  # -0.0 + 0.0 is +0.0


def scale_of(name: str, scene, sweep) -> float:
    """The natural scale of quantity `name` in the scene's units (0 when unknown: then only
    the column's own largest value sets it)."""
    from ..model.names import attr_base, derivative_order, parse_quantity
    try:
        kind, obj, attr = parse_quantity(name)
    except Exception:  # a quantity kind this module does not know
        return 0.0
    if name.startswith("shaking."):  # a force or moment (not a position named x, y, z)
        return 0.0
    L = _size(scene)
    if kind == "sens":
        return scale_of(obj, scene, sweep) / L if L > 0 else 0.0
    order = derivative_order(attr)
    if order is None or order > 2:
        return 0.0
    angular = attr_base(attr) in ("angle", "omega", "alpha")
    base = (180 / math.pi if scene.study.deg else 1.0) if angular else L
    w, a = _input_rates(scene, sweep, L)
    return base * (1.0, w, w * w + a)[order]


def clean(values: dict, scene, sweep) -> dict:
    """Every column of `values` (name -> array, scene units) with its noise set to zero."""
    return {k: snap(v, scale_of(k, scene, sweep)) for k, v in values.items()}


def _size(scene) -> float:
    try:
        return float(scene.mechanism.size())
    except Exception:
        return 0.0


def _input_rates(scene, sweep, L: float) -> tuple[float, float]:
    """The fastest angular rate and acceleration the inputs impose (rad/s, rad/s^2); an input
    that is a length counts as rate / L. At least 1: the scale must not vanish."""
    w = a = 0.0
    for k in sweep.inputs:
        per = 1.0 if is_angle_name(k) else (1.0 / L if L > 0 else 0.0)
        r = np.asarray(sweep.rates.get(k, 0.0), float)
        acc = np.asarray(sweep.accelerations.get(k, 0.0), float)
        w = max(w, float(np.nanmax(np.abs(r))) * per if r.size else 0.0)
        a = max(a, float(np.nanmax(np.abs(acc))) * per if acc.size else 0.0)
    return (w if w > 0 else 1.0), a
