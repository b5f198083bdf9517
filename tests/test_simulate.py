"""Forward dynamics (kincas.simulate, `kincas simulate`), checked against answers written here:
energy conservation, an independent scipy integration of the slider-crank's reduced-inertia
equation, the kinetostatic effort of the simulated motion, and the events that stop it."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

import kincas
from kincas.analysis.simulate import simulate
from kincas.cli.app import main
from kincas.cli.scene import load

G = 9.81


def _fourbar():
    return kincas.Mechanism(
        ground={"A": (0, 0), "D": (0.4, 0)}, gravity=(0, -G),
        links=[kincas.Link.bar("crank", "A", "B", 0.2, mass=1.0, inertia=0.004),
               kincas.Link.bar("coupler", "B", "C", 0.5, mass=2.0, inertia=0.05),
               kincas.Link.bar("rocker", "D", "C", 0.4, mass=1.5, inertia=0.02)],
        inputs=[kincas.Input.angle("crank")], guess={"C": (0.5, 0.4)})


def _energy(r):
    """Kinetic plus potential energy from the points' velocities (each link's centre of
    gravity is the middle of its two points): nothing of kincas's efforts."""
    v = r.values
    mid = lambda a, b: (np.asarray(a) + np.asarray(b)) / 2  # noqa: E731
    T = (0.5 * 1.0 * (mid(0, v["B.vx"]) ** 2 + mid(0, v["B.vy"]) ** 2) + 0.5 * 0.004 * v["crank.omega"] ** 2
         + 0.5 * 2.0 * (mid(v["B.vx"], v["C.vx"]) ** 2 + mid(v["B.vy"], v["C.vy"]) ** 2)
         + 0.5 * 0.05 * v["coupler.omega"] ** 2
         + 0.5 * 1.5 * (mid(0, v["C.vx"]) ** 2 + mid(0, v["C.vy"]) ** 2) + 0.5 * 0.02 * v["rocker.omega"] ** 2)
    V = G * (1.0 * mid(0, v["B.y"]) + 2.0 * mid(v["B.y"], v["C.y"]) + 1.5 * mid(0, v["C.y"]))
    return T + V


REPORT = ["B.vx", "B.vy", "C.vx", "C.vy", "B.y", "C.y", "crank.omega", "coupler.omega", "rocker.omega"]


def test_pendulum_fourbar_conserves_energy():
    r = simulate(_fourbar(), 2.0, 201, initial={"crank.angle": math.radians(30)}, report=REPORT,
                 tolerance=1e-12)
    assert r.ok
    E = _energy(r)
    scale = np.ptp(_energy_kinetic(r)) or 1.0
    assert np.max(np.abs(E - E[0])) / scale < 1e-9
    assert np.ptp(r.inputs["crank.angle"]) > 1.0  # it did swing


def _energy_kinetic(r):
    v = r.values
    return 0.5 * (v["B.vx"] ** 2 + v["C.vx"] ** 2 + v["crank.omega"] ** 2)


def test_effort_of_the_free_input_vanishes_along_the_motion():
    """The simulated accelerations are the rates' derivatives (central differences), and with
    them kincas's kinetostatics needs no effort on the free input."""
    r = simulate(_fourbar(), 0.3, 301, initial={"crank.angle": 0.5}, rates={"crank.angle": 2.0},
                 tolerance=1e-12)
    w, a, h = r.rates["crank.angle"], r.accelerations["crank.angle"], r.time[1] - r.time[0]
    fd = (w[2:] - w[:-2]) / (2 * h)
    assert np.max(np.abs(fd - a[1:-1])) < 1e-3 * np.max(np.abs(a))
    sw = kincas.sweep(_fourbar(), {"crank.angle": r.inputs["crank.angle"]}, rates={"crank.angle": w},
                      accelerations={"crank.angle": a}, report=["effort(crank.angle)"])
    torque_scale = G * 4.5 * 0.4
    assert np.max(np.abs(sw["effort(crank.angle)"])) < 1e-9 * torque_scale


# --- the slider-crank against its own reduced-inertia equation, integrated by scipy ---

R, L, MP, JC, T0 = 0.05, 0.18, 2.0, 0.01, 3.0


