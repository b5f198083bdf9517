"""The spatial mechanisms of bench_space.py once, tool-neutral, with their closed forms.

RSSR: crank A-B about z at A = 0 (radius R_CRANK), rocker D-C about x at D (radius R_ROCK),
a coupler bar B-C of length LC with a spherical joint at each end. The rocker's angle phi
(C = D + R_ROCK (0, -sin phi, cos phi)) solves |B - C| = LC by hand:
a sin phi + b cos phi = c.

Bennett (1903): four revolute joints, links (a, alpha), (b, beta), (a, alpha), (b, beta) in
Denavit-Hartenberg form with a / sin(alpha) = b / sin(beta); its joint angles keep
tan(th1/2) tan(th2/2) = sin((beta + alpha)/2) / sin((beta - alpha)/2), th3 = -th1, th4 = -th2,
so every joint origin is a product of DH transforms: the closed form of every position.
Same numbers as examples/space_bennett.toml (a = 100, alpha = 40 deg, beta = 70 deg, th1 = 1
rad at the drawing).

>>> B, C = rssr_points([0.7, 2.0])
>>> np.round(np.linalg.norm(C - B, axis=1), 12).tolist()   # the coupler keeps its length
[125.0, 125.0]
>>> O, z = bennett_frames(1.3)
>>> bool(np.allclose(O[3], bennett_frames(1.0)[0][3]))   # the ground joint O4 does not move
True
"""
from __future__ import annotations

import math

import numpy as np

R_CRANK, R_ROCK, LC, D = 15.0, 60.0, 125.0, np.array([100.0, 40.0, 30.0])
A_BEN, AL_BEN, BE_BEN, TH10_BEN = 100.0, math.radians(40), math.radians(70), 1.0
B_BEN = A_BEN * math.sin(BE_BEN) / math.sin(AL_BEN)


def rssr_by_hand(th):
    """The rocker's angle phi from |B - C| = lc: a sin phi + b cos phi = c, the root on the
    drawing's branch (phi near 0 at th = 0)."""
    th = np.asarray(th, float)
    bx, by = R_CRANK * np.cos(th), R_CRANK * np.sin(th)
    a, b = -2 * R_ROCK * (D[1] - by), 2 * R_ROCK * D[2]
    c = LC ** 2 - (D[0] - bx) ** 2 - (D[1] - by) ** 2 - D[2] ** 2 - R_ROCK ** 2
    roots = [np.arctan2(a, b) + s * np.arccos(c / np.hypot(a, b)) for s in (1, -1)]
    r0 = [np.angle(np.exp(1j * np.atleast_1d(r)[0])) for r in roots]
    return roots[int(np.argmin(np.abs(r0)))]


def rssr_points(th):
    """(B, C), each (n, 3), at crank angles th (closed form)."""
    th = np.atleast_1d(np.asarray(th, float))
    phi = rssr_by_hand(th)
    B = R_CRANK * np.stack([np.cos(th), np.sin(th), 0 * th], 1)
    C = D[None, :] + R_ROCK * np.stack([0 * phi, -np.sin(phi), np.cos(phi)], 1)
    return B, C


def dh(theta, a, alpha):
    """Denavit-Hartenberg: Rz(theta) Tx(a) Rx(alpha)."""
    c, s, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
    return np.array([[c, -s * ca, s * sa, a * c], [s, c * ca, -c * sa, a * s], [0, sa, ca, 0], [0, 0, 0, 1.0]])


def bennett_theta2(t1):
    k = math.sin((BE_BEN + AL_BEN) / 2) / math.sin((BE_BEN - AL_BEN) / 2)
    return 2 * math.atan(k / math.tan(t1 / 2))


def bennett_frames(t1):
    """Joint origins O1..O4 (4, 3) and axes z1..z4 (4, 3) at input angle t1 (DH, closed form)."""
    t2 = bennett_theta2(t1)
    F = [np.eye(4)]
    for T in (dh(t1, A_BEN, AL_BEN), dh(t2, B_BEN, BE_BEN), dh(-t1, A_BEN, AL_BEN)):
        F.append(F[-1] @ T)
    return np.array([f[:3, 3] for f in F]), np.array([f[:3, 2] for f in F])


def bennett_points(u):
    """(O2, O3, O4), each (n, 3), with the input turned by u from the drawing (th1 = 1 + u)."""
    O = np.array([bennett_frames(TH10_BEN + float(x))[0] for x in np.atleast_1d(u)])
    return O[:, 1], O[:, 2], O[:, 3]
