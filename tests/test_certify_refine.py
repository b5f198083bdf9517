"""The certified search's in-box check (kincas/analysis/certify.py, `_refined`): the float
point refined by Newton lies in its exact box to its own error bound, which grows with the
conditioning (a fixed 1e-12 of the size refused good refinements of ill-conditioned roots:
Dietmaier's Stewart-Gough platform came within 8e-13 of it).

A four-bar stretched almost in line (rocker 2 + 1e-10, coupler 3, crank at pi: |BD| = 5): its
two assemblies are 3e-5 apart and g_q nearly singular. The exact roots are written here by
the circle intersection at 40 digits (mpmath). A point displaced from a root by 1e-10 of the
size along the near-null direction of g_q (what a float solve may return there: its forward
error is about the rounding over the smallest singular value, ~1e-9) is accepted; the other
root (Newton gone to the mirror assembly) and a point far off are refused."""
from __future__ import annotations

import math
import types

import numpy as np
import pytest

import kincas
import kincas.analysis.certify as certify
from kincas.analysis import certify_msolve
from kincas.core.numeric import model_of
from kincas.core.polynomial_planar import closure

mpmath = pytest.importorskip("mpmath")
needs_msolve = pytest.mark.skipif(not certify_msolve.available(),
                                  reason='msolve not installed (pip install "kincas[certify]")')
ROCKER = 2 + 1e-10


def stretched():
    return kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
        links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3),
               kincas.Link.bar("rocker", "D", "C", ROCKER)], inputs=[kincas.Input.angle("crank")])


def exact_roots():
    """(rocker angle, coupler angle) of both assemblies: B = (-1, 0), D = (4, 0),
    C = B + (x, +-sqrt(9 - x^2)), x = (9 - r^2 + 25) / 10."""
    mpmath.mp.dps = 40
    r = mpmath.mpf(ROCKER)
    x = (9 - r * r + 25) / 10
    out = []
    for s in (1, -1):
        cy = s * mpmath.sqrt(9 - x * x)
        cx = -1 + x
        out.append(np.array([float(mpmath.atan2(cy, cx - 4)), float(mpmath.atan2(cy, cx + 1))]))
    return out


@needs_msolve
def test_refined_point_in_its_box_to_its_error_bound():
    m = stretched()
    model, u, p, L = model_of(m), np.array([math.pi]), np.zeros(0), m.size()
    S = closure(m, u)
    assert S.rounded == []  # pi is a multiple of 90 deg: cos, sin exact
    kind, boxes, _ = certify._solve(S)
    assert kind == "finite" and len(boxes) == 2
    roots = exact_roots()
    for q in roots:  # the exact roots close the loop (the angle conventions are kincas's)
        assert np.abs(model.residual(q, u, p)).max() < 1e-13
    scale = np.where(S.length, L, 1.0)
    centres = [np.array([float((a + b) / 2) for a, b in box]) for box in boxes]
    gap = np.abs((centres[0] - centres[1]) / scale).max()
    assert 1e-6 < gap < 1e-4
    k = 0
    c, hw = centres[k], np.array([float((b - a) / 2) for a, b in boxes[k]])
    mine = min(roots, key=lambda q: np.abs(certify._variables_at(S, q) - c).max())
    other = max(roots, key=lambda q: np.abs(certify._variables_at(S, q) - c).max())
    null = np.linalg.svd(model.jac(mine, u, p) * model.column_scale(L))[2][-1]
    null = null * model.column_scale(L)  # back to the unknowns (radians)
    null /= np.abs(null).max()

    def refined(q):
        fake = types.SimpleNamespace(newton=lambda q0, u, p: types.SimpleNamespace(ok=True, q=q),
                                     jac=model.jac, residual=model.residual,
                                     column_scale=model.column_scale, nq=model.nq)
        return certify._refined(m, fake, S, c, hw, scale, u, p, L, gap)

    q, note = refined(mine + 1e-10 * null)  # within a float solve's reach of the root
    assert note == "" and np.abs(q - mine).max() < 2e-10
    assert np.abs((certify._variables_at(S, q) - c) / scale).max() > 1e-11  # beyond a fixed 1e-12
    for wrong in (other, mine + 1e-6 * null):  # the mirror root; a point far along the valley
        q, note = refined(wrong)
        assert "left its box" in note
