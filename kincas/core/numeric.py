"""Numeric evaluation of a mechanism's symbolic model: residuals, Newton, placement, IPOPT.

`model_of(m)` (`kincas.model_of`; 0.1 called it `kincas.compile`, now deprecated) gives the `Model` of m's structure, built once and cached (parameter values are
numeric inputs, so changing them does not rebuild it). Every CasADi call on a hot path goes
through zero-copy numpy buffers (one set per thread). Newton solves the Assur groups of the
structure one after another (kincas/core/structure.py), each until its next step is below
`TOL` (radians, or lengths over its own group's length), which it then applies, as the
compiled kernel does; a pose counts as solved below `ACCEPT` times each group's length. Tolerances relative
to each group make a mechanism of 1e-6 m and one of 1e6 m, or a small group beside a far
point, reach the same relative accuracy.

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
>>> model, p = model_of(m), np.zeros(0)
>>> q0 = model.initial_q(np.array([0.5]), p, {"C": (3.6, 2.9)}, m.size())
>>> sol = model.newton(q0, np.array([0.5]), p, m.size())
>>> sol.ok, bool(sol.residual < 1e-13)
(True, True)
"""
from __future__ import annotations

import threading
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ..model.mechanism import Mechanism, needs_rank_test
from .caches import Memo
from .first_pose import FirstPose
from .newton import lsolve as _lsolve, newton as _newton
from .redundant import decide
from .space_model import SpatialFirstPose, structure_key as _space_key
from .space_symbolic import SpatialSymbolic
from .structure import Structure
from .symbolic import Symbolic
from .tolerances import ACCEPT, IPOPT_TOL, MAX_ITER, MAX_STEP, REGULARIZE, TOL  # noqa: F401  (their old home)


# --- compiled models, one per structure (parameter values stay numeric inputs) ---


def _structure_key(m: Mechanism):
    # loads and gravity enter the force quantities' expressions, so they are structure too
    return (tuple(k for k, _ in m.parameters), m.ground, m.links, m.slides, m.inputs,
            m.gears, m.racks, m.cams, m.gravity, m.loads)


_CACHE = Memo("models by structure", bound=64)
SCALES_KEPT = 16  # geometries (parameter values, driven lengths) whose scales a model keeps


def model_of(m: Mechanism, check: bool = True) -> "Model":
    """The numeric model of `m`'s structure: its residuals, Jacobians, Newton and quantity
    functions as CasADi Functions (built once per structure and cached; parameter values
    stay numeric inputs, so changing them rebuilds nothing; nothing is compiled to C here).

    Safe from several threads: the cache is guarded by a lock, and a `Model` holds no numeric
    state shared between calls. With `check`, a mechanism whose count of freedoms falls
    short of its inputs is first put to the rank test of redundant joints (`ModelError`
    when its inputs are genuinely wrong in number).

    Parameters
    ----------
    m : Mechanism
    check : bool
        Run the deferred mobility check (kincas/core/redundant.py).

    Returns
    -------
    Model

    Examples
    --------
    >>> import kincas
    >>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
    ...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
    ...            kincas.Link.bar("rocker", "D", "C", 3)], inputs=[kincas.Input.angle("crank")])
    >>> model = model_of(m)
    >>> model.nq, [b.size for b in model.blocks], model_of(m.with_parameters()) is model
    (2, [2], True)
    """
    # built once per structure, however many threads ask (Symbolic never reads parameter values)
    if getattr(m, "space", "2d") == "3d":  # a spatial mechanism: the same interface
        model = _CACHE.get_or_build(_space_key(m), lambda: SpatialModel(m))
    else:
        model = _CACHE.get_or_build(_structure_key(m), lambda: Model(Symbolic(m)))
    if check and needs_rank_test(m):
        decide(m, model)
    return model


compile = model_of  # its first name (kincas 0.1): it compiles nothing


def redundant_equations(m: Mechanism) -> int:
    """The number of equations of `m` implied by the others (kincas/core/redundant.py), on the
    model of its structure; what `Mechanism.redundant` answers (the package's face hands it
    to the model)."""
    return decide(m, model_of(m, check=False))


