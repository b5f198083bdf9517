"""Closed-form kinematics of the example scenes, written independently of kincas.

Pure numpy: every function reads its dimensions from the scene's TOML (parameter names
resolved), so the closed forms and the scenes cannot drift apart, and computes the positions
of the points, the angles of the links and the coordinates of the slides by circle
intersections and slider-crank formulas, for a whole array of input values at once.

Each circle intersection has two branches (``side`` = +1 or -1). `solve` picks, for every
example, the combination of branches whose first pose lies nearest to the scene's `[guess]`,
as the solver's assembly mode is picked by that guess; the branch then stays the same along
the sweep, as the solver's does as long as the sweep crosses no singular position.

Angles are handled in radians inside; `Solution.quantities` reports them in the scene's unit,
link angles wrapped to (-180, 180] degrees (or (-pi, pi] radians) as kincas reports them.
Where the mechanism cannot be assembled the values are NaN.
"""
from __future__ import annotations

import itertools
import math
import tomllib
from pathlib import Path

import numpy as np

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


# ----------------------------------------------------------------------------- scene reading

def load_scene(source) -> dict:
    """A parsed scene from a dict, a path, or an example's name (``"fairbairn"``)."""
    if isinstance(source, dict):
        return source
    path = Path(source)
    if not path.suffix and not path.exists():
        path = EXAMPLES / f"{source}.toml"
    with open(path, "rb") as f:
        return tomllib.load(f)


def num(scene: dict, value) -> float:
    """A number of the scene: a literal or the name of a parameter."""
    if isinstance(value, str):
        value = scene["parameters"][value]
        if np.ndim(value):  # a driven parameter: one value per pose (see with_parameter)
            return np.asarray(value, dtype=float)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise TypeError(f"not a number: {value!r}")
    return float(value)


def vec(scene: dict, value) -> np.ndarray:
    return np.array([num(scene, value[0]), num(scene, value[1])])


def angle_unit(scene: dict) -> float:
    """Radians per angle unit of the scene."""
    unit = scene.get("units", {}).get("angle", "deg")
    return math.pi / 180 if unit == "deg" else 1.0


def ground_point(scene: dict, name: str) -> np.ndarray:
    return vec(scene, scene["ground"][name])


def local_points(scene: dict, link: str) -> dict[str, np.ndarray]:
    """The link's points in its own frame (two-point form: P at the origin, Q on the x axis)."""
    spec = scene["links"][link]
    pts = spec["points"]
    if isinstance(pts, list):
        p, q = pts
        length = num(scene, spec["length"])
        return {p: np.zeros(2), q: np.stack([length, np.zeros_like(length)], axis=-1)}
    return {name: vec(scene, xy) for name, xy in pts.items()}


def link_length(scene: dict, link: str, p: str, q: str):
    """Distance between two points of a link (an array if it is a driven parameter)."""
    loc = local_points(scene, link)
    return np.linalg.norm(loc[q] - loc[p], axis=-1)


def slide_spec(scene: dict, name: str) -> dict:
    """point, along, and the slide's line in the frame of `along`: through, unit direction."""
    for spec in scene.get("slides", []):
        if spec.get("name") == name:
            break
    else:
        raise KeyError(f"no slide named {name!r}")
    line = spec.get("line", {})
    through = vec(scene, line["through"]) if "through" in line else np.zeros(2)
    a = num(scene, line.get("angle", 0)) * angle_unit(scene)
    return {"point": spec["point"], "along": spec["along"],
            "through": through, "direction": np.array([math.cos(a), math.sin(a)])}


def input_values(scene: dict, index: int = 0) -> np.ndarray:
    """The values an input takes, in scene units (`steps` = number of poses, ends included)."""
    spec = scene["inputs"][index]
    if "value" in spec:
        return np.array([num(scene, spec["value"])])
    sw = spec["sweep"]
    return np.linspace(num(scene, sw["from"]), num(scene, sw["to"]), int(sw["steps"]))


