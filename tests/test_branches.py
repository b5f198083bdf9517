"""Issue [9]: branches, singular positions and gaps that never lie.

Each case reproduces a defect the issue lists and checks kincas against an independent closed
form written here (circle intersections, slider-crank formulas): no silent branch flip, no
mislabelled resume, no lost pose, no missed crossing, no wrong number at a singular pose,
assembly without a guess, mechanisms with no unknowns.
"""
import math

import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism, Slide


# --- closed forms ---


def circle_point(P, r1, Q, r2, side):
    """The point at r1 from P and r2 from Q, left (side=+1) or right (-1) of P -> Q; NaN where
    the circles miss each other. P, Q: (n, 2) arrays."""
    P, Q = np.broadcast_arrays(np.asarray(P, float), np.asarray(Q, float))
    e = Q - P
    r = np.hypot(e[:, 0], e[:, 1])
    x = (r1 * r1 - r2 * r2 + r * r) / (2 * r)
    with np.errstate(invalid="ignore"):
        h = np.sqrt(r1 * r1 - x * x)
    e = e / r[:, None]
    n = np.stack([-e[:, 1], e[:, 0]], 1)
    return P + x[:, None] * e + side * h[:, None] * n


def fourbar(a, b, c, d, C0=None, s=1.0):
    guess = {} if C0 is None else {"C": (C0[0] * s, C0[1] * s)}
    return Mechanism(ground={"A": (0, 0), "D": (d * s, 0)},
                     links=[Link.bar("crank", "A", "B", a * s), Link.bar("coupler", "B", "C", b * s),
                            Link.bar("rocker", "D", "C", c * s)],
                     inputs=[Input.angle("crank")], guess=guess)


def fourbar_C(th, a, b, c, d, side):
    B = np.stack([a * np.cos(th), a * np.sin(th)], 1)
    return circle_point(B, b, np.array([[d, 0.0]]), c, side)


def xy(sw, p):
    return np.stack([sw[f"{p}.x"], sw[f"{p}.y"]], 1)


def events(sw, kind):
    return [e for e in sw.events if e["kind"] == kind]


# --- silent branch flips ---


@pytest.mark.parametrize("step", [16, 19, 23, 27, 30])
@pytest.mark.parametrize("method", ["fast", "careful"])
def test_slider_crank_rod_1e7_longer_than_crank_keeps_its_branch_at_coarse_steps(step, method):
    # The two branches pass 9e-4 apart near 90 and 270 deg; when continuation fails there,
    # the recovery used to run a plain Newton that accepts whichever branch it lands on.
    r, l = 1.0, 1.0 + 1e-7
    m = Mechanism(ground={"O": (0, 0)}, links=[Link.bar("crank", "O", "A", r), Link.bar("rod", "A", "B", l)],
                  slides=[Slide("B", "ground", name="guide")], inputs=[Input.angle("crank")],
                  guess={"B": (2.0, 0.0)})
    for off in (0, 3, 7):
        th = np.radians(np.arange(off, 721 + off, step))
        sw = kincas.sweep(m, {"crank.angle": th}, report=["B.x", "B.y"], method=method)
        x = r * np.cos(th) + np.sqrt(l * l - (r * np.sin(th)) ** 2)  # the branch of the guess
        assert np.all(sw.ok)
        assert np.abs(sw["B.x"] - x).max() <= 1e-8 * (r + l)
        assert np.all(sw.residual <= 1e-12)


def antiparallelogram_C(th, a, d):
    """The crossed branch: the parallelogram's C = B + (d, 0) reflected across line B-D."""
    B = np.stack([a * np.cos(th), a * np.sin(th)], 1)
    P, D = B + [d, 0.0], np.array([d, 0.0])
    e = (D - B) / np.linalg.norm(D - B, axis=1)[:, None]
    w = P - B
    return B + 2 * (w * e).sum(1)[:, None] * e - w


