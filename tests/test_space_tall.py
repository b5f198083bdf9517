"""The tall examples (redundant joints: Bennett's linkage, the spherical four-bar, the double
Cardan shaft) swept by the compiled fast pass over a full turn: positions against closed
forms to 1e-12, velocities against the closed forms' derivatives, every equation's residual
(the redundant ones too) recomputed at every pose, and the pass compiled when asked.

Their kernel (kincas/core/kernel.py, `_exact_where_needed`) is small enough to compile: the
Gauss-Newton step and the conditioning measure share one symbolic Cholesky factor, and the
exact Jacobian-change measure (a solve with n columns) runs as a numeric solve only where a
cheap bound does not already pass."""
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

import kincas
from kincas.cli.scene import load
from kincas.core.fast import COMPILE_MAX, sweeper_for
from test_space import AL, BE, bennett_theta2, rotate, wrap

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
N = 361  # a full turn in 1-degree steps, as `kincas solve` sweeps them


def swept(name, report, compile):
    m = load(EXAMPLES / f"{name}.toml").mechanism
    th = np.linspace(0, 2 * np.pi, N)
    sw = kincas.sweep(m, {m.inputs[0].key: th}, report=report, compile=compile)
    assert sw.info["fast pass"] == ("compiled" if compile else "virtual machine")
    assert sw.ok.all()
    model, p = kincas.model_of(m), np.array([v for _, v in m.parameters], float)
    # 47-55k instructions before (a symbolic solve of the normal equations for all n columns
    # of the Jacobian-change measure): refused by COMPILE_MAX, swept in the virtual machine
    assert sweeper_for(model, tuple(report), compile).size < COMPILE_MAX / 2
    g = np.array([model.residual(q, np.array([t]), p) for q, t in zip(sw.q, th)])
    assert g.shape[1] > model.nq  # tall: every equation checked, the redundant ones too
    assert np.abs(g).max() < 1e-12 * m.size()
    return th, sw


@pytest.mark.slow  # compiles a kernel: 3-5 s of gcc (more on a loaded machine)
def test_bennett_compiled_follows_its_input_output_relation():
    # tan(th1/2) tan(th2/2) = sin((beta + alpha)/2) / sin((beta - alpha)/2), th3 = -th1,
    # th1 = 1 rad at the drawing pose (the example's own comments)
    th, sw = swept("space_bennett", ["O2.angle", "O2.omega", "O3.angle", "O3.omega"], True)
    t1 = 1.0 + th
    want = np.array([bennett_theta2(t) for t in t1]) - bennett_theta2(1.0)
    assert np.abs(wrap(sw["O2.angle"] - want)).max() < 1e-12
    k = math.sin((BE + AL) / 2) / math.sin((BE - AL) / 2)
    rate = -k / (np.sin(t1 / 2) ** 2 + k ** 2 * np.cos(t1 / 2) ** 2)  # d th2 / d th1
    assert np.abs(sw["O2.omega"] - rate).max() < 1e-10
    assert np.abs(wrap(sw["O3.angle"] + th)).max() < 1e-12 and np.abs(sw["O3.omega"] + 1).max() < 1e-12


def test_spherical_four_bar_keeps_its_coupler_angle_with_its_rate():
    # the coupler keeps the angle between its joints' axes: b(t).c(phi) = b0.c0 with
    # b(t) = Rot(z, t) b0 and c(phi) = Rot(w, phi) c0 (the same kernel as compiled, in the
    # virtual machine: one compile per test file is enough)
    scene = tomllib.loads((EXAMPLES / "space_spherical_fourbar.toml").read_text())
    pts = scene["links"]["coupler"]["points"]
    b0, c0 = (np.array(pts[k]) / np.linalg.norm(pts[k]) for k in ("B", "C"))
    w, z = np.array(scene["joints"][1]["axis"]), np.array([0, 0, 1.0])
    th, sw = swept("space_spherical_fourbar", ["out.angle", "out.omega"], False)
    c_par, c_perp, c_ax = c0 - w * (w @ c0), np.cross(w, c0), w * (w @ c0)
    phi = []
    for t in th:  # a sin(phi) + b cos(phi) = c, on the branch through phi = 0 at t = 0
        b = rotate(b0, z, t)
        a_, b_, c_ = b @ c_perp, b @ c_par, b0 @ c0 - b @ c_ax
        phi.append(math.atan2(a_, b_) - math.acos(c_ / math.hypot(a_, b_)))
    phi = np.array(phi)
    assert abs(wrap(phi[0])) < 1e-12  # the branch the drawing is on
    assert np.abs(wrap(sw["out.angle"] - phi)).max() < 1e-12
    b = np.array([rotate(b0, z, t) for t in th])
    c = np.array([rotate(c0, w, f) for f in phi])
    rate = -np.einsum("ij,ij->i", np.cross(z, b), c) / np.einsum("ij,ij->i", b, np.cross(w, c))
    assert np.abs(sw["out.omega"] - rate).max() < 1e-10


def test_double_cardan_output_turns_with_its_input():
    # Z arrangement, yokes in phase: out.angle = in.angle, at the input's rate
    th, sw = swept("space_double_cardan", ["out.angle", "out.omega"], False)
    assert np.abs(wrap(sw["out.angle"] - th)).max() < 1e-12 and np.abs(sw["out.omega"] - 1).max() < 1e-12
