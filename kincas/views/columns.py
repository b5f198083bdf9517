"""Names, units and values of a sweep as a reader sees them, in the scene's units: column
headings `name [unit]`, the columns of tables and plots (noise set to zero), the abscissa of
plots against the input. Shared by the CSV, the plots, the HTML page and the command line's
printed tables.

>>> heading("rocker.alpha")
'rocker.alpha [rad/s^2]'
"""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from ..results import Sweep
from ..units import unit_label
from ..model.names import is_angle_name

SHAKING_FORCES = ("shaking.x", "shaking.y", "shaking.z")  # 2D: x, y; 3D: x, y, z
SHAKING_MOMENTS = ("shaking.moment", "shaking.mx", "shaking.my", "shaking.mz")  # 2D; 3D


def quantity_unit(sc, name: str) -> str:
    """The unit of quantity `name` in the scene's units (kincas/units.py)."""
    force = sc.study.units.get("force") or "force"
    return unit_label(sc.study.units, sc.mechanism, name, lambda n, L: _force_unit(n, L, force))


def _force_unit(name: str, L: str, force: str = "force") -> str | None:
    """Units of force quantities and curvature (None for others). A force is written with the
    scene's `units.force` label ("N"), else the word `force` (N with masses in kg and SI
    lengths, or in t and mm); a torque is force·length."""
    from ..core.dynamics import _EFFORT
    m = _EFFORT.match(name)
    if m:
        angular = is_angle_name(m["key"])
        return f"{force}·{L}" if angular and L else force
    if name.startswith(("reaction(", "contact(")) or name in SHAKING_FORCES:
        return force
    if name in SHAKING_MOMENTS:
        return f"{force}·{L}" if L else force
    if name.endswith(".curvature"):
        return f"1/{L}" if L else ""
    return None


def _units_of(scene):
    """What `quantity_unit` needs: the scene, or plain radians/seconds without one."""
    if scene is not None:
        return scene
    return SimpleNamespace(study=SimpleNamespace(units={"length": "", "angle": "rad", "time": "s"}),
                           mechanism=SimpleNamespace(param_values={}))


def heading(name: str, scene=None) -> str:
    """`name [unit]`, units as in the printed table (just `name` when it has none).

    >>> heading("rocker.alpha")
    'rocker.alpha [rad/s^2]'
    """
    u = quantity_unit(_units_of(scene), name)
    return f"{name} [{u}]" if u else name


def user_columns(sweep: Sweep, scene=None, names=None):
    """(inputs, values): name -> array in the scene's units (the sweep's own without one)."""
    inputs = scene.user_inputs(sweep) if scene is not None else dict(sweep.inputs)
    values = scene.user_values(sweep) if scene is not None else dict(sweep.values)
    if scene is not None:  # zero to the solve's accuracy as 0, not as noise
        from .numbers import clean
        values = clean(values, scene, sweep)
    if names is not None:
        missing = [n for n in names if n not in values]
        if missing:
            raise KeyError(f"not reported: {missing} (reported: {list(values)})")
        values = {n: values[n] for n in names}
    return inputs, values


def _abscissa(sweep: Sweep, inputs: dict) -> tuple[str | None, np.ndarray]:
    """The first input that varies (inputs that sweep advance together), else the pose index."""
    for k, v in inputs.items():
        if len(v) > 1 and np.ptp(v) > 0:
            return k, np.asarray(v, float)
    return None, np.arange(len(sweep), dtype=float)
