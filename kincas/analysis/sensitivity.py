"""Exact sensitivities of quantities to parameters, gathered as arrays.

The derivative of a quantity Q with respect to a parameter p at a solved pose follows from
the implicit function theorem on the loop-closure residual g(q, u, p) = 0 at fixed inputs u:

    g_q dq/dp + g_p = 0   =>   dq/dp = -g_q^-1 g_p,    dQ/dp = Q_q dq/dp + Q_p,

with the same Jacobian g_q that Newton's method uses, so no difference quotient is involved.
Velocity and acceleration quantities are differentiated through their own expressions in
(q, u, p, u', u'') (see `kincas.symbolic`). This module only names and arranges them:
`sensitivities(m, inputs, of, to)` returns an array (poses x quantities x parameters).

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(parameters={"a": 1.0}, ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", "a"), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
>>> s = sensitivities(m, {"crank.angle": np.array([0.0, np.pi])}, of=["C.x"], to=["a"])
>>> s.matrix.shape, [round(float(v), 6) for v in s["C.x", "a"]]
((2, 1, 1), [0.680556, -0.565])

(With B and C on the ground line, C.x = +-a + (3.5^2 - 3^2 + r^2) / (2 r), r = 4 -+ a, so
dC.x/da = 1 - 1/2 + 3.25 / 18 at 0 and -1 + 1/2 - 3.25 / 50 at pi.)
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..model.mechanism import Mechanism
from ..result_base import Result
from ..results import Sweep


def names(of: list[str], to: list[str]) -> list[str]:
    """The quantity names `d(Q)/d(p)` for every Q in `of` and p in `to`, Q-major.

    >>> names(["C.x", "C.y"], ["a", "b"])
    ['d(C.x)/d(a)', 'd(C.x)/d(b)', 'd(C.y)/d(a)', 'd(C.y)/d(b)']
    """
    return [f"d({q})/d({p})" for q in of for p in to]


@dataclass(repr=False)
class Sensitivities(Result):
    """d(Q)/d(p) at every pose: `matrix[i, j, k]` is d(of[j])/d(to[k]) at pose i (NaN where the
    pose was not solved); `s["C.x", "a"]` is one column over the poses; `sweep` holds the
    solved poses and the quantities `of` themselves."""

    of: list[str]
    to: list[str]
    matrix: np.ndarray
    sweep: Sweep

    def __getitem__(self, key) -> np.ndarray:
        """`s["C.x", "a"]` or `s["d(C.x)/d(a)"]`: d(C.x)/d(a) over the poses."""
        if isinstance(key, str):
            from ..model.names import parse_quantity
            kind, q, p = parse_quantity(key)
            if kind != "sens" or q not in self.of or p not in self.to:
                raise KeyError(f"{key!r} is not one of these sensitivities ({', '.join(self)})")
        else:
            q, p = key
        return self.matrix[:, self.of.index(q), self.to.index(p)]

    def __iter__(self):
        return iter(names(self.of, self.to))

    def __contains__(self, key) -> bool:
        return key in names(self.of, self.to) or (isinstance(key, tuple) and len(key) == 2
                                                 and key[0] in self.of and key[1] in self.to)

    def summary(self) -> str:
        """How many quantities, parameters and poses; the first names (the `repr`'s body)."""
        return (f"{len(self.of)} quantities x {len(self.to)} parameters over "
                f"{self.matrix.shape[0]} poses: {', '.join(list(self)[:3])}{' ...' if len(list(self)) > 3 else ''}")

    def to_pandas(self, length: str = "", angle: str = "rad"):
        """A DataFrame per pose (inputs as index) with a column `d(Q)/d(p)` per pair, then
        `status` and `flag`; units in `df.attrs["units"]` (`length` names lengths')."""
        from ..frames import sensitivities_to_pandas, in_angle
        return in_angle(sensitivities_to_pandas(self, length), angle)

    def to_xarray(self, length: str = "", angle: str = "rad"):
        """A Dataset along `pose`, a variable `d(Q)/d(p)` per pair, as `Sweep.to_xarray`."""
        from ..frames import sensitivities_to_xarray, in_angle
        return in_angle(sensitivities_to_xarray(self, length), angle)

    @property
    def ok(self) -> np.ndarray:
        """Boolean mask of the solved poses."""
        return self.sweep.ok


def sensitivities(m: Mechanism, inputs, of: list[str], to: list[str] | None = None,
                  **sweep_kw) -> Sensitivities:
    """Sweep `m` over `inputs` and return every d(Q)/d(p), Q in `of`, p in `to` (default:
    every parameter that no input drives). `sweep_kw` goes to `kincas.sweep` (rates, ...);
    the quantities `of` are reported too, so `result.sweep[Q]` holds their values.

    Parameters
    ----------
    m : Mechanism
    inputs : dict
        Input key -> values, as for `kincas.sweep`.
    of : list of str
        Quantity names.
    to : list of str, optional
        Parameter names (default: every parameter that no input drives).
    **sweep_kw
        Passed to `kincas.sweep`.

    Returns
    -------
    Sensitivities

    Examples
    --------
    With B and C on the ground line, C.x = a + (3.5^2 - 3^2 + r^2) / (2 r), r = 4 - a, so
    dC.x/da = 1 - 1/2 + 3.25 / 18 at crank angle 0:

    >>> import numpy as np, kincas
    >>> m = kincas.Mechanism(parameters={"a": 1.0}, ground={"A": (0, 0), "D": (4, 0)},
    ...     links=[kincas.Link.bar("crank", "A", "B", "a"), kincas.Link.bar("coupler", "B", "C", 3.5),
    ...            kincas.Link.bar("rocker", "D", "C", 3)],
    ...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
    >>> s = sensitivities(m, {"crank.angle": [0.0]}, of=["C.x"])
    >>> s.to, round(float(s["C.x", "a"][0]), 12), round(1 - 1 / 2 + 3.25 / 18, 12)
    (['a'], 0.680555555556, 0.680555555556)
    """
    from .sweeps import sweep  # casadi is imported only when something is solved

    driven = {i.target for i in m.inputs if i.kind == "parameter"}
    to = [p for p in m.param_values if p not in driven] if to is None else list(to)
    bad = [f"sensitivity: to: unknown parameter {p!r}" for p in to if p not in m.param_values]
    bad += [f"sensitivity: to: {p!r} is driven by an input" for p in to if p in driven]
    if bad:
        raise ModelError(bad)
    of = list(of)
    report = list(dict.fromkeys(of + list(sweep_kw.pop("report", []) or [])))
    sw = sweep(m, inputs, report=report + names(of, to), **sweep_kw)
    mat = np.stack([np.stack([sw[f"d({q})/d({p})"] for p in to], axis=-1) for q in of], axis=1)
    return Sensitivities(of=of, to=to, matrix=mat.reshape(len(sw), len(of), len(to)), sweep=sw)
