"""Exudyn on the spatial mechanisms of bench_space.py, through its documented API.

The loop is an `ObjectKinematicTree` (minimal joint coordinates in one `NodeGenericODE2`) plus
loop-closing constraints on `MarkerKinematicTreeRigid` markers, as in Exudyn's kinematic-tree
examples; the input joint's coordinate is held by an `ObjectConnectorCoordinate` whose
`offset` is set per pose (`mbs.SetObjectParameter`), and `mbs.SolveStatic` (Newton on the
constraints; no loads, so the static pose is the kinematic one) solves each pose from the
last (the solved coordinates become the next initial ones). Newton tolerances tightened to
1e-12 (relative) and 1e-14 (absolute); Bennett's redundant rows need
`linearSolver.ignoreSingularJacobian` with the EigenDense solver (the hint SolveStatic prints
when it fails on them; its fourBarMechanism3D.py example says the same).

RSSR: crank (revolute z at A) and rocker (revolute x at D) are two links of one tree, the
coupler a `DistanceConstraint` between B and C (a bar with a ball at each end: the same
equation, without the bar's spin about its own axis, which a static solve cannot fix).
Bennett: three revolute links about their skew axes (each joint frame's z on the axis), the
fourth revolute a `GenericJoint` (constrainedAxes 1,1,1,1,1,0) between L3 and the ground.
Lengths in metres inside Exudyn, millimetres outside. Licence: EXUDYN General License 1.0 (BSD-3-Clause wording).
"""
from __future__ import annotations

import numpy as np

from . import space_cases as sc

S = 1e-3


def _frame(z):
    """A rotation matrix whose third column is the unit vector z."""
    z = np.asarray(z, float) / np.linalg.norm(z)
    t = np.array([1.0, 0, 0]) if abs(z[0]) < 0.9 else np.array([0, 1.0, 0])
    x = np.cross(t, z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def _system(joints, parents, drive, redundant):
    """mbs with a kinematic tree: joints = [(joint type, R (world), origin (world, mm))]."""
    import exudyn as exu
    from exudyn.itemInterface import (MarkerNodeCoordinate, NodeGenericODE2, NodePointGround,
                                      ObjectConnectorCoordinate, ObjectGround, ObjectKinematicTree)
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    n = len(joints)
    node = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0] * n, initialCoordinates=[0.0] * n,
                                       initialCoordinates_t=[0.0] * n, numberOfODE2Coordinates=n))
    Ts, offs = [], []
    for (_, R, p), par in zip(joints, parents):
        Rp, pp = (np.eye(3), np.zeros(3)) if par < 0 else (joints[par][1], joints[par][2])
        Ts.append(Rp.T @ R)
        offs.append(Rp.T @ (np.asarray(p, float) - pp) * S)
    tree = mbs.AddObject(ObjectKinematicTree(
        nodeNumber=node, jointTypes=[j[0] for j in joints], linkParents=parents,
        jointTransformations=exu.Matrix3DList(Ts), jointOffsets=exu.Vector3DList(offs),
        linkInertiasCOM=exu.Matrix3DList([1e-4 * np.eye(3)] * n),
        linkCOMs=exu.Vector3DList([[0.0, 0.0, 0.0]] * n), linkMasses=[1.0] * n))
    ground = mbs.AddObject(ObjectGround())
    gnode = mbs.AddNode(NodePointGround())
    drv = mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[
        mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=gnode, coordinate=0)),
        mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=drive))], offset=0.0))
    st = exu.SimulationSettings()
    st.solution.file.write = False
    st.solution.sensors.writePeriod = 1e10
    st.staticSolver.verboseMode = 0
    st.staticSolver.useLoadFactor = False
    st.staticSolver.numberOfLoadSteps = 1
    st.staticSolver.newton.relativeTolerance = 1e-12
    st.staticSolver.newton.absoluteTolerance = 1e-14
    if redundant:  # the hint SolveStatic prints for redundant constraints
        st.linearSolver.ignoreSingularJacobian = True
        st.linearSolver.solverType = exu.LinearSolverType.EigenDense
    return exu, SC, mbs, tree, ground, drv, st


