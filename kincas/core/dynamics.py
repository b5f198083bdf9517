"""Efforts, shaking forces and joint reactions from the exact kinematics (kinetostatics).

Every expression here is written in (q, u, p) and the motion's symbols (z', z''), so the
quantity function substitutes the exact velocities and accelerations, and sensitivities
d(effort(KEY))/d(p) follow by the implicit function theorem like any other quantity.

Efforts, by virtual work. A virtual change du of the inputs moves the chain by
dq = T du, T = dq/du = -g_q^-1 g_u (the same Jacobians as the velocities). With d'Alembert's
inertia forces, the generalized force Q_k the input k must supply makes the virtual work of
everything vanish:
    Q_k = sum_links [ m (a_G - g) . dr_G/du_k + J alpha dtheta/du_k ]
          - sum_forces F . dr_P/du_k - sum_torques tau dtheta/du_k + sum_springs k (d - d0) dd/du_k
(a torque for an angle input, a force for a slide or a parameter input such as a length).

Shaking force and moment on the ground (about the origin): -sum m a_G, -sum (r_G x m a_G + J alpha).

Joint reactions, by Newton-Euler per link: each moving link has three equations
    sum F = m a_G,   sum (r - c) x F + sum tau = (r_G - c) x m a_G + J alpha
with moments about c, a point of the link itself (the mean of its points), and unknowns the
pin forces (at a point shared by bodies b0, b1, ..., one unknown force on each of b1, ... and
their opposite sum on b0: the pin carries nothing itself), one normal force per slide, the
torque of each angle input (from the ground on its link) and the force of each slide input
(along its line). A parameter input (an actuator's length) is held rigid at its value: its
force is internal to its link. The system is square for a mechanism without redundant joints,
and its solution is the g_q^T lambda of the same constraints; it is solved exactly
(symbolic QR) only when a report asks for a reaction.

Conditioning. Moments about the origin would be sums of terms |r| |F| that cancel down to
|r - c| |F|: 1e4 lengths away, four digits are gone before the solve, and the solve mixes
force rows (entries 1) with moment rows (entries |r|), a matrix whose condition grows like
|r|^2. So each lever arm r - c is taken from the link's own coordinates, R(theta) (l_P - l_c),
as accurate wherever the link is; only a point that is not the link's (a slide's point on the body
carrying its line) takes the difference of its position and c's, as exact as those positions.
And the system is made dimensionless: with L the mechanism's size (the RMS distance of the
links' points from their links' means), moment rows are divided by L and torque unknowns
are L times a force, so every entry is a ratio of lengths of the same mechanism, whatever
its unit. A force scale would change nothing: the system is linear, so scaling all its
right-hand side scales the solution and its rounding alike.

A point load, a spring's end, and a slide's point act on the first body (in declaration order,
the ground first) that carries the point.
"""
from __future__ import annotations

import re

import casadi as ca

from ..model.mechanism import GROUND

_EFFORT = re.compile(r"^effort\((?P<key>[^()]+)\)$")
_REACTION = re.compile(r"^reaction\(\s*(?P<a>[^,()]+?)\s*(?:,\s*(?P<b>[^,()]+?)\s*)?\)\.(?P<attr>x|y)$")
_SHAKING = {"shaking.x": 0, "shaking.y": 1, "shaking.moment": 2}
_CONTACT = re.compile(r"^contact\((?P<cam>[^()]+)\)$")


# --- names ---


def bodies_at(mech, point: str) -> list[str]:
    """The bodies that carry a point: the ground first, then links in declaration order."""
    out = [GROUND] if point in mech.ground_points else []
    return out + [lk.name for lk in mech.links if point in lk.point_names]


def check(sym, name: str):
    """None when `name` is not a force quantity; else the problems with it ([] if fine)."""
    m = _EFFORT.match(name)
    if m:
        return [] if m["key"] in sym.ukeys else [f"no input {m['key']!r} (inputs: {sym.ukeys})"]
    if name in _SHAKING:
        return []
    m = _CONTACT.match(name)
    if m:
        cams = {c.name: c for c in sym.mech.cams}
        if m["cam"] not in cams:
            return [f"no cam named {m['cam']!r} (cams: {sorted(cams)})"]
        return [] if cams[m["cam"]].follower[0] in ("knife", "roller") else [
            "contact(CAM) is given for knife-edge and roller followers"]
    m = _REACTION.match(name)
    if not m:
        return None
    mech, a, b = sym.mech, m["a"], m["b"]
    if b is None:
        if a not in {s.name for s in mech.slides}:
            return [f"no slide named {a!r} (reaction(SLIDE).x, or reaction(POINT, BODY).x at a pin)"]
    elif len(bodies_at(mech, a)) < 2:
        return [f"{a!r} is not a joint (a point carried by two bodies or more)"]
    elif b not in bodies_at(mech, a):
        return [f"{b!r} does not carry point {a!r} (bodies there: {bodies_at(mech, a)})"]
    return _newton_euler(sym, None)[0]


