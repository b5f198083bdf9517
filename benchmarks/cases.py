"""The mechanisms of the benchmarks, declared once so that every tool solves the same thing.

A `Case` is tool-neutral plain data: ground points (the crank's pivot at the origin, as the
`mechanism` package wants), a crank driven by its angle, rigid links given by their points
and side lengths (bars, and triangles for ternary links), slides (a point on a ground line),
the input angles, the crank's angular velocity, and the points whose positions and
velocities are compared. `steps` writes a dyad chain as successive constructions
(circle-circle, circle-line, rigid triangle vertex, translation): the closed forms of
`peers/closed_form.py` and pylinkage's dyads are built from it. A class-III chain has no
`steps`; its reference comes from a 30-digit Newton method (`peers/mp_newton.py`).

Every case is built from its *reference* pose: `guess` is the reference at the first pose,
moved by 1e-3 of the size, so that every tool starts on the same branch from the same place.

>>> c = fourbar()
>>> c.name, c.size, len(c.theta), c.outputs
('fourbar', 4.0, 720, ('A', 'B'))
>>> sorted(to_kincas(c).structure.order)[0]
('coupler', 'A')
"""
from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))  # `peers` beside this file

# Theo Jansen's eleven "holy numbers" (plus the crank m and the pivot offsets a, l).
JANSEN = dict(a=38.0, b=41.5, c=39.3, d=40.1, e=55.8, f=39.4, g=36.7, h=65.7, i=49.0,
              j=50.0, k=61.9, l=7.8, m=15.0)


@dataclass(frozen=True)
class Case:
    """One benchmark mechanism and study (angles in radians, lengths in the case's unit)."""

    name: str
    title: str
    ground: dict  # name -> (x, y); the crank's pivot is at (0, 0)
    crank: tuple  # (pivot, tip, radius)
    links: tuple  # (name, points, lengths): bars (P, Q), (l,); triangles (P, Q, R), (PQ, QR, PR)
    slides: tuple = ()  # (point, ground point the line passes through, line angle)
    steps: tuple | None = None  # dyad-chain construction of the reference (None: class III)
    theta: np.ndarray = field(default_factory=lambda: np.zeros(1))
    omega: float = 10.0
    outputs: tuple = ()
    kind: str = "dyads"
    guess: dict = field(default_factory=dict)  # moving point -> (x, y) at the first pose
    orient: dict = field(default_factory=dict)  # triangle name -> +1/-1 (R left of P->Q)
    guessless: bool = False  # no tool gets `guess`: kincas assembles its documented default mode

    @property
    def size(self) -> float:
        """Characteristic length: the longest link or ground distance (errors are relative to it)."""
        lengths = [self.crank[2]] + [x for _, _, ls in self.links for x in ls]
        g = np.array(list(self.ground.values()), dtype=float)
        spread = max((math.dist(p, q) for p in g for q in g), default=0.0)
        return float(max(lengths + [spread]))

    @property
    def moving(self) -> tuple:
        """Moving points: the crank's tip first, then in order of first appearance."""
        seen = dict.fromkeys([self.crank[1]] + [p for _, pts, _ in self.links for p in pts])
        return tuple(p for p in seen if p not in self.ground)

    def with_theta(self, theta) -> "Case":
        return replace(self, theta=np.asarray(theta, dtype=float))


def sweep_angles(n: int, start_deg: float = 0.0, turn_deg: float = 360.0) -> np.ndarray:
    """n input angles from `start_deg`, in equal steps over `turn_deg` (the end excluded)."""
    return np.radians(start_deg + turn_deg * np.arange(n) / n)


def _tri_side(p, q, r) -> int:
    return 1 if (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]) > 0 else -1


