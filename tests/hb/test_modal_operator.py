"""fretwear.hb.modal_operator: a ReducedOperator is determined by its stored arrays (what the
wear checkpoint's fingerprint hashes), and those change with the frequency."""

import numpy as np
from helpers.operator_models import F_MAX, ORDERS, block

from fretwear.hb.modal import BlockedModalCondenser


def test_operator_arrays_determine_it():
    """``arrays()`` (what a wear checkpoint's fingerprint hashes instead of the formed
    blocks) changes with the frequency and is the same for the same frequency."""
    bc = BlockedModalCondenser(block(), F_MAX, 7, tol=1e-2)
    a, b, c = (bc.reduced(2 * np.pi * f, ORDERS).Z.arrays() for f in (12e3, 12e3, 13e3))
    assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))
    assert not all(np.array_equal(x, y) for x, y in zip(a, c, strict=True))



def _random_operator(rng, m, q, complex_):
    """An operator of two shared matrices and a rank-q term per block, random."""
    from fretwear.hb.modal_operator import ReducedOperator

    mats = [rng.standard_normal((m, m)) for _ in range(2)]
    coef = rng.standard_normal((3, 2)) + (1j * rng.standard_normal((3, 2)) if complex_ else 0)
    cplx = (lambda a: a + 1j * rng.standard_normal(a.shape)) if complex_ else (lambda a: a)
    U = [None] + [cplx(rng.standard_normal((m, q))) for _ in range(2)]
    Y = [None] + [cplx(rng.standard_normal((q, m))) for _ in range(2)]
    return ReducedOperator(mats, coef, U, Y, symmetric=False), mats, coef, U, Y


def test_formed_rows_columns_and_node_diagonal_equal_the_sum_written_out():
    """``block(b, rows, cols)`` (BLAS axpy and gemm in place) and ``node_diagonal`` against
    ``sum_t c_t X_t - U Y`` written out with NumPy and sliced: the same sums in another
    order, equal to rounding (1e-13 of the entries' size 10)."""
    rng = np.random.default_rng(3)
    m, q, d = 12, 3, 3
    rows, cols = np.array([7, 0, 5, 11]), np.array([2, 3, 9])
    for complex_ in (False, True):
        op, mats, coef, U, Y = _random_operator(rng, m, q, complex_)
        for b in range(3):
            full = coef[b, 0] * mats[0] + coef[b, 1] * mats[1]
            if U[b] is not None:
                full = full - U[b] @ Y[b]
            for r, c in ((None, None), (rows, None), (None, cols), (rows, cols)):
                want = full[(slice(None) if r is None else r)][:, (slice(None) if c is None
                                                                    else c)]
                assert np.abs(op.block(b, r, c) - want).max() < 1e-13 * 10, (b, r, c)
            # rows r0:r1 formed into a kept buffer: the sum written out to rounding, and
            # block()'s own rows bit for bit (the same operations entry by entry)
            buf = np.full((m, m), np.nan, dtype=op.dtype)
            for r0, r1 in ((0, m), (3, 9), (11, 12)):
                got = op.block_rows(b, r0, r1, buf[: r1 - r0])
                assert np.shares_memory(got, buf)
                assert np.abs(got - full[r0:r1]).max() < 1e-13 * 10, (b, r0, r1)
                assert np.array_equal(got, op.block(b, np.arange(r0, r1))), (b, r0, r1)
            diag = np.stack([full[p * d:(p + 1) * d, p * d:(p + 1) * d]
                             for p in range(m // d)])
            assert np.abs(op.node_diagonal(b, d) - diag).max() < 1e-13 * 10


def test_auto_representation_takes_the_operator_above_the_operator_jacobians_size(
        monkeypatch):
    """``representation="auto"`` returns the dense blocks up to OPERATOR_MIN_UNKNOWNS real
    unknowns ``m H`` and the operator above, the bound being the periodic solve's
    DENSE_JACOBIAN_MAX (the size above which it takes the operator Jacobian). On the small
    block (m = 75, H = 15: 1125 unknowns) with the bound moved just below and just at
    1125; the operator's blocks equal the dense ones to rounding (1e-12 relative: the same
    condensation, summed in another order)."""
    from helpers.operator_models import rel

    from fretwear.hb import modal
    from fretwear.hb.modal import ModalCondenser
    from fretwear.hb.modal_operator import ReducedOperator
    from fretwear.hb.problem import DENSE_JACOBIAN_MAX

    assert modal.OPERATOR_MIN_UNKNOWNS == DENSE_JACOBIAN_MAX
    mc = ModalCondenser(block(), F_MAX, 7, tol=1e-2)
    w = 2 * np.pi * 12e3
    assert mc.m * 15 == 1125
    monkeypatch.setattr(modal, "OPERATOR_MIN_UNKNOWNS", 1125)
    dense = mc.reduced(w, ORDERS).Z
    assert isinstance(dense, np.ndarray)
    monkeypatch.setattr(modal, "OPERATOR_MIN_UNKNOWNS", 1124)
    op = mc.reduced(w, ORDERS).Z
    assert isinstance(op, ReducedOperator)
    assert max(rel(op[b], dense[b]) for b in range(ORDERS.size)) < 1e-12
