"""Sweeps that never silently change branch: stiff and extreme cases, each compared at
every pose with a closed form; singular positions flagged and located; ranges of motion."""
import math

import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism, Slide
from kincas.analysis.singular import input_range


def fourbar(a, b, c, d, guess, s=1.0):
    return Mechanism(ground={"A": (0, 0), "D": (d * s, 0)},
                     links=[Link.bar("crank", "A", "B", a * s), Link.bar("coupler", "B", "C", b * s),
                            Link.bar("rocker", "D", "C", c * s)],
                     inputs=[Input.angle("crank")], guess={"C": (guess[0] * s, guess[1] * s)})


def closed(theta, a, b, c, d, sign):
    """C by circle intersection; sign picks the side of line B->D (the assembly branch)."""
    B = np.stack([a * np.cos(theta), a * np.sin(theta)])
    e = np.array([[d], [0.0]]) - B
    r = np.linalg.norm(e, axis=0)
    x = (b * b - c * c + r * r) / (2 * r)
    with np.errstate(invalid="ignore"):
        h = np.sqrt(b * b - x * x)
    e = e / r
    return B + x * e + sign * h * np.stack([-e[1], e[0]])


def branch_of(sw, th, a, b, c, d):
    """Which closed-form branch each solved pose is on (+1, -1), checked to 1e-9 relative."""
    out = np.zeros(len(th))
    for sign in (+1, -1):
        C = closed(th, a, b, c, d, sign)
        hit = np.hypot(sw["C.x"] - C[0], sw["C.y"] - C[1]) <= 1e-9 * (a + b + c + d)
        out[hit & sw.ok] = sign if sign > 0 else np.where(out[hit & sw.ok] == 1, 1, -1)
    return out


def residuals_ok(sw):
    assert np.all(sw.residual[sw.ok] <= 1e-12)


@pytest.mark.parametrize("scale", [1e-6, 1e6])
def test_tiny_and_huge_fourbars_follow_the_closed_form(scale):
    th = np.radians(np.arange(0, 361, 2.0))
    sw = kincas.sweep(fourbar(1, 3.5, 3, 4, (3.6, 2.9), scale), {"crank.angle": th}, report=["C.x", "C.y"])
    residuals_ok(sw)
    C = closed(th, 1, 3.5, 3, 4, +1) * scale
    assert np.all(sw.ok)
    assert np.abs(np.hypot(sw["C.x"] - C[0], sw["C.y"] - C[1])).max() <= 1e-12 * 8.5 * scale


def test_1000_to_1_link_ratio():
    a, b, c, d = 1, 1000.2, 2, 1000
    th = np.radians(np.arange(0, 361, 1.0))
    sw = kincas.sweep(fourbar(a, b, c, d, (1000, 1.5)), {"crank.angle": th}, report=["C.x", "C.y"])
    residuals_ok(sw)
    assert np.all(sw.ok)
    C = closed(th, a, b, c, d, +1)
    assert np.abs(np.hypot(sw["C.x"] - C[0], sw["C.y"] - C[1])).max() <= 1e-12 * (a + b + c + d)


@pytest.mark.parametrize("method", ["fast", "careful"])
@pytest.mark.parametrize("step", [1.0, 15.0])
def test_crank_rocker_near_its_change_point_keeps_its_branch(step, method):
    a, b, c, d = 1, 4, 3, 2.0001
    th = np.radians(np.arange(0, 360 + step / 2, step))
    for sign, gy in ((+1, 3.0), (-1, -3.0)):
        C0 = closed(th[:1], a, b, c, d, sign)[:, 0]
        sw = kincas.sweep(fourbar(a, b, c, d, (C0[0], C0[1])), {"crank.angle": th},
                          report=["C.x", "C.y"], method=method)
        residuals_ok(sw)
        assert np.all(sw.ok)
        C = closed(th, a, b, c, d, sign)
        err = np.hypot(sw["C.x"] - C[0], sw["C.y"] - C[1]).max()
        assert err <= 1e-9 * (a + b + c + d), (sign, err)