def input_kind(scene: dict, index: int = 0) -> tuple[str, str]:
    spec = scene["inputs"][index]
    for kind in ("angle", "parameter", "slide"):
        if kind in spec:
            return kind, spec[kind]
    raise KeyError("input drives nothing")


def input_key(scene: dict, index: int = 0) -> str:
    """The key of the input in the JSON report: LINK.angle, the parameter's name, SLIDE.s."""
    kind, name = input_kind(scene, index)
    return {"angle": f"{name}.angle", "parameter": name, "slide": f"{name}.s"}[kind]


def with_parameter(scene: dict, name: str, value) -> dict:
    """A copy of the scene whose parameter `name` is `value` (an array: one pose each)."""
    return {**scene, "parameters": {**scene.get("parameters", {}), name: value}}


# ----------------------------------------------------------------------------- plane geometry

def rot(angle, v) -> np.ndarray:
    """Rotate the vector(s) v by angle(s) (radians); broadcasts to shape (n, 2)."""
    angle = np.asarray(angle, dtype=float)[..., None]
    v = np.asarray(v, dtype=float)
    c, s = np.cos(angle), np.sin(angle)
    return np.concatenate([c * v[..., :1] - s * v[..., 1:], s * v[..., :1] + c * v[..., 1:]], axis=-1)


def direction(angle) -> np.ndarray:
    angle = np.asarray(angle, dtype=float)
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def _sqrt(x):
    with np.errstate(invalid="ignore"):
        return np.sqrt(x)  # NaN where the mechanism cannot be assembled


def circle_circle(c1, r1, c2, r2, side: int) -> np.ndarray:
    """The point at distance r1 from c1 and r2 from c2; side=+1: left of the line c1 -> c2."""
    c1, c2 = np.asarray(c1, dtype=float), np.asarray(c2, dtype=float)
    d = c2 - c1
    dist = np.linalg.norm(d, axis=-1, keepdims=True)
    e = d / dist
    n = np.concatenate([-e[..., 1:], e[..., :1]], axis=-1)
    a = (dist**2 + np.asarray(r1)[..., None] ** 2 - np.asarray(r2)[..., None] ** 2) / (2 * dist)
    h = _sqrt(np.asarray(r1)[..., None] ** 2 - a**2)
    return c1 + a * e + side * h * n


def line_circle(through, unit, centre, r, side: int):
    """(s, X): X = through + s*unit at distance r from centre; side=+1: the larger s."""
    w = np.asarray(centre, dtype=float) - through
    along = w @ unit
    across = w[..., 0] * unit[1] - w[..., 1] * unit[0]
    s = along + side * _sqrt(np.asarray(r) ** 2 - across**2)
    return s, through + s[..., None] * unit


def fourbar(o2, o4, crank, coupler, rocker, theta, side: int):
    """Generic four-bar: crank o2-A of length `crank` at angle theta (radians, array), coupler
    A-B, rocker o4-B. side=+1 puts B left of the line A -> o4. Returns A, B (n, 2) and the
    coupler's and the rocker's angles (radians)."""
    o2, o4 = np.asarray(o2, dtype=float), np.asarray(o4, dtype=float)
    a = o2 + crank * direction(theta)
    b = circle_circle(a, coupler, np.broadcast_to(o4, a.shape), rocker, side)
    ab, o4b = b - a, b - o4
    return a, b, np.arctan2(ab[..., 1], ab[..., 0]), np.arctan2(o4b[..., 1], o4b[..., 0])


def wrap(x, half_turn: float = 180.0):
    """Wrap angles to (-half_turn, half_turn]."""
    x = np.asarray(x, dtype=float)
    return x - 2 * half_turn * np.ceil((x - half_turn) / (2 * half_turn))


# ----------------------------------------------------------------------------- solutions

