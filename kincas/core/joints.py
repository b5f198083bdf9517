"""Residuals, quantities and placement of gears, racks, cams and relative angle inputs.

Called from `Symbolic._build` (`equations`), as one of Symbolic's quantity extensions
(`check`, `expression`), from `Model.initial_q` (`relative_start`, `place`) and the first
pose of a sweep (`first_pose_problems`). Every equation is written in lengths, so that Newton's residual,
relative to the mechanism's size, means the same for them as for loop closures:

- relative input "A/B": l_A (theta_A - theta_B - u) = 0, l_A a length of link A;
- gear pair: r2 (theta2 - theta_c) - sign r1 (theta1 - theta_c) - r2 phase = 0;
- rack: s - offset + sigma radius (theta_pinion - theta_rack) = 0;
- cam, with phi the profile parameter of the contact (one more unknown) and P(phi), T(phi)
  = dP/dphi, N(phi) the profile's point, tangent and outward unit normal in the cam body's
  frame, mapped to the world by that frame: knife edge F - P = 0; roller C - (P + rho N) = 0;
  flat face (link x axis d through o): d x (P - o) = 0 and d x T = 0.

Angles stay continuous (unknowns are followed by continuation). At the first pose an angle
whose turn is free starts in (-pi, pi]; one that a gear, rack or relative input ties to the
inputs takes the turn its relation gives (kincas/core/turns.py).

>>> import kincas
>>> from kincas.model.joints import Gear
>>> m = kincas.Mechanism(ground={"A": (0, 0), "B": (45, 0)},
...     links=[kincas.Link.bar("g1", "A", "P", 30), kincas.Link.bar("g2", "B", "Q", 15)],
...     gears=[Gear(("g1", "g2"), (30, 15))], inputs=[kincas.Input.angle("g1")])
>>> r = kincas.solve(m, {"g1.angle": 0.5}, report=["g2.angle", "g2/g1.omega"])
>>> round(r["g2.angle"], 12), round(r["g2/g1.omega"], 12)
(-1.0, -3.0)
"""
from __future__ import annotations

import math

import casadi as ca
import numpy as np

from ..errors import ModelError
from ..model import spline
from ..model.joints import Circle, split_relative
from ..model.mechanism import GROUND, as_param
from .turns import turns
from ..model.names import ANGULAR_ATTRS  # noqa: F401  (cam quantities: angles, kept here too)
from .tolerances import MESH, NULL_REL

_PRESSURE_FLOOR = NULL_REL  # a follower slower than this times the inputs' speed scale stands


# --- equations ---


def _rot(th, v):
    c, s = ca.cos(th), ca.sin(th)
    return (c * v[0] - s * v[1], s * v[0] + c * v[1])


def _link_length(sym, name):
    """A length of the link (its two first points' distance), to scale an angle equation."""
    (_, a), (_, b) = sym.mech.link(name).points[:2]
    dx, dy = sym.val(b[0]) - sym.val(a[0]), sym.val(b[1]) - sym.val(a[1])
    return ca.sqrt(dx * dx + dy * dy)


