"""The checks of an optimised design along its checking sweep (a part of
`kincas.simultaneous.Problem`): the sweep must reach every optimised pose on the same branch,
and every tracked max()/min() must be the extreme of that sweep too.

>>> Checks.check_path.__doc__.split(":")[0]
'Sweep the optimised design from the first sample through the others'
"""
from __future__ import annotations

import math

import numpy as np

from ..results import wrap_angle

SAME_POSE = 1e-7  # relative: a pose reached by the checking sweep equals the optimised one
EXTREME_MOVED = "the checking sweep reaches"  # the words of that problem, for a new round


class Checks:
    """Methods of the Problem that judge IPOPT's answer by sweeping the optimised design."""

    def check_path(self, mech, Q, p, problems, check_path):
        """Sweep the optimised design from the first sample through the others: it must reach
        each optimised pose without leaving its branch and assemble on the way."""
        if check_path or self.extremes:
            sw, at = self.dense(mech), self.at
        else:
            sw = self.sweep_fn(mech, {k: self.U[:, j] for j, k in enumerate(self.keys)},
                               rates={k: self.Ud[:, j] for j, k in enumerate(self.keys)},
                               accelerations={k: self.Udd[:, j] for j, k in enumerate(self.keys)},
                               report=list(self.used))
            at = np.arange(self.K)
        angle = ~self.model.is_length
        for k in range(self.K):
            if not check_path and not sw.ok[at[k]]:
                continue  # reported by the polishing already
            lost = np.flatnonzero(~sw.ok[at[k - 1] if k else 0:at[k] + 1])
            if len(lost):
                u = self.path[0][(at[k - 1] if k else 0) + lost[0]]
                problems.append(f"the optimised design does not assemble on the way to sample "
                                f"{k + 1} (at input {_short(u)})")
                break
            d = sw.q[at[k]] - Q[k]
            d[angle] = wrap_angle(d[angle])
            if np.any(np.abs(d) > SAME_POSE * self.qs):
                problems.append(f"sample {k + 1}: driven from sample {max(k, 1)}, the optimised "
                                f"design arrives in another assembly (a branch defect)")
                break
        values = {n: sw[n][at] for n in self.used}
        return sw, values

    def check_extremes(self, sw, p, problems):
        """Each tracked max()/min() must be the extreme of the checking sweep as well."""
        out, (U, Ud, Udd) = [], self.path
        ok = np.flatnonzero(sw.ok)
        for e in self.extremes.values():
            fn = e["fn"]
            value = float(self.extreme_values(e, e["q"], [e["u"]], p, e["rate"][0], e["rate"][1])[0])
            u = e["u"] if e["start"] is None else e["start"] + (e["u"] - e["start"]) % (2 * math.pi)
            out.append({"kind": fn, "expr": e["text"], "input": float(u), "value": value})
            if not len(ok):
                continue
            v = self.extreme_values(e, sw.q[ok], U[ok], p, Ud[ok], Udd[ok])
            j = int(np.argmax(v) if fn == "max" else np.argmin(v))
            slack = 1e-6 * max(float(np.ptp(v)), abs(value), 1e-300)
            if (v[j] > value + slack) if fn == "max" else (v[j] < value - slack):
                problems.append(f"{fn}({e['text']}): the optimiser tracked {value:.6g} at input "
                                f"{e['u']:.6g}, but {EXTREME_MOVED} {v[j]:.6g} at "
                                f"input {U[ok[j], 0]:.6g}")
        return out


def _short(v) -> str:
    v = np.atleast_1d(np.asarray(v, float))
    return ", ".join(f"{x:.6g}" for x in v[:4]) + (", ..." if len(v) > 4 else "")
