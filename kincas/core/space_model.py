"""The first pose of a spatial mechanism, a part of its numeric model (`SpatialModel`,
kincas/core/numeric.py: `Model` on the spatial symbolic model), placed from the drawing pose
and the guess.

Every body starts at the least-squares rigid fit of its drawn points to their guessed
positions (Kabsch: the rotation R minimising sum |R a_i - b_i|^2 over centred points, from the
SVD of sum b_i a_i', with det R = +1), which is the drawing pose itself where nothing is
guessed; a point only bars carry starts at its guess. Then each input on a joint's angle or
translation turns or moves that joint's second body, about the joint's axis through its
point, by the difference between the input and the coordinate at the fitted pose, so that
Newton starts near the driven pose rather than a whole input away from it. A body hung on a
joint (kincas/model/space_tree.py) then takes, in placing order, the input or the coordinate
of its fit relative to its parent's placed pose, and its pose from its parent's.

>>> import numpy as np
>>> from kincas import SpatialMechanism, Body, Joint, Input, model_of
>>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (2, 0, 0)})],
...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
>>> model = model_of(m)
>>> q0 = model.initial_q(np.array([np.pi / 2]), np.zeros(0), dict(m.guess), 2.0)
>>> np.round(model.points(q0, [np.pi / 2], []).ravel(), 12).tolist()  # P turned to (0, 2, 0)
[0.0, 2.0, 0.0]
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from ..model.mobility import GROUND
from .quaternions import rotation
from ..model.space_tree import placement
from .tolerances import IDENTITY_PULL, TINY


def structure_key(m):
    """What the spatial model depends on (parameter values and the guess excepted)."""
    return ("3d", tuple(k for k, _ in m.parameters), m.ground, m.bodies, m.joints, m.slides,
            m.inputs, m.gravity, m.loads)


# --- rotations as numbers ---

def quat_of(R: np.ndarray) -> np.ndarray:
    """The unit quaternion (w >= 0) of a rotation matrix (Shepperd's method: the largest of
    the four squared components first, so no division by a small number)."""
    t = np.trace(R)
    d = np.array([t, R[0, 0], R[1, 1], R[2, 2]])
    k = int(np.argmax(d))
    if k == 0:
        w = np.sqrt(1 + t) / 2
        e = [w, (R[2, 1] - R[1, 2]) / (4 * w), (R[0, 2] - R[2, 0]) / (4 * w), (R[1, 0] - R[0, 1]) / (4 * w)]
    else:
        i, j, l = k - 1, k % 3, (k + 1) % 3
        v = np.zeros(3)
        v[i] = np.sqrt(max(1 + 2 * R[i, i] - t, 0.0)) / 2
        v[j] = (R[j, i] + R[i, j]) / (4 * v[i])
        v[l] = (R[l, i] + R[i, l]) / (4 * v[i])
        w = (R[l, j] - R[j, l]) / (4 * v[i])
        e = [w, *v]
    e = np.array(e)
    return e if e[0] >= 0 else -e


def rot_of(e) -> np.ndarray:
    w, x, y, z = e
    return np.array([[w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z]])


def axis_rotation(a, angle) -> np.ndarray:
    a = np.asarray(a, float)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def angle_about(R, a) -> float:
    """The angle in (-pi, pi] of the rotation about the unit axis a nearest R (a rotation):
    2 atan2(v.a, w) of its quaternion (w, v), w >= 0."""
    e = quat_of(R)
    return float(2 * np.arctan2(e[1:] @ np.asarray(a, float), e[0]))


def kabsch(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """The rotation R minimising sum |R a_i - b_i|^2 (rows of A and B, already centred).
    Where the points leave it undecided (two points, or points on a line: a turn about
    their line costs nothing), the one nearest the identity: a faint pull towards it is
    added to the correlation matrix (the drawing pose's orientation is the identity)."""
    H = B.T @ A
    U, _, Vt = np.linalg.svd(H + IDENTITY_PULL * (np.trace(A.T @ A) + TINY) * np.eye(3))
    D = np.diag([1.0, 1.0, np.sign(np.linalg.det(U @ Vt)) or 1.0])
    return U @ D @ Vt


class SpatialFirstPose:
    """The first pose of a spatial `Model` (kincas/core/numeric.py `SpatialModel`), which
    supplies the symbolic model and its geometry call."""

    @property
    def watch_scaled(self) -> np.ndarray:
        """Per unknown, whether the careful path's watch scales its group's block to unit
        columns and rows (kincas/analysis/watch.py): a quaternion's (its norm equation, the
        axis equations' half angles carry factors of their own) and a joint angle's (the
        loops' axis equations likewise); a position's group is measured as in the plane."""
        return np.array([k != "length" for k in self.unknown_kinds], bool)

    @property
    def assembly_starts(self):
        """Group by group assembly (kincas/core/assembly.py) spreads starts by turning angles;
        a quaternion's components are not turned so: with a floating body, the start near the
        last pose and one more; with joint angles only (every body hung), as many as planar."""
        return 2 if "quaternion" in self.unknown_kinds else 10 ** 9

    def _drawn(self, u, p):
        """Per rigid body its drawn points (n x 3); the ground points by name."""
        m = self.sym.mech
        local, ground = (a.ravel() for a in self._geometry(u, p))
        out, k = {}, 0
        for b in m.bodies:
            n = 2 if b.two_point else len(b.points)
            if not b.two_point:
                out[b.name] = local[k:k + 3 * n].reshape(n, 3)
            k += 3 * n
        gv = {g: ground[3 * i:3 * i + 3] for i, (g, _) in enumerate(m.ground)}
        return out, gv

    def _placing(self):
        """What `initial_q` reads of the structure, once per model: per rigid body, in the
        order the model places it (kincas/model/space_tree.py), its name, point names, how it
        hangs (None: it floats) and where its unknowns sit in q (a floating body's r and e;
        a hung body's coordinates that are unknowns, by name); per point only bars carry,
        where its coordinates sit; whether any input drives a joint."""
        def build():
            m, sym = self.sym.mech, self.sym
            index = {name: i for i, (name, _) in enumerate(sym.unknowns)}
            bodies = []
            for name, hang in placement(m):
                if hang is None:
                    slots = ([index[f"{name}.r{a}"] for a in "xyz"], [index[f"{name}.q{a}"] for a in "wxyz"])
                elif hang.type == "ball":
                    slots = {"e": [index[f"{name}.q{a}"] for a in "wxyz"]}
                else:
                    slots = {k: index[f"{hang.joint}.{k}"] for k in ("angle", "s") if f"{hang.joint}.{k}" in index}
                bodies.append((name, m.link(name).point_names, hang, slots))
            bars = [(pt, [index[f"{pt}.{a}"] for a in "xyz"]) for pt in m.moving_points if f"{pt}.x" in index]
            return bodies, bars, any(inp.kind == "joint" for inp in m.inputs)
        return self.memo("first_pose.placing", build)

    def initial_q(self, u, p, guess, L, turn=None, free=None) -> np.ndarray:
        """Unknowns placed from the drawing pose, the guess and the inputs (module text)."""
        m = self.sym.mech
        u = np.asarray(u, float)
        drawn, gv = self._drawn(u, p)
        bodies, bars, driven = self._placing()
        q = np.zeros(self.nq)
        o = gv[m.ground[0][0]] if m.ground else np.zeros(3)  # the model's origin
        pose = {GROUND: (np.zeros(3), np.eye(3), np.zeros(3))}  # body -> (r, R, c)
        for name, names, _, _ in bodies:
            P0 = drawn[name]
            c = P0.sum(axis=0) / len(P0)  # (the mean's own arithmetic, without its checks)
            have = [i for i, pt in enumerate(names) if pt in guess or pt in gv]
            if have:
                A = P0[have]
                B = np.array([guess[names[i]] if names[i] in guess else gv[names[i]] for i in have], float)
                a0, b0 = A.sum(axis=0) / len(A), B.sum(axis=0) / len(B)
                R = kabsch(A - a0, B - b0) if len(have) > 1 else np.eye(3)
                r = b0 - R @ (a0 - c)
            else:
                R, r = np.eye(3), c
            pose[name] = (r, R, c)
        if driven:  # an input on a joint that closes a loop (a hung body's: its angle below)
            hanging = {h.joint for _, _, h, _ in bodies if h is not None}
            for k, inp in enumerate(m.inputs):
                if inp.kind == "joint" and inp.target.partition(".")[0] not in hanging:
                    self._drive(pose, m, inp.target, u[k], drawn)
        for name, names, hang, slots in bodies:
            if hang is None:
                r, R, _ = pose[name]
                q[slots[0]] = r - o
                q[slots[1]] = quat_of(R)
            else:  # from its parent's pose as placed: its coordinates (the fit's, or the inputs)
                coords = self._hung(pose, m, name, names, hang, u, drawn, gv)
                for k, i in slots.items():
                    q[i] = coords[k]
        for pt, xi in bars:
            q[xi] = np.array(guess[pt], float) - o
        return q

    @staticmethod
    def _hung(pose, m, name, names, hang, u, drawn, gv) -> dict:
        """A hung body's coordinates {"angle": .., "s": ..}: the inputs, else the turn about
        the joint's axis a nearest its fitted rotation relative to its parent's placed one
        (R1' R2 = Rot(a, theta)) and its fitted point's distance along the first body's
        line; its pose then set from the parent's (a revolute's point where the parent
        carries it, a slide's moved along the line by s). A body on a ball keeps its fitted
        rotation ({"e": its quaternion}), its point where the parent carries it."""
        if hang.type == "ball":
            rp, Rp, cp = pose[hang.parent]
            _, R, c = pose[name]
            X = gv[hang.point] if hang.parent == GROUND else \
                rp + Rp @ (drawn[hang.parent][m.link(hang.parent).point_names.index(hang.point)] - cp)
            pose[name] = (X - R @ (drawn[name][names.index(hang.point)] - c), R, c)
            return {"e": quat_of(R)}
        j = m.joint(hang.joint)
        a = np.asarray(j.axis, float)
        rp, Rp, cp = pose[hang.parent]
        r, R, c = pose[name]
        out, Rn = {}, Rp
        if j.type in ("revolute", "cylindrical"):
            th = float(u[hang.driven]) if hang.driven is not None else \
                angle_about(Rp.T @ R if hang.parent_first else R.T @ Rp, a)
            H = axis_rotation(a, th)
            out["angle"], Rn = th, Rp @ (H if hang.parent_first else H.T)
        if j.type == "revolute":
            X = gv[hang.point] if hang.parent == GROUND else \
                rp + Rp @ (drawn[hang.parent][m.link(hang.parent).point_names.index(hang.point)] - cp)
            P0 = drawn[name][names.index(hang.point)]
        else:
            owner = m.joint_bodies(j)[1]  # the point is drawn on the second body
            P0 = gv[hang.point] if owner == GROUND else drawn[owner][m.link(owner).point_names.index(hang.point)]
            Xp, Xc = rp + Rp @ (P0 - cp), r + R @ (P0 - c)  # the parent's and the fit's copies
            sign, Ra = (1.0 if hang.parent_first else -1.0), Rp @ a
            out["s"] = float(u[hang.driven_s]) if hang.driven_s is not None else float(sign * (Xc - Xp) @ Ra)
            X = Xp + sign * out["s"] * Ra
        pose[name] = (X - Rn @ (P0 - c), Rn, c)
        return out

    @staticmethod
    def _drive(pose, m, target, value, drawn):
        """Turn (or move) a driven joint's second body so its coordinate reads `value`."""
        jname, _, coord = target.partition(".")
        j = m.joint(jname)
        b1, b2 = m.joint_bodies(j)
        if coord not in ("angle", "s") or j.type not in ("revolute", "cylindrical", "prismatic"):
            return
        r1, R1, c1 = pose[b1]
        r2, R2, c2 = pose[b2]
        a = R1 @ np.asarray(j.axis)
        P0 = next(drawn[b.name][i] for b in m.bodies if b.name == b2 for i, p in enumerate(b.point_names)
                  if p == j.point)
        X = r2 + R2 @ (P0 - c2)  # the joint's point
        if coord == "angle":
            e = quat_of(R1.T @ R2)
            now = 2 * np.arctan2(e[1:] @ np.asarray(j.axis), e[0])
            T = axis_rotation(a, value - now)
            pose[b2] = (X + T @ (r2 - X), T @ R2, c2)
        else:
            X1 = r1 + R1 @ (P0 - c1)
            pose[b2] = (r2 + (value - (X - X1) @ a) * a, R2, c2)

    # --- the bodies' poses as numbers (modes' signatures, the certified map) ---
    def _pose_function(self):
        """A Function (q, u, p) -> per rigid body (declaration order) the centroid of its
        drawn points (relative to the model's origin) and its rotation's 9 entries, row by
        row (R(e) / e.e: the rotation itself, whatever e's norm)."""
        def build():
            sym, m = self.sym, self.sym.mech
            out = []
            for b in m.bodies:
                if b.two_point:
                    continue
                loc = [sym._rel(xyz) for _, xyz in b.points]
                c = [sum(v[i] for v in loc) / len(loc) for i in range(3)]
                e = sym.frames[b.name][1]
                n, R = e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + e[3] * e[3], rotation(e)
                out += sym.world(b.name, c) + [R[i][k] / n for i in range(3) for k in range(3)]
            return ca.Function("body_poses", [sym.q, sym.u, sym.p], [ca.vertcat(*out)] if out else [ca.SX(0, 1)])
        return self.memo("space.body_poses", build)

    def body_poses(self, q, u, p) -> dict:
        """Per rigid body its (centroid relative to the model's origin, rotation matrix)."""
        v = np.asarray(self._pose_function()(q, u, p), float).ravel()
        names = [b.name for b in self.sym.mech.bodies if not b.two_point]
        return {nm: (v[12 * k:12 * k + 3], v[12 * k + 3:12 * k + 12].reshape(3, 3)) for k, nm in enumerate(names)}

    def rotations_many(self, Q, u, p) -> np.ndarray:
        """Every rigid body's rotation matrix at each row of Q (one input u): one row of
        9 entries per body per row of Q (kincas/analysis/assembly_mode.py's signature)."""
        n = Q.shape[0]
        f = self._pose_function().map(n)
        V = np.asarray(f(Q.T, np.tile(np.reshape(u, (-1, 1)), n), np.tile(np.reshape(p, (-1, 1)), n)), float)
        V = V.reshape(-1, 12, n)[:, 3:, :]  # bodies x 9 x n
        return V.transpose(2, 0, 1).reshape(n, -1)

    def unknowns_from_poses(self, poses, points) -> np.ndarray:
        """q from every rigid body's (centroid relative to the model's origin, rotation) and
        every point only bars carry (relative to the origin): a floating body's r and unit
        quaternion (w >= 0); a hung body's angle from its rotation relative to its parent's,
        its slide from its point's distance along the first body's line (an input's
        coordinate: no unknown)."""
        m = self.sym.mech
        index = {name: i for i, name in enumerate(self.unknown_names)}
        o = np.array([m.value(c) for c in m.ground[0][1]]) if m.ground else np.zeros(3)
        rel = lambda xyz: np.array([m.value(c) for c in xyz], float) - o  # noqa: E731

        def world(b, P0):
            if b == GROUND:
                return P0
            r, R = poses[b]
            return r + R @ (P0 - np.mean([rel(xyz) for _, xyz in m.link(b).points], axis=0))
        q = np.zeros(self.nq)
        for name, hang in placement(m):
            r, R = poses[name]
            if hang is None or hang.type == "ball":  # (on a ball: its rotation only)
                if hang is None:
                    q[[index[f"{name}.r{a}"] for a in "xyz"]] = r
                q[[index[f"{name}.q{a}"] for a in "wxyz"]] = quat_of(R)
                continue
            j = m.joint(hang.joint)
            Rp = np.eye(3) if hang.parent == GROUND else poses[hang.parent][1]
            if f"{j.name}.angle" in index:
                q[index[f"{j.name}.angle"]] = angle_about(Rp.T @ R if hang.parent_first else R.T @ Rp, j.axis)
            if f"{j.name}.s" in index:
                P0 = rel(m.slide_point(j))
                sign = 1.0 if hang.parent_first else -1.0
                q[index[f"{j.name}.s"]] = sign * (world(name, P0) - world(hang.parent, P0)) @ (Rp @ np.asarray(j.axis))
        for pt, v in points.items():
            q[[index[f"{pt}.{a}"] for a in "xyz"]] = v
        return q

    def scatter(self, m, n: int, L: float, rng) -> np.ndarray:
        """n random starts (kincas.find_modes): each floating body's reference point uniform
        in a cube of half-side L about a ground point, its quaternion uniform on the unit
        sphere of R^4 (a uniformly random rotation), a point only bars carry likewise in the
        cube; a hung body's joint angle uniform on the circle; its slide s uniform within
        `reach` of the line's point nearest a randomly chosen ground point (as drawn): every
        point of the mechanism is within the sum of its bodies' extents of the ground, so its
        assemblies' s are there (a slider-crank's second one is twice the rod's run away from
        the drawn one, beyond (-L, L); 16 starts missed it in 21 runs of 25)."""
        names, sym = self.unknown_names, self.sym
        reach = self._reach(m)
        Q = np.zeros((n, len(names)))
        o = np.array([m.value(c) for c in m.ground[0][1]]) if m.ground else np.zeros(3)
        ground = np.array([[m.value(c) for c in xyz] for _, xyz in m.ground]).reshape(-1, 3) - o
        ground = ground if len(ground) else np.zeros((1, 3))
        for j, (nm, kind) in enumerate(sym.unknowns):
            if nm.endswith((".rx", ".x")):  # a body's reference point, or a bar-only point
                centre = ground[rng.integers(len(ground), size=n)]
                Q[:, j:j + 3] = centre + rng.uniform(-L, L, size=(n, 3))
            elif kind == "angle":  # a hung body's joint angle
                Q[:, j] = rng.uniform(-np.pi, np.pi, n)
            elif nm.endswith(".s"):  # a hung body's slide along its joint's line
                jt = m.joint(nm[:-2])
                P0 = np.array([m.value(c) for c in m.slide_point(jt)]) - o
                near = (ground[rng.integers(len(ground), size=n)] - P0) @ np.asarray(jt.axis, float)
                Q[:, j] = near + rng.uniform(-reach, reach, n)
            elif nm.endswith(".qw"):
                e = rng.standard_normal((n, 4))
                Q[:, j:j + 4] = e / np.linalg.norm(e, axis=1, keepdims=True)
        return Q

    @staticmethod
    def _reach(m) -> float:
        """The sum of the bodies' extents (a bar's length, a body's largest distance between
        its drawn points): no point is further than that from the ground's."""
        def extent(b):
            if b.two_point:
                return abs(m.value(b.length))
            P = np.array([[m.value(c) for c in xyz] for _, xyz in b.points])
            return float(np.max(np.linalg.norm(P[:, None] - P[None], axis=2)))
        return sum(extent(b) for b in m.bodies) or 1.0

    def mode_angles(self) -> list[tuple[str, str]]:
        """(name, quantity) of the angles a mode reports: every joint's angle coordinates."""
        m = self.sym.mech
        return [(f"{j.name}.{c}", f"{j.name}.{c}") for j in m.joints for c in j.coordinates
                if c.startswith("angle")]

    def drawing_inputs(self, p) -> np.ndarray:
        """The inputs at the drawing pose: joint coordinates 0, a slide's s as drawn, a driven
        parameter its value (where the rank test of redundant joints starts)."""
        m = self.sym.mech
        out = []
        for inp in m.inputs:
            if inp.kind == "parameter":
                out.append(m.parameter(inp.target))
            elif inp.kind == "slide":
                sl = m.slide(inp.target)
                pt = dict(m.guess)[sl.point]
                d = np.array([m.value(c) for c in pt]) - np.array([m.value(c) for c in sl.through])
                out.append(float(d @ np.asarray(sl.direction)))
            else:
                out.append(0.0)
        return np.array(out, float)
