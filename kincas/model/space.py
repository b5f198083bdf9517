"""Declarations of a spatial mechanism as an immutable value (no casadi here).

A spatial mechanism is ground points, bodies drawn in one assembled pose (global
coordinates), two-point bars, joints (a point shared by two bodies is a ball joint unless a
`Joint` there says otherwise), slides on lines and planes, and inputs: joint coordinates
(`Input.joint("A")`), slides and parameters. Angles are radians in Python. kincas.core builds
its equations (kincas/core/space_symbolic.py); docs/spatial.md says how and why.

>>> m = SpatialMechanism(
...     ground={"A": (0, 0, 0), "D": (120, 40, 30)},
...     bodies=[Body("crank", {"A": (0, 0, 0), "B": (25, 0, 0)}), Body.bar("coupler", "B", "C", 130),
...             Body("rocker", {"D": (120, 40, 30), "C": (120, 40, 90)})],
...     joints=[Joint("revolute", "A", axis=(0, 0, 1)), Joint("revolute", "D", axis=(1, 0, 0))],
...     inputs=[Input.joint("A")])
>>> m.inputs[0].key, m.mobility, m.moving_points
('A.angle', 1, ('B', 'C'))
"""
from __future__ import annotations

from dataclasses import dataclass, field

from ..errors import ModelError
from .mobility import GROUND, Structure
from .parts import Input, is_number
from .space_checks import SpatialChecks
from .space_lookups import SpatialLookups
from .space_parts import ON_SECOND, Body, Joint, SpatialSlide, _triple  # noqa: F401
from .values import _table

SPACE = "3d"