class _Call:
    """A casadi Function called through zero-copy numpy buffers: no DM conversions, about
    0.1 us of overhead instead of 10 (see shared/casadi-notes.md).

    Each thread gets its own buffers (a casadi buffer is work space: two threads sharing
    one overwrite each other's outputs), and each call returns fresh copies of the outputs,
    so a caller may keep them and the call is re-entrant."""

    def __init__(self, f: ca.Function):
        ins = f.sx_in()
        self.f = ca.Function(f.name() + "_dense", ins, [ca.densify(o) for o in f.call(ins)])
        self._local = threading.local()

    def _buffers(self):
        b = getattr(self._local, "b", None)
        if b is None:
            f = self.f
            ins = [np.zeros(f.nnz_in(i)) for i in range(f.n_in())]
            flat = [np.zeros(f.nnz_out(i)) for i in range(f.n_out())]
            buf, ev = f.buffer()  # keep buf referenced with ev: raw pointers inside
            for i, a in enumerate(ins):
                buf.set_arg(i, memoryview(a))
            for i, a in enumerate(flat):
                buf.set_res(i, memoryview(a))
            shapes = [f.size_out(i) for i in range(f.n_out())]
            b = self._local.b = (ins, flat, shapes, buf, ev)
        return b

    def __call__(self, *args):
        ins, flat, shapes, _, ev = self._buffers()
        for a, x in zip(ins, args):
            a[:] = np.ravel(x, order="F")
        ev()
        return [a.reshape(s, order="F").copy(order="F") for a, s in zip(flat, shapes)]


@dataclass
class Solution:
    q: np.ndarray
    residual: float
    iterations: int
    ok: bool
    J: np.ndarray | None = None  # g_q at q