@pytest.mark.parametrize("off", [5, 15])
def test_antiparallelogram_in_30_deg_steps_across_180_and_360(off):
    a, d = 2.0, 4.0
    th = np.radians(np.arange(off, off + 721, 30.0))
    C = antiparallelogram_C(th, a, d)
    m = Mechanism(ground={"A": (0, 0), "D": (d, 0)},
                  links=[Link.bar("crank", "A", "B", a), Link.bar("coupler", "B", "C", d),
                         Link.bar("rocker", "D", "C", a)],
                  inputs=[Input.angle("crank")], guess={"C": tuple(C[0])})
    for method in ("fast", "careful"):
        sw = kincas.sweep(m, {"crank.angle": th}, report=["C.x", "C.y"], method=method)
        assert np.all(sw.ok)
        assert np.abs(xy(sw, "C") - C).max() <= 1e-9 * d
        # the four change points crossed (180, 360, 540, 720 deg) are located
        at = sorted(math.degrees(e["inputs"]["crank.angle"]) for e in events(sw, "change point"))
        assert np.allclose(at, [180, 360, 540, 720], atol=1e-6)


def test_micro_scale_kite_in_five_poses():
    # A deltoid (crank = ground, coupler = rocker) 1e-6 m in size: C lies on the bisector
    # of angle BAD, at t u with u = (cos th/2, sin th/2) and |C - D| = b.
    s, a, b = 1e-6, 1.0, 2.0
    th = np.radians([20.0, 90.0, 160.0, 230.0, 300.0])
    u = np.stack([np.cos(th / 2), np.sin(th / 2)], 1)
    ud = u[:, 0] * a
    t = ud + np.sqrt(ud * ud - a * a + b * b)
    C = t[:, None] * u * s
    m = fourbar(a, b, b, a, C[0] / s, s)
    sw = kincas.sweep(m, {"crank.angle": th}, report=["C.x", "C.y"])
    assert np.all(sw.ok)
    assert np.abs(xy(sw, "C") - C).max() <= 1e-9 * s


# --- singular positions, scale-free ---


@pytest.mark.parametrize("scale", [1.0, 1e-6, 1e6])
def test_limit_located_at_every_size(scale):
    a, b, c, d = 1, 1.9, 3, 4  # triple rocker: the crank turns back at +-151.19 deg
    lim = math.acos((a * a + d * d - (b + c) ** 2) / (2 * a * d))
    th = np.radians(np.arange(100.0, 171.0, 3.0))
    sw = kincas.sweep(fourbar(a, b, c, d, (3.2, 2.5), scale), {"crank.angle": th}, report=["C.x"])
    limits = events(sw, "limit")
    assert len(limits) == 1
    assert abs(limits[0]["inputs"]["crank.angle"] - lim) <= 1e-9
    assert sw.flags[limits[0]["pose"]] == "limit"


def nfourbar(N, th0):
    """IFToMM benchmark A02: N four-bars in a row, each sharing a crank with the next; every
    crank and coupler 1 long, cranks 1 apart: a parallelogram chain that folds all at once."""
    ground = {f"G{i}": (float(i), 0.0) for i in range(N + 1)}
    links = [Link.bar(f"crank{i}", f"G{i}", f"B{i}", 1.0) for i in range(N + 1)]
    links += [Link.bar(f"coupler{i}", f"B{i - 1}", f"B{i}", 1.0) for i in range(1, N + 1)]
    guess = {f"B{i}": (i + math.cos(th0), math.sin(th0)) for i in range(1, N + 1)}
    return Mechanism(ground=ground, links=links, inputs=[Input.angle("crank0")], guess=guess)


