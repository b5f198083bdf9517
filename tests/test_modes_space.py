"""The multistart search (`kincas modes`, `find_modes`) on spatial mechanisms: assemblies that
differ only in a body's spin about the line of its points.

The double Cardan shaft at in.angle = 0: shaft_in is fixed by the input, O2 by the output's
revolute (O3 - 150 x, whatever it turns), so the intermediate shaft can only spin by phi about
its line O1 O2, and the output by psi about x. Cross 1 asks (y) . (R_mid z) = 0, where
R_mid z = cos(phi) z + sin(phi) d x z and y . (d x z) = -d_x != 0: sin(phi) = 0. Cross 2 asks
(R_mid z) . (R_out y) = +-z . (cos(psi) y + sin(psi) z) = 0: sin(psi) = 0. Four assemblies
(phi, psi in {0, pi}), every one with the same points: a search that tells modes apart by
points alone (it did, and found 1 of 4) must also compare the bodies' orientations.
"""
from __future__ import annotations

import numpy as np
import pytest

import kincas
import kincas.cli.scene
from conftest import EXAMPLES, run_cli
from kincas.analysis.modes import find_modes

CARDAN = EXAMPLES / "space_double_cardan.toml"


def rotations(md, body, m):
    """The body's rotation matrix at the mode, read as its quantities L.R11 .. L.R33 (a body
    hung on a revolute has no quaternion among the unknowns: kincas/model/space_tree.py)."""
    model = kincas.model_of(m)
    names = tuple(f"{body}.R{i}{k}" for i in (1, 2, 3) for k in (1, 2, 3))
    u = np.array([[md.inputs[i.key] for i in m.inputs]])
    p = np.array([v for _, v in m.parameters], float)
    return model.quantities(names, np.asarray(md.q, float)[None], u, p, 0 * u, 0 * u)[:, 0].reshape(3, 3)


def test_double_cardan_four_modes_told_apart_by_orientation():
    m = kincas.cli.scene.load(CARDAN).mechanism
    found = find_modes(m, {"in.angle": 0.0}, starts=64)
    assert len(found) == 4
    d = np.array([181.26155740732997, 84.52365234813989, 0.0])
    d /= np.linalg.norm(d)
    seen = set()
    for md in found:
        Rm, Ro = rotations(md, "mid", m), rotations(md, "shaft_out", m)
        # the independent answer: R_mid a rotation by 0 or pi about d, R_out by 0 or pi about x
        phi = next(a for a in (0.0, np.pi) if np.allclose(Rm, kincas.core.space_model.axis_rotation(d, a), atol=1e-9))
        psi = next(a for a in (0.0, np.pi) if np.allclose(Ro, kincas.core.space_model.axis_rotation([1, 0, 0], a), atol=1e-9))
        seen.add((phi, psi))
        assert np.allclose(md.points["O2"], [181.26155740732997, 84.52365234813989, 0.0], atol=1e-9)
    assert len(seen) == 4
    assert sum(md.from_guess for md in found) == 1  # the guess's assembly: one of the four


@pytest.mark.slow
def test_double_cardan_cli_modes_count(capsys):
    code, out, err = run_cli(capsys, "modes", CARDAN)  # plain: 512 starts
    assert code == 0 and "4 assembly modes" in out and "cannot pick between them" in out


def test_double_cardan_multistart_matches_the_certified_count():
    from kincas.analysis import certify_msolve
    if not certify_msolve.available():
        pytest.skip('msolve not installed (pip install "kincas[certify]")')
    m = kincas.cli.scene.load(CARDAN).mechanism
    u = 0.7  # (0 is the CLI test's)
    assert len(find_modes(m, {"in.angle": u}, starts=64)) == kincas.modes(m, {"in.angle": u}, certify=True).count == 4


@pytest.mark.parametrize("angle, starts, seed", [(np.pi / 2, 16, 0), (np.pi / 4, 64, 1)])
def test_double_cardan_multistart_survives_a_start_with_a_singular_normal_matrix(angle, starts, seed):
    """At 90 deg, one of 16 scattered starts met a singular J'J: casadi's QR inside the mapped
    step failed the whole call ('map16_newton_step ... Evaluation failed', a traceback from
    `kincas modes`). Such a start is dropped; the four assemblies are still found, each a
    solution: the residual of every equation recomputed here from its unknowns."""
    m = kincas.cli.scene.load(CARDAN).mechanism
    found = find_modes(m, {"in.angle": angle}, starts=starts, seed=seed)
    assert len(found) == 4
    model = kincas.model_of(m)
    for md in found:
        g = model.residual(np.asarray(md.q, float), np.array([angle]), model.sym.p0 if hasattr(model.sym, "p0") else
                           np.asarray([m.param_values[k] for k in model.sym.mech.param_values], float))
        assert np.abs(g).max() < 1e-9 * 200


def test_multistart_finds_both_assemblies_of_the_spatial_slider_crank():
    """The slider's second assembly lies 2 d.(C - B) = 279.6 mm from the drawn one along its
    line, beyond the size (150 mm) that once bounded the starts of a slide: 16 starts missed
    it in most runs. The two roots of |C0 + s d - B|^2 = 150^2, written here, at every seed."""
    import kincas
    sc = kincas.scene.load(EXAMPLES / "space_slider_crank.toml")
    m = sc.mechanism
    C0 = np.array([154.4018940888198, 68.88037881776397, 68.32056822664595])
    d = np.array([0.9407208683835973, 0.18814417367671946, 0.28221626051507914])
    B = np.array([40.0, 0.0, 0.0])  # the crank at 0 deg, as drawn
    b, c = d @ (C0 - B), (C0 - B) @ (C0 - B) - 150.0 ** 2
    roots = sorted(-b + k * np.sqrt(b * b - c) for k in (-1, 1))
    for seed in range(8):
        modes = kincas.find_modes(m, {"A.angle": 0.0}, starts=16, seed=seed)
        got = sorted((np.array(md.points["C"]) - C0) @ d for md in modes)
        assert np.allclose(got, roots, atol=1e-9), (seed, got, roots)
