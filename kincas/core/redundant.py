"""Redundant joints: mobility decided by the rank of the constraint Jacobian, not by counting.

Counting (Gruebler: unknowns minus equations) assumes every equation independent. A
parallelogram four-bar with a third parallel link has 3 unknown angles and 4 closure
equations, a count of 0, yet it moves with 1 degree of freedom: at every assembly one
closure equation is implied by the others. `kincas.model` asks this module only when the
count gives fewer freedoms than inputs (so ordinary mechanisms never pay for it).

With x = (q, u) (unknowns and inputs) and G = g_x = [g_q g_u], an assembly x* (g(x*) = 0)
where the ranks are locally constant decides:
- rank g_q = nq: the inputs fix the unknowns (no freedom is left undriven);
- rank G = nq: every input column lies in g_q's column space, so the inputs can move
  independently and the tall system stays consistent (real mobility nq + nu - rank G = nu);
- the redundant equations are then ng - nq of them.
The assembly is found by Gauss-Newton on g(x) = 0 with the inputs free (minimum-norm
least-squares steps: the system is underdetermined in x), from the guessed points, and then
moved a small generic step along the null space of G and re-assembled: special positions
(links collinear at a change point) have lower rank than the chain, and a generic point of
the configuration manifold has none of them.

>>> import kincas
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0), "E": (2, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1),
...            kincas.Link("coupler", {"B": (0, 0), "C": (4, 0), "F": (2, 0)}),
...            kincas.Link.bar("rocker", "D", "C", 1), kincas.Link.bar("rocker2", "E", "F", 1)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (4.5, 0.8), "F": (2.5, 0.8)})
>>> m.mobility, m.redundant                     # counted 0 freedoms; 1 equation is redundant
(0, 1)
"""
from __future__ import annotations

import math

import numpy as np

RANK_TOL = 1e-8  # a scaled singular value below this times the largest one counts as zero
GAP = 1e-4  # ... and the smallest one kept must stand above this (a regular assembly)


def _start_inputs(m) -> np.ndarray:
    """Input values read off the guess: an angle input takes the angle that points its link
    at a guessed or ground point, a driven parameter its declared value, a slide 0."""
    known = {k: (m.value(x), m.value(y)) for k, (x, y) in (*m.ground, *m.guess)}
    u = []
    for inp in m.inputs:
        v = 0.0
        if inp.kind == "parameter":
            v = m.parameter(inp.target)
        elif inp.kind == "angle":
            lk = m.link(inp.target)
            ref = [(p, lk.local(p)) for p in lk.point_names if p in known]
            v = 0.3  # generic: an angle 0 often puts links in line (a special position)
            if len(ref) >= 2:
                (a, la), (b, lb) = ref[:2]
                d = np.subtract(known[b], known[a])
                dl = (m.value(lb[0]) - m.value(la[0]), m.value(lb[1]) - m.value(la[1]))
                v = math.atan2(d[1], d[0]) - math.atan2(dl[1], dl[0])
        u.append(v)
    return np.array(u, float)


def _assemble(model, x, p, L, scale, max_iter=60):
    """Gauss-Newton on g(q, u) = 0 in x = (q, u), minimum-norm steps in scaled coordinates
    (angles as they are, lengths over L), backtracking on the residual. Returns (x, residual)."""
    nq = model.nq

    def ev(x):
        g, J, Ju = model._tangent(x[:nq], x[nq:], p)
        return g.ravel().copy(), np.hstack([J, Ju]) * scale

    g, G = ev(x)
    r = np.abs(g).max(initial=0.0) / L
    for _ in range(max_iter):
        if r <= 1e-14:
            break
        dz = np.linalg.lstsq(G, -g, rcond=None)[0]
        dz /= max(1.0, np.abs(dz).max() / 0.5)  # at most half a radian (or L/2) per step
        t = 1.0
        while t >= 1 / 64:
            xn = x + t * dz * scale
            gn, Gn = ev(xn)
            rn = np.abs(gn).max(initial=0.0) / L
            if rn < r:
                break
            t /= 2
        if not rn < r:
            break
        x, g, G, r = xn, gn, Gn, rn
    return x, r, G


def rank_test(m):
    """(real freedoms, redundant equations, ok) of `m` at a generic assembly near its guess.

    `ok` when the inputs drive the chain exactly (rank g_q = rank [g_q g_u] = nq); the real
    freedoms are those of the chain's coordinates (q and the inputs that are not driven
    parameters): their number less the rank of their Jacobian. None for both numbers when
    no assembly was found near the guess."""
    from .numeric import compile
    from ..analysis.singular import _scales
    model = compile(m)
    nq = model.nq
    p = np.array([v for _, v in m.parameters], float)
    L = m.size()
    guess = {k: (m.value(x), m.value(y)) for k, (x, y) in m.guess}
    u0 = _start_inputs(m)
    cq, cu = _scales(model, L)
    scale = 1.0 / np.concatenate([cq, cu]) / L  # scaled coordinate * scale = coordinate
    rng = np.random.default_rng(7)  # fixed seed: the same answer every time
    x = np.concatenate([model.initial_q(u0, p, guess, L), u0])
    x = x + 1e-3 * rng.standard_normal(x.size) * scale  # off any special position
    x, r, G = _assemble(model, x, p, L, scale)
    if r > 1e-10:
        return None, None, False
    # a small generic step within the configuration manifold, then back onto it
    _, s, vt = np.linalg.svd(G)
    rank = int(np.sum(s > RANK_TOL * s[0])) if s.size else 0
    null = vt[rank:]
    if null.shape[0]:
        x, r, G = _assemble(model, x + 0.05 * (rng.standard_normal(null.shape[0]) @ null) * scale,
                            p, L, scale)
        if r > 1e-10:
            return None, None, False
    s_all = np.linalg.svd(G, compute_uv=False)
    s_q = np.linalg.svd(G[:, :nq], compute_uv=False)
    top = max(s_all[0] if s_all.size else 1.0, 1.0)
    rank_g = int(np.sum(s_all > RANK_TOL * top))
    rank_q = int(np.sum(s_q > RANK_TOL * top))
    chain = [nq + k for k, i in enumerate(m.inputs) if i.kind != "parameter"]
    s_c = np.linalg.svd(G[:, list(range(nq)) + chain], compute_uv=False)
    free = nq + len(chain) - int(np.sum(s_c > RANK_TOL * top))  # the chain's own freedoms
    regular = rank_q == nq and (nq == 0 or s_q[nq - 1] > GAP * top)
    ok = regular and rank_g == nq
    return free, model.sym.g.numel() - rank_g, ok
