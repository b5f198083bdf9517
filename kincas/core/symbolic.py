"""Loop-closure residuals and quantity expressions of a mechanism, as CasADi Functions.

Unknowns q: the angle of every link that hangs on a point of what is already placed, and
(x, y, angle) of a link that floats; a link driven by an angle input takes the input instead
of an unknown. Inputs u: one per `Input` (a driven parameter is replaced by its input).
Parameters p: every named parameter. The residual g(q, u, p) = 0 is square, or tall when
the mechanism has redundant joints (`Mechanism.redundant` equations implied by the others,
kincas/redundant.py): then g_q has full column rank at a regular pose and the system is
consistent, so each linear solve below is done by its normal equations,
g_q' g_q x = g_q' b, which give the exact solution of a consistent g_q x = b.

Time derivatives come from the exact Jacobians. With z = (q, u):
    g_q q' = -g_u u'                                   (velocities)
    g_q q'' = -g_u u'' - d2g/dz2 [z', z']              (accelerations)
    g_q q''' = -g_u u''' - (d/dt g'' at fixed z'')     (jerks)
and a quantity E(z) has E' = E_z z', E'' = E_z z'' + d2E/dz2 [z', z'], and so on: each time
derivative is the operator D = (d/dz) z' + (d/dz') z'' + (d/dz'') z''' (kincas/core/geometry.py).
Efforts, reactions and shaking forces (kincas/core/dynamics.py) and the kinematic geometry
(curvature, instant centres) are more quantities written with the same operator.

>>> from kincas.model import Mechanism, Link, Input
>>> m = Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[Link.bar("crank", "A", "B", 1), Link.bar("coupler", "B", "C", 3.5),
...            Link.bar("rocker", "D", "C", 3)], inputs=[Input.angle("crank")])
>>> s = Symbolic(m)
>>> s.nq, s.nu, [k for k, _ in s.unknowns]
(2, 1, ['rocker.angle', 'coupler.angle'])
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from ..errors import ModelError
from ..model.mechanism import GROUND, Mechanism, as_param
from ..model.names import LINK_Q, POINT_Q, SENS, SLIDE_Q, default_report, is_angular, parse_quantity  # noqa: F401
from . import joints as _joints
from .tolerances import JAMMED

# --- quantity names (kincas/model/names.py: parsed without the solver) ---

_POINT_Q, _LINK_Q, _SLIDE_Q, _SENS = POINT_Q, LINK_Q, SLIDE_Q, SENS


def _extras():
    """Modules that define more quantities (each: `check(sym, name)` -> None when the name is
    not theirs, else a list of problems; `expression(sym, name, t)` -> SX)."""
    from . import dynamics, geometry
    return geometry, dynamics, _joints


def needs_jerk(name: str) -> bool:
    """Whether a quantity depends on the inputs' jerks (a third time derivative)."""
    kind, a, b = parse_quantity(name)
    if kind == "sens":
        return needs_jerk(a)
    return b in ("jx", "jy", "jerk")


