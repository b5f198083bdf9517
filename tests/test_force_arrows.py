"""Arrows the forces overlay (kincas/views/forces.py) draws that it used to leave out, against
values worked out by hand: each link's weight m g at its centre of gravity, and a parameter
input's effort (a linear actuator's force) along the actuator's line."""
from __future__ import annotations

import numpy as np

import kincas
from kincas.views.forces import overlay, weights
from kincas.views.poses import geometry

G = 9.81


def pendulum(cg=None):
    """A bar O-A of length 2 and mass 3 turning about O under gravity (0, -g)."""
    extra = {} if cg is None else {"cg": cg}
    return kincas.Mechanism(ground={"O": (0, 0)},
                            links=[kincas.Link.bar("bar", "O", "A", 2, mass=3, **extra)],
                            inputs=[kincas.Input.angle("bar")], gravity=(0, -G))


def test_a_weight_is_m_g_at_the_centre_of_gravity():
    th = np.array([0.0, 0.7, 2.0, -1.2])
    m = pendulum()
    sw = kincas.sweep(m, {"bar.angle": th})
    (w,) = [a for a in weights(m, geometry(m, sw))]
    assert w.label == "weight of bar"
    np.testing.assert_allclose(w.vec, np.tile([0, -3 * G], (4, 1)))  # m g
    np.testing.assert_allclose(w.at, np.stack([np.cos(th), np.sin(th)], axis=1), atol=1e-12)  # the middle


def test_a_weight_at_a_given_centre_of_gravity_turns_with_the_link():
    th = np.array([0.0, 0.7, 2.0])
    m = pendulum(cg=(0.5, 0.25))  # in the bar's frame: 0.5 along it, 0.25 to its left
    sw = kincas.sweep(m, {"bar.angle": th})
    w = next(a for a in overlay(m, sw).arrows if a.label == "weight of bar")
    want = np.stack([0.5 * np.cos(th) - 0.25 * np.sin(th), 0.5 * np.sin(th) + 0.25 * np.cos(th)], axis=1)
    np.testing.assert_allclose(w.at, want, atol=1e-12)
    np.testing.assert_allclose(w.vec[:, 1], -3 * G)


def test_no_gravity_no_weights():
    m = kincas.Mechanism(ground={"O": (0, 0)}, links=[kincas.Link.bar("bar", "O", "A", 2, mass=3)],
                         inputs=[kincas.Input.angle("bar")])
    sw = kincas.sweep(m, {"bar.angle": [0.3]})
    assert weights(m, geometry(m, sw)) == []


def test_an_actuators_effort_is_drawn_along_it_and_balances_the_load():
    """A crank O-A (length 1) held by an actuator G-A of length s (the input) against a force F
    at A. Moments about O: A x (f u) + A x F = 0, so the actuator's force on A is f u with
    f = -(A x F) / (A x u), u the unit vector from G to A."""
    F = np.array([3.0, -5.0])
    m = kincas.Mechanism(
        ground={"O": (0, 0), "G": (-2, -1)},
        links=[kincas.Link.bar("crank", "O", "A", 1), kincas.Link.bar("jack", "G", "A", "s")],
        parameters={"s": 2.5}, inputs=[kincas.Input.parameter("s")], guess={"A": (0.2, 0.95)},
        loads=[kincas.Load.force("A", tuple(F))])
    s = np.linspace(2.3, 2.8, 5)
    sw = kincas.sweep(m, {"s": s})
    assert sw.ok.all()
    (arrow,) = [a for a in overlay(m, sw).arrows if a.label == "effort(s)"]
    geo = geometry(m, sw)
    A, Gp = geo.point("A"), geo.point("G")
    np.testing.assert_allclose(arrow.at, A)
    u = (A - Gp) / np.linalg.norm(A - Gp, axis=1)[:, None]
    cross = lambda a, b: a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]  # noqa: E731
    f = -cross(A, np.tile(F, (5, 1))) / cross(A, u)
    np.testing.assert_allclose(arrow.vec, f[:, None] * u, rtol=1e-8, atol=1e-9)
