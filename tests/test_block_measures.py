"""`block_measures`' lower bound of each diagonal block's smallest singular value (relative
to max(1, ||A||_F), a bound of the largest), against numpy's SVD: exact for blocks of one and two unknowns,
including where both singular values are equal (F^2 = 4 d^2) and near singular blocks."""
from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from kincas.core.blocks import block_measures
from kincas.core.structure import Block


def _svd_measure(A, c):
    s = np.linalg.svd(A * c, compute_uv=False)
    return s[-1] / max(1.0, np.sqrt(np.sum(s * s)))


@pytest.mark.parametrize("A, c", [
    ([[2.0, 1.0], [0.0, 3.0]], [1.0, 1.0]),
    ([[0.6, -0.8], [0.8, 0.6]], [1.0, 1.0]),            # a rotation: both singular values 1
    ([[0.3, -0.4], [0.4, 0.3]], [1.0, 1.0]),            # equal singular values below 1
    ([[1.0, 2.0], [1.0, 2.0 + 1e-9]], [0.5, 4.0]),      # near singular, columns scaled
    ([[-3.0, 0.2], [0.1, -0.05]], [0.25, 0.25]),
])
def test_two_by_two_bound_is_the_smallest_singular_value(A, c):
    A, c = np.array(A), np.array(c)
    signs, rel = block_measures(ca.DM(A), c, [Block(np.arange(2), np.arange(2), ())])
    assert float(signs) == np.sign(np.linalg.det(A))
    assert float(rel) == pytest.approx(_svd_measure(A, c), rel=1e-9, abs=1e-15)


def test_smallest_over_blocks_of_one_and_two():
    A = np.array([[0.5, 0.0, 0.0], [1.0, 2.0, 1.0], [0.0, 1.0, 3.0]])
    blocks = [Block(np.arange(1), np.arange(1), ()), Block(np.arange(1, 3), np.arange(1, 3), ())]
    signs, rel = block_measures(ca.DM(A), np.ones(3), blocks)
    assert np.allclose(np.asarray(signs).ravel(), [1, 1])
    want = min(_svd_measure(A[:1, :1], np.ones(1)), _svd_measure(A[1:, 1:], np.ones(2)))
    assert float(rel) == pytest.approx(want, rel=1e-12)
