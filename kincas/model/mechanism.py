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
import re
from dataclasses import dataclass, field, replace
from typing import Iterable, Mapping

from ..errors import ModelError
from . import joints as _joints
from .loads import Load, check_loads
from .parts import Input, Link, Num, Param, Slide, _pair, _table, as_number, as_param, is_number  # noqa: F401

GROUND = "ground"
# How a mechanism whose count falls short learns its redundant equations: the rank test of
# kincas.core, handed over by the package's face (`import kincas` calls use_rank_test);
# declarations never import the solver, and the solver never edits the declarations.
_rank_decision = None
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_\-]*$")
NAME_RULE = "a name starts with an ASCII letter or _, then ASCII letters, digits, _ or -"
RESERVED = (f'"{GROUND}" is reserved: it names the fixed frame (a slide\'s `along = "{GROUND}"`, '
            f'an angle relative to it, "crank/{GROUND}"); choose another name')


# --- the structure of the chain: a spanning tree of revolute joints ---


@dataclass(frozen=True)
class Structure:
    """How the loop-closure equations are laid out (derived from names only).

    Links are placed from the ground outwards: a link that shares a point with what is
    already placed hangs on that point and needs only its angle as an unknown; a link with
    no such point floats (x, y, angle). Every other shared point closes a loop: two
    equations saying that the two bodies put the point at the same place. Each slide adds
    one equation (the point's distance from the line is zero).
    """

    order: tuple[tuple[str, str | None], ...]  # (link, point it hangs on, or None: floating)
    owner: tuple[tuple[str, str], ...]  # point -> body whose frame defines it
    closures: tuple[tuple[str, str], ...]  # (point, link): that link's copy must meet the owner's
    n_unknowns: int
    n_equations: int

    @property
    def mobility(self) -> int:
        return self.n_unknowns - self.n_equations


def _structure(ground: Iterable[str], links: tuple[Link, ...], n_slides: int) -> Structure:
    owner = {g: GROUND for g in ground}
    order, closures, remaining = [], [], list(links)
    n_unknowns = 0

    def place(link: Link, at: str | None):
        nonlocal n_unknowns
        order.append((link.name, at))
        n_unknowns += 1 if at is not None else 3
        for p in link.point_names:
            if p == at:
                continue
            if p in owner:
                closures.append((p, link.name))
            else:
                owner[p] = link.name
        remaining.remove(link)

    # Breadth-first from the ground keeps chains short, so each loop closes near its root.
    while remaining:
        ready = [(lk, next((p for p in lk.point_names if p in owner), None)) for lk in remaining]
        ready = [(lk, at) for lk, at in ready if at is not None]
        if not ready:
            place(remaining[0], None)
            continue
        for lk, _ in ready:
            at = next(p for p in lk.point_names if p in owner)
            place(lk, at)
    return Structure(tuple(order), tuple(owner.items()), tuple(closures),
                     n_unknowns, 2 * len(closures) + n_slides)


# --- the mechanism ---


