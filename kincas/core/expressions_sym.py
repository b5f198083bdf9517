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

import casadi as ca

# the kinds of an expression's value (kincas/synthesis/expressions.py): the same at every
# sample, one value per sample, or over all samples
CONST, SAMPLE, TOTAL = "constant", "per sample", "total"


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