def equations(sym, new) -> list:
    """The equations of relative inputs, gears, racks and cams; cams add their unknown by
    `new(name, kind)`. Fills `sym.cams` (name -> contact data) for quantities."""
    m, eqs = sym.mech, []
    theta = {b: f[2] for b, f in sym.frames.items()}
    for k, inp in enumerate(m.inputs):
        rel = split_relative(inp.target) if inp.kind == "angle" else None
        if rel is not None:
            a, b = rel
            eqs.append(_link_length(sym, a) * (theta[a] - theta[b] - sym.u[k]))
    for g in m.gears:
        (t1, t2), tc = (theta[b] for b in g.links), theta[g.carrier]
        r1, r2 = (sym.val(r) for r in g.radii)
        eqs.append(r2 * (t2 - tc) - g.sign * r1 * (t1 - tc) - r2 * sym.val(g.phase))
    for r in m.racks:
        along = m.slide(r.slide).along
        eqs.append(sym.slide_s[r.slide] - sym.val(r.offset)
                   + r.sigma * sym.val(r.radius) * (theta[r.pinion] - theta[along]))
    sym.cams = {}
    for c in m.cams:
        phi = new(f"{c.name}.phi", "angle")
        P, T = _profile(sym, c.profile, phi)
        ox, oy, th = sym.frames[c.body]
        Pw = tuple(o + d for o, d in zip((ox, oy), _rot(th, P)))
        Tw = _rot(th, T)
        nt = ca.sqrt(Tw[0] ** 2 + Tw[1] ** 2)
        Nw = (Tw[1] / nt, -Tw[0] / nt)  # the profile runs counter-clockwise: outward is right
        kind, who = c.follower
        point = None
        if kind == "knife":
            point = sym.points[who]
            eqs += [point[0] - Pw[0], point[1] - Pw[1]]
        elif kind == "roller":
            point, rho = sym.points[who], sym.val(c.roller_radius)
            eqs += [point[0] - Pw[0] - rho * Nw[0], point[1] - Pw[1] - rho * Nw[1]]
        else:
            fx, fy, fth = sym.frames[who]
            dx, dy = ca.cos(fth), ca.sin(fth)
            eqs += [dx * (Pw[1] - fy) - dy * (Pw[0] - fx), dx * Tw[1] - dy * Tw[0]]
        sym.cams[c.name] = {"phi": phi, "contact": Pw, "normal": Nw, "point": point}
    return eqs


def _profile(sym, prof, phi):
    """(P, T): the profile point and its tangent dP/dphi in the body's frame."""
    c, s = ca.cos(phi), ca.sin(phi)
    if isinstance(prof, Circle):
        R = sym.val(prof.radius)
        cx, cy = (sym.val(v) for v in prof.center)
        return (cx + R * c, cy + R * s), (-R * s, R * c)
    r, dr = polar_radius(sym, prof, phi)
    return (r * c, r * s), (dr * c - r * s, dr * s + r * c)


def polar_radius(sym, prof, phi):
    """r(phi) and r'(phi) of the periodic cubic spline through the profile's points: the
    coefficients are linear maps of the (possibly symbolic) radii; the interval is picked by
    piecewise constants, whose derivative is zero, so the derivatives are exact."""
    a = np.asarray(prof.angles, float)
    # numbers stay numbers: only the radii given as parameters enter symbolically, through
    # the columns of the coefficient maps that multiply them (sizes O(n) per parameter)
    plain = np.array([0.0 if as_param(v) else float(v) for v in prof.radii])
    named = [k for k, v in enumerate(prof.radii) if as_param(v)]
    coef = [ca.DM(c) for c in spline.coefficients(a, plain)]
    if named:
        unit = np.zeros((len(a), len(named)))
        unit[named, range(len(named))] = 1.0
        maps = spline.coefficients(a, unit)
        radii = ca.vertcat(*[sym.val(prof.radii[k]) for k in named])
        coef = [c + ca.mtimes(ca.DM(Mx), radii) for c, Mx in zip(coef, maps)]
    A, B, C, D = coef
    t = phi - a[0]
    t = t - spline.TURN * ca.floor(t / spline.TURN)  # in [0, 2 pi) from the first angle
    knots = a - a[0]
    brk = ca.DM(knots[1:])
    pick = lambda v: ca.pw_const(t, brk, v)  # noqa: E731
    dt = t - pick(ca.DM(knots))
    a0, b0, c0, d0 = pick(A), pick(B), pick(C), pick(D)
    return a0 + dt * (b0 + dt * (c0 + dt * d0)), b0 + dt * (2 * c0 + 3 * dt * d0)


# --- quantities (an extension module of Symbolic: `check` and `expression`) ---

_REL_Q = {"angle": 0, "omega": 1, "alpha": 2, "jerk": 3}
_CONTACT_Q = {"x": (0, 0), "y": (1, 0), "vx": (0, 1), "vy": (1, 1), "ax": (0, 2), "ay": (1, 2),
              "jx": (0, 3), "jy": (1, 3)}


