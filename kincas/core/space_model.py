"""The first pose of a spatial mechanism, a part of its numeric model (`SpatialModel`,
kincas/core/numeric.py: `Model` on the spatial symbolic model), placed from the drawing pose
and the guess.

Every body starts at the least-squares rigid fit of its drawn points to their guessed
positions (Kabsch: the rotation R minimising sum |R a_i - b_i|^2 over centred points, from the
SVD of sum b_i a_i', with det R = +1), which is the drawing pose itself where nothing is
guessed; a point only bars carry starts at its guess. Then each input on a joint's angle or
translation turns or moves that joint's second body, about the joint's axis through its
point, by the difference between the input and the coordinate at the fitted pose, so that
Newton starts near the driven pose rather than a whole input away from it.

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

import numpy as np

from ..model.mobility import GROUND
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

    # group by group assembly (kincas/core/assembly.py) spreads starts by turning angles;
    # a quaternion's components are not turned so: the start near the last pose, and one more
    assembly_starts = 2

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
        """What `initial_q` reads of the structure, once per model: per rigid body its name and
        point names and where its r and e sit in q; per point only bars carry, where its
        coordinates sit; whether any input drives a joint."""
        def build():
            m, sym = self.sym.mech, self.sym
            index = {name: i for i, (name, _) in enumerate(sym.unknowns)}
            bodies = [(b.name, b.point_names, [index[f"{b.name}.r{a}"] for a in "xyz"],
                       [index[f"{b.name}.q{a}"] for a in "wxyz"]) for b in m.bodies if not b.two_point]
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
        if driven:
            for k, inp in enumerate(m.inputs):
                if inp.kind == "joint":
                    self._drive(pose, m, inp.target, u[k], drawn)
        for name, _, ri, ei in bodies:
            r, R, _ = pose[name]
            q[ri] = r - o
            q[ei] = quat_of(R)
        for pt, xi in bars:
            q[xi] = np.array(guess[pt], float) - o
        return q

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

    def scatter(self, m, n: int, L: float, rng) -> np.ndarray:
        """n random starts (kincas.find_modes): each body's reference point uniform in a cube
        of half-side L about a ground point, its quaternion uniform on the unit sphere of R^4
        (a uniformly random rotation), a point only bars carry likewise in the cube."""
        names, sym = self.unknown_names, self.sym
        Q = np.zeros((n, len(names)))
        o = np.array([m.value(c) for c in m.ground[0][1]]) if m.ground else np.zeros(3)
        ground = np.array([[m.value(c) for c in xyz] for _, xyz in m.ground]).reshape(-1, 3) - o
        ground = ground if len(ground) else np.zeros((1, 3))
        for j, (nm, kind) in enumerate(sym.unknowns):
            if nm.endswith((".rx", ".x")):  # a body's reference point, or a bar-only point
                centre = ground[rng.integers(len(ground), size=n)]
                Q[:, j:j + 3] = centre + rng.uniform(-L, L, size=(n, 3))
            elif nm.endswith(".qw"):
                e = rng.standard_normal((n, 4))
                Q[:, j:j + 4] = e / np.linalg.norm(e, axis=1, keepdims=True)
        return Q

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
