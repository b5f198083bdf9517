"""Polynomials with exact rational coefficients, and a system of them written for an exact
solver (no casadi, no sympy: a few dozen lines on dicts).

A `Poly` maps monomials to `fractions.Fraction` coefficients; a monomial is a sorted tuple of
(variable index, exponent) pairs, so variables may be added to a `PolySystem` while the
equations are being written. The scene's numbers enter exactly: every float is a dyadic
rational, `exact(x) = Fraction(x)`. An angle's cosine and sine are rarely rational: `unit`
gives a rational point of the unit circle near (cos t, sin t), from the rational tangent of
the half angle, so a rotation built from it is an exact rotation (by an angle that differs
from t by at most about 1e-12 rad; `exact` tells whether it differs at all in floating point).

A `PolySystem` is a residual description: named variables, equations (each = 0), and for
each moving point its coordinates as polynomials in the variables. Nothing here is planar:
a spatial model writes its own equations (unit quaternions, say) into the same system.

>>> S = PolySystem()
>>> x, y = S.var("x"), S.var("y")
>>> S.equations += [x * x + y * y - 1, 4 * x - 1]
>>> print(S.msolve_input())
x0,x1
0
x0^2+x1^2-1,
4*x0-1
>>> c, s, same = unit(0.5)
>>> c * c + s * s == 1, same, abs(float(c) - math.cos(0.5)) < 1e-11
(True, False, True)
>>> unit(math.pi / 2)
(Fraction(0, 1), Fraction(1, 1), True)
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction

from .tolerances import CERTIFY_DENOMINATOR, TINY


def exact(v: float) -> Fraction:
    """A float as the exact rational it is (a dyadic rational)."""
    return Fraction(float(v))


def unit(theta: float) -> tuple[Fraction, Fraction, bool]:
    """A rational point (c, s) with c^2 + s^2 = 1 exactly, near (cos theta, sin theta), and
    whether its angle is theta to floating-point rounding (then nothing was rounded).

    With t = tan(phi / 2) rational, ((1 - t^2), 2 t) / (1 + t^2) lies on the unit circle;
    phi is theta reduced to [-pi/2, pi/2] (the other half turn by a sign), so |t| <= 1."""
    half = math.remainder(theta, 2 * math.pi)  # in [-pi, pi]
    flip = abs(half) > math.pi / 2
    phi = math.remainder(half + math.pi, 2 * math.pi) if flip else half
    t = Fraction(math.tan(phi / 2)).limit_denominator(CERTIFY_DENOMINATOR)
    c, s = (1 - t * t) / (1 + t * t), 2 * t / (1 + t * t)
    if flip:
        c, s = -c, -s
    err = abs(math.remainder(math.atan2(float(s), float(c)) - theta, 2 * math.pi))
    return c, s, err <= 4 * math.ulp(max(1.0, abs(theta)))


class Poly:
    """A polynomial: {monomial: Fraction}, a monomial being ((variable, exponent), ...)."""

    __slots__ = ("terms",)

    def __init__(self, terms=None):
        self.terms = {m: Fraction(c) for m, c in (terms or {}).items() if c != 0}

    @classmethod
    def const(cls, c) -> "Poly":
        return cls({(): c})

    @classmethod
    def var(cls, index: int) -> "Poly":
        return cls({((index, 1),): 1})

    @staticmethod
    def _lift(o) -> "Poly":
        return o if isinstance(o, Poly) else Poly.const(Fraction(o))

    def __add__(self, o):
        out = dict(self.terms)
        for m, c in Poly._lift(o).terms.items():
            out[m] = out.get(m, 0) + c
        return Poly(out)

    __radd__ = __add__

    def __neg__(self):
        return Poly({m: -c for m, c in self.terms.items()})

    def __sub__(self, o):
        return self + (-Poly._lift(o))

    def __rsub__(self, o):
        return Poly._lift(o) - self

    def __mul__(self, o):
        out: dict = {}
        for m1, c1 in self.terms.items():
            for m2, c2 in Poly._lift(o).terms.items():
                m = _times(m1, m2)
                out[m] = out.get(m, 0) + c1 * c2
        return Poly(out)

    __rmul__ = __mul__

    def __eq__(self, o):
        return self.terms == Poly._lift(o).terms

    def __repr__(self):
        return f"Poly({self.terms!r})"

    @property
    def degree(self) -> int:
        return max((sum(e for _, e in m) for m in self.terms), default=0)

    def value(self, x) -> float:
        """The value at a point (floats; x indexed by variable)."""
        return float(sum(float(c) * math.prod(x[v] ** e for v, e in m) for m, c in self.terms.items()))

    def spread(self, box) -> float:
        """A bound on |P(x) - P(centre)| over a box ((lo, hi) per variable, exact rationals),
        by exact interval arithmetic term by term (the bound is exact for degree one)."""
        centre = [(lo + hi) / 2 for lo, hi in box]
        total = Fraction(0)
        for m, c in self.terms.items():
            lo = hi = Fraction(1)  # the monomial's range over the box
            for v, e in m:
                a, b = box[v][0] ** e, box[v][1] ** e
                ends = [a, b] + ([Fraction(0)] if e % 2 == 0 and box[v][0] < 0 < box[v][1] else [])
                cand = [lo * min(ends), lo * max(ends), hi * min(ends), hi * max(ends)]
                lo, hi = min(cand), max(cand)
            mid = math.prod((centre[v] ** e for v, e in m), start=Fraction(1))
            total += abs(c) * max(hi - mid, mid - lo)
        return float(total)

    def subs(self, values: dict) -> "Poly":
        """The polynomial with variables replaced (variable index -> Poly)."""
        out = Poly()
        for m, c in self.terms.items():
            term = Poly.const(c)
            for v, e in m:
                base = values.get(v, Poly.var(v))
                for _ in range(e):
                    term = term * base
            out = out + term
        return out

    def linear(self) -> tuple[dict, Fraction] | None:
        """(variable -> coefficient, constant) when the degree is at most one, else None."""
        if self.degree > 1:
            return None
        return ({m[0][0]: c for m, c in self.terms.items() if m}, self.terms.get((), Fraction(0)))

    def gradient(self, x, n: int) -> list[float]:
        """The partial derivatives at a point (floats; x indexed by variable), n variables.

        >>> P = Poly({((0, 2), (1, 1)): 3})  # 3 x0^2 x1
        >>> P.gradient([2.0, 5.0], 2)
        [60.0, 12.0]
        """
        out = [0.0] * n
        for m, c in self.terms.items():
            for k, (v, e) in enumerate(m):
                rest = math.prod(x[w] ** f for j, (w, f) in enumerate(m) if j != k)
                out[v] += float(c) * e * x[v] ** (e - 1) * rest
        return out

    def integer_terms(self) -> dict:
        """The same equation with coprime integer coefficients (denominators cleared)."""
        lcm = math.lcm(*(c.denominator for c in self.terms.values())) if self.terms else 1
        ints = {m: int(c * lcm) for m, c in self.terms.items()}
        g = math.gcd(*ints.values()) if ints else 1
        return {m: c // g for m, c in ints.items()}


def independent(equations, x, n: int, scale, tol: float, always=()) -> list[int]:
    """Indices of a largest set of `equations` whose gradients at x are independent: the
    `always` ones kept whatever they are (a rotation's R'R = I and det R = 1: locally
    dependent, globally needed against reflections), then each of the others in turn, the
    linear ones first, kept when its gradient leaves the span of those kept (Gram-Schmidt,
    each gradient normalised, the columns of length variables times their `scale`; a
    remainder below `tol` counts as inside). The others are implied there to first order.

    >>> S = PolySystem(); x, y = S.var("x"), S.var("y")
    >>> independent([x * y - 1, 2 * x - 2 * y, x - y, x + y], [1.0, 1.0], 2, [1.0, 1.0], 1e-8)
    [1, 3]
    """
    import numpy as np
    J = np.array([P.gradient(x, n) for P in equations]).reshape(len(equations), n) * np.asarray(scale, float)
    J /= np.maximum(np.linalg.norm(J, axis=1, keepdims=True), TINY)
    basis, keep = [], []

    def add(k, forced):
        r = J[k].copy()
        for _ in range(2):  # twice: Gram-Schmidt's rounding
            for b in basis:
                r -= (b @ r) * b
        norm = np.linalg.norm(r)
        if norm > tol:
            basis.append(r / norm)
        if forced or norm > tol:
            keep.append(k)

    for k in always:
        add(k, True)
    rest = [k for k in range(len(equations)) if k not in set(always)]
    for k in sorted(rest, key=lambda k: equations[k].degree > 1):  # linear first, stable
        add(k, False)
    return sorted(keep)


def _times(m1, m2):
    out = dict(m1)
    for v, e in m2:
        out[v] = out.get(v, 0) + e
    return tuple(sorted(out.items()))


@dataclass
class PolySystem:
    """Variables, equations (each = 0) and what they mean for the model that wrote them.

    `points`: moving point -> its coordinates as polynomials (for the box's size in length
    units); `unknowns`: per unknown of the numerical model, how to read it from a solution
    (("angle", ci, si): atan2 of two variables; ("value", i): a variable); `rounded`: notes
    on inputs that were rounded to rationals (the certificate is for the rounded pose)."""

    names: list[str] = field(default_factory=list)
    equations: list[Poly] = field(default_factory=list)
    points: dict = field(default_factory=dict)
    unknowns: list = field(default_factory=list)
    rounded: list[str] = field(default_factory=list)
    length: list[bool] = field(default_factory=list)  # per variable: a length (else a ratio)
    at: dict = field(default_factory=dict)  # the values the equations were written at (rounded ones)
    to_unknowns: object = None  # x -> kincas's q, when not per unknown as in `unknowns` (spatial: R -> e)
    from_unknowns: object = None  # (q[, u]) -> x, its inverse (q at inputs u: the system's own by default)
    off_model: object = None  # x -> how far (relative) x is from from_unknowns(to_unknowns(x)): equations
    # the numerical model satisfies by construction (spatial: a body hung on its joint) that x breaks
    perturbation: float = 0.0  # relative distance of the rationalised geometry (axes) from the scene's floats
    structural: list = field(default_factory=list)  # indices of equations kept whatever the rank (R'R = I, det R = 1)
    implied: int = 0  # equations left out as implied (an overconstrained mechanism: kincas/analysis/certify_over.py)

    def var(self, name: str, length: bool = False) -> Poly:
        self.names.append(name)
        self.length.append(length)
        return Poly.var(len(self.names) - 1)

    def msolve_input(self, equations=None, variables=None) -> str:
        """msolve's input: the variables, the characteristic 0, the equations expanded with
        integer coefficients (msolve misreads parentheses and fractions). `variables`: the
        indices written (as x0, x1, ... in this order); default all."""
        eqs = self.equations if equations is None else equations
        used = list(range(len(self.names))) if variables is None else list(variables)
        rename = {v: Poly.var(k) for k, v in enumerate(used)}
        rows = [_write(p.subs(rename).integer_terms()) for p in eqs if p.terms]
        return ",".join(f"x{k}" for k in range(len(used))) + "\n0\n" + ",\n".join(rows)

    def eliminated(self):
        """The linear equations solved exactly (Gauss-Jordan over the rationals) and
        substituted into the others: (equations in the free variables, the free variables,
        variable -> affine Poly in them for every eliminated one), or None when the linear
        equations are inconsistent (no solution). Fewer variables make msolve's work far
        smaller (the 56-solution Assur group 4.4: 16 variables -> 8)."""
        rows, rest = [], []
        for p in self.equations:
            lin = p.linear()
            (rows if lin is not None else rest).append(lin if lin is not None else p)
        pivots: dict = {}  # variable -> (coefficients of the others, constant): var = -(...)
        for coef, const in rows:
            coef, const = dict(coef), const
            for v, (pc, pk) in pivots.items():  # reduce by earlier pivots
                if v in coef:
                    f = coef.pop(v)
                    for w, c in pc.items():
                        coef[w] = coef.get(w, 0) - f * c
                    const -= f * pk
            coef = {w: c for w, c in coef.items() if c != 0}
            if not coef:
                if const != 0:
                    return None  # 0 = const: inconsistent
                continue
            v = max(coef)  # the latest variable: kept ones are the first links' angles
            f = coef.pop(v)
            pc, pk = {w: c / f for w, c in coef.items()}, const / f
            for u, (uc, uk) in list(pivots.items()):  # back-substitute into earlier pivots
                if v in uc:
                    g = uc.pop(v)
                    for w, c in pc.items():
                        uc[w] = uc.get(w, 0) - g * c
                    pivots[u] = ({w: c for w, c in uc.items() if c != 0}, uk - g * pk)
            pivots[v] = (pc, pk)
        value = {v: Poly({((w, 1),): -c for w, c in pc.items()}) - pk for v, (pc, pk) in pivots.items()}
        eqs = [q for q in (p.subs(value) for p in rest) if q.terms]
        free = [k for k in range(len(self.names)) if k not in value]
        return eqs, free, value


def _write(terms: dict) -> str:
    out = []
    for m, c in sorted(terms.items(), key=lambda t: (-sum(e for _, e in t[0]), t[0])):
        mono = "*".join(f"x{v}" + (f"^{e}" if e > 1 else "") for v, e in m)
        body = (str(abs(c)) if not mono else mono if abs(c) == 1 else f"{abs(c)}*{mono}")
        out.append(("-" if c < 0 else "+") + body)
    text = "".join(out)
    return text[1:] if text.startswith("+") else text
