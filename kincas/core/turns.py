"""The whole turns of angles that gears, racks and relative inputs tie together.

A pin or a slide sees an angle only through its sine and cosine: adding 2 pi to it changes
nothing. Gears, racks and relative inputs relate the angles themselves, linearly,

    sum_i a_i theta_i + c = 0,

gear pair: a = (r2, -sign r1, sign r1 - r2) on (theta2, theta1, theta_carrier), c = -r2 phase;
rack: a = (sigma r, -sigma r) on (theta_pinion, theta_rack), c = s - offset (s, the slide's
coordinate, depends on the angles only through sines and cosines); relative input "A/B":
a = (1, -1) on (theta_A, theta_B), c = -u. So a turn more or less of an angle tied by one of
them is another pose (a rack one pitch circumference further along), or no pose at all, and
a start whose turns disagree with a relation is whole turns away from every solution there:
Newton, whose steps are bounded to `MAX_STEP` radians, then wanders off or lands on some
other turn. `turns` gives such a start the turns the relations want, propagating from the
inputs (an input angle enters as given) and from the guessed positions (a rack's s);
`free` tells the angles whose turn is free (in no relation), which start in (-pi, pi].

>>> import numpy as np, kincas
>>> from kincas.model import Gear
>>> m = kincas.Mechanism(ground={"A": (0, 0), "B": (45, 0)},
...     links=[kincas.Link.bar("g1", "A", "P", 30), kincas.Link.bar("g2", "B", "Q", 15)],
...     gears=[Gear(("g1", "g2"), (30, 15))], inputs=[kincas.Input.angle("g1")])
>>> model = kincas.model_of(m)
>>> q = turns(model, np.array([0.5]), np.array([20.0]), np.zeros(0))  # g2 = -2 g1 = -40 rad
>>> bool(abs(q[0] + 40) <= np.pi), bool(np.isclose(np.sin(q[0]), np.sin(0.5)))
(True, True)
"""
from __future__ import annotations

import math

import casadi as ca
import numpy as np

from ..model.joints import split_relative
from ..model.mechanism import GROUND
from .tolerances import NEARER, ROUNDING_REL, TINY

TURN = 2 * math.pi
ROOT_TURNS = 3  # a component of relations tied to no input: its first angle tries this many turns either way


def wrap(a):
    """Angles taken into (-pi, pi]."""
    w = np.mod(np.asarray(a, float) + math.pi, TURN) - math.pi
    return np.where(w == -math.pi, math.pi, w)


def _relations(model):
    """(slots, f): per relation its terms' slots, ("q", j) an unknown angle, ("u", k) an
    input angle, None the ground; f(q, u, p) -> every term's coefficient, then every
    relation's constant (built once per model)."""
    def build():
        sym = model.sym
        m = sym.mech
        index = {name: j for j, (name, _) in enumerate(sym.unknowns)}
        given = {i.target: k for k, i in enumerate(m.inputs)
                 if i.kind == "angle" and split_relative(i.target) is None}

        def slot(body):
            if body == GROUND:
                return None
            if f"{body}.angle" in index:
                return ("q", index[f"{body}.angle"])
            return ("u", given[body])
        slots, coef, const = [], [], []
        for k, inp in enumerate(m.inputs):
            rel = split_relative(inp.target) if inp.kind == "angle" else None
            if rel is not None:
                slots.append([slot(rel[0]), slot(rel[1])])
                coef += [ca.SX(1), ca.SX(-1)]
                const.append(-sym.u[k])
        for g in m.gears:
            r1, r2 = (sym.val(r) for r in g.radii)
            slots.append([slot(g.links[1]), slot(g.links[0]), slot(g.carrier)])
            coef += [r2, -g.sign * r1, g.sign * r1 - r2]
            const.append(-r2 * sym.val(g.phase))
        for r in m.racks:
            sr = r.sigma * sym.val(r.radius)
            slots.append([slot(r.pinion), slot(m.slide(r.slide).along)])
            coef += [sr, -sr]
            const.append(sym.slide_s[r.slide] - sym.val(r.offset))
        out = ca.vertcat(*coef, *const) if slots else ca.SX(0, 1)
        return slots, ca.Function("relations", [sym.q, sym.u, sym.p], [out])
    return model.memo("turns.relations", build)


def tied(model) -> np.ndarray:
    """Whether each unknown is an angle that a gear, rack or relative input relates."""
    out = np.zeros(model.nq, dtype=bool)
    for terms in _relations(model)[0]:
        for s in terms:
            if s is not None and s[0] == "q":
                out[s[1]] = True
    return out


def free(model) -> np.ndarray:
    """Whether each unknown is an angle whose turn is free (seen by sines and cosines only)."""
    return ~model.sym.is_length & ~tied(model)


