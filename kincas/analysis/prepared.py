"""What a sweep needs of one mechanism, worked out once per mechanism and kept by its model.

A `Mechanism` is an immutable value, so its parameter values, its size and its guessed
points never change, and neither does the first pose's *placement*: the unknowns that
`guessed_start` builds from the guessed points at given inputs (or, without a guess, the
pose assembled group by group in the default modes). Repeated sweeps of one mechanism (the
usual case: a user, a benchmark or an optimiser calling `kincas.sweep` again) read them here
instead of recomputing them. The table belongs to the structure's `Model` (`Model.memo`),
holds the RECENT mechanisms prepared last (each kept by a reference, so its `id` stays its
own) and is a `Memo` (kincas/core/caches.py, the one kind of cache), as is each mechanism's
table of placements: nothing here is global, and threads share only immutable arrays.

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
>>> model = kincas.model_of(m)
>>> pm = prepared(model, m)
>>> pm is prepared(model, m), pm.size, pm.keys
(True, 4.0, ('crank.angle',))
>>> q0 = pm.placement(model, np.array([0.0]), pm.guess).q0
>>> bool(np.allclose(q0, guessed_start(model, np.array([0.0]), pm.p, 4.0, pm.guess)))
True
"""
from __future__ import annotations

import math

import numpy as np

from ..core.assembly import ambiguous, assemble
from ..core.caches import Memo
from ..core.fast import sweeper_for
from ..core.guessed import guessed_start
from ..core.numeric import Solution
from ..model.mechanism import Mechanism, check_guess

_PLAIN = (float, int, np.float64)  # numbers a guess gives as they are (not bool: not a number)
_F8, _ND = np.dtype(np.float64), np.ndarray
RECENT = 32  # mechanisms kept per structure
PLACEMENTS = 8  # first-pose placements kept per mechanism (inputs and guesses of its sweeps)


# --- one mechanism's fixed data ---


class Prepared:
    """A mechanism's parameter values `p` (read-only), `size`, input `keys`, guessed points
    `guess` (name -> (x, y), numbers) and its first-pose placements (`placement`)."""

    def __init__(self, m: Mechanism):
        self.m = m
        self.p = np.array([v for _, v in m.parameters], dtype=float)
        self.p.flags.writeable = False
        self.size = m.size()
        self.keys = tuple(i.key for i in m.inputs)
        self.guess = {k: tuple(map(m.value, xy)) for k, xy in dict(m.guess).items()}
        # gears and racks: the first pose's free angles are taken into (-pi, pi] after Newton
        # (core/turns.settle): that pose stays on the careful path
        self.plain = not (m.gears or m.racks)
        self._places = Memo(bound=PLACEMENTS)  # (inputs, guess) -> Placement or None
        self._sweepers: dict = {}  # (report, compile) -> FastSweeper
        self._names: set = set()  # reports whose names were checked
        self.reports: dict = {}  # report as given (None, a name, a tuple of names) -> the names
        self._moving = frozenset(m.moving_points)  # the points a guess may place
        self._dim = 3 if getattr(m, "space", "2d") == "3d" else 2

    def with_guess(self, guess) -> dict:
        """The guessed points (`guess`, numbers) updated by a guess given to one call, checked
        as the mechanism's own (`check_guess`: ModelError naming what is wrong). Plain finite
        numbers for moving points, the usual case, are taken as they are without the full
        check (a forward-kinematics loop passes a fresh guess at every call)."""
        if not guess:
            return self.guess
        if type(guess) is dict:
            new, dim, moving = {}, self._dim, self._moving
            for k, xy in guess.items():
                t = type(xy)
                if t is np.ndarray:
                    xy = xy.tolist() if xy.dtype == np.float64 and xy.shape == (dim,) else None
                elif t is not tuple and t is not list:
                    xy = None
                if xy is None or len(xy) != dim or k not in moving:
                    break
                c = tuple(float(v) for v in xy if type(v) in _PLAIN)
                if len(c) != dim or not all(map(math.isfinite, c)):
                    break
                new[k] = c
            else:
                return {**self.guess, **new}
        m = self.m
        return {**self.guess, **{k: tuple(map(m.value, xy)) for k, xy in check_guess(m, guess)}}

    def sweeper(self, model, report: tuple, compile):
        """The model's `FastSweeper` for `report` and `compile` (`sweeper_for`), found here
        without the model's lock once looked up (unknown names raise ModelError, every time)."""
        fast = self._sweepers.get((report, compile))
        if fast is None:
            fast = self._sweepers[(report, compile)] = sweeper_for(model, report, compile)
        return fast

    def check_report(self, model, report: tuple) -> None:
        """ModelError for a quantity name the model does not know (`Model.quantity_function`),
        each list of names looked up once."""
        if report not in self._names:
            model.quantity_function(report)
            self._names.add(report)

    def placement(self, model, u: np.ndarray, guess: dict):
        """A `Placement` (q0, qs): the first pose's unknowns placed at inputs u from `guess`
        (the guessed points, as the careful path places them), and each unknown's scale within
        its own group (`Model.scales`); None where the careful path must decide alone (gears, no
        assembly found group by group). Computed once per inputs and guess."""
        if not self.plain or model.nq == 0:
            return None
        key = (u.tobytes() if type(u) is _ND and u.dtype == _F8 else np.asarray(u, float).tobytes(),
               None if guess is self.guess else tuple(sorted(guess.items())))  # (the usual case)
        out = self._places.peek(key, self)  # (self: not kept; a placement may be None)
        return self._placed(key, model, u, guess) if out is self else out

    def _placed(self, key, model, u, guess):
        """`placement` not found: made (once per key, `Memo.get_or_build`). (A closure made
        in `placement` would make cells of its arguments at every call.)"""
        return self._places.get_or_build(key, lambda: self._place(model, u, guess))

    def _place(self, model, u, guess):
        u = np.array(u, float)
        if guess:
            q0 = guessed_start(model, u, self.p, self.size, guess)
        elif not ambiguous(model):  # no guess: the careful path assembles group by group
            sol = assemble(model, u, self.p, self.size)
            q0 = None if sol is None else sol.q
        else:
            q0 = None
        if q0 is not None and np.all(np.isfinite(q0)):
            return Placement(q0, model.scales(u, self.p)[1])
        return None


