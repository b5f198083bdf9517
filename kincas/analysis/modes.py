"""Assembly modes: every distinct real assembly of a mechanism at given input values.

A closed chain has, for the same inputs, several ways to be put together: a four-bar two
(the coupler above or below), an Assur class-III triad up to six. A sweep follows one of
them, the one its `[guess]` points at. `find_modes` finds them all: Newton's method with the
exact Jacobian run from many starts scattered over the reachable workspace (every unknown
angle uniform in (-pi, pi], every floating link's origin within the mechanism's size around
a ground point), all starts at once in one vectorised evaluation per iteration; the
converged ones are polished one by one, checked by their residual, and duplicates removed.
Each `Mode` gives its points and a ready `[guess]` block that picks it.

There is no proof of completeness (a root that no start reaches is missed), but a mode's
basin of attraction under a trust-region Newton is rarely small: with a few hundred starts
the six assemblies of the class-III triad are found from every seed in the tests.

>>> import numpy as np, kincas
>>> from kincas.analysis.modes import find_modes
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)], inputs=[kincas.Input.angle("crank")])
>>> modes = find_modes(m, {"crank.angle": np.pi / 2}, starts=64)
>>> len(modes), sorted(round(md.points["C"][1], 6) for md in modes)
(2, [-2.015052, 2.823876])
>>> print(modes[0].guess_block().splitlines()[0])
[guess]
>>> sw = kincas.sweep(m, {"crank.angle": [np.pi / 2, np.pi]}, guess=modes[0].guess)
>>> bool(abs(sw["C.y"][0] - modes[0].points["C"][1]) < 1e-12)
True
"""
from __future__ import annotations

import math
import sys
import types
from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError
from ..model.mechanism import Mechanism
from ..results import wrap_angle
from ..core.turns import tied, turns
from ..core.assembly import first_pose
from ..core.scatter import newton_starts
from ..core.numeric import model_of
from ..core.tolerances import ACCEPT, BRANCH, SAME_ASSEMBLY as SAME, START_CONVERGED as CONVERGED
from .inputs import input_table

# SAME: two assemblies are one mode when every point agrees to this times the size


# --- a mode ---


@dataclass(frozen=True)
class Mode:
    """One real assembly: the unknowns `q`, the moving points' positions, the link angles
    (radians, wrapped to (-pi, pi]), the relative residual after polishing, the sign of the
    Jacobian's determinant (which side of the singular positions the mode lies on; 0 when
    singular), and whether the mechanism's own guess leads to it."""

    q: np.ndarray
    unknowns: tuple[str, ...]
    points: dict[str, tuple[float, float]]
    angles: dict[str, float]
    residual: float
    orientation: int
    from_guess: bool = False
    inputs: dict[str, float] = field(default_factory=dict)

    @property
    def guess(self) -> dict[str, tuple[float, float]]:
        """The points as a guess: `kincas.sweep(m, ..., guess=mode.guess)` follows this mode."""
        return dict(self.points)

    def guess_block(self, digits: int = 12) -> str:
        """A `[guess]` section for a scene file that picks this mode.

        >>> Mode(np.zeros(1), ("a",), {"C": (1.0, -2.5)}, {}, 0.0, 1).guess_block()
        '[guess]\\nC = [1, -2.5]\\n'
        """
        rows = [f"{p} = [{x:.{digits}g}, {y:.{digits}g}]" for p, (x, y) in self.points.items()]
        return "[guess]\n" + "".join(r + "\n" for r in rows)


# --- the search ---