# --- bodies: mass, centre of gravity, angle ---


def _to_global(sym, body, lx, ly):
    ox, oy, th = sym.frames[body]
    c, s = ca.cos(th), ca.sin(th)
    return ox + c * lx - s * ly, oy + s * lx + c * ly


def _mean_point(sym, lk):
    """The mean of a link's points, in its frame."""
    n = len(lk.points)
    return (sum((sym.val(x) for _, (x, _y) in lk.points), ca.SX(0)) / n,
            sum((sym.val(y) for _, (_x, y) in lk.points), ca.SX(0)) / n)


def _masses(sym):
    """(link, m, J, (x_G, y_G), theta, (lx, ly)) for each link with a mass or an inertia:
    its centre of gravity in the plane and in the link's frame."""
    out = []
    for lk in sym.mech.links:
        i = lk.inertial
        m, J = sym.val(i.mass), sym.val(i.inertia)
        if ca.is_equal(m, 0) and ca.is_equal(J, 0):
            continue
        lx, ly = (sym.val(i.cg[0]), sym.val(i.cg[1])) if i.cg is not None else _mean_point(sym, lk)
        th = sym.frames[lk.name][2]
        out.append((lk.name, m, J, _to_global(sym, lk.name, lx, ly), th, (lx, ly)))
    return out


def _gravity(sym):
    gx, gy = sym.mech.gravity
    return sym.val(gx), sym.val(gy)


def _applied(sym):
    """Applied loads as (body, kind, data): ("force", point, (fx, fy)) or ("torque", tau)."""
    mech, out = sym.mech, []
    for ld in mech.loads:
        if ld.kind == "force":
            out.append((bodies_at(mech, ld.at)[0], "force", ld.at,
                        (sym.val(ld.value[0]), sym.val(ld.value[1]))))
        elif ld.kind == "torque":
            out.append((ld.at, "torque", sym.val(ld.value)))
        else:  # spring: -k (d - d0) along P - Q on P, the opposite on Q
            (p, q), k, d0 = ld.points, sym.val(ld.stiffness), sym.val(ld.free_length)
            (px, py), (qx, qy) = sym.points[p], sym.points[q]
            d = ca.sqrt((px - qx) ** 2 + (py - qy) ** 2)
            f = -k * (d - d0) / d
            out.append((bodies_at(mech, p)[0], "force", p, (f * (px - qx), f * (py - qy))))
            out.append((bodies_at(mech, q)[0], "force", q, (-f * (px - qx), -f * (py - qy))))
    return out


# --- efforts, shaking ---


def expression(sym, name: str, t):
    m = _EFFORT.match(name)
    if m:
        if "efforts" not in t.cache:
            t.cache["efforts"] = _efforts(sym, t)
        return t.cache["efforts"][sym.ukeys.index(m["key"])]
    if name in _SHAKING:
        return _shaking(sym, t)[_SHAKING[name]]
    m = _CONTACT.match(name)
    if m:
        return _contact(sym, t, m["cam"])
    m = _REACTION.match(name)
    return _reaction(sym, t, m["a"], m["b"], m["attr"])


def _efforts(sym, t):
    """Q (one per input) by virtual work, with dr/du = r_z (T; I)."""
    Q = generalised(sym, t, ca.vertcat(-sym.lsolve(sym.Ju), ca.SX.eye(sym.nu)))
    return [Q[k] for k in range(sym.nu)]


def _contact(sym, t, cam):
    """The normal force of a cam on its (knife-edge or roller) follower, positive when it
    pushes: the generalised force of the virtual motion that parts them. The cam's rows of g
    read F - (P + rho N) = 0; relaxed to eps N (inputs held), the follower leaves the profile
    by eps along the outward normal N, dz = (g_q^-1 e, 0) with e = N on those rows, and the
    contact force f does the work f eps. So f is the effort that motion needs."""
    rows = _cam_rows(sym)[cam]
    nx, ny = sym.cams[cam]["normal"]
    e = ca.SX.zeros(sym.ng)
    e[rows[0]], e[rows[1]] = nx, ny
    return generalised(sym, t, ca.vertcat(sym.lsolve(e), ca.SX.zeros(sym.nu)))[0]