def finish(case: Case) -> Case:
    """Fill `guess` and triangle orientations from the reference at the first pose."""
    from peers.closed_form import reference  # the reference needs the case's geometry only

    P, _ = reference(case.with_theta(case.theta[:1]))
    L = case.size
    guess = {}
    for k, name in enumerate(case.moving):  # a fixed small offset: nobody starts exactly on it
        xy = P[name][0]
        guess[name] = (float(xy[0] + 1e-3 * L * math.cos(k)), float(xy[1] + 1e-3 * L * math.sin(k)))
    orient = {nm: _tri_side(*(P[p][0] for p in pts)) for nm, pts, _ in case.links if len(pts) == 3}
    return replace(case, guess=guess, orient=orient)


# --- the four cases of error against time and of throughput ---


def fourbar(n: int = 720, scale: float = 1.0, name: str = "fourbar") -> Case:
    """The README's crank-rocker: crank 1, coupler 3.5, rocker 3, ground 4 (Grashof)."""
    s = scale
    return finish(Case(
        name, "four-bar 1 : 3.5 : 3 : 4", {"O": (0.0, 0.0), "D": (4.0 * s, 0.0)},
        ("O", "A", 1.0 * s), (("coupler", ("A", "B"), (3.5 * s,)), ("rocker", ("D", "B"), (3.0 * s,))),
        steps=(("rrr", "B", "A", "D", 3.5 * s, 3.0 * s, 1),), theta=sweep_angles(n), outputs=("A", "B")))


def slider_crank(n: int = 720) -> Case:
    """Offset slider-crank: crank 1, rod 3.5, slider on the line y = 0.5."""
    return finish(Case(
        "slider_crank", "offset slider-crank 1 : 3.5, offset 0.5",
        {"O": (0.0, 0.0), "T": (-2.0, 0.5)}, ("O", "A", 1.0), (("rod", ("A", "B"), (3.5,)),),
        slides=(("B", "T", 0.0),), steps=(("rrp", "B", "A", 3.5, "T", 0.0, 1),),
        theta=sweep_angles(n), outputs=("A", "B")))


def jansen(n: int = 720) -> Case:
    """Theo Jansen's leg: crank m at O, pivot P = (-a, -l), two ternary links (b, e, d), (g, h, i)."""
    J = JANSEN
    links = (("j", ("A", "B"), (J["j"],)), ("k", ("A", "C"), (J["k"],)),
             ("upper", ("P", "B", "D"), (J["b"], J["e"], J["d"])), ("c", ("P", "C"), (J["c"],)),
             ("f", ("D", "E"), (J["f"],)), ("leg", ("C", "E", "F"), (J["g"], J["h"], J["i"])))
    steps = (("rrr", "B", "A", "P", J["j"], J["b"], -1), ("rrr", "C", "A", "P", J["k"], J["c"], 1),
             ("tri", "D", "B", "P", J["e"], J["d"], -1), ("rrr", "E", "D", "C", J["f"], J["g"], -1),
             ("tri", "F", "E", "C", J["h"], J["i"], -1))
    return finish(Case("jansen", "Jansen leg (Theo Jansen's lengths)",
                       {"O": (0.0, 0.0), "P": (-J["a"], -J["l"])}, ("O", "A", J["m"]), links,
                       steps=steps, theta=sweep_angles(n), outputs=("B", "C", "D", "E", "F")))


def class3(n: int = 720) -> Case:
    """A class-III Assur group (a triad) driven by a crank: the ternary link P1 P2 P3 hangs on
    the crank's tip by L1 and on the ground by L2 and L3. No dyad splits it off."""
    pts = {"A": (0.0, 0.4), "P1": (2.0, 3.0), "P2": (4.5, 3.2), "P3": (3.0, 5.0)}
    ground = {"O": (0.0, 0.0), "G2": (5.0, 0.0), "G3": (1.0, 6.5)}
    d = lambda p, q: math.dist({**pts, **ground}[p], {**pts, **ground}[q])
    links = (("L1", ("A", "P1"), (d("A", "P1"),)), ("L2", ("G2", "P2"), (d("G2", "P2"),)),
             ("L3", ("G3", "P3"), (d("G3", "P3"),)),
             ("triad", ("P1", "P2", "P3"), (d("P1", "P2"), d("P2", "P3"), d("P1", "P3"))))
    base = Case("class3", "class-III triad on a crank", ground, ("O", "A", 0.4), links,
                theta=sweep_angles(n, 90.0), outputs=("P1", "P2", "P3"), kind="class III")
    return finish(replace(base, guess={k: v for k, v in pts.items()}))


