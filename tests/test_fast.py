"""The fast sweep (kincas.core.fast) against closed forms, its compiled and uncompiled paths against
each other, its disk cache, its fallback, and its refusal to jump branch near singular poses.

Compiled kernels are shared through a module-wide cache directory (one compilation each)."""
import json
import os
import subprocess
import sys
import warnings

import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism, Slide
from kincas.core.fast import FastRun, FastSweeper, QuantityEvaluator
from kincas.core.numeric import Solution


@pytest.fixture(scope="module", autouse=True)
def cache(tmp_path_factory):
    with pytest.MonkeyPatch.context() as mp:
        path = tmp_path_factory.mktemp("kincas-cache")
        mp.setenv("KINCAS_CACHE", str(path))
        mp.delenv("KINCAS_NO_COMPILE", raising=False)
        yield path


# --- independent answers: closed forms written without kincas ---


def fourbar_closed(th, a, b, c, d, w=1.0, side=+1):
    """Crank a at A=(0,0), coupler b, rocker c at D=(d,0), crank speed w: C, its velocity,
    the rocker's angle and angular velocity, by circle intersection and the velocity loop."""
    Bx, By = a * np.cos(th), a * np.sin(th)
    ex, ey = d - Bx, -By
    r = np.hypot(ex, ey)
    x = (b * b - c * c + r * r) / (2 * r)
    with np.errstate(invalid="ignore"):  # NaN where the loop cannot close
        h = np.sqrt(b * b - x * x)
    Cx, Cy = Bx + (x * ex - side * h * ey) / r, By + (x * ey + side * h * ex) / r
    ux, uy, vx, vy = Cx - Bx, Cy - By, Cx - d, Cy  # coupler B->C, rocker D->C
    vBx, vBy = -w * By, w * Bx
    w4 = (ux * vBx + uy * vBy) / (uy * vx - ux * vy)  # vB + w3 k x u = w4 k x v
    return {"C.x": Cx, "C.y": Cy, "C.vx": -w4 * vy, "C.vy": w4 * vx,
            "rocker.angle": np.arctan2(vy, vx), "rocker.omega": w4}


def slider_closed(th, r, l, e, w, al):
    """Offset slider-crank: crank r at O, rod l, B on the line y = e, right-hand branch."""
    s, cth, sth = e - r * np.sin(th), np.cos(th), np.sin(th)
    h = np.sqrt(l * l - s * s)
    x1 = -r * sth + s * r * cth / h  # dx/dth
    x2 = -r * cth + r * ((-r * cth**2 - s * sth) / h - s * s * r * cth**2 / h**3)  # d2x/dth2
    return {"B.x": r * cth + h, "B.vx": x1 * w, "B.ax": x2 * w * w + x1 * al}


def fourbar(a=1.0, b=3.5, c=3.0, d=4.0, guess=(3.6, 2.9)):
    return Mechanism(parameters={"a": a, "b": b, "c": c}, ground={"A": (0, 0), "D": (d, 0)},
                     links=[Link.bar("crank", "A", "B", "a"), Link.bar("coupler", "B", "C", "b"),
                            Link.bar("rocker", "D", "C", "c")],
                     inputs=[Input.angle("crank")], guess={"C": guess})


FOURBAR_REPORT = ["C.x", "C.y", "C.vx", "C.vy", "rocker.angle", "rocker.omega"]


def first_pose(m, U):
    model, p, L = kincas.model_of(m), np.array([v for _, v in m.parameters]), m.size()
    g = {k: (m.value(x), m.value(y)) for k, (x, y) in m.guess}
    sol = model.newton(model.initial_q(U[0], p, g, L), U[0], p, L)
    assert sol.ok
    return model, p, L, sol.q


def check_residuals(model, run, p, L, tol=1e-12):
    """Every accepted pose closes its loops, checked again outside the kernel."""
    for k in np.flatnonzero(run.accepted):
        assert np.abs(model.residual(run.Q[k], run.U[k], p)).max() / L <= tol


@pytest.fixture(scope="module")
def fourbar_sweepers():
    model = kincas.model_of(fourbar())
    return {c: FastSweeper(model, FOURBAR_REPORT, compile=c) for c in (True, False)}


# --- agreement with closed forms ---


