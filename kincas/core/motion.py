"""Equations of motion in the free inputs, read off kincas's own efforts, as CasADi Functions.

The free inputs u_f are the coordinates of the motion (the others, u_p, are prescribed
functions of time). The unknowns q(u) solve g(q, u, p) = 0; the chain's velocities are
z' = Z u' with Z = dz/du = (-g_q^-1 g_u ; I) (the same Jacobians as the kinematics). Virtual
work with d'Alembert's inertia forces gives the effort each input must supply
(kincas/core/dynamics.py):

    effort(u, u', u'') = Z' M_body (Z u'' + Z' u') - Z' F(u, u', t)

exactly linear in u''. A free input is driven by nobody: its effort is zero. So with
E_f = effort of the free inputs,

    M(u) u_f'' + h(u, u', u_p'', t) = 0,   M = dE_f / du_f'' = Z_f' M_body Z_f,
    h = E_f at u_f'' = 0 (minus the generalised forces, plus the velocity terms),

M the reduced mass matrix of the kinetic energy (symmetric, positive definite away from
singular positions). Both are read off the one symbolic effort expression, so the motion
satisfies effort(KEY) = 0 exactly as kincas writes its kinetostatics.

Loads that are expressions of the state and time (kincas/core/motion_loads.py) enter as
parameters of the mechanism whose value is the expression: the effort stays kincas's own.

For the integrator, the state is x = (q~, u_f, u_f'), where q~ carries a guess of q: at
every evaluation CasADi's Newton rootfinder solves g(q, u, p) = 0 from q~ (exact, with its
derivatives by the implicit function theorem), and q~' = q' keeps the guess next to the
solution. The motion itself is the ODE in (u_f, u_f') only; q~ never enters it.

>>> import kincas
>>> m = kincas.Mechanism(ground={"O": (0, 0)},
...     links=[kincas.Link.bar("bob", "O", "A", 2, mass=3, cg=(2, 0))],
...     inputs=[kincas.Input.angle("bob")], gravity=(0, -9.81))
>>> mo = Motion(kincas.model_of(m), ["bob.angle"])
>>> a, _ = mo.accelerations([], [0.0], [0.0], 0.0, [])    # a pendulum at the horizontal
>>> round(float(a[0]), 12)                                 # -g / l
-4.905
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from ..errors import ModelError
from .motion_loads import substituted


class Motion:
    """M(u) u_f'' = -h(u, u', t) on a model, with the loads' expressions substituted.

    Parameters
    ----------
    model : kincas.core.numeric.Model
    free : list of str
        The free inputs' keys.
    expressions : dict, optional
        Parameter name -> LoadExpression: the parameter's value at each instant.
    angle : float
        The expressions' angle unit in radians (pi/180 for degrees).
    cams : list of str
        Cams whose contact force is watched (knife-edge and roller followers).
    """

    def __init__(self, model, free, expressions=None, angle: float = 1.0, cams=(), exact=False):
        sym = model.sym
        self.exact = exact
        self.model, self.sym, self.cams = model, sym, list(cams)
        bad = [k for k in free if k not in sym.ukeys]
        if bad or not free:
            raise ModelError(f"free: {bad or 'none'}: expected input keys among {sym.ukeys}")
        self.free = [sym.ukeys.index(k) for k in free]
        self.held = [k for k in range(sym.nu) if k not in self.free]
        nq, nu, npar, nf = sym.nq, sym.nu, sym.np, len(self.free)
        q, u, ud, p = (ca.SX.sym(n, k) for n, k in (("q", nq), ("u", nu), ("ud", nu), ("p", npar)))
        t, a_f, a_h = ca.SX.sym("t"), ca.SX.sym("a_f", nf), ca.SX.sym("a_h", nu - nf)
        p_eff = substituted(sym, q, u, ud, t, p, expressions or {}, angle)
        udd = ca.SX.zeros(nu)
        udd[self.free], udd[self.held] = a_f, a_h
        names = [f"effort({sym.ukeys[k]})" for k in self.free] + [f"contact({c})" for c in self.cams]
        out = sym.quantity_function(names)(q, u, p_eff, ud, udd)
        E, C = out[:nf], out[nf:]
        M = ca.jacobian(E, a_f)
        h = ca.substitute(E, a_f, ca.SX.zeros(nf))
        acc = -ca.solve(M, h)  # (symbolic LU of an nf x nf matrix: nf is small)
        C = ca.substitute(C, a_f, acc)
        args = [q, u, ud, t, p, a_h]
        self.f_acc = ca.Function("accelerations", args, [acc, C])
        self.f_mass = ca.Function("mass", args, [M])
        self.f_params = ca.Function("parameters", [q, u, ud, t, p], [p_eff])
        qd = -sym.lsolve(ca.mtimes(sym.Ju, ud))
        self.f_qdot = ca.Function("qdot", [sym.q, sym.u, sym.p, ud], [ca.densify(qd)])
        self._rhs, self._int = None, {}

    # --- numbers ---
    def accelerations(self, q, u, ud, t, p, a_held=None):
        """(u_f'', contact forces) at a state: q solved, u and u' full input vectors."""
        a_held = np.zeros(len(self.held)) if a_held is None else a_held
        acc, C = self.f_acc(q, u, ud, t, p, a_held)
        return np.asarray(acc).ravel(), np.asarray(C).ravel()

    def rhs(self):
        """The ODE x' = f(x, t; par) for CasADi's integrators, x = (q~, u_f, u_f'), par =
        (p, c0, c1, c2) with the held inputs u_h = c0 + c1 t + c2 t^2 / 2: an MX dict
        {"x", "t", "p", "ode"} and, under "post", (q, u_f'', contact forces, vec(g_q), vec(g_u_f))."""
        if self._rhs is None:
            sym, nq, nf, nh = self.sym, self.sym.nq, len(self.free), len(self.held)
            x, t = ca.MX.sym("x", nq + 2 * nf), ca.MX.sym("t")
            par = ca.MX.sym("par", sym.np + 3 * nh)
            p, c = par[:sym.np], par[sym.np:]
            c0, c1, c2 = c[:nh], c[nh:2 * nh], c[2 * nh:]
            u, ud = ca.MX.zeros(sym.nu), ca.MX.zeros(sym.nu)
            u[self.free], ud[self.free] = x[nq:nq + nf], x[nq + nf:]
            if nh:
                u[self.held], ud[self.held] = c0 + c1 * t + c2 * t ** 2 / 2, c1 + c2 * t
            qs = self.rootfinder()(x[:nq], ca.vertcat(u, p))
            acc, C = self.f_acc(qs, u, ud, t, p, c2)
            J, Ju = ca.Function("jq", [sym.q, sym.u, sym.p], [ca.densify(sym.Jq), ca.densify(sym.Ju[:, self.free])])(qs, u, p)
            post = ca.Function("post", [x, t, par], [qs, acc, C, ca.vec(J), ca.vec(Ju)])
            if self.exact:  # q solved at every evaluation of the ODE
                ode = ca.vertcat(self.f_qdot(qs, u, p, ud), x[nq + nf:], acc)
                self._rhs = {"x": x, "t": t, "p": par, "ode": ode, "post": post}
            else:  # q carried by q' = -g_q^-1 g_u u' (one SX graph), solved at the outputs
                xs, ts, ps = ca.SX.sym("x", x.numel()), ca.SX.sym("t"), ca.SX.sym("par", par.numel())
                us, uds = ca.SX.zeros(sym.nu), ca.SX.zeros(sym.nu)
                us[self.free], uds[self.free] = xs[nq:nq + nf], xs[nq + nf:]
                cs = ps[sym.np:]
                if nh:
                    us[self.held] = cs[:nh] + cs[nh:2 * nh] * ts + cs[2 * nh:] * ts ** 2 / 2
                    uds[self.held] = cs[nh:2 * nh] + cs[2 * nh:] * ts
                a, _ = self.f_acc(xs[:nq], us, uds, ts, ps[:sym.np], cs[2 * nh:])
                ode = ca.vertcat(self.f_qdot(xs[:nq], us, ps[:sym.np], uds), xs[nq + nf:], a)
                self._rhs = {"x": xs, "t": ts, "p": ps, "ode": ode, "post": post}
        return self._rhs

    # --- integrators (numbers in, numbers out: the analysis floor holds no CasADi object) ---
    def integrate(self, x0, par, t0: float, h: float, n: int, tol: float) -> np.ndarray:
        """The states at t0 + h, ..., t0 + n h (one row each) from x0 at t0, by CVODES
        (Adams, functional iteration: the motion is not stiff). RuntimeError when it fails.
        One integrator per (n, tol) serves every interval: time enters as t0 + h tau."""
        key = ("integrator", self.exact, n, tol)
        if key not in self._int:
            from .tolerances import SIM_ATOL, SIM_MAX_STEPS, SIM_RTOL
            dae = self.rhs()
            S = type(dae["x"])  # SX (q carried) or MX (q solved inside)
            x, par_, tau, t0h = (S.sym("x", dae["x"].numel()), S.sym("par", dae["p"].numel()),
                                 S.sym("tau"), S.sym("t0h", 2))
            f = ca.Function("f", [dae["x"], dae["t"], dae["p"]], [dae["ode"]])
            ode = t0h[1] * f(x, t0h[0] + t0h[1] * tau, par_)
            self._int[key] = _cvodes({"x": x, "t": tau, "p": ca.vertcat(par_, t0h), "ode": ode},
                                     n, tol, SIM_ATOL / SIM_RTOL * tol, SIM_MAX_STEPS)
        out = self._int[key](x0=x0, p=np.concatenate([par, [t0, h]]))
        return np.asarray(out["xf"]).T

    def post(self, xs, ts, par):
        """(q, u_f'', contact forces, vec(g_q), vec(g_u) of the free inputs) at states xs (one row each) at times ts, as
        numpy columns; RuntimeError where Newton finds no q."""
        n = len(ts)
        out = self.rhs()["post"].map(n)(np.asarray(xs).T, np.asarray(ts, float), np.tile(np.reshape(par, (-1, 1)), n))
        return tuple(np.asarray(a) for a in out)

    def parameters(self, Q, U, Ud, ts, P):
        """The parameters at each state (columns), the loads' expressions evaluated."""
        n = len(ts)
        return np.asarray(self.f_params.map(n)(Q, U, Ud, np.asarray(ts, float), P))

    def mass(self, q, u, ud, t, p):
        """The reduced mass matrix M(u) at a solved state."""
        return np.asarray(self.f_mass(q, u, ud, t, p, np.zeros(len(self.held))))

    def rootfinder(self):
        """q(u, p) by CasADi's Newton from a guess: g = 0 (g_q' g = 0 where g_q is tall)."""
        sym = self.sym
        q, up = ca.SX.sym("q", sym.nq), ca.vertcat(sym.u, sym.p)
        g = ca.substitute(sym.g, sym.q, q)
        if sym.ng > sym.nq:
            g = ca.mtimes(ca.jacobian(g, q).T, g)
        G = ca.Function("g", [q, up], [g])
        from .tolerances import ROOT_ABSTOL, ROOT_STEPTOL
        return ca.rootfinder("q_of_u", "newton", G, {"abstol": ROOT_ABSTOL * self._size(),
                                                     "abstolStep": ROOT_STEPTOL, "max_iter": 50,
                                                     "error_on_fail": True})

    def _size(self) -> float:
        m = self.sym.mech
        return max(1.0, m.size()) if hasattr(m, "size") else 1.0


def _cvodes(dae, n, tol, atol, steps):
    """CVODES over tau = 1..n (or the grid's fractions), Adams with functional iteration."""
    grid = list(range(1, n + 1)) if isinstance(n, int) else list(n)
    opts = {"reltol": tol, "abstol": atol, "max_num_steps": steps, "show_eval_warnings": False,
            "linear_multistep_method": "adams", "nonlinear_solver_iteration": "functional"}
    return ca.integrator("motion", "cvodes", dae, 0, grid, opts)


class CycleODE:
    """One free angle theta as the independent variable over a cycle Theta:
    y = (t, q, w), dt/dtheta = 1/w, dq/dtheta = q'/w, dw/dtheta = theta''/w, with
    theta = theta0 + Theta tau, tau in [0, 1] (kincas/analysis/steady.py shoots on it)."""

    def __init__(self, mo: Motion):
        sym, nq = mo.sym, mo.sym.nq
        y, tau, par = ca.SX.sym("y", nq + 2), ca.SX.sym("tau"), ca.SX.sym("par", sym.np + 2)
        p, theta = par[:sym.np], par[sym.np] + par[sym.np + 1] * tau
        t, q, w = y[0], y[1:nq + 1], y[nq + 1]
        u, ud = ca.SX.zeros(sym.nu), ca.SX.zeros(sym.nu)
        u[mo.free[0]], ud[mo.free[0]] = theta, w
        acc, _ = mo.f_acc(q, u, ud, t, p, ca.SX(0, 1))
        dy = ca.vertcat(1 / w, mo.f_qdot(q, u, p, ud) / w, acc / w) * par[sym.np + 1]
        self.f_slope = ca.Function("slope", [y, tau, par], [dy])
        self.dae, self._int = {"x": y, "t": tau, "p": par, "ode": dy}, {}

    def run(self, y0, par, n: int, tol: float, upto: float = 1.0) -> np.ndarray:
        """y at tau = upto k / n, k = 1..n, from y0 at tau = 0 (one row each)."""
        if (n, tol) not in self._int:
            from .tolerances import SIM_ATOL, SIM_MAX_STEPS, SIM_RTOL
            self._int[(n, tol)] = _cvodes(self.dae, [k / n for k in range(1, n + 1)], tol,
                                          SIM_ATOL / SIM_RTOL * tol, 4 * SIM_MAX_STEPS)
        pp = np.array(par, float)
        pp[-1] *= upto  # a part of the cycle: theta = theta0 + (upto Theta) tau
        return np.asarray(self._int[(n, tol)](x0=y0, p=pp)["xf"]).T

    def slope(self, y, tau, par) -> np.ndarray:
        return np.asarray(self.f_slope(y, tau, par)).ravel()
