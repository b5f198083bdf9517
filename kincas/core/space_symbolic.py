"""The symbolic model of a spatial mechanism: the same interface as `Symbolic` (planar), so
that Newton, sweeps, singular flags, sensitivities and the compiled kernels use it unchanged.

Formulation (docs/spatial.md): absolute coordinates with unit quaternions, reduced on the
tree of revolutes from the ground. A floating rigid body has unknowns r (3, its reference
point: at the drawing pose the centroid c of its drawn points) and e = (w, x, y, z) (4), with
e.e - 1 = 0; its point P (drawn at P0) is r + R(e) (P0 - c), R(e) the quadratic rotation
matrix of e. A body hung on a revolute of an already placed body (kincas/model/space_tree.py)
has one unknown instead, the joint's angle theta (the input where one drives it: none), with
e = e_parent (x) (cos(theta/2), sin(theta/2) a) and r the joint's point where the parent
carries it (c its drawn position): its norm, the joint's point and axis equations hold
identically and are not written. On a cylindrical joint it has the angle and the slide s
(r moved along the first body's line by s), on a prismatic one s alone (e = e_parent). Every position inside is taken
relative to the first ground point (added back to reported positions), so a mechanism far
from the global origin keeps its residuals' and steps' relative accuracy. A point that only two-point bars
carry has its 3 coordinates as unknowns; a bar adds (|P - Q|^2 - L^2) / L = 0. Every
equation is polynomial in (r, e) (and in the half angles' cosines and sines). Equations
without a length (a quaternion's norm, axes kept
perpendicular) are multiplied by the mechanism's size `Ls`, so that every residual is a
length and every quaternion column of g_q is a length, like an angle's in the planar model:
the tolerances and the scales of kincas/core/numeric.py mean the same at any size.

A joint's angle comes from the relative quaternion conj(e1) (x) e2 = (w, v): a rotation about
the unit axis a by theta has v = sin(theta/2) a, w = cos(theta/2), so with s = v.a,
theta = atan2(2 s w, w^2 - s^2), wrapped in (-pi, pi] (a hung body's: atan2(sin, cos) of its
unknown). An input driving a joint that closes a loop adds
s cos(u/2) - w sin(u/2) = sin((theta - u)/2) = 0: e and -e (the same rotation) both satisfy
it, and theta = u + 2k pi only (no spurious branch). A revolute joint keeps v along a
(v.b1 = v.b2 = 0 for b1, b2 perpendicular to a): regular at every angle (the Jacobian of
(v.b1, v.b2) in the rotations about b1, b2 has determinant (w^2 + s^2) / 4 = 1/4), and
without the flipped assembly R2 a = -R1 a that (R2 a).(R1 b) = 0 would admit.

An RSSR: the crank hangs on its driven revolute (no unknown), the rocker on its own (its
angle), and the bar between them is the one equation:

>>> import kincas
>>> from kincas import SpatialMechanism, Body, Joint, Input
>>> m = SpatialMechanism(ground={"A": (0, 0, 0), "D": (4, 0, 0)},
...     bodies=[Body("crank", {"A": (0, 0, 0), "B": (1, 0, 0)}), Body.bar("coupler", "B", "C", 4.5),
...             Body("rocker", {"D": (4, 0, 0), "C": (4, 0, 3)})],
...     joints=[Joint("revolute", "A", axis=(0, 0, 1)), Joint("revolute", "D", axis=(1, 0, 0))],
...     inputs=[Input.joint("A")])
>>> s = SpatialSymbolic(m)
>>> s.nq, s.ng, s.unknowns
(1, 1, [('D.angle', 'angle')])
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from ..model.mobility import GROUND
from ..model.names import parse_quantity
from ..model.space_names import BODY_Q, POINT_Q3, SLIDE_Q, joint_attrs
from ..model.space_parts import ON_SECOND
from ..model.space_tree import placement
from .quaternions import apply, apply_t, conj, cross, dot, qmul, rotation  # noqa: F401
from .symbolic import Symbolic
from .tolerances import PROJECTION

IDENTITY = (1.0, 0.0, 0.0, 0.0)


def perpendiculars(a) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors making (a, b1, b2) a right-handed orthonormal frame."""
    a = np.asarray(a, float)
    k = int(np.argmin(np.abs(a)))
    b1 = np.cross(a, np.eye(3)[k])
    b1 /= np.linalg.norm(b1)
    return b1, np.cross(a, b1)


