"""The Assur-group structure of a mechanism: g_q in block-triangular form, and each group's scale.

The loop-closure Jacobian g_q of a mechanism is sparse: an equation involves only the
unknowns of the links its loop passes through. Permuting its rows and columns into
block-triangular form (the Dulmage-Mendelsohn decomposition, `casadi.Sparsity.btf`) gives
irreducible diagonal blocks: each is one Assur group (2 x 2 for a dyad of two angles, 4 x 4
for a triad, ...), and the equations of a block involve only its own unknowns and those of
the blocks solved before it. So the groups are solved one after another, each by its own
small Newton, each measured against its own size.

The decomposition uses the sparsity pattern only, so it is computed once per structure
(parameter values never change it).

>>> from kincas.model import Mechanism, Link, Input
>>> from kincas.core.symbolic import Symbolic
>>> m = Mechanism(ground={"A": (0, 0), "D": (4, 0), "E": (-3, 1)},
...     links=[Link.bar("crank", "A", "B", 1), Link.bar("coupler", "B", "C", 3.5),
...            Link.bar("rocker", "D", "C", 3), Link.bar("rod", "B", "F", 4),
...            Link.bar("arm", "E", "F", 2)], inputs=[Input.angle("crank")])
>>> s = Structure(Symbolic(m))
>>> sorted((b.links, b.size) for b in s.blocks)  # two dyads, independent of each other
[(('arm', 'rod'), 2), (('coupler', 'rocker'), 2)]
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class Block:
    """One irreducible diagonal block of g_q: an Assur group.

    Attributes
    ----------
    rows : numpy.ndarray
        Indices of its equations (rows of g).
    cols : numpy.ndarray
        Indices of its unknowns (entries of q).
    links : tuple of str
        The links whose unknowns it solves, sorted by name.
    """

    rows: np.ndarray
    cols: np.ndarray
    links: tuple[str, ...]

    @property
    def size(self) -> int:
        """Number of unknowns of the block."""
        return int(self.cols.size)


class Structure:
    """Blocks of g_q in solve order, and what each block's scale is measured from.

    Parameters
    ----------
    sym : kincas.core.symbolic.Symbolic
        The symbolic model of the structure.

    Attributes
    ----------
    blocks : tuple of Block
        Block i's equations depend only on unknowns of blocks 0..i. A tall system
        (redundant joints) or one whose pattern is not structurally regular is one block.
    """

    def __init__(self, sym):
        self.sym = sym
        nq, ng = sym.nq, sym.ng
        owner = sym.unknown_links()  # unknown -> its link
        blocks = []
        if nq and ng == nq:
            sp = sym.Jq.sparsity()
            nb, rp, cp, rb, cb, _, ccb = sp.btf()
            if ccb[3] == nq:  # structurally regular: square irreducible blocks
                blocks = [(np.array(sorted(rp[rb[k]:rb[k + 1]]), dtype=int),
                           np.array(sorted(cp[cb[k]:cb[k + 1]]), dtype=int)) for k in range(nb)]
                blocks = _solve_order(blocks, sp)
        if nq and not blocks:
            blocks = [(np.arange(ng, dtype=int), np.arange(nq, dtype=int))]
        self.blocks = tuple(Block(r, c, tuple(sorted({owner[j] for j in c}))) for r, c in blocks)
        self._extent_links = [self._neighbours(b.links) for b in self.blocks]

    # --- scales ---
    def _neighbours(self, links):
        """The block's links and the bodies joined to them (the bodies its loops pass through),
        and the ground points the block's links carry."""
        m = self.sym.mech
        # (a point that only bars carry owns its own unknowns: kincas/core/space_symbolic.py)
        pts = {p for lk in m.links if lk.name in links for p in lk.point_names} | set(links)
        # bodies meeting the block's links at a pin, or at a slide (either side of it)
        slid = {s.along for s in m.slides if s.point in pts}
        slid_pts = {s.point for s in m.slides if s.along in links}
        near = [i for i, lk in enumerate(m.links) if lk.name in links or lk.name in slid
                or (pts | slid_pts) & set(lk.point_names)]
        ground = [i for i, (g, _) in enumerate(m.ground) if g in pts]
        return near, ground

    def block_lengths(self, local: np.ndarray, ground: np.ndarray) -> np.ndarray:
        """Each block's length: the largest distance between two points of one body its loops
        pass through (a link of the block or next to it, or the ground points they carry).

        `local` is every link's points in its own frame (as `Model.f_local` gives them),
        `ground` the ground points' coordinates, both at the parameter values in use. A block
        with no extent takes the whole mechanism's length (`Mechanism.size()`'s definition,
        from these same values: the model is shared by every parameter value)."""
        m, dim = self.sym.mech, self.sym.dim
        ext, k = [], 0
        for lk in m.links:
            n = len(lk.points)
            pts = local[k:k + dim * n].reshape(n, dim)
            k += dim * n
            ext.append(max((math.dist(a, b) for a in pts for b in pts), default=0.0))
        gxy = ground.reshape(-1, dim)
        out = np.empty(len(self.blocks))
        for i, (near, gidx) in enumerate(self._extent_links):
            span = max((math.dist(gxy[a], gxy[b]) for a in gidx for b in gidx), default=0.0)
            out[i] = max([span] + [ext[j] for j in near])
        if not out.all():
            box = np.ptp(gxy, axis=0) if len(gxy) else np.zeros(dim)
            out[out == 0] = max(max(ext, default=0.0), math.hypot(*box)) or 1.0
        return out

    def length_function(self):
        """kL(u, p) -> each block's length, the same definition as `block_lengths` written
        in casadi, so that a compiled kernel measures each group against its own length
        without a call back to Python (it agrees with `block_lengths` to rounding)."""
        import casadi as ca  # casadi is only needed by the kernels that ask for this

        sym, m = self.sym, self.sym.mech
        fmax = lambda xs, d=0.0: _reduce(ca.fmax, xs, d)
        dist = lambda a, b: ca.sqrt(sum((a[i] - b[i]) ** 2 for i in range(len(a))))
        ext = []
        for lk in m.links:
            pts = sym.local_points(lk)
            ext.append(fmax([dist(a, b) for i, a in enumerate(pts) for b in pts[i + 1:]]))
        gxy = [sym.ground_at(g) for g, _ in m.ground]
        out = []
        for near, gidx in self._extent_links:
            span = [dist(gxy[a], gxy[b]) for i, a in enumerate(gidx) for b in gidx[i + 1:]]
            out.append(fmax(span + [ext[j] for j in near]))
        if gxy:
            box = [fmax([g[c] for g in gxy], -ca.inf) - _reduce(ca.fmin, [g[c] for g in gxy], ca.inf)
                   for c in range(sym.dim)]
            whole = fmax([fmax(ext), ca.sqrt(sum(b ** 2 for b in box))])
        else:
            whole = fmax(ext)
        whole = ca.if_else(whole == 0, 1.0, whole)
        out = [ca.if_else(b == 0, whole, b) for b in out]
        return ca.Function("kL", [sym.u, sym.p], [ca.densify(ca.vertcat(*out)) if out else ca.SX(0, 1)])


def _reduce(f, xs, start):
    """f(...f(f(start, x0), x1)..., xn): casadi's fmax / fmin over a list."""
    out = start
    for x in xs:
        out = f(out, x)
    return out


def _solve_order(blocks, sp):
    """Blocks sorted so that each comes after every block whose unknowns its equations use
    (a topological order of the block graph; among ready blocks the one holding the lowest
    unknown first, so the order is stable)."""
    rows, cols = sp.get_triplet()
    block_of_row = np.empty(sp.size1(), dtype=int)
    block_of_col = np.empty(sp.size2(), dtype=int)
    for k, (r, c) in enumerate(blocks):
        block_of_row[r], block_of_col[c] = k, k
    needs = [set() for _ in blocks]
    for r, c in zip(rows, cols):
        i, j = block_of_row[r], block_of_col[c]
        if i != j:
            needs[i].add(j)
    order, done = [], set()
    while len(order) < len(blocks):
        ready = [k for k in range(len(blocks)) if k not in done and needs[k] <= done]
        k = min(ready, key=lambda k: blocks[k][1].min())  # never empty: btf's blocks form a DAG
        order.append(blocks[k])
        done.add(k)
    return order
