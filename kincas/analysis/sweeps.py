"""Position solving (damped Newton, IPOPT fallback), sweeps with branch continuity.

A pose is solved when its loop-closure residual is below `ACCEPT` times the mechanism's
size (see kincas/numeric.py). A pose that cannot be solved is data (status and NaN), never an
exception. The guess picks the assembly branch; in a sweep each pose is predicted from the
one before along the exact tangent dq/du = -g_q^-1 g_u, so the branch is kept.

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
>>> r = kincas.sweep(m, {"crank.angle": np.linspace(0, 2 * np.pi, 7)}, report=["C.x", "C.y"])
>>> r.status[:2].tolist(), bool(r.residual.max() < 1e-12)
(['ok', 'ok'], True)
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import ModelError
from ..model.mechanism import Mechanism
from ..core.fast_run import FastRun
from ..core.numeric import Model, compile
from ..results import Pose, Sweep
from ..core.symbolic import needs_jerk
from ..model.names import default_report
from .choice import choose_assembly
from .resume import unlabelled_resumes
from .events import nothing_met, nothing_met_measures, nothing_met_summary, null_derivatives, sweep_events
from ..core.joints import check_first_pose
from .inputs import derivative_table, input_table as _input_table
from .prepared import model_and_prepared
from .methods import SweepMethod, method_of
from .problem import SweepProblem

_model_of = compile  # for sweep(), whose `compile` argument hides the name

NO_ASSEMBLY = "no assembly"
REPORTS_KEPT = 64  # lists of reported names remembered as checked, per mechanism
# (numpy's names every sweep calls, looked up once: `np.name` is a module look-up a call)
_count, _zeros, _empty = np.count_nonzero, np.zeros, np.empty


# --- sweeps ---


def sweep(m: Mechanism, inputs=None, *, rates=None, accelerations=None, report=None,
          guess=None, progress=None, method: str | SweepMethod = "fast", compile: bool | None = None,
          jerks=None) -> Sweep:
    """Solve the mechanism at every pose of `inputs` (input key -> array), keeping the branch.

    `rates`, `accelerations` and `jerks` give each input's first, second and third time
    derivative (default 1, 0 and 0). `report` lists the quantities wanted (default: points and link angles); only what
    they need is computed. `guess` overrides the mechanism's guessed points. `progress`, if
    given, is called as progress(done, total) while solving.

    `method` is how the poses are solved (kincas/analysis/methods.py): `kincas.Fast(compile)`
    (the default) runs a compiled pass over the poses and re-solves on the careful path
    (continuation with step cutting) every pose that it does not accept; `kincas.Careful()`
    uses the careful path for every pose; a subclass of `kincas.SweepMethod` is called as
    they are. The strings "fast" (with `compile`) and "careful" mean the same two. `compile`:
    None compiles the fast pass to C when a compiled library is cached or the sweep is long,
    compiles it in a background thread when a structure is swept again (500 poses in all) or
    its sweeps add up to 20,000 poses (the virtual machine serving until it is loaded), and leaves out the fast pass where it would
    not pay (a large mechanism, a short sweep); True compiles it (unless the kernel is too
    large for the compiler to be worth waiting for), False runs it in CasADi's virtual machine.

    One rule decides whether the fast pass runs compiled: unless `compile` is False, a compiled
    library of its kernel is used as soon as it exists (in the cache, or loaded by this
    process, whichever option built it); `Sweep.info["fast pass"]` says which ran: "compiled",
    "virtual machine", or None where every pose was solved on the careful path.

    Each solved pose gets a flag where it sits at or next to a singular position ("limit",
    "change point", "singular"); `Sweep.events` lists those positions with their input values
    located exactly, and where a sweep resumed after poses with no assembly, on which branch.
    Without any guess, where the default assembly loses poses that another assembly of the
    first pose keeps, the sweep runs on that one and an "assembly" event says which and why
    (kincas/analysis/choice.py); a guess is always obeyed.

    Parameters
    ----------
    m : Mechanism
    inputs : dict or array_like
        Input key -> values (radians for angles); an array for a one-input mechanism.
    rates, accelerations, jerks : dict, optional
        Input key -> the input's time derivatives (a number or one per pose).
    report : list of str, optional
        Quantity names (docs/scene-format.md).
    guess : dict, optional
        Point -> (x, y), overriding the mechanism's guess.
    progress : callable, optional
        progress(done, total).
    method : SweepMethod or {"fast", "careful"}
        kincas.Fast(compile=None) by default; "fast" is kincas.Fast(compile), "careful"
        kincas.Careful().
    compile : bool, optional
        With the string "fast" only (a method object carries its own).

    Returns
    -------
    Sweep
        Values per pose; poses not solved have a status saying why and NaN values.

    Examples
    --------
    At crank angle 0 and pi, B and C lie on the ground line: C.x = +-1 + (3.5^2 - 3^2 + r^2)
    / (2 r) with r = |BD| = 3 and 5.

    >>> import numpy as np, kincas
    >>> m = kincas.Mechanism(parameters={"a": 1.0}, ground={"A": (0, 0), "D": (4, 0)},
    ...     links=[kincas.Link.bar("crank", "A", "B", "a"), kincas.Link.bar("coupler", "B", "C", 3.5),
    ...            kincas.Link.bar("rocker", "D", "C", 3)],
    ...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
    >>> sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 2 * np.pi, 361)}, report=["C.x"])
    >>> sw.ok.all(), round(float(sw["C.x"][0]), 12), round(float(sw["C.x"][180]), 12)
    (np.True_, 3.041666666667, 1.825)
    """
    solver = method_of(method, compile)  # a wrong `method` fails before any work
    # the model and the parameter values, size, guess, input keys: once per mechanism
    model, pm = model_and_prepared(m, _model_of)
    report, names = _report(m, model, pm, report)  # unknown names fail here, before any solving
    U = _input_table(m, inputs, "inputs", None, pm.keys)
    n = U.shape[0]
    Ud = _per_pose(m, rates, "rates", 1.0, n, pm.keys)
    Udd = _per_pose(m, accelerations, "accelerations", 0.0, n, pm.keys)
    Uddd = None if jerks is None else derivative_table(m, jerks, "jerks", 0.0, n, pm.keys)
    p, L = pm.p, pm.size
    g = pm.with_guess(guess)
    events = []
    # The fast pass (compiled, checked pose by pose) solves what it can; every pose it does
    # not accept goes to the careful path (`SweepProblem.careful`), and the fast pass restarts
    # after it. (a tall system, with redundant joints, has no compiled pass: its g_q is not
    # square) Which pass solves which pose is the method's choice (kincas/analysis/methods.py).
    run = solver.sweep(SweepProblem(model, pm, names, report, U, Ud, Udd, p, L, m, g, events, progress))
    ok, Q = run.solved, run.Q
    every = _count(ok) == n  # (a ufunc's reduction costs twice as much)
    if m.gears and ok.any():  # gear centre distances at the first solved pose
        check_first_pose(model, Q[ok.argmax()], U[ok.argmax()], p, L)
    # status None: every pose "ok" (the Sweep makes the array when first read)
    status = None if every else np.array(["ok" if s else NO_ASSEMBLY for s in ok], dtype=object)
    flags = None  # None: no pose flagged (the Sweep makes the list when first read)
    if not every:  # after gaps the fast pass crossed (none where every pose is solved)
        events += unlabelled_resumes(model, U, p, L, Q, ok, events)
    crossed = getattr(run, "crossed", ())
    if every and not len(crossed) and _nothing_met(run, ok):
        at = None  # the usual sweep: no singular position met, no gap (nothing to search)
    else:
        flags = [None] * n
        found, at = _singular_events(model, m, U, Q, ok, p, L, flags, run.signs, run.sigma, crossed)
        events += found
    values = run.values
    if Uddd is not None:  # the inputs' jerks enter only the third derivatives
        values = _with_jerks(model, report, values, Q, U, p, Ud, Udd, Uddd, ok)
    if at is not None and at.any():  # no wrong number at a singular pose
        null_derivatives(model, report, values, Q, U, p, at)
    keys = pm.keys
    if events:
        _sort_events(events, U, keys)
    if len(keys) == 1:  # (one input: no view of the caller's array, no comprehension)
        k0 = keys[0]
        ins, rts, accs = {k0: U.ravel().copy()}, {k0: Ud[:, 0]}, {k0: Udd[:, 0]}
    else:
        ins, rts, accs = _columns(keys, U, Ud, Udd)
    its = run.info[4] if getattr(run, "attempted", False) else run.iterations  # (whole numbers:
    # the Sweep makes them integers when first read)
    out = Sweep._built(n, status, flags, its, {
        "inputs": ins, "rates": rts, "accelerations": accs,
        "values": dict(zip(report, values)),  # (each row a view, as indexing gives it)
        "q": Q, "residual": run.residual, "unknowns": model.unknown_names, "size": L,
        "events": events, "info": {"fast pass": getattr(run, "backend", None)}})
    if g or every:
        return out  # the guess picks the assembly, whatever poses its branch loses
    # no guess: where the default assembly loses poses, one of the first pose's others that
    # runs them all (kincas/analysis/choice.py), said in an "assembly" event
    rerun = _rerun(m, inputs, rates, accelerations, report, progress, method, compile, jerks)
    return choose_assembly(model, m, U, p, L, out, rerun) or out


# (the helpers below hold what `sweep` does on its rarer roads: a comprehension or a closure
# in `sweep` itself would make a cell of each name it reads, at every call)


def _with_jerks(model, report, values, Q, U, p, Ud, Udd, Uddd, ok):
    """The reported values with the third derivatives that the inputs' jerks enter."""
    third = [i for i, nm in enumerate(report) if needs_jerk(nm)]
    if third and ok.any():
        got = model.third_derivatives([report[i] for i in third], Q[ok], U[ok], p, Ud[ok], Udd[ok], Uddd[ok])
        values = np.array(values, dtype=float)
        values[np.ix_(third, np.flatnonzero(ok))] = got
    return values