@pytest.mark.parametrize("N", [1, 2, 3, 40])
def test_n_fourbar_a02_every_fold_is_an_event(N):
    th = np.radians(np.arange(5.0, 366.0, 20.0))
    sw = kincas.sweep(nfourbar(N, th[0]), {"crank0.angle": th}, report=[f"B{N}.x", f"B{N}.y"])
    assert np.all(sw.ok)
    assert np.hypot(sw[f"B{N}.x"] - N - np.cos(th), sw[f"B{N}.y"] - np.sin(th)).max() <= 1e-9
    cps = events(sw, "change point")
    at = [math.degrees(e["inputs"]["crank0.angle"]) for e in cps]
    # N loops fold at 180 deg and again at 360 deg: one event per loop
    assert len(cps) == 2 * N
    assert np.allclose(sorted(at), [180] * N + [360] * N, atol=1e-6)


@pytest.mark.parametrize("N", [1, 2, 3, 40])
def test_n_fourbar_a02_exactly_at_its_singular_position(N):
    th = np.radians([170.0, 180.0, 190.0])
    names = [f"B{N}.{c}" for c in ("x", "y", "vx", "vy", "ax", "ay")]
    sw = kincas.sweep(nfourbar(N, th[0]), {"crank0.angle": th}, report=names)
    assert np.all(sw.ok)
    # positions on the parallelogram: B_N = (N + cos th, sin th), exactly
    assert np.abs(sw[f"B{N}.x"] - N - np.cos(th)).max() <= 1e-12
    assert np.abs(sw[f"B{N}.y"] - np.sin(th)).max() <= 1e-12
    assert sw.flags[1] == "change point"
    # velocities and accelerations at unit rate: the branch's values, or null (never wrong)
    exact = {"vx": -np.sin(th), "vy": np.cos(th), "ax": -np.cos(th), "ay": -np.sin(th)}
    for c, v in exact.items():
        got = sw[f"B{N}.{c}"]
        assert np.abs(got[[0, 2]] - v[[0, 2]]).max() <= 1e-9
        assert np.isnan(got[1]) or abs(got[1] - v[1]) <= 1e-9, (c, got[1])


def test_parallelogram_exactly_at_180_deg():
    th = np.radians([150.0, 180.0])
    C0 = (4 + math.cos(th[0]), math.sin(th[0]))
    sw = kincas.sweep(fourbar(1, 4, 1, 4, C0), {"crank.angle": th},
                      report=["C.x", "C.y", "C.vy", "C.ay"])
    assert sw.ok.all()
    assert abs(sw["C.y"][1] - math.sin(math.pi)) <= 1e-12  # on the branch: C.y = 0
    assert abs(sw["C.x"][1] - 3.0) <= 1e-12
    assert sw.flags[1] == "change point"
    for name, v in (("C.vy", -1.0), ("C.ay", 0.0)):
        got = sw[name][1]
        assert np.isnan(got) or abs(got - v) <= 1e-9, (name, got)


def test_pose_exactly_at_a_change_point_gives_no_huge_velocity():
    # Solved alone (a single pose, no sweep to carry the branch through).
    for N in (2, 40):
        for deg in (0.0, 180.0):
            p = kincas.solve(nfourbar(N, math.radians(deg)), {"crank0.angle": math.radians(deg)},
                             report=[f"B{N}.vx", f"B{N}.vy", f"B{N}.ay"])
            assert p.ok
            for name, v in ((f"B{N}.vx", 0.0), (f"B{N}.vy", math.cos(math.radians(deg))),
                            (f"B{N}.ay", 0.0)):
                got = p[name]
                assert np.isnan(got) or abs(got - v) <= 1e-9, (N, deg, name, got)
            assert p.flag == "change point"


