"""`kincas solve` on scenes whose loads are expressions of the state ([[loads]] written as
strings, docs/simulate.md): the kinematics never need the loads; a force quantity takes each
expression at the pose's own state (positions, velocities, the sweep's input), and one whose
expression needs the time `t` (which a kinematic sweep does not have) is refused in one line
naming the load and its field, exit 2.

The numbers are checked against closed forms written here: a slider-crank with no masses,
whose input effort is minus the virtual power of the loads per unit crank rate.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import EXAMPLES, run_cli, write_scene

SIMULATE = sorted(EXAMPLES.glob("simulate_*.toml"))


@pytest.mark.parametrize("path", SIMULATE, ids=lambda p: p.stem)
def test_every_simulate_example_solves_with_its_report(capsys, path):
    import tomllib
    scene = tomllib.loads(path.read_text(encoding="utf-8"))
    code, out, err = run_cli(capsys, "solve", path, "--json")
    assert code == 0, err
    assert out["status"] == ["ok"] and set(scene["output"]["report"]) <= set(out["values"])
    assert all(v[0] is not None and math.isfinite(v[0]) for v in out["values"].values())


def test_the_engine_and_the_press_efforts_take_their_expressions_at_the_pose(capsys):
    """The engine at top dead centre turning at w0: the gas force on the piston does no virtual
    work (dB.x/dtheta = 0) and, M(theta) being even, the inertia forces' effort 1/2 M'(0) w^2 is
    zero, so the effort is minus the load torque -Tm w/w0 = -Tm: +Tm. The press at rest: no
    inertia forces, the workpiece's table is 0 at 0 deg, the motor gives its stall torque T0."""
    code, out, err = run_cli(capsys, "solve", EXAMPLES / "simulate_engine.toml", "--json")
    assert code == 0, err
    assert out["values"]["B.x"][0] == pytest.approx(230, abs=1e-9)
    assert out["values"]["effort(crank.angle)"][0] == pytest.approx(53250, rel=1e-9)
    code, out, err = run_cli(capsys, "solve", EXAMPLES / "simulate_press.toml", "--json")
    assert code == 0, err
    assert out["values"]["effort(crank.angle)"][0] == pytest.approx(-1.5e6, rel=1e-12)


R, L, K, C0, C1, C2 = 50.0, 180.0, 3.0, 400.0, 0.5, 2.0


def _slider_crank(torque, report, rate=30.0):
    return {
        "units": {"length": "mm", "angle": "deg", "time": "s"},
        "parameters": {"k": K, "c0": C0},
        "ground": {"O": [0, 0]},
        "links": {"crank": {"points": ["O", "A"], "length": R},
                  "rod": {"points": ["A", "B"], "length": L}},
        "slides": [{"name": "cyl", "point": "B", "along": "ground"}],
        "loads": [{"link": "crank", "torque": torque},
                  {"point": "B", "force": ["-k * B.x", 0]}],
        "inputs": [{"angle": "crank", "sweep": {"from": 10, "to": 710, "steps": 21}, "rate": rate}],
        "guess": {"B": [230, 0]},
        "output": {"report": report},
    }


def test_a_sweep_evaluates_state_expressions_at_every_pose(capsys, tmp_path):
    """effort = -tau - F_x dB.x/dtheta with tau = c0 + C1 omega + C2 theta (degrees: the
    input's angle as swept, past 360 too), F_x = -k B.x, B.x = r cos + sqrt(l^2 - r^2 sin^2)."""
    torque = f"c0 + {C1} * crank.omega + {C2} * crank.angle"
    path = write_scene(tmp_path, _slider_crank(torque, ["B.x", "effort(crank.angle)"]))
    code, out, err = run_cli(capsys, "solve", path, "--json")
    assert code == 0, err
    th_deg = np.arange(10, 711, 35.0)
    th = np.radians(th_deg)
    bx = R * np.cos(th) + np.sqrt(L ** 2 - (R * np.sin(th)) ** 2)
    dbx = -R * np.sin(th) - R ** 2 * np.sin(th) * np.cos(th) / np.sqrt(L ** 2 - (R * np.sin(th)) ** 2)
    tau = C0 + C1 * 30.0 + C2 * th_deg
    want = -tau - (-K * bx) * dbx
    assert np.allclose(out["values"]["B.x"], bx, rtol=1e-12)
    assert np.allclose(out["values"]["effort(crank.angle)"], want, rtol=1e-10, atol=1e-9 * np.max(np.abs(want)))


def test_a_time_expression_is_refused_only_where_a_force_needs_it(capsys, tmp_path):
    torque = "c0 * sin(90 * t)"
    path = write_scene(tmp_path, _slider_crank(torque, ["B.x", "B.vx"]))
    code, out, err = run_cli(capsys, "solve", path, "--json")
    assert code == 0, err          # kinematics need no loads
    path = write_scene(tmp_path, _slider_crank(torque, ["B.x", "effort(crank.angle)"]))
    code, out, err = run_cli(capsys, "solve", path)
    assert code == 2
    msg = [line for line in err.strip().splitlines() if not line.startswith("kincas: error in")]
    assert len(msg) == 1 and "Traceback" not in err, err
    assert "[[loads]] 1: torque" in msg[0] and "`t`" in msg[0], msg[0]
