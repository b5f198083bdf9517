"""Efforts and shaking forces of spatial mechanisms against hand balances: a body turning
about a tilted axis under gravity (its moment about the axis), and the RSSR's power balance
(effort x rate = d(kinetic + potential energy)/dt, central differences of energies)."""
import math

import numpy as np

import kincas
from kincas import Body, Input, Joint, Load, SpatialMechanism


def rot(a, t):
    a = np.asarray(a, float)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(t) * K + (1 - math.cos(t)) * K @ K


def test_body_on_a_tilted_axis_under_gravity():
    a = np.array([0.3, -0.2, 1.0]) / np.linalg.norm([0.3, -0.2, 1.0])
    O, G0, mass = np.array([1.0, 2.0, 3.0]), np.array([1.8, 2.5, 3.1]), 2.5
    I0 = np.array([[0.4, 0.05, -0.02], [0.05, 0.3, 0.01], [-0.02, 0.01, 0.2]])
    grav = np.array([0.0, -3.0, -9.81])
    m = SpatialMechanism(ground={"O": tuple(O)},
                         bodies=[Body("arm", {"O": tuple(O), "P": (2.5, 2.0, 3.5)}, mass=mass, cg=tuple(G0),
                                      inertia=I0.tolist())],
                         joints=[Joint("revolute", "O", axis=tuple(a))], inputs=[Input.joint("O")],
                         gravity=tuple(grav))
    th, w, al = np.array([0.2, 1.4, -2.5]), 1.7, -0.6
    sw = kincas.sweep(m, {"O.angle": th}, rates={"O.angle": w}, accelerations={"O.angle": al},
                      report=["effort(O.angle)", "shaking.x", "shaking.z", "shaking.mz"])
    for k, t in enumerate(th):
        R = rot(a, t)
        r = R @ (G0 - O)
        Ia = a @ (R @ I0 @ R.T) @ a + mass * np.linalg.norm(np.cross(a, r)) ** 2
        assert abs(sw["effort(O.angle)"][k] - (Ia * al - a @ np.cross(r, mass * grav))) < 1e-12 * 10
        aG = np.cross(al * a, r) + np.cross(w * a, np.cross(w * a, r))  # about a fixed axis
        assert abs(sw["shaking.x"][k] + mass * aG[0]) < 1e-12 and abs(sw["shaking.z"][k] + mass * aG[2]) < 1e-12
        Iw, om = R @ I0 @ R.T, w * a
        mom = np.cross(O + r, mass * aG) + Iw @ (al * a) + np.cross(om, Iw @ om)
        assert abs(sw["shaking.mz"][k] + mom[2]) < 1e-11


def rssr_loaded():
    D = (100.0, 40.0, 30.0)
    return SpatialMechanism(
        ground={"A": (0, 0, 0), "D": D, "S": (50.0, -30.0, 10.0)},
        bodies=[Body("crank", {"A": (0, 0, 0), "B": (15, 0, 0)}, mass=1.2, cg=(15, 0, 0), inertia=[3.0, 4.0, 5.0]),
                Body.bar("coupler", "B", "C", 125),
                Body("rocker", {"D": D, "C": (100.0, 40.0, 90.0)}, mass=0.8, cg=(100.0, 40.0, 90.0),
                     inertia=[[7.0, 0.5, 0.2], [0.5, 6.0, 0.1], [0.2, 0.1, 2.0]])],
        joints=[Joint("revolute", "A", axis=(0, 0, 1)), Joint("revolute", "D", axis=(1, 0, 0))],
        inputs=[Input.joint("A")], gravity=(0.0, -2.0, -9.81),
        loads=[Load("force", "C", (3.0, -1.0, 2.0)), Load("torque", "rocker", (4.0, 0.5, -1.0)),
               Load.spring("S", "C", 0.3, 60.0)])


