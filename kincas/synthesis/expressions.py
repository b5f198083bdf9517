"""A small, safe expression language for objectives and constraints, written with quantity names.

An expression is parsed by Python's `ast` module and only these nodes are accepted: numbers,
names, `+ - * /`, powers (`**` or `^`), unary minus, and calls of the functions below. Nothing
is ever evaluated by Python itself; the tree is turned into a CasADi expression (with the
operations of kincas/core/expressions_sym.py), so that its derivatives through the
kinematics are exact.

Names:
  * a quantity `P.x`, `L.angle`, `S.s`, `P.vx`, ... (see docs/scene-format.md): its value at a
    sample, in the unit of the caller (degrees in a degree scene);
  * a parameter: its value (the same at every sample, unless an input drives it);
  * a data array given beside the expression: one value per sample;
  * `pi`.
  * a force quantity written as a call: `effort(crank.angle)`, `reaction(B, rod).x`;
Functions, element by element: sin cos tan asin acos atan atan2 sqrt exp log abs hypot (the
trigonometric ones take and give angles in the caller's unit). Over the samples:
  * `sum(E)`, `mean(E)`: over the sample inputs;
  * `max(E)`, `min(E)`: the extreme of E over the whole range of the (single) input between
    the first and the last sample, not only at the samples (found exactly by the optimiser).

An expression is *per sample* when it names a quantity or a data array outside those four
functions, *total* when it has gone through one of them, *constant* when it names only
parameters and numbers. Totals and per-sample values cannot be mixed.

>>> e = parse("sum((C.x - tx)^2) + 0.1 * max(rocker.angle)", "minimize", data=["tx"])
>>> e.quantities, e.data, [(k, a.text) for k, a in e.extremes]
(['C.x', 'rocker.angle'], ['tx'], [('max', 'rocker.angle')])
"""
from __future__ import annotations

import ast
import math
from dataclasses import dataclass, field

import numpy as np

from ..core.expressions_sym import CONST, SAMPLE, TOTAL  # noqa: F401  (the kinds, shared)
from ..core.expressions_sym import BINARY, UNARY, quantity_name  # noqa: F401  (shared with the loads' expressions)
from ..errors import ModelError

AGGREGATE = {"sum", "mean", "max", "min"}
FORCES = {"effort", "reaction"}  # quantity names written as calls (kincas/core/dynamics.py)


class NUMERIC:
    """numpy's arithmetic for `Evaluator` (the default): an expression's value on numbers."""

    const = float
    sqrt, exp, log, abs = np.sqrt, np.exp, np.log, np.abs
    sin, cos, tan, asin, acos, atan = np.sin, np.cos, np.tan, np.arcsin, np.arccos, np.arctan
    atan2 = np.arctan2


@dataclass
class Expr:
    """A parsed expression: its text, its tree, and what it refers to."""

    text: str
    tree: ast.AST
    where: str
    quantities: list[str] = field(default_factory=list)
    names: list[str] = field(default_factory=list)  # bare names: parameters or data
    data: list[str] = field(default_factory=list)
    extremes: list[tuple[str, "Expr"]] = field(default_factory=list)  # ("max" | "min", E)


def parse(text: str, where: str, data=()) -> Expr:
    """Parse and check an expression; ModelError naming `where` when it is not allowed."""
    if not isinstance(text, str) or not text.strip():
        raise ModelError(f"{where}: expected an expression (a string), got {text!r}")
    src = text.replace("^", "**")
    try:
        tree = ast.parse(src.strip(), mode="eval").body
    except SyntaxError as e:
        raise ModelError(f"{where}: cannot read {text!r}: {e.msg}") from None
    out = Expr(text, tree, where)
    _walk(tree, out, set(data), inside=False)
    return out


def _walk(node, out: Expr, data: set, inside: bool):
    where = out.where
    if isinstance(node, ast.Constant):
        if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
            raise ModelError(f"{where}: {node.value!r} is not a number")
    elif isinstance(node, ast.Attribute):
        name = quantity_name(node)
        if name is None:
            raise ModelError(f"{where}: {ast.unparse(node)!r} is not a quantity name (OBJECT.attribute)")
        out.quantities.append(name) if name not in out.quantities else None
    elif isinstance(node, ast.Name):
        if node.id in data:
            out.data.append(node.id) if node.id not in out.data else None
        elif node.id != "pi":
            out.names.append(node.id) if node.id not in out.names else None
    elif isinstance(node, ast.BinOp):
        if not isinstance(node.op, (ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow)):
            raise ModelError(f"{where}: operator {type(node.op).__name__} is not allowed "
                             f"(use + - * / ** ^)")
        _walk(node.left, out, data, inside), _walk(node.right, out, data, inside)
    elif isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        _walk(node.operand, out, data, inside)
    elif isinstance(node, ast.Call) and quantity_name(node) is not None:  # effort(KEY)
        name = quantity_name(node)
        out.quantities.append(name) if name not in out.quantities else None
    elif isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and not node.keywords:
        f, n = node.func.id, len(node.args)
        if f in FORCES:
            raise ModelError(f"{where}: {ast.unparse(node)!r}: write effort(KEY) with an input's "
                             f"key, or reaction(P, LINK).x / reaction(SLIDE).y")
        if f in AGGREGATE:
            if n != 1:
                raise ModelError(f"{where}: {f}() takes one expression")
            if inside:
                raise ModelError(f"{where}: {f}() inside sum/mean/max/min is not allowed")
            if f in ("max", "min"):
                sub = Expr(ast.unparse(node.args[0]), node.args[0], where)
                _walk(node.args[0], sub, data, inside=True)
                if sub.data:
                    raise ModelError(f"{where}: {f}() is taken over the whole input range, "
                                     f"where data arrays ({', '.join(sub.data)}) have no value")
                out.extremes.append((f, sub))
            _walk(node.args[0], out, data, inside=True)
        elif f in UNARY or f in BINARY:
            if n != (1 if f in UNARY else 2):
                raise ModelError(f"{where}: {f}() takes {1 if f in UNARY else 2} argument(s)")
            for a in node.args:
                _walk(a, out, data, inside)
        else:
            raise ModelError(f"{where}: unknown function {f!r} (allowed: "
                             f"{', '.join(sorted(UNARY | BINARY | AGGREGATE))})")
    else:
        raise ModelError(f"{where}: {ast.unparse(node)!r} is not allowed in an expression "
                         f"(numbers, names, + - * / ^ and functions only)")


