"""Repeated sweeps of one mechanism take the short road (issue [15], speed where users call
it): a mechanism found by identity, its report checked once, rates written out per pose
without broadcasting, no copy of what is the sweep's own already. What the short road must
keep, checked here against the circle-intersection closed form of the four-bar and its
derivative by central differences:

- a Sweep's inputs and rates are its own (the user's arrays changed afterwards change nothing);
- rates given as an int, a float, one per pose, or not at all, give the right velocities;
- another mechanism (other parameter values, or an equal one built anew) is not mistaken for
  one swept before; a name the model does not know fails on every call, not the first only;
- a NaN or infinite input is refused; huge finite inputs are not;
- the layout of a run's block, kept per sweeper and sizes, serves other mechanisms, lengths,
  rates and accelerations with their own numbers; two threads sweeping one mechanism at
  once get what each gets alone; a warm result's containers are its own.
"""
import threading

import numpy as np
import pytest

import closed_forms
import kincas
from kincas import Input, Link, Mechanism
from kincas.errors import ModelError


def fourbar(b=3.5):
    return Mechanism(parameters={"b": b}, ground={"A": (0, 0), "D": (4, 0)},
                     links=[Link.bar("crank", "A", "B", 1.0), Link.bar("coupler", "B", "C", "b"),
                            Link.bar("rocker", "D", "C", 3.0)],
                     inputs=[Input.angle("crank")], guess={"C": (3.6, 2.9)})


def closed_C(th, b):
    """C (2, n): the circles (B, b) and (D, 3) intersected on the upper side."""
    return closed_forms.fourbar((0, 0), (4, 0), 1.0, b, 3.0, th, +1)[1].T


def closed_V(th, b, w):
    """dC/dt = w dC/dtheta, dC/dtheta by central differences of the closed form."""
    e = 1e-6
    return w * (closed_C(th + e, b) - closed_C(th - e, b)) / (2 * e)


REPORT = ["C.x", "C.y", "C.vx", "C.vy"]


def check(sw, th, b, w):
    assert sw.ok.all()
    C, V = closed_C(th, b), closed_V(th, b, w)
    assert np.abs(np.array([sw["C.x"], sw["C.y"]]) - C).max() < 1e-12
    assert np.abs(np.array([sw["C.vx"], sw["C.vy"]]) - V).max() < 1e-7 * max(1.0, np.abs(w).max())


@pytest.mark.parametrize("rates, w", [(None, 1.0), (2, 2.0), (-0.5, -0.5), ("per pose", None)])
def test_rates_in_every_form_give_the_closed_form_velocities(rates, w):
    m, th = fourbar(), np.linspace(0, 2 * np.pi, 90)
    if rates == "per pose":
        w = 1.0 + np.sin(th)
        rates = {"crank.angle": w}
    elif rates is not None:
        rates = {"crank.angle": rates}
    for _ in range(2):  # the first sweep of the mechanism, then the short road
        sw = kincas.sweep(m, {"crank.angle": th}, rates=rates, report=REPORT)
        check(sw, th, 3.5, w)
        assert np.array_equal(sw.rates["crank.angle"], np.broadcast_to(w, th.shape))


def test_a_sweeps_inputs_and_rates_are_its_own():
    m, th = fourbar(), np.linspace(0, 2 * np.pi, 60)
    w = np.full(60, 3.0)
    sw = kincas.sweep(m, {"crank.angle": th}, rates={"crank.angle": w}, report=REPORT)
    th_copy = th.copy()
    th += 1.0
    w[:] = -7.0
    assert np.array_equal(sw.inputs["crank.angle"], th_copy) and (sw.rates["crank.angle"] == 3.0).all()
    check(sw, th_copy, 3.5, 3.0)


def test_other_mechanisms_are_not_taken_for_one_swept_before():
    th = np.linspace(0.2, 2.0, 40)
    m = fourbar(3.5)
    for mech, b in ((m, 3.5), (m.with_parameters(b=3.6), 3.6), (fourbar(3.5), 3.5), (m, 3.5),
                    (fourbar(3.45), 3.45)):
        check(kincas.sweep(mech, {"crank.angle": th}, report=REPORT), th, b, 1.0)


