"""The first pose of a sweep solved in the fast kernel from the placed guess (issue [8]).

The guess chooses the branch: the kernel's answer is accepted only where it is the careful
path's (`kincas.core.assembly.first_pose`), so every guess, good or poor, near either branch
or near the fold between them, gives the careful path's pose to 1e-12, and both equal the
circle intersection on the branch the careful path took.
"""
import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism
from kincas.analysis.prepared import prepared
from kincas.core.assembly import first_pose
from kincas.core.fast import sweeper_for


def circle_C(th, a, b, c, d):
    """Both assemblies of the four-bar's C (left and right of B -> D), by circle intersection."""
    B, D = np.array([a * np.cos(th), a * np.sin(th)]), np.array([d, 0.0])
    e = D - B
    r = np.hypot(*e)
    x = (b * b - c * c + r * r) / (2 * r)
    h = np.sqrt(b * b - x * x)
    e, n = e / r, np.array([-e[1], e[0]]) / r
    return B + x * e + h * n, B + x * e - h * n


def fourbar(guess, a=1.0, b=3.5, c=3.0, d=4.0):
    return Mechanism(ground={"A": (0, 0), "D": (d, 0)},
                     links=[Link.bar("crank", "A", "B", a), Link.bar("coupler", "B", "C", b),
                            Link.bar("rocker", "D", "C", c)],
                     inputs=[Input.angle("crank")], guess={"C": tuple(guess)})


def guesses(th):
    """Guessed C from one assembly to the other across the fold (the line B-D, where both
    meet), and far off to either side."""
    up, down = circle_C(th, 1.0, 3.5, 3.0, 4.0)
    ts = np.r_[np.linspace(-0.5, 1.5, 41), 0.4999, 0.5001]
    mid, n = (up + down) / 2, np.array([-(up - down)[1], (up - down)[0]])
    return [up + t * (down - up) for t in ts] + [mid + s * n for s in (-0.3, 0.3, 3.0)]


@pytest.mark.parametrize("th", [0.3, 2.0, -2.6])
def test_kernel_first_pose_is_the_careful_pose_for_any_guess(th):
    report = ["C.x", "C.y", "C.vx", "C.vy"]
    up, down = circle_C(th, 1.0, 3.5, 3.0, 4.0)
    accepted = rejected = 0
    for G in guesses(th):
        m = fourbar(G)
        model = kincas.model_of(m)
        pm, u = prepared(model, m), np.array([th])
        want = first_pose(model, u, pm.p, pm.size, pm.guess)
        fast = sweeper_for(model, tuple(report), False)
        run = kincas.core.fast.FastRun(fast, u[None], pm.p, pm.size)
        got = fast._from_guess(run, 0, pm.placement(model, u, pm.guess), 1)
        if got == 1:  # accepted: the careful path's pose, to rounding
            accepted += 1
            assert want.ok
            assert np.abs(run.Q[0] - want.q).max() < 1e-12
        else:  # left to the careful path, nothing of the attempt kept
            rejected += 1
            assert np.isnan(run.Q[0]).all() and not run.solved[0]
        # the whole sweep (kernel first) against the careful path alone, and the closed form
        ths = th + np.linspace(0, 0.2, 5)
        sw = kincas.sweep(m, {"crank.angle": ths}, report=report, compile=False)
        ref = kincas.sweep(m, {"crank.angle": ths}, report=report, method="careful")
        assert sw.status.tolist() == ref.status.tolist()
        for k in report:
            assert np.allclose(sw[k], ref[k], rtol=0, atol=1e-12, equal_nan=True)
        if want.ok:
            C = np.array([sw["C.x"][0], sw["C.y"][0]])
            assert min(np.abs(C - up).max(), np.abs(C - down).max()) < 1e-12
    assert accepted >= 10 and rejected >= 1  # both ways were taken


# guesses from which the kernel's Newton, were its answer not checked, converges to a pose
# other than the careful path's (found among 1,600 random guesses): they must be refused
@pytest.mark.parametrize("th, G", [(2.0, (7.74610694, 0.31767392)), (1.0, (-4.01969978, 3.48102958))])
def test_a_guess_where_plain_newton_leaves_the_careful_answer_goes_to_the_careful_path(th, G):
    m = fourbar(G)
    model = kincas.model_of(m)
    pm, u = prepared(model, m), np.array([th])
    want = first_pose(model, u, pm.p, pm.size, pm.guess)
    fast = sweeper_for(model, ("C.x", "C.y"), False)
    run = kincas.core.fast.FastRun(fast, u[None], pm.p, pm.size)
    if fast._from_guess(run, 0, pm.placement(model, u, pm.guess), 1) == 1:
        assert np.abs(run.Q[0] - want.q).max() < 1e-12
    sw = kincas.sweep(m, {"crank.angle": [th, th + 0.01]}, report=["C.x", "C.y"], compile=False)
    assert np.abs(sw.q[0] - want.q).max() < 1e-12


def test_placement_is_kept_per_mechanism_and_inputs():
    m = fourbar((3.6, 2.9))
    model = kincas.model_of(m)
    pm = prepared(model, m)
    a = pm.placement(model, np.array([0.2]), pm.guess)
    assert pm.placement(model, np.array([0.2]), pm.guess) is a  # placed once
    assert pm.placement(model, np.array([0.3]), pm.guess) is not a
    other = fourbar((3.6, -2.9))  # another mechanism of the same structure: its own guess
    assert prepared(model, other) is not pm
    q_other = prepared(model, other).placement(model, np.array([0.2]), prepared(model, other).guess)
    assert not np.allclose(q_other.q0, a.q0)
    with pytest.raises(ValueError):
        a.q0[0] = 1.0  # read-only: shared by threads


# --- the correction bound is per Assur group, not summed over a chain ---


def test_chain_first_pose_in_kernel_with_per_group_correction(monkeypatch):
    """Eight chained four-bars (benchmarks/cases.py) from a guess a little off every assembly: each
    group's Newton moves about 0.1 of its scale, so the sum over the chain (about 1) exceeds
    CORRECTION while each group stays within it. The bound must be per group (the chain is
    block triangular): the kernel then takes the first pose, and its answer is the careful
    path's, on the same branch, to rounding."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    import cases
    from kincas.core import fast

    from dataclasses import replace

    c = cases.chain(8, 20)
    off = {k: (x + 0.15, y - 0.1) for k, (x, y) in c.guess.items() if k != "A"}
    m = cases.to_kincas(replace(c, guess={**c.guess, **off}))
    rep = cases.kincas_report(c)
    taken = []
    orig = fast.FastSweeper._from_guess

    def spy(self, r, k, placed, stop):
        out = orig(self, r, k, placed, stop)
        taken.append(out > k)
        return out

    monkeypatch.setattr(fast.FastSweeper, "_from_guess", spy)
    fast_sw = kincas.sweep(m, {"crank.angle": c.theta}, report=rep, method="fast")
    careful = kincas.sweep(m, {"crank.angle": c.theta}, report=rep, method="careful")
    assert taken and taken[0], "the first pose went to the careful path"
    assert fast_sw.ok.all() and careful.ok.all()
    for name in rep:
        np.testing.assert_allclose(fast_sw[name], careful[name], rtol=0, atol=1e-12 * c.size)