MAIN = {"fourbar": fourbar, "slider_crank": slider_crank, "jansen": jansen, "class3": class3}


# --- the stiff and extreme cases (stability) ---


def _bar4(name, title, crank, coupler, rocker, ground, n, start=90.0, turn=360.0, side=1):
    return finish(Case(
        name, title, {"O": (0.0, 0.0), "D": (ground, 0.0)}, ("O", "A", crank),
        (("coupler", ("A", "B"), (coupler,)), ("rocker", ("D", "B"), (rocker,))),
        steps=(("rrr", "B", "A", "D", coupler, rocker, side),),
        theta=sweep_angles(n, start, turn), outputs=("A", "B")))


def stiff_cases(n: int = 360) -> list[Case]:
    """The cases of issue [2], each with a one-dyad closed form and its other branch."""
    micro, mega = fourbar(n, 1e-6, "fourbar_1e-6"), fourbar(n, 1e6, "fourbar_1e6")
    micro = replace(micro, title="four-bar at 1e-6 m")
    mega = replace(mega, title="four-bar at 1e6 m")
    rod = 1.0 + 1e-6
    slider = finish(Case(
        "slider_rod_1e-6", "slider-crank, rod 1e-6 longer than crank", {"O": (0.0, 0.0), "T": (-5.0, 0.0)},
        ("O", "A", 1.0), (("rod", ("A", "B"), (rod,)),), slides=(("B", "T", 0.0),),
        steps=(("rrp", "B", "A", rod, "T", 0.0, 1),), theta=sweep_angles(n, 0.0), outputs=("A", "B")))
    para = finish(Case(
        "parallelogram", "parallelogram 1 : 4 : 1 : 4 through its change points",
        {"O": (0.0, 0.0), "D": (4.0, 0.0)}, ("O", "A", 1.0),
        (("coupler", ("A", "B"), (4.0,)), ("rocker", ("D", "B"), (1.0,))),
        steps=(("translate", "B", "A", 4.0, 0.0),), theta=sweep_angles(n, 30.0), outputs=("A", "B")))
    return [micro, mega,
            _bar4("ratio_1000", "1000:1 links (1, 1000.2, 2, 1000)", 1.0, 1000.2, 2.0, 1000.0, n),
            _bar4("change_1e-4_1deg", "crank-rocker 1e-4 from change point, 1 deg steps",
                  1.0, 4.0, 3.0, 2.0001, 360, start=90.0),
            _bar4("change_1e-4_15deg", "same, 15 deg steps", 1.0, 4.0, 3.0, 2.0001, 24, start=90.0),
            slider, para,
            _bar4("triple_rocker", "triple rocker (1, 1.9, 3, 4) over a full turn", 1.0, 1.9, 3.0, 4.0, n,
                  start=0.0)]


def alternatives(case: Case, most: int = 64) -> list[tuple]:
    """Other assemblies of a dyad chain as `steps`: every combination of sides of its circle
    intersections (a parallelogram's or antiparallelogram's point as the two intersections of
    its coupler's and rocker's circles); beyond `most` combinations, the case's own steps with
    one point at a time on either side (a jump of one loop among many)."""
    options = []
    for step in case.steps:
        kind, p = step[0], step[1]
        if kind in ("translate", "cross"):  # a four-bar's point: both circle points
            a = step[2]
            coupler = next(ls[0] for _, pts, ls in case.links if len(pts) == 2 and set(pts) == {a, p})
            g, rocker = next((q, ls[0]) for _, pts, ls in case.links if len(pts) == 2 and p in pts
                             for q in pts if q != p and q != a)
            options.append([("rrr", p, a, g, coupler, rocker, s) for s in (1, -1)])
        elif kind in ("rrr", "rrp"):
            options.append([step[:-1] + (s,) for s in (1, -1)])
        else:  # a rigid triangle's vertex: one place only
            options.append([step])
    if math.prod(len(o) for o in options) <= most:
        import itertools
        return [tuple(c) for c in itertools.product(*options)]
    return [case.steps[:k] + (alt,) + case.steps[k + 1:] for k, o in enumerate(options) if len(o) > 1
            for alt in o]