def _parse(sym, name: str):
    """("relative", (A, B), order) | ("contact", cam, (component, order)) | ("phi" or
    "pressure", cam, None), or None when the name is not a joint quantity."""
    obj, _, attr = name.rpartition(".")
    rel = split_relative(obj)
    if rel is not None and attr in _REL_Q:
        return "relative", rel, _REL_Q[attr]
    cams = getattr(sym, "cams", {})
    head, _, tail = obj.partition(".")
    if tail == "contact" and head in cams and attr in _CONTACT_Q:
        return "contact", head, _CONTACT_Q[attr]
    if obj in cams and attr in ("phi", "pressure"):
        return attr, obj, None
    return None


def check(sym, name: str):
    """None when `name` is not a joint quantity; else its problems ([] if fine)."""
    what = _parse(sym, name)
    if what is None:
        return None
    if what[0] == "relative":
        bodies = set(sym.angles) | {GROUND}
        return [f"unknown body {b!r} (a link's name or \"ground\")" for b in what[1] if b not in bodies]
    return []


def expression(sym, name: str, t):
    """A relative angle and its rates, a cam's contact point, contact angle (wrapped to
    (-pi, pi]) or pressure angle."""
    kind, obj, order = _parse(sym, name)
    if kind == "relative":
        a, b = obj
        return t.d(sym.frames[a][2] - sym.frames[b][2], order)
    data = sym.cams[obj]
    if kind == "contact":
        return t.d(data["contact"][order[0]], order[1])
    if kind == "phi":
        return ca.atan2(ca.sin(data["phi"]), ca.cos(data["phi"]))
    return pressure(data, t)


def pressure(data, t):
    """The acute angle between the common normal and the follower point's absolute velocity,
    atan2(|n x v|, |n . v|) in [0, pi/2]; NaN for a flat face and where the point stands
    (|v| <= 1e-9 of the inputs' speed scale, as for kincas/core/geometry.py's nulls)."""
    if data["point"] is None:
        return ca.SX(np.nan)
    n = data["normal"]
    v = [t.d(c) for c in data["point"]]
    speed = ca.sqrt(v[0] ** 2 + v[1] ** 2)
    ang = ca.atan2(ca.fabs(n[0] * v[1] - n[1] * v[0]), ca.fabs(n[0] * v[0] + n[1] * v[1]))
    return ca.if_else(speed <= _PRESSURE_FLOOR * t.speed_scale, np.nan, ang)


# --- placement of the first pose ---


def relative_start(m, lname: str, u, theta: dict, th: float) -> float:
    """A link driven relative to a body placed before it starts at theta_B + u."""
    for k, inp in enumerate(m.inputs):
        rel = split_relative(inp.target) if inp.kind == "angle" else None
        if rel and rel[0] == lname and rel[1] in theta:
            return float(theta[rel[1]] + u[k])
    return th


def _cam_function(model):
    """(q, u, p) -> per cam: body frame (x, y, angle), the follower's frame or point, and
    the profile's numbers (circle: centre, radius; polar: radii)."""
    if getattr(model, "_cam_f", None) is None:
        sym, out = model.sym, []
        for c in sym.mech.cams:
            kind, who = c.follower
            f = sym.frames[who] if kind == "flat" else (*sym.points[who], ca.SX(0))
            extra = ([sym.val(v) for v in c.profile.center] + [sym.val(c.profile.radius)]
                     if isinstance(c.profile, Circle) else [sym.val(v) for v in c.profile.radii])
            rho = sym.val(c.roller_radius) if kind == "roller" else ca.SX(0)
            out += [*sym.frames[c.body], *f, rho, *extra]
        model._cam_f = ca.Function("cams", [sym.q, sym.u, sym.p], [ca.vertcat(*out) if out else ca.SX(0, 1)])
    return model._cam_f