class Solution:
    """Poses of a scene: every point's global position, every link's frame (angle, origin)."""

    def __init__(self, scene: dict, n: int):
        self.scene = scene
        self.n = n
        self.points: dict[str, np.ndarray] = {
            name: np.tile(ground_point(scene, name), (n, 1)) for name in scene.get("ground", {})}
        self.frames: dict[str, tuple[np.ndarray, np.ndarray]] = {}

    def place(self, link: str, p: str, q: str, angle=None):
        """Place `link` from the known global positions of its points p and q (or from p and
        its angle), and record the positions of all its points."""
        loc = local_points(self.scene, link)
        if angle is None:
            dg = self.points[q] - self.points[p]
            dl = loc[q] - loc[p]
            angle = np.arctan2(dg[:, 1], dg[:, 0]) - np.arctan2(dl[..., 1], dl[..., 0])
        angle = np.broadcast_to(np.asarray(angle, dtype=float), (self.n,))
        origin = self.points[p] - rot(angle, loc[p])
        self.frames[link] = (angle, origin)
        for name, xy in loc.items():
            self.points.setdefault(name, origin + rot(angle, xy))
        return angle

    def slider_dyad(self, rod: str, slide: str, side: int):
        """RRP dyad: put the point of a ground slide at the rod's length from the rod's other
        point (already placed), on the side'th intersection (+1: larger s); place the rod."""
        spec = slide_spec(self.scene, slide)
        assert spec["along"] == "ground"
        p = spec["point"]
        (q,) = [x for x in local_points(self.scene, rod) if x != p]
        _, self.points[p] = line_circle(spec["through"], spec["direction"], self.points[q],
                                        link_length(self.scene, rod, q, p), side)
        self.place(rod, q, p)

    def frame(self, body: str):
        if body == "ground":
            return np.zeros(self.n), np.zeros((self.n, 2))
        return self.frames[body]

    def line(self, slide: str):
        """Global (through, unit direction) of a slide's line, per pose."""
        spec = slide_spec(self.scene, slide)
        angle, origin = self.frame(spec["along"])
        return origin + rot(angle, spec["through"]), rot(angle, spec["direction"])

    def slide_s(self, slide: str) -> np.ndarray:
        through, unit = self.line(slide)
        p = self.points[slide_spec(self.scene, slide)["point"]]
        return np.einsum("ij,ij->i", p - through, unit)

    def moving_points(self) -> list[str]:
        ground = self.scene.get("ground", {})
        return [p for p in self.points if p not in ground]

    def quantities(self) -> dict[str, np.ndarray]:
        """Positions of moving points, link angles (scene unit, wrapped), slide coordinates."""
        k = angle_unit(self.scene)
        out = {}
        for name in self.moving_points():
            out[f"{name}.x"] = self.points[name][:, 0]
            out[f"{name}.y"] = self.points[name][:, 1]
        for link, (angle, _) in self.frames.items():
            out[f"{link}.angle"] = wrap(angle / k, math.pi / k)
        for spec in self.scene.get("slides", []):
            if "name" in spec:
                out[f"{spec['name']}.s"] = self.slide_s(spec["name"])
        return out

    def residuals(self) -> np.ndarray:
        """Largest violation, per pose, of the scene's constraints by these positions: every
        point of every link where the link's frame puts it, ground points where they are,
        slide points on their lines. A check of the closed forms themselves."""
        worst = np.zeros(self.n)
        for name in self.scene.get("ground", {}):
            worst = np.fmax(worst, np.linalg.norm(self.points[name] - ground_point(self.scene, name), axis=1))
        for link in self.scene["links"]:
            angle, origin = self.frames[link]
            for name, xy in local_points(self.scene, link).items():
                err = np.linalg.norm(self.points[name] - (origin + rot(angle, xy)), axis=1)
                worst = np.fmax(worst, err)
        for spec in self.scene.get("slides", []):
            through, unit = self.line(spec["name"])
            w = self.points[spec["point"]] - through
            worst = np.fmax(worst, np.abs(w[:, 0] * unit[:, 1] - w[:, 1] * unit[:, 0]))
        return worst


# ----------------------------------------------------------------------------- the examples
# Each takes (scene, u, sides): u the input values in scene units, sides one +1/-1 per branch.

