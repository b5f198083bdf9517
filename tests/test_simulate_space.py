"""`kincas simulate` on spatial scenes (`space = "3d"`), checked against answers written here:
a body swinging on a tilted revolute axis against the pendulum's exact period (complete
elliptic integral) and its energy, and the RSSR released from rest under gravity against its
kinetic plus potential energy from the points' velocities and against kincas's kinetostatics
of the simulated motion (the free input needs no effort)."""
from __future__ import annotations

import json
import math

import numpy as np
from scipy.special import ellipk

import kincas
from kincas.analysis.simulate import simulate
from kincas.cli.app import main
from kincas.cli.scene import load, loads
from kincas.cli.simulate import run_scene

G = 9.81
TILT = math.radians(35)  # the revolute axis, 35 deg from the vertical
M, D, IG, THETA0 = 2.0, 0.3, 0.01, math.radians(40)


def _pendulum(theta0=THETA0, steps=3, duration=None, rate=0.0):
    """A body on a revolute through O with axis n = (sin a, 0, cos a); its cg G drawn at its
    lowest, a distance D from the axis along (cos a, 0, -sin a) (perpendicular to n, in the
    vertical plane of n); gravity -z. Only g sin a (the part of g across the axis) swings it."""
    a = TILT
    gx, gz = D * math.cos(a), -D * math.sin(a)
    return loads(f'''
space = "3d"
units = {{ length = "m", angle = "rad", time = "s" }}
gravity = [0, 0, {-G}]
[ground]
O = [0, 0, 0]
[links]
bob = {{ points = {{ O = [0, 0, 0], G = [{gx}, 0, {gz}] }}, cg = [{gx}, 0, {gz}], mass = {M}, inertia = {IG} }}
[[joints]]
type = "revolute"
point = "O"
axis = [{math.sin(a)}, 0, {math.cos(a)}]
[[inputs]]
joint = "O"
free = true
value = {theta0}
rate = {rate}
[simulate]
duration = {duration or 1.0}
steps = {steps}
tolerance = 1e-12
[output]
report = ["G.vx", "G.vy", "G.vz", "G.z", "bob.omega_x", "bob.omega_y", "bob.omega_z"]
''')


def test_tilted_pendulum_half_period_is_the_elliptic_integrals():
    """T = 4 sqrt(I_O / (m g sin(a) d)) K(sin(theta0 / 2)): after T/4 the body passes its
    lowest point at the speed energy gives, after T/2 it is at -theta0 at rest."""
    IO = IG + M * D ** 2
    k = math.sin(THETA0 / 2)
    T = 4 * math.sqrt(IO / (M * G * math.sin(TILT) * D)) * ellipk(k ** 2)
    sc = _pendulum(duration=T / 2)
    r = run_scene(sc)
    assert r.ok
    th, w = r.inputs["O.angle"], r.rates["O.angle"]
    w_bottom = math.sqrt(2 * M * G * math.sin(TILT) * D * (1 - math.cos(THETA0)) / IO)
    assert abs(th[1]) < 1e-8 and abs(abs(w[1]) - w_bottom) < 1e-8 * w_bottom
    assert abs(th[2] + THETA0) < 1e-8 and abs(w[2]) < 1e-8 * w_bottom
    # energy from the cg's velocity and the angular velocity (isotropic inertia about G)
    v = r.values
    E = (0.5 * M * (v["G.vx"] ** 2 + v["G.vy"] ** 2 + v["G.vz"] ** 2)
         + 0.5 * IG * (v["bob.omega_x"] ** 2 + v["bob.omega_y"] ** 2 + v["bob.omega_z"] ** 2) + M * G * v["G.z"])
    assert np.max(np.abs(E - E[0])) < 1e-9 * 0.5 * IO * w_bottom ** 2


# --- the RSSR of examples/simulate_space_rssr.toml, released from rest ---
GMM = 9810.0  # mm/s^2
CRANK_M, CRANK_IZ, COUPLER_M, ROCKER_M, ROCKER_IX = 0.001, 0.05, 0.002, 0.0015, 0.6
REPORT = ["B.vx", "B.vy", "B.vz", "C.vx", "C.vy", "C.vz", "B.z", "C.z",
          "crank.omega_x", "crank.omega_y", "crank.omega_z",
          "rocker.omega_x", "rocker.omega_y", "rocker.omega_z"]


