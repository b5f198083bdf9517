"""The first pose of a mechanism, before any Newton: unknowns placed from the user's guessed
points by walking the spanning tree from the ground (`initial_q`), or the assembly nearest to
target positions found by IPOPT (`nearest_assembly`). A part of `kincas.core.numeric.Model`,
which supplies the symbolic model, its geometry call, its lock and its Newton.

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
>>> model = kincas.core.numeric.model_of(m)
>>> q0 = model.initial_q(np.array([0.0]), np.zeros(0), {"C": (3.6, 2.9)}, m.size())
>>> q0.shape
(2,)
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

import casadi as ca
import numpy as np

from . import joints as _joints
from .cancel import interruptible
from .tolerances import IPOPT_TOL, REGULARIZE

if TYPE_CHECKING:
    from .numeric import Solution


class FirstPose:
    """The first pose of a `Model` (kincas/core/numeric.py): from a guess, or nearest targets."""

    # --- the first pose: from the user's guess ---
    def initial_q(self, u, p, guess: dict[str, tuple[float, float]], L: float,
                  turn: dict | None = None, free: list | None = None) -> np.ndarray:
        """Unknowns placed from guessed points, walking the spanning tree from the ground.

        A link hanging on point P takes the angle that points it at another of its points
        whose position is guessed (or already known); with none, angle 0, or `turn[link]`
        where given. The links so left free of the guess (their angle an unknown, no input
        turning them) are appended to `free` where given: kincas/core/guessed.py tries
        them in several turns, so that the guessed points decide their assembly.
        """
        m, sym = self.sym.mech, self.sym
        loc_flat, gflat = (a.ravel() for a in self._geometry(u, p))
        loc, k = {}, 0
        for lk in m.links:
            for pt, _ in lk.points:
                loc[(lk.name, pt)] = loc_flat[k:k + 2]
                k += 2
        gv = {g: gflat[2 * k:2 * k + 2] for k, (g, _) in enumerate(m.ground)}
        known = dict(gv)
        guessed = {k: np.asarray(v, float) for k, v in guess.items()}
        q = np.zeros(self.nq)
        index = {name: i for i, (name, _) in enumerate(sym.unknowns)}
        angle_in = {i.target: u[k] for k, i in enumerate(m.inputs) if i.kind == "angle"}
        centre = np.mean(list(gv.values()), axis=0) if gv else np.zeros(2)
        theta = {"ground": 0.0}  # angles placed so far (a relative input starts from them)
        turn = turn or {}
        for lname, at in m.structure.order:
            pts = [pt for pt, _ in m.link(lname).points]
            ref = [pt for pt in pts if pt in guessed or pt in known]
            pos = {pt: guessed.get(pt, known.get(pt)) for pt in ref}
            if at is not None:
                anchor = guessed.get(at, known[at])
                others = [pt for pt in ref if pt != at]
                th, unset = turn.get(lname, 0.0), not others
                if others:
                    d = pos[others[0]] - anchor
                    dl = loc[(lname, others[0])] - loc[(lname, at)]
                    th = math.atan2(d[1], d[0]) - math.atan2(dl[1], dl[0])
                th = float(angle_in.get(lname, _joints.relative_start(m, lname, u, theta, th)))
                c, s = math.cos(th), math.sin(th)
                R = np.array([[c, -s], [s, c]])
                origin = known[at] - R @ loc[(lname, at)]
            else:
                th, unset = turn.get(lname, 0.0), len(ref) < 2
                if len(ref) >= 2:
                    d, dl = pos[ref[1]] - pos[ref[0]], loc[(lname, ref[1])] - loc[(lname, ref[0])]
                    th = math.atan2(d[1], d[0]) - math.atan2(dl[1], dl[0])
                th = float(angle_in.get(lname, _joints.relative_start(m, lname, u, theta, th)))
                c, s = math.cos(th), math.sin(th)
                R = np.array([[c, -s], [s, c]])
                origin = (pos[ref[0]] - R @ loc[(lname, ref[0])]) if ref else centre
                q[index[f"{lname}.x"]], q[index[f"{lname}.y"]] = origin
            if f"{lname}.angle" in index:
                q[index[f"{lname}.angle"]] = th
                if unset and free is not None and th == turn.get(lname, 0.0):  # no input turned it
                    free.append(lname)
            theta[lname] = th
            for pt in pts:
                known.setdefault(pt, origin + R @ loc[(lname, pt)])
        return _joints.place(self, q, u, p)  # cams' contact parameters; angles in (-pi, pi]

    # --- IPOPT: the assembly nearest to target positions ---
    def nearest_assembly(self, q0, u, p, targets: dict[str, np.ndarray], L) -> Solution:
        """min sum |P - target|^2 subject to g = 0, by IPOPT (scaled by the size L)."""
        sym, names = self.sym, list(self.sym.mech.moving_points)
        with self._lock:
            if self._nlp is None:
                self._nlp = self._build_nlp()
        solver, _ = self._nlp
        T = np.zeros((sym.dim, len(names)))
        W = np.zeros(len(names))
        for k, n in enumerate(names):
            if n in targets:
                T[:, k], W[k] = targets[n], 1.0
        qs = np.where(sym.is_length, L, 1.0)
        par = np.concatenate([np.ravel(u), np.ravel(p), T.ravel(order="F"), W, q0 / qs, [L]])
        with interruptible():  # IPOPT would take Ctrl-C for a failed solve and go on
            out = solver(x0=q0 / qs, p=par, lbg=0, ubg=0)
        q = np.asarray(out["x"]).ravel() * qs
        return self.newton(q, u, p, L)  # polish, and judge by the residual alone

    def _build_nlp(self):
        sym, names = self.sym, list(self.sym.mech.moving_points)
        x = ca.SX.sym("x", self.nq)
        npt = len(names)
        T, W = ca.SX.sym("T", sym.dim, npt), ca.SX.sym("W", npt)
        x0, Ls = ca.SX.sym("x0", self.nq), ca.SX.sym("L")
        qscale = ca.if_else(ca.DM(sym.is_length.astype(float)), Ls, 1)
        q = x * qscale
        subst = lambda e: ca.substitute(e, sym.q, q)
        P = subst(sym._point_matrix())
        obj = ca.mtimes(ca.sum1((P - T) ** 2), W) / Ls ** 2 + REGULARIZE * ca.sumsqr(x - x0)
        par = ca.vertcat(sym.u, sym.p, ca.vec(T), W, x0, Ls)
        nlp = {"x": x, "p": par, "f": obj, "g": subst(sym.g) / Ls}
        opts = {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes",
                "ipopt.max_iter": 200, "ipopt.tol": IPOPT_TOL, "error_on_fail": False}
        return ca.nlpsol("assemble", "ipopt", nlp, opts), qscale
