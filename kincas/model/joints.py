"""Joints beyond pins and slides: gear pairs (and belts), racks, cams (no casadi here).

Each is plain immutable data checked with the mechanism (`problems`) and counted in its
mobility (`counts`): a gear pair or a rack removes one freedom (one equation); a cam adds
one unknown, the profile parameter of the contact point, and two equations, so it also
removes one. Angles are radians in Python. See docs/scene-format.md for the conventions.

>>> g = Gear(("sun", "planet"), (30, 15), carrier="arm")
>>> g.sign, g.kind
(-1, 'external')
>>> Cam("cam", "shaft", Circle((10, 0), 40), knife="F").follower
('knife', 'F')
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from . import spline

if TYPE_CHECKING:
    from .mechanism import Mechanism, Num

GROUND = "ground"


# --- declarations ---


@dataclass(frozen=True)
class Gear:
    """Two bodies in mesh: theta2 - theta_c = sign k (theta1 - theta_c) + phase, k = r1/r2,
    sign -1 for an external mesh, +1 for an internal one (the second body a ring gear) or a
    belt. Each gear's centre is the origin of its body's frame (of the ground: (0, 0))."""

    links: tuple[str, str]
    radii: tuple["Num", "Num"]
    internal: bool = False
    belt: bool = False
    carrier: str = GROUND
    phase: "Num" = 0.0
    name: str = ""

    def __post_init__(self):
        object.__setattr__(self, "links", tuple(self.links))
        object.__setattr__(self, "radii", tuple(self.radii))

    @property
    def sign(self) -> int:
        return 1 if (self.internal or self.belt) else -1

    @property
    def kind(self) -> str:
        return "belt" if self.belt else ("internal" if self.internal else "external")


@dataclass(frozen=True)
class Rack:
    """A pinion rolling on a rack: slide.s = offset - sigma radius (theta_pinion - theta_rack),
    sigma = +1 for teeth on the right of the slide's line, -1 on its left."""

    pinion: str
    radius: "Num"
    slide: str
    teeth: str = "right"
    offset: "Num" = 0.0
    name: str = ""

    @property
    def sigma(self) -> int:
        return 1 if self.teeth == "right" else -1


@dataclass(frozen=True)
class Circle:
    """A circular profile: centre and radius in the cam body's frame."""

    center: tuple["Num", "Num"]
    radius: "Num"


@dataclass(frozen=True)
class Polar:
    """A closed profile r(phi) about the body's origin: `angles` (radians, numbers, strictly
    increasing, spanning less than a turn) and `radii` (numbers or parameters), closed by a
    periodic cubic spline."""

    angles: tuple[float, ...]
    radii: tuple["Num", ...]

    def __post_init__(self):
        object.__setattr__(self, "angles", tuple(float(a) for a in self.angles))
        object.__setattr__(self, "radii", tuple(self.radii))


@dataclass(frozen=True)
class Cam:
    """A follower on a cam profile carried by `body` (a link or "ground"). Exactly one of
    `knife` (a point on the profile), `roller` (a roller's centre point, with `roller_radius`,
    touching the profile from outside) or `flat` (a link whose x axis stays tangent)."""

    name: str
    body: str
    profile: Circle | Polar
    knife: str = ""
    roller: str = ""
    roller_radius: "Num" = 0.0
    flat: str = ""

    @property
    def follower(self) -> tuple[str, str]:
        """(kind, name): ("knife", point), ("roller", centre point) or ("flat", link)."""
        for kind in ("knife", "roller", "flat"):
            if getattr(self, kind):
                return kind, getattr(self, kind)
        return "", ""


# --- relative angles: "A/B" ---


def split_relative(target: str) -> tuple[str, str] | None:
    """("A", "B") for a relative angle "A/B", else None.

    >>> split_relative("forearm/upper"), split_relative("crank")
    (('forearm', 'upper'), None)
    """
    a, sep, b = target.partition("/")
    return (a, b) if sep and a and b else None


# --- counting and checking ---


def counts(m: "Mechanism") -> tuple[int, int]:
    """(extra unknowns, extra equations) of the gears, racks and cams."""
    return len(m.cams), len(m.gears) + len(m.racks) + 2 * len(m.cams)


