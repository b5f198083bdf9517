"""The symbolic side of the simultaneous NLP behind `kincas.optimize`
(kincas/synthesis/simultaneous.py holds the problem's checks and the reading of its input):
its variables, the user's expressions in them, the max()/min() samples and the IPOPT call.

Variables: the varied parameters (scaled by their size), the unknowns q_k at every sample
(lengths divided by the mechanism's size), and for each max()/min() an extra sample (q*, u*).
Equality constraints: g(q_k, u_k, p) / L = 0 at every sample; at an extra sample also its
closure and dE/du = 0. Inequalities: s_kb det(B_b(q_k)) >= 0 for each Assur group's block B_b of
g_q, which keeps every sample on the initial design's assembly branch (and off singular positions); then the user's
constraints. Everything is one CasADi SX graph, so IPOPT gets exact gradients and Hessians.

>>> SampledNLP.solve.__doc__.split(".")[0]
'IPOPT on the problem built so far'
"""
from __future__ import annotations

import math

import casadi as ca
import numpy as np

from ..errors import ModelError
from ..results import wrap_angle
from .cancel import interruptible
from .expressions_sym import CONST, SAMPLE, SYMBOLIC
from .symbolic import is_angular
from .tolerances import SAME_INPUT, TINY



class SampledNLP:
    """The symbolic NLP of `kincas.synthesis.simultaneous.Problem` (a base class of it).

    It needs of the problem: m, model, L, p0, vary, pscale, data, deg, qs, K, U, Ud,
    Udd, D, path, ref, Q0, us, ulo, uhi, urows, u_at(k), sign(q, u, p), dense(mech) and the
    evaluator class (`evaluator`) of the expression language.
    """

    @property
    def sym(self):
        """The model's symbolic form: the NLP is built here, in the core; the synthesis holds
        only the model."""
        return self.model.sym

    # --- the variables ---
    def make_symbols(self):
        """The varied parameters xp, the parameters P in them, rates, data."""
        nv = len(self.vary)
        self.xp = ca.SX.sym("xp", nv)
        P = [self.p0[i] for i in range(len(self.p0))]
        for j, p in enumerate(self.vary):
            P[self.sym.pnames.index(p)] = self.xp[j] * self.pscale[j]
        self.P = ca.vertcat(*P) if P else ca.SX(0, 1)
        self.ud, self.udd = ca.SX.sym("ud", self.sym.nu), ca.SX.sym("udd", self.sym.nu)
        self.ds = ca.SX.sym("data", len(self.data))

    def make_sample_unknowns(self):
        """q_k at the K samples, scaled to O(1)."""
        self.Qv = ca.SX.sym("q", self.sym.nq, self.K)
        self.Q = self.Qv * ca.DM(self.qs) if self.sym.nq else self.Qv

    def make_free_inputs(self):
        """The (single) input at every sample as a variable v_k (u_k = us * v_k)."""
        self.Uv = ca.SX.sym("u", self.K)
        return self.Uv

    # --- expressions into the NLP's variables ---
    def leaf(self, kind, name):
        sym = self.sym
        if kind == "quantity":
            e = self.model.quantity_function((name,))(sym.q, sym.u, sym.p, self.ud, self.udd)
            return SAMPLE, (e * (180 / math.pi) if self.deg and is_angular(name, self.m) else e)
        if kind == "data":
            return SAMPLE, self.ds[list(self.data).index(name)]
        v = sym.val(name)
        return (SAMPLE if sym.nu and ca.depends_on(v, sym.u) else CONST), v

    def fn(self, E):
        sym = self.sym
        return ca.Function("e", [sym.q, sym.u, sym.p, self.ud, self.udd, self.ds], [E])

    def at_sample(self, F, k):
        return F(self.Q[:, k], self.u_at(k), self.P, self.Ud[k], self.Udd[k], self.D[:, k])

    def aggregate(self, f, kind, E, text):
        if f in ("sum", "mean"):
            F = self.fn(E)
            total = sum(self.at_sample(F, k) for k in range(self.K))
            return total / self.K if f == "mean" else total
        return self.extreme(f, E, text)

    def total(self, E):
        return ca.substitute(E, self.sym.p, self.P)

    def evaluate(self, e, where, objective=False):
        ev = self.evaluator(self.leaf, self.aggregate, self.total,
                            angle=math.pi / 180 if self.deg else 1.0, ops=SYMBOLIC)
        kind, v = ev(e)
        if kind == SAMPLE and objective:
            raise ModelError(f"{where}: the objective changes from sample to sample: "
                             f"wrap it in sum(), mean(), max() or min()")
        if kind == SAMPLE:
            F = self.fn(v)
            return kind, ca.vertcat(*[self.at_sample(F, k) for k in range(self.K)])
        return kind, (self.total(v) if kind == CONST else v)

    def extreme(self, f, E, text):
        """max/min of E over the input's range: a sample of its own whose input is free and
        held where dE/du = 0, started at the extreme of the initial design's checking sweep."""
        sym, key = self.sym, (f, text)
        if key in self.extremes:
            return self.extremes[key]["value"]
        if sym.nu != 1:
            raise ModelError(f"{f}({text}): needs a mechanism driven by one input")
        if self.Uv is not None:
            raise ModelError(f"{f}({text}): max()/min() cannot be combined with a curve")
        if self._dense0 is None:
            self._dense0 = self.dense(self.m)
        d0, F = self._dense0, self.fn(E)
        U, Ud, Udd = self.path
        ok = np.flatnonzero(d0.ok)
        if not len(ok):
            raise ModelError(f"{f}({text}): the initial design assembles nowhere on the range")
        vals = np.asarray(F.map(len(ok))(d0.q[ok].T, U[ok].T, np.repeat(self.p0[:, None], len(ok), 1),
                                          Ud[ok].T, Udd[ok].T, np.zeros((len(self.data), len(ok)))))
        i = ok[int(np.argmax(vals) if f == "max" else np.argmin(vals))]
        qx, ux = ca.SX.sym(f"qe{len(self.extremes)}", sym.nq), ca.SX.sym(f"ue{len(self.extremes)}")
        qe = qx * ca.DM(self.qs) if sym.nq else qx
        zero = np.zeros(len(self.data))
        value = F(qe, ux, self.P, Ud[i], Udd[i], zero)
        span = float(U[:, 0].max() - U[:, 0].min())
        periodic = self.m.inputs[0].is_angle and span >= 2 * math.pi - SAME_INPUT
        end = i in (0, len(U) - 1) and not periodic
        rows = [sym.f_res(qe, ux, self.P) / self.L]
        if not end:  # stationary: dE/du = E_q dq/du + E_u with dq/du = -g_q^-1 g_u
            dE = ca.mtimes(ca.jacobian(E, sym.q), -ca.solve(sym.Jq, sym.Ju)) + ca.jacobian(E, sym.u)
            scale = max(float(np.ptp(vals)), SAME_INPUT * float(np.abs(vals).max()), TINY)
            rows.append(self.fn(dE)(qe, ux, self.P, Ud[i], Udd[i], zero) / scale)
        lo, hi = ((U[i, 0], U[i, 0]) if end else (-np.inf, np.inf) if periodic
                  else (U[:, 0].min(), U[:, 0].max()))
        q0 = d0.q[i].copy()
        q0[~sym.is_length] = wrap_angle(q0[~sym.is_length])
        self.extremes[key] = dict(fn=f, text=text, F=F, x=[qx, ux], x0=np.r_[q0 / self.qs, U[i, 0]],
                                  lo=np.r_[np.full(sym.nq, -np.inf), lo],
                                  hi=np.r_[np.full(sym.nq, np.inf), hi],
                                  rows=ca.vertcat(*rows), value=value, rate=(Ud[i], Udd[i]),
                                  start=float(U[:, 0].min()) if periodic else None,
                                  sign=self.sign(d0.q[i], U[i], self.p0))
        return value

    def extreme_values(self, e, Q, U, p, Ud, Udd) -> np.ndarray:
        """The expression a max()/min() tracks (`e`, from `extreme`), at N poses: rows of Q,
        U, Ud, Udd, parameters p; numbers for the checks, which hold no CasADi object."""
        Q, U, Ud, Udd = (np.atleast_2d(np.asarray(a, float)) for a in (Q, U, Ud, Udd))
        n = len(Q)
        f = e["F"].map(n)
        return np.asarray(f(Q.T, U.T, np.repeat(np.reshape(p, (-1, 1)), n, 1), Ud.T, Udd.T,
                            np.zeros((len(self.data), n)))).ravel()

    def squared_distances(self, point, targets):
        """sum_k |P(q_k, u_k) - T_k|^2 of a point P and targets T (K x 2): a curve's objective."""
        F = self.model.quantity_function((f"{point}.x", f"{point}.y"))
        f = 0
        for k in range(self.K):
            d = F(self.Q[:, k], self.u_at(k), self.P, self.Ud[k], self.Udd[k]) - ca.DM(targets[k])
            f = f + ca.sumsqr(d)
        return f

    # --- IPOPT ---
    def solve(self, f, rows, check_path, max_iter, tol) -> dict:
        """IPOPT on the problem built so far. f: the objective; rows: the user's constraints
        [(constraint, (kind, G))]; then the problem's `check` of IPOPT's answer."""
        sym, K = self.sym, self.K
        ext = list(self.extremes.values())
        free = self.Uv is not None
        Uv = [self.Uv] if free else []
        X = ca.vertcat(self.xp, ca.vec(self.Qv), *Uv, *[v for e in ext for v in e["x"]])
        lo = [b[0] / s for b, s in zip(self.vary.values(), self.pscale)]
        hi = [b[1] / s for b, s in zip(self.vary.values(), self.pscale)]
        x0 = np.r_[[self.m.parameter(p) / s for p, s in zip(self.vary, self.pscale)],
                   (self.Q0 / self.qs).ravel(), *([self.U[:, 0] / self.us] if free else []),
                   *[e["x0"] for e in ext]]
        lbx = np.r_[lo, np.full(sym.nq * K, -np.inf), *([self.ulo] if free else []),
                    *[e["lo"] for e in ext]]
        ubx = np.r_[hi, np.full(sym.nq * K, np.inf), *([self.uhi] if free else []),
                    *[e["hi"] for e in ext]]
        closure = [sym.f_res(self.Q[:, k], self.u_at(k), self.P) / self.L for k in range(K)]
        G = [*closure, *[e["rows"] for e in ext]]
        lbg = [np.zeros(g.numel()) for g in G]
        ubg = list(lbg)
        for g, a, b in (self.urows if free else []):  # the fitted inputs' order
            G.append(g)
            lbg.append(np.full(g.numel(), a))
            ubg.append(np.full(g.numel(), b))
        # The branch is kept at every sample: each Assur group's block of g_q keeps the sign
        # its determinant has on the initial design (a polynomial in q, so its derivatives are
        # exact; it also keeps the samples off singular positions, where it is 0). Group by
        # group, as sweeps tell branches: det(g_q) of the whole would miss two groups flipping
        # together, and expanding it symbolically grows with the whole system (a suspension's
        # 21 x 21: a minute to build, another for IPOPT's derivatives) where the groups are small.
        poses = [(self.Q[:, k], self.u_at(k), self.ref[k]) for k in range(K)]
        poses += [(e["x"][0] * ca.DM(self.qs), e["x"][1], e["sign"]) for e in ext]
        dets = self.model.memo("nlp.group_determinants", lambda: group_determinants(self.model))
        for q, u, sign in poses:
            for s, (fdet, cols_b) in zip(sign, dets):
                if s:  # (0: a tall group, or a sample that did not assemble)
                    scale = float(np.prod(self.qs[cols_b] / self.L))  # columns O(1), as in Newton
                    G.append(s * scale * fdet(q, u, self.P))
                    lbg.append(np.zeros(1))
                    ubg.append(np.full(1, np.inf))
        self.n_fixed = sum(np.size(b) for b in lbg)  # closure, extremes, branch rows
        self.row_sizes = [g.numel() for _, (_, g) in rows]
        for c, (_, g) in rows:
            G.append(g)
            lbg.append(np.full(g.numel(), -np.inf if c.min is None else c.min))
            ubg.append(np.full(g.numel(), np.inf if c.max is None else c.max))
        G = ca.vertcat(*G)
        opts = {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes",
                "ipopt.max_iter": int(max_iter), "ipopt.tol": tol, "error_on_fail": False,
                "ipopt.bound_relax_factor": 0.0}
        solver = ca.nlpsol("kincas_optimize", "ipopt", {"x": X, "f": f, "g": G}, opts)
        with interruptible():  # IPOPT would take Ctrl-C for a failed solve and go on
            out = solver(x0=x0, lbx=lbx, ubx=ubx, lbg=np.concatenate(lbg), ubg=np.concatenate(ubg))
        stats = solver.stats()
        fgs = ca.Function("fg", [X], [f, G])
        fg = lambda x: tuple(np.asarray(v).ravel() for v in fgs(x))  # numpy values for the checks
        f0 = float(fg(x0)[0][0])
        return self.check(np.asarray(out["x"]).ravel(), fg, f0, rows, stats, check_path)



