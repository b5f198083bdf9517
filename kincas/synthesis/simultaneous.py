"""The simultaneous NLP behind `kincas.optimize`, and the checks of IPOPT's answer.

Variables: the varied parameters (scaled by their size), the unknowns q_k at every sample
(lengths divided by the mechanism's size), and for each max()/min() an extra sample (q*, u*).
Equality constraints: g(q_k, u_k, p) / L = 0 at every sample; at an extra sample also its
closure and dE/du = 0. Inequalities: sign_k det(g_q(q_k)) >= 0, which keeps every sample on
the initial design's assembly branch (and off singular positions); then the user's
constraints. Everything is one CasADi SX graph, so IPOPT gets exact gradients and Hessians.

>>> from kincas.optimize import optimize  # the public entry point; see its docstring
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import ModelError
from .expressions import CONST, SAMPLE, Evaluator, parse
from ..model.mechanism import Mechanism
from .checks import Checks, _short
from ..results import Sweep, wrap_angle

REFINE = 400  # poses of the checking sweep between the first and the last sample, at least
CON_TOL = 1e-6  # relative violation allowed of a constraint after polishing


# --- the problem: parsing, the NLP, the checks ---


class Problem(Checks):
    """One optimisation: parses the expressions, builds the NLP, runs IPOPT, checks."""

    def __init__(self, m: Mechanism, model, vary, data, deg):
        import casadi as ca

        self.ca, self.m, self.model, self.sym = ca, m, model, model.sym
        self.deg, self.L = deg, m.size()
        self.p0 = np.array([v for _, v in m.parameters], dtype=float)
        driven = {i.target for i in m.inputs if i.kind == "parameter"}
        problems = []
        if not isinstance(vary, dict) or not vary:
            problems.append("vary: expected a table of parameter names and [low, high] bounds")
            vary = {}
        self.vary = {}
        for p, b in vary.items():
            if p not in m.param_values:
                problems.append(f"vary: {p}: unknown parameter (declare it in [parameters])")
            elif p in driven:
                problems.append(f"vary: {p}: driven by an input, so it cannot be optimised")
            elif (not isinstance(b, (tuple, list)) or len(b) != 2
                  or not all(isinstance(x, (int, float)) and not isinstance(x, bool)
                             and math.isfinite(x) for x in b) or not b[0] < b[1]):
                problems.append(f"vary: {p}: expected bounds [low, high] with low < high, got {b!r}")
            elif not b[0] <= m.parameter(p) <= b[1]:
                problems.append(f"vary: {p}: the initial value {m.parameter(p):g} is outside "
                                f"[{b[0]:g}, {b[1]:g}]")
            else:
                self.vary[p] = (float(b[0]), float(b[1]))
        self.data = {}
        for k, v in (data or {}).items():
            a = np.asarray(v, dtype=float) if _numbers(v) else None
            if a is None or a.ndim != 1 or not np.all(np.isfinite(a)):
                problems.append(f"data: {k}: expected a list of finite numbers")
            elif k in m.param_values:
                problems.append(f"data: {k}: a parameter has that name")
            else:
                self.data[k] = a
        if problems:
            raise ModelError(problems)
        nv = len(self.vary)
        self.xp = ca.SX.sym("xp", nv)
        self.pscale = np.array([max(abs(m.parameter(p)), hi - lo) for p, (lo, hi) in self.vary.items()])
        P = [self.p0[i] for i in range(len(self.p0))]
        for j, p in enumerate(self.vary):
            P[self.sym.pnames.index(p)] = self.xp[j] * self.pscale[j]
        self.P = ca.vertcat(*P) if P else ca.SX(0, 1)
        self.ud, self.udd = ca.SX.sym("ud", self.sym.nu), ca.SX.sym("udd", self.sym.nu)
        self.ds = ca.SX.sym("data", len(self.data))
        self.qs = np.where(self.sym.is_length, self.L, 1.0)  # unknowns scaled to O(1)
        self.extremes: dict[tuple, dict] = {}
        self.used: list[str] = []
        self.Uv = None  # the sample inputs as variables (a curve: see kincas.curve)

    # --- parsing ---
    def parse(self, text, where):
        e = parse(text, where, data=self.data)
        bad = self.sym.check_names(e.quantities, where)
        bad += [f"{where}: unknown name {n!r} (not a parameter, a data array or pi)"
                for n in e.names if n not in self.m.param_values]
        if bad:
            raise ModelError(bad)
        self.used += [q for q in e.quantities if q not in self.used]
        return e

    def parse_constraint(self, c, i):
        where = f"constraints[{i + 1}]"
        for k in ("min", "max"):
            v = getattr(c, k)
            if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float))
                                  or not math.isfinite(v)):
                raise ModelError(f"{where}: {k}: expected a finite number, got {v!r}")
        if c.min is None and c.max is None:
            raise ModelError(f"{where}: give min, max or both")
        if c.min is not None and c.max is not None and c.min > c.max:
            raise ModelError(f"{where}: min {c.min:g} is above max {c.max:g}")
        return c, self.parse(c.expr, f"{where} {c.expr!r}")

    # --- the samples, their starting poses, the checking path ---
    def set_samples(self, sw0: Sweep, sweep_fn):
        ca, sym, model, m = self.ca, self.sym, self.model, self.m
        self.sweep_fn, self.keys = sweep_fn, list(sw0.inputs)
        col = lambda d: np.stack([d[k] for k in self.keys], axis=1)
        self.U, self.Ud, self.Udd = col(sw0.inputs), col(sw0.rates), col(sw0.accelerations)
        K = self.K = len(sw0)
        bad = [f"data: {k}: {len(a)} values for {K} samples" for k, a in self.data.items()
               if len(a) != K]
        if bad:
            raise ModelError(bad)
        self.D = np.stack(list(self.data.values())) if self.data else np.zeros((0, K))
        Q0, ok = sw0.q.copy(), sw0.ok
        solved = np.flatnonzero(ok)
        guess = {k: (m.value(x), m.value(y)) for k, (x, y) in m.guess}
        for k in np.flatnonzero(~ok):  # start where it did not assemble from a neighbour
            Q0[k] = (Q0[solved[np.argmin(np.abs(solved - k))]] if len(solved)
                     else model.initial_q(self.U[k], self.p0, guess, self.L))
        angle = ~sym.is_length
        Q0[:, angle] = wrap_angle(Q0[:, angle])  # expressions see angles as reported
        self.Q0, self.initial_status = Q0, list(sw0.status)
        self.ref = np.array([self.sign(Q0[k], self.U[k], self.p0) if ok[k] else 0.0
                             for k in range(K)])
        self.Qv = ca.SX.sym("q", sym.nq, K)
        self.Q = self.Qv * ca.DM(self.qs) if sym.nq else self.Qv
        self.make_path()
        self._dense0 = None

    def make_path(self):
        """The checking path: the samples with REFINE poses in between, in order."""
        K = self.K
        sub = max(2, math.ceil(REFINE / max(K - 1, 1))) if K > 1 else 1
        t = np.arange((K - 1) * sub + 1) / sub
        idx = np.minimum(np.floor(t).astype(int), K - 1)
        nxt, frac = np.minimum(idx + 1, K - 1), (t - idx)[:, None]
        lerp = lambda A: A[idx] + (A[nxt] - A[idx]) * frac
        self.path = (lerp(self.U), lerp(self.Ud), lerp(self.Udd))
        self.at = np.arange(K) * sub

    def free_inputs(self, lo, hi, rows, scale, normal=None):
        """Make the (single) input at every sample a variable u_k = scale * v_k with bounds
        lo <= u_k <= hi (arrays) and extra constraints rows(u) -> [(SX, low, high)];
        normal(U) gives the fitted inputs as reported (whole turns taken off)."""
        if self.extremes:
            raise ModelError("max()/min() cannot be combined with a curve (its inputs are fitted)")
        self.Uv = self.ca.SX.sym("u", self.K)
        self.us, self.ulo, self.uhi = scale, np.asarray(lo) / scale, np.asarray(hi) / scale
        self.urows, self.unormal = rows(self.Uv * scale), normal

    def u_at(self, k):
        """The input at sample k: a number, or the variable when the inputs are fitted."""
        return self.U[k] if self.Uv is None else self.Uv[k] * self.us

    def sign(self, q, u, p) -> float:
        """Sign of det(g_q) with columns scaled to O(1): it tells the assembly branch."""
        if not self.sym.nq:
            return 1.0
        return float(np.sign(np.linalg.det(self.model.jac(q, u, p) * (1.0 / self.qs))))

    def dense(self, mech, guess=None):
        U, Ud, Udd = self.path
        return self.sweep_fn(mech, {k: U[:, j] for j, k in enumerate(self.keys)},
                             rates={k: Ud[:, j] for j, k in enumerate(self.keys)},
                             accelerations={k: Udd[:, j] for j, k in enumerate(self.keys)},
                             report=list(self.used), guess=guess)

    # --- expressions into the NLP's variables ---
    def leaf(self, kind, name):
        from ..core.symbolic import is_angular
        ca, sym = self.ca, self.sym
        if kind == "quantity":
            e = self.model.quantity_function((name,))(sym.q, sym.u, sym.p, self.ud, self.udd)
            return SAMPLE, (e * (180 / math.pi) if self.deg and is_angular(name, self.m) else e)
        if kind == "data":
            return SAMPLE, self.ds[list(self.data).index(name)]
        v = sym.val(name)
        return (SAMPLE if sym.nu and ca.depends_on(v, sym.u) else CONST), v

    def fn(self, E):
        ca, sym = self.ca, self.sym
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
        return self.ca.substitute(E, self.sym.p, self.P)

    def evaluate(self, e, where, objective=False):
        ev = Evaluator(self.leaf, self.aggregate, self.total,
                       angle=math.pi / 180 if self.deg else 1.0)
        kind, v = ev(e)
        if kind == SAMPLE and objective:
            raise ModelError(f"{where}: the objective changes from sample to sample: "
                             f"wrap it in sum(), mean(), max() or min()")
        if kind == SAMPLE:
            F = self.fn(v)
            return kind, self.ca.vertcat(*[self.at_sample(F, k) for k in range(self.K)])
        return kind, (self.total(v) if kind == CONST else v)

    def extreme(self, f, E, text):
        """max/min of E over the input's range: a sample of its own whose input is free and
        held where dE/du = 0, started at the extreme of the initial design's checking sweep."""
        ca, sym, key = self.ca, self.sym, (f, text)
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
        periodic = self.m.inputs[0].is_angle and span >= 2 * math.pi - 1e-9
        end = i in (0, len(U) - 1) and not periodic
        rows = [sym.f_res(qe, ux, self.P) / self.L]
        if not end:  # stationary: dE/du = E_q dq/du + E_u with dq/du = -g_q^-1 g_u
            dE = ca.mtimes(ca.jacobian(E, sym.q), -ca.solve(sym.Jq, sym.Ju)) + ca.jacobian(E, sym.u)
            scale = max(float(np.ptp(vals)), 1e-9 * float(np.abs(vals).max()), 1e-300)
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

    # --- IPOPT ---
    def solve(self, f, rows, check_path, max_iter, tol) -> dict:
        ca, sym, K = self.ca, self.sym, self.K
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
        # The branch is kept at every sample: det(g_q) keeps the initial design's sign there
        # (a polynomial in q, so its derivatives are exact too; it also keeps the samples off
        # singular positions, where det(g_q) = 0).
        poses = [(self.Q[:, k], self.u_at(k), self.ref[k]) for k in range(K)]
        poses += [(e["x"][0] * ca.DM(self.qs), e["x"][1], e["sign"]) for e in ext]
        for q, u, sign in poses:
            if sign and sym.nq:
                J = sym.f_resjac(q, u, self.P)[1] * ca.repmat(ca.DM(self.qs).T, sym.nq, 1) / self.L
                G.append(sign * ca.det(J))
                lbg.append(np.zeros(1))
                ubg.append(np.full(1, np.inf))
        self.n_fixed = sum(np.size(b) for b in lbg)  # closure, extremes, branch rows
        for c, (_, g) in rows:
            G.append(g)
            lbg.append(np.full(g.numel(), -np.inf if c.min is None else c.min))
            ubg.append(np.full(g.numel(), np.inf if c.max is None else c.max))
        G = ca.vertcat(*G)
        opts = {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes",
                "ipopt.max_iter": int(max_iter), "ipopt.tol": tol, "error_on_fail": False,
                "ipopt.bound_relax_factor": 0.0}
        solver = ca.nlpsol("kincas_optimize", "ipopt", {"x": X, "f": f, "g": G}, opts)
        out = solver(x0=x0, lbx=lbx, ubx=ubx, lbg=np.concatenate(lbg), ubg=np.concatenate(ubg))
        stats = solver.stats()
        fg = ca.Function("fg", [X], [f, G])
        f0 = float(fg(x0)[0])
        return self.check(np.asarray(out["x"]).ravel(), fg, f0, rows, stats, check_path)

    # --- the checks: a design is optimal only if it really is one ---
    def check(self, x, fg, f0, rows, stats, check_path) -> dict:
        sym, K, model, nv = self.sym, self.K, self.model, len(self.vary)
        problems = []
        # IPOPT may relax a bound by a few 1e-9: the design is clipped into its bounds
        varied = {p: float(np.clip(x[j] * self.pscale[j], *self.vary[p]))
                  for j, p in enumerate(self.vary)}
        mech = self.m.with_parameters(**varied)
        p = np.array([v for _, v in mech.parameters])
        Q = x[nv:nv + sym.nq * K].reshape(K, sym.nq) * self.qs
        at = nv + sym.nq * K
        if self.Uv is not None:  # fitted inputs: the checks and the report follow them
            self.U = x[at:at + K, None] * self.us
            self.U = self.U if self.unormal is None else self.unormal(self.U)
            at += K
            self.make_path()
        for k in range(K):  # polish, and judge by the residual and the branch
            sol = model.newton(Q[k], self.U[k], p, self.L)
            Q[k] = sol.q
            if not sol.ok:
                problems.append(f"sample {k + 1}: the optimised design does not assemble "
                                f"(residual {sol.residual:.2g} of its size)")
            elif self.ref[k] and self.sign(sol.q, self.U[k], p) != self.ref[k]:
                problems.append(f"sample {k + 1}: the optimised design is on another assembly "
                                f"branch than the initial one")
        xs = [x[:nv], (Q / self.qs).ravel(), *([self.U[:, 0] / self.us] if self.Uv is not None else [])]
        for e in self.extremes.values():
            q, u = x[at:at + sym.nq] * self.qs, x[at + sym.nq]
            sol = model.newton(q, np.array([u]), p, self.L)
            e["u"], e["q"], at = u, sol.q, at + sym.nq + 1
            if not sol.ok:
                problems.append(f"{e['fn']}({e['text']}): the design does not assemble at its extreme")
            xs.append(np.r_[sol.q / self.qs, u])
        xp = np.concatenate(xs)
        fval, g = (np.asarray(v).ravel() for v in fg(xp))
        first = self.n_fixed
        cons = []
        for c, (kind, gr) in rows:
            v = g[first:first + gr.numel()]
            first += gr.numel()
            okc = True
            for b, sgn in ((c.min, 1), (c.max, -1)):
                if b is not None and np.any(sgn * (v - b) < -CON_TOL * max(1.0, abs(b))):
                    okc = False
            if not okc:
                problems.append(f"constraint {c.expr!r} does not hold (values {_short(v)}, "
                                f"bounds [{c.min}, {c.max}])")
            cons.append({"expr": c.expr, "min": c.min, "max": c.max, "kind": kind,
                         "value": v if kind == SAMPLE else float(v[0]), "satisfied": okc})
        pts = model.points(Q[0], self.U[0], p)
        mech = mech.with_guess(**{n: tuple(pts[:, j]) for j, n in enumerate(self.m.moving_points)})
        sw, values = self.check_path(mech, Q, p, problems, check_path)
        extremes = self.check_extremes(sw, p, problems)
        success = bool(stats.get("success", False))
        status = str(stats.get("return_status", "unknown"))
        ok = success and not problems
        msg = ("converged; the optimised design assembles at every sample on the initial branch"
               if ok else f"IPOPT: {status}" if not success else "not optimal: " + problems[0])
        return dict(
            ok=ok, converged=success, status=status, message=msg, objective=float(fval[0]),
            initial_objective=f0, parameters=mech.param_values, varied=varied, mechanism=mech,
            samples={k: self.U[:, j].copy() for j, k in enumerate(self.keys)}, q=Q,
            values=values, constraints=cons, extremes=extremes,
            iterations=int(stats.get("iter_count", 0)), problems=problems, sweep=sw)


def _numbers(v) -> bool:
    return isinstance(v, (list, tuple, np.ndarray)) and all(
        isinstance(x, (int, float, np.floating, np.integer)) and not isinstance(x, bool) for x in v)
