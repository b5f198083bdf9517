"""MuJoCo on the spatial mechanisms of bench_space.py, through its documented API.

MuJoCo is a dynamics engine: a closed loop is a kinematic tree plus `<equality><connect>`
constraints (a ball joint between two bodies' points), and those are soft (solref, solimp):
the solver lets them be violated and pulls them back over time. It has no position solver.
Two ways to a closed pose, both timed:
- prepare(): as its documentation drives a mechanism. The input joint is held by a
  `<equality><joint>` constraint (joint1 - its qpos0 = polycoef[0], set per pose in
  `model.eq_data`), gravity and contacts are off (the bars' capsules meet at the joints), and
  `mj_step` runs until every equality residual (`data.efc_pos`, the violations MuJoCo computes
  itself) is below `tol` or `max_steps` pass;
- prepare_newton(): MuJoCo's kinematics and constraint rows (`mj_fwdPosition`: `efc_pos` and
  its Jacobian `efc_J`) with a Gauss-Newton step in Python, `mj_integratePos` applying it.
Steps or iterations per pose and the worst residual are returned with the points so that the
table can say them.

Each model is built at the closed form's pose of the first input (a connect's anchor on
body2 is where it meets body1 at qpos0, so the tree must be assembled there). Lengths in
metres inside MuJoCo (its defaults are tuned for SI), millimetres outside. Licence: Apache-2.0.
"""
from __future__ import annotations

import numpy as np

from . import space_cases as sc

S = 1e-3  # mm -> m
# Equality constraints stiffened to the shortest time constant MuJoCo recommends (2 steps),
# critically damped; default solimp. Documented knobs, no private ones.
TIMESTEP, SOLREF = 1e-3, "0.002 1"


# gravity and contacts off (the bars' capsules meet at the joints), a dense constraint Jacobian
_HEAD = f"""
  <option timestep="{TIMESTEP}" gravity="0 0 0" jacobian="dense"><flag contact="disable"/></option>
  <default><geom type="capsule" size="0.004"/><equality solref="{SOLREF}"/></default>
"""


def _v(p):
    return " ".join(f"{x * S:.17g}" for x in p)


def _a(p):
    return " ".join(f"{x:.17g}" for x in p)


def rssr_xml(th0):
    """RSSR tree: crank (hinge z at A) -> coupler (ball at B); rocker (hinge x at D); a connect
    closes the loop at C; a joint equality drives A."""
    B, C = (x[0] for x in sc.rssr_points([th0]))
    return f"""
<mujoco model="rssr">{_HEAD}  <worldbody>
    <body name="crank" pos="0 0 0">
      <joint name="A" type="hinge" axis="0 0 1"/>
      <geom fromto="0 0 0 {_v(B)}"/>
      <body name="coupler" pos="{_v(B)}">
        <joint name="B" type="ball"/>
        <geom fromto="0 0 0 {_v(C - B)}"/>
        <site name="Cc" pos="{_v(C - B)}"/>
      </body>
    </body>
    <body name="rocker" pos="{_v(sc.D)}">
      <joint name="D" type="hinge" axis="1 0 0"/>
      <geom fromto="0 0 0 {_v(C - sc.D)}"/>
      <site name="Cr" pos="{_v(C - sc.D)}"/>
    </body>
  </worldbody>
  <equality>
    <connect body1="coupler" body2="rocker" anchor="{_v(C - B)}"/>
    <joint name="drive" joint1="A" polycoef="0 0 0 0 0"/>
  </equality>
</mujoco>"""