def group_determinants(model) -> list:
    """Per Assur group of g_q: (det of its block as a Function of (q, u, p), its columns); None
    for a tall group. Built once per model; every sample calls it."""
    sym, out = model.sym, []
    for b in model.blocks:
        if b.rows.size != b.cols.size:
            out.append((None, b.cols))
            continue
        d = determinant(sym.Jq[b.rows.tolist(), b.cols.tolist()])
        out.append((ca.Function("group_det", [sym.q, sym.u, sym.p], [d]), b.cols))
    return out


def determinant(M):
    """det(M) of a square SX matrix, expanded along its rows with every minor built once: the
    minor on the last k rows and a set S of k columns is
        D(S) = sum over j in S of (-1)^(number of columns of S before j) M[n-k, j] D(S - {j}),
    so at most n 2^n products, far fewer where M is sparse (a zero entry or minor is skipped).
    A polynomial in M's entries (no division: exact derivatives, no pole where a pivot
    vanishes). CasADi's own SX det expands without sharing minors: a 12 x 12 block of a
    suspension took seconds per sample and a graph IPOPT's Hessian could hardly build.

    >>> import casadi as ca
    >>> x = ca.SX.sym("x", 3)
    >>> M = ca.vertcat(ca.horzcat(x[0], 1, 0), ca.horzcat(2, x[1], 0), ca.horzcat(0, 0, x[2]))
    >>> ca.Function("d", [x], [determinant(M)])([1, 3, 5])  # (1 * 3 - 2) * 5
    DM(5)
    """
    n = M.shape[0]
    minors = {0: ca.SX(1)}  # a set of columns as a bit mask -> its minor on the last rows
    for k in range(1, n + 1):
        row, nxt = n - k, {}
        for S, d in minors.items():
            for j in range(n):
                if S >> j & 1 or M[row, j].is_zero():
                    continue
                T = S | 1 << j
                before = bin(T & ((1 << j) - 1)).count("1")  # columns of T left of j
                term = M[row, j] * d if before % 2 == 0 else -(M[row, j] * d)
                nxt[T] = nxt[T] + term if T in nxt else term
        minors = nxt
    return minors.get((1 << n) - 1, ca.SX(0))