class Symbolic:
    """The symbolic model of one mechanism structure; parameters stay symbolic."""

    dim = 2  # coordinates of a point (kincas/core/space_symbolic.py: 3)

    def __init__(self, mech: Mechanism):
        self.mech = mech
        self.pnames = [k for k, _ in mech.parameters]
        self.ukeys = [i.key for i in mech.inputs]
        self.np, self.nu = len(self.pnames), len(mech.inputs)
        self.p = ca.SX.sym("p", self.np)
        self.u = ca.SX.sym("u", self.nu)
        driven = {i.target: self.u[k] for k, i in enumerate(mech.inputs) if i.kind == "parameter"}
        self._pvar = {n: driven.get(n, self.p[k]) for k, n in enumerate(self.pnames)}
        self._build()

    # --- numbers to expressions ---
    def val(self, v):
        p = as_param(v)
        return ca.SX(float(v)) if p is None else p.scale * self._pvar[p.name]

    def _build(self):
        m = self.mech
        angle_in = {i.target: self.u[k] for k, i in enumerate(m.inputs) if i.kind == "angle"}
        qs, self.unknowns = [], []  # unknowns: (name, "angle" | "length")
        self.frames: dict[str, tuple] = {GROUND: (ca.SX(0), ca.SX(0), ca.SX(0))}
        self.points = {g: (self.val(x), self.val(y)) for g, (x, y) in m.ground}
        eqs = []

        def new(name, kind):
            qs.append(ca.SX.sym(name))
            self.unknowns.append((name, kind))
            return qs[-1]

        # Each point also as (the ground point it hangs from, the sum of link vectors from
        # there): a loop closure is written as the difference of the two ground points (exact
        # for numbers) plus the difference of the two sums, so its rounding is that of the
        # links' lengths, not of the coordinates. A point 160 from the origin (the 40th of
        # chained four-bars 4 apart) would otherwise carry rounding of 160 ulps into g, and
        # the next Newton step's floor above STEP (the fast kernel's acceptance).
        rel = {g: (g, (ca.SX(0), ca.SX(0))) for g, _ in m.ground}
        for lname, at in m.structure.order:
            lk = m.link(lname)
            loc = {p: (self.val(x), self.val(y)) for p, (x, y) in lk.points}
            th = angle_in[lname] if lname in angle_in else new(f"{lname}.angle", "angle")
            c, s = ca.cos(th), ca.sin(th)
            if at is None:  # floating: its origin is unknown too
                ox, oy = new(f"{lname}.x", "length"), new(f"{lname}.y", "length")
                base, (rx, ry) = None, (ox, oy)
            else:  # hangs on point `at`: origin = P - R(th) p_local
                (px, py), (lx, ly) = self.points[at], loc[at]
                ox, oy = px - (c * lx - s * ly), py - (s * lx + c * ly)
                base, (ax, ay) = rel[at]
                rx, ry = ax - (c * lx - s * ly), ay - (s * lx + c * ly)
            self.frames[lname] = (ox, oy, th)
            for p, (lx, ly) in loc.items():
                w = (ox + c * lx - s * ly, oy + s * lx + c * ly)
                if p == at:
                    continue
                off = (rx + c * lx - s * ly, ry + s * lx + c * ly)
                if p in self.points:  # loop closure: both bodies put p at the same place
                    eqs += self._closure(base, off, *rel[p])
                else:
                    self.points[p], rel[p] = w, (base, off)
        self.slide_s = {}
        for sl in m.slides:
            ox, oy, th = self.frames[sl.along]
            c, s = ca.cos(th), ca.sin(th)
            tx, ty = (self.val(v) for v in sl.through)
            a = th + self.val(sl.angle)
            dx, dy = ca.cos(a), ca.sin(a)
            ex = self.points[sl.point][0] - (ox + c * tx - s * ty)
            ey = self.points[sl.point][1] - (oy + s * tx + c * ty)
            eqs.append(dx * ey - dy * ex)  # distance of the point from the line
            self.slide_s[sl.name] = dx * ex + dy * ey
        eqs += _joints.equations(self, new)  # relative inputs, gears, racks, cams
        for k, i in enumerate(m.inputs):
            if i.kind == "slide":
                eqs.append(self.slide_s[i.target] - self.u[k])
        self.angles = {lk.name: self.frames[lk.name][2] for lk in m.links}
        self._finish(qs, eqs)

    def _closure(self, base_a, off_a, base_b, off_b) -> list:
        """Both coordinates of (a - b) for points a, b given as (ground point or None for the
        origin, vector from it): (B_a - B_b) + (off_a - off_b)."""
        at = lambda b, i: ca.SX(0) if b is None else self.points[b][i]
        if base_a == base_b:
            return [off_a[i] - off_b[i] for i in range(2)]
        return [(at(base_a, i) - at(base_b, i)) + (off_a[i] - off_b[i]) for i in range(2)]

    def _finish(self, qs, eqs):
        """The unknowns q and residual g from their lists, g's Jacobians and the Functions
        every solve calls (shared with the spatial model, kincas/core/space_symbolic.py)."""
        self.q = ca.vertcat(*qs) if qs else ca.SX(0, 1)
        self.nq = len(qs)
        self.g = ca.vertcat(*eqs) if eqs else ca.SX(0, 1)
        self.ng = self.g.numel()
        if self.ng < self.nq:  # guarded by the model's mobility check
            raise ModelError(f"[inputs]: {self.nq} unknowns but {self.ng} equations")
        self.is_length = np.array([k == "length" for _, k in self.unknowns], dtype=bool)
        self.Jq = ca.jacobian(self.g, self.q)
        self.Ju = ca.jacobian(self.g, self.u)
        args = [self.q, self.u, self.p]
        self.f_res = ca.Function("residual", args, [self.g])
        self.f_resjac = ca.Function("residual_jac", args, [self.g, self.Jq])
        self.f_tangent = ca.Function("tangent", args, [self.g, self.Jq, self.Ju])
        self.f_points = ca.Function("points", args, [self._point_matrix()])

    def unknown_links(self) -> list[str]:
        """Per unknown, the link (or point) it places: how groups are named."""
        return [name.split(".")[0] for name, _ in self.unknowns]

    def ground_at(self, g: str) -> list:
        """Where ground point `g` is drawn (fixed): its coordinates as expressions."""
        return self.points[g]

    def _point_matrix(self):
        pts = [self.points[p] for p in self.mech.moving_points]
        return ca.horzcat(*[ca.vertcat(*xy) for xy in pts]) if pts else ca.SX(self.dim, 0)

    def local_points(self, lk) -> list[tuple]:
        """A link's points in its own frame, as expressions of the parameters."""
        return [tuple(self.val(c) for c in xy) for _, xy in lk.points]

    def lsolve(self, b):
        """g_q^-1 b, or for a tall consistent system (redundant joints) the solution of its
        normal equations (g_q' g_q) x = g_q' b, exact when g_q x = b has a solution."""
        if self.ng == self.nq:
            return ca.solve(self.Jq, b)
        return ca.solve(ca.mtimes(self.Jq.T, self.Jq), ca.mtimes(self.Jq.T, b))

    # --- quantities ---
    def position_expr(self, obj: str, attr: str):
        """The position-level expression behind a quantity and the derivative order wanted."""
        if attr in _POINT_Q and obj in self.points:
            comp, order = _POINT_Q[attr]
            return self.points[obj][comp], order
        if attr in _LINK_Q and obj in self.angles:
            return self.angles[obj], _LINK_Q[attr]
        if attr in _SLIDE_Q and obj in self.slide_s:
            return self.slide_s[obj], _SLIDE_Q[attr]
        return None, None

    def extra(self, name: str):
        """(module, problems) of the extension that knows `name`, or (None, None)."""
        for mod in _extras():
            problems = mod.check(self, name)
            if problems is not None:
                return mod, problems
        return None, None

    def check_names(self, names: list[str], where: str = "[output] report") -> list[str]:
        """Problems with quantity names (unknown object or attribute)."""
        out = []
        for n in names:
            kind, a, b = parse_quantity(n)
            if kind == "plain" and self.position_expr(a, b)[0] is None and self.extra(n)[0]:
                out += [f"{where}: {n!r}: {msg}" for msg in self.extra(n)[1]]
                continue
            if kind == "sens" and parse_quantity(a)[0] == "sens":  # d2Q/dp2: not built
                out.append(f"{where}: {n!r}: a sensitivity of a sensitivity is not supported "
                           f"(d(Q)/d(p) takes a quantity Q, not d(...)/d(...))")
            elif kind == "sens":
                out += self.check_names([a], where)
                if b not in self.pnames:
                    out.append(f"{where}: {n!r}: unknown parameter {b!r}")
                elif b in {i.target for i in self.mech.inputs if i.kind == "parameter"}:
                    out.append(f"{where}: {n!r}: {b!r} is driven by an input (use its rate instead)")
            elif self.position_expr(a, b)[0] is None:
                out.append(f"{where}: unknown quantity {n!r} (expected P.x, P.vx, P.ax, P.jx, "
                           f"P.curvature, P.cx, L.angle, L.omega, L.alpha, L.jerk, L.icx, A/B.angle, "
                           f"A/B.omega, A/B.icx, S.s, S.v, S.a, S.jerk, cam.contact.x, cam.phi, "
                           f"cam.pressure, effort(KEY), shaking.x, reaction(P, L).x "
                           f"or d(Q)/d(p) with declared names)")
        return out

    def quantity_function(self, names: list[str], jerk: bool = False, lsolve=None,
                          velocity: bool = False) -> ca.Function:
        """f(q, u, p, u', u'') -> the named quantities (only what they need is built).

        With `velocity=True` the function takes q' = dq/du u' as its last argument instead of
        solving g_q q' = -g_u u' itself (the fast kernel has the tangent dq/du already).

        With `jerk=True` the function takes the inputs' jerks u''' as a sixth argument;
        otherwise they are zero (the default of every input's `jerk`). `lsolve(b)`, if given,
        replaces `self.lsolve` for the solves with g_q (the fast kernel solves them Assur
        group by Assur group, kincas/core/blocks.py).

        Sensitivities d(Q)/d(p) follow the implicit function theorem on the same Jacobian:
        dq/dp = -g_q^-1 g_p, so dQ/dp = Q_q dq/dp + Q_p, with Q written in (q, u, p, u', u'')
        (its q' and q'' substituted), so that the sensitivity of a velocity is exact too.
        """
        bad = self.check_names(names)
        if bad:
            raise ModelError(bad)
        from .geometry import Time
        z = ca.vertcat(self.q, self.u)
        ud, udd = ca.SX.sym("ud", self.nu), ca.SX.sym("udd", self.nu)
        uddd = ca.SX.sym("uddd", self.nu) if jerk else ca.SX.zeros(self.nu)
        qd_s, qdd_s, qddd_s = (ca.SX.sym(k, self.nq) for k in ("qd", "qdd", "qddd"))
        zd, zdd = ca.vertcat(qd_s, ud), ca.vertcat(qdd_s, udd)
        t = Time(self, z, zd, zdd, ca.vertcat(qddd_s, uddd))
        parsed = [parse_quantity(n) for n in names]
        raw = [self._expr(a if k == "sens" else n, t) for n, (k, a, b) in zip(names, parsed)]
        out = ca.vertcat(*raw) if raw else ca.SX(0, 1)
        orders = 3 if ca.depends_on(out, qddd_s) else self._needs(out, qd_s, qdd_s)
        lsolve = lsolve or self.lsolve
        qd_in = ca.SX.sym("qd_in", self.nq) if velocity else None
        if orders >= 1:  # only build the linear solves that the report needs
            qd = qd_in if velocity else ca.densify(-lsolve(ca.mtimes(self.Ju, ud)))  # dense even with no input
            qdd = ca.SX.zeros(self.nq)
            if orders >= 2:
                gam = ca.jtimes(ca.jtimes(self.g, z, zd), z, zd)
                qdd = ca.densify(ca.substitute(-lsolve(ca.mtimes(self.Ju, udd) + gam), qd_s, qd))
            if orders >= 3:  # g''' = g_q q''' + (the rest, at q''' = 0), with q'' and q' known
                g2 = ca.jtimes(self.g, z, zdd) + gam
                rest = t.d(g2, 1, third=ca.vertcat(ca.SX.zeros(self.nq), uddd))
                rest = ca.substitute(ca.substitute(rest, qdd_s, qdd), qd_s, qd)
                out = ca.substitute(out, qddd_s, ca.densify(-lsolve(rest)))
            out = ca.substitute(ca.substitute(out, qdd_s, qdd), qd_s, qd)
        rows = [out[i] for i in range(out.numel())]
        sens = [(i, b) for i, (k, _, b) in enumerate(parsed) if k == "sens"]
        if sens:
            gp = ca.jacobian(self.g, self.p)
            dq_dp = -lsolve(gp)  # one factorisation serves every parameter
            for i, b in sens:
                j = self.pnames.index(b)
                rows[i] = ca.jtimes(rows[i], self.q, dq_dp[:, j]) + ca.jacobian(rows[i], self.p[j])
                if self.ng > self.nq:  # redundant joints: p must keep g_q dq + g_p dp = 0
                    # solvable, or a change of p jams the chain and there is no derivative
                    miss = ca.mmax(ca.fabs(ca.mtimes(self.Jq, dq_dp[:, j]) + gp[:, j]))
                    rows[i] = ca.if_else(miss > JAMMED * (1 + ca.mmax(ca.fabs(gp[:, j]))), np.nan, rows[i])
        out = ca.vertcat(*rows) if rows else ca.SX(0, 1)
        args = [self.q, self.u, self.p, ud, udd] + ([uddd] if jerk else []) + ([qd_in] if velocity else [])
        return ca.Function("quantities", args, [out])

    def _expr(self, name, t):
        _, obj, attr = parse_quantity(name)
        e, order = self.position_expr(obj, attr)
        if e is None:
            return self.extra(name)[0].expression(self, name, t)
        return t.d(e, order)

    @staticmethod
    def _needs(expr, qd_s, qdd_s) -> int:
        if ca.depends_on(expr, qdd_s):
            return 2
        return 1 if ca.depends_on(expr, qd_s) else 0