def in_plane_axes(n) -> tuple[np.ndarray, np.ndarray]:
    """A planar joint's e1 (global x projected on the plane, normalised; global y where x is
    normal to it) and e2 = n x e1."""
    n = np.asarray(n, float)
    for g in np.eye(3)[:2]:
        e1 = g - (g @ n) * n
        if np.linalg.norm(e1) > PROJECTION:
            e1 /= np.linalg.norm(e1)
            return e1, np.cross(n, e1)
    raise AssertionError("unreachable: x and y cannot both be normal to a plane")


def joint_angle(w, s):
    """The rotation 2 atan2(s, w), written as atan2(2 s w, w^2 - s^2): in (-pi, pi]."""
    return ca.atan2(2 * s * w, w * w - s * s)


class SpatialSymbolic(Symbolic):
    """The symbolic model of one spatial mechanism structure (parameters stay symbolic)."""

    dim = 3

    def _build(self):
        m = self.mech
        qs, self.unknowns, eqs = [], [], []

        body = [None]  # the body being placed: it owns the unknowns made now (a joint's J.angle too)

        def new(name, kind):
            qs.append(ca.SX.sym(name))
            self.unknowns.append((name, kind))
            self._owner.append(body[0] or name.split(".")[0])
            return qs[-1]

        self.Ls = self._size()
        Ls = self.Ls
        self._half, self._sc = {}, {}  # per joint angle: (w, s) of its half angle; (sin, cos)
        # coordinates relative to the first ground point: far from the global origin, the
        # residuals (differences of nearby points) and the steps keep their relative accuracy
        self.origin = self._xyz(m.ground[0][1]) if m.ground else [ca.SX(0)] * 3
        exempt = m.exempt()
        # a ground point that is the point of a cylindrical, prismatic or planar joint with the
        # ground first marks where the line or plane is drawn; the point itself is the second
        # body's (it slides), so the ground's copy does not hold it
        self._ground = {g: self._rel(xyz) for g, xyz in m.ground}
        self.points = {g: v for g, v in self._ground.items() if (g, GROUND) not in exempt}
        self.frames = {GROUND: ([ca.SX(0)] * 3, [ca.SX(c) for c in IDENTITY], [ca.SX(0)] * 3)}
        self.hung = {}  # "J.angle", "J.s" of the joints bodies hang on: an unknown, or the input
        self._owner = []
        for name, hang in placement(m):
            b, body[0] = m.link(name), name
            loc = {p: self._rel(xyz) for p, xyz in b.points}
            if hang is None:  # floating: its reference point and unit quaternion
                c = [sum(v[i] for v in loc.values()) / len(loc) for i in range(3)]
                r = [new(f"{name}.r{a}", "length") for a in "xyz"]
                e = [new(f"{name}.q{a}", "quaternion") for a in "wxyz"]
                eqs.append(Ls * (dot(e[1:], e[1:]) + e[0] * e[0] - 1))
            elif hang.type == "ball":  # on a placed point: its unit quaternion, r where the point is
                e = [new(f"{name}.q{a}", "quaternion") for a in "wxyz"]
                eqs.append(Ls * (dot(e[1:], e[1:]) + e[0] * e[0] - 1))
                r, c = self._carried(hang), loc[hang.point]
            else:  # hung on a placed body's joint: its coordinates only (kincas/model/space_tree.py)
                r, e, c = self._hang(hang, loc, new)
            self.frames[name] = (r, e, c)
            for p, P0 in loc.items():
                if (p, name) in exempt or (hang is not None and hang.type in ("revolute", "ball") and p == hang.point):
                    continue  # a hanging revolute's or ball's point: where the parent carries it, identically
                w = self.world(name, P0)
                if p in self.points:  # a ball joint (or the point of a revolute, universal)
                    eqs += [w[i] - self.points[p][i] for i in range(3)]
                else:
                    self.points[p] = w
        body[0] = None
        for p in m.moving_points:
            if p not in self.points:  # carried by bars only
                self.points[p] = [new(f"{p}.{a}", "length") for a in "xyz"]
        for b in m.bodies:
            if b.two_point:
                P, Q = (self.points[n] for n in b.point_names)
                d = [P[i] - Q[i] for i in range(3)]
                L = self.val(b.length)
                eqs.append((dot(d, d) - L * L) / L)
        self.joint_q, self.slide_s = {}, {}
        for j in m.joints:
            eqs += self._joint(j)
        for sl in m.slides:
            r1, e1, c1 = self.frames[sl.along]
            R1 = rotation(e1)
            X1 = self.world(sl.along, self._rel(sl.through))
            d = [self.points[sl.point][i] - X1[i] for i in range(3)]
            if sl.on_line:
                b1, b2 = perpendiculars(sl.direction)
                eqs += [dot(d, apply(R1, list(b1))), dot(d, apply(R1, list(b2)))]
                self.slide_s[sl.name] = dot(d, apply(R1, list(sl.direction)))
            else:
                eqs.append(dot(d, apply(R1, list(sl.normal))))
        for k, i in enumerate(m.inputs):
            u = self.u[k]
            if i.kind == "slide":
                eqs.append(self.slide_s[i.target] - u)
            elif i.kind == "joint" and i.target not in self.hung:
                eqs.append(self._input_equation(i.target, u))
        self.angles = {}
        self.points = {k: [v[i] + self.origin[i] for i in range(3)] for k, v in self.points.items()}
        self._ground = {k: [v[i] + self.origin[i] for i in range(3)] for k, v in self._ground.items()}
        self._finish(qs, eqs)

    def unknown_links(self) -> list[str]:
        """Per unknown, the body it places (a hung body's joint coordinate `D.angle` is the
        body's, not the joint's), or the point only bars carry: how groups are named."""
        return list(self._owner)

    def _hang(self, hang, loc, new):
        """(r, e, c) of a body hung on a placed body's joint (kincas/model/space_tree.py), its
        coordinates the inputs driving them, else unknowns (in `self.hung` by name):
        e = e_parent (x) h (conj(h) when the parent is the joint's second body), h =
        (cos(theta/2), sin(theta/2) a) for a revolute or cylindrical joint, e = e_parent for a
        prismatic one. A revolute's r is its point where the parent carries it; a slide moves
        the point drawn on the second body along the first's line by s: r = X1 + s R1 a (the
        parent first) or X2 - s R2 a (the parent second). c: the point's drawn position."""
        m, j = self.mech, self.mech.joint(hang.joint)
        coord = lambda c, k, kind: self.u[k] if k is not None else new(f"{j.name}.{c}", kind)
        ep = [ca.SX(c) for c in IDENTITY] if hang.parent == GROUND else self.frames[hang.parent][1]
        e = ep
        if j.type in ("revolute", "cylindrical"):
            th = self.hung[f"{j.name}.angle"] = coord("angle", hang.driven, "angle")
            h = [ca.cos(th / 2)] + [ca.sin(th / 2) * a for a in j.axis]
            h = h if hang.parent_first else conj(h)
            e = h if hang.parent == GROUND else qmul(ep, h)
        if j.type == "revolute":
            return self._carried(hang), e, loc[hang.point]
        s = self.hung[f"{j.name}.s"] = coord("s", hang.driven_s, "length")
        P0 = self._rel(m.slide_point(j))  # the point is drawn on the second body
        Xp = self.world(hang.parent, P0)
        Ra = apply(rotation(ep), list(j.axis)) if hang.parent != GROUND else list(j.axis)
        sign = 1 if hang.parent_first else -1
        return [Xp[i] + sign * s * Ra[i] for i in range(3)], e, P0

    def _carried(self, hang) -> list:
        """Where the placed parent carries the point a body hangs on (relative coordinates)."""
        if hang.parent == GROUND:
            return list(self.points[hang.point])
        return self.world(hang.parent, self._rel(self.mech.link(hang.parent).local(hang.point)))

    def ground_at(self, g: str) -> list:
        """Where ground point `g` is drawn, also where it is the anchor of a slide joint."""
        return self._ground[g]

    # --- numbers, frames ---
    def _xyz(self, xyz):
        return [self.val(c) for c in xyz]

    def _rel(self, xyz):
        """A drawn point relative to the model's origin (the first ground point)."""
        return [self.val(c) - o for c, o in zip(xyz, self.origin)]

    def world(self, body, P0):
        """Where the point drawn at P0 (global, drawing pose) is when `body` has moved."""
        r, e, c = self.frames[body]
        if body == GROUND:
            return list(P0)
        v = apply(rotation(e), [P0[i] - c[i] for i in range(3)])
        return [r[i] + v[i] for i in range(3)]

    def _size(self):
        """The mechanism's size as an expression of the parameters (`SpatialMechanism.size`)."""
        m, terms = self.mech, [ca.SX(0)]
        dist = lambda a, b: ca.sqrt(sum((a[i] - b[i]) ** 2 for i in range(3)))
        for b in m.bodies:
            if b.two_point:
                terms.append(ca.fabs(self.val(b.length)))
                continue
            pts = [self._xyz(xyz) for _, xyz in b.points]
            terms += [dist(a, c) for k, a in enumerate(pts) for c in pts[k + 1:]]
        g = [self._xyz(xyz) for _, xyz in m.ground]
        terms += [dist(a, c) for k, a in enumerate(g) for c in g[k + 1:]]
        out = terms[0]
        for t in terms[1:]:
            out = ca.fmax(out, t)
        return ca.if_else(out > 0, out, 1.0)

    def local_points(self, lk) -> list[tuple]:
        """A body's points as drawn; a bar's ends at (0, 0, 0) and (L, 0, 0)."""
        if lk.two_point:
            return [(ca.SX(0), ca.SX(0), ca.SX(0)), (self.val(lk.length), ca.SX(0), ca.SX(0))]
        return [tuple(self._xyz(xyz)) for _, xyz in lk.points]

    # --- joints ---
    def _relative(self, b1, b2):
        """conj(e1) (x) e2: the rotation of body 2 relative to body 1, in body 1's axes."""
        return qmul(conj(self.frames[b1][1]), self.frames[b2][1])

    def _joint(self, j) -> list:
        m, Ls = self.mech, self.Ls
        b1, b2 = m.joint_bodies(j)
        R1, R2 = rotation(self.frames[b1][1]), rotation(self.frames[b2][1])
        eqs, name = [], j.name
        if j.type == "universal":
            a0, a1 = (list(a) for a in j.axes)
            eqs.append(Ls * dot(apply(R1, a0), apply(R2, a1)))
            v1 = apply_t(R1, apply(R2, a1))  # R1' R2 a1 = Rot(a0, angle1) a1
            v2 = apply_t(R2, apply(R1, a0))  # R2' R1 a0 = Rot(a1, -angle2) a0
            s1, c1 = dot(a0, cross(a1, v1)), dot(a1, v1)
            s2, c2 = -dot(a1, cross(a0, v2)), dot(a0, v2)
            self.joint_q[f"{name}.angle1"] = ca.atan2(s1, c1)
            self.joint_q[f"{name}.angle2"] = ca.atan2(s2, c2)
            self._sc[f"{name}.angle1"], self._sc[f"{name}.angle2"] = (s1, c1), (s2, c2)
            return eqs
        if j.type == "spherical":
            return eqs
        if f"{name}.angle" in self.hung or f"{name}.s" in self.hung:  # a body hangs on it:
            if f"{name}.angle" in self.hung:  # its equations hold identically
                th = self.hung[f"{name}.angle"]
                self.joint_q[f"{name}.angle"] = ca.atan2(ca.sin(th), ca.cos(th))
                self._half[f"{name}.angle"] = (ca.cos(th / 2), ca.sin(th / 2))
            if f"{name}.s" in self.hung:
                self.joint_q[f"{name}.s"] = self.hung[f"{name}.s"]
            return eqs
        a = list(j.axis)
        b1v, b2v = (list(v) for v in perpendiculars(a))
        if j.type in ("revolute", "cylindrical", "planar"):
            # a rotation about a alone: the relative quaternion's vector part along a. (Keeping
            # R2 a perpendicular to R1 b1 and R1 b2 instead would also admit R2 a = -R1 a: a
            # spurious assembly half a turn away that a sweep can fall into.)
            w, *v = self._relative(b1, b2)
            eqs += [Ls * dot(v, b1v), Ls * dot(v, b2v)]
            self.joint_q[f"{name}.angle"] = joint_angle(w, dot(v, a))
            self._half[f"{name}.angle"] = (w, dot(v, a))
        if j.type in ON_SECOND:
            P0 = self._rel(next(xyz for b in m.bodies if b.name == b2 for p, xyz in b.points if p == j.point))
            X1 = self.world(b1, P0)
            d = [self.points[j.point][i] - X1[i] for i in range(3)]
            if j.type == "planar":
                eqs.append(dot(d, apply(R1, a)))
                e1, e2 = in_plane_axes(a)
                self.joint_q[f"{name}.s1"] = dot(d, apply(R1, list(e1)))
                self.joint_q[f"{name}.s2"] = dot(d, apply(R1, list(e2)))
            else:
                eqs += [dot(d, apply(R1, b1v)), dot(d, apply(R1, b2v))]
                self.joint_q[f"{name}.s"] = dot(d, apply(R1, a))
            if j.type == "prismatic":  # no rotation at all: the relative quaternion's vector part
                eqs += [Ls * c for c in self._relative(b1, b2)[1:]]
        return eqs

    def _input_equation(self, coord, u):
        """One equation fixing a joint coordinate at u (see the module's text)."""
        if coord in self._half:
            w, s = self._half[coord]
            return self.Ls * (s * ca.cos(u / 2) - w * ca.sin(u / 2))
        if coord in self._sc:  # a universal joint's angle: sin(theta - u) = 0
            s, c = self._sc[coord]
            return self.Ls * (s * ca.cos(u) - c * ca.sin(u))
        return self.joint_q[coord] - u

    # --- quantities ---
    def position_expr(self, obj: str, attr: str):
        if attr in POINT_Q3 and obj in self.points:
            comp, order = POINT_Q3[attr]
            return self.points[obj][comp], order
        if attr in SLIDE_Q and obj in self.slide_s:
            return self.slide_s[obj], SLIDE_Q[attr]
        if obj in {j.name for j in self.mech.joints}:
            coords = self.mech.joint(obj).coordinates
            hit = joint_attrs(coords).get(attr)
            if hit is not None:
                return self.joint_q[f"{obj}.{hit[0]}"], hit[1]
        if obj in self.frames and obj != GROUND and attr in BODY_Q and BODY_Q[attr][0] in ("q", "R"):
            return self._orientation(obj, attr), 0
        return None, None

    def _orientation(self, body, attr):
        e = self.frames[body][1]
        kind, i = BODY_Q[attr]
        if kind == "R":
            return rotation(e)[i // 3][i % 3]
        sgn = ca.SX(1)
        for c in reversed(e):  # qw >= 0; where qw = 0, the first non-zero of qx, qy, qz > 0
            sgn = ca.if_else(c > 0, 1, ca.if_else(c < 0, -1, sgn))
        return sgn * e[i]

    def extra(self, name: str):
        kind, obj, attr = parse_quantity(name)
        if kind == "plain" and obj in self.frames and obj != GROUND and BODY_Q.get(attr, ("",))[0] in ("omega", "alpha"):
            return _BodyRates, []
        from . import space_dynamics  # efforts and shaking (it imports this module's helpers lazily)
        problems = space_dynamics.check(self, name)
        return (None, None) if problems is None else (space_dynamics, problems)

    def check_names(self, names: list[str], where: str = "[output] report") -> list[str]:
        out = []
        for n in names:
            kind, a, b = parse_quantity(n)
            if kind == "sens":
                out += super().check_names([n], where)
            elif n.replace(" ", "").startswith("reaction("):  # optional in 3D (contract), not built
                out.append(f"{where}: {n!r}: joint reactions are not built for spatial scenes in this "
                           f"version (efforts, effort(KEY), and shaking.x .. shaking.mz are)")
            elif b in BODY_Q and any(lk.two_point and lk.name == a for lk in self.mech.bodies):
                out.append(f"{where}: {n!r}: {a} is a two-point bar: its spin about its own axis is "
                           f"not defined, so it has no rotation, quaternion or angular rate (report "
                           f"its ends' positions and velocities, or make it a body with points)")
            elif self.position_expr(a, b)[0] is None and self.extra(n)[0] is None:
                out.append(f"{where}: unknown quantity {n!r} (expected P.x .. P.z, P.vx, P.ax, P.jx .., "
                           f"L.qw .. L.qz, L.R11 .. L.R33, L.omega_x .., L.alpha_x .., J.angle, "
                           f"J.omega, J.alpha, J.s, J.v, J.a (J.angle1, J.s1 ..), S.s of a slide, "
                           f"or d(Q)/d(p) with declared names)")
        return out


class _BodyRates:
    """A body's angular velocity and acceleration, global axes: with e' = D e,
    omega = 2 vec(e' (x) conj(e)), alpha = 2 vec(e'' (x) conj(e)) (the derivative of
    e' (x) conj(e') is real: its vector part vanishes)."""

    @staticmethod
    def expression(sym, name, t):
        _, body, attr = parse_quantity(name)
        kind, i = BODY_Q[attr]
        e = sym.frames[body][1]
        order = 1 if kind == "omega" else 2
        de = [t.d(c, order) for c in e]
        return 2 * qmul(de, conj(e))[1 + i]
