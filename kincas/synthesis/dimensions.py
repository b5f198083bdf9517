"""The unit of an expression of the `[optimize]` language, inferred from its tree.

A unit is a product of powers of named units ({"mm": 2, "s": -1} is mm^2/s), read from the
labels that reports already give each quantity ("mm/s^2", "force·mm", "1/mm"). Inference
follows dimensional analysis:

- a quantity or a parameter has its label's unit; a data array and a number fit whatever
  they meet (a target `tx` beside `P.x` is a length), and are dimensionless alone;
- `a + b`, `a - b`, `hypot(a, b)`: both sides must agree, and the sum has their unit;
- `a * b` and `a / b` add and subtract powers; `a ^ n` multiplies them by the number n;
- `sum`, `mean`, `max`, `min`, `abs` keep the unit; `sqrt` halves the powers;
- `sin cos tan exp log` give a pure number; `asin acos atan atan2` give the angle unit.

Where the analysis cannot decide (sides that disagree, a power that is not a number, an
odd power under a square root) the unit is unknown (None) and nothing is printed: a missing
unit is better than a wrong one.

>>> from kincas.synthesis.expressions import parse
>>> labels = {"P.x": "mm", "P.y": "mm", "rocker.omega": "deg/s", "r1": "mm"}
>>> unit = lambda text, **kw: expression_unit(parse(text, "minimize", **kw), labels.get)
>>> unit("sum((P.x - tx)^2 + (P.y - ty)^2)", data=["tx", "ty"])
'mm^2'
>>> unit("max(rocker.omega) / r1"), unit("sqrt(mean(P.x^2))"), unit("P.x + rocker.omega")
('deg/(s·mm)', 'mm', None)
"""
from __future__ import annotations

import ast
from fractions import Fraction

from .expressions import AGGREGATE, Expr, quantity_name

Unit = dict  # name -> Fraction power; None: unknown; _FREE: fits anything (numbers, data)
_FREE = "free"
_ANGLE_OUT = {"asin", "acos", "atan", "atan2"}
_PURE_OUT = {"sin", "cos", "tan", "exp", "log"}


# --- labels <-> powers ---


def parse_label(label: str | None):
    """'mm/s^2' -> {'mm': 1, 's': -2}; '' -> {} (a pure number); None stays None.

    >>> parse_label("force·mm"), parse_label("1/mm"), parse_label("mm/mm")
    ({'force': Fraction(1, 1), 'mm': Fraction(1, 1)}, {'mm': Fraction(-1, 1)}, {})
    """
    if label is None:
        return None
    num, _, den = label.replace(" per ", "/").partition("/")
    out: dict = {}
    for part, sign in ((num, 1), (den.strip("()"), -1)):
        for atom in filter(None, part.replace("*", "·").split("·")):
            name, _, power = atom.strip().partition("^")
            if name == "1":
                continue
            try:
                out[name] = out.get(name, Fraction(0)) + sign * Fraction(power or 1)
            except ValueError:
                return None
    return {k: v for k, v in out.items() if v}


def format_unit(u) -> str | None:
    """{'mm': 2, 's': -1} -> 'mm^2/s'; {} -> '' (a pure number); None -> None."""
    if u is None or u == _FREE:
        return None if u is None else ""
    show = lambda k, v: k if v == 1 else f"{k}^{v}"
    num = [show(k, v) for k, v in u.items() if v > 0]
    den = [show(k, -v) for k, v in u.items() if v < 0]
    top = "·".join(num) or ("1" if den else "")
    if not den:
        return top
    return f"{top}/{den[0]}" if len(den) == 1 else f"{top}/({'·'.join(den)})"


# --- inference ---


