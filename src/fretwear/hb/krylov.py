"""The DLFT Jacobian as an operator, for interfaces with many contact nodes (docs/theory.md,
"Large interfaces").

After condensation the linear part of the balance is block-diagonal per harmonic (dense
``m x m`` complex blocks ``Z_r(n w)``, eq. 19) and the contact part is block-diagonal per node
(dense ``dH x dH`` blocks ``G_p = d lambda_x~_p / d lambda_u~_p``, eq. 23-28). The Jacobian
``J = eps I - G (eps I - Z)`` (eq. 22) of ``n = m H`` unknowns is never formed: a product with
it costs ``k m^2`` complex operations (the harmonic blocks) plus ``nc (dH)^2`` (the node
blocks), against ``n^2`` memory and ``n^3 / 3`` operations for a dense LU.

The Newton step ``J s = -f`` is reduced to the nodes that slip or separate during the period
(a node that sticks all period has ``G_p = 0``: its unknowns follow from its rows ``eps I``)
and the active system is solved by a LAPACK LU when it is small, else by GMRES preconditioned
with per-harmonic factorisations of the active block: replacing each node's time-varying gain
by its mean over the period (``gbar_p``, the (0, 0) coefficient block of ``G_p``) makes it
block-diagonal per harmonic, ``P_n = eps I + gbar (Z_aa(n w) - eps I)`` (``gbar``
block-diagonal per node), so the preconditioner is ``k + 1`` dense LUs of ``m_a x m_a``
(``m_a`` = active DOFs; in single precision by default,
:class:`fretwear.hb.options.KrylovOptions`). It is exact for
nodes whose gain does not vary over the period and for a linear interface; it is kept
while the active set does not change and rebuilt when GMRES slows down. Its sharing test
multiplies by the blocks without forming them (``block_products``, the later harmonics'
probes in one product per step): a block is formed only to be factored, in one compiled
pass from the whole block and the active rows into the factors' type and layout
(:func:`_gain_block`). On large active sets it is followed by a node-local correction
(:func:`node_local_inverse`, ``KrylovOptions.node_correction``): ``Q = eps I + G (Z_D - eps
I)`` with each node's own blocks of ``Z~``, exact in the coupling of a node's harmonics by
its time-varying gain, which the mean gain drops; the two combined multiplicatively halved
the GMRES iterations of the partial-slip pad (docs/studies/large-interface-solve.md, "The
preconditioner's builds and a node-local correction"). GMRES's products on loosely solved
steps go through a single-precision twin of ``Z`` (``KrylovOptions.single_products``), on
large interfaces a compressed one (``KrylovOptions.compressed_products_min_dofs``,
:func:`twin_tolerance`: hierarchical low-rank blocks in float32, products below ``m^2``);
the residual keeps the exact operator. The contact law and
the residual are those of the dense path: only the linear algebra of the step differs, so
the converged answer is the same (tests/hb/test_krylov.py).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse.linalg as spla
from numba import njit, types
from numba.extending import intrinsic

from fretwear.hb.solvers import KRYLOV

#: relative residual to which GMRES solves the Newton step (the dense LU is exact to rounding;
#: an inexact step changes the iterates, not the converged answer, which the residual test of
#: the nonlinear solver decides)
GMRES_RTOL = 1e-10
#: power-iteration steps that estimate how well one harmonic's preconditioner factors serve
#: another, and the estimate below which they are shared (MeanGainPreconditioner._close)
SHARE_PROBES = 2
SHARE_BELOW = 0.25
#: Krylov vectors kept before a restart, and restarts allowed
GMRES_RESTART = 60
GMRES_MAXITER = 4
#: a kept preconditioner is rebuilt from the current Jacobian when GMRES needs more than
#: REBUILD_AFTER iterations and more than REBUILD_GROWTH times those of its first run (in
#: partial slip a fresh one needs 30-45 iterations, and one kept over the Newton steps of a
#: solve about as many: docs/studies/large-interface-solve.md)
REBUILD_AFTER = 25
REBUILD_GROWTH = 2.0
#: the step is solved by a LAPACK LU of the active block up to this many unknowns (slipping
#: or separating nodes x d x H), by GMRES above (docs/theory.md, "Large interfaces")
ACTIVE_DENSE_MAX = 3000
#: the compressed twin of GMRES's products (KrylovOptions.compressed_products_min_dofs) is
#: compressed to this fraction of the smallest GMRES rtol it serves (:func:`twin_tolerance`)
TWIN_MARGIN = 1e-2
#: rows of a block formed at a time by :meth:`KrylovJacobian.column_norms` (an operator's
#: blocks, hb/operator_blocks.py: a panel of 2.4 MB at 1024 contact nodes, reused, in place of
#: a fresh m x m block per harmonic)
COLUMN_NORM_PANEL = 96
#: from this fraction of the DOFs active (but not all), the active blocks of an operator
#: (hb/operator_blocks.py) are a view (:class:`_ActiveView`: products through the whole
#: operator) instead of copies of its m x m matrices (2 x 1.125 GiB at 4096 contact nodes);
#: a product costs at most (1 / 0.75)^2 = 1.8 times the copy's
VIEW_FRACTION = 0.75
#: rows of the preconditioner's block formed at a time by :func:`_gain_block` before they are
#: written column by column (a buffer of 16 x 3054 doubles, 0.4 MB, at 1024 contact nodes)
GAIN_ROWS = 16


@njit(cache=True)
def _gram_quad(Are, Aim, rows, M, c0, c1, out):
    """``out[t, c - c0] += sum_p x_pc^T M[t, p] x_pc`` for the columns ``c0 <= c < c1`` of a
    block, where ``x_pc`` (r,) holds the block's entries in the rows ``rows[p]`` (d,) of
    node ``p``: ``Are[rows[p], c]`` if ``r = d``, followed by ``Aim[rows[p], c]`` if
    ``r = 2 d`` (the real and imaginary parts of a complex block). One pass over the rows,
    without the copies and the ``(na, r, ncol)`` product of the batched NumPy form; the
    nodes in order, so that a block's rows taken panel by panel (:meth:`KrylovJacobian.
    column_norms`) sum as in one call."""
    nt, na, r, _ = M.shape
    d = rows.shape[1]
    x = np.empty(r)
    for p in range(na):
        for c in range(c0, c1):
            for i in range(d):
                x[i] = Are[rows[p, i], c]
                if r > d:
                    x[d + i] = Aim[rows[p, i], c]
            for t in range(nt):
                acc = 0.0
                for i in range(r):
                    s = 0.0
                    for j in range(r):
                        s += M[t, p, i, j] * x[j]
                    acc += x[i] * s
                out[t, c - c0] += acc
    return out


@njit(cache=True)
def _gram_quad_real3(A, rows, M, c0, c1, out):
    """:func:`_gram_quad` for a real block and 3 DOFs per node (3D), the common case of
    large interfaces: the symmetric form ``sum_ij M_ij x_i x_j`` with its six coefficients
    taken out of the loop over the columns (five times faster)."""
    nt, na = M.shape[0], M.shape[1]
    for p in range(na):
        r0, r1, r2 = A[rows[p, 0]], A[rows[p, 1]], A[rows[p, 2]]
        for t in range(nt):
            m00, m11, m22 = M[t, p, 0, 0], M[t, p, 1, 1], M[t, p, 2, 2]
            m01 = M[t, p, 0, 1] + M[t, p, 1, 0]
            m02 = M[t, p, 0, 2] + M[t, p, 2, 0]
            m12 = M[t, p, 1, 2] + M[t, p, 2, 1]
            o = out[t]
            for c in range(c0, c1):
                a, b, e = r0[c], r1[c], r2[c]
                o[c - c0] += (m00 * a * a + m11 * b * b + m22 * e * e + m01 * a * b
                              + m02 * a * e + m12 * b * e)
    return out


@intrinsic
def _fma(typingctx, a, b, c):
    """``a b + c`` rounded once (LLVM's ``fma``), for float64 arguments."""
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        return builder.fma(*args)

    return sig, codegen


@njit(cache=True)
def _gain_block(Zb, rows, gbar, eps, out):
    """``out = eps I + gbar (Z - eps I)`` (:meth:`MeanGainPreconditioner._block`) with
    ``Z = Zb[rows][:, rows]`` (``Zb`` real (M, M), ``rows`` (m,); ``gbar`` (nc, d, d), m = nc
    d), formed in one pass into ``out`` (m, m) of its own type (float32 for single factors)
    and layout (Fortran order: LAPACK factors it in place): no gathered copy of the block,
    no double ``P`` and no cast or copy after. Each entry in double, with the operations of
    the NumPy form (the ``d``-term product as BLAS forms it, the first product rounded, then
    fused multiply-adds; then ``- eps gbar`` on a node's own block, ``+ eps`` on the
    diagonal), so that ``out`` is that form's ``P`` rounded to its type (tests/hb/
    test_krylov.py). The rows of a few nodes at a time (:data:`GAIN_ROWS`) are formed in
    a buffer and written column by column: contiguous in Fortran order."""
    nc, d = gbar.shape[0], gbar.shape[1]
    m = rows.size
    per = max(1, GAIN_ROWS // d)  # nodes per buffer
    acc = np.empty((per * d, m))
    for p0 in range(0, nc, per):
        p1 = min(p0 + per, nc)
        for p in range(p0, p1):
            for i in range(d):
                a = (p - p0) * d + i
                g = gbar[p, i, 0]
                z = Zb[rows[p * d]]
                t = acc[a]
                for c in range(m):
                    t[c] = g * z[rows[c]]
                for j in range(1, d):
                    g = gbar[p, i, j]
                    z = Zb[rows[p * d + j]]
                    for c in range(m):
                        t[c] = _fma(g, z[rows[c]], t[c])
                for j in range(d):
                    t[p * d + j] = t[p * d + j] - eps * gbar[p, i, j]
                t[p * d + i] = t[p * d + i] + eps
        r0, nr = p0 * d, (p1 - p0) * d
        for c in range(m):
            for a in range(nr):
                out[r0 + a, c] = acc[a, c]
    return out

class HarmonicBlocks:
    """``Z~`` of the real Fourier basis held as its complex per-harmonic blocks (nb, m, m).

    Products follow :func:`fretwear.hb.reduce.to_real_blocks` (harmonic ``n >= 1`` maps
    ``[a; b]`` by ``[[Zr, Zi], [-Zi, Zr]]``) on DOF-major ``(m, H)`` arrays, without the
    ``(mH)^2`` real matrix.
    """

    def __init__(self, Zc: np.ndarray):
        self.Zc = np.ascontiguousarray(Zc)
        self.nb, self.m, _ = Zc.shape
        self.k = self.nb - 1
        self.H = 1 + 2 * self.k
        self.Z0 = np.ascontiguousarray(Zc[0].real)
        self._ZcH = None
        self._symmetric = None
        self._real = None
        self._Zr = None

    @property
    def real(self) -> bool:
        """Whether every block is real (an undamped structure: ``Z_n = K - (n w)^2 M``).
        Products, factorisations and column norms then use real arithmetic on the real
        blocks (:attr:`Zr`): half the memory traffic of the complex products and a quarter
        of the operations of a complex LU, with the same result to rounding."""
        if self._real is None:
            self._real = not np.iscomplexobj(self.Zc) or not np.any(self.Zc.imag)
        return self._real

    @property
    def Zr(self) -> np.ndarray:
        """The real blocks (nb, m, m) of a real operator (:attr:`real`), copied once."""
        if self._Zr is None:
            self._Zr = (self.Zc if not np.iscomplexobj(self.Zc)
                        else np.ascontiguousarray(self.Zc.real))
        return self._Zr

    def block(self, b: int) -> np.ndarray:
        """Block ``b`` as the products use it: real (:attr:`Zr`) when :attr:`real`."""
        return self.Zr[b] if self.real else self.Zc[b]

    def block_source(self, b: int) -> tuple[np.ndarray, np.ndarray]:
        """``(A, r)`` with block ``b`` (as :meth:`block`, ``Z0`` for 0) equal to ``A[r][:, r]``:
        the block itself and every row here; an active view gives its operator's block and
        its DOFs (:class:`MeanGainPreconditioner` forms ``P_b`` from it without a copy)."""
        return (self.Z0 if b == 0 else self.block(b)), np.arange(self.m)

    def row_block(self, b: int, dofs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(A, r)`` with row ``r[i]`` of ``A`` the row ``dofs[i]`` of block ``b`` (as
        :meth:`block`): the stored block and ``dofs`` themselves here; an operator forms
        only those rows."""
        return (self.Z0 if b == 0 else self.block(b)), np.asarray(dofs)

    def row_panel(self, b: int, dofs: np.ndarray, buf: np.ndarray):
        """As :meth:`row_block`, for a panel of rows taken in turn (the column norms): the
        stored block here (``buf`` unused); an operator forms the panel into ``buf``."""
        return self.row_block(b, dofs)

    def block_products(self, blocks, V: np.ndarray) -> np.ndarray:
        """``Z_b V[:, j]`` with ``b = blocks[j]`` (``Z_0`` its real part, as :attr:`Z0`;
        real or complex ``V`` (m, r)): (m, r), complex where a block or ``V`` is. The
        stored blocks here; an operator multiplies without forming them (the sharing
        test of :class:`MeanGainPreconditioner`)."""
        cols = [(self.Z0 if b == 0 else self.block(b)) @ V[:, j] for j, b in enumerate(blocks)]
        return np.stack(cols, axis=1)

    def node_diagonal(self, b: int, d: int) -> np.ndarray:
        """The (m / d, d, d) diagonal node blocks of block ``b`` (as :meth:`block`)."""
        Zb = self.Z0 if b == 0 else self.block(b)
        nc = self.m // d
        idx = np.arange(nc)
        return Zb.reshape(nc, d, nc, d)[idx, :, idx, :]

    def single(self, compress: float | None = None):
        """The blocks in single precision for GMRES's loose products (``compress``: their
        matrices compressed to that relative error), or None: stored blocks keep their one
        (double) copy (an operator's, hb/operator_blocks.py, have one)."""
        return None

    def leading(self, nb: int) -> HarmonicBlocks:
        """The blocks of the first ``nb`` harmonics, sharing this object's arrays (and its
        real copies)."""
        out = HarmonicBlocks(self.Zc[:nb])
        out._real = self.real
        if self.real:
            out._Zr = self.Zr[:nb]
        return out

    def sub(self, dofs: np.ndarray) -> HarmonicBlocks:
        """The blocks restricted to the rows and columns ``dofs`` (real when these are); this
        object itself when ``dofs`` are all its DOFs in order (every node active: no copy)."""
        if dofs.size == self.m and np.array_equal(dofs, np.arange(self.m)):
            return self
        src = self.Zr if self.real else self.Zc
        out = np.empty((self.nb, dofs.size, dofs.size), dtype=src.dtype)
        for b in range(self.nb):  # rows then columns: 40 % faster than z[np.ix_(...)]
            out[b] = np.take(np.take(src[b], dofs, axis=0), dofs, axis=1)
        return HarmonicBlocks(out)

    def _apply(self, Z0, Zc, U, conj=False):
        U = U.reshape(self.m, self.H)
        k = self.k
        out = np.empty((self.m, self.H))
        out[:, 0] = Z0 @ U[:, 0]
        if k and self.real:  # conj(Z) = Z: U_n = a_n - i b_n by two real columns
            ab = np.stack([U[:, 1 : k + 1].T, U[:, k + 1 :].T], axis=2)  # (k, m, 2)
            y = np.matmul(self.Zr[1:] if Zc is self.Zc else Zc[1:], ab)  # Z a, Z b
            out[:, 1 : k + 1] = y[:, :, 0].T
            out[:, k + 1 :] = y[:, :, 1].T
        elif k:
            c = (U[:, 1 : k + 1] - 1j * U[:, k + 1 :]).T  # (k, m): U_n = a_n - i b_n
            if conj:  # conj(Z) c = conj(Z conj(c))
                y = np.conj(np.matmul(Zc[1:], np.conj(c)[:, :, None])[:, :, 0])
            else:
                y = np.matmul(Zc[1:], c[:, :, None])[:, :, 0]  # (k, m)
            out[:, 1 : k + 1] = y.real.T
            out[:, k + 1 :] = -y.imag.T
        return out

    def apply(self, U) -> np.ndarray:
        """``Z~ U`` (m, H) for ``U`` (m, H) or (m*H,)."""
        return self._apply(self.Z0, self.Zc, U)

    def symmetric(self) -> bool:
        """Whether every block is complex symmetric (symmetric ``K, M, C, D``): then
        ``Z_n^H = conj(Z_n)`` and no transposed copy is needed."""
        if self._symmetric is None:
            self._symmetric = all(_symmetric(z) for z in (self.Zr if self.real else self.Zc))
        return self._symmetric

    def apply_sub(self, rows: np.ndarray, cols: np.ndarray, U: np.ndarray) -> np.ndarray:
        """``(Z~ U)`` on the DOFs ``rows`` for ``U`` (len(cols), H, r) non-zero on the DOFs
        ``cols`` only (several right-hand sides): (len(rows), H, r). Harmonics on which ``U``
        vanishes are skipped."""
        k, r = self.k, U.shape[2]
        out = np.zeros((rows.size, self.H, r))
        if not (rows.size and cols.size):
            return out
        if np.any(U[:, 0]):
            out[:, 0] = self.Z0[np.ix_(rows, cols)] @ U[:, 0]
        for b in range(1, k + 1):
            if not (np.any(U[:, b]) or np.any(U[:, k + b])):
                continue
            Zs = self.block(b)[np.ix_(rows, cols)]
            if self.real:
                out[:, b], out[:, k + b] = Zs @ U[:, b], Zs @ U[:, k + b]
            else:
                y = Zs @ (U[:, b] - 1j * U[:, k + b])
                out[:, b], out[:, k + b] = y.real, -y.imag
        return out

    def node_rows(self, V: np.ndarray) -> np.ndarray:
        """``sum_i V[p, i] Z~[p dH + i, :]`` for every node ``p``: (nc, m H) from ``V``
        (nc, d H) (node-major rows ``(DOF, coefficient)``; the node blocks of a row vector
        times ``Z~``, e.g. the wear rate's gradient), ``(k + 1) m^2`` operations instead of
        the ``(m H)^2`` real matrix."""
        m, H, k = self.m, self.H, self.k
        nc = V.shape[0]
        d = m // nc
        V = V.reshape(nc, d, H)
        out = np.empty((nc, m, H))
        out[:, :, 0] = np.einsum("pi,pij->pj", V[:, :, 0], self.Z0.reshape(nc, d, m))
        for b in range(1, k + 1):
            # row (r, a_n) of Z~ is [Re Z_n, Im Z_n], row (r, b_n) is [-Im Z_n, Re Z_n]:
            # (V_a + i V_b) Z_n gives the a-columns in its real part, the b-columns in its
            # imaginary part
            # (:meth:`block`: a stored block, or one formed in turn by an operator's blocks)
            Zb = self.block(b).reshape(nc, d, m)
            if self.real:
                out[:, :, b] = np.einsum("pi,pij->pj", V[:, :, b], Zb)
                out[:, :, k + b] = np.einsum("pi,pij->pj", V[:, :, k + b], Zb)
                continue
            y = np.einsum("pi,pij->pj", V[:, :, b] + 1j * V[:, :, k + b], Zb)
            out[:, :, b], out[:, :, k + b] = y.real, y.imag
        return out.reshape(nc, m * H)

    def apply_T(self, U) -> np.ndarray:
        """``Z~^T U`` (m, H): the real form of the conjugate transposes ``Z_n^H``."""
        if self.symmetric():
            return self._apply(self.Z0, self.Zc, U, conj=True)
        if self._ZcH is None:
            src = self.Zr if self.real else self.Zc
            self._ZcH = np.ascontiguousarray(np.conj(np.transpose(src, (0, 2, 1))))
        return self._apply(np.ascontiguousarray(self.Z0.T), self._ZcH, U)

    def dense(self) -> np.ndarray:
        """The real (mH, mH) matrix (:func:`fretwear.hb.reduce.to_real_blocks`)."""
        from fretwear.hb.reduce import to_real_blocks

        return to_real_blocks(self.Zc, np.arange(self.nb))


#: rows and columns of the tiles :func:`_symmetric` compares
TILE = 512


def _symmetric(z: np.ndarray, rel: float = 1e-13) -> bool:
    """Whether ``|z - z^T| <= rel max|z|`` entry by entry (NaN: not symmetric), compared tile
    against transposed tile (:data:`TILE`), so that no temporary of the size of ``z`` is
    made: ``np.allclose`` on the whole blocks took 7.8 s CPU of the 58 s solve of
    benchmarks/scale_3d.py's 1024 contact nodes (eight 3072 x 3072 blocks)."""
    m = z.shape[0]
    diff, top = 0.0, 0.0
    for i in range(0, m, TILE):
        ri = slice(i, min(i + TILE, m))
        for j in range(i, m, TILE):
            rj = slice(j, min(j + TILE, m))
            a, b = z[ri, rj], z[rj, ri]
            with np.errstate(invalid="ignore"):  # inf - inf: NaN, refused below
                now = (float(np.abs(a - b.T).max()), float(np.abs(a).max()),
                       float(np.abs(b).max()))
            if not np.all(np.isfinite(now)):  # (Python's max() would drop a NaN)
                return False
            diff, top = max(diff, now[0]), max(top, now[1], now[2])
    return diff <= rel * max(top, 1e-300)


def harmonic_gains(G: np.ndarray, d: int, oscillating: bool = True):
    """The gains of :class:`MeanGainPreconditioner` from the node blocks ``G`` (nc, dH, dH):
    ``gbar`` (nc, d, d), the (0, 0) coefficient block (the response of the mean correction to
    the mean of ``lambda_u``), the gain of harmonic 0; and ``gosc`` (nc, d, d), the gain of
    the harmonics ``n >= 1``: the mean over them of the diagonal blocks
    ``(G_p[a_n, a_n] + G_p[b_n, b_n]) / 2`` (the response of harmonic ``n`` to itself), or
    ``gbar`` itself unless ``oscillating``.

    The two differ where a node slips during part of the period only (partial slip, the
    fretting case): the derivative of the law (eq. 27-28) is then a sample and hold,
    ``lambda_x,T`` following ``lambda_u,T`` at the slip instants and keeping its value while
    the node sticks. A constant change of ``lambda_u,T`` passes whole (``gbar`` = 1 in the
    slip direction), an oscillating one only through its samples at the slip instants (the
    diagonal blocks well below 1): the mean gain alone treats the oscillating harmonics of
    such nodes as if they slipped all period. Measured (docs/studies/
    large-interface-solve.md): GMRES iterations from 214 to 41 on the 256-node pad in partial
    slip, from 35 to 2 on the benchmark's mostly stuck pad. Where the whole interface slides
    or lifts (a 25-node block in gross slip and separation) the mean gain served better (280
    iterations against no convergence in 480): :meth:`KrylovJacobian._gmres` falls back to
    it when GMRES fails with the oscillating gains."""
    nc, dH, _ = G.shape
    H = dH // d
    k = (H - 1) // 2
    Gr = G.reshape(nc, d, H, d, H)
    gbar = np.ascontiguousarray(Gr[:, :, 0, :, 0])
    if not k or not oscillating:
        return gbar, gbar
    gosc = np.zeros_like(gbar)
    for b in range(1, 2 * k + 1):
        gosc += Gr[:, :, b, :, b]
    return gbar, gosc / (2 * k)


def node_local_inverse(G: np.ndarray, diag: list, eps: float) -> np.ndarray | None:
    """``Q^-1`` (na, dH, dH) of the node-local part of the Jacobian, ``Q = eps I + G
    (Z_D - eps I)``, with ``Z_D`` the diagonal node blocks of ``Z~`` (each node's own ``d x
    d`` block of every harmonic, ``diag[b]`` (na, d, d), on the real Fourier basis:
    :func:`_node_diagonal_real`) and ``G`` (na, dH, dH) the node blocks of the law (eq.
    22-28). ``Q`` is exact in what :class:`MeanGainPreconditioner` drops, the coupling of a
    node's harmonics by its time-varying gain, and drops what that keeps, the coupling of
    the nodes through ``Z``: the two combined (:meth:`KrylovJacobian._node_correction`)
    halved the GMRES iterations of the partial-slip pad (docs/studies/
    large-interface-solve.md, "The preconditioner's builds and a node-local correction").
    None where a ``Q`` is singular or not finite."""
    na, dH, _ = G.shape
    d = diag[0].shape[1]
    W = _node_diagonal_real(diag, d, dH // d)
    W[:, np.arange(dH), np.arange(dH)] -= eps
    Q = np.matmul(G, W)
    Q[:, np.arange(dH), np.arange(dH)] += eps
    try:
        Qi = np.linalg.inv(Q)
    except np.linalg.LinAlgError:
        return None
    return Qi if np.all(np.isfinite(Qi)) else None


def _node_diagonal_real(diag: list, d: int, H: int) -> np.ndarray:
    """``Z~_D`` (na, dH, dH): the diagonal node blocks ``diag[b]`` (na, d, d) of every
    harmonic on the real Fourier basis (harmonic ``n`` maps ``(a_n, b_n)`` by ``[[X, Y], [-Y,
    X]]``, ``Z_n = X + i Y``, as :func:`fretwear.hb.reduce.to_real_blocks`)."""
    na = diag[0].shape[0]
    k = (H - 1) // 2
    W = np.zeros((na, d, H, d, H))
    W[:, :, 0, :, 0] = diag[0].real
    for b in range(1, k + 1):
        X = diag[b].real
        W[:, :, b, :, b] = X
        W[:, :, k + b, :, k + b] = X
        if np.iscomplexobj(diag[b]):
            Y = diag[b].imag
            W[:, :, b, :, k + b] = Y
            W[:, :, k + b, :, b] = -Y
    return W.reshape(na, d * H, d * H)


def _step_operator(Z, G, eps, na, dH):
    """``v -> J_aa v = eps v + G_a (Z_aa v - eps v)`` (eq. 22 on the active nodes) for
    GMRES: ``Z`` the active blocks (``apply``), ``G`` the active node blocks (na, dH,
    dH)."""

    def matvec(v):
        v = np.asarray(v, float).reshape(-1)
        y = (Z.apply(v).reshape(-1) - eps * v).reshape(na, dH)
        return eps * v + np.matmul(G, y[:, :, None])[:, :, 0].reshape(-1)

    return matvec


def _lu_solve(lu, b):
    """``P^-1 b`` by LAPACK factors ``lu``, in their precision (single factors,
    ``KrylovOptions.single_factors``: the right-hand side rounded to the single type of the
    factors and of ``b`` together, the result returned in double, complex where either
    is)."""
    if lu[0].dtype not in (np.float32, np.complex64):
        return sla.lu_solve(lu, b, check_finite=False)
    kind = np.result_type(lu[0].dtype, np.complex64 if np.iscomplexobj(b) else np.float32)
    return sla.lu_solve(lu, np.asarray(b, kind), check_finite=False).astype(
        np.result_type(kind, np.float64))


class MeanGainPreconditioner:
    """``P^-1`` with ``P_n = eps I + g_n (Z_n - eps I)`` per harmonic (module docstring).

    gbar : (nc, d, d) mean gain of each node over the period (the (0, 0) coefficient block of
    ``G_p``), the gain ``g_0`` of harmonic 0; gosc : (nc, d, d) the gain ``g_n`` of the
    harmonics ``n >= 1`` (:func:`harmonic_gains`; default ``gbar``); Z :
    :class:`HarmonicBlocks`; share : let a harmonic use the factors of the last factored one
    when they precondition it well (:meth:`_close`): below the structure's first resonances
    ``Z_n`` hardly differs from ``Z_0`` (``-(n w)^2 M_r`` against the stiffness) and one LU
    serves several harmonics. A rebuild after a GMRES failure does not share. single :
    the factors in single precision (``KrylovOptions.single_factors``; a rebuild after a GMRES
    failure or a slow GMRES run
    factors in double).
    """

    def __init__(self, gbar: np.ndarray, Z: HarmonicBlocks, eps: float, share: bool = True,
                 gosc: np.ndarray | None = None, single: bool = False):
        self.k, self.m, self.H = Z.k, Z.m, Z.H  # (no reference to Z: kept across sweeps)
        self.single = single
        gosc = gbar if gosc is None else gosc
        self.factors = []  # per harmonic block: LAPACK LU of P_n or of a close P_b
        self.shared = 0
        last = None  # (b, g_b, its LU) of the last factored harmonic
        # blocks held as an operator (hb/operator_blocks.py) bound the factors' memory: past
        # the bound every further harmonic shares the last factors
        budget = getattr(Z, "factor_budget", None)
        most = Z.nb if budget is None else max(1, int(budget // (8 * Z.m * Z.m)))
        probe = {}  # the sharing test's first products, made once (_close_all)
        close = {}  # the sharing test's answers for the last factors, made at once
        for b in range(Z.nb):
            full = last is not None and len({id(f) for f in self.factors}) >= most
            if full:  # (the block is not formed: m^2 memory and time for nothing)
                self.factors.append(last[2])
                self.shared += 1
                continue
            g = gbar if b == 0 else gosc
            # (the test by products: a block is formed only to be factored; the harmonics
            # after b that take the same gain are tested with it, against the same factors)
            if share and last is not None and b not in close:
                later = [n for n in range(b, Z.nb) if (gbar if n == 0 else gosc) is g]
                close = self._close_all(g, later, last, eps, Z, probe)
            if share and last is not None and close[b]:
                self.factors.append(last[2])
                self.shared += 1
                continue
            P = self._gain_block(g, Z, b, eps, single)
            lu = sla.lu_factor(P, overwrite_a=True, check_finite=False)
            self.factors.append(lu)
            last = (b, g, lu)
            close = {}  # (answers for the factors before)
        # the harmonics of each set of factors, solved together by apply()
        groups: dict = {}
        for b, lu in enumerate(self.factors):
            groups.setdefault(id(lu), (lu, []))[1].append(b)
        self.groups = list(groups.values())

    @staticmethod
    def _block(gbar, Zn, eps):
        """``eps I + gbar (Z_n - eps I)`` with ``gbar`` applied node block by node block
        (``d m^2`` operations, not the ``m^3`` of a dense product)."""
        nc, d, _ = gbar.shape
        m = Zn.shape[0]
        P = np.matmul(gbar, Zn.reshape(nc, d, m)).reshape(m, m)
        idx = np.arange(nc)
        P.reshape(nc, d, nc, d)[idx, :, idx, :] -= eps * gbar
        P[np.diag_indices(m)] += eps
        return P

    @classmethod
    def _gain_block(cls, g, Z, b, eps, single):
        """``P_b`` (:meth:`_block`) of the gain ``g``, in single precision if ``single``:
        on real blocks by the compiled :func:`_gain_block` from the block's source
        (``Z.block_source``: an active view's whole block and its rows, no gathered copy),
        else by :meth:`_block` and a cast."""
        if Z.real and hasattr(Z, "block_source"):
            src, rows = Z.block_source(b)
            # the kernel does not check bounds: the gains must cover the block's rows
            if not (g.shape[0] * g.shape[1] == rows.size == Z.m and src.ndim == 2
                    and src.shape[0] == src.shape[1] and rows.max(initial=-1) < src.shape[0]):
                raise ValueError(f"gains of {g.shape[0]} x {g.shape[1]} DOFs for a block of "
                                 f"{rows.size} rows of {Z.m}")
            P = np.empty((Z.m, Z.m), dtype=np.float32 if single else np.float64, order="F")
            return _gain_block(src, np.ascontiguousarray(rows, dtype=np.int64),
                               np.ascontiguousarray(g, dtype=np.float64), float(eps), P)
        P = cls._block(g, Z.Z0 if b == 0 else Z.block(b), eps)
        if single:
            P = P.astype(np.complex64 if np.iscomplexobj(P) else np.float32)
        return P

    @staticmethod
    def _solve(lu, b):
        """``P^-1 b`` by the factors ``lu`` (``b`` (m,) or (m, r)); a complex ``b`` with real
        factors as its real and imaginary parts (a mixed call would copy the factors to
        complex)."""
        if np.iscomplexobj(b) and not np.iscomplexobj(lu[0]):
            if b.ndim == 1:
                y = _lu_solve(lu, np.column_stack([b.real, b.imag]))
                return y[:, 0] + 1j * y[:, 1]
            r = b.shape[1]
            y = _lu_solve(lu, np.hstack([b.real, b.imag]))
            return y[:, :r] + 1j * y[:, r:]
        return _lu_solve(lu, b)

    @classmethod
    def _close(cls, gn, n, last, eps, Z, probe) -> bool:
        """Whether the factors of ``P_b`` (``last`` = ``(b, g_b, LU)``) precondition ``P_n``
        (gain ``gn``) well (:meth:`_close_all` for the one harmonic ``n``)."""
        return cls._close_all(gn, [n], last, eps, Z, probe)[n]

    @classmethod
    def _close_all(cls, gn, ns, last, eps, Z, probe) -> dict:
        """``{n: close}`` for the harmonics ``ns`` (of one gain ``gn``): whether the factors
        of ``P_b`` (``last`` = ``(b, g_b, LU)``) precondition ``P_n`` well: ``P_b^-1 P_n = I
        + E`` with ``E = P_b^-1 (P_n - P_b)``, which is ``P_b^-1 g (Z_n - Z_b)`` when both
        take the same gain ``g``, and GMRES on it converges about as fast as on ``I`` when
        ``E`` is small. Its size is estimated by :data:`SHARE_PROBES` steps of the power
        iteration from a fixed random vector (``2 SHARE_PROBES`` products and solves of
        ``m^2`` operations, against the ``m^3`` of an LU): shared when below
        :data:`SHARE_BELOW`. An isolated large eigenvalue of ``E`` that the probe misses
        costs GMRES about one iteration.

        The products ``Z_n v``, ``Z_b v`` are taken from ``Z`` (its ``block_products``)
        without forming the blocks: on an operator's blocks (hb/operator_blocks.py) a
        formed block costs several passes over ``m x m`` arrays and its page faults, a
        product one pass over the stored matrices. The first step's are made for every
        harmonic in one product, kept in ``probe`` (the same vector for all); each later
        step's for every harmonic of ``ns`` in one product and their solves in one call
        (each stored matrix and the factors read once per step, not once per harmonic)."""
        sizes = cls._probe_sizes(gn, ns, last, eps, Z, probe)
        return {n: bool(np.isfinite(x) and x <= SHARE_BELOW) for n, x in sizes.items()}

    @classmethod
    def _probe_sizes(cls, gn, ns, last, eps, Z, probe) -> dict:
        """``{n: size}``: the power estimate of ``|E|`` of :meth:`_close_all` for each
        harmonic of ``ns`` (the ratio of the norms of the last two iterates; 0 or not
        finite where an iterate vanished or overflowed)."""
        b, gb, lu = last
        nc, d, _ = gn.shape
        m = Z.m
        if not probe:
            v0 = np.random.default_rng(0).standard_normal(m)
            probe["v"] = v0
            probe["Zv"] = Z.block_products(np.arange(Z.nb), np.repeat(v0[:, None], Z.nb, 1))
        ns = list(ns)
        V = np.repeat(probe["v"][:, None], len(ns), 1)
        size = dict.fromkeys(ns, 0.0)
        going = list(range(len(ns)))  # columns of V still iterated
        for step in range(SHARE_PROBES):
            if not going:
                break
            if step == 0:
                zn = probe["Zv"][:, [ns[i] for i in going]]
                zb = np.repeat(probe["Zv"][:, [b]], len(going), 1)
            else:
                blocks = [x for i in going for x in (ns[i], b)]
                zz = Z.block_products(blocks, np.repeat(V[:, going], 2, axis=1))
                zn, zb = zz[:, 0::2], zz[:, 1::2]
            Vg = V[:, going]
            r = len(going)
            if gn is gb:
                y = np.matmul(gn, (zn - zb).reshape(nc, d, r))
            else:
                y = (np.matmul(gn, (zn - eps * Vg).reshape(nc, d, r))
                     - np.matmul(gb, (zb - eps * Vg).reshape(nc, d, r)))
            W = cls._solve(lu, y.reshape(m, r))
            if np.iscomplexobj(W) and not np.iscomplexobj(V):
                V = V.astype(W.dtype)
            kept = []
            for t, i in enumerate(going):
                w = W[:, t]
                size[ns[i]] = float(np.linalg.norm(w) / np.linalg.norm(V[:, i]))
                V[:, i] = w
                if np.isfinite(size[ns[i]]) and size[ns[i]] != 0.0:
                    kept.append(i)
            going = kept
        return size

    def apply(self, r) -> np.ndarray:
        """``P^-1 r``: the harmonics that share factors are solved together, one call with
        all their columns (the factors are read once)."""
        r = np.asarray(r).reshape(self.m, self.H)
        k = self.k
        out = np.empty_like(r)
        for lu, hs in self.groups:
            if not np.iscomplexobj(lu[0]):  # real P_n: P_n (a - i b) = P_n a - i P_n b
                cols = [c for b in hs for c in ([0] if b == 0 else [b, k + b])]
                out[:, cols] = _lu_solve(lu, r[:, cols])
                continue
            # complex factors (a damped harmonic; never harmonic 0, whose block is real)
            y = _lu_solve(lu, (r[:, hs] - 1j * r[:, [k + b for b in hs]]))
            out[:, hs], out[:, [k + b for b in hs]] = y.real, -y.imag
        return out.reshape(-1)


class KrylovJacobian:
    """``J = eps I - G (eps I - Z~)`` (eq. 22) as an operator: ``J @ x``, ``J.T @ x``,
    ``column_norms()`` (exact, from the block structure) and ``solve(b)`` (GMRES
    preconditioned by :class:`MeanGainPreconditioner`).

    G : (nc, dH, dH) node blocks (:func:`fretwear.hb.contact.dlft_jacobian`);
    Z : :class:`HarmonicBlocks`; owner : the object that keeps the preconditioner across
    Jacobians (its attribute ``_precond``, and ``_mean_gain`` once the oscillating gains of
    :func:`harmonic_gains` failed on it).
    """

    def __init__(self, G: np.ndarray, Z: HarmonicBlocks, eps: float, d: int, owner=None):
        self.G, self.Z, self.eps, self.d = G, Z, float(eps), d
        self.nc, self.dH = G.shape[0], G.shape[1]
        self.n = Z.m * Z.H
        self.shape = (self.n, self.n)
        self.owner = owner if owner is not None else self
        self.gmres_iterations = 0
        self.node_corrected = False  # the last GMRES step used the node-local correction

    # -- products -----------------------------------------------------------------------------
    def matvec(self, x) -> np.ndarray:
        x = np.asarray(x, float).reshape(-1)
        y = (self.Z.apply(x).reshape(-1) - self.eps * x).reshape(self.nc, self.dH)
        return self.eps * x + np.matmul(self.G, y[:, :, None])[:, :, 0].reshape(-1)

    def rmatvec(self, x) -> np.ndarray:
        x = np.asarray(x, float).reshape(-1)
        y = np.matmul(np.transpose(self.G, (0, 2, 1)),
                      x.reshape(self.nc, self.dH, 1))[:, :, 0].reshape(-1)
        return self.eps * x + self.Z.apply_T(y).reshape(-1) - self.eps * y

    def __matmul__(self, x):
        return self.matvec(x)

    @property
    def T(self):
        return _Transposed(self)

    def column_norms(self, chunk: int = 1024) -> np.ndarray:
        """Euclidean norm of every column of ``J`` (what MINPACK scales the variables by),
        exact: column ``(j, c)`` of ``Z~`` has non-zeros in the coefficients ``cs`` of its
        harmonic only, so ``|G Z~ e|^2 = sum_p z_p^T (G_p,cs^T G_p,cs) z_p`` with the small
        Gram matrices of the node blocks, plus the ``eps (I - G)`` term of the column's own
        node: ``4 d^2 nc n`` operations and no ``n x n`` intermediate. Only the rows of the
        active nodes enter the sums (the Gram matrices of the stuck nodes vanish), read in
        place by a compiled kernel (:func:`_gram_quad`); the own-node entries come from the
        diagonal node blocks. The real columns of harmonic ``n`` come from ``Re Z_n``,
        ``Im Z_n``, both columns ``(a_n, b_n)`` of a DOF from the same rows."""
        Z, G, eps, d = self.Z, self.G, self.eps, self.d
        H, nc, dH, m = Z.H, self.nc, self.dH, Z.m
        Gr = G.reshape(nc, dH, d, H)
        out = np.zeros((m, H))
        act = self.active_nodes()  # the Gram matrices of the stuck nodes vanish
        na = act.size
        rows = np.ascontiguousarray(act[:, None] * d + np.arange(d))  # (na, d)

        # the active rows formed panel by panel into one buffer (an operator's blocks)
        panel = max(1, min(na, COLUMN_NORM_PANEL // d))
        # (twice a panel's rows: a panel of active nodes with stuck ones between them)
        buf = np.empty((2 * panel * d, m), dtype=complex if not Z.real else float)
        for b in range(Z.nb):
            cs = [0] if b == 0 else [b, Z.k + b]
            nl = len(cs)
            Gs = np.ascontiguousarray(Gr[:, :, :, cs].reshape(nc, dH, d * nl))
            Ga = Gs[act]
            gram = np.matmul(np.transpose(Ga, (0, 2, 1)), Ga)  # (na, d nl, d nl)
            diag = Z.node_diagonal(b, d)  # every node's own d x d block (nc, d, d)
            if b == 0:
                M = gram[None]
            elif Z.real:
                # Im Z_n = 0: column (j, a_n) is (x, 0) and (j, b_n) is (0, x) in the
                # coefficient pairs, so only the (a, a) and (b, b) parts of the Gram matrix act
                g5 = gram.reshape(na, d, 2, d, 2)
                M = np.stack([g5[:, :, 0, :, 0], g5[:, :, 1, :, 1]])
            else:
                # in the order [Re rows; Im rows] of X = [x; y] (x = Re Z_n, y = Im Z_n):
                # column (j, a_n) has entries (x, -y), column (j, b_n) entries (y, x), both
                # interleaved per DOF in gram's order (DOF, coefficient)
                g5 = gram.reshape(na, d, 2, d, 2)
                A, B, D = g5[:, :, 0, :, 0], g5[:, :, 0, :, 1], g5[:, :, 1, :, 1]
                M = np.stack([np.block([[A, -B], [-np.transpose(B, (0, 2, 1)), D]]),
                              np.block([[D, np.transpose(B, (0, 2, 1))], [B, A]])])
            S = np.zeros((M.shape[0], m))  # sum over the active nodes, in their order
            for p0 in range(0, na, panel):
                ps = slice(p0, min(p0 + panel, na))
                # the block's rows of these active nodes (an operator forms only these)
                Zb, lrows = Z.row_panel(b, rows[ps].reshape(-1), buf)
                lrows = np.ascontiguousarray(np.reshape(lrows, (-1, d)))
                Mp = np.ascontiguousarray(M[:, ps])
                if d == 3 and not np.iscomplexobj(Zb):
                    _gram_quad_real3(Zb, lrows, Mp, 0, m, S)
                else:
                    Are, Aim = (Zb.real, Zb.imag) if np.iscomplexobj(Zb) else (Zb, Zb)
                    _gram_quad(Are, Aim, lrows, Mp, 0, m, S)
            for j0 in range(0, m, chunk):
                sl = slice(j0, min(j0 + chunk, m))
                js = np.arange(sl.start, sl.stop)
                sq = S[:, sl].T.copy()  # (ncol, nl)
                # + eps (I - G) on the owner's block: column (j, c) -> node j // d, row j%d, c
                q = js // d
                ci = np.arange(js.size)
                own = diag[q, :, js % d]  # (ncol, d): the column's entries at its node
                if b == 0:
                    zz = [own.real]
                else:
                    xo, yo = own.real, (own.imag if np.iscomplexobj(own)
                                        else np.zeros_like(own))
                    zz = [np.stack([xo, -yo], axis=2).reshape(js.size, d * nl),
                          np.stack([yo, xo], axis=2).reshape(js.size, d * nl)]
                for t, c in enumerate(cs):
                    row = (js % d) * H + c
                    g = np.einsum("cij,cj->ci", Gs[q], zz[t])  # (ncol, dH): G_q z_q
                    e = -eps * G[q, :, row]
                    e[ci, row] += eps
                    sq[:, t] += 2.0 * np.einsum("ci,ci->c", g, e) + np.einsum("ci,ci->c", e, e)
                out[js, np.array(cs)[:, None]] = np.sqrt(np.maximum(sq, 0.0)).T
        return out.reshape(-1)

    def toarray(self) -> np.ndarray:
        """The formed (n, n) Jacobian (as the dense path forms it)."""
        GZ = np.matmul(self.G, self.Z.dense().reshape(self.nc, self.dH, self.n))
        J = GZ.reshape(self.n, self.n)
        for p in range(self.nc):
            sl = slice(p * self.dH, (p + 1) * self.dH)
            J[sl, sl] -= self.eps * self.G[p]
        J[np.diag_indices(self.n)] += self.eps
        return J

    # -- the Newton step ----------------------------------------------------------------------
    def active_nodes(self) -> np.ndarray:
        """Nodes whose block ``G_p`` is not zero: those that slip or separate during the
        period (a node that sticks all period has ``G_p = 0``, its rows of ``J`` are
        ``eps I``)."""
        return np.flatnonzero(np.any(self.G.reshape(self.nc, -1) != 0.0, axis=1))

    def solve(self, b, rtol: float | None = None) -> np.ndarray:
        """``J^-1 b``, exact on the stuck nodes and reduced to the active ones
        (:meth:`active_nodes`): with ``s`` the stuck unknowns, ``x_s = b_s / eps`` and

            (eps I + G_a (Z_aa - eps I)) x_a = b_a - G_a Z_as x_s,

        solved by a LAPACK LU when it has at most :data:`ACTIVE_DENSE_MAX` unknowns, else by
        right-preconditioned GMRES on that active system to the relative residual
        ``rtol`` (default :data:`GMRES_RTOL`; Powell's inexact Newton steps ask for less
        far from the solution, :func:`fretwear.hb.solvers.powell`) (the
        preconditioner, restricted to the active nodes, is rebuilt when the active set
        changes, when the kept one needs more than :data:`REBUILD_AFTER` iterations or
        fails). ``b`` (n,) or (n, r)."""
        b = np.asarray(b, float)
        act = self.active_nodes()
        x, rhs, dofs = self._reduce(b, act)
        if act.size:
            if act.size * self.dH <= ACTIVE_DENSE_MAX:
                x[act] = self._lu_active(rhs, act, dofs)
            else:
                x[act] = self._gmres_active(rhs, act, dofs,
                                            GMRES_RTOL if rtol is None else max(rtol,
                                                                                GMRES_RTOL))
        return x.reshape(b.shape)

    def _reduce(self, b, act):
        """``x`` (nc, dH, r) with the stuck unknowns ``b_s / eps`` (active ones 0), the
        active right-hand side ``b_a - G_a Z_as x_s`` (na, dH, r) and the active DOFs."""
        eps, dH, d, Z = self.eps, self.dH, self.d, self.Z
        B = b.reshape(self.n, -1)
        r = B.shape[1]
        x = (B / eps).reshape(self.nc, dH, r)
        x[act] = 0.0
        dofs = (act[:, None] * d + np.arange(d)[None, :]).reshape(-1)
        if not act.size:
            return x, None, dofs
        # G_a Z_as x_s: the product with the stuck part only, on the active rows, from the
        # stuck DOFs where x_s is not zero (one column per node for the wear rate's dU/dW)
        xs = x.reshape(Z.m, Z.H, r)
        cols = np.flatnonzero(np.any(xs != 0.0, axis=(1, 2)))
        ZX = Z.apply_sub(dofs, cols, xs[cols])  # (na d, H, r) = rows of the active nodes
        rhs = B.reshape(self.nc, dH, r)[act] - np.matmul(self.G[act],
                                                         ZX.reshape(act.size, dH, r))
        return x, rhs, dofs

    def _active_blocks(self, dofs) -> HarmonicBlocks:
        """The harmonic blocks of ``Z_aa``, copied once and kept by the owner while the
        active DOFs (and the operator ``Z``) do not change: Powell's successive Jacobians
        near a solution share them."""
        kept = getattr(self.owner, "_active_Z", None)
        if kept is not None and kept[0] is self.Z and np.array_equal(kept[1], dofs):
            return kept[2]
        Z = self.Z
        op = getattr(Z, "op", None)
        # (an operator with compressed forms is cut: its sub-operator carries the cut forms,
        # which the near-field preconditioner reads; the view serves the stored matrices)
        view = (op is not None and getattr(op, "products", None) is None
                and VIEW_FRACTION * Z.m <= dofs.size < Z.m)
        Za = _ActiveView(Z, dofs) if view else Z.sub(dofs)
        self.owner._active_Z = (Z, dofs, Za)
        return Za

    def _lu_active(self, rhs, act, dofs) -> np.ndarray:
        from fretwear.hb.solvers import solve_identity_rows

        eps, dH = self.eps, self.dH
        na, r = act.size, rhs.shape[2]
        Za = self.Z.sub(dofs).dense()
        Ja = np.matmul(self.G[act], Za.reshape(na, dH, na * dH)).reshape(na * dH, na * dH)
        for i in range(na):
            sl = slice(i * dH, (i + 1) * dH)
            Ja[sl, sl] -= eps * self.G[act[i]]
        Ja[np.diag_indices(na * dH)] += eps
        return solve_identity_rows(Ja, rhs.reshape(na * dH, r)).reshape(na, dH, r)

    @property
    def first_scales(self) -> bool:
        """Whether Powell keeps the first Jacobian's variable scales
        (:attr:`fretwear.hb.options.KrylovOptions.first_scales`)."""
        return self.options.first_scales

    @property
    def options(self):
        """The owner's :class:`fretwear.hb.options.KrylovOptions` (its ``krylov``; the
        defaults when it has none)."""
        return getattr(self.owner, "krylov", None) or KRYLOV

    def _preconditioner(self, act, Za, rebuild=False):
        """The kept preconditioner, or a new one for the active nodes ``act``: sharing
        factors between harmonics unless ``rebuild`` (GMRES failed with the kept one); in
        single precision when the options ask for it, unless ``rebuild`` or once a GMRES
        run with single factors was slow on this owner (``_double``)."""
        owner = self.owner
        pc = getattr(owner, "_precond", None)
        if (pc is None or rebuild or pc.m != Za.m
                or not np.array_equal(getattr(pc, "nodes", None), act)
                or (getattr(pc, "single", False) and getattr(owner, "_double", False))):
            gbar, gosc = harmonic_gains(self.G[act], self.d,
                                        not getattr(owner, "_mean_gain", False))
            from fretwear.hb.nearfield_preconditioner import preconditioner_for

            opts = self.options
            # compressed forms: the near field when asked
            cls = preconditioner_for(Za, opts.preconditioner)
            if cls is None:
                single = (opts.single_factors and not rebuild
                          and not getattr(owner, "_double", False))
                pc = MeanGainPreconditioner(gbar, Za, self.eps, share=not rebuild, gosc=gosc,
                                            single=single)
            else:
                pc = cls(gbar, Za, self.eps, share=not rebuild, gosc=gosc)
            pc.oscillating = gosc is not gbar
            pc.nodes = act
            pc.first_iterations = None  # GMRES iterations per decade, first run
            owner._precond = pc
        return pc

    def _single_blocks(self, Za):
        """The single-precision twin of the active blocks ``Za`` (their ``single()``), kept
        by the owner while ``Za`` is the same object; None where there is none. Compressed
        (``single(compress)``, :func:`twin_tolerance`) from
        ``KrylovOptions.compressed_products_min_dofs`` DOFs of the whole operator."""
        kept = getattr(self.owner, "_single_Z", None)
        if kept is not None and kept[0] is Za:
            return kept[1]
        twin = None
        if hasattr(Za, "single"):
            opts = self.options
            least = opts.compressed_products_min_dofs
            tol = (twin_tolerance(opts.single_products_rtol)
                   if least is not None and self.Z.m >= least else None)
            twin = Za.single(tol)
        self.owner._single_Z = (Za, twin)
        return twin

    def _gmres_active(self, rhs, act, dofs, rtol=GMRES_RTOL) -> np.ndarray:
        """GMRES on the active system, one right-hand side at a time; its products with
        ``Z_aa`` in single precision when the options ask for it and ``rtol`` is at least
        ``KrylovOptions.single_products_rtol`` (a loose Newton step: the single products'
        ``1e-7`` relative error is far below it)."""
        eps, dH = self.eps, self.dH
        Za = self._active_blocks(dofs)
        opts = self.options
        Zp = Za
        if opts.single_products and rtol >= opts.single_products_rtol:
            Zp = self._single_blocks(Za) or Za
        Ga = self.G[act]
        na = act.size
        n = na * dH
        A = spla.LinearOperator((n, n), matvec=_step_operator(Zp, Ga, eps, na, dH),
                                dtype=float)
        correct = None
        if opts.node_correction and na * self.d >= opts.node_correction_min_dofs:
            correct = self._node_correction(act, Ga, Za)
        self.node_corrected = correct is not None
        out = np.empty_like(rhs)
        for c in range(rhs.shape[2]):
            out[:, :, c] = self._gmres(A, rhs[:, :, c].reshape(-1), act, Za,
                                       rtol, correct).reshape(na, dH)
        return out

    def _node_diagonals(self, act) -> list:
        """Every harmonic block's diagonal node blocks on the active nodes ``act``: a list
        of (na, d, d) arrays (real or complex), from ``Z.node_diagonal`` (no block
        formed)."""
        return [self.Z.node_diagonal(b, self.d)[act] for b in range(self.Z.nb)]

    def _node_correction(self, act, Ga, Za):
        """The node-local correction of the preconditioner on the active nodes ``act``
        (:func:`node_local_inverse` of their node blocks ``Ga``), as a function of the
        preconditioner's ``apply`` returning the two combined: ``x = Q^-1 r``, then ``x +
        P^-1 (r - J x)`` (a multiplicative two-level preconditioner: ``Q`` exact in the
        coupling of a node's harmonics by its time-varying gain, ``P`` in the coupling of
        the nodes through ``Z``; the product ``J x`` in single precision where there is a
        single twin). None where ``Q`` is singular."""
        eps, dH = self.eps, self.dH
        na = act.size
        qinv = node_local_inverse(Ga, self._node_diagonals(act), eps)
        if qinv is None:
            return None
        Zs = self._single_blocks(Za) or Za  # (the correction's product: approximate)
        rough = _step_operator(Zs, Ga, eps, na, dH)

        def wrap(apply):
            def both(r):
                r = np.asarray(r, float).reshape(-1)
                x = np.matmul(qinv, r.reshape(na, dH, 1))[:, :, 0].reshape(-1)
                return x + apply(r - rough(x))

            return both

        return wrap

    def _gmres(self, A, b, act, Za, rtol=GMRES_RTOL, correct=None) -> np.ndarray:
        """GMRES on one right-hand side. When it fails with a preconditioner kept from an
        earlier Jacobian or with shared factors, one more run from its last iterate with a
        preconditioner rebuilt from this Jacobian without sharing; when a fresh unshared one
        or with single-precision factors (``KrylovOptions.single_factors``) the same with
        a double-precision one; when a fresh unshared one in double
        with the oscillating gains of :func:`harmonic_gains` fails, the owner takes the mean
        gain from then on and one more run follows with it; a fresh unshared one with the
        mean gain is the best at hand (GMRES's last iterate is returned). A kept
        preconditioner that needs more than :data:`REBUILD_AFTER` iterations and more than
        :data:`REBUILD_GROWTH` times those of its first run (per decade of the residual:
        ``rtol`` varies) is rebuilt at the next Jacobian; one with single-precision factors
        whose run converged in more than ``KrylovOptions.single_max_iterations``
        iterations is rebuilt in double at the next Jacobian, and the owner's
        preconditioners are factored in double from then on."""
        x = None
        for attempt in range(3):
            pc0 = getattr(self.owner, "_precond", None)
            fresh = attempt > 0 or pc0 is None or not np.array_equal(
                getattr(pc0, "nodes", None), act)
            pc = self._preconditioner(act, Za, rebuild=attempt > 0)
            apply = pc.apply if correct is None else correct(pc.apply)
            M = spla.LinearOperator(A.shape, matvec=apply, dtype=float)
            count = [0]

            def cb(_r, count=count):
                count[0] += 1

            x, info = spla.gmres(A, b, x0=x, rtol=rtol, atol=0.0,
                                 restart=GMRES_RESTART, maxiter=GMRES_MAXITER, M=M,
                                 callback=cb, callback_type="pr_norm")
            self.gmres_iterations += count[0]
            if info == 0:
                rate = count[0] / max(-np.log10(rtol), 1.0)  # iterations per decade
                if (getattr(pc, "single", False)
                        and count[0] > self.options.single_max_iterations):
                    self.owner._double = True  # slow in single precision: double from now
                elif pc.first_iterations is None:
                    pc.first_iterations = rate
                elif (count[0] > REBUILD_AFTER
                      and rate > REBUILD_GROWTH * pc.first_iterations):
                    self.owner._precond = None  # slow: rebuild at the next Jacobian
                break
            if fresh and not pc.shared and not getattr(pc, "single", False):
                if not pc.oscillating:
                    break  # the best preconditioner at hand: GMRES's last iterate
                self.owner._mean_gain = True  # the oscillating gains failed here
        return x


def twin_tolerance(rtol: float) -> float:
    """The relative Frobenius error to which the compressed twin of GMRES's products is
    compressed when it serves steps solved to ``rtol`` or looser
    (``KrylovOptions.single_products_rtol``): ``TWIN_MARGIN rtol``.

    Why: GMRES on the twin ``J_H = J + E`` returns ``s`` with ``|J_H s + f| <= rtol |f|``,
    so the step's true residual is ``|J s + f| <= rtol |f| + |E s|`` and ``|E s| <=
    ||E||_2 |s|``. ``E = -G (Z~ - Z~_H)`` carries the twin's error ``sum_X |c_X(n)| e_X
    ||X^cc||_F`` (``||.||_2 <= ||.||_F``), relative to the operator as the single twin's
    rounding (``2^-24`` per entry, about ``6e-8`` relative) is. With the default
    ``rtol >= 1e-5`` the bound is ``1e-7``: of the order of the single twin's rounding,
    which the same rule admits, and two decades below the loosest step's ``rtol``, so the
    twin moves the step's residual by about one percent of what GMRES already leaves (an
    amplification ``|s| ||Z~|| / |f|`` of up to a few tens, measured as the ratio of a
    compressed solve's error to the compression's, docs/studies/large-interface-solve.md,
    keeps it within ``rtol``). The residual ``f(U)`` is the dense operator's: the root the
    solve converges to is not moved, only the steps towards it."""
    return TWIN_MARGIN * float(rtol)


class _ActiveView:
    """The harmonic blocks of an operator ``Z`` (hb/operator_blocks.py) on the DOFs ``dofs``
    as the GMRES path and :class:`MeanGainPreconditioner` use them (``apply``, ``block``,
    ``Z0``, the sizes and ``factor_budget``), without copies of ``Z``'s stored matrices: a
    product scatters into the whole operator's unknowns and gathers the rows ``dofs``; a
    block is formed on ``dofs`` only when asked for. The same products as ``Z.sub(dofs)``
    to rounding (a sum over zeros more)."""

    def __init__(self, Z, dofs: np.ndarray):
        self.Z, self.dofs = Z, np.asarray(dofs)
        self.m, self.H, self.k, self.nb = self.dofs.size, Z.H, Z.k, Z.nb
        self.real = Z.real
        self.factor_budget = getattr(Z, "factor_budget", None)

    @property
    def Z0(self) -> np.ndarray:
        return self.block(0)

    def block(self, b: int) -> np.ndarray:
        """Block ``b`` on ``dofs`` (formed, (m_a, m_a)): the whole block formed (no
        temporaries), then one gather (the row-then-column selection of
        ``ReducedOperator.block(b, rows, cols)`` would hold two more m_a x m arrays)."""
        Zb = self.Z.Z0 if b == 0 else self.Z.block(b)
        return Zb[np.ix_(self.dofs, self.dofs)]

    def block_source(self, b: int) -> tuple[np.ndarray, np.ndarray]:
        """As :meth:`HarmonicBlocks.block_source`: the whole block ``b`` of ``Z`` (formed)
        and ``dofs``."""
        return (self.Z.Z0 if b == 0 else self.Z.block(b)), self.dofs

    def block_products(self, blocks, V: np.ndarray) -> np.ndarray:
        """As :meth:`HarmonicBlocks.block_products` on ``dofs``: ``V`` scattered into the
        whole operator's DOFs, multiplied there (no block formed), the rows ``dofs``
        gathered."""
        full = np.zeros((self.Z.m, V.shape[1]), dtype=V.dtype)
        full[self.dofs] = V
        return self.Z.block_products(blocks, full)[self.dofs]

    def single(self, compress: float | None = None):
        """The same view of ``Z``'s single-precision blocks (``Z.single(compress)``), or
        None."""
        twin = self.Z.single(compress)
        return None if twin is None else _ActiveView(twin, self.dofs)

    def apply(self, U) -> np.ndarray:
        """``Z_aa U`` for ``U`` (m_a H,) or (m_a, H) on the real Fourier basis."""
        full = np.zeros((self.Z.m, self.H))
        full[self.dofs] = np.asarray(U, dtype=float).reshape(self.m, self.H)
        return self.Z.apply(full).reshape(self.Z.m, self.H)[self.dofs]


class _Transposed:
    def __init__(self, J):
        self.J = J

    def __matmul__(self, x):
        return self.J.rmatvec(x)
