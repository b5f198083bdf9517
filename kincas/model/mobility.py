"""The structure of a mechanism's chain and the count of its freedoms (no casadi here).

The links are laid out as a spanning tree of revolute joints grown from the ground; each
shared point left over closes a loop (two equations) and each slide adds one. Unknowns minus
equations is the mobility that the inputs must match; where counting gives fewer freedoms
than inputs, a redundant joint may hide the missing ones and kincas/core/redundant.py decides.

>>> from kincas.model import Input, Link, Mechanism
>>> m = Mechanism(ground={"O": (0, 0)}, links=[Link.bar("crank", "O", "A", 1)],
...               inputs=[Input.angle("crank")])
>>> counted_freedoms(m), needs_rank_test(m)
(1, False)
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Iterable

if TYPE_CHECKING:
    from .mechanism import Mechanism
    from .parts import Link

GROUND = "ground"


# --- the structure of the chain: a spanning tree of revolute joints ---


@dataclass(frozen=True)
class Structure:
    """How the loop-closure equations are laid out (derived from names only).

    Links are placed from the ground outwards: a link that shares a point with what is
    already placed hangs on that point and needs only its angle as an unknown; a link with
    no such point floats (x, y, angle). Every other shared point closes a loop: two
    equations saying that the two bodies put the point at the same place. Each slide adds
    one equation (the point's distance from the line is zero).
    """

    order: tuple[tuple[str, str | None], ...]  # (link, point it hangs on, or None: floating)
    owner: tuple[tuple[str, str], ...]  # point -> body whose frame defines it
    closures: tuple[tuple[str, str], ...]  # (point, link): that link's copy must meet the owner's
    n_unknowns: int
    n_equations: int

    @property
    def mobility(self) -> int:
        return self.n_unknowns - self.n_equations


def _structure(ground: Iterable[str], links: tuple[Link, ...], n_slides: int) -> Structure:
    owner = {g: GROUND for g in ground}
    order, closures, remaining = [], [], list(links)
    n_unknowns = 0

    def place(link: Link, at: str | None):
        nonlocal n_unknowns
        order.append((link.name, at))
        n_unknowns += 1 if at is not None else 3
        for p in link.point_names:
            if p == at:
                continue
            if p in owner:
                closures.append((p, link.name))
            else:
                owner[p] = link.name
        remaining.remove(link)

    # Breadth-first from the ground keeps chains short, so each loop closes near its root.
    while remaining:
        ready = [(lk, next((p for p in lk.point_names if p in owner), None)) for lk in remaining]
        ready = [(lk, at) for lk, at in ready if at is not None]
        if not ready:
            place(remaining[0], None)
            continue
        for lk, _ in ready:
            at = next(p for p in lk.point_names if p in owner)
            place(lk, at)
    return Structure(tuple(order), tuple(owner.items()), tuple(closures),
                     n_unknowns, 2 * len(closures) + n_slides)


# --- counting the freedoms ---


def counted_freedoms(m: Mechanism) -> int:
    """Degrees of freedom by counting: unknowns minus equations, plus driven parameters."""
    return m.structure.mobility + sum(inp.kind == "parameter" for inp in m.inputs)


def solved_unknowns(m: Mechanism) -> int:
    """The unknowns the solver finds at each pose: the structure's coordinates less the link
    angles that inputs drive (a driven angle is given, not solved for); the size of q.

    >>> from kincas.model import Input, Link, Mechanism
    >>> m = Mechanism(ground={"O": (0, 0)}, links=[Link.bar("crank", "O", "A", 1)],
    ...               inputs=[Input.angle("crank")])
    >>> m.structure.n_unknowns, solved_unknowns(m)
    (1, 0)
    """
    spatial = getattr(m, "solved_unknowns", None)  # a spatial mechanism's own (its tree reduction)
    if spatial is not None:
        return spatial()
    links = {lk.name for lk in m.links}
    driven = {i.target for i in m.inputs if i.kind == "angle" and i.target in links}
    return m.structure.n_unknowns - len(driven)


def needs_rank_test(m: Mechanism) -> bool:
    """Whether counting gives fewer freedoms than inputs: a redundant joint may hide the
    missing ones, and only the constraint Jacobian's rank at an assembly can tell
    (kincas/core/redundant.py decides, at the first solve: a declaration runs no numerics)."""
    return counted_freedoms(m) < len(m.inputs)


def mobility_problem(m: Mechanism, free: int | None = None, tested: bool = False) -> str:
    """The message for a wrong number of inputs; `tested`: the rank test ran and found
    `free` freedoms (None: no assembly found from the guess to test)."""
    st, dof = m.structure, counted_freedoms(m)
    n_param = dof - st.mobility
    detail = (f"{st.n_unknowns} unknown coordinates, {st.n_equations} equations"
              + (f", plus {n_param} driven parameter(s)" if n_param else ""))
    hint = ""
    if tested:
        hint = ("; a redundant joint would add freedoms to this count, but "
                + ("no assembly was found from the guess to test for one" if free is None else
                   f"the constraint Jacobian at generic points of the assemblies found gives it "
                   f"{free + n_param} degree(s) of freedom"))
    return (f"[inputs]: the mechanism has {dof} degree(s) of freedom ({detail}) "
            f"but {len(m.inputs)} input(s) drive it; give one input per degree of freedom{hint}")


def _check_mobility(m: Mechanism) -> list[str]:
    """Problems with the number of inputs that counting alone proves (too few inputs)."""
    dof = counted_freedoms(m)
    if (dof == len(m.inputs) and m.structure.mobility >= 0) or needs_rank_test(m):
        return []
    return [mobility_problem(m)]
