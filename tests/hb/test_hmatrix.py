"""fretwear.hb.hmatrix: the hierarchical low-rank compression against the dense matrix it
compresses (its error bound ``||A - A_H||_F <= tol ||A||_F``), and the compressed products of
the modal operator (hb/modal_operator.py, hb/operator_blocks.py) against its dense
products."""

import numpy as np
import pytest
from helpers.operator_models import rel

from fretwear.errors import InputError
from fretwear.hb.hmatrix import compress


def _kernel(n, d, seed=0, a=0.05):
    """``1 / (r + a)`` between ``n`` random points of a flat box (a contact face), each
    point's ``d`` DOFs coupled by a fixed symmetric positive definite ``d x d`` matrix:
    smooth away from the diagonal, symmetric."""
    rng = np.random.default_rng(seed)
    P = rng.random((n, 3)) * [1.0, 1.0, 0.05]
    K = 1.0 / (np.linalg.norm(P[:, None] - P[None], axis=2) + a)
    S = np.eye(d) + 0.3 * np.ones((d, d))
    return np.kron(K, S), P


@pytest.mark.parametrize("tol", [1e-3, 1e-7])
def test_kernel_compression_within_its_bound(tol):
    """A smooth kernel on 400 random points (one DOF each) against its compressed form:
    the formed ``A_H`` is within ``tol ||A||_F`` (the bound, independent of how it is met)
    and its error is the one the compression states (exactly computed per block, so to a
    relative 1e-6: rounding of the sums); the products ``A_H X`` and ``A_H^T X`` differ
    from ``A X`` by at most ``||A - A_H||_2 ||X||_F <= tol ||A||_F ||X||_F``. The form must
    be smaller than ``A`` and hold low-rank blocks (else the test would check a dense
    copy)."""
    A, P = _kernel(400, 1)
    H = compress(A, P, tol, leaf=16)
    err = np.linalg.norm(A - H.toarray()) / np.linalg.norm(A)
    assert err <= tol
    assert abs(err - H.error) <= 1e-6 * tol
    assert H.nbytes < 0.7 * A.nbytes and H.ranks().size and H.ranks().max() > 0
    X = np.random.default_rng(1).standard_normal((400, 5))
    bound = tol * np.linalg.norm(A) * np.linalg.norm(X)
    assert np.linalg.norm(H @ X - A @ X) <= bound
    assert np.linalg.norm(H.T @ X - A.T @ X) <= bound
    x = X[:, 0] + 1j * X[:, 1]  # a complex vector: real and imaginary parts apart
    assert np.linalg.norm(H @ x - A @ x) <= tol * np.linalg.norm(A) * np.linalg.norm(x)


def test_restriction_to_rows_and_columns():
    """``sub(rows)`` and ``sub(rows, cols)`` of a compressed 3-DOF kernel against the same
    rows and columns of ``A``: within the whole matrix's absolute bound ``tol ||A||_F``
    (a restriction of the error is no larger), in the order asked (unsorted indices); a
    non-symmetric matrix (its transpose's products) as well."""
    A, P = _kernel(150, 3, seed=2)
    tol = 1e-5
    H = compress(A, P, tol, leaf=8)
    assert H.ranks().size and H.error > 0  # low-rank blocks to cut
    rng = np.random.default_rng(3)
    rows = rng.permutation(A.shape[0])[:200]
    cols = rng.permutation(A.shape[0])[:120]
    for S, want in ((H.sub(rows), A[np.ix_(rows, rows)]),
                    (H.sub(rows, cols), A[np.ix_(rows, cols)])):
        assert np.linalg.norm(S.toarray() - want) <= tol * np.linalg.norm(A)
        x = rng.standard_normal(S.shape[1])
        assert np.linalg.norm(S @ x - want @ x) <= tol * np.linalg.norm(A) * np.linalg.norm(x)
    B = A + 0.1 * np.triu(A, 3)  # not symmetric: every block compressed on its own
    HB = compress(B, P, tol, leaf=8)
    x = rng.standard_normal(B.shape[0])
    assert np.linalg.norm(HB.T @ x - B.T @ x) <= tol * np.linalg.norm(B) * np.linalg.norm(x)


