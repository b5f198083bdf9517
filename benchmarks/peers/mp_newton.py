"""Reference for chains with no closed form (the class-III triad): Newton's method in mpmath.

Unknowns: the coordinates of every moving point but the crank's tip (which the input places).
Equations, written here independently of kincas: for every pair of points on one link,
|P - Q|^2 - l^2 = 0 (a triangle gives its three sides), and for every slide the point's
distance from its line, u x (P - T) = 0. Each pose starts from the one before (the first
from the case's guess), and Newton runs at `dps` digits until the step is below 1e-25 of the
size: far beyond float64. Velocities solve the differentiated equations J v = -(dg/dA) V_A.

>>> import cases
>>> c = cases.fourbar(4)
>>> P, V = reference(c)
>>> Q, W = __import__("peers.closed_form", fromlist=["x"]).reference(c)
>>> bool(np.abs(P["B"] - Q["B"]).max() < 1e-15 and np.abs(V["B"] - W["B"]).max() < 1e-13)
True
"""
from __future__ import annotations

import math

import numpy as np


def pairs(case):
    """(P, Q, length) for every distance the links keep (a triangle: its three sides)."""
    out = []
    for _, pts, ls in case.links:
        if len(pts) == 2:
            out.append((pts[0], pts[1], ls[0]))
        else:
            (p, q, r), (pq, qr, pr) = pts, ls
            out += [(p, q, pq), (q, r, qr), (p, r, pr)]
    return out


def reference(case, dps: int = 30, max_iter: int = 60):
    """{point: (N, 2)} positions and velocities (NaN where Newton fails to converge)."""
    import mpmath
    mp = mpmath.mp
    o, tip, rad = case.crank
    free = [p for p in case.moving if p != tip]
    col = {p: 2 * i for i, p in enumerate(free)}
    cons = pairs(case)
    n, L = len(case.theta), case.size
    names = list(case.ground) + list(case.moving)
    Pout = {k: np.full((n, 2), np.nan) for k in names}
    Vout = {k: np.full((n, 2), np.nan) for k in names}
    ok = False
    with mpmath.workdps(dps):
        x = mpmath.matrix([mp.mpf(c) for p in free for c in case.guess[p]])
        gnd = {g: (mp.mpf(v[0]), mp.mpf(v[1])) for g, v in case.ground.items()}
        for i, th in enumerate(case.theta):
            th = mp.mpf(float(th))
            A = (gnd[o][0] + rad * mp.cos(th), gnd[o][1] + rad * mp.sin(th))
            VA = (-case.omega * rad * mp.sin(th), case.omega * rad * mp.cos(th))

            def pos(p, x):
                return (x[col[p]], x[col[p] + 1]) if p in col else (A if p == tip else gnd[p])

            def system(x):
                m = len(free) * 2
                g, J = mpmath.matrix(m, 1), mpmath.matrix(m, m)
                rows = 0
                for p, q, l in cons:  # |P - Q|^2 - l^2 and its gradient 2 (P - Q), -2 (P - Q)
                    (px, py), (qx, qy) = pos(p, x), pos(q, x)
                    g[rows] = (px - qx) ** 2 + (py - qy) ** 2 - mp.mpf(l) ** 2
                    for pt, sgn in ((p, 1), (q, -1)):
                        if pt in col:
                            J[rows, col[pt]] += 2 * sgn * (px - qx)
                            J[rows, col[pt] + 1] += 2 * sgn * (py - qy)
                    rows += 1
                for p, t, ang in case.slides:  # u x (P - T)
                    ux, uy = mp.cos(mp.mpf(ang)), mp.sin(mp.mpf(ang))
                    (px, py), (tx, ty) = pos(p, x), gnd[t]
                    g[rows] = ux * (py - ty) - uy * (px - tx)
                    J[rows, col[p]], J[rows, col[p] + 1] = -uy, ux
                    rows += 1
                return g, J

            if i > 0 and ok:  # predict along the tangent: dx/dtheta = v / omega
                x = x + v * (th - thprev) / case.omega
            ok = False
            for _ in range(max_iter):
                g, J = system(x)
                try:
                    dx = mpmath.lu_solve(J, -g)
                except ZeroDivisionError:
                    break
                x = x + dx
                if mpmath.mnorm(dx, 1) < mp.mpf(10) ** -25 * L:
                    ok = True
                    break
            if not ok:
                x = mpmath.matrix([mp.mpf(c) for p in free for c in case.guess[p]]) if i == 0 else xprev
                continue
            xprev, thprev = x, th
            # velocities: d/dt |P - Q|^2 = 2 (P - Q).(V_P - V_Q) = 0, known V_A moved to the right
            _, J = system(x)
            rhs = mpmath.matrix(J.rows, 1)
            for r_, (p, q, l) in enumerate(cons):
                (px, py), (qx, qy) = pos(p, x), pos(q, x)
                for pt, sgn in ((p, 1), (q, -1)):
                    if pt == tip:
                        rhs[r_] -= 2 * sgn * ((px - qx) * VA[0] + (py - qy) * VA[1])
            v = mpmath.lu_solve(J, rhs)
            for p in free:
                Pout[p][i] = [float(x[col[p]]), float(x[col[p] + 1])]
                Vout[p][i] = [float(v[col[p]]), float(v[col[p] + 1])]
            Pout[tip][i] = [float(A[0]), float(A[1])]
            Vout[tip][i] = [float(VA[0]), float(VA[1])]
    for g, xy in case.ground.items():
        Pout[g][:] = xy
        Vout[g][:] = 0.0
    return Pout, Vout