def test_an_unknown_name_fails_on_every_call():
    m, th = fourbar(), np.linspace(0, 1, 5)
    kincas.sweep(m, {"crank.angle": th}, report=REPORT)
    for _ in range(2):
        with pytest.raises(ModelError, match="nowhere"):
            kincas.sweep(m, {"crank.angle": th}, report=["nowhere.x"])


def test_inputs_checked_finite_whatever_their_size():
    m = fourbar()
    with pytest.raises(ModelError, match="finite"):
        kincas.sweep(m, {"crank.angle": np.array([0.0, np.nan, 1.0])}, report=["C.x"])
    with pytest.raises(ModelError, match="finite"):
        kincas.sweep(m, {"crank.angle": np.array([0.0, np.inf])}, report=["C.x"])
    th = np.array([1e200, -1e200])
    sw = kincas.sweep(m, {"crank.angle": th}, report=["C.x", "C.y"])
    C = closed_C(th, 3.5)  # the crank at angle 1e200 rad is somewhere on its circle
    solved = sw.ok
    assert np.abs(np.array([sw["C.x"], sw["C.y"]])[:, solved] - C[:, solved]).max(initial=0) < 1e-9


# --- what the warm road keeps per mechanism, report and guess must never be served to another ---


def test_two_mechanisms_one_length_apart_swept_alternately():
    """Same structure, same report list, same input array, coupler 3.5 against 3.4: each sweep
    gives its own mechanism's closed form, however they alternate (warm and compiled)."""
    th = np.linspace(0.1, 6.0, 120)
    m1, m2 = fourbar(3.5), fourbar(3.4)
    kincas.sweep(m1, {"crank.angle": th}, report=REPORT, compile=True)
    for mech, b in [(m1, 3.5), (m2, 3.4), (m1, 3.5), (m2, 3.4), (m2, 3.4), (m1, 3.5)]:
        check(kincas.sweep(mech, {"crank.angle": th}, rates={"crank.angle": 2.0}, report=REPORT), th, b, 2.0)


def test_a_changed_guess_picks_the_other_branch_every_time():
    """The guess (C above or below the ground line) picks the branch on every call: the
    placement kept for one guess is not served for the other."""
    th = np.linspace(0.1, 6.0, 90)
    m = fourbar()
    for sign in (+1, -1, +1, -1, -1, +1):
        sw = kincas.sweep(m, {"crank.angle": th}, report=REPORT, guess={"C": (3.6, sign * 2.9)})
        C = closed_forms.fourbar((0, 0), (4, 0), 1.0, 3.5, 3.0, th, sign)[1].T
        assert sw.ok.all() and np.abs(np.array([sw["C.x"], sw["C.y"]]) - C).max() < 1e-12
    # and the mechanism's own guess (upper) again, after the others
    check(kincas.sweep(m, {"crank.angle": th}, report=REPORT), th, 3.5, 1.0)


def test_reports_swept_alternately_give_each_their_own_values():
    th = np.linspace(0.1, 6.0, 60)
    m = fourbar()
    C = closed_C(th, 3.5)
    for rep in (["C.y"], ["C.x", "C.y"], ["C.y", "C.x"], ["C.y"], REPORT, ["C.x"]):
        sw = kincas.sweep(m, {"crank.angle": th}, report=rep)
        assert sw.names == rep
        for name in rep[:2]:
            want = C[0] if name == "C.x" else C[1] if name == "C.y" else None
            if want is not None:
                assert np.abs(sw[name] - want).max() < 1e-12


def test_ok_follows_the_status_as_it_is_now():
    """`Sweep.ok` is `status == "ok"` whatever was assigned to the status since, and an
    "ok" that is an equal string but not the same object counts as solved."""
    sw = kincas.sweep(fourbar(), {"crank.angle": np.linspace(0.1, 1.0, 6)}, report=["C.x"])
    assert sw.ok.tolist() == [True] * 6 and sw.ok.dtype == bool
    sw.status[2] = "no assembly"
    assert sw.ok.tolist() == [True, True, False, True, True, True]
    sw.status[2] = "".join(["o", "k"])  # equal, not identical
    assert sw.ok.tolist() == [True] * 6
    sw.status[0] = None
    assert sw.ok.tolist() == [False] + [True] * 5
    a, b = sw.ok, sw.ok
    a[1] = False
    assert b[1] and sw.ok[1]  # each call a mask of its own


