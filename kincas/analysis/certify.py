"""Every real assembly, certified: `kincas.modes(m, inputs, certify=True)`.

The multistart search (kincas/analysis/modes.py) finds the assemblies that its starts reach;
nothing proves that none is missed. Here the closure equations are written as polynomials
with exact rational coefficients (kincas/core/polynomial_planar.py: each unknown angle as its
cosine and sine on the unit circle), and an exact solver (msolve: Gröbner bases over the
rationals, then real root isolation; kincas/analysis/certify_msolve.py) returns every real
solution, each isolated in a box that holds it and no other. Then, per box:

1. the box's centre is mapped to kincas's unknowns (an angle is atan2(s, c); a relative
   input's angle is kept within a turn of its equation), and refined by kincas's own Newton;
2. the refined point must lie in its box to its own floating-point error bound (first
   order: the scaled Jacobian's pseudo-inverse times the residual left plus its rounding,
   so it grows with the conditioning; `_refined`), that bound below half the distance to
   the nearest other root: if it does not (Newton left for another root, or crawled onto a
   singular one), the mode says so and keeps the box's centre, itself right to 2^-64;
3. the rule for an assembly: kincas's relative residual at the point is at most ACCEPT.
   Every real solution of these equations is an assembly (no mirror images, no spurious
   roots: the unknowns are kincas's), so a rejected one means a failure, and it is reported
   in `rejected`, never dropped silently;
4. coinciding assemblies (a singular pose): msolve lists a multiple root once. Its
   multiplicity shows in the Jacobian (column-scaled g_q of corank k >= 1 there: at least
   k + 1 assemblies meet) and in how many real roots it splits into when the first input
   moves by +-CERTIFY_NUDGE (two more exact solves): the multiplicity is the larger of the
   two; such a mode is listed once, flagged "singular".

The certificate is for the pose written: where a driven angle (or a slide's line angle) is
not a multiple of 90 degrees its cosine and sine are rational only after rounding (by about
1e-12 rad, to an exact rotation), and `rounded` says so. A system with infinitely many
solutions (a link free to spin at this pose) is reported as `positive_dimension`.

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)], inputs=[kincas.Input.angle("crank")])
>>> found = certify_modes(m, {"crank.angle": np.pi / 2})  # doctest: +SKIP
>>> found.count, found.certified, found.rounded                     # doctest: +SKIP
(2, True, [])
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from fractions import Fraction

import numpy as np

from ..core.assembly import first_pose
from ..core.numeric import model_of
from ..core.polynomial_planar import NotPolynomial, closure
from ..core.tolerances import (ACCEPT, CERTIFY_NUDGE, CERTIFY_OFF_MODEL, CERTIFY_ROUNDING, CERTIFY_SPLIT, CERTIFY_TIMEOUT,
                               RANK, TINY)
from ..frames import Modes
from ..model.joints import split_relative
from ..model.mechanism import Mechanism
from .certify_msolve import solve
from ..core.tolerances import SAME_ASSEMBLY as SAME
from .assembly_mode import Mode, input_vector as _input_vector, mode_at, signature


@dataclass(frozen=True)
class CertifiedMode(Mode):
    """A `Mode` proven to be one of all: `halfwidth` (the isolating box's half-width, in
    length units, over every moving point), `multiplicity` (1, or how many assemblies
    coincide here), `flag` ("singular" when more than one), `note` (the refined point left
    its box, or Newton did not converge: the box's centre is used)."""

    halfwidth: float = 0.0
    multiplicity: int = 1
    flag: str = ""
    note: str = ""


class CertifiedModes(Modes):
    """Every real assembly, certified: a list of `CertifiedMode`, with `count` (None when the
    solutions are not finite in number), `rounded` (inputs taken as nearby rational ones),
    `positive_dimension`, `rejected` (solutions that failed to refine: none expected) and
    `discarded` (an overconstrained mechanism's square subsystem's roots that break an
    implied equation: not assemblies, kincas/analysis/certify_over.py)."""

    certified = True

    def __init__(self, modes=(), *, rounded=(), positive_dimension=False, rejected=(), inputs=None,
                 discarded=()):
        super().__init__(modes)
        self.rounded, self.rejected, self.discarded = list(rounded), list(rejected), list(discarded)
        self.positive_dimension = positive_dimension
        self.count = None if positive_dimension else len(self)
        self.inputs = dict(inputs or {})

    @property
    def ok(self) -> bool:
        return len(self) > 0

    def summary(self) -> str:
        if self.positive_dimension:
            return "infinitely many assemblies at this pose (certified)"
        return f"{len(self)} assembly modes (certified: every real assembly)"


def certify_modes(m: Mechanism, inputs=None, *, threads: int = 1,
                  timeout: float = CERTIFY_TIMEOUT) -> CertifiedModes:
    """Every real assembly of `m` at `inputs`, proven complete by an exact solver.

    Parameters
    ----------
    m : Mechanism
        Pins and slides (gears, racks, cams raise `NotPolynomial`, a `ModelError`).
    inputs : dict or float, optional
        Input key -> value; a number for a one-input mechanism.
    threads : int
        msolve's threads (one: on a loaded machine two were 10 times slower on these small
        systems).
    timeout : float
        Seconds before msolve is stopped (`SolverFailed`).

    Returns
    -------
    CertifiedModes
        The modes sorted as `find_modes` sorts them, with `count` and `rounded`.

    Examples
    --------
    >>> import numpy as np, kincas
    >>> from kincas.analysis import certify_msolve
    >>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
    ...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
    ...            kincas.Link.bar("rocker", "D", "C", 3)], inputs=[kincas.Input.angle("crank")])
    >>> if certify_msolve.available():
    ...     found = certify_modes(m, {"crank.angle": np.pi / 2})
    ...     assert found.count == 2 and all(md.multiplicity == 1 for md in found)
    """
    u = _input_vector(m, inputs)
    system = lambda v: _system(m, v, threads, timeout)
    S = system(u)
    kind, boxes, value = _solve(S, threads, timeout)
    if kind == "positive" and S.implied:
        from .certify_over import REFUSED
        raise NotPolynomial(REFUSED.format(why=" (and its square subsystem has infinitely many solutions)"))
    u_r = np.array([S.at.get(i.key, float(v)) for i, v in zip(m.inputs, u)])
    m_r = _rounded_lines(m, S)
    driven = {i.target: float(v) for i, v in zip(m.inputs, u) if i.kind == "parameter"}
    L = (m_r.with_parameters(**driven) if driven else m_r).size()
    used = {i.key: float(v) for i, v in zip(m.inputs, u_r)}
    if kind == "positive":
        return CertifiedModes(rounded=S.rounded, positive_dimension=True, inputs=used)
    model, p = model_of(m_r), np.array([v for _, v in m_r.parameters], dtype=float)
    guess = {k: tuple(m_r.value(c) for c in xyz) for k, xyz in m_r.guess}
    first = first_pose(model, u_r, p, L, guess)
    picked = signature(model, first.q, u_r, p, L)[0] if first.ok else None
    scale = np.where(S.length, L, 1.0)
    centres = [np.array([float((a + b) / 2) for a, b in box]) for box in boxes]
    out, rejected, discarded = [], [], []
    for k, box in enumerate(boxes):
        c, hw = centres[k], np.array([float((b - a) / 2) for a, b in box])
        others = [np.abs((c - o) / scale).max() for j, o in enumerate(centres) if j != k]
        q, note = _refined(m, model, S, c, hw, scale, u_r, p, L, min(others, default=math.inf))
        halfwidth = max((P.subs(value).spread(box) for xy in S.points.values() for P in xy), default=0.0)
        md = mode_at(m_r, model, q, u_r, p, L, picked, kind=CertifiedMode, halfwidth=halfwidth, note=note)
        # a root that breaks an equation the numerical model holds by construction (a spatial
        # body hung on its joint: kincas/model/space_tree.py) is off its unknowns' map
        off = S.off_model(c) if S.off_model is not None else 0.0
        off = off if off > ACCEPT + CERTIFY_OFF_MODEL * S.perturbation else 0.0
        if max(md.residual, off) > ACCEPT:  # the rule for an assembly (every real root should pass)
            md = replace(md, residual=max(md.residual, off))
            if S.implied:  # a root of the kept equations only: it breaks an implied one
                discarded.append(f"real solution {k + 1} of the kept equations: relative residual "
                                 f"{md.residual:.1e} of all of them (above {ACCEPT:g}): not an assembly")
            else:
                rejected.append(f"real solution {k + 1}: relative residual {md.residual:.1e} "
                                f"after refinement (above {ACCEPT:g}): not an assembly")
            continue
        corank = _corank(model, q, u_r, p, L)
        if corank:
            mult = max(1 + corank, _split_count(m, u, S, c, scale, L, min(others, default=1.0), system))
            md = replace(md, multiplicity=mult, flag="singular" if mult > 1 else "")
        out.append(md)
    rows = lambda md: np.array([v for xy in md.points.values() for v in xy])
    out.sort(key=lambda md: tuple(np.round(rows(md) / (SAME * L))))
    return CertifiedModes(out, rounded=S.rounded, rejected=rejected, inputs=used, discarded=discarded)


def _solve(S, threads=1, timeout=CERTIFY_TIMEOUT):
    """("finite" | "positive", a box per real solution over all of S's variables, the
    eliminated variables as affine Polys in the free ones). The linear equations are solved
    exactly first (`PolySystem.eliminated`): msolve sees only the free variables, and the
    eliminated ones' intervals follow exactly (affine in the free ones)."""
    red = S.eliminated()
    if red is None:  # the linear equations contradict each other
        return "finite", [], {}
    eqs, free, value = red
    if not free:  # every variable fixed by linear equations: one solution, or none
        found = [[]] if not eqs else []
        kind = "finite"
    else:
        kind, found = solve(S.msolve_input(eqs, free), threads=threads, timeout=timeout)
    boxes = []
    for fb in found:
        box = [None] * len(S.names)
        for v, iv in zip(free, fb):
            box[v] = iv
        centre = [None if b is None else (b[0] + b[1]) / 2 for b in box]
        for v, expr in value.items():
            mid = sum((c * math.prod((centre[w] ** e for w, e in mono), start=Fraction(1))
                       for mono, c in expr.terms.items()), Fraction(0))
            half = sum((abs(c) * (box[mono[0][0]][1] - box[mono[0][0]][0]) / 2
                        for mono, c in expr.terms.items() if mono), Fraction(0))
            box[v] = (mid - half, mid + half)
        boxes.append(box)
    return kind, boxes, value


def _spatial(m) -> bool:
    from ..model.space import SpatialMechanism
    return isinstance(m, SpatialMechanism)


def _system(m, u, threads=1, timeout=CERTIFY_TIMEOUT):
    """The system to solve at inputs u: the closure equations, or for an overconstrained
    spatial mechanism whose float axes lost its motion, their square subsystem
    (kincas/analysis/certify_over.py)."""
    S = _closure(m, u)
    if _spatial(m):
        from .certify_over import system_to_solve
        S = system_to_solve(m, u, S, lambda T: _solve(T, threads, timeout))
    return S


def _closure(m, u):
    """The polynomial closure equations: planar, or spatial (kincas/core/polynomial_space.py)."""
    if _spatial(m):
        from ..core.polynomial_space import closure_space
        return closure_space(m, u)
    return closure(m, u)


def _rounded_lines(m: Mechanism, S) -> Mechanism:
    """`m` with each slide's line angle as the equations took it (rounded where said)."""
    if _spatial(m):  # spatial slides have directions, not angles
        return m
    slides = tuple(replace(sl, angle=S.at[f"slide {sl.name}"]) if f"slide {sl.name}" in S.at
                   and S.at[f"slide {sl.name}"] != m.value(sl.angle) else sl for sl in m.slides)
    return m if slides == m.slides else replace(m, slides=slides)


def _unknowns_at(m, S, x, u) -> np.ndarray:
    """kincas's unknowns q at the variables x: angles by atan2, a relative input's link
    within half a turn of its equation's angle (kincas's equation is not modulo 2 pi)."""
    if S.to_unknowns is not None:
        return S.to_unknowns(x)
    q = np.array([math.atan2(x[e[3]], x[e[2]]) if e[1] == "angle" else x[e[2]] for e in S.unknowns])
    names = [e[0] for e in S.unknowns]
    for i, v in zip(m.inputs, u):
        rel = split_relative(i.target) if i.kind == "angle" else None
        if rel and f"{rel[0]}.angle" in names:
            a, b = rel
            tb = (q[names.index(f"{b}.angle")] if f"{b}.angle" in names else
                  next((w for j, w in zip(m.inputs, u) if j.kind == "angle" and j.target == b), 0.0))
            ka = names.index(f"{a}.angle")
            q[ka] += 2 * math.pi * round((tb + v - q[ka]) / (2 * math.pi))
    return q


def _variables_at(S, q) -> np.ndarray:
    """The polynomial variables at kincas's unknowns q (the inverse of `_unknowns_at`)."""
    if S.from_unknowns is not None:
        return S.from_unknowns(q)
    x = np.zeros(len(S.names))
    for e, v in zip(S.unknowns, q):
        if e[1] == "angle":
            x[e[2]], x[e[3]] = math.cos(v), math.sin(v)
        else:
            x[e[2]] = v
    return x


def _refined(m, model, S, c, hw, scale, u, p, L, nearest=math.inf):
    """(q, note): Newton from the box's centre, kept when it converges inside the box.

    Inside to what? The float point q is the root only to its forward error: to first order
    |dz| <= ||G^+|| (|g(q)| / L + CERTIFY_ROUNDING), G the column-scaled g_q over L (O(1)),
    g(q) the residual left and CERTIFY_ROUNDING the rounding of its evaluation (relative):
    a bound that grows with the conditioning, not a fixed 1e-12. In the polynomial
    variables (cosines, lengths over the size, a rotation matrix's entries: at most
    4 |de| for a unit quaternion's change de) that is `_error_bound`. The refined point
    counts as the box's root when every variable is within the box's half-width plus that
    bound of its centre, and the bound is below half the (scaled) distance to the nearest
    other root, so that it cannot be another box's. At a multiple root (a singular pose) the
    first-order bound is infinite; the float point's error there is of the order of the
    square root of the rounding (a double root), the cap used."""
    q0 = _unknowns_at(m, S, c, u)
    sol = model.newton(q0, u, p)
    if not sol.ok:
        return q0, "Newton did not converge from the box (a singular pose?): the box's centre is used"
    # plus the rounding of the map from q to the variables (cosines, a rotation's entries)
    bound = (_error_bound(model, sol.q, u, p, L, S.perturbation) * (4.0 if _spatial(m) else 1.0)
             + CERTIFY_ROUNDING)
    off = (np.abs(_variables_at(S, sol.q) - c) - hw) / scale
    if (off > bound).any() or bound >= 0.5 * nearest:
        return q0, (f"the refined point left its box by {float(off.max()):.1e} (relative; its error "
                    f"bound {bound:.1e}, the nearest root at {nearest:.1e}): the box's centre is used")
    return sol.q, ""


def _error_bound(model, q, u, p, L, perturbation=0.0) -> float:
    """First-order bound on the float point q's distance to the root (relative to the size
    for lengths, radians for angles): ||(g_q s)^+||_inf (|g(q)|_inf / L + CERTIFY_ROUNDING
    + 2 perturbation), s the column scale (kincas's `column_scale`); `perturbation` the
    relative distance of the exact system's geometry from the floats' (a rounded axis a
    changes R1 a - R2 a by at most twice its change)."""
    if model.nq == 0:
        return 0.0
    G = model.jac(q, u, p) * model.column_scale(L)
    g = np.abs(model.residual(q, u, p)).max(initial=0.0) / L
    bound = float(np.abs(np.linalg.pinv(G)).sum(axis=1).max() * (g + CERTIFY_ROUNDING + 2 * perturbation))
    return min(bound, math.sqrt(CERTIFY_ROUNDING)) if math.isfinite(bound) else math.sqrt(CERTIFY_ROUNDING)


def _corank(model, q, u, p, L) -> int:
    """Zero singular values of the column-scaled g_q (RANK relative to the largest)."""
    if model.nq == 0:
        return 0
    sv = np.linalg.svd(model.jac(q, u, p) * model.column_scale(L), compute_uv=False)
    return int(model.nq - np.sum(sv > RANK * max(sv.max(initial=0.0), TINY)))


def _split_count(m, u, S, c, scale, L, nearest, system=None) -> int:
    """How many real roots the multiple root at c splits into when the first input moves by
    +-CERTIFY_NUDGE (times the size for a length): the larger count of the two sides, within
    half the distance to the nearest other root (at most CERTIFY_SPLIT, scaled)."""
    if not len(u):
        return 0
    radius = min(0.5 * nearest, CERTIFY_SPLIT)
    step = CERTIFY_NUDGE * (1.0 if m.inputs[0].is_angle else L)
    best = 0
    for sign in (1, -1):
        v = np.array(u, dtype=float)
        v[0] += sign * step
        kind, boxes, _ = _solve((system or (lambda w: _closure(m, w)))(v))
        if kind == "finite":
            near = [b for b in boxes
                    if np.abs((np.array([float((a + z) / 2) for a, z in b]) - c) / scale).max() <= radius]
            best = max(best, len(near))
    return best
