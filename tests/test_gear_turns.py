"""Gears and racks relate absolute angles, so an angle's whole turns are not a matter of
representation there: a rack turned one more time relative to its pinion has slid one pitch
circumference further. These tests check, against closed forms written here, that

- a pose is "no assembly" only where the closed form has none near the guessed branch, from
  any start of a sweep and on both paths (fast and careful);
- an unknown angle whose turn is free (a pin's: only its sine and cosine enter) starts in
  (-pi, pi], and one that a gear or rack ties to the inputs takes the turn the relation and
  the guessed points give it (never hundreds of radians);
- `solve()` re-started from a sweep's pose (its points as the guess) returns that pose.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import kincas
from kincas import Input, Link, Mechanism, Slide
from kincas.model import Gear, Rack

TURN = 2 * math.pi


def wrap(a):
    return np.mod(np.asarray(a, float) + math.pi, TURN) - math.pi


# --- a pinion about the ground pin G drives a rack whose point R1 runs on a tilted guide ---
# The rack's slot `travel` (its line 20 above the rack's x axis) carries the fixed pin G; R1
# sits at (-150, 0) in the rack's frame, on the ground line through P0 at angle ALPHA.

G, P0, ALPHA, RP = np.array([0.0, 20.0]), np.array([-150.0, 0.0]), math.radians(120), 20.0


def rack_residual(th, tp, alpha=ALPHA):
    """The guide's equation at rack angle th, pinion angle tp: with e, n the rack's axes,
    travel.s = -RP (tp - th) puts the rack's origin at G - 20 n - s e, and R1 = origin - 150 e
    must lie on the guide: d x (R1 - P0) = 0."""
    d = np.array([math.cos(alpha), math.sin(alpha)])
    e, n = np.array([np.cos(th), np.sin(th)]), np.array([-np.sin(th), np.cos(th)])
    s = -RP * (tp - th)
    R1 = G[:, None] - 20 * n - (s + 150) * e
    v = R1 - P0[:, None]
    return d[0] * v[1] - d[1] * v[0]


def rack_roots(tp, alpha=ALPHA, span=30.0):
    """Every rack angle in [-span, span] that assembles at pinion angle tp (brentq between
    the sign changes of a fine scan)."""
    th = np.linspace(-span, span, 60001)
    f = rack_residual(th, tp, alpha)
    idx = np.flatnonzero(np.sign(f[:-1]) != np.sign(f[1:]))
    return np.array([brentq(lambda t: float(rack_residual(np.array([t]), tp, alpha)[0]), th[i], th[i + 1],
                            xtol=1e-15) for i in idx])


def rack_points(th, tp):
    """R1 and R2 of the assembly at rack angle th."""
    e, n = np.array([math.cos(th), math.sin(th)]), np.array([-math.sin(th), math.cos(th)])
    origin = G - 20 * n + RP * (tp - th) * e
    return origin - 150 * e, origin + 100 * e


def rack_mechanism(alpha=ALPHA, guess=None):
    return Mechanism(parameters={"rp": RP}, ground={"G": tuple(G)},
                     links=[Link.bar("pinion", "G", "T", "rp"), Link("rack", {"R1": (-150, 0), "R2": (100, 0)})],
                     slides=[Slide("R1", "ground", through=tuple(P0), angle=alpha, name="guide"),
                             Slide("G", "rack", through=(0, 20), angle=0, name="travel")],
                     racks=[Rack("pinion", "rp", "travel")], inputs=[Input.angle("pinion")],
                     guess=guess or {"R1": (-150, 0), "R2": (100, 0)})


def drawn_guess(th, tp):
    """The rack drawn by hand near the assembly at rack angle th: points to the millimetre."""
    R1, R2 = rack_points(th, tp)
    return {"R1": tuple(np.round(R1)), "R2": tuple(np.round(R2))}


def branch(tp0, th0, U, alpha=ALPHA):
    """The closed-form branch through (tp0, th0), followed root by root over U."""
    out, th = [], th0
    for tp in U:
        roots = rack_roots(tp, alpha)
        th = roots[np.argmin(np.abs(roots - th))]
        out.append(th)
    return np.array(out)


@pytest.mark.parametrize("method", ["fast", "careful"])
@pytest.mark.parametrize("start", [3.0, 3.375])
def test_rack_sweep_assembles_wherever_the_closed_form_does(method, start):
    """The rack drawn at its assembly with angle ~5.9 rad (-0.41 rad, one turn on) at pinion
    angle 3: one continuous assembly for every pinion angle in [3, 4]. Every pose is solved,
    on that branch, whichever pose the sweep starts at; the rack angle keeps the turn the
    rack relation gives it (travel.s = -RP (pinion - rack): the drawn rack position)."""
    roots = rack_roots(3.0)
    th0 = roots[np.argmin(np.abs(roots - 5.9))]
    assert 5.8 < th0 < 6.0  # the assembly drawn, independently of kincas
    U = np.linspace(start, 4.0, 1 + round((4.0 - start) / 0.025))
    ref = branch(3.0, th0, np.r_[np.linspace(3.0, start, 9), U])[9:]
    m = rack_mechanism(guess=drawn_guess(th0, 3.0))
    sw = kincas.sweep(m, {"pinion.angle": U}, report=["R1.x", "R1.y", "travel.s", "rack.angle"], method=method)
    assert list(sw.status) == ["ok"] * len(U)
    th = sw.q[:, sw.unknowns.index("rack.angle")]
    np.testing.assert_allclose(th, ref, rtol=0, atol=1e-9)
    np.testing.assert_allclose(sw["travel.s"], -RP * (U - ref), rtol=0, atol=1e-7)
    R1 = np.array([rack_points(t, tp)[0] for t, tp in zip(ref, U)])
    np.testing.assert_allclose(np.c_[sw["R1.x"], sw["R1.y"]], R1, rtol=0, atol=1e-7)
    np.testing.assert_allclose(sw["rack.angle"], wrap(ref), rtol=0, atol=1e-9)


def test_rack_solve_at_one_pose_equals_the_sweeps_pose():
    roots = rack_roots(3.0)
    th0 = roots[np.argmin(np.abs(roots - 5.9))]
    m = rack_mechanism(guess=drawn_guess(th0, 3.0))
    pose = kincas.solve(m, {"pinion.angle": 3.375}, report=["travel.s"])
    sw = kincas.sweep(m, {"pinion.angle": np.linspace(3.0, 3.375, 16)}, report=["travel.s"])
    assert pose.status == "ok" and sw.status[-1] == "ok"
    assert abs(pose["travel.s"] - sw["travel.s"][-1]) < 1e-9


@pytest.mark.parametrize("alpha_deg,th_guess", [(60, 4.8), (30, -0.5)])
def test_rack_first_pose_takes_the_assembly_drawn(alpha_deg, th_guess):
    """Where the drawn rack is near an assembly, the first pose is that assembly (Newton
    from the drawn points once went to rack angles of -448 rad: the rack slid 9 m)."""
    alpha = math.radians(alpha_deg)
    roots = rack_roots(3.0, alpha)
    th0 = roots[np.argmin(np.abs(roots - th_guess))]
    m = rack_mechanism(alpha, guess=drawn_guess(th0, 3.0))
    for method in ("fast", "careful"):
        sw = kincas.sweep(m, {"pinion.angle": np.linspace(3.0, 3.3, 7)}, method=method)
        assert sw.ok.all()
        th = sw.q[:, sw.unknowns.index("rack.angle")]
        np.testing.assert_allclose(th, branch(3.0, th0, np.linspace(3.0, 3.3, 7), alpha), rtol=0, atol=1e-9)


# --- a geared five-bar: crank2 = -crank1 / 2 (pitch radii 20 and 40) ---


def fivebar(drive="crank1", guess=None):
    return Mechanism(parameters={"r1": 20.0, "r2": 40.0}, ground={"A": (0, 0), "D": (60, 0)},
                     links=[Link.bar("crank1", "A", "B", 25), Link.bar("crank2", "D", "C", 30),
                            Link.bar("left", "B", "P", 90), Link.bar("right", "C", "P", 90)],
                     gears=[Gear(("crank1", "crank2"), ("r1", "r2"))], inputs=[Input.angle(drive)],
                     guess=guess or {"C": (90, 0), "P": (40, 85)})


def fivebar_closed_form(t1):
    """B, C and both intersections of the circles of radius 90 about them (P's two branches)."""
    t2 = -t1 / 2
    B = 25 * np.c_[np.cos(t1), np.sin(t1)]
    C = np.array([60.0, 0.0]) + 30 * np.c_[np.cos(t2), np.sin(t2)]
    d = C - B
    L = np.hypot(d[:, 0], d[:, 1])
    h = np.sqrt(90 ** 2 - (L / 2) ** 2)
    mid, n = (B + C) / 2, np.c_[-d[:, 1], d[:, 0]] / L[:, None]
    return t2, B, C, mid + h[:, None] * n, mid - h[:, None] * n


@pytest.mark.parametrize("method", ["fast", "careful"])
@pytest.mark.parametrize("start", [0.0, 2.0, 50.0, -47.0])
def test_geared_fivebar_from_any_input(method, start):
    """Driven at crank1 from anywhere (an input enters as given: from 50 rad crank2 is at
    -25 rad, not taken back into (-pi, pi]): every pose solved, crank2 = -crank1 / 2 exactly,
    P on the circle intersection with P left of B -> C (the guess's side) at every pose;
    the free angles (the dyad's) start in (-pi, pi]."""
    U = np.linspace(start, start + 4 * math.pi, 13)
    sw = kincas.sweep(fivebar(), {"crank1.angle": U}, report=["P.x", "P.y"], method=method)
    assert list(sw.status) == ["ok"] * len(U)
    t2, B, C, left, right = fivebar_closed_form(U)
    np.testing.assert_allclose(sw.q[:, sw.unknowns.index("crank2.angle")], t2, rtol=0, atol=1e-12 * max(1, abs(start)))
    np.testing.assert_allclose(np.c_[sw["P.x"], sw["P.y"]], left, rtol=0, atol=1e-9)
    free = [sw.unknowns.index(n) for n in ("left.angle", "right.angle")]
    assert np.all((sw.q[0, free] > -math.pi) & (sw.q[0, free] <= math.pi))


# --- a re-solve from a sweep's pose returns that pose ---


@pytest.mark.parametrize("case", ["rack", "fivebar", "fivebar_far"])
def test_resolve_from_a_sweeps_pose_returns_it(case):
    if case == "rack":
        roots = rack_roots(3.0)
        th0 = roots[np.argmin(np.abs(roots - 5.9))]
        m, key, U = rack_mechanism(guess=drawn_guess(th0, 3.0)), "pinion.angle", np.linspace(3.0, 4.0, 11)
    else:
        m, key = fivebar(), "crank1.angle"
        U = np.linspace(0, 4 * math.pi, 13) + (40.0 if case == "fivebar_far" else 0.0)
    sw = kincas.sweep(m, {key: U})
    assert sw.ok.all()
    pts, L = list(m.moving_points), m.size()
    for k in range(len(U)):
        guess = {P: (sw[f"{P}.x"][k], sw[f"{P}.y"][k]) for P in pts}
        pose = kincas.solve(m, {key: U[k]}, guess=guess)
        assert pose.status == "ok", k
        for P in pts:
            assert math.hypot(pose[f"{P}.x"] - guess[P][0], pose[f"{P}.y"] - guess[P][1]) < 1e-9 * L, (k, P)


def test_modes_of_a_rack_are_closed_form_roots():
    """`find_modes` starts every scattered guess at the turns the rack relation wants: each
    mode found is a closed-form assembly, and the two nearest rack angle 0 are among them."""
    from kincas.analysis.modes import find_modes
    alpha = ALPHA
    roots = rack_roots(3.0, alpha)
    found = [md.q[md.unknowns.index("rack.angle")] for md in find_modes(rack_mechanism(alpha), {"pinion.angle": 3.0}, starts=64)]
    assert all(np.abs(roots - t).min() < 1e-9 for t in found)
    near = roots[np.argsort(np.abs(roots))[:2]]
    assert all(np.abs(np.array(found) - t).min() < 1e-9 for t in near)


def test_assembly_near_a_solved_pose_keeps_its_turns():
    """Group by group from a solved pose (how a sweep resumes after a gap), a group with a
    rack keeps the free angles' turns of that pose: a sweep's angles stay continuous."""
    from kincas.cli.scene import load
    from kincas.core.assembly import assemble
    from conftest import EXAMPLES
    m = load(EXAMPLES / "rack_fourbar.toml").mechanism
    model, p, L = kincas.model_of(m), np.array([v for _, v in m.parameters]), m.size()
    sw = kincas.sweep(m, {"pinion.angle": [0.3]})
    near = sw.q[0].copy()
    j = sw.unknowns.index("coupler.angle")
    near[j] += 2 * TURN
    sol = assemble(model, np.array([0.3]), p, L, want=[0] * len(model.blocks), near=near)
    assert sol is not None and abs(sol.q[j] - near[j]) < 1e-6
    np.testing.assert_allclose(np.delete(sol.q, j), np.delete(sw.q[0], j), rtol=0, atol=1e-9 * L)
