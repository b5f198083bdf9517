"""Redundant joints: mobility decided by the rank of the constraint Jacobian, not by counting.

Counting (Gruebler: unknowns minus equations) assumes every equation independent. A
parallelogram four-bar with a third parallel link has 3 unknown angles and 4 closure
equations, a count of 0, yet it moves with 1 degree of freedom: at every assembly one
closure equation is implied by the others. Where the count gives fewer freedoms than inputs,
`decide(m)` runs the test below once per mechanism, at its first solve (`kincas.compile`)
or when `Mechanism.redundant` is read; declaring a mechanism runs no numerics, and ordinary
mechanisms never pay for it.

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
import threading

import numpy as np

from ..errors import ModelError
from ..model import mechanism as _mechanism
from .newton import newton
from .tolerances import ACCEPT, RANK as RANK_TOL

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
    """Gauss-Newton on g(q, u) = 0 in x = (q, u) (kincas/core/newton.py: minimum-norm steps
    in scaled coordinates, angles as they are and lengths over L). Returns (x, residual, G)
    with G = [g_q g_u] in scaled coordinates."""
    nq = model.nq

    def F(x):
        _, J, Ju = model._tangent(x[:nq], x[nq:], p)
        g = model.residual(x[:nq], x[nq:], p)
        return g, np.hstack([J, Ju])

    res = newton(F, x, scale, np.full(model.ng, L), max_iter=max_iter)
    return res.x, res.residual, res.J * scale


def rank_test(m, model):
    """(real freedoms, redundant equations, ok) of `m` at a generic assembly near its guess.

    `ok` when the inputs drive the chain exactly (rank g_q = rank [g_q g_u] = nq); the real
    freedoms are those of the chain's coordinates (q and the inputs that are not driven
    parameters): their number less the rank of their Jacobian. None for both numbers when
    no assembly was found near the guess."""
    nq = model.nq
    p = np.array([v for _, v in m.parameters], float)
    L = m.size()
    guess = {k: (m.value(x), m.value(y)) for k, (x, y) in m.guess}
    u0 = _start_inputs(m)
    cq = model.column_scale(L)
    cu = np.array([1.0 / L if i.kind == "angle" else 1.0 for i in m.inputs])
    scale = 1.0 / np.concatenate([cq, cu]) / L  # scaled coordinate * scale = coordinate
    rng = np.random.default_rng(7)  # fixed seed: the same answer every time
    x = np.concatenate([model.initial_q(u0, p, guess, L), u0])
    x = x + 1e-3 * rng.standard_normal(x.size) * scale  # off any special position
    x, r, G = _assemble(model, x, p, L, scale)
    if r > ACCEPT:
        return None, None, False
    # a small generic step within the configuration manifold, then back onto it
    _, s, vt = np.linalg.svd(G)
    rank = int(np.sum(s > RANK_TOL * s[0])) if s.size else 0
    null = vt[rank:]
    if null.shape[0]:
        x, r, G = _assemble(model, x + 0.05 * (rng.standard_normal(null.shape[0]) @ null) * scale,
                            p, L, scale)
        if r > ACCEPT:
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


# --- the decision, once per mechanism ---

_DECIDED: dict = {}  # mechanism -> redundant equations, or the ModelError message
_LOCK = threading.Lock()


def decide(m, model) -> int:
    """The number of redundant equations of `m`; `ModelError` (naming [inputs]) when the
    inputs are genuinely wrong in number. Counting decides where it can; the rank test runs
    only where counting gives fewer freedoms than inputs, once per mechanism value, on
    `model` (the model of m's structure).

    >>> import kincas
    >>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
    ...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 4),
    ...            kincas.Link.bar("rocker", "D", "C", 1)],
    ...     inputs=[kincas.Input.angle("crank")], guess={"C": (4.5, 0.8)})
    >>> decide(m, None)  # a four-bar: counting suffices
    0
    """
    if not _mechanism.needs_rank_test(m):
        return 0
    with _LOCK:
        known = _DECIDED.get(m)
    if known is None:
        free, redundant, ok = rank_test(m, model)
        known = redundant if ok else _mechanism.mobility_problem(m, free, tested=True)
        with _LOCK:
            _DECIDED[m] = known
            while len(_DECIDED) > 256:
                _DECIDED.pop(next(iter(_DECIDED)))
    if isinstance(known, str):
        raise ModelError([known])
    return known

