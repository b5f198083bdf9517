"""Loads on a mechanism and the inertia of its links, as immutable plain data (no casadi).

A `Load` is a force at a point (global axes), a torque on a link (counter-clockwise
positive), or a linear spring between two points. A link's inertia is its `Inertia`: mass,
moment of inertia about its centre of gravity, and the centre of gravity in the link's frame
(default: the mean of its points). The mechanism's `gravity` is an acceleration vector.
Numbers are used as written (consistent units: force = mass·length/time²).

>>> Load.force("F", (0, -100)).kind, Load.torque("rocker", 5).link
('force', 'rocker')
>>> Load.spring("A", "P", 200, 40).points
('A', 'P')
>>> Inertia(2.0, 0.02, (1.5, 0)).cg
(1.5, 0)
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from .values import _pair, as_number

# --- declarations ---


@dataclass(frozen=True)
class Inertia:
    """Mass, moment of inertia about the centre of gravity, and the centre of gravity in the
    link's frame (None: the mean of the link's points). Numbers or parameter names.

    >>> Inertia(mass=1.0).inertia
    0.0
    """

    mass: object = 0.0
    inertia: object = 0.0
    cg: tuple | None = None


@dataclass(frozen=True)
class Load:
    """A force at a point, a torque on a link, or a linear spring between two points.

    `Load.force(point, (fx, fy))` (global axes), `Load.torque(link, t)` (counter-clockwise
    positive), `Load.spring(a, b, stiffness, free_length)`: a spring pulls its two points
    together when it is longer than its free length and pushes them apart when shorter.
    `at` is the point (force) or the link (torque); `value` the force vector or the torque.

    Parameters
    ----------
    kind : str
        "force", "torque" or "spring" (better made by the class methods below).
    at : str
        The point of a force, the link of a torque.
    value : float, str or (fx, fy)
        The torque, or the force vector; numbers or parameter names.
    points : (str, str)
        A spring's two points.
    stiffness, free_length : float or str
        A spring's stiffness and free length.

    Examples
    --------
    >>> Load.torque("crank", -3.0).value
    -3.0
    """

    kind: str  # "force" | "torque" | "spring"
    at: str = ""
    value: object = 0.0
    points: tuple = ()
    stiffness: object = 0.0
    free_length: object = 0.0

    @classmethod
    def force(cls, point: str, force) -> "Load":
        """A force at a point, in global axes.

        Parameters
        ----------
        point : str
        force : (fx, fy)
            Numbers or parameter names.

        Returns
        -------
        Load

        Examples
        --------
        >>> Load.force("C", (0, -9.81)).value
        (0, -9.81)
        """
        return cls("force", at=point, value=_pair(force, f"[[loads]] force at {point}: force"))

    @classmethod
    def torque(cls, link: str, torque) -> "Load":
        """A torque on a link, counter-clockwise positive.

        Parameters
        ----------
        link : str
        torque : float or str

        Returns
        -------
        Load

        Examples
        --------
        >>> Load.torque("rocker", "T").at
        'rocker'
        """
        return cls("torque", at=link, value=as_number(torque))

    @classmethod
    def spring(cls, a: str, b: str, stiffness, free_length) -> "Load":
        """A linear spring between points a and b: tension stiffness * (|ab| - free_length).

        Parameters
        ----------
        a, b : str
        stiffness, free_length : float or str

        Returns
        -------
        Load

        Examples
        --------
        >>> Load.spring("A", "P", 200, 40).stiffness
        200
        """
        return cls("spring", points=(a, b), stiffness=as_number(stiffness),
                   free_length=as_number(free_length))

    @property
    def link(self) -> str:
        """The link of a torque ("" for a force or a spring).

        Examples
        --------
        >>> Load.torque("crank", 1).link, Load.force("B", (1, 0)).link
        ('crank', '')
        """
        return self.at if self.kind == "torque" else ""


# --- validation: every problem names the section and the field ---


def check_loads(m, num) -> list[str]:
    """Problems with a mechanism's gravity, loads and links' inertia. `num(where, v)` checks
    a number or parameter reference (it appends its own problems); returns the others."""
    out: list[str] = []
    links = {lk.name: lk for lk in m.links}
    points = set(m.ground_points) | set(m.moving_points)
    gx, gy = m.gravity
    num("gravity", gx), num("gravity", gy)
    for lk in m.links:
        i = lk.inertial
        where = f"[links] {lk.name}"
        num(f"{where}: mass", i.mass), num(f"{where}: inertia", i.inertia)
        if i.cg is not None:
            num(f"{where}: cg", i.cg[0]), num(f"{where}: cg", i.cg[1])
        for f in ("mass", "inertia"):
            v = getattr(i, f)
            name = v if isinstance(v, str) else getattr(v, "name", None)  # a name or a Param
            if name in m.param_values:  # a parameter's value must not be negative either
                v = m.value(v)
            if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and v < 0:
                out.append(f"{where}: {f}: must not be negative, got {v}")
    for k, ld in enumerate(m.loads):
        where = f"[[loads]] {k + 1}"
        if ld.kind == "force":
            if ld.at not in points:
                out.append(f"{where}: point: unknown point {ld.at!r}")
            num(f"{where}: force", ld.value[0]), num(f"{where}: force", ld.value[1])
        elif ld.kind == "torque":
            if ld.at not in links:
                out.append(f"{where}: link: unknown link {ld.at!r}")
            num(f"{where}: torque", ld.value)
        elif ld.kind == "spring":
            if len(ld.points) != 2:
                out.append(f"{where}: spring: expected two point names")
            else:
                out += [f"{where}: spring: unknown point {p!r}" for p in ld.points if p not in points]
                if ld.points[0] == ld.points[1]:
                    out.append(f"{where}: spring: its two points are the same")
            num(f"{where}: stiffness", ld.stiffness), num(f"{where}: free_length", ld.free_length)
        else:
            out.append(f"{where}: unknown kind {ld.kind!r} (force, torque or spring)")
    return out
