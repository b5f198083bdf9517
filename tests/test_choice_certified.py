"""A sweep without a guess chooses among certified assemblies (kincas/analysis/choice.py with
msolve installed): every assembly of the first pose, proven, is a candidate.

Independent answers written here: the Whitworth quick return's four assemblies and which of
them run every pose (tests/test_guess_branch.py's circle and line intersections); a four-bar
carrying a dyad whose two assemblies per four-bar mode are circle intersections, where the
dyad's reach fails one four-bar mode at +90 deg and the other at -90 deg, so that none of the
four runs the whole sweep. Skipped without msolve."""
from __future__ import annotations

import math

import numpy as np
import pytest

import kincas
import kincas.analysis.choice as choice
from kincas import Input, Link, Mechanism
from kincas.analysis import certify_msolve
from test_guess_branch import chosen, whitworth_assemblies, whitworth_without_guess

needs_msolve = pytest.mark.skipif(not certify_msolve.available(),
                                  reason='msolve not installed (pip install "kincas[certify]")')


@needs_msolve
def test_whitworth_chooses_among_certified_assemblies():
    sc = whitworth_without_guess()
    sw = sc.run()
    th = sw.inputs["crank.angle"]
    assert len(sw) == 73 and sw.ok.all()
    [e] = chosen(sw)
    assert e["certified"] is True and e["count"] == len(whitworth_assemblies(th[0])) == 4
    assert "certified" in e["reason"] and "fails 11 of 73" in e["reason"]
    # the chosen one is one of the two with the lever towards the pin: each runs every pose
    D0 = np.array([sw["D.x"][0], sw["D.y"][0]])
    assert min(np.abs(D0 - w["D"]).max() for w in whitworth_assemblies(th[0])[:2]) <= 1e-9 * 150


@needs_msolve
def test_certified_choice_finds_what_a_starved_multistart_misses(monkeypatch):
    """With one start (the default assembly itself) the multistart sees no other assembly and
    the sweep keeps losing 11 poses; certified, the other assemblies are all there."""
    monkeypatch.setattr(choice, "CHOICE_STARTS", 1)
    monkeypatch.setattr(certify_msolve, "available", lambda: False)
    sw = whitworth_without_guess().run()
    assert int((~sw.ok).sum()) == 11 and not chosen(sw)
    monkeypatch.undo()
    monkeypatch.setattr(choice, "CHOICE_STARTS", 1)
    sw = whitworth_without_guess().run()
    assert sw.ok.all() and chosen(sw)[0]["certified"] is True


G, ARM, LINK = np.array([7.0, 0.0]), 3.0, 2.2


def fourbar_dyad():
    return Mechanism(ground={"A": (0, 0), "D": (4, 0), "G": tuple(G)},
                     links=[Link.bar("crank", "A", "B", 1), Link.bar("coupler", "B", "C", 4),
                            Link.bar("rocker", "D", "C", 3), Link.bar("arm", "C", "E", ARM),
                            Link.bar("link", "G", "E", LINK)], inputs=[Input.angle("crank")])


def coupler_points(th):
    """C for both four-bar modes: |C - B| = 4, |C - D| = 3 (a circle intersection)."""
    B, D = np.array([math.cos(th), math.sin(th)]), np.array([4.0, 0.0])
    d = D - B
    L = np.linalg.norm(d)
    x = (16 - 9 + L * L) / (2 * L)
    h = math.sqrt(16 - x * x)
    e = d / L
    return [B + x * e + s * h * np.array([-e[1], e[0]]) for s in (1, -1)]


@needs_msolve
def test_no_certified_assembly_runs_the_sweep_said_with_certainty():
    th = np.radians([0, 45, 90, 45, 0, -45, -90])
    reach = lambda C: abs(ARM - LINK) <= np.linalg.norm(C - G) <= ARM + LINK
    # independent: 2 four-bar modes x 2 dyad modes at 0; mode 1 loses +90, mode 2 -90
    assert all(reach(C) for C in coupler_points(0.0))
    up90, down90 = coupler_points(math.pi / 2)
    up_90, down_90 = coupler_points(-math.pi / 2)
    assert reach(up90) and not reach(down90) and not reach(up_90) and reach(down_90)
    sw = kincas.sweep(fourbar_dyad(), {"crank.angle": th}, report=["C.y"])
    assert not sw.ok.all()
    [e] = chosen(sw)
    assert e["certified"] is True and e["count"] == 4 and e["groups"] == []
    assert "none of the first pose's 4 assemblies" in e["reason"] and "default stands" in e["reason"]
    assert sw["C.y"][0] == pytest.approx(max(C[1] for C in coupler_points(0.0)), abs=1e-9)  # the default