def _slider_crank(torque="T"):
    return kincas.Mechanism(
        parameters={"T": 0.0, "F": 0.0}, ground={"O": (0, 0)},
        links=[kincas.Link.bar("crank", "O", "A", R, inertia=JC, cg=(0, 0)),
               kincas.Link.bar("rod", "A", "B", L, mass=MP, cg=(L, 0))],
        slides=[kincas.Slide(point="B", along="ground", through=(0, 0), angle=0.0, name="guide")],
        inputs=[kincas.Input.angle("crank")], guess={"B": (0.23, 0)},
        loads=[kincas.Load.torque("crank", torque), kincas.Load.force("B", ("F", 0))])


def _hand_written(theta0, w0, times, force):
    """(J + m x'^2) theta'' + m x' x'' theta'^2 = T + F(theta, w) x', with x the piston's
    position in closed form."""
    from scipy.integrate import solve_ivp

    def rhs(t, y):
        th, w = y
        s, c = math.sin(th), math.cos(th)
        S = math.sqrt(L * L - R * R * s * s)
        x1 = -R * s - R * R * s * c / S
        x2 = -R * c - R * R * (c * c - s * s) / S - R ** 4 * s * s * c * c / S ** 3
        return [w, (T0 + force(th, w) * x1 - MP * x1 * x2 * w * w) / (JC + MP * x1 * x1)]
    sol = solve_ivp(rhs, (times[0], times[-1]), [theta0, w0], t_eval=times, rtol=1e-12, atol=1e-12,
                    method="DOP853")
    return sol.y


def test_slider_crank_against_scipy_reduced_inertia():
    times = np.linspace(0, 0.5, 51)
    r = simulate(_slider_crank(), 0.5, 51, initial={"crank.angle": 0.3}, rates={"crank.angle": 5.0},
                 expressions={"T": str(T0), "F": "-20 * (1 + sin(crank.angle)) - 0.5 * B.vx"},
                 tolerance=1e-12)
    th, w = _hand_written(0.3, 5.0, times, lambda th, w: -20 * (1 + math.sin(th))
                          - 0.5 * (-R * math.sin(th) - R * R * math.sin(th) * math.cos(th)
                                   / math.sqrt(L * L - R * R * math.sin(th) ** 2)) * w)
    assert r.ok
    assert np.max(np.abs(r.inputs["crank.angle"] - th)) < 1e-8
    assert np.max(np.abs(r.rates["crank.angle"] - w)) < 1e-7 * np.max(np.abs(w))


# --- events ---


def test_a_free_slider_stops_at_its_dead_centre():
    """The piston as the free input, pushed outwards: it reaches s = l + r (the crank and the
    rod in line), a limit of its own coordinate, in finite time, and the motion stops there."""
    m = kincas.Mechanism(
        ground={"O": (0, 0)},
        links=[kincas.Link.bar("crank", "O", "A", R, inertia=JC, cg=(0, 0)),
               kincas.Link.bar("rod", "A", "B", L, mass=MP, cg=(L, 0))],
        slides=[kincas.Slide(point="B", along="ground", through=(0, 0), angle=0.0, name="guide")],
        inputs=[kincas.Input.slide("guide")], guess={"A": (0.03, 0.04)},
        loads=[kincas.Load.force("B", (50.0, 0))])
    r = simulate(m, 1.0, 101, initial={"guide.s": 0.2})
    assert not r.ok and len(r.events) == 1
    e = r.events[0]
    assert "limit" in e["reason"] and 0 < e["time"] < 1.0
    s = r.inputs["guide.s"]
    last = s[np.isfinite(s)][-1]
    assert last < R + L and R + L - last < 1e-3
    assert np.all(r.status[r.time > e["time"]] == "not reached")