class Model(FirstPose):
    """Numeric evaluation of a symbolic model: residuals, Newton, IPOPT, quantities."""

    def __init__(self, sym: Symbolic):
        self.sym = sym
        self.nq, self.nu, self.ng = sym.nq, sym.nu, sym.ng
        self.square = self.ng == self.nq  # tall: redundant joints (a consistent system)
        m = sym.mech
        locs = [c for lk in m.links for xy in sym.local_points(lk) for c in xy]
        self.f_local = ca.Function("local", [sym.u, sym.p], [ca.vertcat(*locs)])
        gxy = [c for g, _ in m.ground for c in sym.ground_at(g)]
        self.f_ground = ca.Function("ground", [sym.u, sym.p], [ca.vertcat(*gxy) if gxy else ca.SX(0, 1)])
        # both at once through buffers: every Newton asks for them (its groups' lengths)
        self._geometry = _Call(ca.Function("geometry", [sym.u, sym.p],
                                           [self.f_local(sym.u, sym.p), self.f_ground(sym.u, sym.p)]))
        self._nlp = None
        self._qfun: dict[tuple, ca.Function] = {}
        self._blocks = None
        self._lock = threading.RLock()  # guards the lazily built members above
        self._memo = Memo(gate=self._lock)  # builds of one model never overlap (CasADi symbols)
        self._scales = Memo(bound=SCALES_KEPT)  # geometry -> scales (`scales`)
        self._resjac, self._tangent = _Call(sym.f_resjac), _Call(sym.f_tangent)
        self._res = _Call(sym.f_res)
        self.structure = Structure(sym)

    # --- structure: Assur groups and their scales ---
    @property
    def blocks(self):
        """The Assur groups of g_q in solve order (see kincas/core/structure.py): each has
        `.rows` (equations), `.cols` (unknowns), `.size` and `.links`; block i's equations
        involve only unknowns of blocks 0..i."""
        return self.structure.blocks

    def scales(self, u, p):
        """(eq_scale, q_scale): per equation, the length its residual is measured against;
        per unknown, the scale of a step (1 for an angle, a length for a length unknown).
        Both come from the unknown's or equation's own group (its block's bodies), not from
        the whole drawing, so a far point elsewhere loosens nobody's tolerance."""
        local, ground = (a.ravel() for a in self._geometry(u, p))
        # a pure function of the geometry at (u, p), kept for the last few: every Newton and
        # every first pose asks for it, mostly at the same parameter values
        eq, qs = self._scales.get_or_build(local.tobytes() + ground.tobytes(),
                                           lambda: self._scales_of(local, ground))
        return eq.copy(), qs.copy()

    def _scales_of(self, local, ground):
        Lb = self.structure.block_lengths(local, ground)
        eq, qs = np.ones(self.ng), np.ones(self.nq)
        for b, L in zip(self.blocks, Lb):
            eq[b.rows] = L
            qs[b.cols] = np.where(self.sym.is_length[b.cols], L, 1.0)
        return eq, qs

    # --- residuals and Newton ---
    def residual(self, q, u, p) -> np.ndarray:
        return self._res(q, u, p)[0].ravel()

    def resjac(self, q, u, p):
        """(g, g_q) at a pose, as fresh numpy arrays."""
        g, J = self._resjac(q, u, p)
        return g.ravel(), J

    def newton(self, q, u, p, L=None, max_iter=MAX_ITER) -> Solution:
        """Solve g(q) = 0 near q, one Assur group after another (kincas/core/newton.py).

        Each block of `self.blocks` is solved by its own damped Newton with the exact
        Jacobian, its residual measured against its own group's length (`scales`), with the
        unknowns of earlier blocks fixed; so the cost grows with the number of groups and a
        far point elsewhere loosens nobody's tolerance. With redundant joints g_q is tall:
        the step is Gauss-Newton's, the least-squares solution of g_q dq = -g, which
        converges quadratically on a consistent system where g_q has full column rank.
        The residual reported is the largest over all equations, each relative to its group.

        Parameters
        ----------
        q : array
            The starting unknowns.
        u, p : array
            The inputs' and the parameters' values.
        L : float, optional
            Ignored, whatever it is: None or any size gives the same answer, because each
            group's residual is measured against that group's own length (`scales(u, p)`),
            so no overall size is needed. It is kept so that calls written for kincas 0.1,
            `newton(q, u, p, L)`, still work; new code leaves it out (tolerances were once
            relative to the whole mechanism's size).
        max_iter : int
            Newton iterations per group at most.

        Returns
        -------
        Solution
            `q`, the relative residual, iterations, `ok`, and the Jacobian at `q`.

        Examples
        --------
        >>> import numpy as np, kincas
        >>> m = kincas.Mechanism(ground={"O": (0, 0)}, links=[kincas.Link.bar("crank", "O", "A", 2)],
        ...                      inputs=[kincas.Input.angle("crank")])
        >>> model, u, p = kincas.model_of(m), np.array([0.5]), np.zeros(0)
        >>> q0 = model.initial_q(u, p, {}, 2.0)
        >>> a, b = model.newton(q0, u, p), model.newton(q0, u, p, 1e6)  # L changes nothing
        >>> a.ok, bool(np.array_equal(a.q, b.q)), a.residual == b.residual
        (True, True, True)
        """
        q = np.array(q, dtype=float)
        eq, qs = self.scales(u, p)
        its, ok = 0, True
        for b, call in zip(self.blocks, self._block_calls()):
            def F(x, b=b, call=call):
                q[b.cols] = x
                g, J = call(q, u, p)
                return g.ravel(), J
            res = _newton(F, q[b.cols], qs[b.cols], eq[b.rows], max_iter=max_iter)
            q[b.cols] = res.x
            its = max(its, res.iterations)
            if not res.ok:
                ok = False
                break
        g, J = self.resjac(q, u, p)
        r = float(np.abs(g / eq).max(initial=0.0))
        r = r if np.isfinite(r) else np.inf
        return Solution(q, r, its, ok and r <= ACCEPT, J)

    def _block_calls(self):
        """Per block, (q, u, p) -> (its equations, their Jacobian in its unknowns)."""
        with self._lock:
            if self._blocks is None:
                if len(self.blocks) == 1 and self.blocks[0].size == self.nq:
                    self._blocks = [self._resjac]  # one group: the whole system
                else:
                    sym, calls = self.sym, []
                    for k, b in enumerate(self.blocks):
                        gb = sym.g[[int(i) for i in b.rows]]
                        qb = sym.q[[int(j) for j in b.cols]]
                        calls.append(_Call(ca.Function(f"block{k}", [sym.q, sym.u, sym.p],
                                                       [gb, ca.jacobian(gb, qb)])))
                    self._blocks = calls
            return self._blocks

    def tangent(self, q, u, p) -> np.ndarray:
        """dq/du (nq x nu) at a solved pose, from the implicit function theorem:
        -g_q^-1 g_u, or -pinv(g_q) g_u for a tall consistent g_q (redundant joints)."""
        _, J, Ju = self._tangent(q, u, p)
        return _lsolve(J, -Ju)

    def column_scale(self, L) -> np.ndarray:
        """Factors bringing g_q's columns to O(1) at any size: an angle unknown's column is
        a length (times 1/L), a length unknown's is a ratio (times 1). Conditioning and
        determinant signs compared through it mean the same at 1e-6 m and at 1e6 m."""
        return np.where(self.sym.is_length, 1.0, 1.0 / L)

    def jac(self, q, u, p) -> np.ndarray:
        return self._resjac(q, u, p)[1]

    def points(self, q, u, p) -> np.ndarray:
        """World positions of the moving points, 2 x n (3 x n in space)."""
        return np.asarray(self.sym.f_points(q, u, p))

    def memo(self, key, build):
        """`build()` once per `key` for this structure (a Function that other modules derive
        from the model), kept with the model; safe from several threads."""
        return self._memo.get_or_build(key, build)

    # --- quantities over many poses ---
    def quantity_function(self, names: tuple[str, ...]) -> ca.Function:
        with self._lock:
            if names not in self._qfun:
                self._qfun[names] = self.sym.quantity_function(list(names))
            return self._qfun[names]

    def quantities(self, names, Q, U, P, Ud, Udd) -> np.ndarray:
        """Quantities (len(names) x N) at N solved poses, in one vectorised call."""
        n = Q.shape[0]
        if n == 0 or not names:
            return np.zeros((len(names), n))
        f = self.quantity_function(tuple(names)).map(n)
        rep = lambda a: np.repeat(np.reshape(a, (-1, 1)), n, axis=1)
        return np.asarray(f(Q.T, U.T, rep(P), Ud.T, Udd.T))

    def third_derivatives(self, names, Q, U, P, Ud, Udd, Uddd) -> np.ndarray:
        """Quantities that need the inputs' jerks (len(names) x N) at N solved poses."""
        n = Q.shape[0]
        if n == 0 or not names:
            return np.zeros((len(names), n))
        f = self.memo(("jerk", tuple(names)), lambda: self.sym.quantity_function(list(names), jerk=True)).map(n)
        rep = lambda a: np.repeat(np.reshape(a, (-1, 1)), n, axis=1)
        return np.asarray(f(Q.T, U.T, rep(P), Ud.T, Udd.T, Uddd.T))

    # --- the structure as plain values: the other floors never hold a CasADi object ---
    @property
    def mech(self) -> Mechanism:
        """The mechanism the model was built from (its structure; values may differ)."""
        return self.sym.mech

    @property
    def unknown_names(self) -> list[str]:
        """The names of the unknowns, in the order of q (`crank.angle`, `L.x`, ...): a new
        list each time (the names found once)."""
        names = self.__dict__.get("_unknown_names")
        if names is None:
            names = self._unknown_names = tuple(nm for nm, _ in self.sym.unknowns)
        return list(names)

    @property
    def unknown_kinds(self) -> list[str]:
        """Per unknown, its kind ("angle", "length", or "quaternion" in space)."""
        return [k for _, k in self.sym.unknowns]

    @property
    def dim(self) -> int:
        """Coordinates of a point: 2, or 3 for a spatial mechanism."""
        return self.sym.dim

    @property
    def is_length(self) -> np.ndarray:
        """Per unknown: True for a length (a floating link's origin), False for an angle."""
        return self.sym.is_length

    def check_names(self, names, where: str = "[output] report") -> list[str]:
        """Problems with quantity names this model cannot give, each naming `where`."""
        return self.sym.check_names(names, where)

    def derivative_order(self, obj: str, attr: str) -> int:
        """The time derivative a plain quantity `obj.attr` is of a position (0: a position)."""
        return self.sym.position_expr(obj, attr)[1]

    def points_many(self, Q, u, p) -> np.ndarray:
        """The moving points at each row of Q (one input u, parameters p), one row
        (x1, y1, x2, y2, ...) per row of Q."""
        n = Q.shape[0]
        if n == 0:
            return np.zeros((0, 0))
        f = self.sym.f_points.map(n)
        pts = np.asarray(f(Q.T, np.tile(np.reshape(u, (-1, 1)), n), np.tile(np.reshape(p, (-1, 1)), n)))
        return pts.reshape(self.sym.dim, -1, n, order="F").transpose(2, 1, 0).reshape(n, -1)


class SpatialModel(SpatialFirstPose, Model):
    """`Model` of a spatial mechanism (kincas/core/space_symbolic.py): the same numerics, its
    first pose from the drawing pose (kincas/core/space_model.py)."""

    def __init__(self, m):
        Model.__init__(self, SpatialSymbolic(m))
