"""pinocchio on the spatial mechanisms of bench_space.py, through its documented API.

A closed loop in pinocchio is a kinematic tree (`Model.addJoint`) plus `RigidConstraintModel`s
(CONTACT_3D: a point of one joint's body on a point of another's). Its example
`simulation-closed-kinematic-chains.py` finds a pose that closes the loop by "inverse
geometry": a proximal Newton iteration on the KKT system of the constraint Jacobian, factored
by `ContactCholeskyDecomposition` with the mass matrix replaced by rho I. We do the same per
pose, with two changes: on Bennett rho = 1e-2 (see RHO), and, to drive an input, the input
joint's diagonal entry is 1e12 instead of rho, so the steps leave it where it was set.
Iterations stop when every constraint residual (`c1Mc2.translation`) is below `tol` (metres)
or after `max_iter`; each pose starts from the last. Lengths in metres inside pinocchio,
millimetres outside. Licence: BSD-2-Clause (its LICENSE; PyPI metadata of `pin` says BSD-3).
"""
from __future__ import annotations

import numpy as np

from . import space_cases as sc

S = 1e-3
# The example's rho = 1e-10 (with mu = 1e-4) takes 3 iterations a pose on the RSSR but stalls
# near 6e-10 m on Bennett's redundant rows (50 iterations a pose, 6e-9 of the size), where
# rho = 1e-2 converges in about 6 (and takes 9 on the RSSR): each mechanism gets the better one.
# The input's weight HEAVY: at 1e10 against rho = 1e-2 Bennett's input drifted (7e-13 of a).
RHO, RHO_REDUNDANT, MU, HEAVY = 1e-10, 1e-2, 1e-4, 1e12


def _se3(p):
    import pinocchio as pin
    return pin.SE3(np.eye(3), np.asarray(p, float) * S)


def prepare(model, constraints, drive, inputs, outputs, rho=RHO, tol=1e-15, max_iter=50):
    """run() -> (points (n, len(outputs), 3) in mm, iterations per pose (n,), worst residual (n,)).

    constraints: RigidConstraintModels; drive: the index of the driven joint's coordinate (a
    one-coordinate joint, q = v there); outputs: (joint id, point in its frame, mm)."""
    import pinocchio as pin
    data = model.createData()
    cms = pin.StdVec_RigidConstraintModel()
    cds = pin.StdVec_RigidConstraintData()
    for c in constraints:
        cms.append(c)
        cds.append(c.createData())
    nc = 3 * len(constraints)  # CONTACT_3D rows
    kkt = pin.ContactCholeskyDecomposition(model, data, cms, cds)
    W = np.full(model.nv, rho)
    W[model.joints[drive].idx_v] = HEAVY
    iq = model.joints[drive].idx_q
    inputs = np.asarray(inputs, float)
    q0 = pin.neutral(model)

    def run():
        q = q0.copy()
        pts = np.empty((len(inputs), len(outputs), 3))
        its, res = np.zeros(len(inputs), int), np.zeros(len(inputs))
        for k, t in enumerate(inputs):
            q[iq] = t
            y = np.zeros(nc)
            for i in range(max_iter + 1):
                pin.computeJointJacobians(model, data, q)
                for cm, cd in zip(cms, cds):
                    cm.calc(model, data, cd)
                c = np.concatenate([cd.c1Mc2.translation for cd in cds])
                r = float(np.abs(c).max())
                if r < tol or i == max_iter:
                    break
                data.M = np.diag(W)
                kkt.compute(model, data, cms, cds, MU)
                dz = kkt.solve(np.concatenate([-c - y * MU, np.zeros(model.nv)]))
                q = pin.integrate(model, q, -dz[nc:])
                y += dz[:nc] - y
            pts[k] = [data.oMi[j].act(np.asarray(p, float) * S) / S for j, p in outputs]
            its[k], res[k] = i, r
        return pts, its, res
    return run


def rssr(th):
    """The RSSR over crank angles th: C on the coupler and on the rocker. Tree: RZ at A ->
    spherical at B; RX at D; one CONTACT_3D at C."""
    import pinocchio as pin
    th = np.asarray(th, float)
    B, C = (x[0] for x in sc.rssr_points([th[0]]))
    m = pin.Model()
    jA = m.addJoint(0, pin.JointModelRZ(), _se3((0, 0, 0)), "A")
    jB = m.addJoint(jA, pin.JointModelSpherical(), _se3(B), "B")
    jD = m.addJoint(0, pin.JointModelRX(), _se3(sc.D), "D")
    for j in (jA, jB, jD):  # the KKT factorisation wants bodies; their inertia is replaced by W
        m.appendBodyToJoint(j, pin.Inertia.FromSphere(1.0, 0.01), pin.SE3.Identity())
    cm = pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, m, jB, _se3(C - B), jD, _se3(C - sc.D))
    return prepare(m, [cm], jA, th - th[0], [(jB, C - B), (jD, C - sc.D)])


def bennett(u):
    """Bennett over input turns u: O2, O3, O4 (O4 on L3). Tree: revolute O1 -> O2 -> O3 about
    their (unaligned) axes; the revolute O4 to the ground is two CONTACT_3D on its axis (six
    equations for five, besides Bennett's own three redundant ones)."""
    import pinocchio as pin
    O, z = sc.bennett_frames(sc.TH10_BEN)
    m = pin.Model()
    j, prev, ids = 0, np.zeros(3), []
    for i in range(3):
        j = m.addJoint(j, pin.JointModelRevoluteUnaligned(z[i]), _se3(O[i] - prev), f"O{i + 1}")
        m.appendBodyToJoint(j, pin.Inertia.FromSphere(1.0, 0.01), pin.SE3.Identity())
        prev = O[i]
        ids.append(j)
    s = 0.5 * sc.A_BEN
    cms = [pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, m, ids[2], _se3(O[3] - O[2] + e * z[3]),
                                    0, _se3(O[3] + e * z[3])) for e in (0.0, s)]
    return prepare(m, cms, ids[0], np.asarray(u, float),
                   [(ids[1], (0, 0, 0)), (ids[2], (0, 0, 0)), (ids[2], O[3] - O[2])], rho=RHO_REDUNDANT)
