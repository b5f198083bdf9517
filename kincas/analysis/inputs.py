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


def input_table(m: Mechanism, inputs, what: str, default: float | None, keys=None) -> np.ndarray:
    """(N x nu) array of one value per input and pose from a mapping key -> scalar or array
    (`keys`: the mechanism's input keys, if already at hand). Where every input has one
    value, the table has one row (N = 1), whatever the number of poses."""
    keys = [i.key for i in m.inputs] if keys is None else list(keys)
    if inputs is None and default is not None:  # every input at its default: one row
        return np.full((1, len(keys)), float(default))
    if len(keys) == 1 and isinstance(inputs, Mapping) and len(inputs) == 1 and keys[0] in inputs:
        c = np.asarray(inputs[keys[0]], dtype=float)  # the common case, one input: no copy
        if c.ndim <= 1 and c.size and np.isfinite(c).all():
            return c.reshape(-1, 1)
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
    cols = [np.atleast_1d(np.asarray(inputs.get(k, default), dtype=float)) for k in keys]
    bad = [k for k, c in zip(keys, cols) if c.ndim != 1 or not np.isfinite(c).all()]
    if bad:
        raise ModelError([f"{what}: {k!r}: expected finite numbers (one per pose)" for k in bad])
    n = max(len(c) for c in cols)
    if any(len(c) not in (1, n) for c in cols):
        raise ModelError(f"{what}: inputs that sweep advance together, so their lengths must agree")
    return np.stack([np.broadcast_to(c, (n,)) for c in cols], axis=1)
