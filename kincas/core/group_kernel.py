"""The fast kernel's Newton step and final evaluation written group by group, one small
casadi function per kind of Assur group, so that its C code does not grow with the chain.

`kincas/core/kernel.py` writes kN and kF as one expression over all unknowns: the arithmetic
grows linearly with the number of groups, but the C compiler's time grows faster than the
size of one function (gcc -O3 on 40 chained four-bars: 6 s of CPU). Here each group B gets
the same arithmetic on its own unknowns x_B, given the unknowns z_B of the groups its
equations hang on (their values, Newton steps dz_B and tangents T_z):

    Newton step  dx_B = A^-1 (g_B - C dz_B)        (A = dg_B/dx_B, C = dg_B/dz_B)
    tangent      T_B  = -A^-1 (g_B,u + C T_z)

which is the block forward substitution of `kincas.core.blocks.block_solve`, so kN and kF
compute the same numbers as the flat expressions (to rounding). The functions take runs of
`per` consecutive groups (kincas/core/kernel.py: GROUP_RUN), with the flat kernel's
arithmetic within a run: each angle's sine and cosine once, no call between its groups.
Runs whose functions are the same expression up to the numbering of their inputs (every run
of four-bars of a chain but the first) share one casadi function, code-generated once and
called for each of them; kN and kF are then small MX functions that route vectors between
those calls. The reported quantities are their own function (flat: a point far down a
chain needs the whole chain's velocities).

>>> import kincas
>>> links = [kincas.Link.bar("crank", "O", "A", 1)]
>>> for k in range(1, 6):
...     links += [kincas.Link.bar(f"cp{k}", "A" if k == 1 else f"T{k - 1}", f"T{k}", 4),
...               kincas.Link.bar(f"rk{k}", f"G{k}", f"T{k}", 1)]
>>> m = kincas.Mechanism(ground={"O": (0, 0), **{f"G{k}": (4 * k, 0) for k in range(1, 6)}},
...     links=links, inputs=[kincas.Input.angle("crank")])
>>> model = kincas.model_of(m)
>>> kinds = GroupFunctions(model.sym, list(model.blocks))
>>> len(model.blocks), len(kinds.newton_kinds)  # the first four-bar differs from the rest
(5, 2)
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from .blocks import block_change, block_measures, block_solve, diagonal_blocks, diagonal_size, reciprocal
from .lifting import lift_constants, lift_trig
from .structure import Block

OPTS = {"cse": True}  # one sin and cos per angle within a group's function


def _max_abs(v):
    """max |v_i|, NaN if any v_i is (casadi's mmax skips NaNs; a sum keeps them)."""
    return ca.mmax(ca.fabs(v)) + 0 * ca.sum1(v) if v.numel() else 0 * ca.sum1(v)


class _Group:
    """A run of consecutive Assur groups solved by one function: own unknowns `cols` (the
    groups' in solve order), the earlier unknowns `hang` their equations use, the parameters
    `params` they use, the groups in the run's own numbering (`local`); its residual g in
    local symbols (x, z, u, p) with its numeric constants lifted into one more symbol c
    (`values` holds them), and `key`: equal for runs that differ only in those constants."""

    def __init__(self, sym, blks: list[Block]):
        self.cols = [int(j) for b in blks for j in b.cols]
        rows = [int(i) for b in blks for i in b.rows]
        self.local, r0, c0 = [], 0, 0
        for b in blks:
            self.local.append(Block(np.arange(r0, r0 + len(b.rows)), np.arange(c0, c0 + len(b.cols)), ()))
            r0, c0 = r0 + len(b.rows), c0 + len(b.cols)
        gB = sym.g[rows]
        own = set(self.cols)
        used = sorted({int(c) for c in ca.jacobian(gB, sym.q).sparsity().get_col()})
        self.hang = [j for j in used if j not in own]
        self.params = sorted({int(c) for c in ca.jacobian(gB, sym.p).sparsity().get_col()})
        n, m = len(self.cols), len(self.hang)
        x, z = ca.SX.sym("x", n), ca.SX.sym("z", m)
        u, p = ca.SX.sym("u", sym.nu), ca.SX.sym("p", len(self.params))
        qv, pv = [ca.SX(0)] * sym.nq, [ca.SX(0)] * sym.np
        for k, j in enumerate(self.cols):
            qv[j] = x[k]
        for k, j in enumerate(self.hang):
            qv[j] = z[k]
        for k, j in enumerate(self.params):
            pv[j] = p[k]
        old = [sym.q, sym.u, sym.p]
        new = [ca.vertcat(*qv) if qv else ca.SX(0, 1), u, ca.vertcat(*pv) if pv else ca.SX(0, 1)]
        keep = [k for k, v in enumerate(old) if v.numel()]
        g = ca.substitute([gB], [old[k] for k in keep], [new[k] for k in keep])[0]
        trig, self.trig = lift_trig(ca.Function("g", [x, z, u, p], [g]), 1)
        shape, self.values = lift_constants(trig)
        self.is_length = sym.is_length[self.cols]
        layout = tuple((len(b.rows), len(b.cols)) for b in blks)
        self.key = (shape.serialize(), tuple(self.is_length), layout)
        self.x, self.z, self.u, self.p, self.t, self.c = shape.sx_in()
        self.g = shape.call(shape.sx_in())[0]
        self.nj = diagonal_size(self.local)
        self.passes = []  # own unknowns (local) whose sine and cosine later runs take

    def hang_jacobian(self):
        """dg/dz with z's sines and cosines t (inputs) depending on z: d sin z = cos z dz."""
        C = ca.jacobian(self.g, self.z)
        if self.trig:
            dt = ca.SX(2 * len(self.trig), self.z.numel())
            for n, k in enumerate(self.trig):
                dt[2 * n, k], dt[2 * n + 1, k] = self.t[2 * n + 1], -self.t[2 * n]
            C = C + ca.mtimes(ca.jacobian(self.g, self.t), dt)
        return C

    def passed(self):
        """[sin x_k, cos x_k for k in passes]: computed with g's own (one sincos call)."""
        return ca.vertcat(*[f(self.x[k]) for k in self.passes for f in (ca.sin, ca.cos)]) if self.passes else ca.SX(0, 1)


class GroupFunctions:
    """Per run of `per` consecutive groups, the casadi functions of its Newton step and final
    evaluation, one per kind of run. Within a run the arithmetic is the flat kernel's (one
    sine and cosine per angle, the block forward substitution); between runs, MX calls.

    `newton_kinds` / `final_kinds`: the distinct functions; `kind[i]`: run i's index in
    them. A kind is called with run i's inputs (`groups[i]`) and then its constants
    (`groups[i].values`)."""

    def __init__(self, sym, blocks, per: int = 1):
        self.sym, self.blocks = sym, blocks
        self.groups = [_Group(sym, blocks[i:i + per]) for i in range(0, len(blocks), per)]
        owner = {j: (i, k) for i, grp in enumerate(self.groups) for k, j in enumerate(grp.cols)}
        passes = {}  # per kind of run, the own unknowns whose sine and cosine a later run takes
        for grp in self.groups:
            for k in grp.trig:
                i, kk = owner[grp.hang[k]]
                passes.setdefault(self.groups[i].key, set()).add(kk)
        for grp in self.groups:  # the same for every run of a kind: one function
            grp.passes = sorted(passes.get(grp.key, ()))
            grp.key = (*grp.key, tuple(grp.passes))
        self.newton_kinds, self.final_kinds, self.kind, seen = [], [], [], {}
        for grp in self.groups:
            if grp.key not in seen:
                seen[grp.key] = len(self.newton_kinds)
                self.newton_kinds.append(self._newton(grp, f"gN{len(self.newton_kinds)}"))
                self.final_kinds.append(self._final(grp, f"gF{len(self.final_kinds)}"))
            self.kind.append(seen[grp.key])

    @staticmethod
    def _scales(grp, Lb):
        """(D, Lg): each unknown's scale (its group's length, or 1 for an angle) and each
        equation's group length."""
        Lq, Lg = group_scales(Lb, grp.local, grp.x.numel(), grp.g.numel())
        return ca.if_else(ca.DM(grp.is_length.astype(float)), Lq, 1), Lg

    @staticmethod
    def _newton(grp, name):
        """(x, z, dz, u, p, Lb, c, t) -> (dx, [max |g| / Lb, max |dx / D|], passed)."""
        dz, Lb = ca.SX.sym("dz", grp.z.numel()), ca.SX.sym("Lb", len(grp.local))
        A, C = ca.jacobian(grp.g, grp.x), grp.hang_jacobian()
        D, Lg = GroupFunctions._scales(grp, Lb)
        rhs = grp.g - ca.mtimes(C, dz) if grp.z.numel() else grp.g
        dx = block_solve(A, rhs, grp.local)
        rs = ca.vertcat(_max_abs(grp.g * reciprocal(Lg)), _max_abs(dx * reciprocal(D)))
        return ca.Function(name, [grp.x, grp.z, dz, grp.u, grp.p, Lb, grp.c, grp.t],
                           [ca.densify(dx), rs, grp.passed()], OPTS)

    @staticmethod
    def _final(grp, name):
        """(x, z, dz, Tz, u, p, Lb, L, A0, xp, c, t) -> (A, T, rs, [change, correction],
        [sign per group, sigma], dx, passed): kF's measures for this run."""
        n, m, nu = grp.x.numel(), grp.z.numel(), grp.u.numel()
        dz, Tz, Lb, L = ca.SX.sym("dz", m), ca.SX.sym("Tz", m, nu), ca.SX.sym("Lb", len(grp.local)), ca.SX.sym("L")
        A0, xp = ca.SX.sym("A0", grp.nj), ca.SX.sym("xp", n)
        A, C = ca.jacobian(grp.g, grp.x), grp.hang_jacobian()
        Gu = ca.jacobian(grp.g, grp.u)
        D, Lg = GroupFunctions._scales(grp, Lb)
        cs = ca.if_else(ca.DM(grp.is_length.astype(float)), 1, reciprocal(L))  # columns to O(1): 1 (lengths), 1/L (angles)
        dx = block_solve(A, grp.g - ca.mtimes(C, dz) if m else grp.g, grp.local)
        T = -block_solve(A, Gu + ca.mtimes(C, Tz) if m else Gu, grp.local)
        rs = ca.vertcat(_max_abs(grp.g * reciprocal(Lg)), _max_abs(dx * reciprocal(D)))
        change = block_change(A0, A, D, grp.local)
        corr = group_correction((grp.x - xp) / D, grp.local)
        signs, sigma = block_measures(A, cs, grp.local)
        return ca.Function(name, [grp.x, grp.z, dz, Tz, grp.u, grp.p, Lb, L, A0, xp, grp.c, grp.t],
                           [diagonal_blocks(A, grp.local), ca.densify(T), rs, ca.vertcat(change, corr),
                            ca.vertcat(signs, sigma), ca.densify(dx), grp.passed()], OPTS)

    # --- kN and kF: MX functions routing vectors between the groups' calls ---
    def kernel(self, report_function):
        """(kN, kF) with the signatures of `kernel_functions`' flat ones."""
        sym, nq, nu = self.sym, self.sym.nq, self.sym.nu
        q, u, p, Lb = ca.MX.sym("q", nq), ca.MX.sym("u", nu), ca.MX.sym("p", sym.np), ca.MX.sym("Lb", len(self.blocks))
        L, ud, udd = ca.MX.sym("L"), ca.MX.sym("ud", nu), ca.MX.sym("udd", nu)
        nj = sum(len(b.cols) ** 2 for b in self.blocks)
        J0, qp = ca.MX.sym("J0", nj), ca.MX.sym("qp", nq)
        pick = lambda v, idx: v[idx] if idx else ca.MX(0, 1)
        rows = lambda parts, idx: ca.vertcat(*[parts[j] for j in idx]) if idx else ca.MX(0, 1)
        # sin and cos of unknown j as the run that solved j computed them, for the later ones
        trig = lambda grp, passed: dict(zip(grp.passes, ca.vertsplit(passed, 2))) if grp.passes else {}
        given = lambda grp, tr: ca.vertcat(*[tr[grp.hang[k]] for k in grp.trig]) if grp.trig else ca.MX(0, 1)
        # kN
        dxs, r, b0, tr = [None] * nq, [], 0, {}
        for grp, kd in zip(self.groups, self.kind):
            f, c, nb = self.newton_kinds[kd], ca.DM(grp.values), len(grp.local)
            dx, rs, ps = f(pick(q, grp.cols), pick(q, grp.hang), rows(dxs, grp.hang), u, pick(p, grp.params),
                           Lb[b0:b0 + nb], c, given(grp, tr))
            tr.update({grp.cols[k]: v for k, v in trig(grp, ps).items()})
            b0 += nb
            for k, j in enumerate(grp.cols):
                dxs[j] = dx[k]
            r.append(rs)
        step = ca.vertcat(*dxs) if nq else ca.MX(0, 1)
        rs = _max_rows(r)
        kN = ca.Function("kN", [q, u, p, Lb], [step, rs])
        # kF
        dxs, Ts, r, A, ch, co, sg, sig, at, b0 = [None] * nq, [None] * nq, [], [], [], [], [], [], 0, 0
        tr = {}
        for grp, kd in zip(self.groups, self.kind):
            f, c, nb = self.final_kinds[kd], ca.DM(grp.values), len(grp.local)
            Tz = ca.vertcat(*[Ts[j] for j in grp.hang]) if grp.hang else ca.MX(0, nu)
            a, T, rs, mc, ms, dx, ps = f(pick(q, grp.cols), pick(q, grp.hang), rows(dxs, grp.hang), Tz, u,
                                         pick(p, grp.params), Lb[b0:b0 + nb], L, J0[at:at + grp.nj],
                                         pick(qp, grp.cols), c, given(grp, tr))
            tr.update({grp.cols[k]: v for k, v in trig(grp, ps).items()})
            at, b0 = at + grp.nj, b0 + nb
            for k, j in enumerate(grp.cols):
                dxs[j], Ts[j] = dx[k], T[k, :]
            r.append(rs)
            A.append(a)
            ch.append(mc[0])
            co.append(mc[1])
            sg.extend(ca.vertsplit(ms[:nb]))
            sig.append(ms[nb])
        step = ca.vertcat(*dxs) if nq else ca.MX(0, 1)
        T = ca.vertcat(*Ts) if nq else ca.MX(0, nu)
        # q' = (dq/du) u' from the tangent just computed: no solve through the chain again
        y = report_function(q, u, p, ud, udd, ca.mtimes(T, ud)) if report_function is not None else ca.MX(0, 1)
        change = ca.mmax(ca.vertcat(0, *ch))
        corr = ca.mmax(ca.vertcat(*co)) if co else ca.MX(0)  # per group, as the flat kernel
        sigma = ca.mmin(ca.vertcat(*sig)) if sig else ca.MX(1)
        kF = ca.Function("kF", [q, u, p, L, ud, udd, J0, qp, Lb],
                         [ca.vertcat(*A) if A else ca.MX(0, 1), T, _max_rows(r), ca.vertcat(change, corr),
                          ca.vertcat(*sg, sigma), y, step])
        return kN, kF


def kernel_sizes(functions) -> tuple[int, int]:
    """(code, work) of casadi functions, in instructions: `code` counts each function once
    however often it is called (what the C compiler sees), `work` counts every call (what
    one evaluation costs, and what the virtual machine runs once the calls are inlined).

    >>> import casadi as ca
    >>> x = ca.MX.sym("x")
    >>> f = ca.Function("f", [ca.SX.sym("y")], [ca.SX.sym("y") * 0 + 1])
    >>> kernel_sizes([ca.Function("g", [x], [f(f(x))])])[1] > kernel_sizes([ca.Function("g", [x], [f(f(x))])])[0]
    True
    """
    seen: set = set()

    def count(f):
        if f.class_name() == "Switch":  # one of its cases runs (a tall kernel's, kernel.py)
            cases = [count(g) for g in f.find_functions(1) if g.class_name() in ("SXFunction", "MXFunction")]
            return sum(c for c, _ in cases), max((w for _, w in cases), default=0)
        if not f.is_a("MXFunction"):
            n = f.n_instructions()
            new = f.name() not in seen
            seen.add(f.name())
            return (n if new else 0), n
        code = work = 0
        for i in range(f.n_instructions()):
            if f.instruction_id(i) == ca.OP_CALL:
                c, w = count(f.instruction_MX(i).which_function())
                code, work = code + c, work + w
            else:
                code, work = code + 1, work + 1
        return code, work
    out = [count(f) for f in functions]
    return sum(c for c, _ in out), sum(w for _, w in out)


def group_scales(Lb, blocks, nq, ng):
    """(per unknown, per equation) the length of the group it belongs to."""
    Lq, Lg = [ca.SX(1)] * nq, [ca.SX(1)] * ng
    for i, b in enumerate(blocks):
        for j in b.cols:
            Lq[int(j)] = Lb[i]
        for r in b.rows:
            Lg[int(r)] = Lb[i]
    return ca.vertcat(*Lq) if nq else ca.SX(0, 1), ca.vertcat(*Lg) if ng else ca.SX(0, 1)


def group_correction(dx, blocks):
    """max over the Assur groups of ||D^-1 (q - q_pred)||_1 restricted to the group: each
    group's Newton wanders on its own (the system is block triangular), so the bound is per
    group, and a chain of 40 groups is held to what one group is."""
    parts = [ca.norm_1(dx[[int(c) for c in b.cols]]) for b in blocks if len(b.cols)]
    return ca.mmax(ca.vertcat(*parts)) if parts else ca.SX(0)


def _max_rows(parts):
    """Entry-wise max of the [residual, step] pairs of every group (NaN kept)."""
    if not parts:
        return ca.MX.zeros(2)
    M = ca.horzcat(*parts)
    return ca.vertcat(ca.mmax(M[0, :]) + 0 * ca.sum2(M[0, :]), ca.mmax(M[1, :]) + 0 * ca.sum2(M[1, :]))
