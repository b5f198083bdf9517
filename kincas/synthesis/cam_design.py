"""Cam design: a disc cam's profile from its follower's motion law (numpy only).

A disc cam turns counter-clockwise about its shaft O by theta; a translating follower moves
along the line x = e (the offset), its knife edge or roller centre at (e, s0 + s(theta)),
s0 = sqrt(Rp^2 - e^2), Rp = base radius + roller radius (the prime circle). The motion law
s(theta) is made of segments over the turn: rises and returns by a cycloidal, simple
harmonic or 3-4-5 polynomial law, and dwells.

In the cam's frame the roller centre runs along the pitch curve c(theta) = R(-theta) w0,
w0 = (e, s0 + s), with dc/dtheta = R(-theta) w, w = (s0 + s, s' - e) (s' = ds/dtheta); the
curve turns clockwise, its outward normal is the tangent turned a quarter turn to the left,
and the profile is the pitch curve moved inwards by the roller radius. Then:

- pressure angle (between the common normal and the follower's direction, acute):
  atan(|s' - e| / (s0 + s));
- radius of curvature of the pitch curve, positive where convex:
  rho_p = -|w|^3 / (w x (w' - J w)), w' - J w = (2 s' - e, s'' - s0 - s);
  the profile's is rho_p - roller radius, and it is undercut where the pitch curve is convex
  with rho_p <= roller radius (the roller cannot follow it).

The profile, in polar form about O with increasing angles, is what a scene's
`profile = { polar = { angles, radii } }` takes; fed back into a scene it reproduces the
motion law (tests/test_cam_design.py).

>>> d = design_cam([Segment("rise", 90, 20, "cycloidal"), Segment("dwell", 90),
...                 Segment("return", 90, 20, "polynomial345"), Segment("dwell", 90)],
...                base_radius=40, roller_radius=10, points=360)
>>> round(float(d.s.max()), 12), round(float(d.pressure.max()), 4)
(20.0, 0.4055)
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._deprecated import keyword

TURN = 2 * math.pi
LAWS = ("cycloidal", "harmonic", "polynomial345")
MOTIONS = ("rise", "dwell", "return")


@dataclass(frozen=True)
class Segment:
    """One part of the motion law: `motion` "rise", "return" or "dwell" over `angle`
    (degrees), by `lift` (length; rises and returns) following `law`."""

    motion: str
    angle: float
    lift: float = 0.0
    law: str = "cycloidal"


def law(name: str, x, jerk: bool = False):
    """(y, y', y'') of a normalized rise from 0 to 1 over x in [0, 1]; with `jerk`, y''' too
    (the jerk per unit of x cubed).

    >>> [round(float(v), 12) for v in law("polynomial345", 0.5)]
    [0.5, 1.875, 0.0]
    >>> float(law("polynomial345", 0.5, jerk=True)[3])
    -30.0
    """
    x = np.asarray(x, float)
    out = _law(name, x)
    return out if jerk else out[:3]


def _law(name: str, x):
    if name == "cycloidal":
        w = TURN * x
        return x - np.sin(w) / TURN, 1 - np.cos(w), TURN * np.sin(w), TURN ** 2 * np.cos(w)
    if name == "harmonic":
        a = math.pi * x
        return ((1 - np.cos(a)) / 2, math.pi * np.sin(a) / 2, math.pi ** 2 * np.cos(a) / 2,
                -math.pi ** 3 * np.sin(a) / 2)
    if name == "polynomial345":
        return (10 * x ** 3 - 15 * x ** 4 + 6 * x ** 5, 30 * x ** 2 - 60 * x ** 3 + 30 * x ** 4,
                60 * x - 180 * x ** 2 + 120 * x ** 3, 60 - 360 * x + 360 * x ** 2)
    raise ValueError(f"law: {name!r} is not one of {list(LAWS)}")


def problems(segments, base_radius, roller_radius, offset, samples) -> list[str]:
    """What is wrong with a design's data (fields named as in `[cam_design]`)."""
    out = []
    for k, sg in enumerate(segments):
        where = f"[cam_design] segments[{k}]"
        if sg.motion not in MOTIONS:
            out.append(f"{where}.motion: {sg.motion!r} is not one of {list(MOTIONS)}")
        if not (math.isfinite(sg.angle) and sg.angle > 0):
            out.append(f"{where}.angle: must be a positive number of degrees")
        if sg.motion != "dwell":
            if sg.law not in LAWS:
                out.append(f"{where}.law: {sg.law!r} is not one of {list(LAWS)}")
            if not (math.isfinite(sg.lift) and sg.lift > 0):
                out.append(f"{where}.lift: a rise or return needs a positive lift")
    if not segments:
        out.append("[cam_design] segments: none given")
    elif abs(sum(sg.angle for sg in segments) - 360) > 1e-9:
        out.append(f"[cam_design] segments: their angles add up to {sum(sg.angle for sg in segments):g} "
                   f"degrees, not 360")
    else:
        end = sum((sg.lift if sg.motion == "rise" else -sg.lift if sg.motion == "return" else 0)
                  for sg in segments)
        if abs(end) > 1e-9 * max(1.0, max(sg.lift for sg in segments)):
            out.append(f"[cam_design] segments: the follower ends {end:g} from where it started "
                       f"(the rises and returns must cancel)")
        low = np.cumsum([sg.lift if sg.motion == "rise" else -sg.lift if sg.motion == "return" else 0
                         for sg in segments]).min()
        if low < -1e-9:
            out.append("[cam_design] segments: a return goes below the starting height")
    if not (math.isfinite(base_radius) and base_radius > 0):
        out.append("[cam_design] base_radius: must be positive")
    if not (math.isfinite(roller_radius) and roller_radius >= 0):
        out.append("[cam_design] roller_radius: must be zero (knife edge) or positive")
    if not math.isfinite(offset) or abs(offset) >= base_radius + roller_radius:
        out.append("[cam_design] offset: must be smaller than the prime circle's radius "
                   "(base_radius + roller_radius)")
    if not (isinstance(samples, int) and 8 <= samples <= 100000):
        out.append("[cam_design] samples: expected a whole number from 8 to 100000")
    return out


@dataclass
class CamDesign:
    """A designed cam, every array over the cam angles `theta` (radians, from 0):
    follower displacement `s` and its derivatives `ds`, `dds`, `ddds` (the jerk) per radian of
    cam angle (times the cam's speed to that power for time derivatives);
    `pitch` (N x 2) and `profile` (N x 2) in the cam's frame; `pressure` (radians, acute);
    `rho_pitch` and `rho_profile` (radii of curvature, positive where convex; inf where
    straight); `undercut` (bool)."""

    theta: np.ndarray
    s: np.ndarray
    ds: np.ndarray
    dds: np.ndarray
    pitch: np.ndarray
    profile: np.ndarray
    pressure: np.ndarray
    rho_pitch: np.ndarray
    rho_profile: np.ndarray
    undercut: np.ndarray
    base_radius: float
    roller_radius: float
    offset: float
    ddds: np.ndarray | None = None

    @property
    def s0(self) -> float:
        return math.sqrt((self.base_radius + self.roller_radius) ** 2 - self.offset ** 2)

    def polar(self) -> tuple[np.ndarray, np.ndarray]:
        """(angles, radii) of the profile about the shaft: angles increasing from the first,
        spanning less than a turn (radians), as a scene's polar profile takes them."""
        phi = np.arctan2(self.profile[:, 1], self.profile[:, 0])
        r = np.hypot(self.profile[:, 0], self.profile[:, 1])
        order = np.argsort(np.mod(phi - phi[0], TURN))
        phi = phi[0] + np.mod(phi[order] - phi[0], TURN)
        return phi, r[order]


def motion(segments, theta, jerk: bool = False):
    """(s, s', s'') at cam angles theta (radians, in [0, 2 pi)); with `jerk`, s''' too."""
    s, ds, dds, ddds = (np.zeros_like(theta) for _ in range(4))
    start, height = 0.0, 0.0
    for sg in segments:
        beta = math.radians(sg.angle)
        inside = (theta >= start) & (theta < start + beta)
        if sg.motion == "dwell":
            s[inside] = height
        else:
            y, y1, y2, y3 = law(sg.law, (theta[inside] - start) / beta, jerk=True)
            sign = 1.0 if sg.motion == "rise" else -1.0
            s[inside] = height + sign * sg.lift * y
            ds[inside] = sign * sg.lift * y1 / beta
            dds[inside] = sign * sg.lift * y2 / beta ** 2
            ddds[inside] = sign * sg.lift * y3 / beta ** 3
            height += sign * sg.lift
        start += beta
    return (s, ds, dds, ddds) if jerk else (s, ds, dds)


def design_cam(segments, base_radius: float, roller_radius: float = 0.0, offset: float = 0.0,
               points: int = 3600, *, samples: int | None = None) -> CamDesign:
    """The cam for a translating follower moving by `segments` (see the module's text), its
    profile computed at `points` equally spaced cam angles (the scene's `[cam_design]
    samples`; `samples=` is 0.1's name of `points`, kept one release with a
    DeprecationWarning).

    Raises ValueError naming the `[cam_design]` field when the data are wrong.
    """
    points = keyword("design_cam", "samples", "points", samples, points, 3600)
    segments = list(segments)
    bad = problems(segments, base_radius, roller_radius, offset, points)
    if bad:
        raise ValueError("\n".join(bad))
    theta = np.arange(points) * (TURN / points)
    s, ds, dds, ddds = motion(segments, theta, jerk=True)
    e, rho = offset, roller_radius
    s0 = math.sqrt((base_radius + rho) ** 2 - e * e)
    c, si = np.cos(theta), np.sin(theta)

    def to_cam(vx, vy):  # R(-theta) v
        return np.stack([c * vx + si * vy, -si * vx + c * vy], axis=1)
    pitch = to_cam(np.full_like(theta, e), s0 + s)
    wx, wy = s0 + s, ds - e  # the tangent dc/dtheta, in the follower's (fixed) frame
    ax, ay = 2 * ds - e, dds - s0 - s  # w' - J w
    speed = np.hypot(wx, wy)
    cross = wx * ay - wy * ax
    with np.errstate(divide="ignore"):
        rho_p = np.where(cross != 0, -speed ** 3 / cross, np.inf)
    tangent = to_cam(wx / speed, wy / speed)
    outward = np.stack([-tangent[:, 1], tangent[:, 0]], axis=1)  # the curve turns clockwise
    profile = pitch - rho * outward
    pressure = np.arctan(np.abs(ds - e) / (s0 + s))
    undercut = (rho_p > 0) & (rho_p <= rho) if rho > 0 else np.zeros_like(theta, dtype=bool)
    return CamDesign(theta, s, ds, dds, pitch, profile, pressure, rho_p, rho_p - rho, undercut,
                     float(base_radius), float(rho), float(e), ddds)
