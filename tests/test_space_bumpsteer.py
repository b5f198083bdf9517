"""`kincas optimize` on a spatial mechanism: the tie rod's inner end of a double-wishbone
corner placed for least bump steer (examples/space_suspension_bumpsteer.toml). Checked apart
from the optimiser: the objective re-evaluated by plain sweeps of the scene (toe from the
upright's rotation matrix), its gradient by central differences at the optimum (tests only),
and the assembly kept. Also the determinant behind the branch rows of the NLP, against numpy."""
from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

import kincas
from conftest import EXAMPLES, run_cli
from kincas.core.nlp import determinant

SCENE = EXAMPLES / "space_suspension_bumpsteer.toml"


def toe_sum(trz, tl):
    """sum over the scene's travel of toe^2 (deg^2), toe = atan2(R12, R22), by a plain sweep."""
    sc = kincas.scene.load(SCENE)
    m = sc.mechanism.with_parameters(trz=trz, tl=tl)
    sw = kincas.sweep(m, dict(sc.study.inputs), report=["upright.R12", "upright.R22"])
    assert sw.ok.all() and sw.residual.max() < 1e-12
    toe = np.degrees(np.arctan2(sw["upright.R12"], sw["upright.R22"]))
    return float(np.sum(toe ** 2)), toe


def test_bump_steer_optimum_is_a_minimum_of_the_swept_objective(capsys):
    code, out, err = run_cli(capsys, "optimize", SCENE, "--json")
    assert code == 0 and out["ok"], err
    trz, tl = out["parameters"]["trz"], out["parameters"]["tl"]
    f0, toe0 = toe_sum(260.0, 380.13155617496426)
    f1, toe1 = toe_sum(trz, tl)
    assert abs(f0 - out["initial_objective"]) < 1e-9 * f0 and abs(f1 - out["objective"]) < 1e-6 * f0
    assert np.ptp(toe0) > 4 and np.abs(toe1).max() < 0.1  # the example's comment
    h = 1e-3  # mm; the objective is smooth here: its gradient vanishes at the optimum
    g = [(toe_sum(trz + h, tl)[0] - toe_sum(trz - h, tl)[0]) / (2 * h),
         (toe_sum(trz, tl + h)[0] - toe_sum(trz, tl - h)[0]) / (2 * h)]
    g0 = (toe_sum(260 + h, 380.13155617496426)[0] - toe_sum(260 - h, 380.13155617496426)[0]) / (2 * h)
    assert max(map(abs, g)) < 1e-4 * abs(g0), (g, g0)


@pytest.mark.parametrize("n", [1, 2, 5, 9])
def test_determinant_by_shared_minors_equals_numpys(n):
    rng = np.random.default_rng(n)
    A = rng.normal(size=(n, n)) * (rng.random((n, n)) < 0.5) + np.diag(rng.normal(size=n))
    X = ca.SX.sym("x", n, n)
    M = ca.SX.zeros(n, n)
    for i, j in zip(*np.nonzero(A)):
        M[int(i), int(j)] = X[int(i), int(j)]  # structural zeros stay zeros (they are skipped)
    d = float(ca.Function("d", [ca.vec(X)], [determinant(M)])(A.ravel(order="F")))
    assert math.isclose(d, np.linalg.det(A), rel_tol=1e-12, abs_tol=1e-12)
