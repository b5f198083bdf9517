"""The spatial model's tree reduction (docs/spatial.md, "Formulation"): which rigid body hangs
on which revolute (cylindrical, prismatic) joint of an already placed body, so that it takes
that joint's coordinates as its unknowns (angle; angle and s; s), or none where inputs drive
them, instead of a reference point and a quaternion.

Order, deterministic: the ground is placed; then, repeated until nothing changes, each rigid
body not yet placed (in declaration order) that shares a revolute, cylindrical or prismatic
joint with a placed body hangs on it and is placed; among several such joints, one driven by an input first, else the
first declared. Where nothing more hangs, the first body left (declaration order) that
shares a point with a placed body (a ball: a spherical or universal joint, or a point merely
shared) hangs on that point: its rotation stays unknown (quaternion and norm), its reference
point is where the placed body carries the point (3 unknowns and 3 equations fewer); else the
first body left floats (its 7 unknowns); either is placed and the hanging resumes from it. A body's other joints to
placed bodies stay equations: they close the loops. Bars carry no axis joint: never placed.

The hanging joint's angle keeps its convention, the rotation of its second body relative to
its first about the axis a (in the first body's axes, equal to global ones at the drawing pose
where every orientation is the identity): with h = (cos(theta/2), sin(theta/2) a), the second
body's quaternion is e1 (x) h when the first is the parent, e2 (x) conj(h) gives the first's
when the second is. A slide s along the axis moves the joint's point along the first body's
line (the point drawn on the second body): X = X1 + s R1 a.

An arm on a driven ground revolute, a link on the arm whose joint names the link first (its
parent is the joint's second body) and a second input:

>>> from kincas import SpatialMechanism, Body, Joint, Input
>>> m = SpatialMechanism(ground={"O": (0, 0, 0)},
...     bodies=[Body("arm", {"O": (0, 0, 0), "K": (1, 0, 0)}), Body("link", {"K": (1, 0, 0), "P": (2, 0, 0)})],
...     joints=[Joint("revolute", "O", axis=(0, 0, 1)), Joint("revolute", "K", axis=(0, 1, 0), bodies=("link", "arm"))],
...     inputs=[Input.joint("O"), Input.joint("K")])
>>> [(b, h.joint, h.parent, h.parent_first, h.driven) for b, h in placement(m)]
[('arm', 'O', 'ground', True, 0), ('link', 'K', 'arm', False, 1)]
"""
from __future__ import annotations

from dataclasses import dataclass

from .mobility import GROUND

HANGING = ("revolute", "cylindrical", "prismatic")  # the joints a body hangs on


@dataclass(frozen=True)
class Hang:
    """How a body hangs: on `joint` (of `type`) of the placed body `parent` (the joint's
    first body when `parent_first`), its angle the input numbered `driven` and its slide `s`
    the input numbered `driven_s` (None: an unknown; a revolute has no s, a prismatic joint
    no angle)."""

    joint: str
    parent: str
    parent_first: bool
    point: str
    driven: int | None
    type: str = "revolute"  # or "cylindrical", "prismatic", "ball" (no joint: `joint` is "")
    driven_s: int | None = None


def placement(m) -> list[tuple[str, Hang | None]]:
    """Every rigid body in the order the model places it, with how it hangs (None: it
    floats, with its reference point and quaternion as unknowns). Module text."""
    rigid = [b.name for b in m.bodies if not b.two_point]
    driven = {i.target: k for k, i in enumerate(m.inputs) if i.kind == "joint"}
    links = []  # (joint, first body, second body) of every joint a body may hang on
    for j in m.joints:
        if j.type in HANGING:
            b1, b2 = m.joint_bodies(j)
            # a revolute's point on both bodies, a slide's on its second (one whose point a body
            # lacks holds by its axis only: its equations stay)
            if _carries(m, b2, j.point) and (j.type != "revolute" or _carries(m, b1, j.point)):
                links.append((j, b1, b2))
    placed, out = {GROUND}, []
    while len(out) < len(rigid):
        changed = True
        while changed:
            changed = False
            for b in rigid:
                if b in placed:
                    continue
                cands = [(j, b1 if b == b2 else b2, b == b2) for j, b1, b2 in links
                         if b in (b1, b2) and b1 != b2 and (b1 if b == b2 else b2) in placed]
                if not cands:
                    continue
                j, parent, first = min(cands, key=lambda c: not any(  # stable: driven first
                    f"{c[0].name}.{k}" in driven for k in ("angle", "s")))
                out.append((b, Hang(j.name, parent, first, j.point, driven.get(f"{j.name}.angle"), j.type,
                                    driven.get(f"{j.name}.s"))))
                placed.add(b)
                changed = True
        rest = [b for b in rigid if b not in placed]
        ball = next(((b, hit) for b in rest for hit in [_ball(m, b, [GROUND] + [o for o, _ in out])] if hit), None)
        if ball is not None:  # a ball on a placed point: its rotation only, the point where placed
            (b, (parent, point)) = ball
            out.append((b, Hang("", parent, True, point, None, "ball")))
            placed.add(b)
        elif rest:
            out.append((rest[0], None))
            placed.add(rest[0])
    return out


def _carries(m, body, point) -> bool:
    """Whether `body` (or the ground) has `point` among its drawn points."""
    return any(g == point for g, _ in m.ground) if body == GROUND else point in m.link(body).point_names


def _ball(m, b, placed):
    """(parent, point): the first point of body b (in its declaration order) that a placed
    body carries (the ground first, then in placing order), neither copy exempt; None."""
    exempt = m.exempt()
    for p in m.link(b).point_names:
        if (p, b) in exempt:
            continue
        for o in placed:
            if _carries(m, o, p) and (p, o) not in exempt:
                return o, p
    return None


def solved_unknowns(m) -> int:
    """The size of the spatial model's q, from the declarations (no model built): 7 per
    floating body, 4 per body on a ball (its quaternion), a hung body's joint coordinates that no
    input drives, 3 per point only bars carry.

    >>> from kincas import SpatialMechanism, Body, Joint, Input
    >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (2, 0, 0)})],
    ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
    >>> solved_unknowns(m)
    0
    """
    n = 0
    for _, hang in placement(m):
        if hang is None or hang.type == "ball":
            n += 7 if hang is None else 4
            continue
        n += (hang.type != "prismatic" and hang.driven is None) + (hang.type != "revolute" and hang.driven_s is None)
    exempt = m.exempt()
    carried = {p for b in m.bodies if not b.two_point for p in b.point_names}
    carried |= {g for g, _ in m.ground if (g, GROUND) not in exempt}
    return n + 3 * sum(p not in carried for p in m.moving_points)

