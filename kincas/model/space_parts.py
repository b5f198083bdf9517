"""The parts of a spatial mechanism as immutable plain data (no casadi here): rigid bodies
drawn in one global frame, two-point bars, joints with axes and slides on lines and planes
(`kincas.SpatialMechanism`, kincas/model/space.py, puts them together).

A spatial scene is drawn in one assembled pose, as in a CAD assembly (docs/spatial.md):
every coordinate is global at that pose, so a body's orientation there is the identity and
a joint's axis is written once, in global axes.

>>> Body("crank", {"A": (0, 0, 0), "B": (25, 0, 0)}).point_names
('A', 'B')
>>> Joint("revolute", "A", axis=(0, 0, 1)).coordinates
('angle',)
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import ModelError
from .parts import Num, as_number
from .values import _table, is_number

JOINT_TYPES = ("spherical", "revolute", "universal", "cylindrical", "prismatic", "planar")
# a joint's coordinates, in the order of the contract's table
COORDINATES = {"spherical": (), "revolute": ("angle",), "universal": ("angle1", "angle2"),
               "cylindrical": ("angle", "s"), "prismatic": ("s",), "planar": ("s1", "s2", "angle")}
AXIS_JOINTS = ("revolute", "cylindrical", "prismatic", "planar")  # one `axis`
ON_SECOND = ("cylindrical", "prismatic", "planar")  # the point belongs to the second body only


def _triple(v, where: str) -> tuple[Num, Num, Num]:
    """(x, y, z) from three numbers or parameter names; ModelError naming `where` otherwise."""
    try:
        if isinstance(v, (str, bytes, dict)):
            raise TypeError
        items = tuple(v)
    except TypeError:
        items = None
    if items is None or len(items) != 3:
        raise ModelError(f"{where}: expected a triple (x, y, z), got {v!r}")
    return tuple(as_number(c) for c in items)


def _tensor(v, where: str) -> tuple:
    """An inertia tensor as 9 entries, row by row: a number (the same about every axis),
    three (principal, along the drawing axes) or a 3 x 3 list."""
    if isinstance(v, (int, float, str)) or is_number(v):
        return (v, 0.0, 0.0, 0.0, v, 0.0, 0.0, 0.0, v)
    rows = tuple(v)
    if len(rows) == 3 and all(isinstance(r, (int, float, str)) or is_number(r) for r in rows):
        a, b, c = rows
        return (a, 0.0, 0.0, 0.0, b, 0.0, 0.0, 0.0, c)
    if len(rows) == 3 and all(len(tuple(r)) == 3 for r in rows):
        return tuple(as_number(x) for r in rows for x in r)
    raise ModelError(f"{where}: expected a number, [Ixx, Iyy, Izz] or a 3 x 3 list, got {v!r}")


def _direction(v, where: str) -> tuple[float, float, float]:
    """A non-zero direction of three plain numbers (axes are not parameters in this version)."""
    d = _triple(v, where)
    if not all(is_number(c) and math.isfinite(c) for c in d):
        raise ModelError(f"{where}: expected three finite numbers, got {v!r}")
    n = math.sqrt(sum(float(c) ** 2 for c in d))
    if n == 0:
        raise ModelError(f"{where}: the direction (0, 0, 0) has no direction")
    return tuple(float(c) / n for c in d)


@dataclass(frozen=True)
class Body:
    """A rigid body carrying named points, written in global coordinates as drawn.

    `Body(name, {"A": (x, y, z), ...})` is the local form (a rigid body whose orientation at
    the drawing pose is the identity); `Body.bar(name, P, Q, length)` the two-point form: a
    bar keeping P and Q at a distance (ball joints at both ends; its spin about its own axis
    is not a freedom, so it has no unknowns and may carry no joint with an axis).

    Parameters
    ----------
    name : str
    points : dict
        Point name -> (x, y, z) as drawn (numbers or parameter names).
    length : float or str, optional
        Set by `Body.bar` only.

    Examples
    --------
    >>> b = Body.bar("coupler", "B", "C", 130)
    >>> b.two_point, b.point_names, b.length
    (True, ('B', 'C'), 130)
    """

    name: str
    points: tuple = ()
    length: Num | None = None
    mass: Num = 0.0
    cg: tuple | None = None  # as drawn; None: the mean of its points
    inertia: tuple = (0.0,) * 9  # about the cg, drawing axes, row by row

    def __init__(self, name: str, points=(), length: Num | None = None, *, mass: Num = 0.0,
                 cg=None, inertia=0.0):
        where = f"[links] {name}"
        object.__setattr__(self, "mass", as_number(mass))
        object.__setattr__(self, "cg", None if cg is None else _triple(cg, f"{where}: cg"))
        object.__setattr__(self, "inertia", _tensor(inertia, f"{where}: inertia"))
        object.__setattr__(self, "name", name)
        if length is None:
            items = _table(points, f"{where}: points", "(x, y, z)")
            pts = tuple((p, _triple(xyz, f"{where}: points.{p}")) for p, xyz in items)
        else:
            pts = tuple((p, None) for p in points)
            if len(pts) != 2 or not all(isinstance(p, str) for p, _ in pts):
                raise ModelError(f"{where}: points: the two-point form takes two point names")
        object.__setattr__(self, "points", pts)
        object.__setattr__(self, "length", as_number(length))

    def _with(self, mass: Num = 0.0, **_) -> "Body":
        """The same bar with a mass (at its middle)."""
        out = Body(self.name, self.point_names, self.length, mass=mass)
        return out

    @classmethod
    def bar(cls, name: str, p: str, q: str, length: Num) -> "Body":
        """A two-point bar P-Q of the given length (a number or a parameter's name).

        Parameters
        ----------
        name, p, q : str
        length : float or str

        Returns
        -------
        Body

        Examples
        --------
        >>> Body.bar("leg1", "B1", "P1", "l1").length
        'l1'
        """
        return cls(name, (p, q), length=length)

    @property
    def two_point(self) -> bool:
        """Whether the body is a two-point bar (no unknowns of its own).

        Examples
        --------
        >>> Body.bar("b", "P", "Q", 1).two_point
        True
        """
        return self.length is not None

    @property
    def point_names(self) -> tuple[str, ...]:
        """The names of the body's points, in declaration order.

        Examples
        --------
        >>> Body("b", {"P": (0, 0, 0), "Q": (1, 0, 0)}).point_names
        ('P', 'Q')
        """
        return tuple(p for p, _ in self.points)

    def local(self, point: str):
        """A point's coordinates as drawn (None for a bar's ends).

        Parameters
        ----------
        point : str

        Returns
        -------
        (x, y, z) or None

        Examples
        --------
        >>> Body("b", {"P": (0, 0, 1)}).local("P")
        (0, 0, 1)
        """
        return dict(self.points)[point]


@dataclass(frozen=True)
class Joint:
    """A joint at a point shared by two bodies (the ground counting as one).

    Parameters
    ----------
    type : str
        "spherical", "revolute", "universal", "cylindrical", "prismatic" or "planar".
    point : str
        The point the joint is at (for cylindrical, prismatic and planar joints a point of
        the second body, whose line or plane in the first body passes through it as drawn).
    axis : (float, float, float), optional
        The joint's axis (revolute, cylindrical, prismatic) or normal (planar), global at
        the drawing pose.
    axes : two (x, y, z), optional
        A universal joint's axes: the first fixed in the first body, the second in the second,
        perpendicular at the drawing pose.
    bodies : (str, str), optional
        The first and the second body; may be left out where exactly two bodies carry `point`.
    name : str, optional
        Prefix of its coordinates (`A.angle`); default the point's name.

    Examples
    --------
    >>> j = Joint("universal", "O", axes=((0, 0, 1), (1, 0, 0)), name="cross")
    >>> j.name, j.coordinates
    ('cross', ('angle1', 'angle2'))
    """

    type: str
    point: str
    axis: tuple | None = None
    axes: tuple | None = None
    bodies: tuple | None = None
    name: str = ""

    def __post_init__(self):
        where = f"[[joints]] {self.name or self.point}"
        if self.type not in JOINT_TYPES:
            raise ModelError(f"{where}: type: {self.type!r} is not one of {list(JOINT_TYPES)}")
        if not self.name:
            object.__setattr__(self, "name", self.point)
        if self.type in AXIS_JOINTS:
            if self.axis is None:
                raise ModelError(f"{where}: axis: missing (a {self.type} joint needs its axis)")
            object.__setattr__(self, "axis", _direction(self.axis, f"{where}: axis"))
        elif self.axis is not None:
            raise ModelError(f"{where}: axis: a {self.type} joint takes no axis")
        if self.type == "universal":
            if self.axes is None or len(tuple(self.axes)) != 2:
                raise ModelError(f"{where}: axes: expected two axes [[x, y, z], [x, y, z]]")
            a, b = (_direction(v, f"{where}: axes[{k}]") for k, v in enumerate(self.axes))
            if abs(sum(x * y for x, y in zip(a, b))) > 1e-9:
                raise ModelError(f"{where}: axes: the two axes are not perpendicular "
                                 f"(cosine {sum(x * y for x, y in zip(a, b)):.6g})")
            object.__setattr__(self, "axes", (a, b))
        elif self.axes is not None:
            raise ModelError(f"{where}: axes: only a universal joint takes `axes`")
        if self.bodies is not None:
            bodies = tuple(self.bodies)
            if len(bodies) != 2 or not all(isinstance(b, str) for b in bodies) or bodies[0] == bodies[1]:
                raise ModelError(f"{where}: bodies: expected two different body names")
            object.__setattr__(self, "bodies", bodies)

    @property
    def coordinates(self) -> tuple[str, ...]:
        """The joint's coordinate names ("angle", "s", "angle1", ...).

        Examples
        --------
        >>> Joint("planar", "P", axis=(0, 0, 1)).coordinates
        ('s1', 's2', 'angle')
        """
        return COORDINATES[self.type]


@dataclass(frozen=True)
class SpatialSlide:
    """`point` stays on a line (two equations) or a plane (one) of body `along`.

    Parameters
    ----------
    point, along : str
    through : (x, y, z)
        A point of the line or plane, global at the drawing pose.
    direction : (x, y, z), optional
        The line's direction (its coordinate `s` is measured along it from `through`).
    normal : (x, y, z), optional
        The plane's normal, instead of a direction.
    name : str, optional

    Examples
    --------
    >>> SpatialSlide("P", "ground", (0, 0, 0), direction=(0, 0, 2)).direction
    (0.0, 0.0, 1.0)
    """

    point: str
    along: str
    through: tuple = (0.0, 0.0, 0.0)
    direction: tuple | None = None
    normal: tuple | None = None
    name: str = ""

    def __post_init__(self):
        if not self.name:
            object.__setattr__(self, "name", self.point)
        where = f"[[slides]] {self.name}"
        object.__setattr__(self, "through", _triple(self.through, f"{where}: through"))
        if (self.direction is None) == (self.normal is None):
            raise ModelError(f"{where}: give either a line (direction) or a plane (normal)")
        if self.direction is not None:
            object.__setattr__(self, "direction", _direction(self.direction, f"{where}: line.direction"))
        else:
            object.__setattr__(self, "normal", _direction(self.normal, f"{where}: plane.normal"))

    @property
    def on_line(self) -> bool:
        """Whether the slide keeps its point on a line (else on a plane).

        Examples
        --------
        >>> SpatialSlide("P", "ground", normal=(0, 0, 1)).on_line
        False
        """
        return self.direction is not None