def turns(model, q, u, p, cols=None, known=(), start=True) -> np.ndarray:
    """q with the whole turns of its tied angles chosen so that each relation holds as
    nearly as turns can make it, and (`start`: a first pose) its free angles in (-pi, pi].

    An angle is set from a relation whose other angles are known: the inputs, the angles in
    `known`, and those set before it (so the turns propagate from the inputs, through a
    gear train or a rack's guessed position); it keeps its sine and cosine and takes the
    turn nearest the relation's value. A component of relations tied to no known angle
    gets its first angle in (-pi, pi], or the turn within ROOT_TURNS of it whose relations
    then hold best. Only the angles among `cols` (default: every unknown) change; a
    relation with an angle outside `cols` and `known` is left alone (not solved yet).
    Without `start` (a start near a solved pose), free angles and a component's first
    angle keep their turns: a sweep's angles stay continuous."""
    q = np.array(q, dtype=float)
    slots, f = _relations(model)
    angle = ~model.sym.is_length
    change = np.zeros(model.nq, dtype=bool)
    change[np.arange(model.nq) if cols is None else np.asarray(cols, int)] = True
    change &= angle
    if start:
        q[change & free(model)] = wrap(q[change & free(model)])
    if not slots:
        return q
    vals = np.asarray(f(q, u, p)).ravel()
    nt = sum(len(t) for t in slots)
    rels, at = [], 0
    for k, terms in enumerate(slots):
        rels.append((terms, vals[at:at + len(terms)], vals[nt + k]))
        at += len(terms)
    usable = [r for r in rels if all(s is None or s[0] == "u" or change[s[1]] or s[1] in known
                                     for s in r[0])]
    u = np.asarray(u, float).ravel()
    fixed = {j for j in known}
    pending = sorted({s[1] for r in usable for s in r[0] if s is not None and s[0] == "q" and change[s[1]]}
                     - fixed)
    if start:
        q[pending] = wrap(q[pending])
    q, fixed = _propagate(q, u, usable, fixed)
    while True:
        left = [j for j in pending if j not in fixed]
        if not left:
            return q
        root, best = left[0], None
        for n in sorted(range(-ROOT_TURNS, ROOT_TURNS + 1), key=lambda n: (abs(n), -n)):
            qt = q.copy()
            qt[root] += n * TURN
            qt, ft = _propagate(qt, u, usable, fixed | {root})
            miss = _mismatch(qt, u, usable, ft)
            if best is None or miss < best[0] * (1 - NEARER) - ROUNDING_REL:
                best = (miss, qt, ft)
        _, q, fixed = best


def _value(s, q, u):
    return 0.0 if s is None else (q[s[1]] if s[0] == "q" else u[s[1]])


def _propagate(q, u, rels, fixed):
    """Set every angle that is the one unfixed angle of a relation, until none is."""
    fixed = set(fixed)
    going = True
    while going:
        going = False
        for terms, a, c in rels:
            open_ = {s[1] for s in terms if s is not None and s[0] == "q" and s[1] not in fixed}
            if len(open_) != 1:
                continue
            j = open_.pop()
            aj = sum(ai for s, ai in zip(terms, a) if s == ("q", j))
            if aj == 0:
                continue
            rest = c + sum(ai * _value(s, q, u) for s, ai in zip(terms, a) if s != ("q", j))
            q[j] += TURN * round((-rest / aj - q[j]) / TURN)
            fixed.add(j)
            going = True
    return q, fixed


def _mismatch(q, u, rels, fixed) -> float:
    """The relations whose angles are all set: sum |residual| / sum |a|."""
    out = 0.0
    for terms, a, c in rels:
        if all(s is None or s[0] == "u" or s[1] in fixed for s in terms):
            out += abs(c + sum(ai * _value(s, q, u) for s, ai in zip(terms, a))) / max(np.abs(a).sum(), TINY)
    return out


def wandered(model, q0, q) -> bool:
    """Whether Newton took a tied angle more than half a turn from its start: then it may
    have passed assemblies nearer the start (a rack's relation is not periodic: its
    assemblies lie a little over a turn apart, and a damped Newton can pass several)."""
    t = tied(model)
    return bool(t.any() and np.abs(np.asarray(q) - q0)[t].max() > math.pi)


def nearest(model, sols, u, p, targets):
    """Of the solved candidates (None or unsolved ones skipped; at least the first is
    solved), the one whose moving points lie nearest the target points (the guess): the
    measure IPOPT's nearest assembly minimises (kincas/core/numeric.py)."""
    names = list(model.sym.mech.moving_points)

    def far(sol):
        P = model.points(sol.q, u, p)
        return sum(float(np.sum((P[:, names.index(k)] - xy) ** 2)) for k, xy in targets.items() if k in names)
    return min((s for s in sols if s is not None and s.ok), key=far)


def settle(model, sol, u, p, L):
    """The first pose with its free angles taken into (-pi, pi] (whole turns: the same pose,
    the residual unchanged up to rounding, polished by one Newton); tied angles keep the
    turns the relations gave them."""
    if not sol.ok or model.nq == 0:
        return sol
    fr = free(model)
    w = sol.q.copy()
    w[fr] = wrap(w[fr])
    if np.array_equal(w, sol.q):
        return sol
    new = model.newton(w, u, p, L)
    return new if new.ok else sol
