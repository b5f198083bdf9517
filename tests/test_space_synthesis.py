"""`optimize` on a spatial scene ([16]: "optimize ... must work in 3D, exactly as in 2D"): the
simultaneous optimiser took a spatial guess (3 coordinates) as planar and raised. Checked by
sweeps around the answer: the objective is larger on both sides (a local minimum), and the
optimised design assembles at every sample."""
from __future__ import annotations

import numpy as np

import kincas
from kincas.cli.scene import loads
from conftest import ROOT


def test_optimize_moves_a_spatial_bar_to_a_local_minimum():
    text = (ROOT / "examples" / "space_rssr.toml").read_text(encoding="utf-8")
    text = text.replace('length = 125 }', 'length = "L" }').replace("[ground]", "[parameters]\nL = 125\n\n[ground]")
    m = loads(text).mechanism
    key, u = m.inputs[0].key, np.linspace(0, 2 * np.pi, 37)

    def cost(L):
        sw = kincas.sweep(m.with_parameters(L=L), {key: u}, report=["C.z"])
        assert sw.ok.all()
        return float(np.mean((sw["C.z"] - 70) ** 2))

    r = kincas.optimize(m, {key: u}, vary={"L": (110, 130.5)}, minimize="mean((C.z - 70)^2)")
    assert r.success, r
    L = r.varied["L"]
    assert 110 < L < 130.5
    c = cost(L)
    assert cost(L - 0.5) > c and cost(L + 0.5) > c  # a minimum, by independent sweeps


def test_modes_of_a_tall_spatial_system_are_found_not_a_crash():
    """`kincas modes` (multistart) on a redundant spatial chain (double Cardan: 22 equations,
    21 unknowns) raised casadi's 'A not square'; each mode found closes the loops and the
    scene's own guess is among them."""
    from kincas.cli.scene import load
    sc = load(ROOT / "examples" / "space_double_cardan.toml")
    inputs = {k: np.asarray(v, float)[:1] for k, v in sc.study.inputs.items()}
    found = kincas.find_modes(sc.mechanism, inputs, starts=64)
    assert len(found) >= 1 and any(md.from_guess for md in found)
    assert all(md.residual < 1e-10 for md in found)
    assert all(len(xyz) == 3 for md in found for xyz in md.points.values())
