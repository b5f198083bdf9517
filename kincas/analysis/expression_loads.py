"""A kinematic sweep of a mechanism whose loads are expressions of the state (docs/simulate.md).

A load's component written as an expression stands in the mechanism as a hidden parameter
(kincas/cli/scene_simulate.py). Positions, velocities and accelerations never depend on the
loads, so they are swept as usual whatever the expressions say. A force quantity (an effort,
a reaction, a shaking force, a cam's contact force) that depends on such a parameter is
evaluated at every solved pose with the parameter replaced by its expression at that pose's
state: the chain's q as the sweep solved it, the inputs' values, rates and accelerations as
swept (so an input's angle is the swept one, continuous past a turn). The time `t` is not a
state: a force that needs an expression of `t` is refused, naming the load and its field.
A sensitivity d(Q)/d(p) of such a force would also need the expression's own derivative; it
is refused in the same way rather than given without it.

>>> import kincas
>>> from kincas.core.motion_loads import LoadExpression
>>> m = kincas.Mechanism(ground={"O": (0, 0)}, parameters={"_load1_torque": 0.0},
...     links=[kincas.Link.bar("wheel", "O", "A", 1.0)], inputs=[kincas.Input.angle("wheel")],
...     loads=[kincas.Load.torque("wheel", "_load1_torque")])
>>> e = {"_load1_torque": LoadExpression("3 * wheel.omega", "[[loads]] 1: torque", {})}
>>> sw = sweep_with_expressions(m, {"wheel.angle": [0.0, 1.0]}, e, rates={"wheel.angle": 2.0},
...                             report=["A.x", "effort(wheel.angle)"])
>>> [round(float(v), 12) for v in sw["effort(wheel.angle)"]]   # minus the torque 3 * 2
[-6.0, -6.0]
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ..model.names import parse_quantity
from ..results import Sweep


def sweep_with_expressions(m, inputs, expressions: dict, *, angle: float = 1.0, report=None,
                           **kw) -> Sweep:
    """`kincas.sweep` of `m` whose parameters named in `expressions` (parameter ->
    LoadExpression) are loads written as expressions of the state, in the angle unit `angle`
    (radians per unit: pi/180 for degrees). Other keyword arguments go to `kincas.sweep`.
    ModelError naming the load and its field when a reported force needs the time `t`."""
    from ..core.motion_loads import load_dependence, loaded_function
    from ..core.numeric import model_of
    from .sweeps import sweep
    names = list(report) if report is not None else None
    if not names or not expressions:
        return sweep(m, inputs, report=report, **kw)
    model = model_of(m)
    if model.check_names(names):  # the sweep names the bad quantity as usual
        return sweep(m, inputs, report=report, **kw)
    loaded = load_dependence(model, names, list(expressions))
    for n, on in loaded.items():
        e = expressions[on[0]]
        if parse_quantity(n)[0] == "sens":
            raise ModelError(f"{e.where}: {e.text!r} is an expression of the state: the report's "
                             f"{n!r} would need its derivative, which a sweep does not take "
                             f"(report the force itself)")
        timed = [expressions[h] for h in on if expressions[h].uses_time]
        if timed:
            e = timed[0]
            raise ModelError(f"{e.where}: {e.text!r} depends on the time `t`, which a kinematic "
                             f"sweep does not have, and the report's {n!r} needs it (`kincas "
                             f"simulate` evaluates it over time)")
    sw = sweep(m, inputs, report=[n for n in names if n not in loaded], **kw)
    if not loaded:
        return sw
    got = _evaluate(loaded_function(model, list(loaded), expressions, angle), m, sw, list(loaded))
    sw.values = {n: got[n] if n in got else sw.values[n] for n in names}
    return sw


def _evaluate(f, m, sw, names) -> dict:
    """The force quantities `names` (f: `loaded_function`) at every solved pose of `sw` (NaN
    elsewhere): the model's inputs and parameters in the mechanism's order."""
    n = len(sw.status)
    out = {k: np.full(n, np.nan) for k in names}
    idx = np.flatnonzero(sw.ok & np.all(np.isfinite(sw.q), axis=1))
    if not idx.size:
        return out
    keys = [i.key for i in m.inputs]
    cols = lambda d: np.array([np.broadcast_to(np.asarray(d[k], float), (n,))[idx]  # noqa: E731
                               for k in keys]).reshape(len(keys), idx.size)
    U, Ud, Udd = cols(sw.inputs), cols(sw.rates), cols(sw.accelerations)
    P = np.tile(np.array([float(v) for _, v in m.parameters])[:, None], idx.size)
    vals = np.asarray(f.map(idx.size)(sw.q[idx].T, U, P, Ud, Udd, np.full((1, idx.size), np.nan)))
    for i, k in enumerate(names):
        out[k][idx] = vals[i]
    return out
