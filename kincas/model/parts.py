"""The parts a mechanism is declared with, as immutable plain data (no casadi here): links
(rigid bodies carrying named points), slides (a point kept on a line of a body), inputs
(what drives it), and numbers that may name a parameter (`Param`). `kincas.Mechanism`
(kincas/model/mechanism.py) puts them together and checks them.

>>> Link.bar("crank", "A", "B", "r").local("B"), Input.angle("crank").key
(('r', 0.0), 'crank.angle')
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Union

from .loads import Inertia
from .names import is_angle_name
from .values import _pair, _table, as_number, is_number  # noqa: F401  (their old home)

# --- numbers that may name a parameter ---


@dataclass(frozen=True)
class Param:
    """A reference to a named parameter, times a fixed factor (degrees -> radians, say).

    Parameters
    ----------
    name : str
        The parameter's name (a key of `Mechanism.parameters`).
    scale : float
        The factor the parameter's value is multiplied by.

    Examples
    --------
    >>> from kincas import Mechanism
    >>> m = Mechanism(parameters={"r_mm": 2000.0}, ground={"O": (0, 0)},
    ...     links=[Link.bar("crank", "O", "A", Param("r_mm", 1e-3))], inputs=[Input.angle("crank")])
    >>> m.value(m.link("crank").local("A")[0])
    2.0
    """

    name: str
    scale: float = 1.0


Num = Union[float, int, str, Param]


def as_param(v: Num) -> Param | None:
    """The parameter a number refers to, or None for a plain number."""
    if isinstance(v, Param):
        return v
    if isinstance(v, str):
        return Param(v)
    return None


# --- bodies, slides, inputs ---


@dataclass(frozen=True)
class Link:
    """A rigid body carrying named points, given in its own frame.

    `Link.bar(name, P, Q, length)` is the two-point form: origin at P, x axis towards Q.
    `Link(name, {"A": (0, 0), "E": (550, 0)})` is the local-coordinates form; the link's
    angle is the angle of its frame's x axis. Optional `mass`, `inertia` (about the centre
    of gravity) and `cg` (in the link's frame; default the mean of its points) give its
    inertia for efforts and shaking forces (kincas/model/loads.py).

    Parameters
    ----------
    name : str
        The link's name.
    points : dict or sequence of (name, (x, y))
        Its points in its own frame; a coordinate may name a parameter.
    two_point : bool
        Whether it is the two-point form (set by `Link.bar`).
    mass, inertia : float or str, optional
        Mass and moment of inertia about the centre of gravity.
    cg : (float, float), optional
        The centre of gravity in the link's frame.

    Examples
    --------
    >>> Link.bar("rod", "E", "F", 360).local("F")
    (360, 0.0)
    >>> Link("frame", {"A": (0, 0), "E": (550, 0), "G": (200, 80)}).point_names
    ('A', 'E', 'G')
    """

    name: str
    points: tuple[tuple[str, tuple[Num, Num]], ...]
    two_point: bool = False
    inertial: Inertia = Inertia()

    def __init__(self, name: str, points, two_point: bool = False, *, mass: Num = 0.0,
                 inertia: Num = 0.0, cg=None):
        where = f"[links] {name}"
        items = _table(points, f"{where}: points")
        object.__setattr__(self, "name", name)
        object.__setattr__(self, "points", tuple((p, _pair(xy, f"{where}: points.{p}")) for p, xy in items))
        object.__setattr__(self, "two_point", two_point)
        object.__setattr__(self, "inertial", Inertia(as_number(mass), as_number(inertia),
                                                     None if cg is None else _pair(cg, f"{where}: cg")))

    @classmethod
    def bar(cls, name: str, p: str, q: str, length: Num, **inertia) -> "Link":
        """Two-point link P-Q of the given length (a number or a parameter name).

        Parameters
        ----------
        name, p, q : str
            The link's name, the point at its origin, the point on its x axis.
        length : float or str
            |PQ|, or the name of the parameter that gives it.
        **inertia
            `mass`, `inertia`, `cg`, as for `Link`.

        Returns
        -------
        Link

        Examples
        --------
        >>> Link.bar("crank", "A", "B", "r").points
        (('A', (0.0, 0.0)), ('B', ('r', 0.0)))
        """
        return cls(name, ((p, (0.0, 0.0)), (q, (length, 0.0))), two_point=True, **inertia)

    @property
    def point_names(self) -> tuple[str, ...]:
        """The names of the link's points, in declaration order.

        Examples
        --------
        >>> Link.bar("crank", "A", "B", 1).point_names
        ('A', 'B')
        """
        return tuple(p for p, _ in self.points)

    def local(self, point: str) -> tuple[Num, Num]:
        """A point's coordinates in the link's frame (numbers or parameter names).

        Parameters
        ----------
        point : str

        Returns
        -------
        (x, y)

        Examples
        --------
        >>> Link("plate", {"A": (0, 0), "P": (1.5, 0.5)}).local("P")
        (1.5, 0.5)
        """
        return dict(self.points)[point]


@dataclass(frozen=True)
class Slide:
    """`point` stays on a line of body `along` (a link's name or "ground").

    The line passes through `through` at `angle` (radians), both in that body's frame;
    the default is the body's x axis. The slide's coordinate `s` is the signed distance
    along the line from `through` to the point.

    Parameters
    ----------
    point : str
        The point kept on the line.
    along : str
        The body carrying the line: a link's name or "ground".
    through : (float, float)
        A point of the line, in that body's frame.
    angle : float or str
        The line's direction in that body's frame (radians).
    name : str
        The slide's name (default: the point's).

    Examples
    --------
    >>> import math
    >>> Slide("F", "ground", through=(700, 0), angle=math.pi / 2, name="guide").name
    'guide'
    >>> Slide("B", "ground").name  # named after its point
    'B'
    """

    point: str
    along: str
    through: tuple[Num, Num] = (0.0, 0.0)
    angle: Num = 0.0
    name: str = ""

    def __post_init__(self):
        object.__setattr__(self, "through", _pair(self.through, f"[[slides]] {self.name or self.point}: line.through"))
        object.__setattr__(self, "angle", as_number(self.angle))
        if not self.name:
            object.__setattr__(self, "name", self.point)


@dataclass(frozen=True)
class Input:
    """What drives the mechanism: a link's absolute angle, a slide's coordinate, or a parameter.

    Parameters
    ----------
    kind : str
        "angle", "slide" or "parameter" (better made by the class methods below).
    target : str
        The link ("A" or "A/B" for a relative angle), the slide, or the parameter.

    Examples
    --------
    >>> Input.angle("crank").key, Input.slide("guide").key, Input.parameter("stroke").key
    ('crank.angle', 'guide.s', 'stroke')
    """

    kind: str  # "angle" | "slide" | "parameter" | "joint" (a spatial joint's coordinate)
    target: str

    @classmethod
    def angle(cls, link: str) -> "Input":
        """The absolute angle of a link, or with "A/B" the angle of link A relative to body B
        (a motor on B turning A; key "A/B.angle").

        Parameters
        ----------
        link : str

        Returns
        -------
        Input

        Examples
        --------
        >>> Input.angle("crank").key, Input.angle("arm/base").key
        ('crank.angle', 'arm/base.angle')
        """
        return cls("angle", link)

    @classmethod
    def relative(cls, link: str, body: str) -> "Input":
        """The angle of `link` relative to `body`: `Input.angle("link/body")`.

        Parameters
        ----------
        link, body : str

        Returns
        -------
        Input

        Examples
        --------
        >>> Input.relative("forearm", "upper").key
        'forearm/upper.angle'
        """
        return cls("angle", f"{link}/{body}")

    @classmethod
    def slide(cls, slide: str) -> "Input":
        """The coordinate s of a slide (a linear actuator): its point's signed distance
        along the line from the line's `through` point.

        Parameters
        ----------
        slide : str
            The slide's name.

        Returns
        -------
        Input

        Examples
        --------
        >>> Input.slide("guide").key
        'guide.s'
        """
        return cls("slide", slide)

    @classmethod
    def joint(cls, coordinate: str) -> "Input":
        """A spatial joint's coordinate: "J" (a joint with one coordinate) or "J.angle1",
        "J.s", ... (kincas.SpatialMechanism keys it by its coordinate: "J.angle").

        Parameters
        ----------
        coordinate : str

        Returns
        -------
        Input

        Examples
        --------
        >>> Input.joint("A.angle").key, Input.joint("cross.angle2").is_angle
        ('A.angle', True)
        """
        return cls("joint", coordinate)

    @classmethod
    def parameter(cls, name: str) -> "Input":
        """A parameter driven as an input (a link that changes length, say).

        Parameters
        ----------
        name : str
            The parameter's name.

        Returns
        -------
        Input

        Examples
        --------
        >>> Input.parameter("stroke").key
        'stroke'
        """
        return cls("parameter", name)

    @property
    def key(self) -> str:
        """The input's name in sweeps and results: "L.angle", "S.s" or the parameter's.

        Examples
        --------
        >>> Input.slide("guide").key
        'guide.s'
        """
        return {"angle": f"{self.target}.angle", "slide": f"{self.target}.s"}.get(self.kind, self.target)

    @property
    def is_angle(self) -> bool:
        """Whether the input is an angle (radians; periodic).

        Examples
        --------
        >>> Input.angle("crank").is_angle, Input.slide("guide").is_angle
        (True, False)
        """
        return is_angle_name(self.key)  # (the one reading of a key: names.is_angle_name)