def _local(joints, i, p):
    """A world point p (mm) in link i's frame at the drawing (m)."""
    return joints[i][1].T @ (np.asarray(p, float) - joints[i][2]) * S


def prepare(exu, SC, mbs, tree, drv, st, inputs, outputs):
    """run() -> (points (n, len(outputs), 3) in mm, NaN where SolveStatic failed; 1 where it said
    solved (n,); 0 (n,)). A failed pose leaves the next one to start from the last solved."""
    from exudyn.itemInterface import SensorKinematicTree
    sens = [mbs.AddSensor(SensorKinematicTree(objectNumber=tree, linkNumber=i, localPosition=list(p),
                                              storeInternal=True, outputVariableType=exu.OutputVariableType.Position))
            for i, p in outputs]
    mbs.Assemble()
    sd = mbs.systemData
    q0 = sd.GetODE2Coordinates(exu.ConfigurationType.Initial)
    inputs = np.asarray(inputs, float)

    def run():
        sd.SetODE2Coordinates(q0, exu.ConfigurationType.Initial)
        pts = np.empty((len(inputs), len(sens), 3))
        ok = np.zeros(len(inputs), int)
        for k, t in enumerate(inputs):
            mbs.SetObjectParameter(drv, "offset", float(t))
            try:
                ok[k] = bool(mbs.SolveStatic(st))
            except exu.SolverError:  # a pose it cannot solve is a failed pose (NaN), not the end
                ok[k] = False
            if not ok[k]:
                pts[k] = np.nan
                continue
            sd.SetODE2Coordinates(sd.GetODE2Coordinates(), exu.ConfigurationType.Initial)
            pts[k] = [np.asarray(mbs.GetSensorValues(s)) / S for s in sens]
        return pts, ok, np.zeros(len(inputs))
    return run


def rssr(th):
    import exudyn as exu
    from exudyn.itemInterface import DistanceConstraint, MarkerKinematicTreeRigid
    th = np.asarray(th, float)
    B, C = (x[0] for x in sc.rssr_points([th[0]]))
    joints = [(exu.JointType.RevoluteZ, np.eye(3), np.zeros(3)), (exu.JointType.RevoluteX, np.eye(3), sc.D)]
    exu, SC, mbs, tree, ground, drv, st = _system(joints, [-1, -1], 0, False)
    mB = mbs.AddMarker(MarkerKinematicTreeRigid(objectNumber=tree, linkNumber=0, localPosition=list(_local(joints, 0, B))))
    mC = mbs.AddMarker(MarkerKinematicTreeRigid(objectNumber=tree, linkNumber=1, localPosition=list(_local(joints, 1, C))))
    mbs.AddObject(DistanceConstraint(markerNumbers=[mB, mC], distance=sc.LC * S))
    # C on the rocker twice: the coupler has no body here, the loop closes through the distance
    return prepare(exu, SC, mbs, tree, drv, st, th - th[0], [(1, _local(joints, 1, C))] * 2)


def bennett(u):
    import exudyn as exu
    from exudyn.itemInterface import GenericJoint, MarkerBodyRigid, MarkerKinematicTreeRigid
    O, z = sc.bennett_frames(sc.TH10_BEN)
    joints = [(exu.JointType.RevoluteZ, _frame(z[i]), O[i]) for i in range(3)]
    exu, SC, mbs, tree, ground, drv, st = _system(joints, [-1, 0, 1], 0, True)
    R4 = _frame(z[3])
    m3 = mbs.AddMarker(MarkerKinematicTreeRigid(objectNumber=tree, linkNumber=2, localPosition=list(_local(joints, 2, O[3]))))
    mg = mbs.AddMarker(MarkerBodyRigid(bodyNumber=ground, localPosition=list(O[3] * S)))
    mbs.AddObject(GenericJoint(markerNumbers=[m3, mg], constrainedAxes=[1, 1, 1, 1, 1, 0],
                               rotationMarker0=(joints[2][1].T @ R4).tolist(), rotationMarker1=R4.tolist()))
    return prepare(exu, SC, mbs, tree, drv, st, np.asarray(u, float),
                   [(1, [0.0, 0.0, 0.0]), (2, [0.0, 0.0, 0.0]), (2, _local(joints, 2, O[3]))])
