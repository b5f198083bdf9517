"""Tall spatial systems (redundant joints: Bennett's linkage, a spherical four-bar, the double
Cardan) take the fast pass (Gauss-Newton inside the kernel, kincas/core/blocks.py): it agrees
with the careful path and with the closed forms of tests/test_space.py to 1e-12, and the
kernel's conditioning measure of a tall group bounds the SVD's from below within sqrt(n)."""
from pathlib import Path

import casadi as ca
import numpy as np

import kincas
from kincas.cli.scene import load
from kincas.core.blocks import block_measures
from kincas.core.structure import Block
from test_space import B0, C0, W, bennett, bennett_theta2, rotate, spherical, wrap

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def both(m, inputs, report):
    fast = kincas.sweep(m, inputs, report=report)
    careful = kincas.sweep(m, inputs, report=report, method="careful")
    assert fast.info["fast pass"] is not None  # the kernel ran (no longer square-only)
    assert fast.ok.all() and careful.ok.all() and fast.residual.max() < 1e-12
    for name in report:
        assert np.abs(wrap(fast[name] - careful[name])).max() < 1e-12, name
    return fast


def test_bennett_fast_pass_agrees_with_careful_path_and_bennetts_relation():
    t10 = 1.0
    u = np.linspace(0, 1.8, 61)
    sw = both(bennett(t10), {"O1.angle": u}, ["O2.angle", "O3.angle", "O4.angle"])
    want = np.array([bennett_theta2(t) for t in t10 + u]) - bennett_theta2(t10)
    assert np.abs(wrap(sw["O2.angle"] - want)).max() < 1e-12
    assert np.abs(wrap(sw["O3.angle"] + u)).max() < 1e-12  # th3 = -th1


def test_spherical_four_bar_fast_pass_keeps_its_closure():
    th = np.linspace(0, 2 * np.pi, 73)
    sw = both(spherical(), {"J1.angle": th}, ["J4.angle"])
    for t, phi in zip(th, sw["J4.angle"]):  # b(th).c(phi) = b0.c0 (the coupler's arc)
        assert abs(rotate(B0, np.array([0, 0, 1.0]), t) @ rotate(C0, W, phi) - B0 @ C0) < 1e-13


def test_double_cardan_fast_pass_turns_its_output_with_its_input():
    m = load(EXAMPLES / "space_double_cardan.toml").mechanism
    key = m.inputs[0].key
    th = np.linspace(0, 2 * np.pi, 91)
    sw = both(m, {key: th}, ["out.angle"])
    assert np.abs(wrap(sw["out.angle"] - th)).max() < 1e-12  # out.angle = in.angle


def test_tall_block_sigma_bounds_the_smallest_singular_value():
    rng = np.random.default_rng(3)
    for scale in (1.0, 1e-6):  # near singular too: a column nearly dependent
        A = rng.normal(size=(9, 6))
        A[:, 5] = A[:, 4] + scale * rng.normal(size=9)
        _, rel = block_measures(ca.DM(A), np.ones(6), [Block(np.arange(9), np.arange(6), ())])
        sv = np.linalg.svd(A, compute_uv=False)
        lb = float(rel) * max(1.0, np.linalg.norm(A))  # relative to max(1, ||A||_F)
        assert sv[-1] / np.sqrt(6) * (1 - 1e-9) <= lb <= sv[-1] * (1 + 1e-9)


def test_spatial_watch_measure_is_scale_free_and_ignores_equation_factors():
    # A quaternion's norm equation (2 L e) and a revolute's axis equations carry factors of
    # their own: the suspension's group (the upper wishbone's angle, the upright's r and e)
    # measures ~0.1 at every pose (the RSSR's quaternion group measured 0.5 before the tree
    # reduction). The watch measure scales each block's columns and rows to unit length:
    # independent of the unknowns' units and of L, above the raw measure, 0 where the block
    # is singular.
    from kincas.analysis.continuation import watch_conditioning
    from kincas.core.assembly import modes
    m = load(EXAMPLES / "space_suspension.toml").mechanism
    model = kincas.model_of(m)
    th = np.radians(np.linspace(-8, 8, 9))
    sw = kincas.sweep(m, {m.inputs[0].key: th}, report=["W.x"], method="careful")
    p = np.array([v for _, v in m.parameters], float)
    J = np.array([model.jac(q, np.array([t]), p) for q, t in zip(sw.q, th)])
    w = watch_conditioning(model, J, m.size())
    quat = [i for i, b in enumerate(model.blocks) if "quaternion" in [model.unknown_kinds[j] for j in b.cols]]
    assert quat and (w[:, quat] > 2 * modes(model, J, m.size())[1][:, quat]).all()
    rng = np.random.default_rng(5)
    Jr = J * rng.uniform(0.1, 10, size=(1, 1, J.shape[2]))  # other units for the unknowns, another L
    assert np.allclose(watch_conditioning(model, Jr, 7.0), w, rtol=1e-10)
    b = max(model.blocks, key=lambda b: len(b.cols))
    Js = J[0].copy()
    Js[np.ix_(b.rows, [b.cols[-1]])] = Js[np.ix_(b.rows, [b.cols[-2]])]  # a column copied: singular
    assert watch_conditioning(model, Js[None], m.size())[0, list(model.blocks).index(b)] < 1e-12


def test_rssr_reduced_to_its_rocker_angle_is_watched_as_a_planar_group():
    # one 1 x 1 group: d/dphi of the bar's (|C - B|^2 - lc^2) / lc, over the size (125): by hand
    # with C = D + R (0, -sin phi, cos phi), B = r (cos th, sin th, 0)
    from kincas.analysis.continuation import watch_conditioning
    from test_space import D, LC, R_CRANK, R_ROCK, rssr
    m = rssr()
    model = kincas.model_of(m)
    th = np.linspace(0, 2 * np.pi, 13)
    sw = kincas.sweep(m, {"A.angle": th}, report=["D.angle"], method="careful")
    J = np.array([model.jac(q, np.array([t]), np.array([LC])) for q, t in zip(sw.q, th)])
    phi = sw["D.angle"]
    C = D + R_ROCK * np.stack([0 * phi, -np.sin(phi), np.cos(phi)], 1)
    B = R_CRANK * np.stack([np.cos(th), np.sin(th), 0 * th], 1)
    dC = R_ROCK * np.stack([0 * phi, -np.cos(phi), -np.sin(phi)], 1)
    assert m.size() == LC and [len(b.cols) for b in model.blocks] == [1]
    want = np.abs(2 * ((C - B) * dC).sum(1) / LC) / LC
    assert np.allclose(watch_conditioning(model, J, m.size())[:, 0], want, rtol=1e-12)
