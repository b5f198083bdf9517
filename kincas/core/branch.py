"""The branch test, written once: which Assur groups changed assembly mode.

A group's mode is the sign of the determinant of its column-scaled block of g_q (+1 or -1;
0 where the block is too close to singular to tell: kincas/core/assembly.py's `modes`). Two
poses are on the same branch of a group unless both modes are defined and they differ: a
mode of 0 at either end says nothing (the sweep's events locate a crossing there), and a
change between two defined modes means a singular position of the group was crossed (det
g_q is continuous along the branch and vanishes only there).

>>> import numpy as np
>>> changed(np.array([1, -1, 0, 1]), np.array([1, 1, -1, 0])).tolist()
[False, True, False, False]
"""
from __future__ import annotations

import numpy as np


def changed(a, b) -> np.ndarray:
    """Elementwise: the modes `a` and `b` (arrays of -1, 0, +1, broadcast together) differ
    and neither is 0 (undefined). Along an axis of poses, `changed(s[:-1], s[1:])` marks
    each step where a group changed mode.

    >>> import numpy as np
    >>> s = np.array([[1, 1], [1, 0], [-1, -1]])
    >>> changed(s[:-1], s[1:]).tolist()
    [[False, False], [True, False]]
    >>> bool(changed(np.array([1, 1]), np.array([1, 1])).any())
    False
    """
    a, b = np.asarray(a), np.asarray(b)
    return (a != b) & (a != 0) & (b != 0)


def kept(sign0, s) -> np.ndarray:
    """Whether the modes s (one row per pose or design, or one) kept sign0 in every group
    where both are defined (sign0 None, or of another length: no mode to keep).

    >>> kept(np.array([1, -1]), np.array([[1, -1], [1, 0], [-1, -1]])).tolist()
    [True, True, False]
    """
    s = np.asarray(s)
    if sign0 is None or s.shape[-1] != len(sign0):
        return np.ones(s.shape[:-1], dtype=bool)
    return ~changed(s, sign0).any(axis=-1)
