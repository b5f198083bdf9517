"""Periodic cubic splines in an angle, as linear maps from the data (numpy only).

A polar cam profile r(phi) is given at increasing angles phi_0 < ... < phi_{n-1} spanning
less than a turn, and closed by the periodic cubic spline with period 2 pi: C2 everywhere,
the last interval running from phi_{n-1} to phi_0 + 2 pi. For fixed knots the spline's
coefficients are linear in the radii, so `coefficient_maps(angles)` returns four (n x n)
matrices A, B, C, D with, on interval i and t = phi - phi_i,

    r(phi) = (A r)_i + (B r)_i t + (C r)_i t^2 + (D r)_i t^3,

which lets the core write r(phi) with symbolic radii (sensitivities to a radius are exact).

>>> import numpy as np
>>> ang = np.linspace(0, 2 * np.pi, 8, endpoint=False)
>>> r = evaluate(ang, 40 + 5 * np.cos(ang), np.array([0.3, 2.0]))
>>> bool(np.allclose(r[0], 40 + 5 * np.cos([0.3, 2.0]), atol=0.05))
True
"""
from __future__ import annotations

import numpy as np

TURN = 2 * np.pi


def intervals(angles) -> np.ndarray:
    """Lengths h_i of the n intervals, the last one closing the turn."""
    a = np.asarray(angles, float)
    return np.diff(np.append(a, a[0] + TURN))


def _cyclic_solve(h: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Solve the cyclic tridiagonal system of the periodic spline's second derivatives,
    h_{i-1} x_{i-1} + 2 (h_{i-1} + h_i) x_i + h_i x_{i+1} = rhs_i (indices modulo n), for
    every column of rhs, in O(n) per column (Thomas's algorithm with the Sherman-Morrison
    correction for the two corner entries)."""
    n = len(h)
    lower, diag, upper = np.roll(h, 1), 2 * (np.roll(h, 1) + h), h.copy()  # row i: h_{i-1}, ..., h_i
    if n == 3:  # too small for the correction's splitting: solve it directly
        K = np.diag(diag)
        for i in range(n):
            K[i, (i - 1) % n] += lower[i]
            K[i, (i + 1) % n] += upper[i]
        return np.linalg.solve(K, rhs)
    gamma = -diag[0]
    d = diag.copy()
    d[0] -= gamma
    d[-1] -= upper[-1] * lower[0] / gamma
    u = np.zeros(n)
    u[0], u[-1] = gamma, upper[-1]  # K = T + u v', v = (1, 0, ..., 0, lower_0 / gamma)

    def thomas(b):
        b = np.array(b, float)
        c, dd = np.zeros(n), d.copy()
        c[0] = upper[0] / dd[0]
        b[0] = b[0] / dd[0]
        for i in range(1, n):
            m = dd[i] - lower[i] * c[i - 1]
            c[i] = upper[i] / m if i < n - 1 else 0.0
            b[i] = (b[i] - lower[i] * b[i - 1]) / m
        for i in range(n - 2, -1, -1):
            b[i] -= c[i] * b[i + 1]
        return b
    y, z = thomas(rhs), thomas(u)
    fact = (y[0] + lower[0] * y[-1] / gamma) / (1 + z[0] + lower[0] * z[-1] / gamma)
    return y - np.multiply.outer(z, fact) if y.ndim > 1 else y - fact * z


def coefficients(angles, radii) -> tuple[np.ndarray, ...]:
    """(a, b, c, d) on each interval for the data `radii` (a vector, or a matrix whose
    columns are several data sets): see `coefficient_maps`."""
    h = intervals(angles)
    r = np.asarray(radii, float)
    hh = h if r.ndim == 1 else h[:, None]
    S = (np.roll(r, -1, axis=0) - r) / hh  # chord slopes
    M = _cyclic_solve(h, 6 * (S - np.roll(S, 1, axis=0)))
    Mn = np.roll(M, -1, axis=0)
    return r, S - hh * (2 * M + Mn) / 6, M / 2, (Mn - M) / (6 * hh)


def coefficient_maps(angles) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(A, B, C, D): the spline's polynomial coefficients on each interval as linear maps of
    the data. The second derivatives M solve the cyclic tridiagonal system
    h_{i-1} M_{i-1} + 2 (h_{i-1} + h_i) M_i + h_i M_{i+1} = 6 (s_i - s_{i-1}),
    with s_i = (r_{i+1} - r_i) / h_i the slopes of the chords (indices modulo n)."""
    return coefficients(angles, np.eye(len(angles)))


def evaluate(angles, radii, phi, order: int = 2) -> np.ndarray:
    """r and its first `order` derivatives in phi at the angles `phi` (rows: r, r', r'')."""
    a = np.asarray(angles, float)
    A, B, C, D = coefficients(a, radii)
    t = np.mod(np.asarray(phi, float) - a[0], TURN)
    i = np.clip(np.searchsorted(a - a[0], t, side="right") - 1, 0, len(a) - 1)
    t = t - (a[i] - a[0])
    rows = [A[i] + t * (B[i] + t * (C[i] + t * D[i])), B[i] + t * (2 * C[i] + 3 * t * D[i]),
            2 * C[i] + 6 * t * D[i]]
    return np.array(rows[:order + 1])


def curvature(r, dr, ddr) -> np.ndarray:
    """Signed curvature of the polar curve r(phi), positive where it is convex (turns left
    as phi increases): (r^2 + 2 r'^2 - r r'') / (r^2 + r'^2)^(3/2)."""
    return (r * r + 2 * dr * dr - r * ddr) / (r * r + dr * dr) ** 1.5
