"""g_q's block-triangular form, and the solves and measures the fast kernel takes from it.

Permuted to its block-triangular form (Dulmage-Mendelsohn, `casadi.Sparsity.btf`), g_q has
irreducible square blocks on its diagonal, one per Assur group (2 x 2 for a dyad, 4 x 4 for a
triad), and zeros on one side of them. So:

- g_q x = b is solved block by block, each group's unknowns from its own equations once the
  groups it hangs on are known: x_B = A_BB^-1 (b_B - sum_C A_BC x_C). Its cost, and the size
  of the generated code, grow with the number of groups instead of with nq^3;
- det g_q = (permutation sign) * prod det A_BB: its sign, which tells assembly branches
  apart, is known per group, and g_q is singular exactly where one of its diagonal blocks is.
  With columns scaled to O(1) (positive factors: the signs do not change), each block gets a
  lower bound of its smallest singular value: exact for blocks of 1 and 2 unknowns
  (sigma_min = 2|d| / (sqrt(F + 2|d|) + sqrt(F - 2|d|)), F = ||A||_F^2), |d| / F^((n-1)/2)
  beyond (the largest singular value is at most sqrt(F)).

The blocks are `Model.blocks` (kincas/core/structure.py), each with `.rows` and `.cols`.

>>> import numpy as np, casadi as ca
>>> from kincas.core.structure import Block
>>> A = ca.DM([[2.0, 1.0], [0.0, 3.0]])
>>> signs, rel = block_measures(A, np.ones(2), [Block(np.arange(2), np.arange(2), ())])
>>> round(float(rel * np.sqrt(14)), 12), round(float(np.linalg.svd(A.full(), compute_uv=False)[-1]), 12)
(1.84240297561, 1.84240297561)
"""
from __future__ import annotations

import functools

import casadi as ca
import numpy as np

# casadi's linear solver for a tall group's normal equations in an MX kernel: sparse LDL'
# (A'A is symmetric positive definite where the rank rules hold; code-generated as a loop)
TALL_LINSOL = "ldl"


# --- symbolic solves and measures over the blocks ---


def _cholesky(M):
    """Lower-triangular L (rows of entries) with L L' = M for a symmetric positive definite
    M (no pivoting: stable for a Gram matrix), written out entry by entry, n^3/6 operations
    (fewer where M is sparse: an entry known zero drops out of the expression)."""
    n = M.size1()
    Lm = _cholesky_function(n)(ca.SX(M))  # evaluated in casadi: no Python call per operation
    return [[Lm[i, j] for j in range(n)] for i in range(n)]


@functools.lru_cache(maxsize=None)
def _cholesky_function(n: int) -> ca.Function:
    M = ca.SX.sym("M", n, n)
    L = [[ca.SX(0)] * n for _ in range(n)]
    for j in range(n):
        d = M[j, j] - sum((L[j][k] ** 2 for k in range(j)), ca.SX(0))
        L[j][j] = ca.sqrt(d)
        for i in range(j + 1, n):
            L[i][j] = (M[i, j] - sum((L[i][k] * L[j][k] for k in range(j)), ca.SX(0))) / L[j][j]
    return ca.Function("cholesky", [M], [ca.vertcat(*[ca.horzcat(*row) for row in L])])


def _tri_solve(L, b, lower: bool):
    """L x = b (lower) or L' x = b (not lower) for the rows of `_cholesky`."""
    n, x = len(L), [None] * len(L)
    order = range(n) if lower else range(n - 1, -1, -1)
    for i in order:
        others = range(i) if lower else range(i + 1, n)
        acc = b[i, :]
        for k in others:
            acc = acc - (L[i][k] if lower else L[k][i]) * x[k]
        x[i] = acc / L[i][i]
    return ca.vertcat(*x)


def _tall_solve(A, b):
    """The least-squares solution of A x = b for a tall A of full column rank (redundant
    joints: a consistent system, so it is the exact solution at a root): the normal
    equations A'A x = A'b by Cholesky (Gauss-Newton's step; the rank rules of
    kincas/core/redundant.py, not this solve, decide that A has full column rank).
    In MX (the fast kernel of a tall structure, kincas/core/kernel.py) the same normal
    equations go to a numeric sparse solver (`TALL_LINSOL`): a loop in the generated C,
    where the Cholesky written out would be an expression of ~n^3 instructions."""
    if isinstance(A, ca.MX):
        return ca.solve(ca.mtimes(A.T, A), ca.mtimes(A.T, b), TALL_LINSOL)
    L = _cholesky(ca.mtimes(A.T, A))
    return _tri_solve(L, _tri_solve(L, ca.mtimes(A.T, b), True), False)