def test_rocker_driven_through_its_limit_reports_no_wrong_velocity():
    # A crank-rocker driven by its rocker: the rocker swings between two limits, where the
    # crank's angular velocity is infinite.  At a pose at a limit the velocity is null.
    a, b, c, d = 1.0, 3.5, 3.0, 4.0
    m = Mechanism(ground={"A": (0, 0), "D": (d, 0)},
                  links=[Link.bar("crank", "A", "B", a), Link.bar("coupler", "B", "C", b),
                         Link.bar("rocker", "D", "C", c)],
                  inputs=[Input.angle("rocker")], guess={"B": (0.8, 0.6)})
    # rocker limit: |AC| = a + b, C on the circle around D
    cos_phi = ((a + b) ** 2 - d * d - c * c) / (2 * d * c)
    phi = math.acos(cos_phi)
    sw = kincas.sweep(m, {"rocker.angle": np.array([phi + 0.2, phi])},
                      report=["B.x", "B.y", "B.vx", "crank.omega"])
    assert sw.ok.all()
    C = np.array([d + c * math.cos(phi), c * math.sin(phi)])
    B = C / np.linalg.norm(C) * a  # crank and coupler in line at the limit
    assert np.hypot(sw["B.x"][1] - B[0], sw["B.y"][1] - B[1]) <= 1e-12
    assert sw.flags[1] == "limit"
    assert np.isnan(sw["B.vx"][1]) and np.isnan(sw["crank.omega"][1])


# --- gaps: resume on the mode left ---


def watt2(e):
    """Two four-bars in series: A-B-C-D (crank-rocker), then the rocker's arm D-E drives a
    second four-bar D-E-F-G whose rocker loses its assembly for part of the turn."""
    return Mechanism(ground={"A": (0, 0), "D": (4, 0), "G": (4 + e, 3.0)},
                     links=[Link.bar("crank", "A", "B", 1), Link.bar("coupler", "B", "C", 3.5),
                            Link("rocker", {"D": (0, 0), "C": (3, 0), "E": (1.5, 1.0)}),
                            Link.bar("rod", "E", "F", 2.0), Link.bar("arm", "G", "F", 1.2)],
                     inputs=[Input.angle("crank")])


def watt2_closed(th, e, s1, s2):
    C = fourbar_C(th, 1, 3.5, 3, 4, s1)
    ang = np.arctan2(C[:, 1], C[:, 0] - 4)
    E = np.array([4.0, 0.0]) + np.stack([1.5 * np.cos(ang) - np.sin(ang), 1.5 * np.sin(ang) + np.cos(ang)], 1)
    F = circle_point(E, 2.0, np.array([[4 + e, 3.0]]), 1.2, s2)
    return C, F


def stephenson3():
    """A four-bar A-B-C-D whose coupler point E drives the dyad E-F-G to the ground at G."""
    return Mechanism(ground={"A": (0, 0), "D": (4, 0), "G": (1.0, 4.2)},
                     links=[Link.bar("crank", "A", "B", 1), Link("coupler", {"B": (0, 0), "C": (3.5, 0), "E": (1.5, 1.5)}),
                            Link.bar("rocker", "D", "C", 3), Link.bar("rod", "E", "F", 1.5),
                            Link.bar("arm", "G", "F", 1.0)],
                     inputs=[Input.angle("crank")])


def stephenson3_closed(th, s1, s2):
    B = np.stack([np.cos(th), np.sin(th)], 1)
    C = fourbar_C(th, 1, 3.5, 3, 4, s1)
    e1 = (C - B) / 3.5
    E = B + 1.5 * e1 + 1.5 * np.stack([-e1[:, 1], e1[:, 0]], 1)
    F = circle_point(E, 1.5, np.array([[1.0, 4.2]]), 1.0, s2)
    return C, F


