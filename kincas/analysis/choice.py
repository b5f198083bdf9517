"""A sweep without a guess: among the first pose's assemblies, one that runs the whole sweep.

With no `[guess]`, the first pose is assembled in the default modes (kincas/core/assembly.py).
That assembly may lose poses another one keeps: the Whitworth quick return's lever pointing
away from its fixed pin lifts D out of the rod's reach for 11 of 73 poses, while with the
lever towards the pin every pose assembles. So where the default fails poses, and each of
them has some assembly (asked of `first_pose` without a guess: for dyads and small groups at
every lost pose, which group by group assembly decides without doubt; for larger groups, whose
search may end in IPOPT, at the first and the middle pose of each gap), the first pose's other
assemblies are found (`find_modes`) and swept from their points, fewest groups changed first,
until one solves every pose. That one is returned with an `"assembly"` event naming it (its points, ready as a
`[guess]`; the groups whose mode differs from the default) and why; where none does, the
default stands. A user's guess is never overridden: this runs only without one.

Which assemblies: where the exact solver is installed (`kincas[certify]`) and the closure is
polynomial, the first pose's assemblies are certified (kincas/analysis/certify.py: every
real one, proven) and every one of them is swept; the event says `"certified": true` and
`"count"`, and where none runs every pose (each sweep checked to have started on its own
assembly) it says so with certainty, the default standing. Otherwise (no solver, gears or
cams, an overconstrained spatial scene the exact system cannot take, msolve out of time)
the multistart search with CHOICE_STARTS starts, of which CHOICE_TRIES are swept:
`"certified": false`, and nothing claimed where none runs.

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(ground={"O": (0, 0), "A": (0, -20)},
...     links=[kincas.Link.bar("crank", "O", "B", 40), kincas.Link.bar("lever", "B", "D", 100),
...            kincas.Link.bar("rod", "D", "E", 150)],
...     slides=[kincas.Slide("A", "lever", name="slot"),
...             kincas.Slide("E", "ground", through=(0, -20), name="ram")],
...     inputs=[kincas.Input.angle("crank")])
>>> sw = kincas.sweep(m, {"crank.angle": np.radians(np.arange(0, 361, 5))}, report=["E.x"])
>>> bool(sw.ok.all()), [e["kind"] for e in sw.events if e["kind"] == "assembly"]
(True, ['assembly'])
"""
from __future__ import annotations

import numpy as np

from ..core.assembly import ambiguous, first_pose, group_links, modes
from ..core.tolerances import (CHOICE_CERTIFY_TIMEOUT, CHOICE_STARTS, CHOICE_TRIES,
                               CHOICE_TRIES_CERTIFIED, SAME_ASSEMBLY)
from ..errors import KincasError, ModelError
from .assembly_mode import signature


def _unreachable(model, U, p, L, ok) -> bool:
    """Whether some pose the default lost has no assembly in any mode. For dyads and small
    groups every lost pose is asked (group by group assembly decides it, cheaply); where a
    larger group makes that a search (with IPOPT), the first and the middle pose of each gap."""
    bad = np.flatnonzero(~ok)
    if ambiguous(model):
        gaps = np.split(bad, np.flatnonzero(np.diff(bad) > 1) + 1)
        bad = sorted({int(g[0]) for g in gaps} | {int(g[len(g) // 2]) for g in gaps})
    return any(not first_pose(model, U[k], p, L, {}).ok for k in bad)


def _assemblies(m, inputs):
    """(the first pose's assemblies, whether certified): the certified list where msolve is
    installed and the closure is polynomial, else the multistart's (None where it cannot be
    posed: the search is a courtesy, the default then stands)."""
    from . import certify_msolve
    if certify_msolve.available():
        from .certify import certify_modes
        try:
            found = certify_modes(m, inputs, timeout=CHOICE_CERTIFY_TIMEOUT)
            if len(found) and not found.positive_dimension and not found.rejected:
                return found, True  # (the default's first pose assembles: none found is a fault)
        except KincasError:  # not polynomial, refused, msolve out of time: the multistart
            pass
    from .modes import find_modes
    try:
        return find_modes(m, inputs, starts=CHOICE_STARTS), False
    except ModelError:
        return None, False


def choose_assembly(model, m, U, p, L, default, rerun):
    """`default` (a Sweep from the default modes, no guess) or, where it fails poses, the
    sweep `rerun(guess)` from the first of the first pose's other assemblies that solves
    every pose, with an "assembly" event; the default with an "assembly" event saying so
    where the assemblies are certified and none does; None to keep the default as it is."""
    ok, n = np.asarray(default.ok), len(default)
    if ok.all() or not ok[0] or model.nq == 0:
        return None
    if _unreachable(model, U, p, L, ok):
        return None  # some pose has no assembly at all: none runs the whole sweep
    u0 = U[0]
    inputs = {i.key: float(v) for i, v in zip(m.inputs, u0)}
    found, certified = _assemblies(m, inputs)
    if found is None:
        return None
    sign0 = modes(model, model.jac(default.q[0], u0, p), L)[0]
    sig0 = signature(model, default.q[0], u0, p, L)[0]
    names = group_links(model)
    others = []
    for k, md in enumerate(found):
        if np.abs(signature(model, md.q, u0, p, L)[0] - sig0).max() <= SAME_ASSEMBLY * L:
            continue  # the default itself
        changed = np.flatnonzero(modes(model, model.jac(md.q, u0, p), L)[0] != sign0)
        others.append((len(changed), k, md, changed))
    others.sort(key=lambda t: t[:2])
    tries = CHOICE_TRIES_CERTIFIED if certified else CHOICE_TRIES
    lost = int((~ok).sum())
    said = {"pose": 0, "poses": n, "certified": certified, "count": len(found), "inputs": inputs}
    proven = certified and len(others) <= tries  # every other assembly swept...
    for _, _, md, changed in others[:tries]:
        sw = rerun(md.guess)
        # ... from itself (a guess of points may not pick a spatial body's spin about them)
        proven = proven and np.abs(signature(model, sw.q[0], u0, p, L)[0]
                                   - signature(model, md.q, u0, p, L)[0]).max() <= SAME_ASSEMBLY * L
        if np.asarray(sw.ok).all():
            groups = [names[i] for i in changed]
            which = (", ".join("[" + ", ".join(g) + "]" for g in groups) + " in the other mode"
                     if groups else "another assembly of the same modes")
            among = (f"of the first pose's {len(found)} assemblies (certified: every real one), "
                     if certified else "")
            reason = (f"no [guess], and the default assembly fails {lost} of {n} poses; "
                      f"{among}this one (group {which}) solves all {n}; to keep it, give its points as [guess]")
            sw.events.insert(0, {"kind": "assembly", **said, "groups": groups,
                                 "guess": dict(md.guess), "reason": reason})
            return sw
    if not proven:
        return None
    # certified: none of the first pose's assemblies runs every pose; the default stands
    reason = (f"no [guess], and the default assembly fails {lost} of {n} poses; none of the first "
              f"pose's {len(found)} assemblies (certified: every real one) solves all {n}: the default stands")
    guess = {nm: tuple(float(c) for c in xy) for nm, xy in
             zip(m.moving_points, model.points(default.q[0], u0, p).T)}
    default.events.insert(0, {"kind": "assembly", **said, "groups": [], "guess": guess, "reason": reason})
    return default
