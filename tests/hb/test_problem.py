"""The DLFT residual ``f = eps (U~ - W~) - P lambda_x`` (paper eq. 22-23) and its full Jacobian
``J = eps I - G (eps I - Z)`` of :class:`fretwear.hb.problem.DLFTProblem`, on hand-built
models whose reduced blocks are complex and non-symmetric.

Independent references: the real form of the reduced blocks written here from
``u = Re(U e^{i h tau})`` (not :func:`fretwear.hb.reduce.to_real_blocks`), the contact law
transcribed from eq. 24-28 in pure Python and the real Fourier basis by direct evaluation
(tests/helpers/contact_law.py), and central finite differences of the residual.
"""

import numpy as np
import pytest
import scipy.sparse as sp
from helpers.contact_law import (
    FD_RTOL,
    FD_STEP,
    HARM,
    MIN_MARGIN,
    NS,
    P_REF,
    Q_REF,
    SWEEPS,
    TOL_LAW,
    case,
    margins,
    ref_law,
)

from fretwear.hb.fourier import FourierBasis
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.reduce import condense
from fretwear.model.core import ContactInterface, Load, Model


def chain_model(d, nc):
    """``nc`` contact nodes (d DOFs each, frames rotated so that no axis is special) tied by
    springs to each other and, through an interior mass, to ground; viscous and hysteretic
    damping so that every harmonic block of Z_r is complex and non-symmetric in real form."""
    rng = np.random.default_rng(3)
    nd = nc * d + d  # contact DOFs then d interior DOFs
    A = rng.standard_normal((nd, nd))
    K = A @ A.T + nd * np.eye(nd)
    M = np.diag(rng.uniform(0.5, 1.5, nd))
    C = 0.01 * K
    D = 0.02 * K
    frames = []
    for _ in range(nc):
        q, _ = np.linalg.qr(rng.standard_normal((d, d)))
        frames.append(q)
    contact = ContactInterface(
        dofs=np.arange(nc * d).reshape(nc, d), frame=np.array(frames), gap=np.zeros(nc),
        area=np.ones(nc), mu=0.3, coords=np.zeros((nc, d)))
    F = np.zeros(nd)
    F[:nc * d] = 1.0
    model = Model(K=sp.csr_matrix(K), M=sp.csr_matrix(M), C=sp.csr_matrix(C),
                  D=sp.csr_matrix(D), contact=contact,
                  loads=[Load(F, "constant"), Load(0.5 * F, "cos"), Load(0.2 * F, "sin")],
                  dim=d)
    return model


def real_blocks(Zc, k):
    """Real operator on [a0, a_h.., b_h..] per DOF from complex blocks, written from
    ``u = Re(U e^{i h tau})`` with U = a - i b (independent of reduce.to_real_blocks)."""
    m = Zc.shape[1]
    H = 1 + 2 * k
    out = np.zeros((m, H, m, H))
    out[:, 0, :, 0] = Zc[0].real
    for i in range(1, k + 1):
        # Z (a - i b) = (Zr a + Zi b) - i (Zr b - Zi a):  new a = Zr a + Zi b, new b = Zr b - Zi a
        zr, zi = Zc[i].real, Zc[i].imag
        out[:, i, :, i] = zr
        out[:, i, :, k + i] = zi
        out[:, k + i, :, i] = -zi
        out[:, k + i, :, k + i] = zr
    return out.reshape(m * H, m * H)