def test_operator_products_compressed_equal_dense_within_bound():
    """The solver's products on the real Fourier basis (``OperatorBlocks.apply``,
    ``apply_T``, the active sub-operator's ``apply`` and ``apply_sub``) of a
    ``ReducedOperator`` whose two shared matrices are compressed, against the same
    operator without: per harmonic ``Z_n = c_K K + c_M M - U_n Y_n`` differs by
    ``c_K dK + c_M dM``, so each column of the result by at most
    ``(|c_K| e_K ||K||_F + |c_M| e_M ||M||_F) |x|`` (``e`` the compressions' stated errors,
    checked above)."""
    from fretwear.hb.modal_operator import ReducedOperator
    from fretwear.hb.operator_blocks import OperatorBlocks

    K, P = _kernel(200, 3, seed=4)
    M, _ = _kernel(200, 3, seed=4, a=0.2)
    m, q, k = K.shape[0], 4, 3
    rng = np.random.default_rng(5)
    w2 = np.arange(k + 1) ** 2 * 0.5
    coef = np.column_stack([np.ones(k + 1), -w2])
    U = [None] + [rng.standard_normal((m, q)) for _ in range(k)]
    Y = [None] + [u.T.copy() for u in U[1:]]  # U_n Y_n symmetric
    prods = [compress(A, P, 1e-5, leaf=8) for A in (K, M)]
    assert all(p.ranks().size and p.error > 0 for p in prods)  # low-rank blocks in both
    dense = OperatorBlocks(ReducedOperator([K, M], coef, U, Y))
    comp = OperatorBlocks(ReducedOperator([K, M], coef, U, Y, products=prods))
    scale = max(abs(c[0]) * prods[0].error * np.linalg.norm(K)
                + abs(c[1]) * prods[1].error * np.linalg.norm(M) for c in coef)
    X = rng.standard_normal((m, 2 * k + 1))
    bound = scale * np.linalg.norm(X)
    assert np.linalg.norm(comp.apply(X) - dense.apply(X)) <= bound
    assert np.linalg.norm(comp.apply_T(X) - dense.apply_T(X)) <= bound
    dofs = np.sort(rng.permutation(m)[:400])
    Xs = X[dofs]
    assert (np.linalg.norm(comp.sub(dofs).apply(Xs) - dense.sub(dofs).apply(Xs))
            <= scale * np.linalg.norm(Xs))
    cols = np.setdiff1d(np.arange(m), dofs)
    Xc = rng.standard_normal((cols.size, 2 * k + 1, 2))
    assert (np.linalg.norm(comp.apply_sub(dofs, cols, Xc) - dense.apply_sub(dofs, cols, Xc))
            <= scale * np.linalg.norm(Xc))
    assert rel(comp.apply(X), dense.apply(X)) > 0  # the compressed products were taken


def test_bad_input_is_refused():
    """One InputError naming the argument for each bad input."""
    A, P = _kernel(20, 1)
    with pytest.raises(InputError, match="tol"):
        compress(A, P, 0.0)
    with pytest.raises(InputError, match="coords"):
        compress(A, np.zeros((20, 3)), 1e-3)
    with pytest.raises(InputError, match="coords"):
        compress(A, P[:7], 1e-3)
    with pytest.raises(InputError, match="A of shape"):
        compress(A[:, :5], P, 1e-3)


