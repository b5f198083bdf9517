"""Property tests on random mechanisms (tests/random_mechanisms.py): positions and their time
derivatives, checked against computations written here.

- Residuals: every link's points recomputed from the reported positions and the link's
  reported angle (its own frame put back where kincas says it is), every ground pivot, every
  slide's line and coordinate, every input; and the positions against the generator's own
  Newton solution (its loop equations, not kincas's).
- Time derivatives: velocities, accelerations and jerks against Richardson-extrapolated
  central differences of the reported positions along the inputs' path.

KINCAS_PROPERTY_N sets the number of mechanisms per family (CI: a dozen); a failure names the
family and the seed, and `random_mechanisms.case(family, seed)` rebuilds the mechanism.
"""
from __future__ import annotations


import numpy as np
import pytest

import random_mechanisms as rm

N = rm.count(6)
EPS = np.finfo(float).eps


def rotate(th, v):
    c, s = np.cos(th), np.sin(th)
    return np.stack([c * v[0] - s * v[1], s * v[0] + c * v[1]])


def xy(sw, p, c):
    """Point p's reported positions (N, 2); a ground point's declared place."""
    if p in c.mech.ground_points:
        g = dict(c.mech.ground)[p]
        return np.tile([c.mech.value(g[0]), c.mech.value(g[1])], (len(sw), 1))
    return np.stack([sw[f"{p}.x"], sw[f"{p}.y"]], axis=1)


def position_residuals(c, sw) -> list[str]:
    """Every loop condition recomputed from the reported positions; each residual against a
    tolerance of 1e-12 of the size plus the rounding of coordinates as far from the origin as
    these are (8 ulps of the largest coordinate)."""
    bad = []
    far = max(np.abs(sw[f"{p}.{k}"]).max() for p in c.moving for k in "xy")
    tol = 1e-12 * c.size + 8 * EPS * far
    m = c.mech
    for lk in m.links:
        th = sw[f"{lk.name}.angle"]
        first = lk.point_names[0]
        o = xy(sw, first, c).T - rotate(th, c.local_at(lk.name, first))  # the frame's origin
        for p in lk.point_names[1:]:
            err = np.abs(xy(sw, p, c).T - (o + rotate(th, c.local_at(lk.name, p)))).max()
            if not err <= tol:
                bad.append(f"link {lk.name}: point {p} is {err / c.size:.2e} sizes off its body")
    for s in m.slides:
        point = xy(sw, s.point, c).T
        if s.along == "ground":
            T = np.array([m.value(s.through[0]), m.value(s.through[1])])[:, None]
            a = m.value(s.angle) + 0 * sw[f"{s.name}.s"]
        else:
            lk = m.link(s.along)
            th = sw[f"{s.along}.angle"]
            first = lk.point_names[0]
            o = xy(sw, first, c).T - rotate(th, c.local(s.along, first))
            T = o + rotate(th, np.array([m.value(s.through[0]), m.value(s.through[1])]))
            a = th + m.value(s.angle)
        w = point - T
        off = np.abs(np.cos(a) * w[1] - np.sin(a) * w[0]).max()
        ds = np.abs(np.cos(a) * w[0] + np.sin(a) * w[1] - sw[f"{s.name}.s"]).max()
        if not (off <= tol and ds <= tol):
            bad.append(f"slide {s.name}: off its line by {off / c.size:.2e} sizes, s wrong by {ds / c.size:.2e}")
    for inp in m.inputs:
        u = c.inputs[inp.key]
        if inp.kind == "angle":
            err = np.abs(np.angle(np.exp(1j * (sw[f"{inp.target}.angle"] - u)))).max()
            ok = err <= 1e-13
        elif inp.kind == "slide":
            err = np.abs(sw[f"{inp.target}.s"] - u).max() / c.size
            ok = err * c.size <= tol
        else:  # an actuator's length
            lk = next(lk for lk in m.links if lk.two_point and lk.points[1][1][0] == inp.target)
            a, b = (xy(sw, p, c) for p in lk.point_names)
            err = np.abs(np.hypot(*(b - a).T) - u).max() / c.size
            ok = err * c.size <= tol
        if not ok:
            bad.append(f"input {inp.key} not where it was driven ({err:.2e})")
    for g in m.gears:  # external mesh: theta2 = -k theta1 + phase, angles continuous from the
        # first pose, where each is in (-pi, pi]
        a1, a2 = (sw[f"{lk}.angle"] for lk in g.links)
        k = m.value(g.radii[0]) / m.value(g.radii[1])
        cont = lambda a: a[0] + np.unwrap(a - a[0])
        err = np.abs(cont(a2) + k * cont(a1) - m.value(g.phase)).max()
        if not err <= 1e-12 * (1 + k):
            bad.append(f"gear {g.name}: theta2 + k theta1 is {err:.2e} off its phase")
    for p, ref in c.ref.items():  # the generator's own solution (conditioned: >= COND_MIN)
        err = np.abs(xy(sw, p, c) - ref).max()
        if not err <= 1e-9 * c.size + 8 * EPS * far:
            bad.append(f"point {p}: {err / c.size:.2e} sizes from the reference solution")
    return bad


