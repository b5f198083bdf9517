"""CasADi's symbolic arithmetic for the expression language (kincas/synthesis/expressions.py):
an objective or constraint written with quantity names becomes a CasADi expression, so its
derivatives through the kinematics are exact.

>>> from kincas.synthesis.expressions import Evaluator, parse
>>> leaf = lambda kind, name: ("constant", 2.0)
>>> kind, v = Evaluator(leaf, None, None, ops=SYMBOLIC)(parse("hypot(3, 4) + abs(-1)", "e"))
>>> kind, float(v)
('constant', 6.0)
"""
from __future__ import annotations

import ast

import casadi as ca

# the kinds of an expression's value (kincas/synthesis/expressions.py): the same at every
# sample, one value per sample, or over all samples
CONST, SAMPLE, TOTAL = "constant", "per sample", "total"
# the functions of values the expression languages share (kincas/synthesis/expressions.py,
# kincas/core/motion_loads.py)
UNARY = {"sin", "cos", "tan", "asin", "acos", "atan", "sqrt", "exp", "log", "abs"}
BINARY = {"atan2", "hypot"}


def quantity_name(node) -> str | None:
    """'P.x' for the tree of `P.x`, 'effort(crank.angle)' for `effort(crank.angle)`,
    'reaction(B, rod).x' for `reaction(B, rod).x`; None for anything else."""
    if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name):
        return f"{node.value.id}.{node.attr}"
    call = node.value if isinstance(node, ast.Attribute) else node
    if not (isinstance(call, ast.Call) and isinstance(call.func, ast.Name) and not call.keywords):
        return None
    f, args = call.func.id, call.args
    if f == "effort" and isinstance(node, ast.Call) and len(args) == 1:
        inner = args[0].id if isinstance(args[0], ast.Name) else quantity_name(args[0])
        return None if inner is None else f"effort({inner})"
    if f == "reaction" and isinstance(node, ast.Attribute) and 1 <= len(args) <= 2 \
            and all(isinstance(a, ast.Name) for a in args):
        return f"reaction({', '.join(a.id for a in args)}).{node.attr}"
    return None


class SYMBOLIC:
    """The operations `Evaluator` needs, on CasADi SX values.

    Examples
    --------
    >>> float(SYMBOLIC.atan2(SYMBOLIC.const(1.0), 1.0) * 4)
    3.141592653589793
    """

    const = staticmethod(ca.SX)
    sqrt, exp, log, abs = staticmethod(ca.sqrt), staticmethod(ca.exp), staticmethod(ca.log), staticmethod(ca.fabs)
    sin, cos, tan = staticmethod(ca.sin), staticmethod(ca.cos), staticmethod(ca.tan)
    asin, acos, atan = staticmethod(ca.asin), staticmethod(ca.acos), staticmethod(ca.atan)
    atan2 = staticmethod(ca.atan2)
