"""Triangular solves of a sparse Cholesky factor for many right-hand sides, supernode by
supernode with the dense BLAS 3 of NumPy and SciPy.

The modal condensation solves ``K_ii X = K_ic`` for every contact DOF (``Psi``, 3072
right-hand sides at 1024 contact nodes of benchmarks/scale_3d.py). CHOLMOD's own solve, as
kvxopt ships it (linked to a generic ATLAS), ran there at 2.6 GFlop/s, a fifteenth of the
speed of NumPy's matrix product on the same machine, and took 58 % of the condensation. This
module takes the factor ``P A P^T = L L^T`` (``L`` sparse lower triangular, ``p`` the
permutation: ``A[p][:, p] = L L^T``), groups its columns into supernodes (consecutive columns
``j, j + 1`` whose patterns below the diagonal block coincide: the parent of ``j`` in the
elimination tree is ``j + 1`` and column ``j + 1`` has one entry fewer) and stores each as a
dense lower triangle ``D`` (w x w) and a dense panel ``B`` (r x w) on the rows ``R`` below it.
The solves are then, for each block of right-hand sides ``Y`` (``COLUMNS`` at a time: their
rows stay in cache),

    forward (L Y = P X):   Y_s = D_s^-1 Y_s,          Y_R -= B_s Y_s      (supernodes in order)
    backward (L^T Z = Y):  Z_s = D_s^-T (Y_s - B_s^T Z_R)                 (in reverse order)

two dense triangular solves and two matrix products per supernode: the same arithmetic as
the sparse triangular solves (4 nnz(L) flops per right-hand side), in another order (equal
to rounding). Measured at 1024 contact nodes (12288 interior DOFs, nnz(L) = 3.8e6, 575
supernodes): 256 right-hand sides in 0.34 s CPU against 1.5-1.7 s by CHOLMOD's solve.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.linalg.lapack import dtrtrs

#: right-hand sides solved together (a block of ``Y``'s rows fits in cache; 256 columns
#: measured 1.3 ms a column, 3072 at once 2.2 ms at 1024 contact nodes)
COLUMNS = 256


class SupernodalFactor:
    """Solves with ``A = P^T L L^T P`` from the sparse lower triangular ``L`` (n, n) and the
    permutation ``p`` (``A[p][:, p] = L L^T``), supernode by supernode (module docstring).

    Attributes: ``n``; ``supernodes``: their number; ``nbytes``: the dense panels' memory.
    """

    def __init__(self, L, p):
        L = sp.csc_matrix(L)
        L.sort_indices()
        self.n = n = L.shape[0]
        self.p = np.asarray(p, dtype=np.int64)
        ip, ix = L.indptr, L.indices
        cnt = np.diff(ip)
        below = np.where(cnt > 1, ix[np.minimum(ip[:-1] + 1, max(ix.size - 1, 0))], -1)
        joined = (below[:-1] == np.arange(1, n)) & (cnt[1:] == cnt[:-1] - 1)
        starts = np.flatnonzero(np.concatenate([[True], ~joined])) if n else np.zeros(0, int)
        ends = np.append(starts[1:], n)
        self.panels = []
        for c0, c1 in zip(starts.tolist(), ends.tolist(), strict=True):
            rows = ix[ip[c0]:ip[c0 + 1]]
            w = c1 - c0
            dense = np.zeros((rows.size, w))  # (w + r, w): the pattern of column c0
            for j in range(w):  # column c0 + j holds the rows of c0 from its j-th on
                if np.array_equal(ix[ip[c0 + j]:ip[c0 + j + 1]], rows[j:]):
                    dense[j:, j] = L.data[ip[c0 + j]:ip[c0 + j + 1]]
                else:  # a pattern without some of its zeros: placed row by row
                    mine = ix[ip[c0 + j]:ip[c0 + j + 1]]
                    if not np.all(np.isin(mine, rows)):
                        raise ValueError("L is not a Cholesky factor: the pattern of "
                                         f"column {c0 + j} is not in that of {c0}")
                    dense[:, j] = L[:, c0 + j][rows].toarray()[:, 0]
            self.panels.append((c0, c1, rows[w:].copy(), np.tril(dense[:w]),
                                np.ascontiguousarray(dense[w:])))
        self.supernodes = len(self.panels)
        self.nbytes = sum(d.nbytes + b.nbytes for _, _, _, d, b in self.panels)

    def solve(self, B: np.ndarray) -> np.ndarray:
        """``A^-1 B`` for a real ``B`` (n,) or (n, k)."""
        B = np.asarray(B, dtype=float)
        one = B.ndim == 1
        B2 = B.reshape(self.n, -1)
        X = np.empty_like(B2)
        for j0 in range(0, B2.shape[1], COLUMNS):
            cols = slice(j0, min(j0 + COLUMNS, B2.shape[1]))
            X[self.p, cols] = self._solve_permuted(B2[self.p, cols])
        return X[:, 0] if one else X

    def _solve_permuted(self, Y: np.ndarray) -> np.ndarray:
        """``(L L^T)^-1 Y`` in place of ``Y`` (C order, rows permuted)."""
        Y = np.ascontiguousarray(Y)
        # LAPACK's trtrs directly: SciPy's solve_triangular's checks cost more than the solve
        # of a narrow supernode (2 s of 6 at 1024 contact nodes)
        for c0, c1, R, D, Bs in self.panels:  # L y = b
            if not Y[c0:c1].any():  # a zero block stays zero (sparse right-hand sides,
                continue  # as K_ic's: the forward solve skips most of the supernodes)
            y, _ = dtrtrs(D, Y[c0:c1], lower=1)
            Y[c0:c1] = y
            if R.size:
                Y[R] -= Bs @ y
        for c0, c1, R, D, Bs in reversed(self.panels):  # L^T x = y
            y = Y[c0:c1]
            if R.size:
                y = y - Bs.T @ Y[R]
            Y[c0:c1] = dtrtrs(D, y, lower=1, trans=1)[0]
        return Y