def test_iterations_are_newtons_steps_with_careful_poses_too():
    """A sweep through the four-bar's limits (coupler 4, rocker 0.8: the crank cannot turn
    round) has poses with no assembly and poses solved on the careful path; its iteration
    counts stay non-negative integers, and each solved pose's C lies on both circles."""
    m = Mechanism(ground={"A": (0, 0), "D": (4, 0)},
                  links=[Link.bar("crank", "A", "B", 1), Link.bar("coupler", "B", "C", 4),
                         Link.bar("rocker", "D", "C", 0.8)],
                  inputs=[Input.angle("crank")], guess={"C": (4.2, 0.77)})
    th = np.linspace(1.5, 1.5 + 2 * np.pi, 73)
    for _ in range(2):
        sw = kincas.sweep(m, {"crank.angle": th}, report=["C.x", "C.y"])
        x, y = sw["C.x"][sw.ok], sw["C.y"][sw.ok]
        assert np.abs(np.hypot(x - np.cos(th[sw.ok]), y - np.sin(th[sw.ok])) - 4).max() < 1e-12
        assert np.abs(np.hypot(x - 4, y) - 0.8).max() < 1e-12
        assert sw.iterations.dtype.kind == "i" and (sw.iterations >= 0).all()
        assert sw.ok.any() and not sw.ok.all()
        assert (sw.ok == (sw.status == "ok")).all()


def test_reported_angles_are_wrapped_beside_other_names():
    """Angles among other names are still taken into (-pi, pi] (the Sweep looks for angle
    names once over all the names): the crank driven to 3 pi reports its angle wrapped."""
    m, th = fourbar(), np.linspace(0.0, 3 * np.pi, 50)
    for rep in (["C.x", "crank.angle"], ["crank.angle"], ["C.x", "C.y"]):
        sw = kincas.sweep(m, {"crank.angle": th}, report=rep)
        if "crank.angle" in rep:
            a = sw["crank.angle"]
            assert (a > -np.pi).all() and (a <= np.pi).all()
            assert np.abs(np.exp(1j * a) - np.exp(1j * th)).max() < 1e-12
        assert np.array_equal(sw.inputs["crank.angle"], th)



def test_the_first_pose_solved_once_per_inputs_and_guess_is_never_served_elsewhere():
    """The careful path's first pose (a search from a rough guess) is kept per placement:
    sweeps starting at other inputs, from the other branch's guess, or of a mechanism one
    length apart must each get their own, and a caller changing its arrays changes nothing."""
    m, m2 = fourbar(), fourbar(3.6)
    for k, t0 in enumerate([0.0, 0.3, 0.0, 0.3] * 2):
        th = np.linspace(t0, t0 + 2 * np.pi, 37)
        mech, b = (m, 3.5) if k < 4 else (m2, 3.6)
        sw = kincas.sweep(mech, {"crank.angle": th}, report=REPORT, guess={"C": (2.5, 1.0)})
        check(sw, th, b, 1.0)  # (a rough guess: the kernel leaves pose 0 to the careful path)
        sw["C.x"][:] = np.nan  # the caller's own arrays: nothing kept is touched
        low = kincas.sweep(mech, {"crank.angle": th}, report=["C.y"], guess={"C": (2.5, -1.0)})
        C_low = closed_forms.fourbar((0, 0), (4, 0), 1.0, b, 3.0, th, -1)[1].T
        assert low.ok.all() and np.abs(low["C.y"] - C_low[1]).max() < 1e-12


# --- what a warm sweep leaves for later, and the one-pass test of "nothing met" ---


