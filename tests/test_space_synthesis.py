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