@pytest.mark.parametrize("compiled", [True, False])
def test_fourbar_matches_closed_form_at_every_pose(fourbar_sweepers, compiled):
    th = np.linspace(-np.pi, 3 * np.pi, 4001)
    U = th[:, None]
    model, p, L, q0 = first_pose(fourbar(), U)
    fs = fourbar_sweepers[compiled]
    run = fs.run(U, p, L, q0, U[0], start=1, Ud=[10.0])
    assert run.first_bad == len(th) and run.accepted[1:].all()
    assert (fs.backend.lib is not None) == compiled
    # predictor error: O(h^2) at the first pose (linear), O(h^3) after it (h = 3.1e-3 here)
    assert run.correction[1] < 1e-5 and run.correction[2:].max() < 2e-7
    assert run.iterations[1:].max() <= 2
    cf = fourbar_closed(th, 1, 3.5, 3, 4, w=10.0)
    for i, name in enumerate(FOURBAR_REPORT):
        scale = L * (10.0 if ".v" in name or "omega" in name else 1.0)
        err = cf[name][1:] - run.values[i, 1:]
        if name.endswith(".angle"):
            err = np.angle(np.exp(1j * err))
        assert np.abs(err).max() <= 1e-12 * scale, name
    check_residuals(model, run, p, L)