def _tall_sigma(A, c):
    """A lower bound of the smallest singular value of a tall A with its columns scaled by
    c > 0, A C (C = diag(c)): sigma_min(A C) = sigma_min(L_C') for (A C)'(A C) = L_C L_C',
    and 1 / ||L_C^-1||_2 >= 1 / ||L_C^-1||_F (within sqrt(n) of it). L_C = C L for A'A =
    L L' (C L is lower triangular with a positive diagonal), so L_C^-1 = L^-1 C^-1: the
    Cholesky factor is `_tall_solve`'s, shared with the Gauss-Newton step in one function."""
    L = _cholesky(ca.mtimes(A.T, A))
    n = len(L)
    Linv = _tri_solve(L, ca.SX.eye(n), True)
    return 1 / ca.sqrt(ca.sumsqr(Linv / ca.repmat(ca.reshape(c, 1, -1), n, 1)))


def reciprocal(d):
    """1 / d written 0.5 (2 / d): the same number (scaling by 2 is exact), but casadi leaves
    x * 0.5 (2 / d) as it is, where it turns x * (1 / d) back into x / d. So a quotient used
    several times costs one division and products: a division takes several
    multiplications' time (4-14 cycles against 0.5-4), and the kernel divides by each
    block's determinant and length at every pose (40 chained four-bars: 15 divisions a group
    before, 4 now).

    >>> import casadi as ca
    >>> x, d = ca.SX.sym("x"), ca.SX.sym("d")
    >>> str(x * reciprocal(d)), float(ca.evalf(ca.substitute(reciprocal(d), d, 3.0))) == 1 / 3
    ('(x*(0.5*(2/d)))', True)
    """
    return 0.5 * (2 / d)


def _small_solve(A, b):
    n = A.size1()
    if n > A.size2():
        return _tall_solve(A, b)
    if n == 1:
        return b * reciprocal(A[0, 0])
    if n == 2:  # Cramer's rule: forward stable in two dimensions, and few operations; one
        # division (1/d, shared by every solve with the same block: the kernel's step and
        # tangent), then products
        d = A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]
        return ca.vertcat(A[1, 1] * b[0, :] - A[0, 1] * b[1, :], A[0, 0] * b[1, :] - A[1, 0] * b[0, :]) * reciprocal(d)
    return ca.solve(A, b)


def block_solve(J, b, blocks: list[Block]):
    """J^-1 b (J with this block structure, b one or more columns), group by group; a tall J
    (redundant joints, consistent) its least-squares solution, each tall group by `_tall_solve`."""
    n, k = J.size2(), b.size2()  # n unknowns (a tall J: more equations)
    x = [None] * n
    for blk in blocks:
        rhs = b[blk.rows.tolist(), :]
        known = [j for j in range(n) if x[j] is not None]
        if known:
            coupling = J[blk.rows.tolist(), known]
            if coupling.nnz():
                rhs = rhs - ca.mtimes(coupling, ca.vertcat(*[x[j] for j in known]))
        xb = _small_solve(J[blk.rows.tolist(), blk.cols.tolist()], rhs)
        for i, j in enumerate(blk.cols):
            x[j] = xb[i, :]
    return ca.vertcat(*x) if n else ca.SX(0, k)


def block_measures(J, cs, blocks: list[Block]):
    """(sign of det of each diagonal block, smallest lower bound of a block's smallest
    singular value relative to max(1, its largest)), J's columns scaled by cs > 0.

    Each block's bound is taken squared, the smallest of them, then one square root: for a
    2 x 2 block A C (C = diag(c), F = ||A C||_F^2, d = det(A C) = det(A) c_1 c_2),
    sigma_min^2 = 2 d^2 / (F + sqrt(F^2 - 4 d^2)) (F^2 - 4 d^2 = (s_1^2 - s_2^2)^2: no
    cancellation), relative to max(1, F): one square root and one division a group where
    the same number as 2|d| / (sqrt(F + 2|d|) + sqrt(F - 2|d|)) / max(1, sqrt F) took three
    and one (40 chained four-bars: 120 square roots a pose). The sign is det(A)'s, which the
    step's solve computes anyway (the positive scales c do not change it)."""
    signs, sig2 = [], []
    for blk in blocks:
        r, c = blk.rows.tolist(), blk.cols.tolist()
        n = len(r)
        if n > len(c):  # tall (redundant joints): no determinant, so no mode (+1)
            F = ca.sumsqr(_scaled(J, cs, blk))
            signs.append(ca.SX(1))
            sig2.append((_tall_sigma(J[r, c], _col_scales(cs, blk)) / ca.fmax(1, ca.sqrt(F))) ** 2)
        elif n == 1:
            v = J[r[0], c[0]] * _col_scales(cs, blk)[0]
            signs.append(ca.sign(v))
            sig2.append(v * v / ca.fmax(1, v * v))
        elif n == 2:
            A, cb = J[r, c], _col_scales(cs, blk)
            d = A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]  # as `_small_solve` writes it: computed once
            ds = d * (cb[0] * cb[1])
            F = (cb[0] * cb[0]) * (A[0, 0] ** 2 + A[1, 0] ** 2) + (cb[1] * cb[1]) * (A[0, 1] ** 2 + A[1, 1] ** 2)
            d2 = ds * ds
            signs.append(ca.sign(d))
            sig2.append(2 * d2 / ((F + ca.sqrt(ca.fmax(F * F - 4 * d2, 0))) * ca.fmax(1, F)))
        else:
            A = _scaled(J, cs, blk)
            F, d = ca.sumsqr(A), ca.det(A)
            signs.append(ca.sign(d))
            sig2.append((ca.fabs(d) / F ** ((n - 1) / 2) / ca.fmax(1, ca.sqrt(F))) ** 2)
    if not blocks:
        return ca.SX(0, 1), ca.SX(1)
    return ca.vertcat(*signs), ca.sqrt(ca.mmin(ca.vertcat(*sig2)))