# --- where a sweep's first pose starts, and its careful answer ---


class Placement:
    """Where the careful path starts Newton for a sweep's first pose: `q0` (the unknowns
    placed from the guessed points, or assembled group by group without a guess) and `qs`,
    each unknown's scale in its own group (`Model.scales`), both read-only; `kernel` is
    left to the fast kernel to keep its state at q0 in (it depends on q0 alone), and `solved`
    (`first_pose`) keeps the careful path's answer from the same guess at the same inputs,
    which depends on nothing else (a rough guess makes it a search: 2 ms in 3D)."""

    __slots__ = ("q0", "qs", "kernel", "_solved")

    def __init__(self, q0, qs):
        self.q0, self.qs, self.kernel, self._solved = q0, qs, None, None
        q0.flags.writeable = qs.flags.writeable = False

    def solved(self, solve) -> Solution:
        """`solve()` (the careful path's first pose from this placement's guess and inputs),
        computed once; each caller gets its own copy of the arrays."""
        sol = self._solved
        if sol is None:  # (two threads may both solve it: the same answer, either is kept)
            sol = self._solved = solve()
        return Solution(sol.q.copy(), sol.residual, sol.iterations, sol.ok,
                        None if sol.J is None else sol.J.copy())


def prepared(model, m: Mechanism) -> Prepared:
    """The `Prepared` data of mechanism m, whose structure's model is `model`."""
    # id(m) -> Prepared, which keeps m: an id is never reused while it is kept
    return model.memo("sweep.prepared", lambda: Memo(bound=RECENT)).get_or_build(id(m), lambda: Prepared(m))


# --- the mechanisms last swept, by identity: their model and prepared data in one look-up ---

# id(m) -> (m, model, Prepared); each entry keeps its m, so its id is its own
_SEEN = Memo("mechanisms last swept", bound=RECENT)


def model_and_prepared(m: Mechanism, model_of):
    """(model_of(m), prepared(model, m)) for mechanism m, found by identity when m was swept
    lately: a sweep of a mechanism already swept neither hashes its structure again (the
    structure key is every link and joint) nor repeats the deferred mobility check, which
    `model_of` runs (a mechanism is immutable: what was decided for it stays decided; a
    mechanism refused raises every time, since nothing is kept for it)."""
    seen = _SEEN.peek(id(m))  # (the usual case: no lock, no closure)
    if seen is not None and seen[0] is m:
        return seen[1], seen[2]
    _, model, pm = _SEEN.get_or_build(id(m), _builder(m, model_of))
    return model, pm


def _builder(m: Mechanism, model_of):
    """build() -> (m, model, prepared) for `model_and_prepared` (a closure made there would
    make cells of its arguments at every call)."""
    def build():
        model = model_of(m)
        return m, model, prepared(model, m)
    return build