def _profile_samples(c, data, n=1440):
    """Profile points, unit outward normals and parameters in the body's frame."""
    if isinstance(c.profile, Circle):
        phi = np.linspace(-math.pi, math.pi, n, endpoint=False)
        cx, cy, R = data[:3]
        N = np.stack([np.cos(phi), np.sin(phi)], axis=1)
        return np.array([cx, cy]) + R * N, N, phi
    a = c.profile.angles
    phi = np.linspace(a[0], a[0] + spline.TURN, n, endpoint=False)
    r, dr = spline.evaluate(a, data, phi, order=1)
    e, f = np.stack([np.cos(phi), np.sin(phi)], axis=1), np.stack([-np.sin(phi), np.cos(phi)], axis=1)
    T = dr[:, None] * e + r[:, None] * f
    N = np.stack([T[:, 1], -T[:, 0]], axis=1) / np.hypot(T[:, 0], T[:, 1])[:, None]
    return r[:, None] * e, N, phi


def place(model, q, u, p):
    """Start each cam's contact parameter at the profile point nearest its follower (knife,
    roller's centre less its radius), or for a flat face at the profile point farthest
    towards the face; then every angle whose turn is free in (-pi, pi], and the angles that
    gears, racks and relative inputs tie to others at the turns their relations give them
    (kincas/core/turns.py)."""
    sym = model.sym
    if sym.mech.cams:
        raw = np.asarray(_cam_function(model)(q, u, p)).ravel()
        index = {name: i for i, (name, _) in enumerate(sym.unknowns)}
        k = 0
        for c in sym.mech.cams:
            n_data = 3 if isinstance(c.profile, Circle) else len(c.profile.radii)
            ox, oy, th, fx, fy, fth, rho = raw[k:k + 7]
            data = raw[k + 7:k + 7 + n_data]
            k += 7 + n_data
            R = np.array([[math.cos(th), math.sin(th)], [-math.sin(th), math.cos(th)]])  # world -> body
            P, N, phi = _profile_samples(c, data)
            f_loc = R @ (np.array([fx, fy]) - [ox, oy])
            if c.follower[0] == "flat":
                d = R @ np.array([math.cos(fth), math.sin(fth)])
                nrm = np.array([-d[1], d[0]])
                if nrm @ (f_loc - P.mean(axis=0)) < 0:
                    nrm = -nrm  # from the cam towards the face
                best = int(np.argmax(P @ nrm))
            else:
                best = int(np.argmin(np.hypot(*(P + rho * N - f_loc).T)))
            q[index[f"{c.name}.phi"]] = phi[best]
    return turns(model, q, u, p)  # free angles in (-pi, pi], tied ones where their relations say


# --- checks at the first solved pose ---


def first_pose_problems(model, q, u, p, L) -> list[str]:
    """Gear pairs whose centres are not r1 + r2 (external) or |r2 - r1| (internal) apart, to
    1e-9 of the mechanism's size, at the first solved pose (belts are not checked)."""
    m = model.sym.mech
    gears = [g for g in m.gears if not g.belt]
    if not gears:
        return []
    if getattr(model, "_gear_f", None) is None:
        sym, out = model.sym, []
        for g in gears:
            for b in g.links:
                out += [sym.frames[b][0], sym.frames[b][1]]
            out += [sym.val(r) for r in g.radii]
        model._gear_f = ca.Function("gears", [sym.q, sym.u, sym.p], [ca.vertcat(*out)])
    raw = np.asarray(model._gear_f(q, u, p)).ravel().reshape(-1, 6)
    problems = []
    for i, (g, (x1, y1, x2, y2, r1, r2)) in enumerate(zip(gears, raw)):
        d = math.hypot(x2 - x1, y2 - y1)
        need = abs(r2 - r1) if g.internal else r1 + r2
        if abs(d - need) > MESH * L:
            k = m.gears.index(g)
            what = "|r2 - r1|" if g.internal else "r1 + r2"
            problems.append(f"[[gears]] {g.name or k + 1}: radii: the centres are {d:.10g} apart at the "
                            f"first pose, but an {g.kind} mesh needs {what} = {need:.10g} "
                            f"(gears[{k}].radii)")
    return problems


def check_first_pose(model, q, u, p, L):
    problems = first_pose_problems(model, q, u, p, L)
    if problems:
        raise ModelError(problems)
