"""The condensed dynamic stiffness ``Z_r`` of the modal (Craig-Bampton) condensation held as a
few shared matrices and a low-rank term per harmonic, not as dense ``m x m`` blocks per
harmonic (docs/theory.md, "Large interfaces").

On the reduced coordinates ``(u_c, q)`` of :mod:`fretwear.hb.modal` every matrix ``X`` of
``K, M, C, D`` projects to ``X^cc`` (m, m), ``X^cq`` (m, q), ``X^qc`` (q, m), ``X^qq`` (q, q),
and harmonic ``n`` (``w_n = n w``) of the condensation is

    Z_r(n) = sum_X c_X(n) X^cc - Z^cq(n) Z^qq(n)^-1 Z^qc(n),
    c_K = 1, c_M = -w_n^2, c_C = i w_n, c_D = i       (harmonic 0 and quasi-static: K alone),

with ``Z^cq(n) = sum_X c_X(n) X^cq`` etc. (eq. 18 on the reduced coordinates). The ``m x m``
matrices ``X^cc`` do not depend on the frequency: they are stored once (two for an undamped
structure: the static condensation ``K_r`` and the projected mass), shared by every harmonic,
frequency, sweep point and the active sub-blocks; each harmonic adds ``U_n = Z^cq(n)``
(m, q) and ``Y_n = Z^qq(n)^-1 Z^qc(n)`` (q, m). A product ``Z_r(n) x`` is then one product
per stored matrix (all harmonics' columns at once) and ``U_n (Y_n x)``: the same
``O(m^2)`` per column as a dense block, with ``2 m^2`` numbers stored instead of
``(H + 1) m^2``. A dense block is formed only where a caller asks for one (:meth:`block`).
With ``products`` (a compressed form of each ``X^cc``, e.g. the hierarchical low-rank
:class:`~fretwear.hb.hmatrix.HMatrix`) the products take those instead of the stored
matrices: below ``O(m^2)`` per column, within the compression's error bound.
The solver's products on the real Fourier basis are in :mod:`fretwear.hb.operator_blocks`.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla


def _times(A: np.ndarray, X: np.ndarray) -> np.ndarray:
    """``A @ X`` for a real ``A`` and a real or complex ``X`` without a complex copy of
    ``A`` (a compressed ``A`` takes a complex ``X`` in one pass itself)."""
    if np.iscomplexobj(X) and isinstance(A, np.ndarray) and not np.iscomplexobj(A):
        return A @ X.real + 1j * (A @ X.imag)
    return A @ X


def _select(A: np.ndarray, rows, cols) -> np.ndarray:
    """``A[rows][:, cols]`` (None: all), a view when both are None."""
    if rows is None and cols is None:
        return A
    if cols is None:
        return np.take(A, rows, axis=0)
    if rows is None:
        return np.take(A, cols, axis=1)
    return np.take(np.take(A, rows, axis=0), cols, axis=1)


def _axpy(c, A: np.ndarray, out: np.ndarray) -> None:
    """``out += c A`` in place: BLAS ``axpy`` on contiguous arrays of one kind, NumPy
    otherwise."""
    if (out.flags.c_contiguous and A.flags.c_contiguous and out.dtype == np.float64
            and A.dtype == np.float64 and np.isrealobj(c)):
        sla.blas.daxpy(A.ravel(), out.ravel(), a=float(c))
    else:
        out += c * A


def _gemm_sub(U: np.ndarray, Y: np.ndarray, out: np.ndarray) -> None:
    """``out -= U Y`` in place (one BLAS ``gemm`` on ``out^T``, F-ordered, for a contiguous
    float64 or complex128 ``out``; NumPy otherwise)."""
    kind = {np.dtype(np.float64): sla.blas.dgemm, np.dtype(np.complex128): sla.blas.zgemm}
    gemm = kind.get(out.dtype)
    if gemm is not None and out.flags.c_contiguous and (
            out.dtype == np.complex128 or not (np.iscomplexobj(U) or np.iscomplexobj(Y))):
        r = gemm(-1.0, np.asarray(Y, out.dtype).T, np.asarray(U, out.dtype).T, beta=1.0,
                 c=out.T, overwrite_c=True)
        if np.shares_memory(r, out):
            return
        out[...] = r.T
        return
    out -= U @ Y


class ReducedOperator:
    """``Z_r`` on ``nb`` harmonic orders (module docstring), in place of the (nb, m, m) array
    of :class:`~fretwear.hb.reduce.Reduced`.

    Parameters
    ----------
    mats : the shared (m, m) real matrices ``X^cc`` (contact-local frames).
    coef : (nb, len(mats)) their coefficients ``c_X(n)`` per block.
    U, Y : per block the low-rank factors ``Z^cq(n)`` (m, q) and ``Z^qq(n)^-1 Z^qc(n)``
        (q, m), or None for a block without a modal term (harmonic 0).
    symmetric : whether every ``X^cc`` is symmetric and ``U_n Y_n`` is (symmetric ``K, M, C,
        D``): then ``Z_r(n)^T = Z_r(n)``.
    products : None, or per stored matrix a compressed form taken by :meth:`matmat` (``@``,
        ``.T``, ``sub(rows, cols)``, ``tol``: :class:`~fretwear.hb.hmatrix.HMatrix`); the
        blocks formed (:meth:`block`, :meth:`node_diagonal`) stay those of ``mats``.
    coords : None, or the (m / d, dim) positions of the contact nodes (``d`` DOFs each):
        what :meth:`single` needs to compress ``mats`` for a compressed twin.
    twins : a dict that holds the compressed twins' matrices made by :meth:`single`, shared
        by the operators on the same ``mats`` (its slices; a condenser passes one dict to
        every operator it makes, so that the compression is made once per condensation);
        None: a new one.

    It has the array interface the solvers use: ``shape``, ``dtype``, ``ndim``, ``nbytes``,
    ``len``; an integer index forms that block (dense, (m, m)), a slice gives the operator of
    those blocks (sharing the matrices), iteration forms the blocks one at a time.
    """

    ndim = 3

    def __init__(self, mats, coef, U, Y, symmetric: bool = True, products=None,
                 coords=None, twins: dict | None = None):
        self.mats = list(mats)
        self.coords = coords
        self.twins = {} if twins is None else twins
        self._cut_of = None  # (operator, dofs) of a sub-operator: single() cuts its twin
        self.products = None if products is None else list(products)
        self.coef = np.asarray(coef)
        self.U, self.Y = list(U), list(Y)
        self.nb = self.coef.shape[0]
        self.m = self.mats[0].shape[0]
        self.symmetric = bool(symmetric)
        cplx = (np.iscomplexobj(self.coef) and np.any(self.coef.imag)) or any(
            u is not None and (np.iscomplexobj(u) or np.iscomplexobj(y))
            for u, y in zip(self.U, self.Y, strict=True))
        self.dtype = np.dtype(complex if cplx else float)
        if not cplx:
            self.coef = self.coef.real

    @property
    def shape(self) -> tuple:
        return (self.nb, self.m, self.m)

    @property
    def real(self) -> bool:
        """Whether every block is real (an undamped structure)."""
        return self.dtype.kind == "f"

    @property
    def nbytes(self) -> int:
        """Bytes held: the shared matrices, their compressed forms and the low-rank
        factors."""
        return int(sum(a.nbytes for a in self.mats + (self.products or []))
                   + sum(u.nbytes + y.nbytes for u, y in zip(self.U, self.Y, strict=True)
                         if u is not None))

    def arrays(self) -> list:
        """Every array that determines the operator (for a fingerprint: hashing the formed
        blocks would form them all)."""
        out = [*self.mats, np.ascontiguousarray(self.coef)]
        if self.products is not None:  # the compression's bounds (it is reproducible)
            out.append(np.array([p.tol for p in self.products]))
        for u, y in zip(self.U, self.Y, strict=True):
            out += [] if u is None else [u, y]
        return out

    def __len__(self) -> int:
        return self.nb

    def __getitem__(self, key):
        if isinstance(key, slice):
            idx = range(self.nb)[key]
            return ReducedOperator(self.mats, self.coef[list(idx)].reshape(len(idx), -1),
                                   [self.U[b] for b in idx], [self.Y[b] for b in idx],
                                   self.symmetric, self.products, self.coords, self.twins)
        return self.block(int(key))

    def __iter__(self):
        for b in range(self.nb):
            yield self.block(b)

    def block(self, b: int, rows=None, cols=None) -> np.ndarray:
        """Block ``b`` formed densely (m, m), or its rows ``rows`` and columns ``cols``
        (either may be None: all). Each stored matrix is read once, added in place (BLAS
        ``axpy``), and the low-rank term subtracted by one ``gemm`` into the result: no
        ``m x m`` temporaries."""
        out = None
        for c, A in zip(self.coef[b], self.mats, strict=True):
            if c == 0:
                continue
            As = _select(A, rows, cols)
            if out is None:
                out = np.multiply(As, c, dtype=self.dtype)
            else:
                _axpy(c, As, out)
        if out is None:
            out = np.zeros(_select(self.mats[0], rows, cols).shape, dtype=self.dtype)
        if self.U[b] is not None:
            U = self.U[b] if rows is None else self.U[b][rows]
            Y = self.Y[b] if cols is None else self.Y[b][:, cols]
            _gemm_sub(U, Y, out)
        return out

    def block_rows(self, b: int, r0: int, r1: int, out: np.ndarray) -> np.ndarray:
        """The rows ``r0:r1`` of block ``b`` formed into ``out`` ((r1 - r0, m), this
        operator's dtype, C-contiguous; returned): as :meth:`block` with those rows, entry
        for entry the same operations, from views of the stored matrices' rows and into a
        buffer the caller keeps, so that forming a block panel by panel (the column norms
        of fretwear.hb.krylov) allocates nothing: a fresh ``m x m`` array costs its page
        faults at every block (46 ms a block at 1024 contact nodes, where the products that
        follow on a cache-sized panel cost 12 ms)."""
        first = True
        for c, A in zip(self.coef[b], self.mats, strict=True):
            if c == 0:
                continue
            if first:
                np.multiply(A[r0:r1], c, out=out, dtype=self.dtype)
                first = False
            else:
                _axpy(c, A[r0:r1], out)
        if first:
            out[...] = 0.0
        if self.U[b] is not None:
            _gemm_sub(self.U[b][r0:r1], self.Y[b], out)
        return out

    def node_diagonal(self, b: int, d: int) -> np.ndarray:
        """The (nc, d, d) blocks of block ``b`` on the diagonal (each node's own ``d x d``
        block, ``nc = m / d``) without forming the block: ``O(m d (len(mats) + q))``."""
        nc = self.m // d
        idx = np.arange(nc)
        out = np.zeros((nc, d, d), dtype=self.dtype)
        for c, A in zip(self.coef[b], self.mats, strict=True):
            if c != 0:
                out += c * A.reshape(nc, d, nc, d)[idx, :, idx, :]
        if self.U[b] is not None:
            q = self.U[b].shape[1]
            out -= np.matmul(self.U[b].reshape(nc, d, q),
                             self.Y[b].reshape(q, nc, d).transpose(1, 0, 2))
        return out

    def sub(self, dofs: np.ndarray) -> ReducedOperator:
        """The operator restricted to the rows and columns ``dofs`` (itself, sharing its
        matrices, when ``dofs`` are all of them in order: every contact node active)."""
        dofs = np.asarray(dofs)
        if dofs.size == self.m and np.array_equal(dofs, np.arange(self.m)):
            return self
        ix = np.ix_(dofs, dofs)
        out = ReducedOperator(
            [A.sub(dofs) if hasattr(A, "sub") else np.ascontiguousarray(A[ix])
             for A in self.mats], self.coef,
            [None if u is None else np.ascontiguousarray(u[dofs]) for u in self.U],
            [None if y is None else np.ascontiguousarray(y[:, dofs]) for y in self.Y],
            self.symmetric, self.cut(dofs, dofs))
        out._cut_of = (self, dofs)
        return out

    def single(self, compress: float | None = None) -> ReducedOperator:
        """This operator in single precision: the stored matrices in float32, the low-rank
        factors in float32 or complex64, no compressed forms; its products are those of
        this operator to single precision (about ``1e-7`` relative), at half the memory
        traffic (:meth:`matmat` multiplies in the matrices' precision). For products whose
        accuracy needs no more: GMRES on a loosely solved Newton step
        (:class:`fretwear.hb.options.KrylovOptions`).

        ``compress`` (a relative error, with :attr:`coords` known and no ``products``):
        the stored matrices instead compressed (:func:`fretwear.hb.hmatrix.compress` to
        ``compress``) and held in float32 (:meth:`HMatrix.astype`): products below
        ``m^2`` per column whose matrices differ from ``mats`` by at most their stated
        errors (``error``: the compression's plus float32's rounding, relative Frobenius;
        :meth:`compressed_error`). The compressed matrices are made once and kept in
        :attr:`twins` (shared with every operator on the same matrices); a sub-operator's
        are those of the operator it was cut from, cut (:meth:`HMatrix.sub`)."""
        def one(a):
            if a is None:
                return None
            return np.asarray(a, np.complex64 if np.iscomplexobj(a) else np.float32)

        U, Y = [one(u) for u in self.U], [one(y) for y in self.Y]
        if compress is not None and self.products is None:
            mats = self._compressed_twin(float(compress))
            if mats is not None:
                return ReducedOperator(mats, self.coef, U, Y, self.symmetric)
        return ReducedOperator([one(A) for A in self.mats], self.coef, U, Y, self.symmetric)

    def _compressed_twin(self, tol: float) -> list | None:
        """The float32 compressed forms of :attr:`mats` to ``tol`` (:meth:`single`), made
        once (kept in :attr:`twins`), or None without :attr:`coords`."""
        if self._cut_of is not None:
            parent, dofs = self._cut_of
            full = parent._compressed_twin(tol)
            return None if full is None else [A.sub(dofs) for A in full]
        if self.coords is None:
            return None
        from fretwear.hb import hmatrix

        key = (tuple(id(A) for A in self.mats), tol)
        if key not in self.twins:
            self.twins[key] = [hmatrix.compress(A, self.coords, tol, leaf=hmatrix.LEAF)
                               .astype(np.float32) for A in self.mats]
        return self.twins[key]

    def compressed_error(self) -> float:
        """The largest stated relative error of the compressed stored matrices (those of a
        compressed twin, :meth:`single`), 0 for dense ones."""
        return max([float(getattr(A, "error", 0.0)) for A in self.mats], default=0.0)

    def cut(self, rows: np.ndarray, cols: np.ndarray):
        """The compressed forms (``products``) restricted to ``rows`` and ``cols``, or
        None."""
        if self.products is None:
            return None
        return [p.sub(rows, cols) for p in self.products]

    def matmat(self, blocks, X: np.ndarray, transpose: bool = False) -> np.ndarray:
        """``Z_r(n_b) X[:, j]`` for the column ``j`` of ``X`` (m, r) on block ``blocks[j]``
        (r,): each stored matrix is read once for all columns. ``transpose``: with
        ``Z_r(n_b)^T`` (``Z_r(n_b)^H`` of a conjugated ``X`` for a damped structure is the
        caller's). With ``products``, those are multiplied instead of ``mats``."""
        blocks = np.asarray(blocks, dtype=np.int64)
        cplx = np.iscomplexobj(X) or not self.real
        rows = self.mats[0].shape[1 if transpose else 0]  # a sub-block may be rectangular
        out = np.zeros((rows, X.shape[1]), dtype=complex if cplx else float)
        for t, A in enumerate(self.mats if self.products is None else self.products):
            c = self.coef[blocks, t]
            if not np.any(c):
                continue
            At = A.T if transpose and not self.symmetric else A
            Xc = X * c[None, :]
            if getattr(A, "dtype", None) == np.float32:  # (single(): not A upcast to X's)
                Xc = Xc.astype(np.complex64 if np.iscomplexobj(Xc) else np.float32)
            out += _times(At, Xc)
        for b in np.unique(blocks):
            if self.U[b] is None:
                continue
            j = np.flatnonzero(blocks == b)
            U, Y = self.U[b], self.Y[b]
            if transpose and not self.symmetric:
                U, Y = Y.T, U.T
            out[:, j] -= U @ (Y @ X[:, j])
        return out