def problem_at(d, keys, frequency=3.0 / (2 * np.pi)):
    """A DLFTProblem on ``chain_model`` and a point U at which lambda_u of node p equals the
    test signal ``keys[p]`` (U from (eps I - Z) U = lambda_u - F + eps W, eps = 2 x spectral
    radius so that eps I - Z is invertible)."""
    nc = len(keys)
    model = chain_model(d, nc)
    basis = FourierBasis(HARM, NS)
    red = condense(model, frequency, [0, *HARM])
    eps = 2.0 * red.spectral_radius()
    scale = 1e3  # forces of order 1e3 N
    anchors = np.array([case(k)[2][0] for k in keys]) * scale / eps  # eps X_a = x_start
    prob = DLFTProblem(red, model.contact, basis, eps=eps, anchor=anchors,
                       periodicity_tol=TOL_LAW, max_sweeps=SWEEPS)
    target = scale * np.concatenate([case(k)[0][0] for k in keys])  # (nc*d, H): lambda_u
    n = prob.m * prob.H
    Z = real_blocks(red.Z, len(HARM))
    F = np.hstack([red.F[0].real[:, None], red.F[1:].real.T, -red.F[1:].imag.T])
    rhs = (target - F + eps * prob.W).reshape(-1)
    U = np.linalg.solve(eps * np.eye(n) - Z, rhs).reshape(prob.m, prob.H)
    return prob, U, Z, F, target


@pytest.mark.parametrize("d, keys", [
    (2, [(2, "mixed"), (2, "wrap"), (2, "slip"), (2, "stick"), (2, "separation")]),
    (3, [(3, "mixed"), (3, "wrap"), (3, "slip"), (3, "stick"), (3, "separation")]),
], ids=["2D", "3D"])
def test_residual_matches_reference(d, keys):
    """DLFTProblem.residual vs an independent assembly: lambda_u~ = F~ - Z U~ + eps (U~ - W~)
    from the complex reduced blocks through ``real_blocks`` (own real form), lambda_u in time
    with ``trig_matrices``, lambda_x by ``ref_law``, f = eps (U~ - W~) - P lambda_x (eq. 22).
    Tolerance 1e-10 of eps |U|: rounding of dense products of size ~ 100."""
    prob, U, Z, F, target = problem_at(d, keys)
    lu = (F - (Z @ U.reshape(-1)).reshape(prob.m, prob.H) + prob.eps * (U - prob.W))
    np.testing.assert_allclose(lu, target, rtol=0, atol=1e-9 * np.abs(target).max())
    lu_t = (lu @ Q_REF.T).reshape(prob.nc, d, NS)
    lx_ref, state_ref = ref_law(lu_t, prob.mu, prob.eps * prob.anchor)
    f_ref = prob.eps * (U - prob.W) - (lx_ref.reshape(prob.m, NS) @ P_REF.T)
    f, _ = prob.residual(U, jacobian=False)
    np.testing.assert_allclose(f, f_ref.reshape(-1), rtol=0,
                               atol=1e-10 * prob.eps * np.abs(U).max())
    _, _, state, _ = prob.time_law(U)
    np.testing.assert_array_equal(state, state_ref)


@pytest.mark.parametrize("d, keys", [
    (2, [(2, "mixed"), (2, "wrap"), (2, "slip"), (2, "stick"), (2, "separation")]),
    (3, [(3, "mixed"), (3, "wrap"), (3, "slip"), (3, "stick"), (3, "separation")]),
], ids=["2D", "3D"])
def test_residual_jacobian_matches_finite_differences(d, keys):
    """Full Jacobian ``J = eps I - G (eps I - Z)`` of DLFTProblem.residual vs central
    differences in U (step 1e-6 x max |U|), on coupled nodes in all state patterns (the
    coupling through Z mixes the nodes, so an error in the ordering of G's rows/columns or in
    the chain rule shows). Tolerance FD_RTOL relative to eps (the size of J's entries)."""
    prob, U, _, _, _ = problem_at(d, keys)
    lu, lx, _, _ = prob.time_law(U)
    assert margins(lu, lx, prob.mu).min() > MIN_MARGIN
    f0, J = prob.residual(U)
    h = FD_STEP * np.abs(U).max()
    n = U.size
    J_fd = np.zeros((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = h
        fp, _ = prob.residual(U + e.reshape(U.shape), jacobian=False)
        fm, _ = prob.residual(U - e.reshape(U.shape), jacobian=False)
        J_fd[:, j] = (fp - fm) / (2 * h)
    np.testing.assert_allclose(J, J_fd, rtol=0, atol=FD_RTOL * prob.eps)
    # the nonlinear part is not negligible: the test would see an error in G
    assert np.abs(J - prob.eps * np.eye(n)).max() > 0.1 * prob.eps