def test_status_flags_and_iterations_made_when_read_are_the_sweeps_own():
    """A sweep with every pose solved makes its status, flags and iteration counts when first
    read: each read gives the same array (a change made to it stays), two sweeps never share
    one, `ok` before and after any read follows the status, and a copy or a pickle keeps them."""
    import copy
    import pickle
    m, th = fourbar(), np.linspace(0.1, 6.0, 40)
    a = kincas.sweep(m, {"crank.angle": th}, report=REPORT)
    b = kincas.sweep(m, {"crank.angle": th}, report=REPORT)
    assert a.ok.dtype == bool and a.ok.all() and len(a.ok) == 40  # before any read of status
    assert a.status is a.status and a.status.dtype == object and a.status.tolist() == ["ok"] * 40
    assert a.flags == [None] * 40 and a.flags is a.flags
    assert a.iterations.dtype.kind == "i" and (a.iterations >= 0).all() and a.iterations is a.iterations
    a.status[3], a.flags[5] = "no assembly", "limit"
    assert not a.ok[3] and a.ok.sum() == 39 and a.flags[5] == "limit"
    assert b.ok.all() and b.status.tolist() == ["ok"] * 40 and b.flags == [None] * 40  # not shared
    c = pickle.loads(pickle.dumps(b))
    d = copy.deepcopy(a)
    assert c.ok.all() and c.status.tolist() == ["ok"] * 40 and c.flags == [None] * 40
    assert d.status[3] == "no assembly" and d.flags[5] == "limit" and d.ok.sum() == 39
    b.status = ["ok"] * 39 + ["gone"]  # set whole: an object array again
    assert b.status.dtype == object and b.ok.tolist() == [True] * 39 + [False]
    check(c, th, 3.5, 1.0)


def edge_tables(rng, trials, groups):
    """(signs, sigma, M) tables of the kernel's measures (M: each pose's modes, then sigma)
    built to sit on every edge of `nothing_met`: in turn as they are, a mode flipped at one
    pose, a mode 0 or NaN, a sigma at, just above or just below the bound, or NaN; 1 to 40
    poses, groups() groups."""
    from kincas.analysis.events import _SIGMA_BOUND
    edges = [_SIGMA_BOUND, np.nextafter(_SIGMA_BOUND, 1), np.nextafter(_SIGMA_BOUND, 0), np.nan, 0.3, 1.0]
    for trial in range(trials):
        n, g = int(rng.choice([1, 2, 7, 40])), groups()
        signs = np.tile(rng.choice([-1.0, 1.0], g), (n, 1))
        sigma = rng.uniform(0.01, 1.0, n)
        kind = trial % 5
        if kind == 1:
            signs[rng.integers(n), rng.integers(g)] *= -1
        elif kind == 2:
            signs[rng.integers(n), rng.integers(g)] = rng.choice([0.0, np.nan])
        elif kind == 3:
            sigma[rng.integers(n)] = rng.choice(edges)
        M = np.empty((n, g + 1))
        M[:, :g], M[:, g] = signs, sigma
        yield signs, sigma, M


def test_nothing_met_from_the_kernels_measures_agrees_with_the_general_test():
    """`nothing_met_measures` (modes summed, one comparison) answers as `nothing_met` on
    tables of modes and sigmas built to sit on every edge: a mode changing once, a mode 0
    or NaN, a sigma at, just above and just below the bound, NaN, one pose, two groups, and
    more groups than are checked in Python."""
    from kincas.analysis.events import nothing_met, nothing_met_measures
    tried = {True: 0, False: 0}
    rng = np.random.default_rng(7)
    for signs, sigma, M in edge_tables(rng, 400, lambda: int(rng.choice([1, 2, 3, 12, 41]))):  # (beyond 8: numpy's sums)
        want = nothing_met(np.ones(len(M), dtype=bool), signs, sigma, True)
        assert nothing_met_measures(M, M.ravel()) == want, (signs, sigma)
        tried[want] += 1
    assert min(tried.values()) > 50  # both answers were met often


def test_a_first_poses_correction_summed_by_numpy_is_pythons_sum():
    """`_moved_within` (the first pose's correction per group, FastSweeper._from_guess) sums
    |q - q0| w per group with np.bincount beyond a few unknowns: the same numbers as Python's
    sums in the order of q, so the same answer at and around CORRECTION, with NaN too (where
    Python's max decides), with unknowns of no group, and with one group."""
    from kincas.core.fast import CORRECTION, _moved_within
    rng = np.random.default_rng(11)
    for trial in range(300):
        nq, ng = int(rng.integers(1, 40)), int(rng.integers(1, 6))
        of = rng.integers(0, ng + 1, nq)  # (ng: an unknown of no group)
        if trial % 5 == 0:  # one group holding every unknown
            ng, of = 1, np.zeros(nq, dtype=int)
        q0, w = rng.normal(size=nq), rng.uniform(0.1, 10.0, nq)
        q = q0 + rng.normal(size=nq) * CORRECTION * rng.choice([0.01, 0.3, 1.0, 3.0])
        if trial % 7 == 0:  # exactly at the bound in one group
            i = int(rng.integers(nq))
            q = q0.copy()
            q[i] = q0[i] + CORRECTION / w[i]
        if trial % 11 == 0:
            q[int(rng.integers(nq))] = np.nan
        # the sums written out, term by term in the order of q
        moved = [0.0] * (ng + 1)
        for g, a, b, x in zip(of.tolist(), q.tolist(), q0.tolist(), w.tolist()):
            moved[g] += abs(a - b) * x
        want = max(moved[:-1]) <= CORRECTION
        got_list = _moved_within(q, q0.tolist(), w.tolist(), of.tolist(), of, ng)
        got_numpy = _moved_within(q, q0, w, of.tolist(), of, ng)
        assert got_list == got_numpy == want, (trial, moved)
        if ng == 1 and not of.any():  # one group holding every unknown: its sum alone
            assert _moved_within(q, q0.tolist(), w.tolist(), None, of, 1) == want, (trial, moved)


