"""What a warm sweep keeps between calls must never give a stale answer (issue [15]): the
layout of a run's block (kept per sweeper and sizes: poses, the rates' and accelerations'
strides, parameters) is reused by other mechanisms of the same structure, other input values
of the same length and other rates; and two threads sweeping one mechanism with different
inputs at once get what each gets alone. Checked against the circle-intersection closed form
of the four-bar and its derivative by central differences (as tests/test_warm_sweep.py)."""
import threading

import numpy as np

import closed_forms
import kincas
from kincas import Input, Link, Mechanism

REPORT = ["C.x", "C.y", "C.vx", "C.vy", "C.ax", "C.ay"]


def fourbar(b=3.5):
    return Mechanism(parameters={"b": b}, ground={"A": (0, 0), "D": (4, 0)},
                     links=[Link.bar("crank", "A", "B", 1.0), Link.bar("coupler", "B", "C", "b"),
                            Link.bar("rocker", "D", "C", 3.0)],
                     inputs=[Input.angle("crank")], guess={"C": (3.6, 2.9)})


def closed_C(th, b):
    return closed_forms.fourbar((0, 0), (4, 0), 1.0, b, 3.0, th, +1)[1].T


def check(sw, th, b, w, alpha):
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
            sw = kincas.sweep(mech, {"crank.angle": th}, rates={"crank.angle": w}, report=REPORT, **kw)
            check(sw, th, b, w, alpha)
            assert np.array_equal(sw.rates["crank.angle"], np.broadcast_to(w, th.shape))
            assert np.array_equal(sw.inputs["crank.angle"], th)


def test_two_threads_sweeping_one_mechanism_get_what_each_gets_alone():
    """One mechanism, two threads, different inputs (lengths, ranges, rates) swept at once
    many times: each result is, number for number, the one its thread gets alone."""
    m = fourbar()
    jobs = [(np.linspace(0.1, 6.0, 360), 2.0), (np.linspace(-1.0, 2.5, 200), np.linspace(1.0, 3.0, 200))]
    alone = [kincas.sweep(m, {"crank.angle": th}, rates={"crank.angle": w}, report=REPORT) for th, w in jobs]
    for (th, w), sw in zip(jobs, alone):
        check(sw, th, 3.5, w, 0.0)
    bad, barrier = [], threading.Barrier(2)

    def work(i):
        th, w = jobs[i]
        barrier.wait()
        for _ in range(150):
            sw = kincas.sweep(m, {"crank.angle": th}, rates={"crank.angle": w}, report=REPORT)
            for k in REPORT:
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
    a = kincas.sweep(m, {"crank.angle": th}, report=REPORT)
    b = kincas.sweep(m, {"crank.angle": th}, report=REPORT)
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