@dataclass(frozen=True)
class Mechanism:
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

    @property
    def param_values(self) -> dict[str, float]:
        """The parameters as a dict: name -> value.

        Examples
        --------
        >>> m = Mechanism(parameters={"r": 2.0}, ground={"O": (0, 0)},
        ...     links=[Link.bar("crank", "O", "A", "r")], inputs=[Input.angle("crank")])
        >>> m.param_values
        {'r': 2.0}
        """
        return dict(self.parameters)

    def parameter(self, name: str) -> float:
        """A parameter's value.

        Parameters
        ----------
        name : str

        Returns
        -------
        float

        Examples
        --------
        >>> m = Mechanism(parameters={"r": 2.0}, ground={"O": (0, 0)},
        ...     links=[Link.bar("crank", "O", "A", "r")], inputs=[Input.angle("crank")])
        >>> m.parameter("r")
        2.0
        """
        return self.param_values[name]

    def link(self, name: str) -> Link:
        """The link of that name.

        Parameters
        ----------
        name : str

        Returns
        -------
        Link

        Examples
        --------
        >>> m = Mechanism(parameters={"r": 2.0}, ground={"O": (0, 0)},
        ...     links=[Link.bar("crank", "O", "A", "r")], inputs=[Input.angle("crank")])
        >>> m.link("crank").point_names
        ('O', 'A')
        """
        return {lk.name: lk for lk in self.links}[name]

    def slide(self, name: str) -> Slide:
        """The slide of that name.

        Parameters
        ----------
        name : str

        Returns
        -------
        Slide

        Examples
        --------
        >>> m = Mechanism(ground={"O": (0, 0)},
        ...     links=[Link.bar("crank", "O", "A", 1), Link.bar("rod", "A", "B", 3)],
        ...     slides=[Slide("B", "ground", name="guide")], inputs=[Input.angle("crank")])
        >>> m.slide("guide").point
        'B'
        """
        return {s.name: s for s in self.slides}[name]

    @property
    def ground_points(self) -> tuple[str, ...]:
        """The ground points' names, in declaration order.

        Examples
        --------
        >>> m = Mechanism(parameters={"r": 2.0}, ground={"O": (0, 0)},
        ...     links=[Link.bar("crank", "O", "A", "r")], inputs=[Input.angle("crank")])
        >>> m.ground_points
        ('O',)
        """
        return tuple(g for g, _ in self.ground)

    @property
    def moving_points(self) -> tuple[str, ...]:
        """Points carried by links and not fixed to the ground, in declaration order.

        Examples
        --------
        >>> m = Mechanism(parameters={"r": 2.0}, ground={"O": (0, 0)},
        ...     links=[Link.bar("crank", "O", "A", "r")], inputs=[Input.angle("crank")])
        >>> m.moving_points
        ('A',)
        """
        seen = dict.fromkeys(p for lk in self.links for p in lk.point_names)
        return tuple(p for p in seen if p not in dict(self.ground))

    @property
    def mobility(self) -> int:
        """Degrees of freedom counted from the structure (unknowns minus equations).

        Examples
        --------
        >>> m = Mechanism(parameters={"r": 2.0}, ground={"O": (0, 0)},
        ...     links=[Link.bar("crank", "O", "A", "r")], inputs=[Input.angle("crank")])
        >>> m.mobility
        1
        """
        return self.structure.mobility

    def value(self, v: Num) -> float:
        """The number `v`, resolving a parameter reference.

        Parameters
        ----------
        v : float, str or Param

        Returns
        -------
        float

        Examples
        --------
        >>> m = Mechanism(parameters={"r": 2.0}, ground={"O": (0, 0)},
        ...     links=[Link.bar("crank", "O", "A", "r")], inputs=[Input.angle("crank")])
        >>> m.value("r"), m.value(Param("r", 0.5)), m.value(3)
        (2.0, 1.0, 3.0)
        """
        p = as_param(v)
        return float(v) if p is None else p.scale * self.param_values[p.name]

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
    def with_parameters(self, **values: float) -> "Mechanism":
        """A new mechanism with some parameters changed.

        Parameters
        ----------
        **values : float
            New values of existing parameters.

        Returns
        -------
        Mechanism

        Examples
        --------
        >>> m = Mechanism(parameters={"r": 2.0}, ground={"O": (0, 0)},
        ...     links=[Link.bar("crank", "O", "A", "r")], inputs=[Input.angle("crank")])
        >>> m.with_parameters(r=3).size(), m.size()
        (3.0, 2.0)
        """
        problems = [f"[parameters] {k}: no such parameter" for k in values if k not in self.param_values]
        problems += [f"[parameters] {k}: expected a number, got {v!r}" for k, v in values.items()
                     if not is_number(v)]
        if problems:
            raise ModelError(problems)
        return replace(self, parameters={**self.param_values, **{k: float(v) for k, v in values.items()}})

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


# --- validation: gather every problem, name the section and the field ---


def _parts(v, field: str, kind: type) -> tuple:
    """`v` as a tuple of `kind` (kincas.Link, ...); ModelError naming `field` for anything
    else (a name given where the part itself is wanted)."""
    if isinstance(v, (str, bytes, Mapping)) or not isinstance(v, Iterable):
        raise ModelError(f"{field}: expected a list of kincas.{kind.__name__}, got {v!r:.80}")
    items = tuple(v)
    bad = [f"{field}[{i}]: expected a kincas.{kind.__name__}, got {x!r:.80}"
           for i, x in enumerate(items) if not isinstance(x, kind)]
    if bad:
        raise ModelError(bad)
    return items


def _number_check(params, out: list[str]):
    """num(where, v): appends to `out` what is wrong with a number or a parameter's name."""
    def num(where: str, v):
        p = as_param(v)
        if p is not None:
            if p.name not in params:
                out.append(f"{where}: unknown parameter {p.name!r}")
        elif not is_number(v):
            out.append(f"{where}: expected a number or a parameter's name, got {v!r}")
        elif not math.isfinite(v):
            out.append(f"{where}: {v} is not a finite number")
    return num