def test_compiled_and_uncompiled_give_the_same_poses(fourbar_sweepers):
    th = np.linspace(0.3, 0.3 + 2 * np.pi, 3001)
    U = th[:, None]
    model, p, L, q0 = first_pose(fourbar(), U)
    a, b = (fourbar_sweepers[c].run(U, p, L, q0, U[0], start=1) for c in (True, False))
    assert a.first_bad == b.first_bad == len(th)
    np.testing.assert_allclose(a.Q, b.Q, rtol=0, atol=1e-14)
    np.testing.assert_allclose(a.values[:, 1:], b.values[:, 1:], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(a.iterations, b.iterations)


@pytest.mark.parametrize("skip", [False, True])
@pytest.mark.parametrize("n", [40, 301, 1500])
def test_both_virtual_machine_forms_follow_the_compiled_loop(fourbar_sweepers, monkeypatch, skip, n):
    """The flat SX pose in 64- or 256-pose chunks (a small kernel) and the switched pose in
    chunks sized to what is left (a large one, forced here) stop where the C loop stops."""
    monkeypatch.setattr("kincas.core.fast_vm.VM_SKIP", -1 if skip else 10**9)
    th = np.linspace(0.3, 0.3 + 2 * np.pi, n)
    U = th[:, None]
    model, p, L, q0 = first_pose(fourbar(), U)
    a = fourbar_sweepers[True].run(U, p, L, q0, U[0], start=1)
    b = FastSweeper(model, FOURBAR_REPORT, compile=False).run(U, p, L, q0, U[0], start=1)
    assert a.first_bad == b.first_bad == n
    np.testing.assert_allclose(a.Q, b.Q, rtol=0, atol=1e-14)
    np.testing.assert_allclose(a.values[:, 1:], b.values[:, 1:], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(a.iterations, b.iterations)
    check_residuals(model, b, p, L)


@pytest.mark.parametrize("scale", [1.0, 1000.0])
def test_offset_slider_crank_positions_velocities_accelerations(scale):
    r, l, e = 1.0 * scale, 3.2 * scale, 0.4 * scale
    m = Mechanism(ground={"O": (0, 0)},
                  links=[Link.bar("crank", "O", "A", r), Link.bar("rod", "A", "B", l)],
                  slides=[Slide("B", "ground", through=(0, e), name="guide")],
                  inputs=[Input.angle("crank")], guess={"B": (r + l, e)})
    th = np.linspace(0, 4 * np.pi, 20001)
    U = th[:, None]
    model, p, L, q0 = first_pose(m, U)
    w, al = 7.0, -3.0
    run = FastSweeper(model, ["B.x", "B.vx", "B.ax"], compile=True).run(
        U, p, L, q0, U[0], start=1, Ud=[w], Udd=[al])
    assert run.first_bad == len(th)
    cf = slider_closed(th, r, l, e, w, al)
    for i, (name, unit) in enumerate([("B.x", 1), ("B.vx", w), ("B.ax", w * w)]):
        assert np.abs(run.values[i, 1:] - cf[name][1:]).max() <= 1e-12 * L * unit, name
    check_residuals(model, run, p, L)


def test_two_inputs_five_bar_with_rates_per_pose():
    m = Mechanism(ground={"A": (0, 0), "E": (2, 0)},
                  links=[Link.bar("c1", "A", "B", 1), Link.bar("c2", "E", "D", 1),
                         Link.bar("l1", "B", "C", 2.5), Link.bar("l2", "D", "C", 2.5)],
                  inputs=[Input.angle("c1"), Input.angle("c2")], guess={"C": (1, 2.3)})
    t = np.linspace(0, 2 * np.pi, 5001)
    path = lambda t: np.stack([t, t + np.pi / 3 + 0.3 * np.sin(t)], axis=1)
    U = path(t)
    Ud = np.stack([np.ones_like(t), 1 + 0.3 * np.cos(t)], axis=1)  # d/dt of the path
    model, p, L, q0 = first_pose(m, U)
    run = FastSweeper(model, ["C.x", "C.y", "C.vx"], compile=True).run(U, p, L, q0, U[0], start=1, Ud=Ud)
    assert run.first_bad == len(t)
    # the predictor's error: O(h^2) at the first pose (linear), O(h^3) after (second order
    # along the turning path of the inputs too; h = 1.3e-3). A mis-laid-out tangent: O(h)
    assert run.correction[1] < 1e-5 and run.correction[2:].max() < 2e-7
    assert run.iterations[1:].max() <= 2

    def closed(t):  # C left of B -> D, at distance 2.5 from both
        u = path(t)
        B = np.stack([np.cos(u[:, 0]), np.sin(u[:, 0])], axis=1)
        D = np.stack([2 + np.cos(u[:, 1]), np.sin(u[:, 1])], axis=1)
        mid, e = (B + D) / 2, D - B
        dist = np.linalg.norm(e, axis=1)[:, None]
        h = np.sqrt(2.5**2 - (dist / 2) ** 2)
        return mid + h * np.stack([-e[:, 1], e[:, 0]], axis=1) / dist

    C = closed(t)
    assert np.abs(run.values[0, 1:] - C[1:, 0]).max() <= 1e-12 * L
    assert np.abs(run.values[1, 1:] - C[1:, 1]).max() <= 1e-12 * L
    hstep = 1e-5  # central differences of the closed form: tests only
    vx = (closed(t + hstep)[:, 0] - closed(t - hstep)[:, 0]) / (2 * hstep)
    assert np.abs(run.values[2, 1:] - vx[1:]).max() <= 1e-7


def test_quantity_evaluator_compiled_and_uncompiled_with_mask():
    th = np.linspace(0, 2 * np.pi, 2001)
    U = th[:, None]
    model, p, L, q0 = first_pose(fourbar(), U)
    Q = FastSweeper(model, compile=False).run(U, p, L, q0, U[0], start=1).Q
    Q[0] = q0
    ok = np.ones(len(th), dtype=bool)
    ok[7] = False
    cf = fourbar_closed(th, 1, 3.5, 3, 4, w=2.0)
    for c in (True, False):
        ev = QuantityEvaluator(model, ["C.x", "C.vy"], compile=c)
        out = ev.evaluate(Q, U, p, Ud=np.full((len(th), 1), 2.0), ok=ok)
        assert (ev.backend.lib is not None) == c
        assert np.isnan(out[:, 7]).all() and np.isfinite(np.delete(out, 7, axis=1)).all()
        assert np.nanmax(np.abs(out[0] - cf["C.x"])) <= 1e-12 * L
        assert np.nanmax(np.abs(out[1] - cf["C.vy"])) <= 2e-12 * L


def test_no_unknowns_every_pose_goes_to_the_careful_path():
    m = Mechanism(ground={"A": (0, 0)}, links=[Link.bar("crank", "A", "B", 2.0)],
                  inputs=[Input.angle("crank")])
    model = kincas.model_of(m)
    th = np.linspace(0, 3, 7)
    calls = []

    def careful(k, j, run):
        calls.append((k, j))
        return model.newton(np.zeros(0), th[k:k + 1], [], 2.0)

    run = FastSweeper(model, ["B.y", "B.vx"]).sweep(th[:, None], [], 2.0, careful, Ud=[3.0])
    assert calls == [(k, k - 1 if k else None) for k in range(7)] and run.solved.all()
    np.testing.assert_allclose(run.values, [2 * np.sin(th), -6 * np.sin(th)], rtol=0, atol=1e-14)


@pytest.mark.parametrize("compiled", [True, False])
def test_progress_in_blocks_gives_the_same_poses(fourbar_sweepers, compiled, monkeypatch):
    import kincas.core.fast
    monkeypatch.setattr(kincas.core.fast, "BLOCK", 300)  # blocks of 300 poses, state carried over
    th = np.linspace(0, 2 * np.pi, 2000)
    U = th[:, None]
    model, p, L, q0 = first_pose(fourbar(), U)
    careful = lambda k, j, run: model.newton(q0 if j is None else run.Q[j], U[k], p, L)
    fs, news = fourbar_sweepers[compiled], []
    a = fs.sweep(U, p, L, careful)
    b = fs.sweep(U, p, L, careful, progress=lambda done, total: news.append((done, total)))
    np.testing.assert_array_equal(a.Q, b.Q)
    assert b.accepted[1:].all() and news[0] == (0, 2000) and news[-1] == (2000, 2000)
    mid = [d for d, _ in news[1:-1]]  # every 256th pose passed, at most one call per block
    assert all(d % 256 == 0 for d in mid) and mid == sorted(set(mid)) and mid[-1] == 1792
    assert len(mid) >= 2000 // 300


# --- compilation: the disk cache, the policy, the fallback ---


def test_disk_cache_is_hit_by_a_second_process(cache):
    m = fourbar(b=3.6)  # a structure of its own: same shape, other report
    fs = FastSweeper(kincas.model_of(m), ["C.y"], compile=True)
    assert fs.backend.compiled(10) is not None
    lib = fs.backend.library
    assert lib.path.exists() and lib.path.parent == cache
    script = f"""
import json, numpy as np, kincas, sys
sys.path.insert(0, {os.path.dirname(__file__)!r})
from test_fast import fourbar
from kincas.core.fast import FastSweeper
fs = FastSweeper(kincas.model_of(fourbar(b=3.6)), ["C.y"], compile=True)
ok = fs.backend.compiled(10) is not None
print(json.dumps({{"cached": fs.backend.library.cached, "compile": fs.backend.library.times["compile"],
                   "path": str(fs.backend.library.path), "ok": ok}}))
"""
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         env={**os.environ, "KINCAS_CACHE": str(cache)}, timeout=120)
    got = json.loads(out.stdout.strip().splitlines()[-1])
    assert got == {"cached": True, "compile": 0.0, "path": str(lib.path), "ok": True}


def test_the_cache_keeps_the_most_recently_used_libraries(tmp_path, monkeypatch):
    import kincas.core.c_library
    monkeypatch.setenv("KINCAS_CACHE", str(tmp_path))
    monkeypatch.setattr(kincas.core.c_library, "MAX_CACHED", 2)
    old = [tmp_path / f"kincas_sweep-old{i}.so" for i in range(3)]
    for i, f in enumerate(old):
        f.write_bytes(b"")
        os.utime(f, (1000 + i, 1000 + i))
    fs = FastSweeper(kincas.model_of(fourbar(b=3.55)), ["C.x"], compile=True)
    assert fs.backend.compiled(10) is not None
    assert sorted(f.name for f in tmp_path.glob("*.so")) == sorted([old[2].name, fs.backend.library.path.name])


def test_auto_policy_does_not_compile_a_short_sweep_unless_cached(fourbar_sweepers, tmp_path, monkeypatch):
    monkeypatch.setenv("KINCAS_CACHE", str(tmp_path))
    model = kincas.model_of(fourbar())
    fs = FastSweeper(model, ["C.x"], compile=None)
    assert fs.backend.compiled(100) is None and not any(tmp_path.iterdir())
    assert fs.backend.compiled(10**6) is not None  # a long sweep is worth compiling
    again = FastSweeper(model, ["C.x"], compile=None)
    assert again.backend.compiled(100) is not None  # now cached: used for short sweeps too


def test_no_compiler_or_a_failing_one_falls_back_without_failing(tmp_path, monkeypatch):
    th = np.linspace(0, 2 * np.pi, 500)
    U = th[:, None]
    model, p, L, q0 = first_pose(fourbar(b=3.7), U)
    monkeypatch.setenv("KINCAS_NO_COMPILE", "1")
    fs = FastSweeper(model, ["C.x"], compile=True)
    assert fs.backend.compiled(10**6) is None
    monkeypatch.delenv("KINCAS_NO_COMPILE")
    monkeypatch.setenv("KINCAS_CACHE", str(tmp_path))
    monkeypatch.setenv("CC", "false")  # a compiler that always fails
    fs = FastSweeper(model, ["C.x"], compile=True)
    with pytest.warns(RuntimeWarning, match="uncompiled path"):
        run = fs.run(U, p, L, q0, U[0], start=1)
    assert fs.backend.lib is None and run.first_bad == len(th)
    assert np.abs(run.values[0, 1:] - fourbar_closed(th, 1, 3.7, 3, 4)["C.x"][1:]).max() <= 1e-12 * L


# --- near singular positions: reject, never jump branch ---


def test_near_change_point_the_guard_stops_a_silent_branch_jump():
    # Grashof by 0.0001 (1 + 4.4299 vs 1.43 + 4): at crank angle 0 the branches nearly meet.
    # In 15 degree steps, Newton from the prediction converges to the other branch there.
    # (Grashof by 0.001 no longer shows it: the quintic prediction stays on the branch.)
    a, b, c = 1.0, 1.43, 4.4299
    th = np.linspace(2.0, 2.0 + 2 * np.pi, 25)
    U = th[:, None]
    model, p, L, q0 = first_pose(fourbar(a, b, c, guess=(3.0, 3.0)), U)
    cf = fourbar_closed(th, a, b, c, 4)
    fs = FastSweeper(model, ["C.x", "C.y"], compile=True)
    wrong = {}
    for guard in (True, False):
        run = FastRun(fs, U, p, L)
        if not guard:
            run.thr[2:4] = np.inf  # no Jacobian-change or correction test
        run.advance(1, q0, U[0])
        err = np.hypot(run.values[0] - cf["C.x"], run.values[1] - cf["C.y"])
        wrong[guard] = int(np.sum(err[run.accepted] > 1e-6))
        if guard:
            assert 1 < run.first_bad < len(th) and np.all(err[run.accepted] <= 1e-12 * L)
    assert wrong == {True: 0, False: wrong[False]} and wrong[False] > 0  # the guard mattered


def test_non_grashof_driven_past_its_toggle_and_back():
    # Crank 1, coupler 1.9, rocker 3, ground 4: the crank cannot pass +-151.2 degrees.
    th = np.concatenate([np.linspace(0, 2 * np.pi, 721), np.linspace(2 * np.pi, 0, 721)[1:]])
    U = th[:, None]
    m = fourbar(1, 1.9, 3, guess=(3.5, 2.9))
    model, p, L, _ = first_pose(m, U)
    cf = fourbar_closed(th, 1, 1.9, 3, 4)
    impossible = np.isnan(cf["C.x"])
    sign = lambda q, u: np.sign(np.linalg.det(model.jac(q, u, p)))
    calls, ref = [], []

    def careful(k, j, run):  # Newton from the last solved pose j, branch by det's sign
        calls.append(k)
        start = model.initial_q(U[k], p, dict(m.guess), L) if j is None else run.Q[j]
        sol = model.newton(start, U[k], p, L)
        if sol.ok and not ref:
            ref.append(sign(sol.q, U[k]))
        if sol.ok and sign(sol.q, U[k]) != ref[0]:
            sol = model.newton(model.initial_q(U[k], p, dict(m.guess), L), U[k], p, L)
            if sol.ok and sign(sol.q, U[k]) != ref[0]:
                sol = Solution(sol.q, sol.residual, sol.iterations, False)
        return sol

    run = FastSweeper(model, ["C.x", "C.y"], compile=True).sweep(U, p, L, careful)
    acc = run.accepted
    assert not np.any(acc & impossible) and not np.any(run.solved & impossible)
    err = np.hypot(run.values[0] - cf["C.x"], run.values[1] - cf["C.y"])
    assert np.all(err[acc] <= 1e-12 * L)  # every accepted pose is on the guessed branch
    assert np.all(err[run.solved] <= 1e-9 * L)  # careful poses by a toggle: a double root
    assert run.solved.sum() == (~impossible).sum()  # every possible pose was solved
    # the fast pass did most of the work, on every stretch between the impossible ones
    assert acc.sum() >= (~impossible).sum() - 12 and len(calls) <= impossible.sum() + 12
    check_residuals(model, run, p, L)
    # the singular measures of every pose, from the kernel or the careful path (they replaced
    # the g_q kept per pose, which this test read before): one branch, one sign of det g_q,
    # and sigma a lower bound of the scaled g_q's smallest singular value, small only near
    # the toggles
    assert np.isnan(run.measures[:, ~run.solved]).all()
    assert set(run.signs[run.solved, 0]) == {np.sign(np.linalg.det(model.jac(run.Q[0], U[0], p)))}
    for k in np.flatnonzero(run.solved)[::25]:
        sv = np.linalg.svd(model.jac(run.Q[k], U[k], p) * model.column_scale(L), compute_uv=False)
        assert run.sigma[k] <= sv[-1] / max(sv[0], 1.0) * (1 + 1e-9)
        assert run.sigma[k] >= 0.5 * sv[-1] / max(sv[0], 1.0) / np.sqrt(2)  # 2 x 2: near exact