def test_condenser_compress_option():
    """``compress=`` of the modal condensers: the operator of every frequency carries the
    compressed ``X^cc`` (made once: the same objects at two frequencies), each within its
    bound, and its products are the dense operator's within that bound (column ``j`` on
    harmonic ``b``: ``sum_t |c_t(b)| e_t ||X_t||_F |x_j|``, plus rounding); the bound is part
    of the construction (``representation=Representation("compressed", tol)``, what
    ``modal_condenser(compress=tol)`` passes; none for the other representations); a bad
    value is refused."""
    from helpers.operator_models import F_MAX, ORDERS, block

    from fretwear.hb.modal import (
        COMPRESS_TOL,
        BlockedModalCondenser,
        ModalCondenser,
        Representation,
        modal_condenser,
    )

    model = block()
    bc = BlockedModalCondenser(model, F_MAX, 7, tol=1e-2, compress=1e-6)
    Z1, Z2 = (bc.reduced(2 * np.pi * f, ORDERS).Z for f in (12e3, 13e3))
    assert Z1.products is not None and all(a is b for a, b in zip(Z1.products, Z2.products,
                                                                  strict=True))
    assert all(p.error <= 1e-6 for p in Z1.products)
    X = np.random.default_rng(0).standard_normal((Z1.m, ORDERS.size))
    blocks = np.arange(ORDERS.size)
    got = Z1.matmat(blocks, X)
    bound = sum(np.abs(Z1.coef[:, t]) * p.error * np.linalg.norm(A)
                for t, (p, A) in enumerate(zip(Z1.products, Z1.mats, strict=True)))
    Z1.products = None
    diff = np.linalg.norm(got - Z1.matmat(blocks, X), axis=0)
    assert np.all(diff <= bound * np.linalg.norm(X, axis=0) + 1e-13 * np.abs(got).max())
    mc = ModalCondenser(model, F_MAX, 7, tol=1e-2, representation="compressed")
    assert mc.compress == COMPRESS_TOL and mc.reduced(2 * np.pi * 12e3, ORDERS).Z.products
    assert mc.representation == "operator"
    assert modal_condenser(model, F_MAX, 7, tol=1e-2, compress=1e-4).compress == 1e-4
    assert ModalCondenser(model, F_MAX, 7, tol=1e-2).compress is None
    with pytest.raises(InputError, match="only \"compressed\" has a bound"):
        Representation("operator", 1e-6)
    with pytest.raises(InputError, match="compress"):
        Representation("compressed", 0.0)
    with pytest.raises(InputError, match="compress"):
        modal_condenser(model, F_MAX, 7, compress=2.0)
    with pytest.raises(InputError, match="compress"):
        BlockedModalCondenser(model, F_MAX, 7, compress="1e-6")
    with pytest.raises(InputError, match="representation"):
        ModalCondenser(model, F_MAX, 7, representation="hmatrix")


def test_float32_copy_states_its_rounding():
    """HMatrix.astype(float32): the formed blocks (in float64, A_H32) differ from A by at
    most the stated error (the compression's plus the stored entries' rounding, Higham's
    entrywise bound, 2^-24 per entry), at a bound where the compression dominates (1e-6)
    and one where the rounding does (1e-9); the stated error stays within the tolerance
    plus a few float32 roundoffs (6e-8 each). Products: A_H32 X in float32 against the
    formed A_H32 X in float64, to float32's accumulated rounding (a sum of m terms: 1e-5
    relative is generous; measured ~1e-7)."""
    rng = np.random.default_rng(3)
    xy = rng.random((400, 2))
    D = np.linalg.norm(xy[:, None] - xy[None], axis=2)
    A = np.kron(1.0 / (D + 0.2), np.eye(3))
    A = 0.5 * (A + A.T)
    X = rng.standard_normal((A.shape[0], 5))
    for tol in (1e-6, 1e-9):
        H = compress(A, xy, tol, leaf=8)
        H32 = H.astype(np.float32)
        assert H32.dtype == np.float32 and H32.ranks().size and H32.ranks().max() > 0
        F = H32.toarray().astype(float)
        formed = np.linalg.norm(F - A) / np.linalg.norm(A)
        assert formed <= H32.error, (tol, formed, H32.error)
        assert H32.error <= tol + 5 * 2.0**-24, (tol, H32.error)
        Y = H32 @ X
        assert Y.dtype == np.float32
        assert np.linalg.norm(Y - F @ X) <= 1e-5 * np.linalg.norm(F @ X)
        Xc = X + 1j * X[::-1]
        assert np.linalg.norm(H32.T @ Xc - F.T @ Xc) <= 1e-5 * np.linalg.norm(F @ Xc)


def _abs_blocks(H):
    """``|A_H|`` with each low-rank block as ``|U| |V|^T`` (the magnitudes a product's
    rounding is bounded by; Higham 2002, sec. 3.5), formed in float64 in ``H``'s order."""
    out = np.zeros((H.rows.size, H.cols.size))
    for b in H.blocks:
        out[b.r0 : b.r1, b.c0 : b.c1] = (np.abs(b.D) if b.D is not None
                                         else np.abs(b.U).astype(float) @ np.abs(b.V).T)
    full = np.empty_like(out)
    full[np.ix_(H.rows, H.cols)] = out
    return full


