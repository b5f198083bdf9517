"""Declarations of a planar mechanism as immutable plain data (no casadi here).

A mechanism is ground points, links (rigid bodies carrying named points), slides (a point
kept on a line of a body) and inputs (what drives it). A point name shared by two bodies is
a revolute joint. Numbers may be given as a parameter's name, so that sensitivities and
optimisation can refer to them. Angles are radians in Python.

>>> m = Mechanism(
...     parameters={"crank": 1.0},
...     ground={"A": (0, 0), "D": (4, 0)},
...     links=[Link.bar("crank", "A", "B", "crank"), Link.bar("coupler", "B", "C", 3.5),
...            Link.bar("rocker", "D", "C", 3.0)],
...     inputs=[Input.angle("crank")],
...     guess={"C": (3.5, 2.5)})
>>> m.mobility
1
>>> m.with_parameters(crank=1.5).parameter("crank")
1.5
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from ..errors import ModelError
from . import joints as _joints
from .checks import NAME_RULE, RESERVED, _check, _guess_problems, _number_check, _parts, check_guess  # noqa: F401
from .loads import Load
from .lookups import Lookups
from .mobility import (GROUND, Structure, _check_mobility, _structure, counted_freedoms,  # noqa: F401
                       mobility_problem, needs_rank_test, solved_unknowns)
from .parts import Input, Link, Num, Param, Slide, _pair, _table, as_number, as_param, is_number  # noqa: F401

# How a mechanism whose count falls short learns its redundant equations: the rank test of
# kincas.core, handed over by the package's face (`import kincas` calls use_rank_test);
# declarations never import the solver, and the solver never edits the declarations.
_rank_decision = None


# --- the mechanism ---


@dataclass(frozen=True)
class Mechanism(Lookups):
    """A planar mechanism: an immutable value, checked on construction.

    Every problem found is gathered into one `ModelError`. Changing anything returns a new
    mechanism (`with_parameters`, `with_guess`, `dataclasses.replace`).

    Parameters
    ----------
    parameters : dict
        Named numbers that other fields may refer to by name.
    ground : dict
        Ground points: name -> (x, y).
    links, slides, inputs : sequence
        Of `Link`, `Slide` and `Input`.
    guess : dict
        Approximate positions of moving points: they pick the assembly branch.
    gears, racks, cams : sequence
        Of kincas.model.joints.Gear, Rack and Cam.
    gravity : (float, float)
        The acceleration of gravity (for efforts).
    loads : sequence
        Of `Load`.

    Examples
    --------
    >>> m = Mechanism(ground={"A": (0, 0), "D": (4, 0)},
    ...     links=[Link.bar("crank", "A", "B", 1), Link.bar("coupler", "B", "C", 3.5),
    ...            Link.bar("rocker", "D", "C", 3)],
    ...     inputs=[Input.angle("crank")], guess={"C": (3.6, 2.9)})
    >>> m.mobility, m.moving_points
    (1, ('B', 'C'))
    >>> Mechanism(ground={"A": (0, 0)}, links=[Link.bar("crank", "A", "B", 1)])
    Traceback (most recent call last):
    ...
    kincas.errors.ModelError: [inputs]: the mechanism has 1 degree(s) of freedom (1 unknown coordinates, 0 equations) but 0 input(s) drive it; give one input per degree of freedom
    """

    parameters: tuple[tuple[str, float], ...] = ()
    ground: tuple[tuple[str, tuple[Num, Num]], ...] = ()
    links: tuple[Link, ...] = ()
    slides: tuple[Slide, ...] = ()
    inputs: tuple[Input, ...] = ()
    guess: tuple[tuple[str, tuple[Num, Num]], ...] = ()
    gears: tuple = ()  # of kincas.model.joints.Gear
    racks: tuple = ()  # of kincas.model.joints.Rack
    cams: tuple = ()  # of kincas.model.joints.Cam
    gravity: tuple[Num, Num] = (0.0, 0.0)  # acceleration vector, length/time²
    loads: tuple[Load, ...] = ()
    structure: Structure = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        params, bad = [], []
        for k, v in _table(self.parameters, "parameters", "number"):
            v = as_number(v)
            if is_number(v):
                params.append((k, float(v)))
            else:
                bad.append(f"[parameters] {k}: expected a number, got {v!r}")
        if bad:
            raise ModelError(bad)
        object.__setattr__(self, "parameters", tuple(params))
        for f in ("ground", "guess"):
            object.__setattr__(self, f, tuple((k, _pair(v, f"[{f}] {k}")) for k, v in _table(getattr(self, f), f)))
        for f, kind in (("links", Link), ("slides", Slide), ("inputs", Input), ("loads", Load),
                        ("gears", _joints.Gear), ("racks", _joints.Rack), ("cams", _joints.Cam)):
            object.__setattr__(self, f, _parts(getattr(self, f), f, kind))
        object.__setattr__(self, "gravity", _pair(self.gravity, "gravity"))
        problems = _check(self)
        if problems:
            raise ModelError(problems)
        st = _structure([g for g, _ in self.ground], self.links, len(self.slides))
        extra_q, extra_g = _joints.counts(self)  # gears, racks, cams: one freedom each
        object.__setattr__(self, "structure", replace(st, n_unknowns=st.n_unknowns + extra_q,
                                                      n_equations=st.n_equations + extra_g))
        problems = _check_mobility(self)
        if problems:
            raise ModelError(problems)

    # --- lookups ---
    @property
    def redundant(self) -> int:
        """Equations implied by the others (redundant joints): 0 where counting gives as many
        freedoms as inputs; otherwise decided by the constraint Jacobian's rank at generic
        assemblies, whatever the guess (kincas.core.redundant, run once per mechanism), which
        raises `ModelError` if the inputs are genuinely wrong in number.

        Examples
        --------
        >>> m = Mechanism(parameters={"r": 2.0}, ground={"O": (0, 0)},
        ...     links=[Link.bar("crank", "O", "A", "r")], inputs=[Input.angle("crank")])
        >>> m.redundant
        0
        """
        if not needs_rank_test(self):
            return 0
        if _rank_decision is None:  # pragma: no cover - kincas/__init__ hands it over
            raise ModelError("[inputs]: the rank test needs kincas.core (import kincas)")
        return _rank_decision(self)

    def size(self) -> float:
        """The mechanism's characteristic length: the largest distance between two points of
        a link or two ground points (1 if there is none).

        Returns
        -------
        float

        Examples
        --------
        >>> m = Mechanism(parameters={"r": 2.0}, ground={"O": (0, 0)},
        ...     links=[Link.bar("crank", "O", "A", "r")], inputs=[Input.angle("crank")])
        >>> m.size()
        2.0
        """
        pts = [(self.value(x), self.value(y)) for _, (x, y) in self.ground]
        extent = 0.0
        for lk in self.links:
            loc = [(self.value(x), self.value(y)) for _, (x, y) in lk.points]
            extent = max([extent] + [math.dist(a, b) for a in loc for b in loc])
        if pts:
            xs, ys = zip(*pts)
            extent = max(extent, math.hypot(max(xs) - min(xs), max(ys) - min(ys)))
        return extent if extent > 0 else 1.0

    # --- new values ---
    def with_guess(self, **points: tuple[float, float]) -> "Mechanism":
        """A new mechanism whose guess (which picks the assembly branch) is updated.

        Parameters
        ----------
        **points : (float, float)
            Approximate positions of moving points.

        Returns
        -------
        Mechanism

        Examples
        --------
        >>> m = Mechanism(parameters={"r": 2.0}, ground={"O": (0, 0)},
        ...     links=[Link.bar("crank", "O", "A", "r")], inputs=[Input.angle("crank")])
        >>> m.with_guess(A=(0, 2)).guess
        (('A', (0, 2)),)
        """
        return replace(self, guess={**dict(self.guess), **points})


def use_rank_test(decide) -> None:
    """Let `Mechanism.redundant` ask `decide(mechanism) -> int` (the core's rank test, given by
    `import kincas`) where counting cannot tell the redundant equations."""
    global _rank_decision
    _rank_decision = decide