def _guess_problems(guess, moving: set, gnames: set, num, out: list[str]) -> None:
    for p, (x, y) in guess:
        if p not in moving:
            what = "is a ground point (fixed)" if p in gnames else "is not a point of any link"
            out.append(f"[guess] {p}: {what}")
        num(f"[guess] {p}", x), num(f"[guess] {p}", y)


def check_guess(m: Mechanism, guess) -> tuple:
    """A guess given to one call (`sweep(..., guess=)`) checked as the mechanism's own is:
    its (point, (x, y)) items, or ModelError naming every unknown point and every value
    that is not a finite number or a parameter's name.

    >>> m = Mechanism(ground={"O": (0, 0)}, links=[Link.bar("crank", "O", "A", 1)],
    ...               inputs=[Input.angle("crank")])
    >>> check_guess(m, {"A": (0, 1)})
    (('A', (0, 1)),)
    >>> check_guess(m, {"Z": (0, float("nan"))})
    Traceback (most recent call last):
    ...
    kincas.errors.ModelError: 2 problems:
      [guess] Z: is not a point of any link
      [guess] Z: nan is not a finite number
    """
    items = tuple((k, _pair(v, f"[guess] {k}")) for k, v in _table(guess, "guess"))
    out: list[str] = []
    _guess_problems(items, set(m.moving_points), set(m.ground_points),
                    _number_check(m.param_values, out), out)
    if out:
        raise ModelError(out)
    return items


def _check(m: Mechanism) -> list[str]:
    out: list[str] = []
    params = m.param_values
    num = _number_check(params, out)

    for k, v in m.parameters:
        if not _NAME.match(k):
            out.append(f"[parameters] {k}: not a valid name ({NAME_RULE})")
        if not math.isfinite(v):
            out.append(f"[parameters] {k}: {v} is not a finite number")
    gnames = set()
    for g, (x, y) in m.ground:
        if g == GROUND:
            out.append(f"[ground] {g}: {RESERVED}")
        elif not isinstance(g, str) or not _NAME.match(g):
            out.append(f"[ground] {g}: not a valid point name ({NAME_RULE})")
        gnames.add(g)
        num(f"[ground] {g}", x), num(f"[ground] {g}", y)
    lnames: set[str] = set()
    for lk in m.links:
        where = f"[links] {lk.name}"
        if lk.name == GROUND:
            out.append(f"{where}: {RESERVED}")
        elif not isinstance(lk.name, str) or not _NAME.match(lk.name):
            out.append(f"{where}: not a valid link name ({NAME_RULE})")
        if lk.name in lnames:
            out.append(f"{where}: declared twice")
        lnames.add(lk.name)
        names = lk.point_names
        if len(names) < 2:
            out.append(f"{where}: points: a link needs at least two points")
        if len(set(names)) != len(names):
            out.append(f"{where}: points: a point is named twice")
        for p, (x, y) in lk.points:
            if not _NAME.match(p):
                out.append(f"{where}: points: {p!r} is not a valid point name ({NAME_RULE})")
            num(f"{where}: points.{p}" if not lk.two_point else f"{where}: length", x)
            num(f"{where}: points.{p}", y)
        if len([p for p in names if p in gnames]) > 1:
            out.append(f"{where}: points: carries two ground points, so it cannot move")
    moving = set(m.moving_points)
    snames: set[str] = set()
    for i, s in enumerate(m.slides):
        where = f"[[slides]] {s.name or i + 1}"
        if s.name in snames:
            out.append(f"{where}: name: two slides are named {s.name!r} (give each a `name`)")
        snames.add(s.name)
        if s.point not in moving and not (s.point in gnames and s.along != GROUND):
            # a ground point in the slot of a moving link is fine (a quick-return guide)
            what = ("is a ground point on a ground line" if s.point in gnames
                    else "is not a point of any link")
            out.append(f"{where}: point: {s.point!r} {what}")
        if s.along != GROUND and s.along not in lnames:
            out.append(f"{where}: along: unknown body {s.along!r} (a link's name or \"ground\")")
        elif s.along != GROUND and s.point in m.link(s.along).point_names:
            out.append(f"{where}: along: {s.point!r} is a point of {s.along!r} itself")
        num(f"{where}: line.through", s.through[0]), num(f"{where}: line.through", s.through[1])
        num(f"{where}: line.angle", s.angle)
    keys = set()
    for i, inp in enumerate(m.inputs):
        where = f"[[inputs]] {i + 1}"
        if not isinstance(inp.target, str):
            out.append(f"{where}: {inp.kind}: expected a name, got {inp.target!r}")
            continue
        ok = {"angle": lnames, "slide": snames, "parameter": set(params)}.get(inp.kind)
        rel = _joints.split_relative(inp.target) if inp.kind == "angle" else None
        if rel is not None:  # "A/B": link A relative to body B
            a, b = rel
            if a not in lnames:
                out.append(f"{where}: angle: unknown link {a!r} in {inp.target!r}")
            if b != GROUND and b not in lnames:
                out.append(f"{where}: angle: unknown body {b!r} in {inp.target!r}")
            if a == b:
                out.append(f"{where}: angle: {inp.target!r} relates a link to itself")
        elif ok is None:
            out.append(f"{where}: unknown kind {inp.kind!r} (angle, slide or parameter)")
        elif inp.target not in ok:
            what = {"angle": "link", "slide": "slide", "parameter": "parameter"}[inp.kind]
            out.append(f"{where}: {inp.kind}: unknown {what} {inp.target!r}")
        if inp.key in keys:
            out.append(f"{where}: {inp.kind}: {inp.target!r} is driven twice")
        keys.add(inp.key)
    _guess_problems(m.guess, moving, gnames, num, out)
    out += _joints.problems(m, lnames, snames, num)
    out += check_loads(m, num)
    if out:
        return out  # the numeric checks below need every name to resolve
    for lk in m.links:
        loc = [(m.value(x), m.value(y)) for _, (x, y) in lk.points]
        if lk.two_point and m.value(lk.points[1][1][0]) <= 0:
            out.append(f"[links] {lk.name}: length must be positive")
        elif all(math.dist(loc[0], b) == 0 for b in loc[1:]):
            out.append(f"[links] {lk.name}: points: all its points coincide")
    return out + _joints.value_problems(m)