# --- what a warm sweep keeps between calls (a run's layout per sweeper and sizes, kept by
# kincas/core/fast_run.py) never gives a stale answer, nor one thread's to another ---

REPORT_A = REPORT + ["C.ax", "C.ay"]


def check_accelerations(sw, th, b, w, alpha):
    """Positions, velocities w dC/dth and accelerations w^2 C'' + alpha C' (central
    differences of the closed form) at every pose."""
    e = 1e-4
    C, Cp, Cm = closed_C(th, b), closed_C(th + e, b), closed_C(th - e, b)
    d1, d2 = (Cp - Cm) / (2 * e), (Cp - 2 * C + Cm) / e ** 2
    assert sw.ok.all()
    assert np.abs(np.array([sw["C.x"], sw["C.y"]]) - C).max() < 1e-12
    assert np.abs(np.array([sw["C.vx"], sw["C.vy"]]) - w * d1).max() < 1e-6 * max(1.0, np.abs(w).max())
    assert np.abs(np.array([sw["C.ax"], sw["C.ay"]]) - (w ** 2 * d2 + alpha * d1)).max() < 1e-4


def test_a_kept_layout_gives_each_mechanism_length_and_rate_its_own_numbers():
    """Same structure (one sweeper), two couplers, two lengths, rates and accelerations given
    as a number and one per pose, swept in turn: every sweep matches its own closed form
    (a layout kept for one set of sizes serves the others only where the sizes agree)."""
    m1, m2 = fourbar(3.5), fourbar(3.3)
    cases = []
    for n in (90, 37):
        th = np.linspace(0.1, 6.0, n)
        w_pose, a_pose = 1.0 + 0.5 * np.sin(th), 0.3 * np.cos(th)
        cases += [(m1, 3.5, th, 2.0, 0.0, None), (m2, 3.3, th, 2.0, 0.0, None),
                  (m1, 3.5, th, w_pose, 0.0, None), (m2, 3.3, th, -1.5, 0.7, 0.7),
                  (m1, 3.5, th, w_pose, a_pose, a_pose)]
    for _ in range(2):
        for mech, b, th, w, alpha, acc in cases:
            kw = {} if acc is None else {"accelerations": {"crank.angle": acc}}
            sw = kincas.sweep(mech, {"crank.angle": th}, rates={"crank.angle": w}, report=REPORT_A, **kw)
            check_accelerations(sw, th, b, w, alpha)
            assert np.array_equal(sw.rates["crank.angle"], np.broadcast_to(w, th.shape))
            assert np.array_equal(sw.inputs["crank.angle"], th)


