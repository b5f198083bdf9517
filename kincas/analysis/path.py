"""The one continuation of kincas: a solved pose walked along a path, step by step.

A path is a homotopy in one scalar s: the inputs, the parameters or both move from where a
pose is solved to where one is wanted (u(s) = u0 + s (u1 - u0), p(s) = p0 + s (p1 - p0)), or
the branch itself is followed in its arclength, through the turning points the inputs
cannot pass (the range of an input, kincas/analysis/singular.py). Every step is the same
three moves, supplied by the caller as one `step` function:

- predict the pose at the step's end: along the path's tangent, from g(q(s), u(s), p(s)) = 0,
      dq/ds = -g_q^-1 (g_u u' + g_p p'),
  or along the secant through the pose before (where g_q is nearly singular and the
  tangent is undefined: two branches cross there);
- correct it by the one Newton (kincas/core/newton.py), on every group or on some;
- test it: converged, not wandered from the prediction (`wandered`), every Assur group in
  its mode (kincas/core/branch.py), no singular position inside the step (located and
  placed on it by kincas/core/limits.on_step).

The walk decides what a rejected step becomes (its step control):

- `Bisect(end, depth)`: cut into two halves walked in turn, `depth` times at most (the
  careful path of a sweep; Assur groups carried through a gap, kincas/analysis/resume.py);
- `Steps(ends)`: fixed steps, none cut (the designs' first poses, continued in the
  parameters from the nominal's, kincas/analysis/design_job.py);
- `Arclength(...)`: the step's length halved on a rejection, grown on a success.

`follow` walks one path; `follow_all` walks many in lockstep, one batched `step` for all
(the designs). A walk ends with its reason, data from `STOPS`: "reached", or why it stopped.

>>> def step(w):  # x^2 = s: predicted along the tangent 1 / (2 x), corrected by Newton
...     x = w.at + (w.target - w.where) / (2 * w.at)
...     for _ in range(6):
...         x -= (x * x - w.target) / (2 * x)
...     return x, None if w.target - w.where <= 0.75 else "slow"  # longer steps refused
>>> w = follow(1.0, 1.0, Bisect(4.0, depth=3), step)
>>> w.reason, round(w.at, 12), [s for _, s in w.reach]  # 3 = 0.75 + 0.75 + 0.75 + 0.75
('reached', 2.0, [1.75, 2.5, 3.25])
>>> follow(1.0, 1.0, Bisect(4.0, depth=1), step).reason  # halves of 1.5: still too long
'slow'
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.tolerances import WANDER_FLOOR, WANDER_SHARE

# Why a walk ended (`Walk.reason`): the same words for every path, in inputs or parameters
STOPS = {
    "reached": "the end of the path was reached",
    "not converged": "Newton did not converge at the end of the shortest step",
    "slow": "Newton needed more iterations than a short step should",
    "wandered": "the corrector landed far from the prediction (another part of the branch)",
    "branch changed": "an Assur group changed assembly mode (kincas/core/branch.py)",
    "singular crossed": "a singular position lies inside the shortest step",
    "budget": "the solves allowed for the walk were spent",
    "step too small": "the step was cut below the shortest allowed",
    "limit": "the followed input turned back: a limit of its range",
    "full turn": "an angle input turned fully",
}


# --- step control ---


class Bisect:
    """A step to `end`, cut in two halves where rejected (each walked in turn), at most
    `depth` times: the careful path's. A half is predicted from the pose before its start
    as a recursive bisection has it: the first half from the pose before the step (`before`,
    (pose, point) or None), the second from the step's start."""

    def __init__(self, end, depth: int, before=None):
        self.stack = [(end, depth, before)]  # (end, cuts left, the pose before its start)

    @property
    def target(self):
        return self.stack[-1][0]

    @property
    def last(self) -> bool:
        return self.stack[-1][1] == 0

    def before(self, walk):
        return self.stack[-1][2]

    def accepted(self, walk) -> bool:
        self.stack.pop()
        return not self.stack

    def rejected(self, walk, why):
        end, depth, before = self.stack.pop()
        if depth == 0:
            return why
        mid = 0.5 * (walk.where + end)
        self.stack += [(end, depth - 1, (walk.at, walk.where)), (mid, depth - 1, before)]
        return None


class Steps:
    """Fixed steps to the points `ends` in turn, none cut: a rejected step ends the walk."""

    def __init__(self, ends):
        self.ends, self.i = list(ends), 0

    @property
    def target(self):
        return self.ends[self.i]

    last = True

    def before(self, walk):
        return _accepted_before(walk)

    def accepted(self, walk) -> bool:
        self.i += 1
        return self.i == len(self.ends)

    def rejected(self, walk, why):
        return why


class Arclength:
    """Steps of length `h` (the target is the length): halved where rejected, until below
    `shortest` ("step too small"); grown by `grow` where accepted, up to `longest`. The walk
    has no end of its own: the caller's `stop` ends it (a limit, a full turn), or its budget."""

    def __init__(self, h: float, longest: float, grow: float, shortest: float):
        self.h, self.longest, self.grow, self.shortest = h, longest, grow, shortest

    @property
    def target(self):
        return self.h

    last = False

    def before(self, walk):
        return _accepted_before(walk)

    def accepted(self, walk) -> bool:
        self.h = min(self.longest, self.h * self.grow)
        return False

    def rejected(self, walk, why):
        self.h /= 2
        return "step too small" if self.h < self.shortest else None


