"""The checks of a mechanism's declaration: every problem gathered, naming the section and
the field (no casadi here). `Mechanism` runs them on construction; `check_guess` checks a
guess given to one call as the mechanism's own is.

>>> from kincas.model import Input, Link, Mechanism
>>> m = Mechanism(ground={"O": (0, 0)}, links=[Link.bar("crank", "O", "A", 1)],
...               inputs=[Input.angle("crank")])
>>> check_guess(m, {"A": (0, 1)})
(('A', (0, 1)),)
"""
from __future__ import annotations

import math
import re
from typing import TYPE_CHECKING, Iterable, Mapping

from ..errors import ModelError
from . import joints as _joints
from .loads import check_loads
from .mobility import GROUND
from .parts import _pair, _table, as_param, is_number

if TYPE_CHECKING:
    from .mechanism import Mechanism

_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_\-]*$")
NAME_RULE = "a name starts with an ASCII letter or _, then ASCII letters, digits, _ or -"
RESERVED = (f'"{GROUND}" is reserved: it names the fixed frame (a slide\'s `along = "{GROUND}"`, '
            f'an angle relative to it, "crank/{GROUND}"); choose another name')


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

    >>> from kincas.model import Input, Link, Mechanism
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
    if getattr(m, "space", "2d") == "3d":  # (x, y, z): kincas/model/space.py checks its own
        return m.check_guess(guess)
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