def bennett_xml(u0):
    """Bennett tree: L1 (hinge z1 at O1) -> L2 (hinge z2 at O2) -> L3 (hinge z3 at O3); the
    revolute O4 between L3 and the ground is two connects on its axis (6 equations for 5,
    and Bennett's own 3 redundant ones: MuJoCo's solver takes redundant rows)."""
    O, z = sc.bennett_frames(sc.TH10_BEN + u0)
    s = 0.5 * sc.A_BEN  # the second point on the axis of O4
    return f"""
<mujoco model="bennett">{_HEAD}  <worldbody>
    <body name="L1" pos="{_v(O[0])}">
      <joint name="O1" type="hinge" axis="{_a(z[0])}"/>
      <geom fromto="0 0 0 {_v(O[1] - O[0])}"/>
      <body name="L2" pos="{_v(O[1] - O[0])}">
        <joint name="O2" type="hinge" axis="{_a(z[1])}"/>
        <geom fromto="0 0 0 {_v(O[2] - O[1])}"/>
        <site name="O2" pos="0 0 0"/>
        <body name="L3" pos="{_v(O[2] - O[1])}">
          <joint name="O3" type="hinge" axis="{_a(z[2])}"/>
          <geom fromto="0 0 0 {_v(O[3] - O[2])}"/>
          <site name="O3" pos="0 0 0"/>
          <site name="O4" pos="{_v(O[3] - O[2])}"/>
        </body>
      </body>
    </body>
  </worldbody>
  <equality>
    <connect body1="L3" body2="world" anchor="{_v(O[3] - O[2])}"/>
    <connect body1="L3" body2="world" anchor="{_v(O[3] - O[2] + s * z[3])}"/>
    <joint name="drive" joint1="O1" polycoef="0 0 0 0 0"/>
  </equality>
</mujoco>"""


def _prepare(xml, inputs, sites, pose):
    """run() -> (points (n, len(sites), 3) in mm, work per pose (n,), worst |efc_pos| (n,)):
    per input, the drive's target set, then pose(mujoco, m, d) -> (work, residual) closes the
    loop from the state the last pose left."""
    import mujoco
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    drive = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_EQUALITY, "drive")
    sid = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, s) for s in sites]
    inputs = np.asarray(inputs, float)

    def run():
        mujoco.mj_resetData(m, d)
        pts = np.empty((len(inputs), len(sid), 3))
        work, res = np.zeros(len(inputs), int), np.zeros(len(inputs))
        for k, t in enumerate(inputs):
            m.eq_data[drive, 0] = t
            work[k], res[k] = pose(mujoco, m, d)
            pts[k] = d.site_xpos[sid] / S
        return pts, work, res
    return run


def prepare(xml, inputs, sites, tol=1e-12, max_steps=5000, chunk=5):
    """Per pose: mj_step in chunks of `chunk` steps until every equality residual is below
    `tol` (metres / radians) or `max_steps` steps; work = steps."""
    def settle(mujoco, m, d):
        n = 0
        while True:
            mujoco.mj_step(m, d, chunk)
            n += chunk
            r = float(np.abs(d.efc_pos[:d.ne]).max())
            if r < tol or n >= max_steps:
                break
        mujoco.mj_kinematics(m, d)  # the positions of the state reached, not of the last step's start
        return n, r
    return _prepare(xml, inputs, sites, settle)


def prepare_newton(xml, inputs, sites, tol=1e-15, max_iter=30):
    """The other way to a closed pose with MuJoCo's own pieces: `mj_fwdPosition` (kinematics
    and the constraint rows: `efc_pos`, the violations, and `efc_J`, their Jacobian) and a
    Gauss-Newton step dq = -pinv(efc_J) efc_pos applied by `mj_integratePos` (the ball joint's
    quaternion stays on its manifold); the drive's row holds the input. work = iterations."""
    def newton(mujoco, m, d):
        for i in range(max_iter + 1):
            mujoco.mj_fwdPosition(m, d)
            r = d.efc_pos[:d.ne]
            worst = float(np.abs(r).max())
            if worst < tol or i == max_iter:
                return i, worst
            J = np.asarray(d.efc_J).reshape(-1, m.nv)[:d.ne]  # dense: nefc x nv, row-major
            mujoco.mj_integratePos(m, d.qpos, -np.linalg.lstsq(J, r, rcond=None)[0], 1.0)
    return _prepare(xml, inputs, sites, newton)


def rssr(th, newton=False):
    """The RSSR over crank angles th (relative to the drawing, as kincas): Cc, Cr (C on the
    coupler and on the rocker)."""
    th = np.asarray(th, float)
    return (prepare_newton if newton else prepare)(rssr_xml(th[0]), th - th[0], ["Cc", "Cr"])  # polycoef: y - y0 = a0


def bennett(u, newton=False):
    """Bennett over input turns u from the drawing: O2, O3, O4 (O4 on L3: the loop's gap)."""
    u = np.asarray(u, float)
    return (prepare_newton if newton else prepare)(bennett_xml(0.0), u, ["O2", "O3", "O4"])