def modes(mechanism: Mechanism, inputs=None, *, certify: bool = False, **options) -> "Modes":
    """Every real assembly of `mechanism` at `inputs`: by the multistart search
    (`find_modes`, not certified), or with `certify=True` by an exact real-root solver whose
    answer proves the list complete (`kincas.analysis.certify.certify_modes`: needs
    `pip install "kincas[certify]"`; pins and slides only).

    Parameters
    ----------
    mechanism : Mechanism
    inputs : dict or float, optional
        Input key -> value (radians for angles); a number for a one-input mechanism.
    certify : bool
        Prove the list complete (each mode isolated in a box by msolve, refined by Newton).
    **options
        Passed on: `starts`, `seed`, `iterations` (multistart), or `threads`, `timeout`
        (certified).

    Returns
    -------
    Modes
        A list of `Mode`; `.certified` tells which search made it. Certified, each mode also
        has `halfwidth`, `multiplicity` and `flag`, and the list its `count`.

    Examples
    --------
    >>> import numpy as np, kincas
    >>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
    ...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
    ...            kincas.Link.bar("rocker", "D", "C", 3)], inputs=[kincas.Input.angle("crank")])
    >>> found = kincas.modes(m, {"crank.angle": np.pi / 2}, starts=64)
    >>> len(found), found.certified
    (2, False)
    """
    if certify:
        from .certify import certify_modes
        return certify_modes(mechanism, inputs, **options)
    return find_modes(mechanism, inputs, **options)



def find_modes(m: Mechanism, inputs=None, *, starts: int = 512, seed: int = 0,
               iterations: int = 60) -> "Modes":
    """The distinct real assemblies of `m` at `inputs` (input key -> value; a plain number
    for a one-input mechanism; nothing for a structure without inputs).

    Deterministic for a given `seed`. Modes are sorted by their points (x, then y, of each
    moving point in declaration order); an empty list means no assembly was found.

    Parameters
    ----------
    m : Mechanism
    inputs : dict or float, optional
        Input key -> value; a number for a one-input mechanism.
    starts : int
        Scattered starting points of Newton.
    seed : int
    iterations : int
        Newton iterations per start.

    Returns
    -------
    Modes
        A list of `Mode` (index it, iterate it as before) that is also a `kincas` result:
        `ok`, `to_pandas()`, `to_xarray()`.

    Examples
    --------
    A four-bar has two assemblies, mirror images about the line BD:

    >>> import numpy as np, kincas
    >>> m = kincas.Mechanism(parameters={"a": 1.0}, ground={"A": (0, 0), "D": (4, 0)},
    ...     links=[kincas.Link.bar("crank", "A", "B", "a"), kincas.Link.bar("coupler", "B", "C", 3.5),
    ...            kincas.Link.bar("rocker", "D", "C", 3)],
    ...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
    >>> modes = find_modes(m, {"crank.angle": 0.5})
    >>> [round(md.points["C"][1], 6) for md in modes], [md.from_guess for md in modes]
    ([-2.610429, 2.933719], [False, True])
    """
    if starts < 1:
        raise ModelError(f"starts: expected a whole number >= 1, got {starts!r}")
    model = model_of(m)
    u = _input_vector(m, inputs)
    driven = {i.target: float(u[k]) for k, i in enumerate(m.inputs) if i.kind == "parameter"}
    m_at = m.with_parameters(**driven) if driven else m
    p = np.array([v for _, v in m.parameters], dtype=float)
    L = m_at.size()

    # The mechanism's own guess is start 0, so the mode a sweep would take is always found.
    guess = {k: (m_at.value(x), m_at.value(y)) for k, (x, y) in m.guess}
    Q = np.vstack([model.initial_q(u, p, guess, L), _scatter(m_at, model, starts - 1, L, seed)])
    if tied(model).any():  # gears, racks: each start at the turns their relations want
        Q = np.array([turns(model, q, u, p) for q in Q])
    Q, r = newton_starts(model, Q, u, p, iterations)
    Q = Q[np.isfinite(r) & (r <= CONVERGED)]
    Q = Q[_unique(_point_rows(model, Q, u, p), 10 * SAME * L)]  # many starts, few modes

    found = [sol.q for sol in (model.newton(q, u, p, L) for q in Q) if sol.ok]  # polish
    first = first_pose(model, u, p, L, guess)  # the assembly a sweep from the guess starts on
    picked = first.q if first.ok else None
    from ..frames import Modes  # a list, with to_pandas() and to_xarray()
    return Modes(_distinct(m, model, found + ([picked] if picked is not None else []), u, p, L, picked))


def _input_vector(m: Mechanism, inputs) -> np.ndarray:
    """One finite value per input (the pose at which the modes are wanted)."""
    U = input_table(m, {} if inputs is None and not m.inputs else inputs, "inputs", None)
    if U.shape[0] != 1:
        raise ModelError("inputs: expected one value per input (modes are found at one pose)")
    return U[0]