# --- the cases of issue [9]: branches, singular positions, gaps ---


def _every(step_deg: float, turn_deg: float = 720.0, start_deg: float = 0.0) -> np.ndarray:
    """Input angles from `start_deg` in steps of `step_deg` up to `start_deg + turn_deg`."""
    return np.radians(start_deg + step_deg * np.arange(int(turn_deg // step_deg) + 1))


def _slider_1e7(step: float) -> Case:
    rod = 1.0 + 1e-7
    return finish(Case(
        f"slider_rod_1e-7_{step:g}deg", f"slider-crank, rod 1e-7 longer than crank, {step:g} deg steps",
        {"O": (0.0, 0.0), "T": (-5.0, 0.0)}, ("O", "A", 1.0), (("rod", ("A", "B"), (rod,)),),
        slides=(("B", "T", 0.0),), steps=(("rrp", "B", "A", rod, "T", 0.0, 1),),
        theta=_every(step, 720.0, 3.0), outputs=("A", "B")))


def _nfourbar(N: int, step: float = 10.0) -> Case:
    """IFToMM benchmark A02: N four-bars in a row, each one's rocker the next one's crank
    through a shared coupler point: every link 1 long, pivots 1 apart, so all N loops fold
    at once (change points at 180 and 360 deg, poses exactly on them; `step` divides 180)."""
    ground = {f"G{i}": (float(i), 0.0) for i in range(N + 1)}
    links = tuple((f"rocker{i}", (f"G{i}", f"B{i}"), (1.0,)) for i in range(1, N + 1))
    links += tuple((f"coupler{i}", (f"B{i - 1}", f"B{i}"), (1.0,)) for i in range(1, N + 1))
    steps = tuple(("translate", f"B{i}", f"B{i - 1}", 1.0, 0.0) for i in range(1, N + 1))
    return finish(Case(f"a02_n{N}", f"IFToMM A02, {N} four-bars folding at once, poses on 180 and 360 deg",
                       ground, ("G0", "B0", 1.0), links, steps=steps, theta=_every(step, 360.0 - step, step),
                       outputs=("B1", f"B{N}")))


def _six_bar(kind: str, s2: int) -> Case:
    """A Watt II (two four-bars in series through a ternary rocker) or a Stephenson III (a
    four-bar's coupler point driving a dyad) whose last dyad loses its assembly for part of
    each turn: two turns in 7 deg steps, through gaps and back."""
    if kind == "watt2":
        ground = {"A": (0.0, 0.0), "D": (4.0, 0.0), "G": (4.6, 3.0)}
        ce, de = math.hypot(1.5, 1.0), math.hypot(1.5, 1.0)
        links = (("coupler", ("B", "C"), (3.5,)), ("rocker", ("D", "C", "E"), (3.0, ce, de)),
                 ("rod", ("E", "F"), (2.0,)), ("arm", ("G", "F"), (1.2,)))
        steps = (("rrr", "C", "B", "D", 3.5, 3.0, 1), ("tri", "E", "C", "D", ce, de, -1),
                 ("rrr", "F", "E", "G", 2.0, 1.2, s2))
        title = "Watt II six-bar through gaps (7 deg steps, two turns)"
    else:
        ground = {"A": (0.0, 0.0), "D": (4.0, 0.0), "G": (1.0, 4.2)}
        be, ce = math.hypot(1.5, 1.5), math.hypot(2.0, 1.5)
        links = (("coupler", ("B", "C", "E"), (3.5, ce, be)), ("rocker", ("D", "C"), (3.0,)),
                 ("rod", ("E", "F"), (1.5,)), ("arm", ("G", "F"), (1.0,)))
        steps = (("rrr", "C", "B", "D", 3.5, 3.0, 1), ("tri", "E", "B", "C", be, ce, 1),
                 ("rrr", "F", "E", "G", 1.5, 1.0, s2))
        title = "Stephenson III six-bar through gaps (7 deg steps, two turns)"
    return finish(Case(f"{kind}_gaps", title, ground, ("A", "B", 1.0), links, steps=steps,
                       theta=_every(7.0, 714.0), outputs=("C", "F")))


def _guessless_fourbar() -> Case:
    """The README's crank-rocker from 0 deg with no guess. The reference is kincas's documented
    default mode, the one whose block of g_q has a positive determinant: with g = B + b e(phi)
    - D - c e(psi) and kincas's unknowns (rocker angle psi, coupler angle phi), in that order,
    det = b c sin(psi - phi) > 0."""
    a, b, c, d = 1.0, 3.5, 3.0, 4.0
    B, D = np.array([a, 0.0]), np.array([d, 0.0])
    side = None
    for s in (1, -1):  # the circle point C on side s of B -> D, and its det sign
        e = (D - B) / np.linalg.norm(D - B)
        x = (b * b - c * c + (d - a) ** 2) / (2 * (d - a))
        C = B + x * e + s * math.sqrt(b * b - x * x) * np.array([-e[1], e[0]])
        phi, psi = math.atan2(*(C - B)[::-1]), math.atan2(*(C - D)[::-1])
        if math.sin(psi - phi) > 0:
            side = s
    case = _bar4("guessless_0deg", "four-bar 1 : 3.5 : 3 : 4 from 0 deg without a guess (reference: "
                 "kincas's default mode; another tool's own default counts as a branch jump)",
                 a, b, c, d, 36, start=0.0, turn=360.0, side=side)
    return replace(case, guessless=True)


def branch_cases() -> list[Case]:
    """The cases of issue [9], each with an independent closed form (`steps`)."""
    a, d = 2.0, 4.0
    anti = finish(Case(
        "antiparallelogram_30deg", "antiparallelogram 2 : 4 : 2 : 4 in 30 deg steps across 180 and 360 deg",
        {"O": (0.0, 0.0), "D": (d, 0.0)}, ("O", "A", a),
        (("coupler", ("A", "C"), (d,)), ("rocker", ("D", "C"), (a,))),
        steps=(("cross", "C", "A", "D", d, 0.0),), theta=_every(30.0, 720.0, 5.0), outputs=("A", "C")))
    s = 1e-6  # a deltoid (crank = ground 1, coupler = rocker 2) 1e-6 m in size, five poses
    kite = _bar4("kite_1e-6", "kite (deltoid) 1 : 2 : 2 : 1 at 1e-6 m, five poses 70 deg apart",
                 1 * s, 2 * s, 2 * s, 1 * s, 5, start=20.0, turn=350.0, side=1)
    limit = _bar4("limit_1e-6", "triple rocker at 1e-6 m swept 100-169 deg through its limit (151.2 deg)",
                  1 * s, 1.9 * s, 3 * s, 4 * s, 24, start=100.0, turn=72.0)
    para = finish(Case(
        "parallelogram_at_180", "parallelogram 1 : 4 : 1 : 4, a pose exactly at 180 deg",
        {"O": (0.0, 0.0), "D": (4.0, 0.0)}, ("O", "A", 1.0),
        (("coupler", ("A", "B"), (4.0,)), ("rocker", ("D", "B"), (1.0,))),
        steps=(("translate", "B", "A", 4.0, 0.0),), theta=np.radians([150.0, 165.0, 180.0, 195.0, 210.0]),
        outputs=("A", "B")))
    gap = _bar4("triple_rocker_gap", "triple rocker 140-220 deg: 57 of 81 poses with no assembly "
                "(the time per pose is mostly deciding 'no assembly')", 1.0, 1.9, 3.0, 4.0, 81,
                start=140.0, turn=81.0)
    return [_slider_1e7(16.0), _slider_1e7(30.0), anti, kite, limit, _nfourbar(2), _nfourbar(40, 20.0),
            _six_bar("watt2", -1), _six_bar("stephenson3", 1), para, _guessless_fourbar(), gap]


# --- growth: N four-bars chained through shared links ---

# The rockers' lengths in turn (the crank's is 1): unit k is a four-bar whose crank is rocker
# k - 1 and whose rocker is k, couplers 4 between pivots 4 apart, so no unit is a parallelogram
# (crank and rocker differ) and no construction but a circle-circle intersection places its
# point. Unit k's rocker turns to about acos(r_{k-1} cos t / r_k): 1 -> 1.1 -> 1 -> ... keeps
# every rocker within 60-125 deg over the driven range, far from every change point (the
# coupler and its rocker at least 50 deg from in line; checked by tests/test_bench_cases.py).
# (1.2 and 1 drift to 145 deg by the 40th unit, 30 deg from in line; 1.3 and 1 lose the
# assembly at the 24th.)
CHAIN_ROCKERS = (1.1, 1.0)


def chain(n_units: int, n_poses: int = 100) -> Case:
    """N four-bars in a row, each one's rocker the next one's crank: pivots G_k = (4k, 0),
    couplers of length 4, rockers of CHAIN_ROCKERS' lengths in turn (1.1, 1, 1.1, ...; the
    crank 1), driven over 60..120 deg. Not parallelograms: the closed form (and pylinkage,
    and any dyad method) intersects two circles per unit, T_k on the left of T_{k-1} -> G_k.
    (A chain of parallelograms would allow a shortcut no general method has: every rocker
    turns with the crank, T_k = G_k + (cos t, sin t).)"""
    ground = {"O": (0.0, 0.0), **{f"G{k}": (4.0 * k, 0.0) for k in range(1, n_units + 1)}}
    links, steps, prev = [], [], "A"
    for k in range(1, n_units + 1):
        r = CHAIN_ROCKERS[(k - 1) % len(CHAIN_ROCKERS)]
        links += [(f"cp{k}", (prev, f"T{k}"), (4.0,)), (f"rk{k}", (f"G{k}", f"T{k}"), (r,))]
        steps.append(("rrr", f"T{k}", prev, f"G{k}", 4.0, r, 1))
        prev = f"T{k}"
    return finish(Case(f"chain{n_units}", f"{n_units} chained four-bars", ground, ("O", "A", 1.0),
                       tuple(links), steps=tuple(steps), theta=np.radians(np.linspace(60, 120, n_poses)),
                       outputs=(prev,)))


# --- to kincas ---


def to_kincas(case: Case):
    """The case as a kincas `Mechanism` (triangles as one link in local coordinates)."""
    import kincas
    from kincas import Input, Link, Slide

    o, a, r = case.crank
    links = [Link.bar("crank", o, a, r)]
    for name, pts, ls in case.links:
        if len(pts) == 2:
            links.append(Link.bar(name, pts[0], pts[1], ls[0]))
        else:  # P at the origin, Q on the x axis, R from the side lengths (law of cosines)
            pq, qr, pr = ls
            x = (pq ** 2 + pr ** 2 - qr ** 2) / (2 * pq)
            y = case.orient[name] * math.sqrt(max(pr ** 2 - x ** 2, 0.0))
            links.append(Link(name, {pts[0]: (0.0, 0.0), pts[1]: (pq, 0.0), pts[2]: (x, y)}))
    slides = [Slide(p, "ground", through=case.ground[t], angle=ang, name=f"slide_{p}")
              for p, t, ang in case.slides]
    return kincas.Mechanism(ground=case.ground, links=links, slides=slides,
                            inputs=[Input.angle("crank")], guess={} if case.guessless else case.guess)


def kincas_report(case: Case) -> list[str]:
    """The kincas quantity names of the compared outputs: x, y, vx, vy of each point."""
    return [f"{p}.{c}" for p in case.outputs for c in ("x", "y", "vx", "vy")]
