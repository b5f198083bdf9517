"""Scene reading for motion under forces: `free = true` inputs, loads written as expressions
of the state and time, `[data]` lists and the `[simulate]` section (docs/simulate.md).

A load's component that is a string and not a parameter's name (nor `-name`) is an
expression: it becomes a hidden parameter of the mechanism (`_load1_torque`,
`_load2_force_y`), whose value at every instant of a simulation is the expression's
(kincas/core/motion_loads.py). `kincas simulate` and `kincas flywheel` evaluate them over
time; `kincas solve` at each pose's state where a reported force needs them
(kincas/analysis/expression_loads.py), refusing one that needs the time `t`.

>>> from kincas.cli.scene import loads
>>> sc = loads('''
... [parameters]
... T0 = 2
... [ground]
... O = [0, 0]
... [links]
... wheel = { points = ["O", "A"], length = 1, inertia = 0.5 }
... [[loads]]
... link = "wheel"
... torque = "T0 * (1 - wheel.omega / 100)"
... [[inputs]]
... angle = "wheel"
... free = true
... value = 0
... rate = 0
... [simulate]
... duration = 1.0
... steps = 11
... ''')
>>> sc.study.simulation["expressions"], sc.study.simulation["free"]
({'_load1_torque': 'T0 * (1 - wheel.omega / 100)'}, ['wheel.angle'])
"""
from __future__ import annotations

import math

from ..errors import SceneError

FIELDS = {"duration", "steps", "flywheel", "tolerance"}


def is_expression(reader, v) -> bool:
    """A string that is not a parameter's name (nor minus one): an expression."""
    if not isinstance(v, str):
        return False
    name = v[1:] if v.startswith("-") else v
    return name not in reader.params and name not in reader.bad_params


def component(reader, where: str, index: int, field: str, v):
    """A load's number, parameter, or expression (a hidden parameter standing for it):
    `field` is "torque", "force_x" or "force_y"."""
    if not is_expression(reader, v):
        return reader.num(f"{where}: {field.split('_')[0]}", v)
    name = f"_load{index}_{field}"
    reader.params[name] = 0.0
    reader.expressions[name] = (v, f"{where}: {field.replace('_', ' ')}")
    return name


def read(reader, doc: dict, mechanism_links, inputs) -> dict:
    """The simulation's settings: free inputs, expressions, data, duration, steps, flywheel,
    tolerance (each problem through the reader, naming the section and the field)."""
    from ..core.motion_loads import LoadExpression, data_lists
    from ..errors import ModelError
    out = {"free": list(reader.free), "expressions": {k: t for k, (t, _) in reader.expressions.items()},
           "where": {k: w for k, (_, w) in reader.expressions.items()},
           "data": {}, "duration": None, "steps": None, "flywheel": None, "tolerance": None}
    try:
        out["data"] = data_lists(doc.get("data", {}))
    except ModelError as e:
        reader.err(str(e))
    for name, (text, where) in reader.expressions.items():
        try:
            LoadExpression(text, where, out["data"])
        except ModelError as e:
            reader.err(str(e))
    sim = doc.get("simulate")
    if sim is None:
        return out
    if not isinstance(sim, dict):
        reader.err("[simulate]: expected a table")
        return out
    reader.fields("[simulate]", sim, FIELDS)
    d = sim.get("duration")
    if isinstance(d, str):
        d = _time(reader, d)
    if d is None:
        reader.err("[simulate] duration: missing (the time to integrate)")
    elif isinstance(d, bool) or not isinstance(d, (int, float)) or not math.isfinite(d) or d <= 0:
        reader.err(f"[simulate] duration: expected a number > 0 (or a time such as '2 s'), got {d!r}")
    else:
        out["duration"] = float(d)
    n = sim.get("steps", 101)
    if isinstance(n, bool) or not isinstance(n, int) or n < 2:
        reader.err(f"[simulate] steps: expected a whole number >= 2, got {n!r}")
    elif reader.affordable("[simulate] steps", n):
        out["steps"] = n
    tol = sim.get("tolerance")
    if tol is not None:
        if isinstance(tol, bool) or not isinstance(tol, (int, float)) or not 0 < tol < 1e-2:
            reader.err(f"[simulate] tolerance: expected a number in (0, 0.01), got {tol!r}")
        else:
            out["tolerance"] = float(tol)
    fw = sim.get("flywheel")
    if fw is not None:
        if not isinstance(fw, dict) or set(fw) != {"link", "inertia"}:
            reader.err('[simulate] flywheel: expected { link = "NAME", inertia = J }')
        elif fw["link"] not in mechanism_links:
            reader.err(f"[simulate] flywheel: link: unknown link {fw['link']!r}")
        else:
            J = reader.value("[simulate] flywheel: inertia", fw["inertia"])
            if J < 0:
                reader.err(f"[simulate] flywheel: inertia: must not be negative, got {J}")
            out["flywheel"] = (fw["link"], J)
    return out


def _time(reader, text: str):
    """`duration = "500 ms"`: a time with its own unit (s, ms, min, h), in the scene's time
    unit; the text itself (refused below, naming the field) when it does not read."""
    from ..units import TIMES
    num, _, unit = text.strip().partition(" ")
    scene = reader.units.get("time", "s")
    try:
        v = float(num)
    except ValueError:
        return text
    if unit.strip() not in TIMES or scene not in TIMES:
        reader.err(f"[simulate] duration: {text!r}: expected a time such as '2 s' or '500 ms' "
                   f"(units {sorted(TIMES)})")
        return 1.0
    return v * TIMES[unit.strip()] / TIMES[scene]


def arguments_of(sc) -> dict:
    """The keyword arguments of `kincas.simulate` that the scene gives (radians inside)."""
    sim = sc.study.simulation
    if not sim.get("free"):
        raise SceneError("[[inputs]]: no input is `free = true` (kincas simulate moves the free "
                         "inputs under the loads)")
    if sim.get("duration") is None:
        raise SceneError("[simulate]: missing (duration = T, steps = N)")
    st = sc.study
    expressions = sc.load_expressions()  # each named where the scene wrote it
    kw = dict(free=sim["free"], initial={k: float(v[0]) for k, v in st.inputs.items()},
              rates=dict(st.rates), accelerations=dict(st.accelerations),
              expressions=expressions, data=sim["data"], flywheel=sim["flywheel"],
              angle=math.pi / 180 if st.deg else 1.0)
    if sim.get("tolerance"):
        kw["tolerance"] = sim["tolerance"]
    return kw
