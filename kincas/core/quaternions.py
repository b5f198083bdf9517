"""Quaternions and 3-vectors as lists of expressions (CasADi SX or numbers): the products the
spatial model writes its equations with (kincas/core/space_symbolic.py, space_dynamics.py).

>>> qmul([0, 1, 0, 0], [0, 0, 1, 0])  # i j = k
[0, 0, 0, 1]
>>> rotation([1, 0, 0, 0])[0]
[1, 0, 0]
"""
from __future__ import annotations


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def qmul(a, b):
    """The quaternion product a (x) b."""
    av, bv, c = a[1:], b[1:], cross(a[1:], b[1:])
    return [a[0] * b[0] - dot(av, bv)] + [a[0] * bv[i] + b[0] * av[i] + c[i] for i in range(3)]


def conj(e):
    return [e[0], -e[1], -e[2], -e[3]]


def rotation(e):
    """R(e) in its homogeneous quadratic form: |e|^2 times the rotation of e/|e| (the
    rotation itself where e.e = 1, as at every solution)."""
    w, x, y, z = e
    return [[w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z]]


def apply(R, v):
    return [R[i][0] * v[0] + R[i][1] * v[1] + R[i][2] * v[2] for i in range(3)]


def apply_t(R, v):
    return [R[0][i] * v[0] + R[1][i] * v[1] + R[2][i] * v[2] for i in range(3)]