@pytest.mark.parametrize("case", ["watt2", "stephenson3"])
@pytest.mark.parametrize("s2", [1, -1])
@pytest.mark.parametrize("step", [7.0, 13.0])
def test_six_bar_resumes_after_a_gap_on_the_mode_it_left(case, s2, step):
    th = np.radians(np.arange(0.0, 721.0, step))
    closed = (lambda t, a, b: watt2_closed(t, 0.6, a, b)) if case == "watt2" else stephenson3_closed
    m = watt2(0.6) if case == "watt2" else stephenson3()
    C, F = closed(th[:1], 1, s2)
    assert np.isfinite(F).all()
    m = m.with_guess(C=tuple(C[0]), F=tuple(F[0]))
    sw = kincas.sweep(m, {"crank.angle": th}, report=["C.x", "C.y", "F.x", "F.y"])
    C, F = closed(th, 1, s2)
    assembles = np.isfinite(F[:, 0])
    assert not assembles.all() and assembles.sum() > 5  # the sweep has gaps
    # no lost pose: every pose that assembles (on the mode left, which always exists when the
    # dyad assembles at all) is solved, and on that mode
    assert np.array_equal(sw.ok, assembles)
    assert np.abs(xy(sw, "C")[sw.ok] - C[sw.ok]).max() <= 1e-9
    assert np.abs(xy(sw, "F")[sw.ok] - F[sw.ok]).max() <= 1e-9
    resumes = events(sw, "resume")
    assert resumes
    assert all(e["branch"] == "same" for e in resumes)


# --- no guess, no unknowns ---


def test_guessless_fourbar_solves_its_first_pose_at_0_deg():
    a, b, c, d = 1, 3.5, 3, 4
    th = np.radians(np.arange(0.0, 361.0, 10.0))
    sw = kincas.sweep(fourbar(a, b, c, d), {"crank.angle": th}, report=["C.x", "C.y"])
    assert np.all(sw.ok)
    on = [np.abs(xy(sw, "C") - fourbar_C(th, a, b, c, d, s)).max() <= 1e-9 for s in (1, -1)]
    assert any(on)  # one assembly mode all along
    # the documented default: the mode kincas modes lists first
    first = kincas.sweep(fourbar(a, b, c, d), {"crank.angle": th[:1]}, report=["C.x", "C.y"])
    assert np.abs(xy(first, "C")[0] - xy(sw, "C")[0]).max() <= 1e-12


def test_guessless_six_bar_solves_every_pose_that_assembles():
    th = np.radians(np.arange(0.0, 361.0, 15.0))
    sw = kincas.sweep(stephenson3(), {"crank.angle": th}, report=["F.x", "F.y"])
    assembles = np.isfinite(stephenson3_closed(th, 1, 1)[1][:, 0])
    assert np.array_equal(sw.ok, assembles)


def test_driven_crank_alone_and_one_rigid_body():
    th = np.array([0.0, 0.5, 2.0])
    m = Mechanism(ground={"A": (0, 0)}, links=[Link.bar("crank", "A", "B", 2)], inputs=[Input.angle("crank")])
    sw = kincas.sweep(m, {"crank.angle": th}, report=["B.x", "B.y", "B.vx", "B.ay"])
    assert list(sw.status) == ["ok"] * 3
    assert np.allclose(sw["B.x"], 2 * np.cos(th), rtol=0, atol=1e-15)
    assert np.allclose(sw["B.vx"], -2 * np.sin(th), rtol=0, atol=1e-15)
    assert np.allclose(sw["B.ay"], -2 * np.sin(th), rtol=0, atol=1e-15)
    body = Mechanism(ground={"A": (1, 1)}, links=[Link("plate", {"A": (0, 0), "P": (2, 0), "Q": (0, 1)})],
                     inputs=[Input.angle("plate")])
    p = kincas.solve(body, {"plate.angle": math.pi / 2}, report=["P.x", "P.y", "Q.x", "Q.vx"])
    assert p.ok
    assert abs(p["P.x"] - 1) <= 1e-15 and abs(p["P.y"] - 3) <= 1e-15
    assert abs(p["Q.x"] - 0) <= 1e-15 and abs(p["Q.vx"] + math.cos(math.pi / 2)) <= 1e-15


