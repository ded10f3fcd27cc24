"""A preconditioner of the active Newton system built from the compressed interface operator
only: the near field of the hierarchical compression (:mod:`fretwear.hb.hmatrix`) as a
sparse matrix per harmonic, factorised by a sparse LU, and the modal condensation's rank-``q``
term added exactly by the Sherman-Morrison-Woodbury identity (docs/theory.md, "Compressed
interface operator").

The mean-gain preconditioner (:class:`fretwear.hb.krylov.MeanGainPreconditioner`) factors
``P_n = eps I + g_n (Z_aa(n w) - eps I)`` (``g_n`` block-diagonal per node) by a dense LU:
``m_a^3 / 3`` operations and ``m_a^2`` numbers per harmonic, which needs the dense ``X^cc``.
With the compressed forms ``X^cc_H`` of :class:`~fretwear.hb.modal_operator.ReducedOperator`
(``products``) the block of harmonic ``n`` is

    Z_aa(n) = sum_X c_X(n) (N_X + F_X) - U_n Y_n,

``N_X`` the dense leaf blocks of ``X^cc_H`` (each leaf cluster with its neighbours: every
node's own ``d x d`` block among them), ``F_X`` its low-rank far field, ``U_n Y_n`` the
modal term (rank ``q``). Dropping the far field,

    P_n = A_n - W_n Y_n,  A_n = eps I + g_n (sum_X c_X(n) N_X - eps I),  W_n = g_n U_n,

``A_n`` sparse (the near field's pattern), factorised by SuperLU
(:func:`scipy.sparse.linalg.splu`, minimum degree ordering on ``A^T + A``), and

    P_n^-1 = A_n^-1 + A_n^-1 W_n (I_q - Y_n A_n^-1 W_n)^-1 Y_n A_n^-1

(``q`` solves with ``A_n`` at the build, a ``q x q`` LU). The far field (smooth, long-range
coupling) is what the preconditioner leaves to GMRES: it is exact where the far field
vanishes and otherwise moves the iteration count, never the answer (GMRES's residual is that
of the compressed operator).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

#: SuperLU's column ordering: the near field's pattern is symmetric (a leaf with its
#: neighbours both ways), for which the minimum degree on ``A^T + A`` left 15 % less fill
#: than COLAMD and factored 20 % faster at 576 contact nodes
#: (docs/studies/large-interface-solve.md)
PERMC = "MMD_AT_PLUS_A"


def near_field(hm) -> sp.csr_matrix:
    """The dense leaf blocks of an :class:`~fretwear.hb.hmatrix.HMatrix` (its near field)
    as a sparse matrix in the original row and column order (the low-rank blocks left
    out)."""
    rows, cols, vals = [], [], []
    for b in hm.blocks:
        if b.D is None:
            continue
        r = hm.rows[b.r0 : b.r1]
        c = hm.cols[b.c0 : b.c1]
        rows.append(np.repeat(r, c.size))
        cols.append(np.tile(c, r.size))
        vals.append(np.asarray(b.D).reshape(-1))
    n_r, n_c = hm.rows.size, hm.cols.size
    if not rows:
        out = sp.csr_matrix((n_r, n_c))
    else:
        out = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows),
                                                    np.concatenate(cols))), shape=(n_r, n_c))
    return out.T.tocsr() if hm._transposed else out


class _NodeBlocks:
    """The near fields of several compressed matrices on one pattern of ``d x d`` node
    blocks (the union of theirs): ``data`` (len(mats), nblocks, d, d), the block row of each
    block and the position of each node's diagonal block, so that a combination
    ``sum_t c_t N_t`` and the products with the node gains are array operations on
    ``data``."""

    def __init__(self, products, d: int):
        bsr = [near_field(p).tobsr(blocksize=(d, d)) for p in products]
        nr = bsr[0].shape[0] // d
        keys = []
        for a in bsr:
            a.sort_indices()
            rows = np.repeat(np.arange(nr), np.diff(a.indptr))
            keys.append(rows * nr + a.indices)
        union = np.unique(np.concatenate(keys))
        self.data = np.zeros((len(bsr), union.size, d, d))
        for t, (a, key) in enumerate(zip(bsr, keys, strict=True)):
            self.data[t, np.searchsorted(union, key)] = a.data
        self.brow, self.indices = union // nr, union % nr
        self.indptr = np.searchsorted(self.brow, np.arange(nr + 1))
        self.diag = np.searchsorted(union, np.arange(nr) * nr + np.arange(nr))
        self.shape = (nr * d, nr * d)

    def block(self, c: np.ndarray, g: np.ndarray, eps: float) -> sp.csc_matrix:
        """``eps I + g (sum_t c_t N_t - eps I)`` (``g`` (nr, d, d) the node gains)."""
        N = np.tensordot(np.asarray(c), self.data, axes=(0, 0))
        A = np.matmul(g[self.brow], N)
        A[self.diag] += eps * (np.eye(g.shape[1]) - g)
        return sp.bsr_matrix((A, self.indices, self.indptr), shape=self.shape).tocsc()


class _Factors:
    """``P^-1`` of one harmonic: the sparse LU of ``A`` and the Woodbury correction; ``A``,
    ``W``, ``Y`` kept for :meth:`product` (the sharing test)."""

    def __init__(self, A: sp.spmatrix, W: np.ndarray | None, Y: np.ndarray | None):
        self.lu = spla.splu(A.tocsc(), permc_spec=PERMC)
        self.A, self.W = A, W
        self.real = not np.iscomplexobj(A)
        self.X = self.C = self.Y = None
        if W is not None:
            self.X = self._solve_A(W)  # A^-1 W (m, q)
            self.Y = Y
            self.C = sla.lu_factor(np.eye(Y.shape[0]) - Y @ self.X, check_finite=False)

    def _solve_A(self, b: np.ndarray) -> np.ndarray:
        if self.real and np.iscomplexobj(b):  # real factors, complex right-hand side
            return self.lu.solve(np.ascontiguousarray(b.real)) + 1j * self.lu.solve(
                np.ascontiguousarray(b.imag))
        return self.lu.solve(np.ascontiguousarray(b, dtype=complex if not self.real
                                                  else float))

    def solve(self, b: np.ndarray) -> np.ndarray:
        y = self._solve_A(b)
        if self.X is not None:
            y = y + self.X @ sla.lu_solve(self.C, self.Y @ y, check_finite=False)
        return y

    def product(self, v: np.ndarray) -> np.ndarray:
        """``P v = A v - W (Y v)``."""
        out = self.A @ v
        return out if self.W is None else out - self.W @ (self.Y @ v)

    def close(self, other: _Factors) -> bool:
        """Whether these factors precondition ``other``'s ``P`` well: the size of
        ``E = P^-1 (P_other - P)`` by the power iteration of
        :meth:`fretwear.hb.krylov.MeanGainPreconditioner._close` (the same probes and
        bound)."""
        from fretwear.hb.krylov import SHARE_BELOW, SHARE_PROBES

        v = np.random.default_rng(0).standard_normal(self.A.shape[0])
        size = 0.0
        for _ in range(SHARE_PROBES):
            w = self.solve(other.product(v) - self.product(v))
            size = float(np.linalg.norm(w) / np.linalg.norm(v))
            v = w.real if self.real else w
            if not np.isfinite(size) or size == 0.0:
                break
        return bool(np.isfinite(size) and size <= SHARE_BELOW)


class _Probe(_Factors):
    """``P = A - W Y`` unfactorised, for :meth:`_Factors.close`."""

    def __init__(self, A, W, Y):  # no super().__init__: no factorisation
        self.A, self.W, self.Y = A, W, Y


class NearFieldPreconditioner:
    """``P^-1`` with ``P_n = A_n - W_n Y_n`` per harmonic (module docstring), for an
    :class:`~fretwear.hb.operator_blocks.OperatorBlocks` whose operator carries compressed
    forms (``Z.op.products``). The interface of
    :class:`~fretwear.hb.krylov.MeanGainPreconditioner`: gbar, gosc the gains of harmonic 0
    and of the harmonics ``n >= 1`` (:func:`fretwear.hb.krylov.harmonic_gains`); ``share``:
    a harmonic ``n >= 2`` takes the factors of the harmonic before it when they precondition
    its ``P_n`` well (the test of the mean-gain preconditioner: below the first resonances
    the ``Z_n`` hardly differ).

    Attributes: ``nnz`` the stored entries of the sparse blocks ``A_n`` (all harmonics),
    ``factor_nnz`` those of their LU factors.
    """

    def __init__(self, gbar: np.ndarray, Z, eps: float, share: bool = True,
                 gosc: np.ndarray | None = None):
        op = Z.op
        self.k, self.m, self.H = Z.k, Z.m, Z.H
        self.shared = 0
        gosc = gbar if gosc is None else gosc
        near = _NodeBlocks(op.products, gbar.shape[1])
        self.factors = []
        self.nnz = self.factor_nnz = 0
        for b in range(Z.nb):
            g = gbar if b == 0 else gosc
            A = near.block(op.coef[b], g, eps)
            if not Z.real and not np.iscomplexobj(A):
                A = A.astype(complex)
            W = Y = None
            if op.U[b] is not None:
                q = op.U[b].shape[1]
                nc, d = g.shape[0], g.shape[1]
                W = np.matmul(g, op.U[b].reshape(nc, d, q)).reshape(self.m, q)
                Y = op.Y[b]
                if Z.real:
                    W, Y = W.real, Y.real
            last = self.factors[-1] if self.factors else None
            if share and b > 1 and last.real == (not np.iscomplexobj(A)) and last.close(
                    _Probe(A, W, Y)):
                self.factors.append(last)  # harmonic b preconditioned by the last factors
                self.shared += 1
                continue
            f = _Factors(A, W, Y)
            self.nnz += A.nnz
            self.factor_nnz += f.lu.L.nnz + f.lu.U.nnz
            self.factors.append(f)
        groups: dict = {}
        for b, f in enumerate(self.factors):
            groups.setdefault(id(f), (f, []))[1].append(b)
        self.groups = list(groups.values())

    def apply(self, r) -> np.ndarray:
        """``P^-1 r`` on the real Fourier basis (DOF-major ``(m, H)``, as
        :meth:`fretwear.hb.krylov.MeanGainPreconditioner.apply`)."""
        r = np.asarray(r).reshape(self.m, self.H)
        k = self.k
        out = np.empty_like(r)
        for f, hs in self.groups:  # the harmonics sharing factors in one call
            if f.real:  # real P_n: P_n (a - i b) = P_n a - i P_n b
                cols = [c for b in hs for c in ([0] if b == 0 else [b, k + b])]
                out[:, cols] = f.solve(r[:, cols]).real
                continue
            y = f.solve(r[:, hs] - 1j * r[:, [k + b if b else 0 for b in hs]]
                        * (np.asarray(hs) > 0))
            out[:, hs] = y.real
            nz = [i for i, b in enumerate(hs) if b]
            out[:, [k + hs[i] for i in nz]] = -y[:, nz].imag
        return out.reshape(-1)


def preconditioner_for(Z, name: str = "mean-gain"):
    """The preconditioner class for the active blocks ``Z``: :class:`NearFieldPreconditioner`
    when they are an operator with compressed forms and ``name`` (the solve's
    ``KrylovOptions.preconditioner``) is ``"nearfield"``, else None (the caller's default,
    the mean gain: faster up to 1024 contact nodes, docs/studies/large-interface-solve.md;
    the near field holds no dense ``m_a x m_a`` factors, for interfaces whose dense factors
    do not fit)."""
    op = getattr(Z, "op", None)
    if name == "nearfield" and getattr(op, "products", None) is not None:
        return NearFieldPreconditioner
    return None
