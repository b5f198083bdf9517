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


def coefficient_maps(angles) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(A, B, C, D): the spline's polynomial coefficients on each interval as linear maps of
    the data. The second derivatives M solve the cyclic tridiagonal system
    h_{i-1} M_{i-1} + 2 (h_{i-1} + h_i) M_i + h_i M_{i+1} = 6 (s_i - s_{i-1}),
    with s_i = (r_{i+1} - r_i) / h_i the slopes of the chords (indices modulo n)."""
    h = intervals(angles)
    n = len(h)
    eye = np.eye(n)
    nxt = np.roll(eye, -1, axis=0)  # row i picks r_{i+1}
    S = (nxt - eye) / h[:, None]  # chord slopes as maps of r
    K = np.zeros((n, n))
    for i in range(n):
        K[i, (i - 1) % n] += h[i - 1]
        K[i, i] += 2 * (h[i - 1] + h[i])
        K[i, (i + 1) % n] += h[i]
    M = np.linalg.solve(K, 6 * (S - np.roll(S, 1, axis=0)))
    Mn = np.roll(M, -1, axis=0)
    A = eye
    B = S - h[:, None] * (2 * M + Mn) / 6
    C = M / 2
    D = (Mn - M) / (6 * h[:, None])
    return A, B, C, D


def evaluate(angles, radii, phi, order: int = 2) -> np.ndarray:
    """r and its first `order` derivatives in phi at the angles `phi` (rows: r, r', r'')."""
    a = np.asarray(angles, float)
    A, B, C, D = (Mx @ np.asarray(radii, float) for Mx in coefficient_maps(a))
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