def test_driven_crank_alone_from_the_command_line(tmp_path, capsys):
    from conftest import run_cli, write_scene
    scene = {"title": "crank", "ground": {"A": [0, 0]},
             "links": {"crank": {"points": ["A", "B"], "length": 2}},
             "inputs": [{"angle": "crank", "sweep": {"from": 0, "to": 90, "steps": 3}}],
             "output": {"report": ["B.x", "B.y"]}}
    code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, scene), "--json")
    assert code == 0, err
    assert out["status"] == ["ok"] * 3


@pytest.mark.parametrize("scale", [1.0, 1e-6])
def test_sweep_that_approaches_a_limit_to_rounding(scale):
    # Positions on the branch, the limit located, velocities null where rounding of the input
    # alone moves them by more than 1e-6; further away, the velocity loop's exact value.
    a, b, c, d = 1, 1.9, 3, 4
    lim = math.acos((a * a + d * d - (b + c) ** 2) / (2 * a * d))
    for eps in (0.0, 1e-15, 1e-12, 1e-10, 1e-6):
        th = np.array([lim - 0.3, lim - 0.1, lim - eps])
        sw = kincas.sweep(fourbar(a, b, c, d, (3.2, 2.5), scale), {"crank.angle": th},
                          report=["C.x", "C.y", "C.vx"])
        assert sw.ok.all()
        t = th[-1]
        B = a * np.array([math.cos(t), math.sin(t)])
        if eps <= 1e-15:  # at the limit coupler and rocker are in line: C = D + c (B - D) / (b + c)
            C = np.array([d, 0.0]) + c * (B - [d, 0.0]) / (b + c)
        else:
            C = fourbar_C(th[-1:], a, b, c, d, 1)[0]
        # (4 ulps of the input from the limit the positions are sqrt(1e-15) from its own)
        tol = 1e-7 if eps == 1e-15 else 1e-8
        assert np.hypot(sw["C.x"][-1] / scale - C[0], sw["C.y"][-1] / scale - C[1]) <= tol
        if eps <= 1e-10:
            assert sw.flags[-1] == "limit" and np.isnan(sw["C.vx"][-1])
            lims = events(sw, "limit")
            assert len(lims) == 1 and abs(lims[0]["inputs"]["crank.angle"] - lim) <= 1e-9
        else:  # velocity loop: B' + b phi' e(phi)^perp = c psi' e(psi)^perp
            phi = math.atan2(*(C - B)[::-1])
            psi = math.atan2(C[1], C[0] - d)
            Bd = a * np.array([-math.sin(t), math.cos(t)])
            M = np.array([[b * math.sin(phi), -c * math.sin(psi)], [-b * math.cos(phi), c * math.cos(psi)]])
            _, psid = np.linalg.solve(M, Bd)
            assert sw.flags[-1] is None
            assert abs(sw["C.vx"][-1] / scale - (-c * psid * math.sin(psi))) <= 1e-6 * abs(c * psid)


def watt2_rocking(s1, s2):
    """A Watt II chain whose first loop is a triple rocker (the crank turns back at +-151 deg)
    and whose second loop has gaps of its own: every gap ends both groups' assembly or the
    second's alone, and the resume must restore both modes (det g_q, their product, cannot
    tell (+, +) from (-, -))."""
    m = Mechanism(ground={"A": (0, 0), "D": (4, 0), "G": (4.6, 3.0)},
                  links=[Link.bar("crank", "A", "B", 1), Link.bar("coupler", "B", "C", 1.9),
                         Link("rocker", {"D": (0, 0), "C": (3, 0), "E": (1.5, 1.0)}),
                         Link.bar("rod", "E", "F", 2.5), Link.bar("arm", "G", "F", 2.0)],
                  inputs=[Input.angle("crank")])

    def closed(th):
        C = fourbar_C(th, 1, 1.9, 3, 4, s1)
        ang = np.arctan2(C[:, 1], C[:, 0] - 4)
        E = np.array([4.0, 0.0]) + np.stack([1.5 * np.cos(ang) - np.sin(ang), 1.5 * np.sin(ang) + np.cos(ang)], 1)
        return C, circle_point(E, 2.5, np.array([[4.6, 3.0]]), 2.0, s2)
    return m, closed