def test_two_threads_sweeping_one_mechanism_get_what_each_gets_alone(monkeypatch):
    """One mechanism, two threads, different inputs (lengths, ranges, rates) swept at once
    many times: each result is, number for number, the one its thread gets alone. (The
    kernel may compile in the background meanwhile: with libm's sines in the compiled code,
    the virtual machine's and the library's numbers are the same bit for bit; with fdlibm's,
    the default, they agree to rounding, kincas/core/c_source.py.)"""
    monkeypatch.setenv("KINCAS_LIBM_TRIG", "1")
    m = fourbar()
    jobs = [(np.linspace(0.1, 6.0, 360), 2.0), (np.linspace(-1.0, 2.5, 200), np.linspace(1.0, 3.0, 200))]
    alone = [kincas.sweep(m, {"crank.angle": th}, rates={"crank.angle": w}, report=REPORT_A) for th, w in jobs]
    for (th, w), sw in zip(jobs, alone):
        check_accelerations(sw, th, 3.5, w, 0.0)
    bad, barrier = [], threading.Barrier(2)

    def work(i):
        th, w = jobs[i]
        barrier.wait()
        for _ in range(150):
            sw = kincas.sweep(m, {"crank.angle": th}, rates={"crank.angle": w}, report=REPORT_A)
            for k in REPORT_A:
                if not np.array_equal(sw[k], alone[i][k]):
                    bad.append((i, k))
            if not (sw.ok.all() and np.array_equal(sw.q, alone[i].q)):
                bad.append((i, "q"))
    threads = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not bad, bad[:5]


def test_a_result_built_on_the_warm_road_has_every_field_of_its_own():
    """`Sweep._built` makes the dict it is given the result's attributes: two sweeps share
    none of their containers, and status, flags and iterations are made when first read."""
    m, th = fourbar(), np.linspace(0.1, 6.0, 50)
    a = kincas.sweep(m, {"crank.angle": th}, report=REPORT_A)
    b = kincas.sweep(m, {"crank.angle": th}, report=REPORT_A)
    for name in ("inputs", "rates", "accelerations", "values", "events", "info"):
        assert getattr(a, name) is not getattr(b, name)
    a.values["C.x"] = None  # a change to one result's dict is its own
    assert b.values["C.x"] is not None and a.info == {"fast pass": b.info["fast pass"]}
    assert b.status.tolist() == ["ok"] * 50 and b.flags == [None] * 50 and b.iterations.dtype.kind == "i"


def test_one_sweeper_runs_rates_given_as_one_row_and_as_a_table_in_turn():
    """A `FastSweeper.run` with rates as one row for every pose (stride 0), then as a table,
    then as a row again (three layouts of one length): each run's velocities are its own."""
    from kincas.core.fast import sweeper_for
    m = fourbar()
    model = kincas.model_of(m)
    fs = sweeper_for(model, ("C.vx", "C.vy"), compile=True)
    th = np.linspace(0.1, 6.0, 120)
    U, p = th[:, None], np.array([3.5])
    q0 = model.newton(model.initial_q(U[0], p, {"C": (3.6, 2.9)}, 4.0), U[0], p, 4.0).q
    e = 1e-6
    d1 = (closed_C(th + e, 3.5) - closed_C(th - e, 3.5)) / (2 * e)
    for w in (np.array([2.0]), np.linspace(1.0, 2.0, 120)[:, None], np.array([-0.5]), np.full((120, 1), 3.0)):
        run = fs.run(U, p, 4.0, q0, U[0], start=0, Ud=w)
        assert run.first_bad == 120
        assert np.abs(run.values - w.ravel() * d1).max() < 1e-6 * np.abs(w).max()


