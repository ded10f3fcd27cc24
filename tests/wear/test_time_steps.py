"""Tests of the slow steps from time integrations (:mod:`fretwear.wear.time_steps`): the slow
Jacobian made safe for the linearly implicit predictor (:func:`without_growth`).

Reference: a hand-built matrix with known eigenpairs. Moved unchanged from
tests/timedomain/test_averaged_rate.py (the time-averaged rate itself is tested there).
"""

from __future__ import annotations

import numpy as np

from fretwear.wear.time_steps import without_growth


def test_without_growth_keeps_decaying_modes_and_makes_growing_ones_explicit():
    """:func:`without_growth` against a hand-built matrix with known eigenpairs: a growing
    mode (+2), a neutral one (0), a decaying one (-5) and a decaying oscillatory pair
    (-1 +- 3i), in a non-orthogonal basis. The predictor ``(I - dN Js+)^-1 g`` must then be,
    along each eigenvector, explicit Euler (growing: factor 1, even at ``dN mu = 1`` where
    ``I - dN Js`` is singular), exact for the neutral mode (factor 1) and ``1 / (1 - dN mu)``
    for the others; the eigenvectors are unchanged. Tolerance: round-off of a 5 x 5 eigen
    decomposition with condition number ~10."""
    rng = np.random.default_rng(3)
    V = np.eye(5) + 0.3 * rng.standard_normal((5, 5))
    B = np.zeros((5, 5))
    B[0, 0], B[1, 1], B[2, 2] = 2.0, 0.0, -5.0
    B[3:, 3:] = [[-1.0, 3.0], [-3.0, -1.0]]  # eigenvalues -1 +- 3i
    Js = V @ B @ np.linalg.inv(V)
    Jp = without_growth(Js)
    assert Jp.dtype == float
    Bp = B.copy()
    Bp[0, 0] = 0.0
    np.testing.assert_allclose(Jp, V @ Bp @ np.linalg.inv(V), atol=1e-12 * np.abs(Js).max())
    dN = 0.5  # dN mu = 1 for the growing mode
    for j, factor in ((0, 1.0), (1, 1.0), (2, 1.0 / (1.0 + 5.0 * dN))):
        step = np.linalg.solve(np.eye(5) - dN * Jp, V[:, j])
        np.testing.assert_allclose(step, factor * V[:, j], atol=1e-12)
    # a matrix without growing modes is returned unchanged
    Bm = B.copy()
    Bm[0, 0] = -2.0
    Jm = V @ Bm @ np.linalg.inv(V)
    np.testing.assert_array_equal(without_growth(Jm), Jm)