def test_coarse_and_fine_sweeps_give_the_same_poses():
    m = fourbar(1, 4, 3, 2.0001, (2.0, 3.0))
    coarse = kincas.sweep(m, {"crank.angle": np.radians(np.arange(0, 361, 15.0))}, report=["C.x", "C.y"])
    fine = kincas.sweep(m, {"crank.angle": np.radians(np.arange(0, 3600.5, 1.0) / 10)}, report=["C.x", "C.y"])
    assert np.all(coarse.ok) and np.all(fine.ok)
    pick = np.arange(0, 3601, 150)
    assert np.abs(coarse["C.x"] - fine["C.x"][pick]).max() < 1e-12
    assert np.abs(coarse["C.y"] - fine["C.y"][pick]).max() < 1e-12


def test_slider_crank_whose_rod_is_barely_longer_than_its_crank():
    r, l = 1.0, 1.0 + 1e-6
    m = Mechanism(ground={"O": (0, 0)},
                  links=[Link.bar("crank", "O", "A", r), Link.bar("rod", "A", "B", l)],
                  slides=[Slide("B", "ground", name="guide")], inputs=[Input.angle("crank")],
                  guess={"B": (2.0, 0.0)})
    th = np.radians(np.arange(0, 361, 1.0))
    sw = kincas.sweep(m, {"crank.angle": th}, report=["B.x", "guide.s"])
    residuals_ok(sw)
    assert np.all(sw.ok)
    x = r * np.cos(th) + np.sqrt(l * l - (r * np.sin(th)) ** 2)
    assert np.abs(sw["B.x"] - x).max() <= 1e-9 * (r + l)


def test_parallelogram_through_its_change_points_stays_a_parallelogram():
    # Start away from the change points (at one of them both branches coincide).
    th = np.radians(np.arange(-170, 191, 1.0))
    C0 = (4 + math.cos(th[0]), math.sin(th[0]))
    sw = kincas.sweep(fourbar(1, 4, 1, 4, C0), {"crank.angle": th},
                      report=["C.x", "C.y", "rocker.angle", "coupler.angle"])
    residuals_ok(sw)
    assert np.all(sw.ok)
    assert np.abs(sw["C.x"] - (4 + np.cos(th))).max() < 1e-9
    assert np.abs(sw["C.y"] - np.sin(th)).max() < 1e-9
    # the change points (everything collinear: crank at 0 and 180 deg) are flagged
    flagged = {round(math.degrees(t)) for t, f in zip(th, sw.flags) if f == "change point"}
    assert flagged == {0, 180}


def test_parallelogram_from_an_imprecise_guess_keeps_its_branch():
    # A guess a little off the assembly leaves Newton's answer 1e-13 off the exact
    # parallelogram; at the change point the tangent is then undefined, and only a predictor
    # that carries the branch straight through (the secant) keeps it.
    th = np.radians(30 + np.arange(360.0))
    m = fourbar(1, 4, 1, 4, (4.868186613007911, 0.5033658839392315))
    sw = kincas.sweep(m.with_guess(B=(0.8700254037844387, 0.5)), {"crank.angle": th},
                      report=["C.x", "C.y"])
    residuals_ok(sw)
    assert np.all(sw.ok)
    assert np.hypot(sw["C.x"] - 4 - np.cos(th), sw["C.y"] - np.sin(th)).max() < 1e-9
    assert [e["kind"] for e in sw.events] == ["change point", "change point"]