def test_threads_reading_a_field_made_later_at_once_get_one_object():
    """Status, flags and iterations made on first read: four threads reading them together
    get the same objects (made once), each what the sweep solved."""
    m, th = fourbar(), np.linspace(0.1, 6.0, 40)
    for _ in range(20):
        sw = kincas.sweep(m, {"crank.angle": th}, report=REPORT)
        got, barrier = [], threading.Barrier(4)

        def read():
            barrier.wait()
            got.append((sw.status, sw.flags, sw.iterations))
        threads = [threading.Thread(target=read) for _ in range(4)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        assert all(g[i] is got[0][i] for g in got for i in range(3))
        assert got[0][0].tolist() == ["ok"] * 40 and got[0][1] == [None] * 40
        assert got[0][2].dtype.kind == "i" and (got[0][2] >= 0).all()


def _measures_summary_lib(m):
    """The compiled library of a mechanism's fast sweep, as `kincas.sweep` builds it."""
    from kincas.core.c_library import compiling_disabled
    from kincas.core.fast import FastSweeper
    if compiling_disabled():
        pytest.skip("compiling disabled")
    fast = FastSweeper(kincas.model_of(m), ["C.x"] if "C" in m.moving_points else [], compile=True)
    return fast, fast.backend.compiled(1)


@pytest.mark.parametrize("units", [0, 3])
def test_the_compiled_loops_summary_of_the_measures_agrees_with_the_general_test(units):
    """`kincas_measures_summary` (C: modes unlike the first pose's counted, the smallest sigma)
    read by `nothing_met_summary` answers as `nothing_met` on tables built to sit on every
    edge (a mode changing once, a mode 0 or NaN, a sigma at, just above and just below the
    bound, NaN, one pose), with one Assur group (a four-bar) and three (chained four-bars)."""
    import ctypes
    from kincas.analysis.events import nothing_met, nothing_met_summary
    from test_group_kernel import chain
    fast, lib = _measures_summary_lib(fourbar() if units == 0 else chain(units))
    g = len(fast.blocks)
    assert g == (1 if units == 0 else units)
    tried = {True: 0, False: 0}
    for signs, sigma, M in edge_tables(np.random.default_rng(5), 300, lambda: g):
        out = np.full(2, -1.0)
        lib.kincas_measures_summary(len(M), M.ctypes.data_as(ctypes.c_void_p), out.ctypes.data_as(ctypes.c_void_p))
        want = nothing_met(np.ones(len(M), dtype=bool), signs, sigma, True)
        assert nothing_met_summary(out) == want, (signs, sigma, out)
        assert out[0] == np.count_nonzero(~(signs == signs[0]))  # (NaN: unlike everything)
        tried[want] += 1
    assert min(tried.values()) > 40


@pytest.mark.parametrize("b", [3.5, 2.0 + 1e-9, 2.001])
@pytest.mark.parametrize("how", ["from the guess", "careful first pose", "in blocks", "virtual machine"])
def test_a_sweeps_summary_is_its_measures(b, how):
    """Whatever road a sweep took (the kernel from the first pose, the careful path first, a
    progress callback's blocks, the virtual machine), the summary it hands `kincas.sweep`,
    where it has one, is that of its whole table of measures; and the sweep meets a
    near-singular pose (b = 2 + 1e-9: the coupler and rocker next to collinear at crank
    angle pi, g_q's smallest singular value 1.7e-5 of its size) as it met it before."""
    import kincas.core.fast_run as fast_run
    from kincas.analysis.events import nothing_met_measures, nothing_met_summary
    th = np.linspace(0, 2 * np.pi, 361)
    m = fourbar(b)  # (its guess (3.6, 2.9) is too far for the kernel: the careful path places C)
    if how != "careful first pose":  # the kernel takes the first pose from a guess next to it
        m = m.with_guess(C=tuple(closed_C(th[:1], b)[:, 0] + 1e-3))
    seen = []
    real = fast_run.FastRun.summary

    def spy(run):
        s = real(run)
        seen.append((s, nothing_met_measures(run.measures_by_pose()[0])))
        return s
    kw = {"progress": lambda a, b: None} if how == "in blocks" else {}
    careful, record = [], fast_run.FastRun.record

    def recording(run, k, sol):
        careful.append(k)
        return record(run, k, sol)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(fast_run.FastRun, "summary", spy)
        mp.setattr(fast_run.FastRun, "record", recording)
        mp.setattr("kincas.core.fast.BLOCK", 100)
        sw = kincas.sweep(m, {"crank.angle": th}, report=["C.x"], compile=how != "virtual machine", **kw)
    assert sw.ok.all() and len(seen) == 1
    (summary, want), = seen
    if how == "virtual machine":
        assert summary is None and sw.info["fast pass"] == "virtual machine"
    else:
        assert summary is not None and nothing_met_summary(summary) == want
        assert (0 in careful) == (how == "careful first pose")
    assert want == (b != 2.0 + 1e-9)
    C = closed_C(th, b)
    assert np.abs(sw["C.x"] - C[0]).max() < 1e-9  # (next to collinear the closed form's own rounding grows)


def test_a_run_from_a_later_pose_has_no_summary():
    """`FastSweeper.run` from pose 1 (pose 0's measures never written by the loop, then NaN):
    no summary, though its one call reached the last pose."""
    from kincas.core.fast import FastSweeper
    from test_fast import first_pose
    m = fourbar()
    U = np.linspace(0.2, 1.2, 50)[:, None]
    model, p, L, q0 = first_pose(m, U)
    run = FastSweeper(model, ["C.x"], compile=True).run(U, p, L, q0, U[0], start=1)
    assert run.first_bad == len(U) and run.summary() is None
