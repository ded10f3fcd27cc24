"""fretwear.hb.nearfield_preconditioner: the preconditioner built from the compressed interface
operator only, against (1) the dense inverse of the matrix it stands for, formed independently
(the compression's formed near field, the modal term, the node gains; a LAPACK solve), and
(2) the Newton step of the mean-gain preconditioner (a dense LU of the uncompressed active
blocks) on a partial-slip pad: GMRES solves the same compressed system with either, so the
two steps agree to GMRES's tolerance."""

import numpy as np
import pytest

from fretwear.hb import hmatrix, krylov
from fretwear.hb.modal_operator import ReducedOperator
from fretwear.hb.nearfield_preconditioner import (
    NearFieldPreconditioner,
    near_field,
    preconditioner_for,
)
from fretwear.hb.operator_blocks import OperatorBlocks
from fretwear.hb.options import KrylovOptions


def _kernel(n, d, seed=0, a=0.05):
    """``1 / (r + a)`` between ``n`` random points of a flat box (tests/hb/test_hmatrix.py's
    kernel), each point's ``d`` DOFs coupled by a fixed s.p.d. ``d x d`` matrix."""
    rng = np.random.default_rng(seed)
    P = rng.random((n, 3)) * [1.0, 1.0, 0.05]
    K = 1.0 / (np.linalg.norm(P[:, None] - P[None], axis=2) + a)
    return np.kron(K, np.eye(d) + 0.3 * np.ones((d, d))), P


def test_near_field_is_the_dense_leaf_blocks():
    """``near_field`` plus the formed low-rank blocks is the formed compression (``toarray``),
    and the near field holds every node's own diagonal block."""
    A, P = _kernel(200, 3, seed=4)
    hm = hmatrix.compress(A, P, 1e-5, leaf=8)
    N = near_field(hm).toarray()
    assert hm.ranks().size and 0 < np.count_nonzero(N) < A.size  # a far field left out
    far = np.zeros_like(A)
    for b in hm.blocks:
        if b.D is None:
            far[np.ix_(hm.rows[b.r0:b.r1], hm.cols[b.c0:b.c1])] = b.U @ b.V.T
    np.testing.assert_allclose(N + far, hm.toarray(), rtol=0, atol=1e-14 * np.abs(A).max())
    idx = np.arange(A.shape[0])
    same_node = idx[:, None] // 3 == idx[None, :] // 3
    np.testing.assert_array_equal(N[same_node], A[same_node])


@pytest.mark.parametrize("real", [True, False], ids=["real", "damped"])
def test_apply_is_the_inverse_of_near_field_plus_modal_term(real):
    """``apply`` against the LAPACK solve with the formed ``P_n = eps I + g_n (sum_X c_X N_X
    - U_n Y_n - eps I)`` per harmonic on the real Fourier basis (harmonic ``n``: ``P_n (a - i
    b)``), on the active rows of a compressed two-matrix operator with a rank-4 modal term:
    the sparse LU and the Woodbury identity are exact up to rounding (1e-10 relative, the
    condition of these ``P_n`` is about 1e3)."""
    K, P = _kernel(200, 3, seed=4)
    M, _ = _kernel(200, 3, seed=4, a=0.2)
    m, q, k = K.shape[0], 4, 2
    rng = np.random.default_rng(7)
    w2 = np.arange(k + 1) ** 2 * 0.3
    coef = np.column_stack([np.ones(k + 1), -w2 if real else -w2 + 0.05j * np.arange(k + 1)])
    U = [None] + [0.1 * rng.standard_normal((m, q)) for _ in range(k)]
    Y = [None] + [u.T.copy() for u in U[1:]]
    prods = [hmatrix.compress(A, P, 1e-5, leaf=8) for A in (K, M)]
    assert all(p.ranks().size for p in prods)  # a far field left out of the preconditioner
    Z = OperatorBlocks(ReducedOperator([K, M], coef, U, Y, products=prods))
    act = np.sort(rng.permutation(200)[:150])
    dofs = (act[:, None] * 3 + np.arange(3)).reshape(-1)
    Za = Z.sub(dofs)
    assert preconditioner_for(Za) is None  # the default: the mean gain
    assert preconditioner_for(Za, "mean-gain") is None
    assert preconditioner_for(Za, "nearfield") is NearFieldPreconditioner
    assert preconditioner_for(OperatorBlocks(ReducedOperator([K, M], coef, U, Y)),
                              "nearfield") is None
    na, ma, eps = act.size, dofs.size, 2.0
    g0 = 0.5 * np.eye(3) + 0.1 * rng.standard_normal((na, 3, 3))
    gn = 0.3 * np.eye(3) + 0.1 * rng.standard_normal((na, 3, 3))
    pc = NearFieldPreconditioner(g0, Za, eps, share=False, gosc=gn)
    N = [near_field(p).toarray() for p in Za.op.products]
    r = rng.standard_normal((ma, 2 * k + 1))
    got = pc.apply(r).reshape(ma, 2 * k + 1)
    for b in range(k + 1):
        Zb = coef[b, 0] * N[0] + coef[b, 1] * N[1]
        if U[b] is not None:
            Zb = Zb - Za.op.U[b] @ Za.op.Y[b]
        g = g0 if b == 0 else gn
        G = np.zeros((ma, ma))
        for i in range(na):
            G[3 * i:3 * i + 3, 3 * i:3 * i + 3] = g[i]
        Pb = eps * np.eye(ma) + G @ (Zb - eps * np.eye(ma))
        rhs = r[:, 0] if b == 0 else r[:, b] - 1j * r[:, k + b]
        want = np.linalg.solve(Pb, rhs)
        have = got[:, 0] if b == 0 else got[:, b] - 1j * got[:, k + b]
        assert np.abs(have - want).max() <= 1e-10 * np.abs(want).max()