def _rssr():
    sc = load("examples/simulate_space_rssr.toml")
    sc.study.report[:] = REPORT
    return sc


def _energy(v):
    """Kinetic plus potential energy from the points' velocities: each body's cg is the mean
    of its two points (A and D fixed), the crank turns about z and the rocker about x, so
    their diagonal inertia tensors act through Izz and Ixx alone (turned about that axis,
    R I0 R' keeps that diagonal entry). Nothing of kincas's efforts."""
    mid = lambda a, b: (np.asarray(a) + np.asarray(b)) / 2  # noqa: E731
    sq = lambda P, Q: sum(mid(P and v[f"{P}.v{c}"] if P else 0, v[f"{Q}.v{c}"]) ** 2 for c in "xyz")  # noqa: E731
    T = (0.5 * CRANK_M * sq(None, "B") + 0.5 * COUPLER_M * sq("B", "C") + 0.5 * ROCKER_M * sq(None, "C")
         + 0.5 * CRANK_IZ * v["crank.omega_z"] ** 2 + 0.5 * ROCKER_IX * v["rocker.omega_x"] ** 2)
    z0D = 30.0
    V = GMM * (CRANK_M * mid(0, v["B.z"]) + COUPLER_M * mid(v["B.z"], v["C.z"]) + ROCKER_M * mid(z0D, v["C.z"]))
    return T, V


def test_rssr_under_gravity_conserves_energy():
    r = run_scene(_rssr())
    assert r.ok and len(r.time) == 101
    v = r.values
    # the axes really are the ones written: no other component of the angular velocities
    assert np.max(np.abs(v["crank.omega_x"]) + np.abs(v["crank.omega_y"])) < 1e-9
    assert np.max(np.abs(v["rocker.omega_y"]) + np.abs(v["rocker.omega_z"])) < 1e-9
    T, V = _energy(v)
    E = T + V
    assert np.ptp(T) > 0 and np.ptp(r.inputs["A.angle"]) > 2.0  # it moved, far
    assert np.max(np.abs(E - E[0])) < 1e-9 * np.ptp(T)


def test_rssr_free_input_needs_no_effort_along_the_motion():
    """The integrator's accelerations are the rates' central differences (to O(h^4)), and with them
    kincas.sweep's kinetostatics at the simulated states needs no effort on A.angle."""
    sc = _rssr()
    sim = kincas.simulate(sc.mechanism, 0.1, 501, initial={"A.angle": math.radians(30)}, tolerance=1e-12)
    assert sim.ok
    th, w, h = sim.inputs["A.angle"], sim.rates["A.angle"], sim.time[1] - sim.time[0]
    acc = sim.accelerations["A.angle"]
    fd = (-w[4:] + 8 * w[3:-1] - 8 * w[1:-3] + w[:-4]) / (12 * h)  # five points: O(h^4)
    assert np.max(np.abs(fd - acc[2:-2])) < 1e-5 * np.max(np.abs(acc))  
    sw = kincas.sweep(sc.mechanism, {"A.angle": th}, rates={"A.angle": w},
                      accelerations={"A.angle": acc}, report=["effort(A.angle)"])
    scale = GMM * (ROCKER_M * 30 + COUPLER_M * 60)  # the rocker's and coupler's weight about D (N mm)
    assert np.max(np.abs(sw["effort(A.angle)"])) < 1e-9 * scale
    # and it is not zero for nothing: at rest, gravity needs a torque at A
    st = kincas.sweep(sc.mechanism, {"A.angle": th[:1]}, report=["effort(A.angle)"])
    assert abs(st["effort(A.angle)"][0]) > 1e-3 * scale


def test_cli_simulate_spatial_json(capsys):
    assert main(["simulate", "examples/simulate_space_rssr.toml", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert len(doc["inputs"]["t"]) == 101 and doc["events"] == []
    assert max(abs(e) for e in doc["values"]["effort(A.angle)"]) < 1e-9