def test_rssr_effort_is_the_power_balance():
    m = rssr_loaded()
    th = np.linspace(0.1, 6.0, 7)
    h = 1e-5
    names = ["B.vx", "B.vy", "B.vz", "C.vx", "C.vy", "C.vz", "D.omega", "B.x", "B.y", "B.z", "C.x", "C.y", "C.z"]

    def energy(t):
        s = kincas.sweep(m, {"A.angle": t}, report=names)
        vB = np.stack([s["B.vx"], s["B.vy"], s["B.vz"]], 1)
        vC = np.stack([s["C.vx"], s["C.vy"], s["C.vz"]], 1)
        B = np.stack([s["B.x"], s["B.y"], s["B.z"]], 1)
        C = np.stack([s["C.x"], s["C.y"], s["C.z"]], 1)
        g = np.array([0.0, -2.0, -9.81])
        kin = 0.5 * 1.2 * (vB ** 2).sum(1) + 0.5 * 5.0 + 0.5 * 0.8 * (vC ** 2).sum(1) + 0.5 * 7.0 * s["D.omega"] ** 2
        pot = -(1.2 * B + 0.8 * C) @ g - C @ np.array([3.0, -1.0, 2.0])
        pot += 0.5 * 0.3 * (np.linalg.norm(C - [50.0, -30.0, 10.0], axis=1) - 60.0) ** 2
        turned = -4.0 * np.unwrap(kincas.sweep(m, {"A.angle": t}, report=["D.angle"])["D.angle"])  # torque's work
        return kin + pot + turned

    dE = (energy(th + h) - energy(th - h)) / (2 * h)
    sw = kincas.sweep(m, {"A.angle": th}, report=["effort(A.angle)"])
    assert np.allclose(sw["effort(A.angle)"], dE, rtol=1e-6, atol=1e-6 * np.abs(dE).max())


SCENE = """space = "3d"
gravity = [0, -2.0, -9.81]
[ground]
A = [0, 0, 0]
D = [100.0, 40.0, 30.0]
S = [50.0, -30.0, 10.0]
[links]
crank = { points = { A = [0, 0, 0], B = [15, 0, 0] }, mass = 1.2, cg = [15, 0, 0], inertia = [3.0, 4.0, 5.0] }
coupler = { points = ["B", "C"], length = 125 }
rocker = { points = { D = [100.0, 40.0, 30.0], C = [100.0, 40.0, 90.0] }, mass = 0.8, cg = [100.0, 40.0, 90.0], inertia = [[7.0, 0.5, 0.2], [0.5, 6.0, 0.1], [0.2, 0.1, 2.0]] }
[[joints]]
type = "revolute"
point = "A"
axis = [0, 0, 1]
[[joints]]
type = "revolute"
point = "D"
axis = [1, 0, 0]
[[loads]]
point = "C"
force = [3.0, -1.0, 2.0]
[[loads]]
link = "rocker"
torque = [4.0, 0.5, -1.0]
[[loads]]
spring = ["S", "C"]
stiffness = 0.3
free_length = 60.0
[[inputs]]
joint = "A"
sweep = { from = 0, to = 90, steps = 4 }
rate = 1
[output]
report = ["effort(A.angle)", "shaking.z", "shaking.mx"]
"""


def test_scene_forces_read_as_the_python_declaration(capsys, tmp_path):
    from conftest import run_cli, write_scene
    code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, SCENE), "--json")
    assert code == 0, err
    sw = kincas.sweep(rssr_loaded(), {"A.angle": np.radians([0, 30, 60, 90])}, rates={"A.angle": math.pi / 180},
                      report=["effort(A.angle)"])
    assert np.allclose(out["values"]["effort(A.angle)"], sw["effort(A.angle)"], rtol=1e-12)


def test_a_reaction_in_a_spatial_scene_is_refused_in_one_line_naming_it(tmp_path):
    """The contract makes reaction(...) optional in 3D, refused with a clear message if not built."""
    import re
    import subprocess
    import sys
    from conftest import ROOT
    text = (ROOT / "examples" / "space_rssr.toml").read_text(encoding="utf-8")
    f = tmp_path / "r.toml"
    f.write_text(re.sub(r"report = \[", 'report = ["reaction(A)", ', text, count=1), encoding="utf-8")
    p = subprocess.run([sys.executable, "-m", "kincas", "solve", str(f)], capture_output=True, text=True, cwd=ROOT)
    assert p.returncode == 2 and "Traceback" not in p.stderr
    assert "reaction(A)" in p.stderr and "not built for spatial scenes" in p.stderr