def counted_freedoms(m: Mechanism) -> int:
    """Degrees of freedom by counting: unknowns minus equations, plus driven parameters."""
    return m.structure.mobility + sum(inp.kind == "parameter" for inp in m.inputs)


def solved_unknowns(m: Mechanism) -> int:
    """The unknowns the solver finds at each pose: the structure's coordinates less the link
    angles that inputs drive (a driven angle is given, not solved for); the size of q.

    >>> m = Mechanism(ground={"O": (0, 0)}, links=[Link.bar("crank", "O", "A", 1)],
    ...               inputs=[Input.angle("crank")])
    >>> m.structure.n_unknowns, solved_unknowns(m)
    (1, 0)
    """
    links = {lk.name for lk in m.links}
    driven = {i.target for i in m.inputs if i.kind == "angle" and i.target in links}
    return m.structure.n_unknowns - len(driven)


def use_rank_test(decide) -> None:
    """Let `Mechanism.redundant` ask `decide(mechanism) -> int` (the core's rank test, given by
    `import kincas`) where counting cannot tell the redundant equations."""
    global _rank_decision
    _rank_decision = decide


def needs_rank_test(m: Mechanism) -> bool:
    """Whether counting gives fewer freedoms than inputs: a redundant joint may hide the
    missing ones, and only the constraint Jacobian's rank at an assembly can tell
    (kincas/core/redundant.py decides, at the first solve: a declaration runs no numerics)."""
    return counted_freedoms(m) < len(m.inputs)


def mobility_problem(m: Mechanism, free: int | None = None, tested: bool = False) -> str:
    """The message for a wrong number of inputs; `tested`: the rank test ran and found
    `free` freedoms (None: no assembly found from the guess to test)."""
    st, dof = m.structure, counted_freedoms(m)
    n_param = dof - st.mobility
    detail = (f"{st.n_unknowns} unknown coordinates, {st.n_equations} equations"
              + (f", plus {n_param} driven parameter(s)" if n_param else ""))
    hint = ""
    if tested:
        hint = ("; a redundant joint would add freedoms to this count, but "
                + ("no assembly was found from the guess to test for one" if free is None else
                   f"the constraint Jacobian at generic points of the assemblies found gives it "
                   f"{free + n_param} degree(s) of freedom"))
    return (f"[inputs]: the mechanism has {dof} degree(s) of freedom ({detail}) "
            f"but {len(m.inputs)} input(s) drive it; give one input per degree of freedom{hint}")


def _check_mobility(m: Mechanism) -> list[str]:
    """Problems with the number of inputs that counting alone proves (too few inputs)."""
    dof = counted_freedoms(m)
    if (dof == len(m.inputs) and m.structure.mobility >= 0) or needs_rank_test(m):
        return []
    return [mobility_problem(m)]
