"""The operator path's products (:class:`~fretwear.hb.krylov.HarmonicBlocks`) on a
:class:`~fretwear.hb.modal_operator.ReducedOperator`: ``Z_r`` of the blocked modal
condensation, never stored as dense blocks per harmonic (docs/theory.md, "Large
interfaces")."""

from __future__ import annotations

import numpy as np

from fretwear.hb.krylov import HarmonicBlocks
from fretwear.hb.modal_operator import ReducedOperator

#: bytes of LU factors the mean-gain preconditioner (hb/krylov.py) may hold for operator
#: blocks: one factorisation of all 4096 contact nodes' DOFs of benchmarks/scale_3d.py
#: (1.1 GiB) fits, not eight
FACTOR_BUDGET = 2 * 2**30


class OperatorBlocks(HarmonicBlocks):
    """:class:`~fretwear.hb.krylov.HarmonicBlocks` of a :class:`ReducedOperator`: the same
    products on the real Fourier basis (DOF-major ``(m, H)`` arrays), through
    :meth:`ReducedOperator.matmat` instead of stored blocks; a block is formed (dense) only
    where :meth:`block` is asked for one (the column norms and the preconditioner, one block
    at a time, on the active DOFs for the latter). The preconditioner's factors are bounded
    by :data:`FACTOR_BUDGET` bytes (``factor_budget``): past it the harmonics share the
    last factors."""

    factor_budget = FACTOR_BUDGET

    def __init__(self, op: ReducedOperator):  # no super().__init__: no (nb, m, m) array
        self.op = op
        self.nb, self.m = op.nb, op.m
        self.k = self.nb - 1
        self.H = 1 + 2 * self.k
        c0 = op.coef[0]
        plain = op.U[0] is None and c0[0] == 1 and not np.any(c0[1:])
        dense = all(isinstance(A, np.ndarray) for A in op.mats)  # (not a compressed twin's)
        self.Z0 = (op.mats[0] if plain else np.ascontiguousarray(op.block(0).real) if dense
                   else None)
        self._ZcH = None
        self._rows = None  # (dofs, the operator of those rows): row_block
        self._symmetric = op.symmetric
        self._real = op.real
        self._single = {}  # single(): the single-precision twins, once made (per bound)

    @property
    def real(self) -> bool:
        return self._real

    @property
    def Zr(self):
        raise AttributeError("OperatorBlocks stores no (nb, m, m) blocks: use block(b)")

    @property
    def Zc(self):
        raise AttributeError("OperatorBlocks stores no (nb, m, m) blocks: use block(b)")

    def block(self, b: int) -> np.ndarray:
        """Block ``b`` formed densely (real when :attr:`real`)."""
        if b == 0:
            return self.Z0
        return self.op.block(b)

    def row_block(self, b: int, dofs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """As :meth:`HarmonicBlocks.row_block`: the rows ``dofs`` of the stored matrices
        are taken once for every harmonic (and kept while ``dofs`` do not change: Powell's
        successive Jacobians near a solution share them), then each block's rows are formed
        from them."""
        dofs = np.asarray(dofs)
        if b == 0:  # held formed
            return self.Z0, dofs
        if dofs.size == self.m and np.array_equal(dofs, np.arange(self.m)):
            return self.op.block(b), dofs  # every row: no copy of the stored matrices' rows
        key = dofs.tobytes()
        if self._rows is None or self._rows[0] != key:
            op = self.op
            self._rows = None  # release the last rows before taking new ones
            self._rows = (key, ReducedOperator(
                [np.take(A, dofs, axis=0) for A in op.mats], op.coef,
                [None if u is None else u[dofs] for u in op.U], op.Y, False))
        return self._rows[1].block(b), np.arange(dofs.size)

    def row_panel(self, b: int, dofs: np.ndarray, buf: np.ndarray):
        """As :meth:`HarmonicBlocks.row_panel`: the rows from the first to the last of the
        increasing ``dofs`` of block ``b`` formed into ``buf`` when they fit (every node
        active, or active nodes with a few stuck ones between them, whose rows are formed
        and not read), else formed from the stored matrices' rows ``dofs`` taken; with the
        rows of ``dofs`` in the result. The same entries as :meth:`row_block`."""
        dofs = np.asarray(dofs)
        if b == 0:  # held formed
            return self.Z0, dofs
        if dofs.size and dofs[-1] - dofs[0] < buf.shape[0] and np.all(np.diff(dofs) > 0):
            r0 = int(dofs[0])
            r1 = int(dofs[-1]) + 1
            return self.op.block_rows(b, r0, r1, buf[: r1 - r0]), dofs - r0
        return self.op.block(b, rows=dofs), np.arange(dofs.size)

    def block_products(self, blocks, V: np.ndarray) -> np.ndarray:
        """As :meth:`HarmonicBlocks.block_products`, through
        :meth:`ReducedOperator.matmat` (each stored matrix read once for all columns, no
        block formed); block 0 by the formed :attr:`Z0` (its real part)."""
        blocks = np.asarray(blocks)
        out = np.empty(V.shape, dtype=np.result_type(V, complex if not self.real else float))
        zero = blocks == 0
        if np.any(zero):
            out[:, zero] = self.Z0 @ V[:, zero]
        if not np.all(zero):
            out[:, ~zero] = self.op.matmat(blocks[~zero], V[:, ~zero])
        return out

    def node_diagonal(self, b: int, d: int) -> np.ndarray:
        if b == 0:
            return super().node_diagonal(0, d)
        out = self.op.node_diagonal(b, d)
        return out.real if self.real else out

    def single(self, compress: float | None = None):
        """The same blocks in single precision (:meth:`ReducedOperator.single`, made once
        and kept by this object), for GMRES's products on loosely solved Newton steps; with
        ``compress`` their stored matrices compressed to that relative error where the
        operator knows its nodes' positions (the compressed twin); None when the operator
        carries compressed forms (their products are already approximate)."""
        if self.op.products is not None:
            return None
        if compress not in self._single:
            self._single[compress] = OperatorBlocks(self.op.single(compress))
        return self._single[compress]

    def leading(self, nb: int) -> OperatorBlocks:
        return OperatorBlocks(self.op[:nb])

    def sub(self, dofs: np.ndarray) -> OperatorBlocks:
        return OperatorBlocks(self.op.sub(dofs))

    def symmetric(self) -> bool:
        return self._symmetric

    def _layout(self):
        k = self.k
        return np.concatenate([[0], np.arange(1, k + 1), np.arange(1, k + 1)])

    def _apply_op(self, U, transpose: bool) -> np.ndarray:
        U = np.asarray(U, dtype=float).reshape(self.m, self.H)
        k = self.k
        if self.real:  # Z_n real: columns a_n and b_n each times Z_n (or Z_n^T)
            return self.op.matmat(self._layout(), U, transpose)
        # c_n = a_n - i b_n; Z~ U <-> Z_n c_n, Z~^T U <-> Z_n^H c_n = conj(Z_n^T conj(c_n))
        c = np.empty((self.m, k + 1), dtype=complex)
        c[:, 0] = U[:, 0]
        c[:, 1:] = U[:, 1 : k + 1] - 1j * U[:, k + 1 :]
        if transpose:
            y = np.conj(self.op.matmat(np.arange(k + 1), np.conj(c), True))
        else:
            y = self.op.matmat(np.arange(k + 1), c)
        out = np.empty((self.m, self.H))
        out[:, 0] = y[:, 0].real
        out[:, 1 : k + 1] = y[:, 1:].real
        out[:, k + 1 :] = -y[:, 1:].imag
        return out

    def apply(self, U) -> np.ndarray:
        return self._apply_op(U, False)

    def apply_T(self, U) -> np.ndarray:
        return self._apply_op(U, True)

    def apply_sub(self, rows: np.ndarray, cols: np.ndarray, U: np.ndarray) -> np.ndarray:
        """As :meth:`HarmonicBlocks.apply_sub`: each stored matrix's sub-block is taken once
        for every harmonic."""
        k, r = self.k, U.shape[2]
        out = np.zeros((rows.size, self.H, r))
        if not (rows.size and cols.size):
            return out
        # only its products are taken: with compressed forms, no dense cut of the matrices
        cut = self.op.cut(rows, cols)
        mats = cut if cut is not None else [np.ascontiguousarray(A[np.ix_(rows, cols)])
                                            for A in self.op.mats]
        sub = ReducedOperator(mats, self.op.coef,
                              [None if u is None else u[rows] for u in self.op.U],
                              [None if y is None else y[:, cols] for y in self.op.Y],
                              False, cut)
        if self.real:
            X = U.transpose(0, 2, 1).reshape(cols.size, r * self.H)  # columns (r, H)
            blocks = np.tile(self._layout(), r)
            return sub.matmat(blocks, X).reshape(rows.size, r, self.H).transpose(0, 2, 1)
        c = np.empty((cols.size, r, k + 1), dtype=complex)
        c[:, :, 0] = U[:, 0]
        c[:, :, 1:] = (U[:, 1 : k + 1] - 1j * U[:, k + 1 :]).transpose(0, 2, 1)
        y = sub.matmat(np.tile(np.arange(k + 1), r), c.reshape(cols.size, -1))
        y = y.reshape(rows.size, r, k + 1)
        out[:, 0] = y[:, :, 0].real
        out[:, 1 : k + 1] = y[:, :, 1:].real.transpose(0, 2, 1)
        out[:, k + 1 :] = -y[:, :, 1:].imag.transpose(0, 2, 1)
        return out

    def dense(self) -> np.ndarray:
        from fretwear.hb.reduce import to_real_blocks

        return to_real_blocks(np.stack(list(self.op)), np.arange(self.nb))


def harmonic_blocks(Z) -> HarmonicBlocks:
    """The :class:`~fretwear.hb.krylov.HarmonicBlocks` of ``Z``: an (nb, m, m) array or a
    :class:`ReducedOperator`."""
    return OperatorBlocks(Z) if isinstance(Z, ReducedOperator) else HarmonicBlocks(Z)
