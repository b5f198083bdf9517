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
import numpy as np

from ..errors import ModelError
from ..model.mechanism import Mechanism
from ..core.turns import tied, turns
from ..core.assembly import first_pose
from ..core.scatter import newton_starts
from ..core.numeric import model_of
from ..core.tolerances import ACCEPT, SAME_ASSEMBLY as SAME, START_CONVERGED as CONVERGED
from .assembly_mode import Mode, input_vector as _input_vector, mode_at, signature  # noqa: F401  (their old home)

# SAME: two assemblies are one mode when every point agrees to this times the size


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
    guess = {k: tuple(map(m_at.value, xy)) for k, xy in m.guess}
    Q = np.vstack([model.initial_q(u, p, guess, L), _scatter(m_at, model, starts - 1, L, seed)])
    if tied(model).any():  # gears, racks: each start at the turns their relations want
        Q = np.array([turns(model, q, u, p) for q in Q])
    Q, r = newton_starts(model, Q, u, p, iterations)
    Q = Q[np.isfinite(r) & (r <= CONVERGED)]
    Q = Q[_unique(signature(model, Q, u, p, L), 10 * SAME * L)]  # many starts, few modes

    found = [sol.q for sol in (model.newton(q, u, p, L) for q in Q) if sol.ok]  # polish
    first = first_pose(model, u, p, L, guess)  # the assembly a sweep from the guess starts on
    picked = first.q if first.ok else None
    from ..frames import Modes  # a list, with to_pandas() and to_xarray()
    return Modes(_distinct(m, model, found + ([picked] if picked is not None else []), u, p, L, picked))


def _scatter(m: Mechanism, model, n: int, L: float, seed: int) -> np.ndarray:
    """n starts over the reachable workspace: angles uniform in (-pi, pi]; the origin of a
    floating link uniform in a square of half-side L around a randomly chosen ground point."""
    rng = np.random.default_rng(seed)
    spread = getattr(model, "scatter", None)  # a model with unknowns of its own kinds spreads them
    if spread is not None:
        return spread(m, n, L, rng)
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


def _unique(rows: np.ndarray, tol: float) -> list[int]:
    """Indices of the first row of each group of rows that agree to `tol` (max norm)."""
    keep: list[int] = []
    for k, row in enumerate(rows):
        if all(np.abs(row - rows[j]).max() > tol for j in keep):
            keep.append(k)
    return keep


def _distinct(m, model, found, u, p, L, picked_q) -> list[Mode]:
    """One Mode per distinct assembly: two solutions are the same mode when all their moving
    points, and every spatial body's rotation times L, agree to SAME * L (the points fix
    every planar link's angle modulo 2 pi, not a spatial body's spin about its points' line)."""
    picked = None if picked_q is None else signature(model, picked_q, u, p, L)[0]
    Q = np.array(found).reshape(len(found), model.nq)
    rows = signature(model, Q, u, p, L)
    keep = [(Q[k], rows[k]) for k in _unique(rows, SAME * L)]
    keep.sort(key=lambda t: tuple(np.round(t[1] / (SAME * L))))
    out = [mode_at(m, model, q, u, p, L, picked) for q, _ in keep]
    return [md for md in out if md.residual <= ACCEPT]  # each checked by its residual


# --- `kincas.modes(...)`: the function, also reachable by its 0.1 module path ---


class _CallableModule(types.ModuleType):
    """`kincas.modes` is both this module (`import kincas.modes`, the path of 0.1) and the
    function `modes`: calling the module calls it."""

    def __call__(self, *args, **kwargs) -> "Modes":
        return modes(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
