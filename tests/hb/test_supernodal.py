"""Supernodal triangular solves (fretwear.hb.supernodal) against LAPACK's dense solve."""

import numpy as np
import scipy.sparse as sp

from fretwear.hb.supernodal import COLUMNS, SupernodalFactor


def _grid_spd(n=6, seed=0):
    """A 3D grid Laplacian (n^3 unknowns) shifted to condition number ~1e2, with random
    symmetric couplings of its own pattern: a stiffness-like SPD matrix whose Cholesky factor
    has supernodes wider than one column."""
    one = sp.diags([-np.ones(n - 1), 2.0 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])
    eye = sp.eye(n)
    A = (sp.kron(sp.kron(one, eye), eye) + sp.kron(sp.kron(eye, one), eye)
         + sp.kron(sp.kron(eye, eye), one)).tocsc()
    rng = np.random.default_rng(seed)
    A = A + 0.1 * sp.diags(rng.random(A.shape[0]) + 1.0)
    return sp.csc_matrix(A)


def test_supernodal_solve_matches_dense():
    """L from the dense Cholesky of the permuted matrix (L's zeros dropped: the sparse
    pattern of the factor, an independent construction from CHOLMOD's): one, a few and more
    than COLUMNS right-hand sides, and sparse ones (K_ic-like: a block of rows only; the
    forward solve then skips zero blocks), agree with LAPACK's solve of A to 1e-12 relative
    (condition number ~1e2: backward-stable solves agree to ~1e-14; a wrong supernode or
    permutation is O(1) off)."""
    A = _grid_spd()
    n = A.shape[0]
    p = np.random.default_rng(1).permutation(n)
    Ld = np.linalg.cholesky(A[p][:, p].toarray())
    Ld[np.abs(Ld) < 1e-300] = 0.0
    f = SupernodalFactor(sp.csc_matrix(Ld), p)
    # the identity permutation on the natural order: bands of width > 1
    g = SupernodalFactor(sp.csc_matrix(np.linalg.cholesky(A.toarray())), np.arange(n))
    assert g.supernodes < n
    rng = np.random.default_rng(2)
    Ad = A.toarray()
    for B in (rng.standard_normal(n), rng.standard_normal((n, 3)),
              rng.standard_normal((n, COLUMNS + 5))):
        X = np.linalg.solve(Ad, B)
        for fac in (f, g):
            assert np.abs(fac.solve(B) - X).max() <= 1e-12 * np.abs(X).max()
    B = np.zeros((n, 20))
    B[:30] = rng.standard_normal((30, 20))
    B[30::7, :5] = 1.0  # scattered rows: blocks of a supernode partly zero
    X = np.linalg.solve(Ad, B)
    for fac in (f, g):
        assert np.abs(fac.solve(B) - X).max() <= 1e-12 * np.abs(X).max()


def test_zero_blocks_skipped_only_when_zero():
    """Four dense 5 x 5 SPD blocks on the diagonal (four supernodes of width 5, none
    updating another) and right-hand sides nonzero in one row inside a block: the forward
    solve skips the blocks that are zero and solves the others, as LAPACK's dense solve
    (1e-12 relative; a skipped nonzero block leaves O(1) errors)."""
    rng = np.random.default_rng(3)
    blocks = []
    for _ in range(4):
        G = rng.standard_normal((5, 5))
        blocks.append(G @ G.T + 5 * np.eye(5))
    A = sp.block_diag(blocks).tocsc()
    f = SupernodalFactor(sp.csc_matrix(np.linalg.cholesky(A.toarray())), np.arange(20))
    assert f.supernodes == 4
    B = np.zeros((20, 12))
    for j in range(12):
        B[(7 * j + 3) % 20, j] = 1.0 + j
    X = np.linalg.solve(A.toarray(), B)
    assert np.abs(f.solve(B) - X).max() <= 1e-12 * np.abs(X).max()
