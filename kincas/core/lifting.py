"""Casadi functions rewritten with some of their instructions' results taken from a new last
input instead: the same operations in the same order otherwise, so the rewritten function
computes the same numbers from the same inputs.

- `lift_constants`: every numeric constant (runs of groups that differ only in their
  dimensions share one compiled function, kincas/core/group_kernel.py);
- `lift_trig`: the sines and cosines of one input's entries (a run of groups takes those of
  the unknowns it hangs on from the run that solved them);
- `lift_trig_pairs`: those of listed (input, entry) pairs, in a layout shared by several
  functions (the compiled sweep loop computes the sines and cosines of the unknowns and inputs
  once and moves them with each Newton step, kincas/core/sweep_loop.py SWEEP_C).

>>> import casadi as ca
>>> x = ca.SX.sym("x", 2)
>>> f = ca.Function("f", [x], [ca.sin(x[0]) * ca.cos(x[0]) + ca.cos(x[1])])
>>> pairs = trig_pairs([f], [0])
>>> pairs
[(0, 0), (0, 1)]
>>> g = lift_trig_pairs(f, pairs, "f")
>>> float(g([0.3, 0.4], [0.5, 2.0, 0.0, 3.0]))  # sin x0 = 0.5, cos x0 = 2, cos x1 = 3
4.0
"""
from __future__ import annotations

import casadi as ca
import numpy as np

_TRIG = (ca.OP_SIN, ca.OP_COS)


def lift_constants(f: ca.Function):
    """(g, c): g(*f's inputs, c) == f(*f's inputs), every constant of f's instructions an
    entry of the new last input c; the same operations in the same order, so g computes
    f's numbers exactly."""
    g, keys = _lift(f, lambda i, op, src: i if op == ca.OP_CONST else None)
    return g, np.array([f.instruction_constant(i) for i in keys], dtype=float)


def lift_trig(f: ca.Function, which: int):
    """(g, ks): the sines and cosines of entries of f's input `which` (a run's hanging
    unknowns z) lifted into a new last input t = [sin z_k, cos z_k for k in ks]: the run that
    solved z_k has computed them already and passes them on (40 chained four-bars: 10 of 90
    sines and cosines a pose fewer). Both of each pair, as d sin z / dz = cos z."""
    pairs = trig_pairs([f], (which,))
    return lift_trig_pairs(f, pairs, "g"), [k for _, k in pairs]


def trig_pairs(functions, inputs) -> list[tuple[int, int]]:
    """The (input, entry) pairs, inputs among `inputs`, whose sine or cosine one of
    `functions` takes directly, sorted (input by input, entry by entry)."""
    out = set()
    for f in functions:
        for i, src in enumerate(_sources(f)):
            if src and src[0] in inputs and f.instruction_id(i) in _TRIG:
                out.add(src)
    return sorted(out)


def lift_trig_pairs(f: ca.Function, pairs, name: str) -> ca.Function:
    """f named `name`, with one input more, t = [sin v, cos v for v in pairs] (v = input
    `pairs[n][0]`'s entry `pairs[n][1]`): where f takes the sine or cosine of one of those
    entries it reads t[2 n] or t[2 n + 1] instead. Pairs f does not use are entries of t it
    does not read, so functions of one layout take one t."""
    at = {(v, op): 2 * n + (op == ca.OP_COS) for n, v in enumerate(pairs) for op in _TRIG}
    g, _ = _lift(f, lambda i, op, src: at.get((src, op)) if op in _TRIG and src else None,
                 slots=2 * len(pairs), name=name)
    return g


def _sources(f):
    """Per instruction of f: (input, entry) where it is unary and its argument an input's
    entry, else None."""
    srcs, slot = [], {}
    for j in range(f.n_instructions()):
        op, o, ii = f.instruction_id(j), f.instruction_output(j), f.instruction_input(j)
        srcs.append(slot.get(ii[0]) if len(ii) == 1 and op not in (ca.OP_INPUT, ca.OP_OUTPUT) else None)
        if op == ca.OP_INPUT:
            slot[o[0]] = (ii[0], ii[1])
        elif op != ca.OP_OUTPUT:
            slot.pop(o[0], None)
    return srcs


def _lift(f: ca.Function, key, slots=None, name: str = "g"):
    """(g, keys): g(*f's inputs, t) == f(*f's inputs) where every instruction i for which
    key(i, op, source) is not None gives (instead of its own result) the entry t[key] of a
    new last input t (`slots` entries, or one per such instruction in their order, `keys`
    holding their keys); every other instruction the same operation in the same order."""
    ins, srcs = f.sx_in(), _sources(f)
    lifted, keys, work, outs = {}, [], {}, [[None] * f.nnz_out(k) for k in range(f.n_out())]
    t = ca.SX.sym("t", slots) if slots is not None else None
    nz = [ca.vertsplit(ca.vec(a), 1) if a.numel() else [] for a in ins]
    for i in range(f.n_instructions()):
        op, o, ii = f.instruction_id(i), f.instruction_output(i), f.instruction_input(i)
        k = key(i, op, srcs[i]) if op not in (ca.OP_INPUT, ca.OP_OUTPUT) else None
        if k is not None:
            if slots is None:
                lifted[k] = ca.SX.sym(f"c{len(keys)}")
                keys.append(k)
            work[o[0]] = t[k] if slots is not None else lifted[k]
        elif op == ca.OP_CONST:
            work[o[0]] = ca.SX(f.instruction_constant(i))
        elif op == ca.OP_INPUT:
            work[o[0]] = nz[ii[0]][ii[1]]
        elif op == ca.OP_OUTPUT:
            outs[o[0]][o[1]] = work[ii[0]]
        elif len(ii) == 1:
            work[o[0]] = ca.SX.unary(op, work[ii[0]])
        else:
            work[o[0]] = ca.SX.binary(op, work[ii[0]], work[ii[1]])
    res = []
    for k, col in enumerate(outs):
        sp = f.sparsity_out(k)
        res.append(ca.SX(sp, ca.vertcat(*[ca.SX(0) if v is None else v for v in col]) if col else ca.SX(0, 1)))
    if slots is None:
        t = ca.vertcat(*[lifted[k] for k in keys]) if keys else ca.SX(0, 1)
    return ca.Function(name, [*ins, t], res), keys