@pytest.mark.parametrize("method", ["fast", "careful"])
def test_triple_rocker_over_a_full_turn_stops_at_its_limits_and_resumes(method):
    a, b, c, d = 1, 1.9, 3, 4  # non-Grashof: the crank rocks between +-151.19 deg
    lim = math.acos((a * a + d * d - (b + c) ** 2) / (2 * a * d))
    th = np.radians(np.r_[np.arange(0, 361, 1.0), np.arange(359, -1, -1.0)])
    sw = kincas.sweep(fourbar(a, b, c, d, (3.2, 2.5)), {"crank.angle": th}, report=["C.x", "C.y"],
                      method=method)
    residuals_ok(sw)
    feasible = np.isfinite(closed(th, a, b, c, d, +1)[0])
    assert np.array_equal(sw.ok, feasible)
    assert all(s == "no assembly" for s, f in zip(sw.status, feasible) if not f)
    branch = branch_of(sw, th, a, b, c, d)
    assert np.all(branch[sw.ok] != 0)  # every solved pose is on one of the closed forms
    # within each run of solved poses the branch never changes
    runs = np.split(np.arange(len(th)), np.flatnonzero(np.diff(sw.ok.astype(int))) + 1)
    for run in runs:
        if sw.ok[run[0]]:
            assert len(set(branch[run])) == 1
    # every pose next to the gap is flagged a limit, located exactly
    limits = [e for e in sw.events if e["kind"] == "limit"]
    assert limits
    for e in limits:
        assert abs(abs(np.angle(np.exp(1j * e["inputs"]["crank.angle"]))) - lim) < 1e-9 * lim
        assert sw.flags[e["pose"]] == "limit"
    # each resumption says truthfully which branch it took; the same one exists, so it is it
    resumes = [e for e in sw.events if e["kind"] == "resume"]
    assert resumes
    for e in resumes:
        before = branch[:e["pose"]][sw.ok[:e["pose"]]][-1]
        assert e["branch"] == ("same" if branch[e["pose"]] == before else "other")
        assert e["branch"] == "same"
    assert len(set(branch[sw.ok])) == 1


def test_range_of_motion_to_1e9():
    a, b, c, d = 1, 1.9, 3, 4
    r = input_range(fourbar(a, b, c, d, (3.2, 2.5)), {"crank.angle": 0.3})
    lim = math.acos((a * a + d * d - (b + c) ** 2) / (2 * a * d))
    assert not r.full_turn
    assert abs(r.high - lim) <= 1e-9 * lim and abs(r.low + lim) <= 1e-9 * lim
    assert input_range(fourbar(1, 3.5, 3, 4, (3.6, 2.9)), {"crank.angle": 0.3}).full_turn


def test_range_of_a_driven_rocker_and_of_an_actuator():
    m = Mechanism(ground={"A": (0, 0), "D": (4, 0)},
                  links=[Link.bar("crank", "A", "B", 1), Link.bar("coupler", "B", "C", 3.5),
                         Link.bar("rocker", "D", "C", 3)], inputs=[Input.angle("rocker")],
                  guess={"B": (0, 1)})
    r = input_range(m, {"rocker.angle": 1.9})
    # rocker dead centres: |AC| = coupler +- crank, C on the circle of radius 3 about D
    ends = sorted(math.pi - math.acos((16 + 9 - dist ** 2) / 24) for dist in (4.5, 2.5))
    assert abs(r.low - ends[0]) <= 1e-9 * ends[0] and abs(r.high - ends[1]) <= 1e-9 * ends[1]
    act = Mechanism(parameters={"len": 5.0}, ground={"O": (0, 0), "P": (6, 0)},
                    links=[Link.bar("act", "O", "E", "len"), Link.bar("arm", "P", "E", 2.0)],
                    inputs=[Input.parameter("len")], guess={"E": (5, 1)})
    r = input_range(act, {"len": 5.0})
    assert abs(r.low - 4.0) < 1e-9 * 4 and abs(r.high - 8.0) < 1e-9 * 8


def test_unknown_method_is_an_error():
    with pytest.raises(kincas.ModelError, match="method"):
        kincas.sweep(fourbar(1, 3.5, 3, 4, (3.6, 2.9)), {"crank.angle": [0.0]}, method="quick")
