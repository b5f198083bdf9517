"""The study part of a scene: its `[[inputs]]` (values or sweeps, rates, accelerations, jerks,
in radians inside), the memory a sweep needs, and the `[output]` quantities and sensitivities,
checked against the mechanism. A part of the scene reader of kincas/cli/scene.py, which
supplies the problems list (`err`), the numbers (`num`, `value`) and the tables.

>>> from kincas.cli.scene import loads
>>> sc = loads('''
... [ground]
... A = [0, 0]
... [links]
... crank = { points = ["A", "B"], length = 1 }
... [[inputs]]
... angle = "crank"
... sweep = { from = 0, to = 90, steps = 3 }
... rate = 2
... [output]
... report = ["B.x"]
... ''')
>>> sc.study.inputs["crank.angle"].round(4).tolist(), round(sc.study.rates["crank.angle"], 4)
([0.0, 0.7854, 1.5708], 0.0349)
>>> sc.study.report
['B.x']
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..errors import SceneError
from ..model.mechanism import Input
from ..model.names import parse_quantity, plain_quantity

if TYPE_CHECKING:
    from ..model.mechanism import Mechanism


class StudyReader:
    """The `[[inputs]]` and `[output]` sections, read into the scene reader's problems."""

    INPUT_KINDS = ("angle", "parameter", "slide")  # a spatial scene's: joint, parameter, slide

    def make_input(self, kind: str, name: str, where: str):
        """The `Input` an `[[inputs]]` entry names (None, with the problem said, if none)."""
        return Input(kind, name)

    def inputs(self):
        inputs, values, rates, accs, steps, written = [], {}, {}, {}, set(), {}
        kinds_allowed = self.INPUT_KINDS
        for i, t in enumerate(self.array("inputs")):
            where = f"[[inputs]] {i + 1}"
            self.fields(where, t, {*kinds_allowed, "value", "sweep", "rate", "acceleration", "jerk", "free"})
            kinds = [k for k in kinds_allowed if k in t]
            if len(kinds) != 1:
                self.err(f"{where}: give exactly one of {', '.join(kinds_allowed[:-1])} or {kinds_allowed[-1]}")
                continue
            kind = kinds[0]
            if not isinstance(t[kind], str):
                self.err(f"{where}: {kind}: expected a name")
                continue
            inp = self.make_input(kind, t[kind], where)
            if inp is None:
                continue
            where = f"[[inputs]] {inp.key}"
            ang = inp.is_angle
            if ("value" in t) == ("sweep" in t):
                self.err(f"{where}: give either `value` or `sweep`")
                continue
            k = np.pi / 180 if ang and self.deg else 1.0
            if "value" in t:
                vals = np.array([self.value(f"{where}: value", t["value"])])
            else:
                sw = t["sweep"]
                if not isinstance(sw, dict) or not {"from", "to", "steps"} <= set(sw):
                    self.err(f"{where}: sweep: expected {{ from = a, to = b, steps = n }}")
                    continue
                self.fields(f"{where}: sweep", sw, {"from", "to", "steps"})
                n = sw["steps"]
                if isinstance(n, bool) or not isinstance(n, int) or n < 1:
                    self.err(f"{where}: sweep.steps: expected a whole number >= 1, got {n!r}")
                    continue
                if not self.affordable(f"{where}: sweep.steps", n):
                    continue
                a = self.value(f"{where}: sweep.from", sw["from"])
                b = self.value(f"{where}: sweep.to", sw["to"])
                vals = np.linspace(a, b, n)
                steps.add(n)
            if t.get("free", False) not in (True, False):
                self.err(f"{where}: free: expected true or false, got {t['free']!r}")
            elif t.get("free", False):
                self.free.append(inp.key)  # moved by the forces (kincas simulate)
            inputs.append(inp)
            written[inp.key] = vals
            values[inp.key] = vals * k
            rates[inp.key] = self.rate(f"{where}: rate", t.get("rate", 1.0), ang, 1)
            accs[inp.key] = self.rate(f"{where}: acceleration", t.get("acceleration", 0.0), ang, 2)
            self.jerks[inp.key] = self.rate(f"{where}: jerk", t.get("jerk", 0.0), ang, 3)
        if len(steps) > 1:
            self.err(f"[[inputs]] sweep.steps: inputs that sweep advance together, but their "
                     f"steps differ ({sorted(steps)})")
        return inputs, values, rates, accs, written

    def rate(self, where: str, v, angular: bool, order: int) -> float:
        """A rate (order 1), acceleration (2) or jerk (3): a number or a parameter in the
        scene's units, or a number with its own unit ("3000 rpm", "0.2 m/s"), converted
        (kincas.units.parse_rate); radians inside for an angle."""
        from ..units import is_quantity_text, parse_rate
        if is_quantity_text(v):
            u = self.units
            try:
                v = parse_rate(v, u.get("angle", "deg"), u.get("time", "s"), order=order,
                               length_unit=u.get("length", ""), angular=angular, where=where)
            except ValueError as e:
                self.err(str(e))
                return 0.0
        return self.value(where, v, angular)

    def affordable(self, where: str, steps: int) -> bool:
        """Whether a sweep of `steps` poses fits in memory (refused up front, before any array
        is made). The unknowns are counted from the file: at most a point's two coordinates
        per link point, one per slide."""
        from . import bounds
        links = self.doc.get("links", {})
        nq = sum(len(t.get("points", ())) for t in links.values() if isinstance(t, dict)) \
            if isinstance(links, dict) else 4
        nq += len(self.doc.get("slides", [])) if isinstance(self.doc.get("slides"), list) else 0
        out = self.doc.get("output", {})
        report = out.get("report") if isinstance(out, dict) else None
        nrep = len(report) if isinstance(report, list) else 2 * nq
        try:
            bounds.check(where, steps, bounds.per_pose(nq, nrep))
        except ValueError as e:
            self.err(str(e))
            return False
        return True

    def output(self):
        out = self.table("output")
        self.fields("[output]", out, {"report", "sensitivity"})
        report = out.get("report")
        if report is not None and (not isinstance(report, list)
                                   or not all(isinstance(r, str) for r in report)):
            self.err("[output] report: expected a list of quantity names")
            report = []
        sens = []
        if "sensitivity" in out:
            s = out["sensitivity"]
            of, to = (s.get("of"), s.get("to")) if isinstance(s, dict) else (None, None)
            if not (isinstance(of, list) and isinstance(to, list)):
                self.err("[output] sensitivity: expected { of = [\"Q\", ...], to = [\"p\", ...] }")
            else:
                self.fields("[output] sensitivity", s, {"of", "to"})
                sens = [f"d({q})/d({p})" for q in of for p in to]
        return report, sens

    def check_quantities(self, m: Mechanism, report: list[str], sens: list[str]):
        """Point, link and slide quantities are checked from the declarations; only a scene
        that names other quantities (efforts, reactions, curvature, ...) builds the model
        to check them, so reading an ordinary scene runs no CasADi."""
        if all(plain_quantity(m, n) for n in [*report, *sens]):
            return
        from ..core.numeric import model_of
        sym = model_of(m, check=False)
        bad = sym.check_names(report)
        # each `of` name and each `to` name once, under the field they were written in
        of = list(dict.fromkeys(parse_quantity(n)[1] for n in sens))
        bad += sym.check_names(of, "[output] sensitivity: of")
        driven = {i.target for i in m.inputs if i.kind == "parameter"}
        for p in dict.fromkeys(parse_quantity(n)[2] for n in sens):
            if p not in m.param_values:
                bad.append(f"[output] sensitivity: to: unknown parameter {p!r}")
            elif p in driven:
                bad.append(f"[output] sensitivity: to: {p!r} is driven by an input (use its rate instead)")
        if bad:
            raise SceneError(bad)
