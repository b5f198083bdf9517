"""Input values as a table: one row per pose, one column per input, from what the user gave
(a mapping of input keys to numbers or arrays, or a bare array for a one-input mechanism).

>>> import kincas
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)], inputs=[kincas.Input.angle("crank")])
>>> input_table(m, [0.1, 0.2], "inputs", None).tolist()
[[0.1], [0.2]]
"""
from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..errors import ModelError
from ..model.mechanism import Mechanism

_PLAIN = (float, int, np.float64)  # numbers an input gives as they are (not bool)
# (numpy's names the usual case calls, looked up once: `np.name` is a module look-up a call)
_ND, _F8, _count, _isfinite = np.ndarray, np.dtype(np.float64), np.count_nonzero, np.isfinite


def input_table(m: Mechanism, inputs, what: str, default: float | None, keys=None) -> np.ndarray:
    """(N x nu) array of one value per input and pose from a mapping key -> scalar or array
    (`keys`: the mechanism's input keys, if already at hand). Where every input has one
    value, the table has one row (N = 1), whatever the number of poses. ModelError naming
    `what` and the input for anything that is not finite numbers, one row per pose."""
    keys = [i.key for i in m.inputs] if keys is None else list(keys)
    if inputs is None and default is not None:  # every input at its default: one row
        return np.full((1, len(keys)), float(default))
    if len(keys) == 1 and (type(inputs) is dict or isinstance(inputs, Mapping)) and len(inputs) == 1 \
            and keys[0] in inputs:
        c = inputs[keys[0]]  # the common case, one input: no copy
        if not (type(c) is _ND and c.dtype == _F8):
            c = _floats(c, what, keys[0])
        if c.ndim <= 1 and c.size and _count(_isfinite(c)) == c.size:  # (.all(): 2x)
            return c.reshape(-1, 1)
    return _table(m, inputs, what, default, keys)


def _table(m: Mechanism, inputs, what: str, default: float | None, keys: list) -> np.ndarray:
    """`input_table` past its usual case (its comprehensions here: in `input_table` they would
    make cells of the names they read at every call)."""
    if type(inputs) is dict and len(inputs) == len(keys) and keys:  # one plain number per
        # input (a pose of kincas.solve): the row as it is, without a column per input
        row = [inputs.get(k, inputs) for k in keys]
        if all(type(v) in _PLAIN for v in row):
            a = np.array([row], dtype=float)
            if np.isfinite(a).all():
                return a
    if inputs is None:
        if default is None and keys:
            raise ModelError(f"{what}: give a value for each of {keys}")
        inputs = {}
    elif not isinstance(inputs, Mapping):
        if len(keys) != 1:
            raise ModelError(f"{what}: the mechanism has inputs {keys}; give a mapping")
        inputs = {keys[0]: inputs}
    problems = [f"{what}: {k!r} is not an input (inputs: {keys})" for k in inputs if k not in keys]
    if default is None:
        problems += [f"{what}: no value for input {k!r}" for k in keys if k not in inputs]
    if problems:
        raise ModelError(problems)
    if not keys:  # a structure (no freedom): one pose
        return np.zeros((1, 0))
    cols = [np.atleast_1d(_floats(inputs.get(k, default), what, k)) for k in keys]
    bad = [k for k, c in zip(keys, cols) if c.ndim != 1 or not np.isfinite(c).all()]
    if bad:
        raise ModelError([f"{what}: {k!r}: expected finite numbers (one per pose)" for k in bad])
    empty = [k for k, c in zip(keys, cols) if not c.size]
    if empty:
        raise ModelError([f"{what}: {k!r}: no values (give at least one)" for k in empty])
    n = max(len(c) for c in cols)
    if any(len(c) not in (1, n) for c in cols):
        raise ModelError(f"{what}: inputs that sweep advance together, so their lengths must agree")
    return np.stack([np.broadcast_to(c, (n,)) for c in cols], axis=1)


def derivative_table(m: Mechanism, values, what: str, default: float, n: int, keys=None) -> np.ndarray:
    """The (n x nu) table of the inputs' rates, accelerations or jerks over n poses: one value
    per input, or one per pose; ModelError naming `what` and the input otherwise.

    >>> import kincas
    >>> m = kincas.Mechanism(ground={"O": (0, 0)}, links=[kincas.Link.bar("crank", "O", "A", 1)],
    ...                      inputs=[kincas.Input.angle("crank")])
    >>> derivative_table(m, {"crank.angle": 2.0}, "rates", 1.0, 3).ravel().tolist()
    [2.0, 2.0, 2.0]
    >>> derivative_table(m, {"crank.angle": [1.0, 2.0]}, "rates", 1.0, 3)
    Traceback (most recent call last):
    ...
    kincas.errors.ModelError: rates: crank.angle: 2 values for 3 poses (give one value, or one per pose)
    """
    T = input_table(m, values, what, default, keys)
    if T.shape[0] not in (1, n):
        keys = [i.key for i in m.inputs] if keys is None else list(keys)
        raise ModelError(f"{what}: {keys[0] if len(keys) == 1 else keys}: {T.shape[0]} values for "
                         f"{n} poses (give one value, or one per pose)")
    return np.broadcast_to(T, (n, T.shape[1]))


def _floats(v, what: str, key: str) -> np.ndarray:
    """v as a float array; ModelError naming `what` and the input for text or other objects."""
    try:
        a = np.asarray(v)
        if a.dtype.kind in "USVMm" or isinstance(v, (str, bytes)):
            raise ValueError
        return a.astype(float, copy=False)
    except (TypeError, ValueError):
        raise ModelError(f"{what}: {key!r}: expected numbers, got {v!r:.80}") from None