def test_newton_step_equals_the_mean_gain_one(monkeypatch):
    """One Newton step of a compressed operator's partial-slip solve (a pad of 8 x 8 contact
    nodes, 3 harmonics, the modal condensation's ``X^cc`` compressed at 1e-4 with leaves of
    at most 8 nodes, so that a far field exists) solved by GMRES with the near-field
    preconditioner and with the mean-gain one. Both solve the same system (the compressed
    operator's) to GMRES's relative residual 1e-10, so ``|s - s_ref| <= kappa 2e-10 |s|``
    with ``kappa`` the active system's condition: 1e-7 relative allows ``kappa`` up to 5e2
    (measured 4e-11); a wrong preconditioner would not bring GMRES to that residual within
    its restarts (asserted through the residual itself)."""
    from fretwear.hb.fourier import FourierBasis
    from fretwear.hb.modal import ModalCondenser
    from fretwear.hb.preload import static_anchor
    from fretwear.hb.problem import DLFTProblem
    from fretwear.model import ContactSpec, Material, Spring, Traction, box, from_mesh

    model = from_mesh(box(0.01, 0.01, 0.004, 7, 7, 2), Material(210e9, 0.3, 7800.0),
                      supports=[Spring("zmax", "x", 1e7), Spring("zmax", "y", 1e7)],
                      loads=[Traction("zmax", pressure=1e7),
                             Traction("zmax", traction=(0.8 * 0.3 * 1e7 * np.cos(0.5),
                                                        0.8 * 0.3 * 1e7 * np.sin(0.5), 0.0),
                                      waveform="cos")],
                      contact=ContactSpec("zmin", mu=0.3))
    assert model.contact.coords.shape[0] == 64
    basis = FourierBasis.up_to(3, 32)
    mc = ModalCondenser(model, 1.2e3, 3, modes=10, representation="operator")
    red = mc.reduced(2 * np.pi * 1e3, basis.orders, frequency=1e3)
    red.Z.products = [hmatrix.compress(A, model.contact.coords, 1e-4, leaf=8)
                      for A in red.Z.mats]
    assert all(p.ranks().size for p in red.Z.products)
    prob = DLFTProblem(red, model.contact, basis, eps="auto",
                       anchor=static_anchor(model, condenser=mc), jacobian="krylov")
    monkeypatch.setattr(krylov, "ACTIVE_DENSE_MAX", -1)
    x = prob.initial_guess()
    f, J = prob.residual(x, True)
    assert 0 < J.active_nodes().size
    steps = {}
    for name in ("nearfield", "mean-gain"):
        prob.krylov = KrylovOptions(preconditioner=name)
        J.owner._precond = None
        s = J.solve(f)
        assert type(J.owner._precond).__name__ == {"nearfield": "NearFieldPreconditioner",
                                                   "mean-gain": "MeanGainPreconditioner"}[name]
        assert np.linalg.norm(J @ s - f) <= 1e-9 * np.linalg.norm(f)
        steps[name] = s
    ref = steps["mean-gain"]
    assert np.abs(steps["nearfield"] - ref).max() <= 1e-7 * np.abs(ref).max()