def problems(m: "Mechanism", lnames: set[str], snames: set[str], num) -> list[str]:
    """Name problems of every gear, rack and cam, each naming its section and field;
    `num(where, v)` checks a number or parameter reference."""
    out: list[str] = []
    bodies = lnames | {GROUND}
    moving = set(m.moving_points)
    for i, g in enumerate(m.gears):
        where = f"[[gears]] {g.name or i + 1}"
        if len(g.links) != 2:
            out.append(f"{where}: links: expected two bodies")
        else:
            for b in g.links:
                if b not in bodies:
                    out.append(f"{where}: links: unknown body {b!r} (a link's name or \"ground\")")
            if g.links[0] == g.links[1]:
                out.append(f"{where}: links: a body cannot mesh with itself")
            elif GROUND in g.links and g.carrier == GROUND:
                pass  # a fixed gear about the ground origin: allowed
        if g.carrier not in bodies:
            out.append(f"{where}: carrier: unknown body {g.carrier!r}")
        if g.internal and g.belt:
            out.append(f"{where}: belt: a belt cannot also be an internal mesh")
        if len(g.radii) != 2:
            out.append(f"{where}: radii: expected [r1, r2]")
        else:
            for r in g.radii:
                num(f"{where}: radii", r)
        num(f"{where}: phase", g.phase)
    for i, r in enumerate(m.racks):
        where = f"[[racks]] {r.name or i + 1}"
        if r.pinion not in lnames:
            out.append(f"{where}: pinion: unknown link {r.pinion!r}")
        sl = {s.name: s for s in m.slides}.get(r.slide)
        if sl is None:
            out.append(f"{where}: slide: unknown slide {r.slide!r}")
        elif r.pinion in lnames and sl.point not in m.link(r.pinion).point_names:
            out.append(f"{where}: slide: the point of slide {r.slide!r} ({sl.point!r}) must be the "
                       f"pinion's centre, a point of {r.pinion!r}")
        if r.teeth not in ("right", "left"):
            out.append(f"{where}: teeth: {r.teeth!r} is neither \"right\" nor \"left\"")
        num(f"{where}: radius", r.radius), num(f"{where}: offset", r.offset)
    names: set[str] = set()
    for i, c in enumerate(m.cams):
        where = f"[[cams]] {c.name or i + 1}"
        if c.name in names:
            out.append(f"{where}: name: two cams are named {c.name!r}")
        names.add(c.name)
        if c.body not in bodies:
            out.append(f"{where}: body: unknown body {c.body!r} (a link's name or \"ground\")")
        kinds = [k for k in ("knife", "roller", "flat") if getattr(c, k)]
        if len(kinds) != 1:
            out.append(f"{where}: follower: give exactly one of a point, roller or flat")
        elif kinds[0] == "flat":
            if c.flat not in lnames:
                out.append(f"{where}: flat: unknown link {c.flat!r}")
            elif c.flat == c.body:
                out.append(f"{where}: flat: the follower cannot be the cam's own body")
        else:
            p, field = (c.knife, "follower") if kinds[0] == "knife" else (c.roller, "roller.center")
            if p not in moving and p not in dict(m.ground):
                out.append(f"{where}: {field}: {p!r} is not a point of any link")
            elif c.body != GROUND and c.body in lnames and p in m.link(c.body).point_names:
                out.append(f"{where}: {field}: {p!r} is a point of the cam's own body")
            if kinds[0] == "roller":
                num(f"{where}: roller.radius", c.roller_radius)
        if isinstance(c.profile, Circle):
            num(f"{where}: profile.circle.center", c.profile.center[0])
            num(f"{where}: profile.circle.center", c.profile.center[1])
            num(f"{where}: profile.circle.radius", c.profile.radius)
        elif isinstance(c.profile, Polar):
            out += _polar_problems(where, c.profile, num)
        else:
            out.append(f"{where}: profile: expected a circle or a polar profile")
    return out


def _polar_problems(where: str, pr: Polar, num) -> list[str]:
    out = []
    a = np.asarray(pr.angles, float)
    if len(a) != len(pr.radii):
        out.append(f"{where}: profile.polar.radii: {len(pr.radii)} radii for {len(a)} angles")
    if len(a) < 3:
        out.append(f"{where}: profile.polar.angles: at least three points are needed")
    elif not np.all(np.isfinite(a)):
        out.append(f"{where}: profile.polar.angles: not all finite")
    elif not np.all(np.diff(a) > 0):
        out.append(f"{where}: profile.polar.angles: the angles must increase")
    elif a[-1] - a[0] >= spline.TURN:
        out.append(f"{where}: profile.polar.angles: they span a turn or more "
                   f"(the profile closes itself from the last angle back to the first)")
    for r in pr.radii:
        num(f"{where}: profile.polar.radii", r)
    return out


