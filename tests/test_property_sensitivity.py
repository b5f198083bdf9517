"""Property test on random mechanisms (tests/random_mechanisms.py): exact sensitivities
d(Q)/d(p) against Richardson-extrapolated central differences of poses solved again with the
parameter moved by +-h and +-2h (kincas's derivatives are not used for the reference).

Every number of a generated mechanism is a parameter (ground and local coordinates, lengths,
slide lines, masses, inertias, centres of gravity, gravity, loads); each mechanism checks a
few drawn at random, on positions, velocities, accelerations, angles and efforts.
"""
from __future__ import annotations

import numpy as np
import pytest

import kincas
import random_mechanisms as rm

N = rm.count(6)


def step_and_scale(c, p):
    """The parameter's natural size: lengths and coordinates the mechanism's size, a slide's
    angle one radian, anything else (mass, inertia, force, gravity, stiffness) its magnitude."""
    if p.endswith("_ang"):
        return 1.0
    if p.startswith(("gx_", "gy_", "len_", "cgx_", "cgy_", "l0_")) or p.endswith(("_x", "_y", "_tx", "_ty")) \
            and not p.startswith(("F_", "grav_")):
        return c.size
    if p.startswith("grav_"):
        return float(np.hypot(*[c.mech.value(v) for v in c.mech.gravity]))
    if p.startswith("F_"):
        return float(np.hypot(c.mech.parameter("F_x"), c.mech.parameter("F_y")))
    return abs(c.mech.parameter(p))


def sensitivity_errors(c) -> list[str]:
    rng = np.random.default_rng(c.seed)
    driven = set(c.keys)
    params = [p for p, _ in c.mech.parameters if p not in driven]
    if c.mech.gears:  # a gear's radius, pivot or centre moved alone breaks the mesh's centre distance
        gear_links = tuple(f"{lk}_" for g in c.mech.gears for lk in g.links)
        params = [p for p in params if not p.startswith(("r_", "gx_", "gy_") + gear_links)]
    chosen = list(rng.choice(params, size=min(3, len(params)), replace=False))
    # one report per family (one set of quantity functions built): the last moving point and
    # link, d/d(every parameter); differences check a few parameters drawn per mechanism
    pt, lk = c.moving[-1], c.mech.links[-1].name
    of = [f"{pt}.x", f"{pt}.vy", f"{pt}.ax", f"{lk}.angle", f"{lk}.omega", f"effort({c.keys[0]})"]
    poses = [0, c.n - 1]
    U = {k: c.inputs[k][poses] for k in c.keys}
    kw = dict(rates=c.rates, accelerations=c.accelerations)
    # (the careful path: the fast pass would generate a kernel for this long report first)
    exact = kincas.sweep(c.mech, U, report=of + [f"d({q})/d({p})" for q in of for p in params],
                         method="careful", **kw)
    if not exact.ok.all():
        return [f"poses not solved: {exact.status.tolist()}"]
    # the nominal pose's positions keep every re-solved mechanism on the same branch
    guess = {p: tuple(c.ref[p][0]) for p in c.ref}
    bad = []
    for p in chosen:
        size = step_and_scale(c, p)
        h = 1e-4 * size if size > 0 else 1e-4
        v0 = c.mech.parameter(p)
        runs = {}
        for k in (-2, -1, 1, 2):
            sw = kincas.sweep(c.mech.with_parameters(**{p: v0 + k * h}), U, report=of, guess=guess, **kw)
            if not sw.ok.all():
                return [f"re-solve with {p} moved by {k} h not solved"]
            runs[k] = sw
        for q in of:
            f = {k: runs[k][q] for k in runs}
            if q.endswith(".angle"):
                f = {k: exact[q] + np.angle(np.exp(1j * (v - exact[q]))) for k, v in f.items()}
            fd = (8 * (f[1] - f[-1]) - (f[2] - f[-2])) / (12 * h)  # O(h^4)
            got = exact[f"d({q})/d({p})"]
            # relative to the derivative's natural size: the quantity's largest magnitude here
            # over the parameter's size (the truncation, (1e-4)^4, and rounding, eps (1 +
            # offset) / 1e-4, are both far below the 1e-6 allowed)
            scale = max(np.abs(exact[q]).max(), np.abs(got).max() * size, 1e-300) / size
            err = np.abs(got - fd).max()
            tol = (1e-6 + 1e-11 * (1 + c.offset)) * scale
            if not err <= tol:
                bad.append(f"d({q})/d({p}) = {got.tolist()}, differences give {fd.tolist()} "
                           f"(error {err / scale:.2e} of its scale)")
    return bad


@pytest.mark.parametrize("family", rm.FAMILIES)
def test_sensitivities_by_richardson(family):
    failures = rm.check_family(family, N, sensitivity_errors)
    assert not failures, failures