def _nothing_met(run, ok) -> bool:
    """Whether a sweep with every pose solved met no singular position (`nothing_met`): from
    the compiled loop's summary where its last call ended the sweep, else from the fast
    kernel's table of measures, else (the careful path alone) from the signs and sigmas."""
    if type(run) is FastRun:
        summary = run.summary()
        return nothing_met_summary(summary) if summary is not None else nothing_met_measures(run.measures_by_pose()[0])
    return nothing_met(ok, run.signs, run.sigma, True)


def _sort_events(events, U, keys) -> None:
    """Events in the order of their poses, each with its inputs' values."""
    events.sort(key=lambda e: e["pose"])
    for e in events:
        e.setdefault("inputs", {kk: float(U[e["pose"], j]) for j, kk in enumerate(keys)})


def _columns(keys, U, Ud, Udd) -> tuple:
    """Per input key: its values (a copy), rates and accelerations (tables of this call's own)."""
    ins = {k: U[:, j].copy() for j, k in enumerate(keys)}
    rts = {k: Ud[:, j] for j, k in enumerate(keys)}
    accs = {k: Udd[:, j] for j, k in enumerate(keys)}
    return ins, rts, accs


def _rerun(m, inputs, rates, accelerations, report, progress, method, compile, jerks):
    """The same sweep from another guess (`choose_assembly`). (Made here, not in `sweep`: a
    closure there would make cells of its arguments at every call.)"""
    return lambda guess: sweep(m, inputs, rates=rates, accelerations=accelerations, report=report,
                               guess=guess, progress=progress, method=method, compile=compile, jerks=jerks)