def _cam_rows(sym):
    """The two rows of g of each knife-edge or roller cam (they follow the slides' rows and
    the relative inputs', gears' and racks' equations, in declaration order)."""
    m = sym.mech
    n = sym.ng - sum(i.kind == "slide" for i in m.inputs) - 2 * len(m.cams)
    out = {}
    for c in m.cams:
        out[c.name] = (n, n + 1)
        n += 2
    return out


def generalised(sym, t, Z):
    """Q = the generalised forces (a row, one per column of Z) the motion needs along the
    virtual motions dz = Z dv of z = (q, u): by virtual work with d'Alembert's inertia forces,
    gravity, the loads and the springs; an input's effort is Q along dz = (T; I) du."""
    def du(e):  # d e / d v along the directions: a row of Z's columns
        return ca.mtimes(ca.jacobian(e, t.z), Z)

    gx, gy = _gravity(sym)
    Q = ca.SX.zeros(1, Z.size2())
    for _, m, J, (x, y), th, _ in _masses(sym):
        Q += m * (t.d(x, 2) - gx) * du(x) + m * (t.d(y, 2) - gy) * du(y) + J * t.d(th, 2) * du(th)
    for lk in sym.mech.loads:
        if lk.kind == "spring":  # potential k/2 (d - d0)^2: the input must supply its gradient
            (px, py), (qx, qy) = sym.points[lk.points[0]], sym.points[lk.points[1]]
            d = ca.sqrt((px - qx) ** 2 + (py - qy) ** 2)
            Q += sym.val(lk.stiffness) * (d - sym.val(lk.free_length)) * du(d)
        elif lk.kind == "torque":
            Q -= sym.val(lk.value) * du(sym.frames[lk.at][2])
        else:
            (x, y), (fx, fy) = sym.points[lk.at], (sym.val(lk.value[0]), sym.val(lk.value[1]))
            Q -= fx * du(x) + fy * du(y)
    return Q


def _shaking(sym, t):
    fx = fy = mz = ca.SX(0)
    for _, m, J, (x, y), th, _ in _masses(sym):
        ax, ay = t.d(x, 2), t.d(y, 2)
        fx, fy = fx - m * ax, fy - m * ay
        mz -= m * (x * ay - y * ax) + J * t.d(th, 2)
    return fx, fy, mz


# --- joint reactions: Newton-Euler per link ---


