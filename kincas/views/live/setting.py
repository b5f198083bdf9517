"""What the live page edits, shaped as a scene (kincas/cli/scene.py's `Scene` is one), made from
a bare mechanism for `kincas.widget`.

>>> import kincas
>>> m = kincas.Mechanism(ground={"O": (0, 0)}, links=[kincas.Link.bar("crank", "O", "A", 1)],
...     inputs=[kincas.Input.angle("crank")])
>>> s = Setting.of(m); len(s.study.inputs["crank.angle"]), s.quantities
(361, ['A.x', 'A.y', 'crank.angle'])
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...model.mechanism import Mechanism
from ...results import Sweep

STEPS = 361  # poses of the default sweep of an angle input (one per degree)


@dataclass
class Setting:
    """What `Live` edits, shaped as a scene (kincas/cli/scene.py's `Scene` is one): the
    `mechanism`, a `study` (inputs in radians, rates, accelerations, report, units, title,
    ranges) and the scene's unit conversions. `Setting.of(m)` makes one from a bare
    mechanism: angle inputs turn a full circle, other inputs stay at their first values."""

    mechanism: Mechanism
    study: object

    @classmethod
    def of(cls, m: Mechanism, inputs=None, report=None) -> "Setting":
        from types import SimpleNamespace
        from ..notebook import first_inputs
        from ...model.names import default_report
        first = first_inputs(m)
        if inputs is None:
            inputs, swept = {}, False
            for inp in m.inputs:
                v = first[inp.key]
                turns = inp.kind == "angle" or (inp.kind == "joint" and inp.key.endswith(".angle"))
                if turns and not swept:
                    inputs[inp.key], swept = v + np.linspace(0, 2 * np.pi, STEPS), True
                else:
                    inputs[inp.key] = np.array([v])
            n = max((len(v) for v in inputs.values()), default=1)
            inputs = {k: np.resize(v, n) if len(v) == 1 else v for k, v in inputs.items()}
        inputs = {k: np.atleast_1d(np.asarray(v, float)) for k, v in inputs.items()}
        study = SimpleNamespace(title="", units={"length": "", "angle": "rad", "time": "s"},
                                inputs=inputs, rates={}, accelerations={}, ranges={},
                                report=list(report) if report is not None else default_report(m),
                                sensitivity=[], deg=False)
        return cls(m, study)

    @property
    def quantities(self) -> list[str]:
        return list(self.study.report)

    def user_inputs(self, s: Sweep) -> dict:
        return dict(s.inputs)

    def user_values(self, s: Sweep) -> dict:
        return dict(s.values)
