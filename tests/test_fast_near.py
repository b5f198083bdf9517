"""The fast kernel where its prediction is already converged (issue [15], speed): once a pose
was predicted to within STEP, the next pose is tried with kF at the prediction first, and
accepted with no Newton step before it where kF's next step is negligible (the same tests as
any pose); else Newton goes on from the prediction as before. The compiled loop and both
forms of the virtual machine take the same decisions (the same unknowns, the same step
counts; compiled with libm's sines and cosines, as the virtual machine takes them), and the
answers are the closed forms'."""
from pathlib import Path

import numpy as np
import pytest

from kincas import Input, Link, Mechanism, Slide
from kincas.core.fast import FastSweeper

from test_fast import check_residuals, first_pose, fourbar, fourbar_closed


@pytest.fixture(scope="module", autouse=True)
def cache(tmp_path_factory):
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("KINCAS_CACHE", str(tmp_path_factory.mktemp("kincas-cache")))
        mp.delenv("KINCAS_NO_COMPILE", raising=False)
        # the compiled loop held to the virtual machine bit for bit: libm's sin and cos in both
        # (kincas/core/c_library.py libm_trig; compiled kernels take fdlibm's otherwise)
        mp.setenv("KINCAS_LIBM_TRIG", "1")
        yield


def parallelograms(n, name):
    """n four-bars in a row, each rocker the next one's crank, every one a parallelogram
    (coupler 4 between pivots 4 apart, cranks and rockers of length `name` = 1): every link
    turns with the crank, T_k = G_k + (cos th, sin th), so q is linear in th and the
    tangent predicts every pose exactly (to rounding)."""
    ground = {"O": (0.0, 0.0), **{f"G{k}": (4.0 * k, 0.0) for k in range(1, n + 1)}}
    links, prev = [Link.bar("crank", "O", "A", name)], "A"
    for k in range(1, n + 1):
        links += [Link.bar(f"cp{k}", prev, f"T{k}", 4.0), Link.bar(f"rk{k}", f"G{k}", f"T{k}", name)]
        prev = f"T{k}"
    guess = {f"T{k}": (4.0 * k + 0.5, 0.87) for k in range(1, n + 1)}
    return Mechanism(parameters={name: 1.0}, ground=ground, links=links,
                     inputs=[Input.angle("crank")], guess=guess)


def runs(m, report, U, Ud, monkeypatch):
    """The compiled run and the virtual machine's two forms (flat, switched) of U[1:]."""
    model, p, L, q0 = first_pose(m, U)
    out = {"compiled": FastSweeper(model, report, compile=True).run(U, p, L, q0, U[0], start=1, Ud=Ud)}
    for skip in (False, True):
        monkeypatch.setattr("kincas.core.fast_vm.VM_SKIP", -1 if skip else 10**9)
        out[f"vm skip={skip}"] = FastSweeper(model, report, compile=False).run(U, p, L, q0, U[0], start=1, Ud=Ud)
    return model, p, L, out


def same_decisions(out):
    a = out["compiled"]
    for b in out.values():
        assert a.first_bad == b.first_bad == len(a.U)
        np.testing.assert_allclose(a.Q, b.Q, rtol=0, atol=1e-14)
        np.testing.assert_allclose(a.values[:, 1:], b.values[:, 1:], rtol=0, atol=1e-12)
        np.testing.assert_array_equal(a.iterations, b.iterations)


@pytest.mark.parametrize("grouped", [False, True])
def test_exact_predictions_take_no_newton_step(monkeypatch, grouped):
    if grouped:  # the kernel written group by group (kincas/core/group_kernel.py)
        monkeypatch.setattr("kincas.core.kernel.GROUPS_APART", 2)
    m = parallelograms(3, f"near_r{int(grouped)}")
    th = np.linspace(np.pi / 3, 2 * np.pi / 3, 121)
    w = 7.0
    model, p, L, out = runs(m, ["T3.x", "T3.y", "T3.vx", "T3.vy"], th[:, None], [w], monkeypatch)
    same_decisions(out)
    run = out["compiled"]
    # pose 1 is predicted linearly (no tangent before it): Newton; from pose 2 on the
    # prediction is exact and kF there accepts it with no Newton step
    assert run.iterations[1] >= 1 and (run.iterations[3:] == 0).all()
    assert run.residual[1:].max() <= 1e-13 and run.step[1:].max() <= 1e-13
    ref = {"T3.x": 12 + np.cos(th), "T3.y": np.sin(th), "T3.vx": -w * np.sin(th), "T3.vy": w * np.cos(th)}
    for i, (name, v) in enumerate(ref.items()):
        assert np.abs(run.values[i, 1:] - v[1:]).max() <= 1e-12 * L * (w if ".v" in name else 1), name
    check_residuals(model, run, p, L)


