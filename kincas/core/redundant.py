"""Redundant joints: mobility decided by the rank of the constraint Jacobian, not by counting.

Counting (Gruebler: unknowns minus equations) assumes every equation independent. A
parallelogram four-bar with a third parallel link has 3 unknown angles and 4 closure
equations, a count of 0, yet it moves with 1 degree of freedom: at every assembly one
closure equation is implied by the others. Where the count gives fewer freedoms than inputs,
`decide(m)` runs the test below once per mechanism, at its first solve (`kincas.model_of`)
or when `Mechanism.redundant` is read; declaring a mechanism runs no numerics, and ordinary
mechanisms never pay for it.

With x = (q, u) (unknowns and inputs) and G = g_x = [g_q g_u], at a generic assembly x*
(g(x*) = 0, the ranks locally constant):
- rank g_q = nq: the inputs fix the unknowns (no freedom is left undriven);
- rank G = nq: every input column lies in g_q's column space, so the inputs can move
  independently and the tall system stays consistent (real mobility nq + nu - rank G = nu);
- the redundant equations are then ng - nq of them.

The rule: the mechanism is accepted when one of its assemblies lies on a branch the inputs
drive, judged at a generic point of that branch, never at the assembly found first. Ranks
at one point depend on the point: at a change point (the links in line) G loses rank, and
the double parallelogram also has isolated assemblies of its anti-parallelogram, where G
has full rank; Gauss-Newton started from a guess inconsistent with the inputs' start ends
at either (turned by 10-150 degrees, the docstring's example below was once refused for 92
of 120 guesses). So:
1. assemblies are found by Gauss-Newton on g(x) = 0 with the inputs free (minimum-norm
   steps: wide in x), from the guess with each angle input turned through `TURNS` angles
   around the circle, the starts most consistent with the guess first;
2. from each, the inputs are moved a random step (`MOVE`, either way, then a tenth of it)
   and q solved with them fixed: a point reached so is generic (special positions are a
   set of measure zero in the inputs), and one where rank g_q = rank G = nq, with g_q's
   smallest singular value clear of zero (`RANK_GAP`), accepts the mechanism;
3. otherwise the mechanism is refused, and the message gives the most freedoms found at a
   generic point of any assembly's branch (each chain coordinate moved in turn, the others
   solved for: 0 where none moves, at an isolated assembly).
An isolated assembly cannot pass step 2 (no assembly at the moved inputs), nor can inputs
that overdrive the chain (moved independently, they find no assembly).

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

from ..errors import ModelError
from ..model import mechanism as _mechanism
from .caches import Memo
from .newton import newton
from .tolerances import GENERIC_MOVE as MOVE, JITTER, RANK as RANK_TOL, RANK_GAP, SAME_ASSEMBLY

TURNS = 12  # an angle input is tried at this many angles around the circle
MOVE_ITER = 15  # Gauss-Newton iterations after such a step (quadratic from that close)
ASSEMBLIES = 8  # distinct assemblies examined at most (a wrong mechanism pays for each)


def _start_inputs(m) -> np.ndarray:
    """Input values read off the guess: an angle input takes the angle that points its link
    at a guessed or ground point, a driven parameter its declared value, a slide 0."""
    known = {k: tuple(map(m.value, xy)) for k, xy in (*m.ground, *m.guess)}
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


class _Chain:
    """The constraint g(x) = 0 in x = (q, u) of one mechanism at its parameter values, with
    per coordinate the unit of a step (1 for an angle, the size L for a length: slides and
    driven parameters count as lengths) and G = [g_q g_u] column-scaled by it over L, so
    the singular values compared with `RANK_TOL` mean the same at any size."""

    def __init__(self, m, model):
        self.model, self.nq, self.nu = model, model.nq, len(m.inputs)
        self.p = np.array([v for _, v in m.parameters], float)
        self.L = m.size()
        self.angle = np.concatenate([~model.sym.is_length, [i.is_angle for i in m.inputs]])
        self.unit = np.where(self.angle, 1.0, self.L)
        # the chain's own coordinates: q and the inputs that are not driven parameters
        self.chain = np.array(list(range(self.nq)) + [self.nq + k for k, i in enumerate(m.inputs)
                                                      if i.kind != "parameter"], int)

    def G(self, x) -> np.ndarray:
        _, J, Ju = self.model._tangent(x[:self.nq], x[self.nq:], self.p)
        return np.hstack([J, Ju]) * self.unit / self.L

    def residual(self, x) -> float:
        g = self.model.residual(x[:self.nq], x[self.nq:], self.p)
        r = float(np.abs(g).max(initial=0.0)) / self.L
        return r if np.isfinite(r) else np.inf

    def solve(self, x, free, max_iter=60) -> np.ndarray | None:
        """The assembly reached by Gauss-Newton on g = 0 in the coordinates `free` (indices
        into x; the others stay as they are), from x (kincas/core/newton.py: minimum-norm
        steps where the system is wide, least squares where tall); None if none is reached."""
        x = np.array(x, float)
        nq = self.nq

        def F(z):
            x[free] = z
            _, J, Ju = self.model._tangent(x[:nq], x[nq:], self.p)
            return self.model.residual(x[:nq], x[nq:], self.p), np.hstack([J, Ju])[:, free]

        res = newton(F, x[free], self.unit[free], np.full(self.model.ng, self.L),
                     max_iter=max_iter)
        if not res.ok:
            return None
        x[free] = res.x
        return x

    def same(self, x, y) -> bool:
        """Whether assemblies x and y are one (angles compared modulo a turn)."""
        d = (x - y) / self.unit
        d = np.where(self.angle, np.angle(np.exp(1j * d)), d)
        return bool(np.abs(d).max(initial=0.0) < SAME_ASSEMBLY)

    def ranks(self, x):
        """(rank G, freedoms of the chain, whether the inputs drive it) at the assembly x:
        they drive it where g_q has full column rank nq, its smallest singular value clear
        of zero (`RANK_GAP`), and rank G = nq (every input column in g_q's column space)."""
        G, nq = self.G(x), self.nq
        s_all = np.linalg.svd(G, compute_uv=False)
        s_q = np.linalg.svd(G[:, :nq], compute_uv=False)
        s_c = np.linalg.svd(G[:, self.chain], compute_uv=False)
        top = max(s_all[0] if s_all.size else 1.0, 1.0)
        rank_g = int(np.sum(s_all > RANK_TOL * top))
        rank_q = int(np.sum(s_q > RANK_TOL * top))
        free = self.chain.size - int(np.sum(s_c > RANK_TOL * top))
        regular = rank_q == nq and (nq == 0 or s_q[nq - 1] > RANK_GAP * top)
        return rank_g, free, regular and rank_g == nq


def _starts(m, chain, rng) -> list[np.ndarray]:
    """Starting points (q, u) for the assembly, the most consistent first: the guess placed
    with the inputs read off it, and with each angle input turned through the circle (an
    input whose link has no guessed point is otherwise a blind 0.3 rad, inconsistent with
    the guessed points: Gauss-Newton from there may end anywhere)."""
    guess = {k: tuple(map(m.value, xy)) for k, xy in m.guess}
    # a spatial model starts where it is drawn: joint coordinates 0 (kincas/core/space_model.py)
    drawn = getattr(chain.model, "drawing_inputs", None)
    u0 = _start_inputs(m) if drawn is None else drawn(chain.p)
    us = [u0]
    for k, inp in enumerate(m.inputs):
        if inp.kind == "angle":
            for j in range(1, TURNS):
                u = u0.copy()
                u[k] += 2 * math.pi * j / TURNS
                us.append(u)
    xs = [np.concatenate([chain.model.initial_q(u, chain.p, guess, chain.L), u]) for u in us]
    xs.sort(key=chain.residual)  # stable: the guess first among equals
    # off any special position the guess may sit on (links in line)
    return [x + JITTER * rng.standard_normal(x.size) * chain.unit for x in xs]


def _inputs_move(chain, x, rng) -> np.ndarray | None:
    """An assembly where the inputs drive the chain, reached from the assembly x by moving
    the inputs a random step (`MOVE` rad or MOVE L, then a tenth of it: x may sit near the
    end of the inputs' range) and solving for q with them fixed; None if none is found.
    The step is random, so the point reached is a generic point of x's branch: a change
    point or another special position is left behind (a set of measure zero)."""
    nq, free = chain.nq, np.arange(chain.nq)
    d = rng.standard_normal(chain.nu)
    d /= np.linalg.norm(d)
    for step in (MOVE, -MOVE, MOVE / 10, -MOVE / 10):
        y = x.copy()
        y[nq:] += step * d * chain.unit[nq:]
        y = chain.solve(y, free, MOVE_ITER)
        if y is not None and chain.ranks(y)[2]:
            return y
    return None


def _freedoms(chain, x, rng) -> int:
    """The chain's freedoms at the assembly x, at a generic point of its branch: each chain
    coordinate in turn is moved (`MOVE`, either way) and the others solved for (parameters
    fixed); the freedoms counted by the rank at the points reached, the most of them (the
    branch of highest dimension through x). 0 when no coordinate moves: x is isolated."""
    best = None
    for j in chain.chain:
        rest = chain.chain[chain.chain != j]
        for sign in (1.0, -1.0):
            y = x.copy()
            y[j] += sign * MOVE * (1 + 0.1 * rng.random()) * chain.unit[j]
            y = chain.solve(y, rest, MOVE_ITER)
            if y is not None:
                free = chain.ranks(y)[1]
                best = free if best is None else max(best, free)
    return 0 if best is None else best


def rank_test(m, model):
    """(real freedoms, redundant equations, ok) of `m`, decided at generic assemblies.

    `ok` when some assembly lies on a branch the inputs drive: moved a random step from it,
    the inputs still find an assembly, where rank g_q = rank [g_q g_u] = nq. Else the real
    freedoms are the most found at a generic point of any assembly's branch (the chain's
    coordinates: q and the inputs that are not driven parameters); None for both numbers
    when no assembly was found at all."""
    chain = _Chain(m, model)
    rng = np.random.default_rng(7)  # fixed seed: the same answer every time
    found, free = [], None
    for x in _starts(m, chain, rng):
        x = chain.solve(x, np.arange(x.size))
        if x is None or any(chain.same(x, y) for y in found):
            continue
        found.append(x)
        if len(found) > ASSEMBLIES:
            break
        y = _inputs_move(chain, x, rng)
        if y is not None:
            return chain.ranks(y)[1], model.ng - chain.nq, True
        f = _freedoms(chain, x, rng)
        free = f if free is None else max(free, f)
    return free, None, False


# --- the decision, once per mechanism ---

# mechanism -> redundant equations, or the ModelError message
_DECIDED = Memo("redundant-joint decisions", bound=256)


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
    known = _DECIDED.get_or_build(m, lambda: _decision(m, model))
    if isinstance(known, str):
        raise ModelError([known])
    return known


def _decision(m, model):
    free, redundant, ok = rank_test(m, model)
    return redundant if ok else _mechanism.mobility_problem(m, free, tested=True)