def expression_unit(e: Expr, label_of) -> str | None:
    """The unit label of a parsed expression, or None where it cannot be decided.

    Parameters
    ----------
    e : Expr
        A parsed expression (`kincas.synthesis.expressions.parse`).
    label_of : callable
        name -> unit label ('mm/s', 'deg', '') of a quantity or parameter, or None if unknown.

    Returns
    -------
    str or None
        The label ('mm^2', 'deg/s', '' for a pure number), None when undecidable.
    """
    u = _unit(e.tree, e, label_of)
    return "" if u == _FREE else format_unit(u)


def term_unit(e: Expr, name: str, label_of) -> str | None:
    """The unit of bare name `name` where it is a term of the expression's outer sum
    (`hypot(shaking.x, shaking.y) - peak`: peak has the unit of the force), read as the unit
    of the rest; None where it is not such a term or the rest's unit is undecided.

    >>> from kincas.synthesis.expressions import parse
    >>> labels = {"shaking.x": "N", "shaking.y": "N"}.get
    >>> term_unit(parse("hypot(shaking.x, shaking.y) - peak", "c"), "peak", labels)
    'N'
    >>> term_unit(parse("2 * peak - shaking.x", "c"), "peak", labels) is None
    True
    """
    def terms(node):
        if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.Add, ast.Sub)):
            return terms(node.left) + terms(node.right)
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
            return terms(node.operand)
        return [node]
    if not any(isinstance(t, ast.Name) and t.id == name for t in terms(e.tree)):
        return None
    free = Expr(e.text, e.tree, e.where, e.quantities, e.names, [*e.data, name], e.extremes)
    u = _unit(e.tree, free, label_of)
    return None if u is None or u == _FREE else format_unit(u)


def _combine(a, b, sign):
    if a is None or b is None:
        return None
    a, b = ({} if a == _FREE else a), ({} if b == _FREE else b)
    out = dict(a)
    for k, v in b.items():
        out[k] = out.get(k, Fraction(0)) + sign * v
    return {k: v for k, v in out.items() if v}


def _same(a, b):
    """The common unit of a sum's two sides: a free side takes the other's unit."""
    if a is None or b is None:
        return None
    if a == _FREE:
        return b
    if b == _FREE or a == b:
        return a
    return None


def _scale(a, k: Fraction):
    if a is None or a == _FREE:
        return a
    return {n: v * k for n, v in a.items() if v * k}


def _unit(node, e: Expr, label_of):
    if isinstance(node, ast.Constant):
        return _FREE
    if isinstance(node, ast.Name):
        if node.id == "pi" or node.id in e.data:
            return _FREE
        return parse_label(label_of(node.id))
    name = quantity_name(node)
    if name is not None:
        return parse_label(label_of(name))
    if isinstance(node, ast.UnaryOp):
        return _unit(node.operand, e, label_of)
    if isinstance(node, ast.BinOp):
        a = _unit(node.left, e, label_of)
        if isinstance(node.op, ast.Pow):
            n = _number(node.right)
            return None if n is None else (a if a == _FREE else _scale(a, n))
        b = _unit(node.right, e, label_of)
        if isinstance(node.op, (ast.Add, ast.Sub)):
            return _same(a, b)
        if a == _FREE and b == _FREE:
            return _FREE
        return _combine(a, b, 1 if isinstance(node.op, ast.Mult) else -1)
    f = node.func.id
    args = [_unit(a, e, label_of) for a in node.args]
    if f in AGGREGATE or f == "abs":
        return args[0]
    if f == "sqrt":
        half = _scale(args[0], Fraction(1, 2))
        ok = half is None or half == _FREE or all(v.denominator == 1 for v in half.values())
        return half if ok else None
    if f == "hypot":
        return _same(*args)
    if f in _PURE_OUT:
        return {}
    if f in _ANGLE_OUT:
        return parse_label(label_of("__angle__"))
    return None


def _number(node) -> Fraction | None:
    """The value of a power's exponent when it is a plain (possibly negated) number."""
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)):
        return Fraction(node.value).limit_denominator(1000)
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
        n = _number(node.operand)
        return None if n is None else -n
    return None
