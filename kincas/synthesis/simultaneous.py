"""The simultaneous NLP behind `kincas.optimize`: reading its input, and the checks of
IPOPT's answer. The problem itself (variables, constraints, the branch kept by the sign of
det(g_q) at every sample, the IPOPT call) is built symbolically in kincas/core/nlp.py.

>>> from kincas.optimize import optimize  # the public entry point; see its docstring
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import ModelError
from ..core.nlp import SampledNLP
from .expressions import SAMPLE, Evaluator, parse
from ..model.mechanism import Mechanism
from .checks import Checks, _short
from ..results import Sweep, wrap_angle

REFINE = 400  # poses of the checking sweep between the first and the last sample, at least
CON_TOL = 1e-6  # relative violation allowed of a constraint after polishing


# --- the problem: parsing, the NLP, the checks ---


class Problem(Checks, SampledNLP):
    """One optimisation: parses the expressions, builds the NLP (kincas/core/nlp.py), runs
    IPOPT, checks."""

    evaluator = Evaluator  # the expression language, for SampledNLP

    def __init__(self, m: Mechanism, model, vary, data, deg):
        self.m, self.model = m, model
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
        self.pscale = np.array([max(abs(m.parameter(p)), hi - lo) for p, (lo, hi) in self.vary.items()])
        self.make_symbols()
        self.qs = np.where(self.model.is_length, self.L, 1.0)  # unknowns scaled to O(1)
        self.extremes: dict[tuple, dict] = {}
        self.used: list[str] = []
        self.Uv = None  # the sample inputs as variables (a curve: see kincas.curve)

    # --- parsing ---
    def parse(self, text, where):
        e = parse(text, where, data=self.data)
        bad = self.model.check_names(e.quantities, where)
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
        model, m = self.model, self.m
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
        guess = {k: tuple(m.value(c) for c in xy) for k, xy in m.guess}  # 2 or 3 coordinates
        for k in np.flatnonzero(~ok):  # start where it did not assemble from a neighbour
            Q0[k] = (Q0[solved[np.argmin(np.abs(solved - k))]] if len(solved)
                     else model.initial_q(self.U[k], self.p0, guess, self.L))
        angle = ~model.is_length
        Q0[:, angle] = wrap_angle(Q0[:, angle])  # expressions see angles as reported
        self.Q0, self.initial_status = Q0, list(sw0.status)
        none = np.zeros(len(self.model.blocks))
        self.ref = np.array([self.sign(Q0[k], self.U[k], self.p0) if ok[k] else none
                             for k in range(K)]).reshape(K, -1)
        self.make_sample_unknowns()
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
        Uv = self.make_free_inputs()
        self.us, self.ulo, self.uhi = scale, np.asarray(lo) / scale, np.asarray(hi) / scale
        self.urows, self.unormal = rows(Uv * scale), normal

    def u_at(self, k):
        """The input at sample k: a number, or the variable when the inputs are fitted."""
        return self.U[k] if self.Uv is None else self.Uv[k] * self.us

    def sign(self, q, u, p) -> np.ndarray:
        """Per Assur group (`model.blocks`), the sign of its block's determinant: the assembly
        branch group by group, as sweeps tell it (two groups flipping together keep det(g_q)'s
        sign but are another assembly). 0 for a tall group (redundant joints: no determinant;
        the rank rules keep it)."""
        J = self.model.jac(q, u, p)
        return np.array([np.sign(np.linalg.det(J[np.ix_(b.rows, b.cols)])) if b.rows.size == b.cols.size
                         else 0.0 for b in self.model.blocks])

    def dense(self, mech, guess=None):
        U, Ud, Udd = self.path
        return self.sweep_fn(mech, {k: U[:, j] for j, k in enumerate(self.keys)},
                             rates={k: Ud[:, j] for j, k in enumerate(self.keys)},
                             accelerations={k: Udd[:, j] for j, k in enumerate(self.keys)},
                             report=list(self.used), guess=guess)

    # --- the checks: a design is optimal only if it really is one ---
    def check(self, x, fg, f0, rows, stats, check_path) -> dict:
        K, model, nv = self.K, self.model, len(self.vary)
        problems = []
        # IPOPT may relax a bound by a few 1e-9: the design is clipped into its bounds
        varied = {p: float(np.clip(x[j] * self.pscale[j], *self.vary[p]))
                  for j, p in enumerate(self.vary)}
        mech = self.m.with_parameters(**varied)
        p = np.array([v for _, v in mech.parameters])
        Q = x[nv:nv + model.nq * K].reshape(K, model.nq) * self.qs
        at = nv + model.nq * K
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
            elif self.ref[k].any() and np.any(self.sign(sol.q, self.U[k], p) != self.ref[k]):
                problems.append(f"sample {k + 1}: the optimised design is on another assembly "
                                f"branch than the initial one")
        xs = [x[:nv], (Q / self.qs).ravel(), *([self.U[:, 0] / self.us] if self.Uv is not None else [])]
        for e in self.extremes.values():
            q, u = x[at:at + model.nq] * self.qs, x[at + model.nq]
            sol = model.newton(q, np.array([u]), p, self.L)
            e["u"], e["q"], at = u, sol.q, at + model.nq + 1
            if not sol.ok:
                problems.append(f"{e['fn']}({e['text']}): the design does not assemble at its extreme")
            xs.append(np.r_[sol.q / self.qs, u])
        xp = np.concatenate(xs)
        fval, g = fg(xp)
        first = self.n_fixed
        cons = []
        for (c, (kind, _)), n in zip(rows, self.row_sizes):
            v = g[first:first + n]
            first += n
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
            inputs={k: self.U[:, j].copy() for j, k in enumerate(self.keys)}, q=Q,
            values=values, constraints=cons, extremes=extremes,
            iterations=int(stats.get("iter_count", 0)), problems=problems, sweep=sw)


def _numbers(v) -> bool:
    return isinstance(v, (list, tuple, np.ndarray)) and all(
        isinstance(x, (int, float, np.floating, np.integer)) and not isinstance(x, bool) for x in v)