def _angle_input(scene, u, link):
    kind, name = input_kind(scene)
    assert (kind, name) == ("angle", link), f"closed form expects the angle of {link} as input"
    return np.asarray(u, dtype=float) * angle_unit(scene)


def fairbairn_poses(scene, u, sides):
    """Crank B-D drives the slotted lever (pivot A, D in the slot on its x axis), rod E-F drives
    slider F along the ground guide."""
    lever_side, rod_side = sides
    theta = _angle_input(scene, u, "crank")
    sol = Solution(scene, len(theta))
    b, d = scene["links"]["crank"]["points"]
    sol.place("crank", b, d, angle=theta)
    slot = slide_spec(scene, "slot")
    assert slot["point"] == d and slot["along"] == "lever"
    loc = local_points(scene, "lever")
    pivot = next(p for p in loc if p in scene["ground"])
    w = loc[pivot] - slot["through"]
    assert abs(w[0] * slot["direction"][1] - w[1] * slot["direction"][0]) < 1e-12, "pivot on the slot line"
    ad = sol.points[d] - sol.points[pivot]
    angle = np.arctan2(ad[:, 1], ad[:, 0]) - math.atan2(slot["direction"][1], slot["direction"][0])
    sol.place("lever", pivot, None, angle=angle + (0 if lever_side > 0 else math.pi))
    sol.slider_dyad("rod", "guide", rod_side)
    return sol


def slider_crank_poses(scene, u, sides):
    """Crank O-A, rod A-B, B on a ground line. Input: the crank's angle or the slide's s."""
    (side,) = sides
    o, a = scene["links"]["crank"]["points"]
    a2, b = scene["links"]["rod"]["points"]
    assert a2 == a
    (slide,) = [s["name"] for s in scene["slides"]]
    spec = slide_spec(scene, slide)
    assert spec["point"] == b and spec["along"] == "ground"
    kind, name = input_kind(scene)
    u = np.asarray(u, dtype=float)
    sol = Solution(scene, len(u))
    if kind == "angle":
        sol.place("crank", o, a, angle=_angle_input(scene, u, "crank"))
        sol.slider_dyad("rod", slide, side)
    else:
        assert (kind, name) == ("slide", slide)
        sol.points[b] = spec["through"] + u[:, None] * spec["direction"]
        sol.points[a] = circle_circle(sol.points[o], link_length(scene, "crank", o, a),
                                      sol.points[b], link_length(scene, "rod", a, b), side)
        sol.place("crank", o, a)
        sol.place("rod", a, b)
    return sol


def fourbar_poses(scene, u, sides):
    """Crank O2-A, coupler (any form, holding A and B, maybe more points), rocker O4-B."""
    (side,) = sides
    o2, a = scene["links"]["crank"]["points"]
    o4, b = scene["links"]["rocker"]["points"]
    theta = _angle_input(scene, u, "crank")
    a_xy, b_xy, _, _ = fourbar(ground_point(scene, o2), ground_point(scene, o4),
                               link_length(scene, "crank", o2, a), link_length(scene, "coupler", a, b),
                               link_length(scene, "rocker", o4, b), theta, side)
    sol = Solution(scene, len(theta))
    sol.place("crank", o2, a, angle=theta)
    sol.points[b] = b_xy
    sol.place("coupler", a, b)
    sol.place("rocker", o4, b)
    return sol


def vtwin_poses(scene, u, sides):
    """One crank O-C, rods C-P1 and C-P2, pistons P1, P2 on ground lines."""
    theta = _angle_input(scene, u, "crank")
    sol = Solution(scene, len(theta))
    o, c = scene["links"]["crank"]["points"]
    sol.place("crank", o, c, angle=theta)
    for spec, side in zip(scene["slides"], sides, strict=True):
        rod = next(k for k, v in scene["links"].items() if v["points"] == [c, spec["point"]])
        sol.slider_dyad(rod, spec["name"], side)
    return sol