def _scatter(m: Mechanism, model, n: int, L: float, seed: int) -> np.ndarray:
    """n starts over the reachable workspace: angles uniform in (-pi, pi]; the origin of a
    floating link uniform in a square of half-side L around a randomly chosen ground point."""
    rng = np.random.default_rng(seed)
    names = model.unknown_names
    Q = rng.uniform(-math.pi, math.pi, size=(n, len(names)))
    ground = np.array([(m.value(x), m.value(y)) for _, (x, y) in m.ground]).reshape(-1, 2)
    if len(ground) == 0:
        ground = np.zeros((1, 2))
    for j, nm in enumerate(names):
        if nm.endswith(".x") and f"{nm[:-2]}.y" in names:  # a floating link's origin
            jy = names.index(f"{nm[:-2]}.y")
            centre = ground[rng.integers(len(ground), size=n)]
            Q[:, j], Q[:, jy] = (centre + rng.uniform(-L, L, size=(n, 2))).T
    return Q


# --- duplicates ---


def _point_rows(model, Q, u, p) -> np.ndarray:
    """The moving points of every row of Q, one row (x1, y1, x2, y2, ...) per start."""
    return model.points_many(Q, u, p)


def _unique(rows: np.ndarray, tol: float) -> list[int]:
    """Indices of the first row of each group of rows that agree to `tol` (max norm)."""
    keep: list[int] = []
    for k, row in enumerate(rows):
        if all(np.abs(row - rows[j]).max() > tol for j in keep):
            keep.append(k)
    return keep


def _distinct(m, model, found, u, p, L, picked_q) -> list[Mode]:
    """One Mode per distinct assembly: two solutions are the same mode when all their moving
    points agree to SAME * L (the points fix every link's angle modulo 2 pi)."""
    picked = None if picked_q is None else model.points(picked_q, u, p).T.ravel()
    Q = np.array(found).reshape(len(found), model.nq)
    rows = _point_rows(model, Q, u, p)
    keep = [(Q[k], rows[k]) for k in _unique(rows, SAME * L)]
    keep.sort(key=lambda t: tuple(np.round(t[1] / (SAME * L))))
    out = [mode_at(m, model, q, u, p, L, picked, pts) for q, pts in keep]
    return [md for md in out if md.residual <= ACCEPT]  # each checked by its residual


def mode_at(m, model, q, u, p, L, picked=None, pts=None, kind=None, **extra) -> Mode:
    """The `Mode` at unknowns q: its points, link angles, relative residual, orientation, and
    whether it is the assembly `picked` (a row of points, or None); `kind` a subclass of
    Mode built with the `extra` fields (kincas/analysis/certify.py)."""
    names = m.moving_points
    pts = model.points(q, u, p).T.ravel() if pts is None else pts
    links = [lk.name for lk in m.links]
    s = model.column_scale(L)  # columns scaled to O(1)
    ang = model.quantities([f"{lk}.angle" for lk in links], q[None, :], u[None, :], p,
                           np.ones((1, len(u))), np.zeros((1, len(u))))[:, 0]
    det = np.linalg.det(model.jac(q, u, p) * s) if model.nq else 1.0
    res = float(np.abs(model.residual(q, u, p)).max(initial=0.0) / L)
    return (kind or Mode)(
        q=np.array(q), unknowns=tuple(model.unknown_names),
        points={nm: (float(pts[2 * j]), float(pts[2 * j + 1])) for j, nm in enumerate(names)},
        angles={lk: float(wrap_angle(a)) for lk, a in zip(links, ang)},
        residual=res, orientation=int(np.sign(det)) if abs(det) > BRANCH else 0,
        from_guess=bool(picked is not None and np.abs(pts - picked).max() <= SAME * L),
        inputs={i.key: float(v) for i, v in zip(m.inputs, u)}, **extra)


# --- `kincas.modes(...)`: the function, also reachable by its 0.1 module path ---


class _CallableModule(types.ModuleType):
    """`kincas.modes` is both this module (`import kincas.modes`, the path of 0.1) and the
    function `modes`: calling the module calls it."""

    def __call__(self, *args, **kwargs) -> "Modes":
        return modes(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