def flagged_or_off(c, sw) -> list[str]:
    bad = [f"flagged {sw.flags} where the generator keeps clear of singular positions"] if any(sw.flags) else []
    return bad + position_residuals(c, sw)


@pytest.mark.parametrize("family", rm.FAMILIES)
def test_residuals_and_reference_positions(family):
    failures = rm.check_family(family, N, lambda c: rm.solved_checked(c, "motion", flagged_or_off))
    assert not failures, failures


# --- time derivatives by Richardson extrapolation ---

STEPS = np.array([-4, -2, -1, 0, 1, 2, 4])


def richardson(f, h):
    """First, second and third derivatives at 0 of samples f at STEPS * h (axis 0), each the
    Richardson extrapolation of two central differences (steps h and 2h, or 2h and 4h for the
    third): truncation error O(h^4)."""
    F = dict(zip(STEPS.tolist(), f))
    d1 = lambda s: (F[s] - F[-s]) / (2 * s * h)
    d2 = lambda s: (F[s] - 2 * F[0] + F[-s]) / (s * h) ** 2
    d3 = lambda s: (F[2 * s] - 2 * F[s] + 2 * F[-s] - F[-2 * s]) / (2 * (s * h) ** 3)
    return ((4 * d1(1) - d1(2)) / 3, (4 * d2(1) - d2(2)) / 3, (4 * d3(1) - d3(2)) / 3)


# The stencil moves the inputs by H rad (or H sizes) a step. Velocities and accelerations are
# checked against derivatives of the positions; jerks against the derivative of the reported
# accelerations (once those are checked against positions: the third derivative of positions
# would lose too many digits to rounding far from the origin). Each tolerance, relative to the
# order's natural scale (random_mechanisms.natural_scales) or the quantity's largest value, is the truncation error's bound
# TRUNC (O(H^4) with the generator's conditioning) plus rounding: positions are exact to a few
# ulps of their own magnitude, eps (1 + offset) sizes, and the Richardson weights of a k-th
# derivative add up to about ROUND[k] / H^k.
H = 1e-3
TRUNC = (3e-7, 3e-6, 2e-5)  # the worst seen over 40 mechanisms a family: 7e-8 in velocity
ROUND = (20.0, 60.0, 20.0)


def derivative_errors(c) -> list[str]:
    w = max(abs(c.rates[k]) / u for k, u in zip(c.keys, c.units))
    h = H / w  # time step: the inputs move by H rad (or H sizes) per step
    base = [0, c.n - 1]
    U = {k: np.concatenate([c.inputs[k][b] + STEPS * h * c.rates[k] for b in base]) for k in c.keys}
    sw = rm.kincas.sweep(c.mech, U, rates=c.rates, accelerations=c.accelerations,
                         report=c.report_motion(), guess=dict(c.mech.guess))
    got = rm.solved(c)
    if not sw.ok.all():
        return [f"stencil poses not solved: {sw.status.tolist()}"]
    sc = rm.natural_scales(c)
    far = EPS * (1 + c.offset)
    bad = []
    ca, cj = c.c_acc, c.c_jerk
    quantities = [(f"{p}.{x}", (f"{p}.v{x}", f"{p}.a{x}", f"{p}.j{x}"), "length")
                  for p in c.moving for x in "xy"]
    quantities += [(f"{lk.name}.angle", (f"{lk.name}.omega", f"{lk.name}.alpha", f"{lk.name}.jerk"), "angle")
                   for lk in c.mech.links]
    quantities += [(f"{s.name}.s", (f"{s.name}.v", f"{s.name}.a", None), "length") for s in c.mech.slides]
    for i, b in enumerate(base):
        sl = slice(7 * i, 7 * i + 7)
        for q, (qv, qa, qj), kind in quantities:
            f = sw[q][sl]
            if kind == "angle":
                f = f[3] + np.angle(np.exp(1j * (f - f[3])))
            # along the stencil u = u_b + t w (w the rates): f' = v; with the inputs'
            # accelerations ca w and jerks cj w: a = f2 + ca f', j = f3 + 3 ca f2 + cj f'
            # (fk the k-th derivative), and the reported a along it has derivative f3 + ca f2
            d1, d2, _ = richardson(f, h)
            want = [d1, d2 + ca * d1, None]
            if qj is not None:
                da = richardson(sw[qa][sl], h)[0]
                want[2] = da + 2 * ca * (got[qa][b] - ca * got[qv][b]) + cj * got[qv][b]
            for order, (name, v) in enumerate(zip((qv, qa, qj), want)):
                if name is None:
                    continue
                unit = max(sc[kind][order + 1], np.abs(got[name]).max())
                tol = unit * (TRUNC[order] + ROUND[order] * far * (H ** -(order + 1) if order < 2 else 1 / H))
                err = abs(got[name][b] - v)
                if not err <= tol:
                    bad.append(f"pose {b}: {name} = {got[name][b]:.10g}, differences give {v:.10g} "
                               f"(error {err / unit:.2e} of its scale, tolerance {tol / unit:.1e})")
    return bad


@pytest.mark.parametrize("family", rm.FAMILIES)
def test_velocities_accelerations_jerks_by_richardson(family):
    failures = rm.check_family(family, N, derivative_errors)
    assert not failures, failures