def _col_scales(cs, blk):
    return cs[blk.cols.tolist()] if isinstance(cs, (ca.SX, ca.DM)) else ca.DM(np.asarray(cs)[blk.cols])


def _scaled(J, cs, blk):
    """J's block `blk`, its columns scaled by cs."""
    c = _col_scales(cs, blk)
    return J[blk.rows.tolist(), blk.cols.tolist()] * ca.repmat(ca.reshape(c, 1, -1), len(blk.rows), 1)


def diagonal_blocks(J, blocks) -> ca.SX:
    """The entries of J's diagonal blocks, one block after another (column-major each): all
    of g_q that the branch test needs from the last pose (sum of size^2, not nq^2)."""
    parts = [ca.vec(J[b.rows.tolist(), b.cols.tolist()]) for b in blocks]  # (rows x cols each)
    return ca.densify(ca.vertcat(*parts)) if parts else ca.SX(0, 1)


def diagonal_size(blocks) -> int:
    return sum(len(b.rows) * len(b.cols) for b in blocks)


def is_tall(blocks) -> bool:
    """Whether a block has more equations than unknowns (redundant joints)."""
    return any(len(b.rows) > len(b.cols) for b in blocks)


def block_change(J0d, J, D, blocks: list[Block], cs=None):
    """max over blocks of sum |D^-1 (A0^-1 A - I) D| for the diagonal blocks A0 (given as
    `diagonal_blocks` of the last pose's g_q) and A of J. Below 1 for every block, each
    A0 + t (A - A0), t in [0, 1], is invertible, hence so is J0 + t (J - J0) (block
    triangular): det g_q keeps its sign between the two. A tall block (m x n) takes
    A0^+ A = (A0'A0)^-1 A0'A, measured by its induced 1-norm: below 1, A0^+ (A0 + t (A - A0)) = I + t (A0^+ A - I) is
    invertible, so every A0 + t (A - A0) keeps full column rank between the two poses.

    With `cs` (the columns' scales of `block_measures`), a tall block takes instead the
    bound ||(A - A0) D||_F / (s(A C) min_j D_j / c_j), s the lower bound of the smallest
    singular value of `_tall_sigma` (the same as `block_measures`'), C = diag(cs): below 1,
    ||(A - A0) D||_2 < sigma_min(A D) and, by Weyl's inequality, every A + s (A0 - A)
    keeps full column rank as well. It costs no solve with n columns (kernel.py computes the
    exact measure only where this bound is above JAC_CHANGE)."""
    out, at = [ca.MX(0) if isinstance(J, ca.MX) else ca.SX(0)], 0
    for blk in blocks:
        r, c = blk.rows.tolist(), blk.cols.tolist()
        n, m, Db = len(c), len(r), D[c]
        A0 = ca.reshape(J0d[at:at + m * n], m, n)
        if m > n:  # tall: A0 is g_q at the last pose, zero where g_q is structurally zero,
            # so it takes J's sparsity (its normal equations then cost what J'J costs)
            sp = J[r, c].sparsity()
            A0 = type(J0d)(sp, J0d[[at + k for k in sp.find()]])
        at += m * n
        if m > n and cs is not None:
            dA = (J[r, c] - A0) * ca.repmat(ca.reshape(Db, 1, -1), m, 1)
            ratio = ca.mmin(Db / cs[c])
            out.append(ca.sqrt(ca.sumsqr(dA)) / (_tall_sigma(J[r, c], cs[c]) * ratio))
            continue
        M = (_small_solve(A0, J[r, c]) - ca.DM.eye(n)) * ca.repmat(Db.T, n, 1) / ca.repmat(Db, 1, n)
        if m > n:  # tall: the induced 1-norm (largest column sum), below 1 just as well; the
            # sum of all n^2 entries would grow with n and stop a 21-unknown group every degree
            out.append(ca.mmax(ca.sum1(ca.fabs(M))))
        else:
            out.append(ca.sum1(ca.sum2(ca.fabs(M))))
    return ca.mmax(ca.vertcat(*out))


def numeric_signs(J: np.ndarray, blocks: list[Block]) -> np.ndarray:
    """(N, len(blocks)) signs of the blocks' determinants of N matrices J (N, n, n)."""
    if not blocks:
        return np.ones((J.shape[0], 0))
    return np.stack([np.sign(np.linalg.det(J[:, b.rows][:, :, b.cols])) if len(b.rows) == len(b.cols)
                     else np.ones(J.shape[0]) for b in blocks], axis=1)  # tall: no mode, +1
