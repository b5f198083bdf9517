"""The careful path's watch for singular positions inside a step (kincas/analysis/continuation.py).

A step whose ends keep every group's mode may still pass a change point (two branches cross
there with the mode unchanged), so a group that is not well conditioned at either end of a
step is searched for a singular position inside it (`passes_singular`). The conditioning is
`modes`' (planar) or, for a group of a spatial model's quaternion or joint-angle unknowns
(the model's `watch_scaled`), its block with columns and rows scaled to unit length (`watch_conditioning`); a spatial group is searched only where the step
could reach a singular block at all (`within_reach`, Weyl's inequality).

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)], inputs=[kincas.Input.angle("crank")])
>>> model = kincas.model_of(m)
>>> sw = kincas.sweep(m, {"crank.angle": [0.5]}, report=[])
>>> J = model.jac(sw.q[0], np.array([0.5]), np.zeros(0))
>>> bool(abs(watch_conditioning(model, J, 4.0)[0] - modes(model, J, 4.0)[1][0]) < 1e-15)  # planar: modes'
True
"""
from __future__ import annotations

import numpy as np

from ..core.assembly import modes
from ..core.numeric import Model, Solution
from ..core.tolerances import TINY, WATCH, WATCH_REACH


def passes_singular(model: Model, q0, u0, u1, J0, sol: Solution, p, L, measured=None) -> bool:
    """Whether a group that is not well conditioned at either end of the step has a singular
    position inside it: then Newton may have landed on the other branch through a change
    point with its mode unchanged (branches cross there), and the step must be cut."""
    from .singular import locate_singular
    (_, c0), (_, c1) = measured() if measured is not None else ((None, None), (None, None))
    c = np.minimum(watch_conditioning(model, J0, L, c0), watch_conditioning(model, sol.J, L, c1))
    watch = np.flatnonzero(c < WATCH)
    if watch.size and _scaled(model).any():  # space: only a dip within reach
        watch = watch[[within_reach(model, J0, sol.J, L, int(i)) for i in watch]]
    watch = watch[np.argsort(c[watch], kind="stable")]  # the likeliest crossing first: any one decides
    scales = model.scales(u0, p) if watch.size else None  # one pose's: shared by every search
    for i in watch:
        # two extended Newton steps putting s outside (-0.5, 1.5): not in this step
        found = locate_singular(model, q0, u0, p, L, u1 - u0, group=int(i), window=(-0.5, 1.5), scales=scales)
        if found is not None and 0 < found[2] < 1:
            return True
    return False


def watch_conditioning(model: Model, J, L, cond=None) -> np.ndarray:
    """Each group's conditioning as `modes` gives it, except that a group of two or more
    unknowns among the model's `watch_scaled` (space: quaternions, joint angles) has its block's columns, then its rows, scaled to unit length first: a
    quaternion's norm equation (2 L e), a revolute's axis equations (a half-angle's 1/2) and
    a quaternion column against a position's (a lever over the size) carry factors of their
    own that held a regular group's sigma_min / sigma_max at 0.1-0.5 (an RSSR: every pose
    watched, a singular position searched at every step). The value is independent of the
    unknowns' units and of L (the columns are normalised); positive factors change no rank, so a singular group still measures 0; a planar group's value is unchanged.
    J is g_q at one pose (ng, nq) or at many (n, ng, nq); `cond`, if given, is `modes`'
    conditioning at J."""
    cond = np.array(modes(model, J, L)[1] if cond is None else cond, float)
    scaled = _scaled(model)
    if not scaled.any():
        return cond
    one = J.ndim == 2
    Jn, cn = (J[None] if one else J) * model.column_scale(L), cond[None] if one else cond
    for i, b in enumerate(model.blocks):
        if len(b.cols) < 2 or not scaled[b.cols].any():
            continue
        B = Jn[:, b.rows][:, :, b.cols]
        tiny = np.finfo(float).tiny
        B = B / np.maximum(np.linalg.norm(B, axis=1, keepdims=True), tiny)  # columns, then rows
        B = B / np.maximum(np.linalg.norm(B, axis=2, keepdims=True), tiny)
        s = np.linalg.svd(B, compute_uv=False)
        cn[:, i] = s[:, -1] / np.maximum(s[:, 0], np.finfo(float).tiny)
    return cn[0] if one else cn


def _scaled(model) -> np.ndarray:
    """Per unknown, whether its group's equations carry factors of their own, so that the
    watch scales the group's block (the model's `watch_scaled`: a spatial model's quaternion
    components and joint angles; none in a planar model)."""
    mask = getattr(model, "watch_scaled", None)
    return np.zeros(model.nq, bool) if mask is None else mask


def within_reach(model: Model, J0, J1, L, i: int) -> bool:
    """Whether group i's block could be singular somewhere inside a step whose ends have
    g_q = J0 and J1 (a spatial group's watch, beside its conditioning below WATCH).

    Both ends' blocks get one scaling (columns by `column_scale`, then columns and rows to
    unit length on average over the two ends), so that Weyl's inequality holds between them:
    sigma_min(B(s)) >= sigma_min(B0) - ||B(s) - B0||_2. The block is singular at some s only
    if ||B(s) - B0|| reaches sigma_min(B0) and ||B(s) - B1|| reaches sigma_min(B1). Along a
    step the block moves by about its chord ||B1 - B0|| (WATCH_REACH times it allows for
    the block turning along the step), so a group whose smallest singular value at both ends
    lies beyond that reach has no singular position inside, however poor its conditioning:
    an RSSR whose transmission angle stays near 20 degrees (sigma_min / sigma_max ~ 0.3 at
    every pose, tests/test_space_singular.py) is not searched at every step of a
    dense sweep, while a step ending next to a singular position (sigma_min ~ its distance)
    still is. Scale-free: positive column and row factors, one L."""
    b = model.blocks[i]
    cs = model.column_scale(L)[b.cols]
    B0, B1 = J0[np.ix_(b.rows, b.cols)] * cs, J1[np.ix_(b.rows, b.cols)] * cs
    c = np.maximum((np.linalg.norm(B0, axis=0) + np.linalg.norm(B1, axis=0)) / 2, TINY)
    B0, B1 = B0 / c, B1 / c
    r = np.maximum((np.linalg.norm(B0, axis=1) + np.linalg.norm(B1, axis=1)) / 2, TINY)[:, None]
    B0, B1 = B0 / r, B1 / r
    s0, s1 = (np.linalg.svd(B, compute_uv=False)[-1] for B in (B0, B1))
    return bool(max(s0, s1) <= WATCH_REACH * np.linalg.norm(B1 - B0, 2))