def _per_pose(m, values, what: str, default: float, n: int, keys) -> np.ndarray:
    """The (n, nu) table of the inputs' rates or accelerations (`derivative_table`), a new array
    (`np.broadcast_to` costs more than filling a few thousand numbers, and a short sweep
    pays every microsecond): the usual cases, none given or one number for the one input,
    without building a table first."""
    if values is None:
        return _zeros((n, len(keys))) if default == 0.0 else np.full((n, len(keys)), default)
    if len(keys) == 1 and type(values) is dict and len(values) == 1:
        v = values.get(keys[0])
        if type(v) is float and math.isfinite(v) or type(v) is int:
            out = _empty((n, 1))  # (np.full checks its arguments: twice the time)
            out.fill(v)
            return out
    return np.array(derivative_table(m, values, what, default, n, keys), dtype=float)  # (a copy:
    # the user's array stays theirs)


def solve(m: Mechanism, inputs=None, *, rates=None, accelerations=None, report=None,
          guess=None, jerks=None) -> Pose:
    """Solve one pose (inputs: key -> value, or a value for a one-input mechanism).

    Parameters
    ----------
    m : Mechanism
    inputs : dict or float
        Input key -> value (radians for angles); a number for a one-input mechanism.
    rates, accelerations, jerks : dict, optional
        Input key -> the input's time derivatives.
    report : list of str, optional
        Quantity names (docs/scene-format.md).
    guess : dict, optional
        Point -> (x, y), overriding the mechanism's guess.

    Returns
    -------
    Pose
        Its status is "ok" or why it was not solved (its values then NaN).

    Examples
    --------
    At crank angle pi/2, B = (0, 1), and C is where the circles of radius 3.5 about B and 3
    about D meet:

    >>> import numpy as np, kincas
    >>> m = kincas.Mechanism(parameters={"a": 1.0}, ground={"A": (0, 0), "D": (4, 0)},
    ...     links=[kincas.Link.bar("crank", "A", "B", "a"), kincas.Link.bar("coupler", "B", "C", 3.5),
    ...            kincas.Link.bar("rocker", "D", "C", 3)],
    ...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
    >>> pose = kincas.solve(m, {"crank.angle": np.pi / 2}, report=["C.x", "C.y"])
    >>> pose.status, bool(abs(np.hypot(pose["C.x"], pose["C.y"] - 1) - 3.5) < 1e-12)
    ('ok', True)
    >>> kincas.solve(m, {"crank.angle": 0.0}, report=["C.x"]).status  # a 3 m rocker is fine
    'ok'
    """
    for what, values in (("inputs", inputs), ("rates", rates), ("accelerations", accelerations),
                         ("jerks", jerks)):
        if values is not None and _input_table(m, values, what, 0.0).shape[0] > 1:
            raise ModelError(f"{what}: solve() solves one pose, so give one value per input "
                             f"(kincas.sweep solves several)")
    return sweep(m, inputs, rates=rates, accelerations=accelerations, report=report,
                 guess=guess, jerks=jerks).pose(0)