@pytest.mark.parametrize("quintic", [False, True])
def test_predictions_near_step_switch_between_both_ways_alike(monkeypatch, quintic):
    # the cubic (kincas/core/prediction.py) misses the four-bar by about STEP at steps of
    # 1e-3 rad (tests/test_fast_predict.py computes it: above at 542 poses, below at 457);
    # with the quintic (forced on a four-bar, which has too few unknowns for it), at 7.5e-3
    # rad over half a turn, where it runs where the cubic misses by up to QUINTIC_TRY and
    # the cubic elsewhere. Poses go either way (kF first, accepted; or not, and Newton from
    # kF's step)
    m = fourbar(b=3.45)
    th = np.linspace(0.3, 3.3, 401) if quintic else np.linspace(0.3, 1.3, 1001)
    extra = ["B.y"] if quintic else []  # (a report of its own: kernels are kept per report)
    if quintic:
        monkeypatch.setattr("kincas.core.kernel.QUINTIC_UNKNOWNS", 1)
    model, p, L, out = runs(m, ["C.x", "C.y", "C.vx", "C.vy", *extra], th[:, None], [10.0], monkeypatch)
    same_decisions(out)
    run = out["compiled"]
    assert (run.sweeper.functions[4] is not None) == quintic
    its = run.iterations[2:]
    assert (its == 0).sum() >= 10 and (its >= 1).sum() >= 10  # both ways
    cf = fourbar_closed(th, 1.0, 3.45, 3.0, 4.0, w=10.0)
    for i, name in enumerate(["C.x", "C.y", "C.vx", "C.vy"]):
        scale = L * (10.0 if ".v" in name else 1.0)
        assert np.abs(run.values[i, 1:] - cf[name][1:]).max() <= 1e-12 * scale, name
    check_residuals(model, run, p, L, tol=1e-13)


def two_inputs():
    """A four-bar and a slider-crank side by side, each driven by its own crank."""
    return Mechanism(ground={"A": (0, 0), "D": (4, 0), "E": (0, 5)},
                     links=[Link.bar("crank", "A", "B", 1.0), Link.bar("coupler", "B", "C", 3.5),
                            Link.bar("rocker", "D", "C", 3.0), Link.bar("crank2", "E", "F", 1.0),
                            Link.bar("rod", "F", "S", 3.0)],
                     slides=[Slide("S", "ground", through=(0, 5), angle=0.0, name="guide")],
                     inputs=[Input.angle("crank"), Input.angle("crank2")],
                     guess={"C": (3.6, 2.9), "S": (3.5, 5.0)})


@pytest.mark.parametrize("case", ["two inputs", "cam"])
def test_predictions_of_the_c_loop_are_the_virtual_machines(monkeypatch, case):
    # The C loop forms the predictions itself from kW's scalars (kincas/core/kernel.py); the
    # virtual machine evaluates kP and kP5 (kincas/core/prediction.py). Both sum in one order,
    # so the unknowns are the same bit for bit: with two inputs (the sums over them), with
    # lengths among the unknowns (a cam's follower: the quintic's error scaled by its group's
    # length), and the quintic at every pose where it applies (forced on: QUINTIC_ON 0,
    # QUINTIC_TRY 1).
    for mod in ("kincas.core.kernel", "kincas.core.fast"):
        monkeypatch.setattr(f"{mod}.QUINTIC_UNKNOWNS", 1, raising=False)
        monkeypatch.setattr(f"{mod}.QUINTIC_ON", 0.0)
        monkeypatch.setattr(f"{mod}.QUINTIC_TRY", 1.0)
    t = np.linspace(0.0, 2.0, 301)
    if case == "cam":
        from kincas.cli import scene
        sc = scene.load(Path(__file__).parents[1] / "examples" / "eccentric_cam.toml")
        m, report, U, Ud = sc.mechanism, list(sc.study.report), t[:, None], [3.0]
    else:
        m, report = two_inputs(), ["C.x", "S.x", "S.vx", "C.vy"]
        U, Ud = np.column_stack([0.3 + t, 1.0 + 0.5 * t]), [3.0, -2.0]
    model, p, L, out = runs(m, report, U, Ud, monkeypatch)
    assert model.sym.nu == 2 if case == "two inputs" else model.sym.is_length.any()
    a = out["compiled"]
    for b in out.values():
        assert a.first_bad == b.first_bad == len(U)
        assert np.array_equal(a.Q[1:], b.Q[1:]) and np.array_equal(a.iterations, b.iterations)
        assert np.array_equal(a.values[:, 1:], b.values[:, 1:])
    assert (a.iterations[3:] == 0).any()  # predictions accepted as they are
    check_residuals(model, a, p, L)
    if case == "two inputs":  # and the closed form: S.x = cos t2 + sqrt(9 - sin^2 t2)
        sx = np.cos(U[:, 1]) + np.sqrt(9 - np.sin(U[:, 1]) ** 2)
        assert np.abs(a.values[1, 1:] - sx[1:]).max() <= 1e-12 * L