def _blockwise(H, X):
    """``A_H X`` one block at a time in ``H``'s precision (``D x`` or ``U (V^T x)`` per
    block, in NumPy): the arithmetic of the per-cluster products before the compiled
    kernels, grouped differently."""
    Xp = X[H.cols].astype(H.dtype)
    Yp = np.zeros((H.rows.size, X.shape[1]), dtype=H.dtype)
    for b in H.blocks:
        x = Xp[b.c0 : b.c1]
        Yp[b.r0 : b.r1] += b.D @ x if b.D is not None else b.U @ (b.V.T @ x)
    Y = np.empty_like(Yp)
    Y[H.rows] = Yp
    return Y


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_compiled_product_within_rounding_of_formed_and_blockwise(dtype):
    """The compiled product (packed stacks, one BLAS gemm each, the near field's mirrored
    blocks applied transposed) against two references: the formed ``A_H`` times ``X`` in
    float64, and the product one block at a time in NumPy (:func:`_blockwise`). Any order
    of summation keeps ``|fl(A_H X) - A_H X| <= g_N |A_H| |X|`` entrywise (Higham, sec. 3.5;
    ``g_N = N u / (1 - N u)``, ``N`` the longest chain of roundings: ``2 m`` covers a row's
    ``m`` terms, the ranks and the partial sums' additions; ``|A_H|`` with ``|U| |V|^T`` for a
    low-rank block), so the two references are within that bound and each other within
    twice it: a bound independent of the kernels' order. On a symmetric matrix (mirrored
    near and far blocks), a non-symmetric one, their transposes, a symmetric cut and a
    rectangular cut in unsorted order; near and far fields both present, and products not
    all zero."""
    A, P = _kernel(240, 3, seed=6)
    x = np.repeat(P[:, 0], 3)
    B = A * (1 + 0.3 * (x[:, None] - x[None, :]))  # not symmetric, as smooth as A
    rng = np.random.default_rng(7)
    rows = rng.permutation(A.shape[0])[:500]
    cols = rng.permutation(A.shape[0])[:300]
    Hs = compress(A, P, 1e-5, leaf=8).astype(dtype)
    Hn = compress(B, P, 1e-5, leaf=8).astype(dtype)
    cases = [Hs, Hs.T, Hn, Hn.T, Hs.sub(rows), Hn.sub(rows, cols), Hn.sub(rows, cols).T]
    u = float(np.finfo(dtype).eps) / 2
    for H in cases:
        assert H.ranks().size and any(b.D is not None for b in H.blocks)
        X = rng.standard_normal((H.shape[1], 7))
        F = H.toarray().astype(float)
        N = 2 * max(H.shape)
        absH = _abs_blocks(H).T if H._transposed else _abs_blocks(H)
        bound = N * u / (1 - N * u) * absH @ np.abs(X)
        Y = H @ X
        assert Y.dtype == dtype and np.linalg.norm(Y) > 0
        assert np.all(np.abs(Y - F @ X) <= bound)
        if not H._transposed:
            assert np.all(np.abs(Y - _blockwise(H, X)) <= 2 * bound)
    assert any(b.of is not None and b.D is not None for b in Hs.blocks)  # mirrored near


def test_compiled_product_same_bits_every_time():
    """Two products of one matrix, of two compressions of one input, of two cuts of it,
    and of the same blocks whose arrays were made in the reverse order, are the same bit
    for bit: the packed stacks follow the blocks' order, not the arrays' memory addresses
    (which an order by address would follow, changing the sums' rounding from run to run;
    a solve repeated must give the same path)."""
    from fretwear.hb.hmatrix import Block, HMatrix

    A, P = _kernel(240, 3, seed=8, a=0.3)
    x = np.repeat(P[:, 0], 3)
    A = A * (1 + 0.3 * (x[:, None] - x[None, :]))  # not symmetric: no shared factors
    rng = np.random.default_rng(9)
    X = rng.standard_normal((A.shape[0], 15)).astype(np.float32)
    dofs = np.sort(rng.permutation(A.shape[0])[:500])
    H1, H2 = (compress(A, P, 1e-5, leaf=8).astype(np.float32) for _ in range(2))
    assert H1.ranks().size > 10
    assert np.array_equal(H1 @ X, H1 @ X) and np.array_equal(H1 @ X, H2 @ X)
    S1, S2 = H1.sub(dofs), H2.sub(dofs)
    assert np.array_equal(S1 @ X[dofs], S2 @ X[dofs])
    assert np.array_equal(S1.T @ X[dofs], S2.T @ X[dofs])
    made = {}
    for i in reversed(range(len(H1.blocks))):  # the copies' arrays made last block first
        b = H1.blocks[i]
        made[i] = ({"D": b.D.copy()} if b.D is not None
                   else {"U": b.U.copy(), "V": b.V.copy()})
    R = HMatrix(H1.rows, H1.cols, [Block(b.r0, b.r1, b.c0, b.c1, **made[i])
                                   for i, b in enumerate(H1.blocks)])
    assert np.array_equal(R @ X, H1 @ X)