def _newton_euler(sym, t):
    """(problems, unknowns by name) of the kinetostatic system; with a Time t, also solved."""
    mech = sym.mech
    if sym.ng > sym.nq:
        return ["joint reactions are not determined where joints are redundant"], None
    kinds = {i.kind for i in mech.inputs} - {"angle", "slide", "parameter"}
    if kinds:
        return ["joint reactions are not available for this kind of input"], None
    if any(getattr(mech, k, ()) for k in ("gears", "racks", "cams")):
        return ["joint reactions are not available yet with gears, racks or cams "
                "(efforts and shaking forces are)"], None
    unknowns = {}  # (kind, names...) -> symbol(s)
    forces = []  # (body, point, (fx, fy)) and torques (body, None, tau)
    for p in list(mech.ground_points) + list(mech.moving_points):
        at = bodies_at(mech, p)
        if len(at) < 2:
            continue
        total = [ca.SX(0), ca.SX(0)]
        for b in at[1:]:
            f = ca.SX.sym(f"R_{p}_{b}", 2)
            unknowns[("pin", p, b)] = f
            forces.append((b, p, (f[0], f[1])))
            total = [total[0] + f[0], total[1] + f[1]]
        forces.append((at[0], p, (-total[0], -total[1])))
    for sl in mech.slides:
        a = sym.frames[sl.along][2] + sym.val(sl.angle)
        n, d = (-ca.sin(a), ca.cos(a)), (ca.cos(a), ca.sin(a))
        lam = unknowns[("slide", sl.name)] = ca.SX.sym(f"N_{sl.name}")
        F = ca.SX(0)
        if any(i.kind == "slide" and i.target == sl.name for i in mech.inputs):
            F = unknowns[("input", sl.name)] = ca.SX.sym(f"F_{sl.name}")
        fx, fy = lam * n[0] + F * d[0], lam * n[1] + F * d[1]
        forces += [(bodies_at(mech, sl.point)[0], sl.point, (fx, fy)),
                   (sl.along, sl.point, (-fx, -fy))]
    lever, motors = _Lever(sym), set()
    for i in mech.inputs:
        if i.kind == "angle":  # a motor on the ground, or on body B for a relative angle A/B
            # the unknown is the torque over the mechanism's size: a force, like the others
            motors.add(("input", i.target))
            T = unknowns[("input", i.target)] = ca.SX.sym(f"T_{i.target}")
            a, _, b = i.target.partition("/")
            forces.append((a, None, lever.size * T))
            if b and b != GROUND:
                forces.append((b, None, -lever.size * T))
    x = ca.vertcat(*unknowns.values()) if unknowns else ca.SX(0, 1)
    n_links = len(mech.links)
    if x.numel() != 3 * n_links:
        return [f"joint reactions: {x.numel()} unknown forces for {3 * n_links} equations "
                f"of motion (the kinetostatic system is not square)"], None
    if t is None:
        return [], None
    forces += [(b, *rest) for b, kind, *rest in _applied(sym) if kind == "force"]
    forces += [(b, None, data[0]) for b, kind, *data in _applied(sym) if kind == "torque"]
    gx, gy = _gravity(sym)
    eqs = {lk.name: [ca.SX(0), ca.SX(0), ca.SX(0)] for lk in mech.links}
    for name, m, J, (x_, y_), th, cg in _masses(sym):  # gravity minus d'Alembert's inertia force
        ax, ay = t.d(x_, 2), t.d(y_, 2)
        fx, fy = m * (gx - ax), m * (gy - ay)
        rx, ry = lever.local(name, *cg)
        e = eqs[name]
        e[0], e[1], e[2] = e[0] + fx, e[1] + fy, e[2] + rx * fy - ry * fx - J * t.d(th, 2)
    for body, point, f in forces:
        if body == GROUND:
            continue
        e = eqs[body]
        if point is None:  # a torque
            e[2] += f
        else:
            rx, ry = lever.arm(body, point)
            e[0], e[1], e[2] = e[0] + f[0], e[1] + f[1], e[2] + rx * f[1] - ry * f[0]
    # moment rows over the size: every entry of the matrix is a ratio of lengths
    E = ca.vertcat(*[c for lk in mech.links
                     for c in (eqs[lk.name][0], eqs[lk.name][1], eqs[lk.name][2] / lever.size)])
    A = ca.jacobian(E, x)
    sol = -ca.solve(A, ca.substitute(E, x, ca.SX.zeros(x.numel())))
    values = {k: ca.substitute(v, x, sol) * (lever.size if k in motors else 1)
              for k, v in unknowns.items()}
    return [], values


class _Lever:
    """Lever arms r - c about each link's mean point c, and the mechanism's size."""

    def __init__(self, sym):
        self.sym, self.mean, self.loc = sym, {}, {}
        total, n = ca.SX(0), 0
        for lk in sym.mech.links:
            self.mean[lk.name] = cx, cy = _mean_point(sym, lk)
            self.loc[lk.name] = loc = {p: (sym.val(x), sym.val(y)) for p, (x, y) in lk.points}
            for lx, ly in loc.values():
                total, n = total + (lx - cx) ** 2 + (ly - cy) ** 2, n + 1
        # the RMS distance of the points from their link's mean: 1 for a mechanism of points
        ms = total / max(n, 1)
        self.size = ca.sqrt(ca.if_else(ms > 0, ms, 1))

    def local(self, body, lx, ly):
        """r - c for the point (lx, ly) of the link's frame: R(theta) (l - l_c), whatever r is."""
        (cx, cy), th = self.mean[body], self.sym.frames[body][2]
        c, s = ca.cos(th), ca.sin(th)
        return c * (lx - cx) - s * (ly - cy), s * (lx - cx) + c * (ly - cy)

    def arm(self, body, point):
        """r - c for a named point: from the link's frame if the link carries it, else (a
        slide's point on the body carrying its line) the difference of the positions."""
        if point in self.loc[body]:
            return self.local(body, *self.loc[body][point])
        (x, y), (cx, cy) = self.sym.points[point], _to_global(self.sym, body, *self.mean[body])
        return x - cx, y - cy


def _reaction(sym, t, a, b, attr):
    if "reactions" not in t.cache:  # one solve serves every reaction of the report
        t.cache["reactions"] = _newton_euler(sym, t)[1]
    values = t.cache["reactions"]
    j = 0 if attr == "x" else 1
    if b is None:  # the slide's normal force, on the body carrying its point
        sl = sym.mech.slide(a)
        ang = sym.frames[sl.along][2] + sym.val(sl.angle)
        return values[("slide", a)] * (-ca.sin(ang) if j == 0 else ca.cos(ang))
    at = bodies_at(sym.mech, a)
    if b != at[0]:
        return values[("pin", a, b)][j]
    return -sum((values[("pin", a, o)][j] for o in at[1:]), ca.SX(0))
