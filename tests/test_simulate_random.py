"""Energy of random mechanisms (tests/random_mechanisms.py) moving freely under their own
constant forces, torques, springs and gravity: every load is conservative, so kinetic plus
potential energy, written here from the points' positions and velocities that kincas reports
(each centre of gravity placed by its link's angle), stays constant along kincas.simulate."""
from __future__ import annotations

import numpy as np
import pytest

from kincas.analysis.simulate import simulate
from random_mechanisms import case

FAMILIES = ["fourbar_grashof", "slider_crank", "watt", "five_bar", "inverted_slider"]


def _energy(c, r):
    m, v = c.mech, r.values
    val = m.value
    gx, gy = (val(g) for g in m.gravity)
    T = V = 0.0
    for lk in m.links:
        P = lk.point_names[0]
        th = np.unwrap(v[f"{lk.name}.angle"])
        w = v[f"{lk.name}.omega"]
        i = lk.inertial
        cg = (np.array([val(i.cg[0]), val(i.cg[1])]) if i.cg is not None
              else np.mean([[val(x), val(y)] for _, (x, y) in lk.points], axis=0))
        d = cg - c.local(lk.name, P)  # P to G in the link's frame, then turned by its angle
        dx, dy = np.cos(th) * d[0] - np.sin(th) * d[1], np.sin(th) * d[0] + np.cos(th) * d[1]
        vx, vy = v[f"{P}.vx"] - w * dy, v[f"{P}.vy"] + w * dx
        mass, J = val(i.mass), val(i.inertia)
        T = T + 0.5 * mass * (vx ** 2 + vy ** 2) + 0.5 * J * w ** 2
        V = V - mass * (gx * (v[f"{P}.x"] + dx) + gy * (v[f"{P}.y"] + dy))
    for ld in m.loads:
        if ld.kind == "force":
            V = V - val(ld.value[0]) * v[f"{ld.at}.x"] - val(ld.value[1]) * v[f"{ld.at}.y"]
        elif ld.kind == "torque":
            V = V - val(ld.value) * np.unwrap(v[f"{ld.at}.angle"])
        else:
            a, b = ld.points
            dist = np.hypot(v[f"{a}.x"] - v[f"{b}.x"], v[f"{a}.y"] - v[f"{b}.y"])
            V = V + 0.5 * val(ld.stiffness) * (dist - val(ld.free_length)) ** 2
    return T, V


def _report(c):
    m = c.mech
    pts = set(m.moving_points) | set(m.ground_points)
    out = []
    for lk in m.links:
        out += [f"{lk.name}.angle", f"{lk.name}.omega"]
    for p in pts:
        out += [f"{p}.x", f"{p}.y", f"{p}.vx", f"{p}.vy"]
    return out


@pytest.mark.parametrize("family", FAMILIES)
def test_energy_is_conserved_on_random_mechanisms(family):
    c = case(family, 0)
    u0 = {k: float(v[0]) for k, v in c.inputs.items()}
    # a time scale: the inputs move about 0.3 rad (or 0.3 sizes) from rest
    probe = simulate(c.mech, 1e-9, 2, initial=u0, report=[])
    acc = max(abs(probe.accelerations[k][0]) / u for k, u in zip(c.keys, c.units))
    duration = 2 * np.sqrt(0.3 / acc)
    r = simulate(c.mech, duration, 101, initial=u0, report=_report(c), tolerance=1e-12)
    ok = r.status == "ok"
    assert ok.sum() > 10, (c.label, r.events)
    T, V = _energy(c, r)
    T, V = T[ok], V[ok]
    E = T + V
    assert np.ptp(T) > 0, c.label
    assert np.max(np.abs(E - E[0])) < 1e-9 * np.ptp(T), c.label  # (about 5e-11 measured)