@dataclass(frozen=True)
class SpatialMechanism(SpatialChecks, SpatialLookups):
    """A spatial mechanism (`space = "3d"`): an immutable value, checked on construction.

    Every problem found is gathered into one `ModelError`. The drawing pose is the default
    guess: `guess` moves points away from it (and places points that only bars carry).

    Parameters
    ----------
    parameters : dict
        Named numbers that coordinates and lengths may refer to by name.
    ground : dict
        Ground points: name -> (x, y, z).
    bodies : sequence of Body
        Rigid bodies (`Body(name, points)`) and two-point bars (`Body.bar`).
    joints : sequence of Joint
    slides : sequence of SpatialSlide
    inputs : sequence of Input
        `Input.joint("J")` / `Input.joint("J.angle1")`, `Input.slide`, `Input.parameter`.
    guess : dict
        Point -> (x, y, z): where points are near at the first pose.

    Examples
    --------
    >>> m = SpatialMechanism(ground={"O": (0, 0, 0)},
    ...     bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
    ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
    >>> m.size(), m.with_parameters().guess
    (1.0, (('P', (1, 0, 0)),))
    """

    parameters: tuple = ()
    ground: tuple = ()
    bodies: tuple = ()
    joints: tuple = ()
    slides: tuple = ()
    inputs: tuple = ()
    guess: tuple = ()
    gravity: tuple = (0.0, 0.0, 0.0)
    loads: tuple = ()
    structure: Structure = field(init=False, repr=False, compare=False)

    space = SPACE
    gears = racks = cams = ()  # planar joints: none in space

    def __post_init__(self):
        put = lambda k, v: object.__setattr__(self, k, v)
        params = []
        for k, v in _table(self.parameters, "parameters", "number"):
            if not is_number(v):
                raise ModelError(f"[parameters] {k}: expected a number, got {v!r}")
            params.append((k, float(v)))
        put("parameters", tuple(params))
        put("ground", tuple((k, _triple(v, f"[ground] {k}")) for k, v in _table(self.ground, "ground", "(x, y, z)")))
        for f, kind in (("bodies", Body), ("joints", Joint), ("slides", SpatialSlide), ("inputs", Input)):
            items = tuple(getattr(self, f))
            bad = [f"{f}[{i}]: expected a kincas.{kind.__name__}, got {x!r:.60}"
                   for i, x in enumerate(items) if not isinstance(x, kind)]
            if bad:
                raise ModelError(bad)
            put(f, items)
        put("gravity", _triple(self.gravity, "gravity"))
        put("loads", tuple(self._load(k, ld) for k, ld in enumerate(self.loads)))
        given = tuple((k, _triple(v, f"[guess] {k}")) for k, v in _table(self.guess, "guess", "(x, y, z)"))
        problems = self._check(given)
        if problems:
            raise ModelError(problems)
        put("inputs", tuple(self._resolve(i) for i in self.inputs))
        # the drawing pose is the default guess; [guess] moves points away from it
        drawn = dict(self._drawn())
        put("guess", tuple({**drawn, **dict(given)}.items()))
        nq, ng = self.counts()
        put("structure", Structure((), (), (), nq, ng))
        from .mobility import _check_mobility
        problems = _check_mobility(self)
        if problems:
            raise ModelError(problems)

    def joint_bodies(self, j: Joint) -> tuple[str, str]:
        """(first, second) body of a joint: its `bodies`, else the two bodies (the ground
        counting as one; never a bar) that carry its point, the ground first, else in
        declaration order; for a joint whose point belongs to its second body only
        (cylindrical, prismatic, planar), a point on one body alone pairs it with the ground.

        Parameters
        ----------
        j : Joint

        Returns
        -------
        (str, str)

        Examples
        --------
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
        >>> m.joint_bodies(m.joint("O"))
        ('ground', 'arm')
        """
        where = f"[[joints]] {j.name}"
        names = {b.name for b in self.bodies} | {GROUND}
        if j.bodies is not None:
            bad = [b for b in j.bodies if b not in names]
            if bad:
                raise ModelError(f"{where}: bodies: unknown body {bad[0]!r}")
            return j.bodies
        on = ([GROUND] if j.point in dict(self.ground) else []) + [
            b.name for b in self.bodies if not b.two_point and j.point in b.point_names]
        if len(on) == 1 and j.type in ON_SECOND and on[0] != GROUND:
            return GROUND, on[0]
        if len(on) != 2:
            raise ModelError(f"{where}: bodies: {len(on)} bodies carry point {j.point!r} "
                             f"({', '.join(on) or 'none'}); name the two: bodies = [\"first\", \"second\"]")
        return on[0], on[1]

    def _resolve(self, i: Input) -> Input:
        """A joint input keyed by its coordinate: "A" -> "A.angle" (a one-coordinate joint)."""
        if i.kind != "joint":
            return i
        jname, _, coord = i.target.partition(".")
        joints = {j.name: j for j in self.joints}
        where = f"[[inputs]] {i.target}"
        if jname not in joints:
            raise ModelError(f"{where}: joint: unknown joint {jname!r} (joints are named by "
                             f"`name`, default their point)")
        coords = joints[jname].coordinates
        if not coord:
            if len(coords) != 1:
                raise ModelError(f"{where}: joint: a {joints[jname].type} joint has coordinates "
                                 f"{list(coords)}: name one, e.g. \"{jname}.{(coords or ('angle',))[0]}\"")
            coord = coords[0]
        if coord not in coords:
            raise ModelError(f"{where}: joint: a {joints[jname].type} joint has no coordinate "
                             f"{coord!r} (it has {list(coords)})")
        return Input("joint", f"{jname}.{coord}")

    # --- counts ---
    def counts(self) -> tuple[int, int]:
        """(unknowns, equations without the inputs'): 7 per body (its reference point and
        unit quaternion), 3 per point only bars carry; 1 per body (the quaternion's norm),
        3 per extra carrier of a point, 1 per bar, and each joint's and slide's own.

        Examples
        --------
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
        >>> m.counts()  # 7 unknowns; the norm, the point, the axis: 6 equations
        (7, 6)
        """
        rigid = [b for b in self.bodies if not b.two_point]
        on_body = {p for b in rigid for p in b.point_names} | set(dict(self.ground))
        free_pts = {p for b in self.bodies for p in b.point_names} - on_body
        nq = 7 * len(rigid) + 3 * len(free_pts)
        ng = len(rigid) + sum(b.two_point for b in self.bodies)
        exempt = self.exempt()
        for p in on_body:
            carriers = ([GROUND] if p in dict(self.ground) and (p, GROUND) not in exempt else []) + [
                b.name for b in rigid if p in b.point_names and (p, b.name) not in exempt]
            ng += 3 * max(len(carriers) - 1, 0)
        extra = {"spherical": 0, "revolute": 2, "universal": 1, "cylindrical": 4,
                 "prismatic": 5, "planar": 3}
        ng += sum(extra[j.type] for j in self.joints)
        ng += sum(2 if s.on_line else 1 for s in self.slides)
        return nq, ng

    def exempt(self) -> set:
        """(point, body): a first body's copy of a point that belongs to the second body of
        its cylindrical, prismatic or planar joint (the joint's own equations hold it).

        Examples
        --------
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
        >>> m.exempt()
        set()
        """
        out = set()
        for j in self.joints:
            if j.type in ON_SECOND:
                try:
                    out.add((j.point, self.joint_bodies(j)[0]))
                except ModelError:
                    pass
        return out