def test_cam_follower_leaves_a_weak_spring(tmp_path, capsys):
    status = main(["simulate", "examples/simulate_cam_spring.toml", "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert status == 3
    (e,) = doc["events"]
    assert "contact lost" in e["reason"] and 0 < e["time"] < doc["inputs"]["t"][-1]
    n = sum(t <= e["time"] for t in doc["inputs"]["t"])
    assert all(v is not None for v in doc["values"]["contact(cam)"][:n])
    assert doc["values"]["contact(cam)"][n - 1] > 0
    assert all(v is None for v in doc["values"]["contact(cam)"][n:])
    # the tappet's own equation of motion, vertically: N n_y + spring - m g = m a_y, with n
    # from the cam's centre to the roller's and the spring k (d - d0) on T = F + (0, 20)
    th = np.radians(doc["inputs"]["cam.angle"][:n])
    Fy, ay, N = (np.array(doc["values"][k][:n]) for k in ("F.y", "F.ay", "contact(cam)"))
    cx, cy = 10 * np.cos(th), 10 * np.sin(th)  # mm, t, N
    ny = (Fy - cy) / np.hypot(0 - cx, Fy - cy)
    d = 100 - (Fy + 20)
    assert np.max(np.abs(N * ny + 0.2 * (d - 60) - 0.0005 * 9810 - 0.0005 * ay)) < 1e-9 * 20


def test_cli_simulate_pendulum_json_and_csv(tmp_path, capsys):
    out = tmp_path / "p.csv"
    status = main(["simulate", "examples/simulate_pendulum_fourbar.toml", "--json", "--csv", str(out)])
    doc = json.loads(capsys.readouterr().out)
    assert status == 0
    assert set(doc) >= {"inputs", "values", "events"} and doc["events"] == []
    assert len(doc["inputs"]["t"]) == 201 and doc["inputs"]["crank.angle"][0] == pytest.approx(30)
    assert max(abs(x) for x in doc["values"]["effort(crank.angle)"]) < 1e-9 * 9810 * 0.0045 * 400
    text = out.read_text()
    assert text.count("\n") >= 201 and text.startswith("t [s],crank.angle [deg],crank.omega [deg/s],")


def test_scene_errors_name_the_field(tmp_path):
    text = open("examples/simulate_pendulum_fourbar.toml").read()
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace("duration = 2.0", "duration = -1"))
    with pytest.raises(kincas.SceneError, match=r"\[simulate\] duration"):
        load(bad)
    bad.write_text(text + '\n[[loads]]\nlink = "crank"\ntorque = "1 + nosuch(crank.omega)"\n')
    with pytest.raises(kincas.SceneError, match=r"\[\[loads\]\] 1: torque: unknown function 'nosuch'"):
        load(bad)
    bad.write_text(text + '\n[[loads]]\nlink = "crank"\ntorque = "2 * crank.omega * t"\n')
    with pytest.raises(kincas.ModelError, match=r"\[\[loads\]\] 1: torque: .* the time `t`"):
        load(bad).run()   # a sweep has no time (tests/test_solve_expression_loads.py)


# --- periodic steady state and flywheel ---

WHEEL = """
title = "wheel"
units = { length = "m", angle = "rad", time = "s" }
[parameters]
T0 = 10
ws = 100
A = 2
[ground]
O = [0, 0]
[links]
wheel = { points = ["O", "P"], length = 0.1, inertia = 0.01, cg = [0, 0] }
[[loads]]
link = "wheel"
torque = "T0 * (1 - wheel.omega / ws) + A * sin(wheel.angle)"
[[inputs]]
angle = "wheel"
free = true
value = 0
rate = 90
[simulate]
duration = 1
steps = 11
flywheel = { link = "wheel", inertia = 0.0 }
"""


def test_flywheel_of_a_sinusoidal_torque_against_the_energy_method(tmp_path, capsys):
    """T = T0 (1 - w/ws) + A sin(theta) on a wheel: the swing of the work is 2A, so to first
    order in Cs the inertia needed in all is 2A / (Cs w^2) (the energy method, exact as Cs -> 0)."""
    scene = tmp_path / "wheel.toml"
    scene.write_text(WHEEL)
    assert main(["flywheel", str(scene), "--fluctuation", "0.01", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    need = 2 * 2 / (0.01 * doc["w_mean"] ** 2)
    assert doc["fluctuation"] <= 0.01 and doc["fluctuation"] > 0.01 * (1 - 1e-6)
    assert abs(doc["estimate"] - need) < 1e-4 * need  # dE = 2A from kincas's net torque
    assert abs(doc["inertia"] + 0.01 - need) < 0.03 * need
    assert abs(doc["w_mean"] - 100) < 0.1


def test_steady_state_is_periodic_in_an_independent_time_integration(capsys):
    assert main(["simulate", "examples/simulate_engine.toml", "--steady", "--json"]) == 0
    st = json.loads(capsys.readouterr().out)
    assert st["cycle"] == pytest.approx(720)
    sc = load("examples/simulate_engine.toml")
    from kincas.cli.simulate import arguments_of
    kw = arguments_of(sc)
    kw["rates"]["crank.angle"] = math.radians(st["w0"])
    r = simulate(sc.mechanism, st["period"], 2001, **kw)
    th, w = np.degrees(r.inputs["crank.angle"]), np.degrees(r.rates["crank.angle"])
    assert abs(th[-1] - th[0] - 720) < 2e-8 * 720 and abs(w[-1] - w[0]) < 1e-7 * w[0]  # tolerance 1e-10
    assert st["w_mean"] == pytest.approx(720 / st["period"], rel=1e-12)
    assert 0 <= st["w_max"] - w.max() < 1e-5 * w.max() and 0 <= w.min() - st["w_min"] < 1e-5 * w.max()
    assert st["fluctuation"] == pytest.approx((st["w_max"] - st["w_min"]) / st["w_mean"], rel=1e-12)


def _double_pendulum():
    return kincas.Mechanism(ground={"O": (0, 0)}, gravity=(0, -G),
                            links=[kincas.Link.bar("a", "O", "A", 1.0, mass=1.0, inertia=0.1),
                                   kincas.Link.bar("b", "A", "B", 0.8, mass=0.5, inertia=0.05)],
                            inputs=[kincas.Input.angle("a"), kincas.Input.angle("b")])


def test_two_free_inputs_conserve_energy():
    """A double pendulum (no loop unknowns at all): both angles free, M a 2 x 2 matrix."""
    r = simulate(_double_pendulum(), 3.0, 301, initial={"a.angle": 1.0, "b.angle": 2.0}, tolerance=1e-12,
                 report=["A.vx", "A.vy", "B.vx", "B.vy", "A.y", "B.y", "a.omega", "b.omega"])
    v = r.values
    T = (0.5 * 1.0 * ((v["A.vx"] / 2) ** 2 + (v["A.vy"] / 2) ** 2) + 0.5 * 0.1 * v["a.omega"] ** 2
         + 0.5 * 0.5 * (((v["A.vx"] + v["B.vx"]) / 2) ** 2 + ((v["A.vy"] + v["B.vy"]) / 2) ** 2)
         + 0.5 * 0.05 * v["b.omega"] ** 2)
    E = T + G * (1.0 * v["A.y"] / 2 + 0.5 * (v["A.y"] + v["B.y"]) / 2)
    assert r.ok and np.ptp(E) < 1e-9 * np.ptp(T)


def test_a_held_input_drives_a_free_one():
    """The upper arm turned at a constant rate, the lower one free: kincas's kinetostatics of
    the simulated motion needs no effort on the free angle (its accelerations from the rates'
    central differences agree with the simulation's)."""
    r = simulate(_double_pendulum(), 1.0, 1001, free=["b.angle"], initial={"a.angle": 0.3, "b.angle": -1.0},
                 rates={"a.angle": 2.0}, tolerance=1e-12)
    assert r.ok and np.allclose(r.inputs["a.angle"], 0.3 + 2.0 * r.time, rtol=0, atol=1e-12)
    w, a, h = r.rates["b.angle"], r.accelerations["b.angle"], r.time[1] - r.time[0]
    assert np.max(np.abs((w[2:] - w[:-2]) / (2 * h) - a[1:-1])) < 1e-4 * np.max(np.abs(a))
    sw = kincas.sweep(_double_pendulum(), {k: r.inputs[k] for k in ("a.angle", "b.angle")},
                      rates={k: r.rates[k] for k in ("a.angle", "b.angle")},
                      accelerations={"a.angle": 0.0, "b.angle": a}, report=["effort(b.angle)"])
    assert np.max(np.abs(sw["effort(b.angle)"])) < 1e-9 * G * 0.5 * 0.8


def test_a_loads_expression_is_refused_where_it_was_written(tmp_path, capsys):
    text = open("examples/simulate_engine.toml").read()
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace('torque = "-Tm * crank.omega / w0"', 'torque = "-Tm * crank.alpha"'))
    assert main(["simulate", str(bad)]) == 2
    assert "[[loads]] 2: torque: 'crank.alpha': a load may depend on positions and velocities" in capsys.readouterr().err
    bad.write_text(text.replace('torque = "-Tm * crank.omega / w0"', 'torque = "-Tx * crank.omega"'))
    assert main(["simulate", str(bad)]) == 2
    assert "[[loads]] 2: torque: unknown name 'Tx' (parameters: ['r', 'l', 'Tm', 'w0']" in capsys.readouterr().err


def test_a_parallelogram_stops_at_its_change_point_in_time():
    """A parallelogram four-bar thrown round under gravity: at crank angle pi the links lie in
    line and the chain may fold either way (a change point: a singular position, not a limit).
    Energy gives the time to get there: I = 2 m (r/2)^2 + m r^2 (the coupler translates),
    V = m g sin(theta) (r/2 + r/2 + r)."""
    from scipy.integrate import quad
    m = kincas.Mechanism(ground={"A": (0, 0), "D": (1, 0)}, gravity=(0, -G),
                         links=[kincas.Link.bar("crank", "A", "B", 0.5, mass=1.0),
                                kincas.Link.bar("coupler", "B", "C", 1.0, mass=1.0),
                                kincas.Link.bar("rocker", "D", "C", 0.5, mass=1.0)],
                         inputs=[kincas.Input.angle("crank")], guess={"C": (1.3, 0.4)})
    r = simulate(m, 1.0, 101, initial={"crank.angle": 0.5}, rates={"crank.angle": 10.0})
    (e,) = r.events
    assert e["reason"].startswith("a singular position") and "change point" in e["reason"]
    inertia, weight = 2 * 0.25 ** 2 + 0.5 ** 2, G * 1.0
    w = lambda th: math.sqrt(100 + 2 * weight * (math.sin(0.5) - math.sin(th)) / inertia)  # noqa: E731
    t_pi = quad(lambda th: 1 / w(th), 0.5, math.pi, epsabs=1e-13)[0]
    # located within the output step (0.01 s) of the true time: at a change point the carried
    # q may cross onto the other branch within an integrator step, so the bisection, which
    # locates a dead centre to 1e-12, is only as sure as the output step here (docs/simulate.md)
    assert abs(t_pi - e["time"]) < 0.01 and np.all(r.status[r.time > t_pi + 0.01] == "not reached")


# --- rates written with their own unit (scene-format.md "Units that read as people write them") ---

def test_a_free_inputs_rate_string_is_converted(tmp_path, capsys):
    """`rate = "3000 rpm"` on the engine's free crank is 3000 * 360 / 60 = 18000 deg/s, the
    number the example writes: the same motion to the last digit."""
    text = open("examples/simulate_engine.toml").read()
    assert "rate = 18000 " in text
    rpm = tmp_path / "rpm.toml"
    rpm.write_text(text.replace("rate = 18000 ", 'rate = "3000 rpm" ').replace("duration = 2.0", "duration = 0.05"))
    num = tmp_path / "num.toml"
    num.write_text(text.replace("rate = 18000 ", f"rate = {3000 * 360 / 60} ").replace("duration = 2.0", "duration = 0.05"))
    assert load(str(rpm)).study.rates["crank.angle"] == pytest.approx(3000 * 2 * math.pi / 60, rel=1e-15)
    out = []
    for f in (rpm, num):
        assert main(["simulate", str(f), "--json"]) == 0
        out.append(json.loads(capsys.readouterr().out))
    assert out[0]["values"] == out[1]["values"] and out[0]["inputs"] == out[1]["inputs"]
    assert out[0]["values"]["crank.omega"][0] == pytest.approx(18000, rel=1e-12)


def test_a_held_inputs_rate_and_acceleration_strings_drive_it(tmp_path):
    """A held input of a simulation turned at "60 rpm" (2 pi rad/s) speeding up at
    "90 deg/s^2" in a radian scene: u = u0 + 2 pi t + (pi / 2) t^2 / 2."""
    from kincas.cli.simulate import run_scene
    sc = load_text(tmp_path, '''
units = { length = "m", angle = "rad", time = "s" }
gravity = [0, -9.81]
[ground]
O = [0, 0]
[links]
a = { points = ["O", "A"], length = 0.4, mass = 1.0, inertia = 0.1 }
b = { points = ["A", "B"], length = 0.3, mass = 0.5, inertia = 0.05 }
[[inputs]]
angle = "a"
value = 0.3
rate = "60 rpm"
acceleration = "90 deg/s^2"
[[inputs]]
angle = "b"
free = true
value = -1.0
rate = "-30 deg/s"
[simulate]
duration = 0.5
steps = 6
''')
    r = run_scene(sc)
    t = r.time
    assert r.ok and np.allclose(r.inputs["a.angle"], 0.3 + 2 * math.pi * t + (math.pi / 2) * t ** 2 / 2, rtol=0, atol=1e-12)
    assert r.rates["b.angle"][0] == pytest.approx(-math.pi / 6, rel=1e-15)


def test_a_rate_with_a_bad_unit_is_one_line_naming_the_field(tmp_path, capsys):
    text = open("examples/simulate_engine.toml").read()
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace("rate = 18000 ", 'rate = "3000 furlongs" '))
    assert main(["simulate", str(bad)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert any(line.startswith("[[inputs]]") and "rate" in line and "furlongs" in line for line in err), err
    bad.write_text(text.replace("rate = 18000 ", 'rate = "3000 m/s" '))  # a speed for an angle
    assert main(["flywheel", str(bad), "--fluctuation", "0.02"]) == 2
    err = capsys.readouterr().err
    assert "rate" in err and "m/s" in err, err


def load_text(tmp_path, text):
    f = tmp_path / "scene.toml"
    f.write_text(text)
    return load(str(f))


def test_a_duration_with_its_unit(tmp_path, capsys):
    """`duration = "500 ms"` in a scene timed in seconds is 0.5 s; a unit that is no time is
    one line naming [simulate] duration."""
    text = open("examples/simulate_engine.toml").read()
    assert load_text(tmp_path, text.replace("duration = 2.0", 'duration = "500 ms"')).study.simulation["duration"] == 0.5
    assert load_text(tmp_path, text.replace("duration = 2.0", 'duration = "0.01 min"')).study.simulation["duration"] == pytest.approx(0.6, rel=1e-15)
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace("duration = 2.0", 'duration = "2 fortnights"'))
    assert main(["simulate", str(bad)]) == 2
    assert "[simulate] duration: '2 fortnights': expected a time" in capsys.readouterr().err


def test_textbook_flywheel_two_stroke_engine(capsys):
    """The classic exercise of examples/simulate_flywheel_textbook.toml (Khurmi & Gupta, "Theory of
    Machines", turning moment and flywheel chapter; numbers stated in full there): T = 1000 +
    300 sin 2θ − 500 cos 2θ N m at 250 rpm, flywheel 400 kg at k = 0.4 m. Energy method, by
    hand: ΔE = √(300² + 500²) = 583.1 J (the work of T − T_mean between two crossings),
    Cs = ΔE / (I ω²) = 1.33 % with I = 64 kg m², and I = ΔE / (Cs ω²) = 85.07 kg m² for Cs = 1 %.
    The energy method is first order in Cs (and the load here varies with the speed by ±Cs/2):
    agreement to 1e-3 of the textbook's values."""
    dE = math.hypot(300, 500)
    w = 250 * 2 * math.pi / 60
    assert round(dE, 1) == 583.1 and round(100 * dE / (64 * w ** 2), 2) == 1.33  # the textbook's rounding
    assert main(["simulate", "examples/simulate_flywheel_textbook.toml", "--steady", "--json"]) == 0
    st = json.loads(capsys.readouterr().out)
    assert st["w_mean"] == pytest.approx(math.degrees(w), rel=1e-4)  # the scene in deg/s, t mm^2
    assert st["fluctuation"] == pytest.approx(dE / (64 * w ** 2), rel=1e-3)
    assert main(["flywheel", "examples/simulate_flywheel_textbook.toml", "--fluctuation", "0.01", "--json"]) == 0
    fw = json.loads(capsys.readouterr().out)
    I_book = dE / (0.01 * w ** 2)
    assert abs(I_book - 85.07) < 0.01
    assert 64 + fw["inertia"] / 1000 == pytest.approx(I_book, rel=1e-3)   # added on the crank's own 64
    assert fw["estimate"] / 1000 == pytest.approx(I_book, rel=1e-3) and fw["fluctuation"] <= 0.01


def test_flywheel_on_a_massless_machine_is_one_line_not_a_traceback(tmp_path):
    """`kincas flywheel` starts from no added flywheel; where the machine then has no inertia at
    all its equations of motion are singular: one line naming [simulate] flywheel, exit 2."""
    import subprocess
    import sys
    from conftest import ROOT
    text = (ROOT / "examples" / "simulate_flywheel_textbook.toml").read_text(encoding="utf-8")
    assert "inertia = 64000, " in text
    f = tmp_path / "fw0.toml"
    f.write_text(text.replace("inertia = 64000, ", ""), encoding="utf-8")
    p = subprocess.run([sys.executable, "-m", "kincas", "flywheel", str(f), "--fluctuation", "0.01"],
                       capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert p.returncode == 2 and "Traceback" not in p.stderr, p.stderr[-500:]
    assert "[simulate] flywheel" in p.stderr and len(p.stderr.strip().splitlines()) <= 2
