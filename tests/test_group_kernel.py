"""The kernel written group by group (kincas/core/group_kernel.py) computes what the flat
kernel computes, and its code does not grow with a chain of equal groups.

N parallelogram four-bars in a row, each rocker the next one's crank (pivots G_k = (4k, 0),
rockers 1, couplers 4): every rocker turns with the crank, T_k = G_k + (cos t, sin t) and
its velocity w (-sin t, cos t), the closed form the sweeps are checked against.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import kincas
from kincas.cli import scene
from kincas.core.fast import FastSweeper, sweeper_for
from kincas.core.group_kernel import GroupFunctions
from kincas.core.kernel import GROUPS_APART, kernel_functions


def chain(n):
    links = [kincas.Link.bar("crank", "O", "A", 1.0)]
    for k in range(1, n + 1):
        links += [kincas.Link.bar(f"cp{k}", "A" if k == 1 else f"T{k - 1}", f"T{k}", 4.0),
                  kincas.Link.bar(f"rk{k}", f"G{k}", f"T{k}", 1.0)]
    ground = {"O": (0.0, 0.0), **{f"G{k}": (4.0 * k, 0.0) for k in range(1, n + 1)}}
    guess = {f"T{k}": (4.0 * k + 0.5, 0.87) for k in range(1, n + 1)}
    return kincas.Mechanism(ground=ground, links=links, inputs=[kincas.Input.angle("crank")], guess=guess)


def test_equal_groups_share_one_function():
    model = kincas.model_of(chain(12))
    kinds = GroupFunctions(model.sym, list(model.blocks))
    assert len(model.blocks) == 12 and len(kinds.newton_kinds) <= 3  # the first ones differ
    small = FastSweeper(kincas.model_of(chain(9)), ["T9.x"], compile=False)
    large = FastSweeper(kincas.model_of(chain(30)), ["T30.x"], compile=False)
    # the code grows with the glue between calls only; the work with every group
    assert large.work > 3 * small.work and large.size < 2 * small.size + 2000


EXAMPLES = sorted((Path(__file__).resolve().parent.parent / "examples").glob("*.toml"))


def test_each_angle_has_one_sine_per_evaluation():
    """A run hanging on an earlier run's angle takes its sine and cosine from that run: kF's
    calls compute one sine and one cosine per angle of the chain (2 per four-bar, and the
    crank's), no more."""
    import casadi as ca
    n = 13  # four runs of GROUP_RUN = 4 groups, the last one short
    model = kincas.model_of(chain(n))
    kF = kernel_functions(model.sym, list(model.blocks), (), model.structure, grouped=True)[2]

    def count(f, op):
        if not f.is_a("MXFunction"):
            return sum(f.instruction_id(i) == op for i in range(f.n_instructions()))
        return sum(count(f.instruction_MX(i).which_function(), op) for i in range(f.n_instructions())
                   if f.instruction_id(i) == ca.OP_CALL)
    assert count(kF, ca.OP_SIN) == 2 * n + 1 and count(kF, ca.OP_COS) == 2 * n + 1


@pytest.mark.parametrize("source", ["chain", "chain9"] + [p.stem for p in EXAMPLES])
def test_grouped_and_flat_kernels_agree(source):
    """kP, kN, kF, kL, kP5 of both writings at the same random arguments: same numbers (chain9:
    three runs of groups, each passing its last rocker's sine and cosine to the next)."""
    if source.startswith("chain"):
        k = int(source[5:] or 4)
        m, report = chain(k), [f"T{k}.{c}" for c in ("x", "y", "vx", "vy", "ax")]
    else:
        sc = scene.load(EXAMPLES[[p.stem for p in EXAMPLES].index(source)])
        m, report = sc.mechanism, sc.study.report
    model = kincas.model_of(m)
    if not model.square or not model.nq:
        pytest.skip("no fast kernel (redundant joints, or nothing to solve)")
    sym, blocks = model.sym, list(model.blocks)
    flat = kernel_functions(sym, blocks, report, model.structure, grouped=False)
    grouped = kernel_functions(sym, blocks, report, model.structure, grouped=True)
    rng = np.random.default_rng(3)
    for a, b in zip(flat, grouped):
        if a is None:  # no quintic prediction (kP5: a kernel of few unknowns), in either
            assert b is None
            continue
        args = [rng.uniform(0.5, 1.5, a.size_in(i)) for i in range(a.n_in())]
        for x, y in zip(a.call(args), b.call(args)):
            x, y = np.asarray(x), np.asarray(y)
            assert x.shape == y.shape
            scale = 1 + np.abs(x)
            # kN solves each group's Newton system at these random arguments, far from any
            # assembly: its condition number (the Delta robot's, with its arms hung on revolutes)
            # multiplies the rounding of the two writings' different orders of operations
            rel = 1e-10 if a.name().startswith("kN") else 1e-12
            assert np.all((np.abs(x - y) <= rel * scale) | (np.isnan(x) & np.isnan(y))), a.name()


@pytest.mark.parametrize("compile", [False, True])
def test_long_chain_sweeps_to_the_closed_form(compile):
    n, t = GROUPS_APART, np.radians(np.linspace(60, 120, 41))  # the kernel written group by group
    m, report = chain(n), [f"T{n}.x", f"T{n}.y", f"T{n}.vx", f"T{n}.vy"]
    assert sweeper_for(kincas.model_of(m), tuple(report), compile).functions[1].is_a("MXFunction")
    s = kincas.sweep(m, {"crank.angle": t}, rates={"crank.angle": 2.0}, report=report, compile=compile)
    assert all(st == "ok" for st in s.status)
    np.testing.assert_allclose(s[f"T{n}.x"], 4.0 * n + np.cos(t), rtol=0, atol=1e-13)
    np.testing.assert_allclose(s[f"T{n}.y"], np.sin(t), rtol=0, atol=1e-13)
    np.testing.assert_allclose(s[f"T{n}.vx"], -2.0 * np.sin(t), rtol=0, atol=1e-12)
    np.testing.assert_allclose(s[f"T{n}.vy"], 2.0 * np.cos(t), rtol=0, atol=1e-12)
