"""Numbers and pairs as a declaration takes them (no casadi, no numpy needed): numpy scalars
become Python floats, pairs and tables of the wrong shape a ModelError naming the field.

>>> _pair((1, "r"), "[ground] A"), as_number(2)
((1, 'r'), 2)
"""
from __future__ import annotations

import numbers
from typing import Mapping

from ..errors import ModelError


def as_number(v):
    """A numpy scalar (np.int64, np.float32, ...) as a Python float; anything else unchanged
    (a Python number, a parameter's name, a `Param`, or a mistake for the checks to name).

    >>> import numpy as np
    >>> as_number(np.int64(3)), as_number(np.float32(0.5)), as_number(2), as_number("r")
    (3.0, 0.5, 2, 'r')
    """
    if isinstance(v, numbers.Real) and not isinstance(v, (bool, int, float)):
        return float(v)
    return v


def is_number(v) -> bool:
    """Whether v is a real number (numpy's too), not a bool.

    >>> import numpy as np
    >>> is_number(np.int64(1)), is_number(1.5), is_number(True), is_number("1")
    (True, True, False, False)
    """
    return isinstance(v, numbers.Real) and not isinstance(v, bool)  # (numpy's bool is no Real)


def _pair(v, where: str = "") -> tuple[Num, Num]:
    """(x, y) from a pair of numbers or parameter names; ModelError naming `where` for
    anything else (a number alone, three values, a string)."""
    try:
        if isinstance(v, (str, bytes, Mapping)):
            raise TypeError
        items = tuple(v)
    except TypeError:
        items = None
    if items is None or len(items) != 2:
        raise ModelError(f"{where or 'point'}: expected a pair (x, y), got {v!r}")
    return (as_number(items[0]), as_number(items[1]))


def _table(v, where: str, what: str = "(x, y)") -> tuple:
    """The (name, value) items of a mapping (or of a sequence of pairs); ModelError naming
    `where` otherwise (a list of values, a string)."""
    if isinstance(v, Mapping):
        return tuple(v.items())
    try:
        if isinstance(v, (str, bytes)):
            raise TypeError
        items = tuple(v)
        if all(isinstance(kv, (tuple, list)) and len(kv) == 2 and isinstance(kv[0], str) for kv in items):
            return tuple((k, v) for k, v in items)
    except TypeError:
        pass
    raise ModelError(f"{where}: expected a dict of name -> {what}, got {v!r:.80}")