def _report(m, model, pm, report) -> tuple[list, tuple]:
    """(list, tuple) of the quantity names to report (`report_names`), checked against the
    model (`Prepared.check_report`): a list of names or the default once per mechanism, a
    look-up afterwards."""
    key = report if report is None or type(report) is str else tuple(report) if type(report) in (list, tuple) else ()
    try:
        names = pm.reports.get(key) if key != () else None
    except TypeError:  # something unhashable in the list: not a name (report_names says so)
        key, names = (), None
    if names is None:
        names = tuple(report_names(m, report))
        pm.check_report(model, names)
        if key != ():
            if len(pm.reports) >= REPORTS_KEPT:  # (a loop over many lists: kept bounded)
                pm.reports.clear()
            pm.reports[key] = names
    return list(names), names


def report_names(m: Mechanism, report) -> list[str]:
    """The quantities to report: the default's when None, one name given alone as a list;
    ModelError naming `report` for anything that is not a name."""
    if report is None:
        return list(default_report(m))
    report = [report] if isinstance(report, str) else report
    try:
        report = list(report)
    except TypeError:
        raise ModelError(f"report: expected a list of quantity names, got {report!r:.80}") from None
    bad = [r for r in report if not isinstance(r, str)]
    if bad:
        raise ModelError([f"report: expected a quantity's name, got {r!r:.80}" for r in bad])
    return report


# --- singular positions met by a sweep ---


def _singular_events(model: Model, m: Mechanism, U, Q, ok, p, L, flags, signs, sigma, crossed=()):
    """Flag solved poses at or next to a singular position and locate it exactly, one event
    per Assur group (kincas/analysis/events.py). Returns (events, at: the poses exactly at a
    singular position, which it moved onto it).

    `signs` (N, groups) and `sigma` (N) come with the solve (the fast kernel computes them at
    every pose, kincas/core/blocks.py): sigma is a lower bound of the smallest singular value
    of a group's scaled block, so only the few poses where it is small, and the ends of a
    change of a group's sign, get exact per-group measures.
    """
    return sweep_events(model, m, U, Q, ok, p, L, flags, signs, sigma, crossed)