def _accepted_before(walk):
    """(pose, point) accepted before the walk's current one; None at its start."""
    return None if walk.prev is None else (walk.prev, walk.prev_where)


# --- the walk ---


@dataclass(eq=False)
class Walk:
    """One path being walked: `at` the last accepted pose (whatever `step` returns) at the
    path's point `where`; `prev` (and `prev_where`) the one accepted before; `reach` every
    (pose, point) accepted before the last, in order; `reason` None while walking, then a
    key of `STOPS`; `tries` the steps tried."""

    at: object
    where: object
    control: object
    prev: object = None
    prev_where: object = None
    reach: list = field(default_factory=list)
    reason: str | None = None
    tries: int = 0

    @property
    def ok(self) -> bool:
        """Whether the walk reached the end of its path."""
        return self.reason == "reached"

    @property
    def target(self):
        """The point the step under way goes to (its length, for an arclength walk)."""
        return self.control.target

    @property
    def last(self) -> bool:
        """Whether a rejection of the step under way ends the walk (no cut left)."""
        return self.control.last

    @property
    def before(self):
        """(pose, point) before the step's start, for a secant predictor (None: none)."""
        return self.control.before(self)


def follow_all(walks: list[Walk], step, *, stop=None, budget: int | None = None, reach: bool = True) -> list[Walk]:
    """Walk every path of `walks` to its end, in lockstep: each round, one call
    `step(live)` tries the next step of every walk still going and returns, per walk,
    (pose, None) for an accepted step or (anything, reason) for a rejected one (a key of
    `STOPS`). An accepted step moves the walk to the step's target (and, where the step
    control has no end, `stop(walk)` may end it with a reason); a rejected one is cut by the
    walk's step control, or ends it. `budget`: steps tried per walk at most. `reach`: keep
    every pose passed in `Walk.reach` (False: a long walk that needs only its ends).

    Parameters
    ----------
    walks : list of Walk
    step : callable
        list of Walk -> list of (pose, reason or None).
    stop : callable, optional
        Walk -> reason or None, after each accepted step.
    budget : int, optional
    reach : bool

    Returns
    -------
    list of Walk
        The same walks, each with its `reason`.

    Examples
    --------
    Two walks, one batched step: x^2 = s from s = 1, to s = 4 and to s = 9, two steps each,
    predicted along the tangent 1 / (2 x) only (Euler's method: 1 + 1.5 / 2 = 1.75, then
    1.75 + 1.5 / 3.5; 1 + 4 / 2 = 3, then 3 + 4 / 6):

    >>> def step(live):
    ...     return [(w.at + (w.target - w.where) / (2 * w.at), None) for w in live]
    >>> ws = follow_all([Walk(1.0, 1.0, Steps([2.5, 4.0])), Walk(1.0, 1.0, Steps([5.0, 9.0]))], step)
    >>> [(w.reason, round(w.at, 12)) for w in ws], round(1.75 + 1.5 / 3.5, 12), round(3 + 4 / 6, 12)
    ([('reached', 2.178571428571), ('reached', 3.666666666667)], 2.178571428571, 3.666666666667)
    """
    live = [w for w in walks if w.reason is None]
    while live:
        if budget is not None:
            for w in live:
                if w.tries >= budget:
                    w.reason = "budget"
            live = [w for w in live if w.reason is None]
            if not live:
                break
        for w, (new, why) in zip(live, step(live)):
            w.tries += 1
            if why is None:
                target = w.control.target
                done = w.control.accepted(w)
                w.prev, w.prev_where, w.at, w.where = w.at, w.where, new, target
                if done:
                    w.reason = "reached"
                else:
                    if reach:
                        w.reach.append((new, target))
                    w.reason = stop(w) if stop is not None else None
            else:
                w.reason = w.control.rejected(w, why)
        live = [w for w in live if w.reason is None]
    return walks


def follow(at, where, control, step, *, stop=None, budget: int | None = None, reach: bool = True) -> Walk:
    """Walk one path from the pose `at` at its point `where` (see `follow_all`; `step` takes
    and answers for one walk).

    >>> def step(w):  # x = s, exactly, where s <= 2
    ...     return w.target, None if w.target <= 2 else "not converged"
    >>> w = follow(0.0, 0.0, Bisect(3.0, depth=2), step)
    >>> w.reason, w.where, [s for _, s in w.reach]
    ('not converged', 1.5, [1.5])
    """
    walk = Walk(at, where, control)
    return follow_all([walk], lambda live: [step(live[0])], stop=stop, budget=budget, reach=reach)[0]


def wandered(q0, pred, q1, scale) -> bool:
    """Whether the corrected pose q1 lies far from the prediction pred made from q0: by more
    than WANDER_SHARE of the predicted move, or WANDER_FLOOR, in unknowns over `scale`
    (angles as they are, lengths over the size): then Newton went elsewhere on the branch,
    or to another branch, and the step is cut.

    >>> q0, pred = np.zeros(2), np.array([0.1, 0.0])  # a predicted move of 0.1: 0.05 allowed
    >>> wandered(q0, pred, np.array([0.1, 0.04]), np.ones(2)), wandered(q0, pred, np.array([0.1, 0.06]), np.ones(2))
    (False, True)
    """
    moved = float(np.abs((pred - q0) / scale).max(initial=0.0))
    return float(np.abs((q1 - pred) / scale).max(initial=0.0)) > max(WANDER_FLOOR, WANDER_SHARE * moved)