@pytest.mark.parametrize("s1, s2", [(1, 1), (-1, -1), (1, -1), (-1, 1)])
def test_two_groups_resume_in_both_modes_they_left(s1, s2):
    th = np.radians(np.r_[np.arange(-150.0, 151.0, 4.0), np.arange(150.0, -151.0, -4.0)])
    m, closed = watt2_rocking(s1, s2)
    C, F = closed(th)
    start = int(np.flatnonzero(np.isfinite(F[:, 0]))[0])
    m = m.with_guess(C=tuple(C[start]), F=tuple(F[start]))
    sw = kincas.sweep(m, {"crank.angle": th[start:]}, report=["C.x", "C.y", "F.x", "F.y"])
    C, F = C[start:], F[start:]
    assembles = np.isfinite(F[:, 0])
    assert not assembles.all()
    assert np.array_equal(sw.ok, assembles)
    assert np.abs(xy(sw, "C")[sw.ok] - C[sw.ok]).max() <= 1e-9
    assert np.abs(xy(sw, "F")[sw.ok] - F[sw.ok]).max() <= 1e-9
    assert all(e["branch"] == "same" for e in events(sw, "resume"))


@pytest.mark.parametrize("method", ["fast", "careful"])
def test_no_assembly_is_decided_without_the_optimiser(method, monkeypatch):
    # A triple rocker over a full turn in 1 deg steps: 57 poses have no assembly, each decided
    # by its dyad's circles (a discriminant), never by IPOPT (about 50 ms a pose).
    from kincas.core.numeric import Model

    def refuse(*args, **kwargs):
        raise AssertionError("IPOPT called for a dyad")
    monkeypatch.setattr(Model, "nearest_assembly", refuse)
    a, b, c, d = 1, 1.9, 3, 4
    th = np.radians(np.arange(0.0, 361.0, 1.0))
    sw = kincas.sweep(fourbar(a, b, c, d, (3.2, 2.5)), {"crank.angle": th}, report=["C.x", "C.y"],
                      method=method)
    C = fourbar_C(th, a, b, c, d, 1)
    assert np.array_equal(sw.ok, np.isfinite(C[:, 0]))
    assert np.abs(xy(sw, "C")[sw.ok] - C[sw.ok]).max() <= 1e-9


@pytest.mark.parametrize("order", ["coupler first", "rocker first", "rocker reversed"])
def test_guessless_default_mode_is_the_documented_one(order):
    # docs/scene-format.md: the default mode of the four-bar's dyad has B, D, C counter-clockwise
    # (C to the left of B -> D), whatever the declaration order or direction of the links
    a, b, c, d = 1, 3.5, 3, 4
    crank = Link.bar("crank", "A", "B", a)
    coupler = Link.bar("coupler", "B", "C", b)
    rocker = Link.bar("rocker", "C", "D", c) if order == "rocker reversed" else Link.bar("rocker", "D", "C", c)
    links = [crank, rocker, coupler] if order == "rocker first" else [crank, coupler, rocker]
    m = Mechanism(ground={"A": (0, 0), "D": (d, 0)}, links=links, inputs=[Input.angle("crank")])
    for th in np.radians([0.0, 75.0, 200.0, 300.0]):
        sw = kincas.sweep(m, {"crank.angle": [th]}, report=["C.x", "C.y"])
        B = np.array([a * math.cos(th), a * math.sin(th)])
        want = circle_point(B[None], b, np.array([[d, 0.0]]), c, 1)[0]  # left of B -> D
        assert (want[0] - B[0]) * want[1] - (want[1] - B[1]) * (want[0] - d) > 0  # (C-B) x (C-D)
        C = xy(sw, "C")[0]
        assert np.abs(C - want).max() <= 1e-12 * d