def value_problems(m: "Mechanism") -> list[str]:
    """Problems with the numbers once every name resolves: positive radii, a roller that
    fits the profile's concave parts (its radius below their radius of curvature), and no
    flat face on a profile with concave parts."""
    out = []
    for i, g in enumerate(m.gears):
        where = f"[[gears]] {g.name or i + 1}"
        if any(m.value(r) <= 0 for r in g.radii):
            out.append(f"{where}: radii: the pitch radii must be positive")
        elif g.internal and m.value(g.radii[0]) == m.value(g.radii[1]):
            out.append(f"{where}: radii: an internal mesh needs different radii")
    for i, r in enumerate(m.racks):
        where = f"[[racks]] {r.name or i + 1}"
        if m.value(r.radius) <= 0:
            out.append(f"{where}: radius: the pitch radius must be positive")
        centre = m.link(r.pinion).local(m.slide(r.slide).point)
        if any(m.value(v) != 0 for v in centre):
            out.append(f"{where}: slide: the point of slide {r.slide!r} must be the pinion's centre, "
                       f"the origin of {r.pinion!r}'s frame")
    for i, c in enumerate(m.cams):
        where = f"[[cams]] {c.name or i + 1}"
        rho = m.value(c.roller_radius) if c.roller else 0.0
        if c.roller and rho <= 0:
            out.append(f"{where}: roller.radius: must be positive")
        if isinstance(c.profile, Circle):
            if m.value(c.profile.radius) <= 0:
                out.append(f"{where}: profile.circle.radius: must be positive")
            continue
        radii = np.array([m.value(r) for r in c.profile.radii])
        if np.any(radii <= 0):
            out.append(f"{where}: profile.polar.radii: must be positive")
            continue
        smallest, at = most_concave(c.profile.angles, radii)
        if c.roller and rho >= smallest:
            out.append(f"{where}: roller.radius: {rho:.6g} is not below the smallest radius of "
                       f"curvature of the profile's concave parts ({smallest:.6g}): the roller "
                       f"cannot follow it (undercut)")
        if c.flat and smallest < math.inf:
            # a flat face touches where its line is tangent to the profile; only on a convex
            # profile is every tangent line a supporting line (the cam on one side of it): at
            # a concave part the face would cut through the cam, and the true contact would
            # bridge the hollow, jumping from one side of it to the other
            r = float(spline.evaluate(c.profile.angles, radii, np.array([at]), 0)[0, 0])
            x, y = (_num(r * f(at), radii.max()) for f in (math.cos, math.sin))
            out.append(f"{where}: flat: the profile is not convex everywhere (most concave at "
                       f"({x}, {y}) in the frame of {c.body!r}, radius of curvature {smallest:.6g}): "
                       f"a flat face would cut through the cam there; use a convex profile, or "
                       f"a knife edge or a roller")
    return out


def _num(v: float, size: float) -> str:
    """v to 6 significant digits, 0 where it is rounding next to `size`."""
    return f"{v:.6g}" if abs(v) > 1e-12 * size else "0"


def most_concave(angles, radii, samples: int = 2048) -> tuple[float, float]:
    """(radius of curvature, angle phi) where a polar profile is most concave, from the
    spline at `samples` angles and at its knots; (inf, nan) where it is convex everywhere.
    The polar curve r(phi) is convex where r^2 + 2 r'^2 - r r'' > 0 (`spline.curvature`)."""
    phi = np.concatenate([np.linspace(angles[0], angles[0] + spline.TURN, samples, endpoint=False),
                          np.asarray(angles, float)])
    k = spline.curvature(*spline.evaluate(angles, radii, phi))
    if not (k < 0).any():
        return math.inf, math.nan
    j = int(np.argmin(k))
    return float(-1 / k[j]), float(phi[j])


def concave_radius(angles, radii, samples: int = 2048) -> float:
    """The smallest radius of curvature over the concave parts of a polar profile (inf when
    it is convex everywhere), from the spline at `samples` angles and at its knots."""
    return most_concave(angles, radii, samples)[0]