def sixbar_poses(scene, u, sides):
    """Crank O2-A, coupler A-B, rocker (pivot O4, points B and C), rod C-D, slider D."""
    rocker_side, rod_side = sides
    theta = _angle_input(scene, u, "crank")
    sol = Solution(scene, len(theta))
    o2, a = scene["links"]["crank"]["points"]
    a2, b = scene["links"]["coupler"]["points"]
    c, d = scene["links"]["rod"]["points"]
    assert a2 == a
    loc = local_points(scene, "rocker")
    o4 = next(p for p in loc if p in scene["ground"])
    sol.place("crank", o2, a, angle=theta)
    sol.points[b] = circle_circle(sol.points[a], link_length(scene, "coupler", a, b),
                                  sol.points[o4], link_length(scene, "rocker", o4, b), rocker_side)
    sol.place("coupler", a, b)
    sol.place("rocker", o4, b)
    (slide,) = [s["name"] for s in scene["slides"]]
    assert slide_spec(scene, slide)["point"] == d
    sol.slider_dyad("rod", slide, rod_side)
    return sol


def actuator_bellcrank_poses(scene, u, sides):
    """Actuator G-P (length = the driven parameter), bell crank (pivot O, points P, Q),
    coupler Q-R, rocker O5-R."""
    bell_side, rocker_side = sides
    kind, name = input_kind(scene)
    assert kind == "parameter" and scene["links"]["actuator"]["length"] == name
    u = np.asarray(u, dtype=float)
    scene = with_parameter(scene, name, u)
    sol = Solution(scene, len(u))
    g, p = scene["links"]["actuator"]["points"]
    q, r = scene["links"]["coupler"]["points"]
    o5, r2 = scene["links"]["rocker"]["points"]
    assert r2 == r
    loc = local_points(scene, "bellcrank")
    o = next(x for x in loc if x in scene["ground"])
    sol.points[p] = circle_circle(sol.points[g], u, sol.points[o],
                                  link_length(scene, "bellcrank", o, p), bell_side)
    sol.place("bellcrank", o, p)
    sol.points[r] = circle_circle(sol.points[q], link_length(scene, "coupler", q, r),
                                  sol.points[o5], link_length(scene, "rocker", o5, r), rocker_side)
    sol.place("coupler", q, r)
    sol.place("rocker", o5, r)
    sol.place("actuator", g, p)
    return sol


CLOSED_FORMS = {
    "fairbairn": (fairbairn_poses, 2),
    "slider_crank": (slider_crank_poses, 1),
    "fourbar_coupler": (fourbar_poses, 1),
    "study_fourbar": (fourbar_poses, 1),  # the nominal design of the study example
    "vtwin": (vtwin_poses, 2),
    "sixbar": (sixbar_poses, 2),
    "actuator_bellcrank": (actuator_bellcrank_poses, 2),
}


def pick_sides(poses, scene, n_sides, u0) -> tuple[int, ...]:
    """The branches whose pose at input u0 lies nearest to the scene's [guess]."""
    guess = {k: vec(scene, v) for k, v in scene.get("guess", {}).items()}
    assert guess, "the scene has no [guess] to pick a branch"
    best = None
    for sides in itertools.product((1, -1), repeat=n_sides):
        sol = poses(scene, np.array([u0]), sides)
        dist = sum(float(np.linalg.norm(sol.points[k][0] - xy)) for k, xy in guess.items())
        if not math.isnan(dist) and (best is None or dist < best[0]):
            best = (dist, sides)
    assert best is not None, "no branch assembles at the first pose"
    return best[1]


def solve(kind: str, scene, u=None, sides=None) -> Solution:
    """Closed-form poses of `scene` (a dict, path or example name) solved as the example `kind`
    ("fourbar_coupler" also serves any crank/coupler/rocker four-bar, "slider_crank" any
    slider-crank), at the input values u (default: the scene's own), on the branch of the guess."""
    scene = load_scene(scene)
    poses, n_sides = CLOSED_FORMS[kind]
    u = input_values(scene) if u is None else np.atleast_1d(np.asarray(u, dtype=float))
    if sides is None:
        sides = pick_sides(poses, scene, n_sides, float(input_values(scene)[0]))
    return poses(scene, u, sides)