# --- evaluation ---


class Evaluator:
    """Turns a tree into (kind, value), with the arithmetic of the caller's values: `ops`
    has `const(x)` and the functions sqrt exp log abs sin cos tan asin acos atan atan2 of
    those values (CasADi's symbolic ones: `kincas.core.expressions_sym.SYMBOLIC`; numpy's
    work as well). The caller supplies how leaves and aggregates become values:

      leaf(kind, name) -> (CONST | SAMPLE, SX)  for quantities ("quantity"), parameters
                                                 ("parameter") and data ("data");
      aggregate(fn, kind, expr, text) -> SX      a TOTAL for sum/mean/max/min of a
                                                 per-sample (or constant) expression;
      total(const_expr) -> SX                    a constant carried into the totals' variables.

    `angle` is the caller's angle unit in radians (pi/180 for degrees): trigonometric
    functions convert their arguments from it and their results to it."""

    def __init__(self, leaf, aggregate, total, angle: float = 1.0, ops=None):
        self.leaf, self.aggregate, self.total, self.angle = leaf, aggregate, total, angle
        self.ops = ops or NUMERIC

    def __call__(self, e: Expr):
        return self.eval(e.tree, e)

    def eval(self, node, e: Expr):
        ops = self.ops
        if isinstance(node, ast.Constant):
            return CONST, ops.const(float(node.value))
        if isinstance(node, ast.Attribute):
            return self.leaf("quantity", quantity_name(node))
        if isinstance(node, ast.Name):
            if node.id == "pi":
                return CONST, ops.const(math.pi)
            return self.leaf("data" if node.id in e.data else "parameter", node.id)
        if isinstance(node, ast.UnaryOp):
            k, v = self.eval(node.operand, e)
            return k, (-v if isinstance(node.op, ast.USub) else v)
        if isinstance(node, ast.BinOp):
            (ka, a), (kb, b) = self.eval(node.left, e), self.eval(node.right, e)
            k, a, b = self._join(ka, a, kb, b, e, ast.unparse(node))
            if isinstance(node.op, ast.Add):
                return k, a + b
            if isinstance(node.op, ast.Sub):
                return k, a - b
            if isinstance(node.op, ast.Mult):
                return k, a * b
            if isinstance(node.op, ast.Div):
                return k, a / b
            return k, a ** b
        if quantity_name(node) is not None:
            return self.leaf("quantity", quantity_name(node))
        f = node.func.id
        if f in AGGREGATE:
            k, v = self.eval(node.args[0], e)
            if k == TOTAL:
                raise ModelError(f"{e.where}: {f}() of a total")
            return TOTAL, self.aggregate(f, k, v, ast.unparse(node.args[0]))
        args = [self.eval(a, e) for a in node.args]
        if len(args) == 2:
            k, a, b = self._join(*args[0], *args[1], e, ast.unparse(node))
            if f == "hypot":
                return k, ops.sqrt(a * a + b * b)
            return k, ops.atan2(a, b) / self.angle
        k, a = args[0]
        if f in ("sin", "cos", "tan"):  # angles in the caller's unit
            return k, getattr(ops, f)(a * self.angle)
        if f in ("asin", "acos", "atan"):
            return k, getattr(ops, f)(a) / self.angle
        return k, getattr(ops, f)(a)

    def _join(self, ka, a, kb, b, e: Expr, text: str):
        """The kind of a combination; constants follow totals into the totals' variables."""
        if {ka, kb} == {SAMPLE, TOTAL}:
            raise ModelError(f"{e.where}: {text!r} mixes values per sample with totals "
                             f"(wrap the per-sample part in sum(), mean(), max() or min())")
        if TOTAL in (ka, kb):
            return TOTAL, (self.total(a) if ka == CONST else a), (self.total(b) if kb == CONST else b)
        return (SAMPLE if SAMPLE in (ka, kb) else CONST), a, b
