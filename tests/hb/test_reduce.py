"""Tests of the exact per-harmonic condensation on the contact DOFs (fretwear.hb.reduce).

The model is a hand-assembled 2D truss (independent of the FE layer). Every reference is a
*dense* solve of the full model written from the equation of motion in core.py,

    Z_n U + T^T lambda = F_n   on the free DOFs,   u_loc = T U,

with numpy.linalg (not the sparse LU used by reduce), for arbitrary contact forces lambda, so
that the condensed relation ``Z_r u_loc + lambda = F_r`` is checked for every contact state.
Tolerances: relative errors of a well-conditioned dense solve are ~ cond * 1e-16; near a
resonance (0.999 f) the amplification is ~1e3, so 1e-9 relative leaves a wide margin while any
formula error (a missing term, a wrong sign or frame) gives O(1) errors.
"""

import numpy as np
import pytest
import scipy.linalg as sla
from helpers.models import RNG, truss

from fretwear.errors import InputError
from fretwear.hb import reduce
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.reduce import condense, loads_to_real, recover, to_real_blocks

RTOL = 1e-9


@pytest.fixture(autouse=True, params=["batched", "dense", "sparse"])
def condensation_path(request, monkeypatch):
    """Every test runs on the three paths of the condensation: every harmonic in one batched
    LAPACK solve (tiny models, reduce.BATCH_MAX), LAPACK per harmonic on dense blocks (small
    models, reduce.DENSE_MAX) and SuperLU with blocked multi-right-hand-side solves (BLOCK = 5
    columns, so the 12 contact DOFs of the truss take three blocks)."""
    monkeypatch.setattr(reduce, "DENSE_MAX", -1 if request.param == "sparse" else 10**9)
    monkeypatch.setattr(reduce, "BATCH_MAX", 10**9 if request.param == "batched" else -1)
    monkeypatch.setattr(reduce, "BLOCK", 5)
    monkeypatch.setattr(reduce, "_CONDENSERS", {})
    return request.param


def dense_Z(model, omega, n):
    """Z_n written from the docstring of core.Model (independent of reduce.dynamic_stiffness)."""
    K = model.K.toarray()
    if n == 0:
        return K.astype(complex)
    w = n * omega
    Z = K - w**2 * model.M.toarray() + 0j
    if model.D is not None:
        Z += 1j * model.D.toarray()
    if model.C is not None:
        Z += 1j * w * model.C.toarray()
    return Z


def full_solve(model, Z, F, lam):
    """Dense solve of Z U + T^T lam = F with the fixed DOFs held; returns all DOFs."""
    T = model.contact.local_transform(model.ndof).toarray()
    free = model.free_dofs()
    U = np.zeros(model.ndof, dtype=complex)
    U[free] = np.linalg.solve(Z[np.ix_(free, free)], (F - T.T @ lam)[free])
    return U


def free_eigenfrequencies(model):
    """Undamped eigenfrequencies [rad/s] of the structure with a free interface (dense)."""
    free = model.free_dofs()
    lam = sla.eigh(model.K.toarray()[np.ix_(free, free)], model.M.toarray()[np.ix_(free, free)],
                   eigvals_only=True)
    return np.sqrt(lam)


def rel(a, b):
    return np.max(np.abs(a - b)) / np.max(np.abs(b))


@pytest.mark.parametrize("damping", ["hysteretic", "rayleigh", "both"])
def test_condensed_response_equals_full_solve(damping):
    """For random contact forces lambda, the reduced equation Z_r u + lambda = F_r gives the
    contact-local displacements of the full dense solve, and obs_A u + obs_b the observed DOFs,
    at several frequencies including 0.999 x an eigenfrequency, harmonics 0..3 (static, cos,
    sin and 'fourier' loads), with tilted contact frames."""
    model = truss(damping=damping)
    T = model.contact.local_transform(model.ndof).toarray()
    wn = free_eigenfrequencies(model)
    orders = np.array([0, 1, 2, 3])
    obs = np.concatenate([p.dofs for p in model.observed])
    for f in np.array([0.31 * wn[0], 0.999 * wn[2], 1.7 * wn[4]]) / (2 * np.pi):
        red = condense(model, f, orders)
        omega = red.omega
        F_all = model.load_harmonics(3)
        for b, n in enumerate(orders):
            lam = RNG.standard_normal(red.m) + 1j * RNG.standard_normal(red.m) * (n > 0)
            U = full_solve(model, dense_Z(model, omega, n), F_all[n], lam)
            u_ref = T @ U
            u = np.linalg.solve(red.Z[b], red.F[b] - lam)
            assert rel(u, u_ref) < RTOL
            np.testing.assert_allclose(red.obs_A[b] @ u + red.obs_b[b], U[obs], rtol=0,
                                       atol=RTOL * np.abs(U).max())
        np.testing.assert_array_equal(red.obs_dofs, obs)


def test_recover_equals_full_solve():
    """recover() from the contact solution gives every DOF of the full dense solve (fixed DOFs
    exactly zero), here with a stuck-like state lambda != 0 and a tilted frame."""
    model = truss(damping="both")
    T = model.contact.local_transform(model.ndof).toarray()
    f = 0.8 * free_eigenfrequencies(model)[1] / (2 * np.pi)
    omega = 2 * np.pi * f
    orders = np.array([0, 1, 3])
    F_all = model.load_harmonics(3)
    lams = RNG.standard_normal((orders.size, 2 * 6))
    U_ref = np.array([full_solve(model, dense_Z(model, omega, n), F_all[n], lam)
                      for n, lam in zip(orders, lams, strict=True)])
    U = recover(model, f, orders, U_ref @ T.T)
    assert rel(U, U_ref) < RTOL
    assert np.all(U[:, model.fixed_dofs] == 0)


def test_quasi_static_equals_static_solve_for_every_harmonic():
    """quasi_static=True drops inertia and damping: for every harmonic the reduced equation
    must reproduce the static solve K U + T^T lambda = F_n (dense), and Z_r be the same for all
    harmonics (the static condensation of K)."""
    model = truss(damping="both")
    T = model.contact.local_transform(model.ndof).toarray()
    orders = np.array([0, 1, 2, 3])
    red = condense(model, 1234.0, orders, quasi_static=True)
    assert red.quasi_static
    K = model.K.toarray().astype(complex)
    F_all = model.load_harmonics(3)
    obs = np.concatenate([p.dofs for p in model.observed])
    for b, n in enumerate(orders):
        np.testing.assert_allclose(red.Z[b], red.Z[0], rtol=0, atol=0)
        lam = RNG.standard_normal(red.m) + 1j * RNG.standard_normal(red.m)
        U = full_solve(model, K, F_all[n], lam)
        u = np.linalg.solve(red.Z[b], red.F[b] - lam)
        assert rel(u, T @ U) < RTOL
        assert rel(red.obs_A[b] @ u + red.obs_b[b], U[obs]) < RTOL
    # the static reduced stiffness is real and symmetric
    assert np.abs(red.Z[0].imag).max() == 0
    np.testing.assert_allclose(red.Z[0], red.Z[0].T, rtol=1e-12, atol=0)


def test_spectral_radius_against_flexibility():
    """Largest |eig Z_r| computed independently: Z_r^-1 is the contact block of the full
    dense flexibility Z^-1 in local frames (inverse of a Schur complement = block of the
    inverse), so rho(Z_r) = 1 / min |eig(T Z^-1 T^T)|."""
    model = truss(damping="hysteretic")
    orders = np.array([0, 1, 2])
    red = condense(model, 0.5 * free_eigenfrequencies(model)[0] / (2 * np.pi), orders)
    omega = red.omega
    T = model.contact.local_transform(model.ndof).toarray()
    free = model.free_dofs()
    Tf = T[:, free]
    rho = 0.0
    for n in orders:
        Z = dense_Z(model, omega, n)[np.ix_(free, free)]
        G = Tf @ np.linalg.solve(Z, Tf.T)
        rho = max(rho, 1.0 / np.min(np.abs(np.linalg.eigvals(G))))
    assert red.spectral_radius() == pytest.approx(rho, rel=1e-9)


def test_singular_interior_raises_input_error():
    """A node hanging on one bar from a contact node has a transverse mechanism the contact
    does not hold: its static (n = 0, or quasi-static) interior stiffness is singular."""
    model = truss(dangling=True)
    with pytest.raises(InputError, match="singular"):
        condense(model, 100.0, [0, 1])
    with pytest.raises(InputError, match="singular"):
        condense(model, 100.0, [1], quasi_static=True)
    # with inertia (n >= 1, omega > 0) the mass holds it: no error
    condense(model, 100.0, [1])


def test_contact_dof_cannot_be_fixed():
    """A contact DOF that is also a Dirichlet DOF is contradictory input: InputError."""
    model = truss()
    model.fixed_dofs = np.append(model.fixed_dofs, 0)
    with pytest.raises(InputError, match="fixed"):
        condense(model, 10.0, [0])


def test_real_blocks_match_time_domain_operator():
    """to_real_blocks/loads_to_real vs the time-domain operator K u + C u' + M u'' applied to
    the real Fourier coefficients with the derivative matrix of fretwear.hb.fourier (tested on its
    own in test_fourier): the sign convention of eq. (18) for viscous damping."""
    model = truss(nx=3, ny=2, damping="rayleigh")
    omega = 900.0
    basis = FourierBasis((1, 2, 3), 16)
    orders = basis.orders
    Zc = np.array([dense_Z(model, omega, n) for n in orders])
    R = to_real_blocks(Zc, orders)
    nd, H = model.ndof, basis.size
    c = RNG.standard_normal((nd, H))  # coefficients per DOF, [0, cos.., sin..]
    D = basis.derivative_matrix(omega)
    K, C, M = (A.toarray() for A in (model.K, model.C, model.M))
    ref = K @ c + C @ c @ D.T + M @ c @ (D @ D).T
    np.testing.assert_allclose((R @ c.reshape(-1)).reshape(nd, H), ref, rtol=0,
                               atol=1e-12 * np.abs(ref).max())
    F = model.load_harmonics(3)
    samples = model.load_time(basis.tau)  # exact load samples (N, ndof)
    np.testing.assert_allclose(loads_to_real(F), basis.to_freq(samples.T), rtol=0, atol=1e-12)


def test_condenser_reused_until_the_model_changes():
    """A second condensation of the same model reuses the prepared condenser (and its static
    LU); replacing or editing a matrix in place gives a new one, whose result is that of a
    fresh model (exact comparison with a condensation of a copy)."""
    model = truss(damping="both")
    c1 = reduce.condenser(model)
    assert reduce.condenser(model) is c1
    model.K = model.K.tocsr(copy=True)
    model.K.data[0] *= 1.5
    c2 = reduce.condenser(model)
    assert c2 is not c1
    model.K.data[0] *= 2.0  # in place: seen by the fingerprint
    assert reduce.condenser(model) is not c2
    red = condense(model, 10.0, [0, 1])
    fresh = truss(damping="both")
    fresh.K = model.K.copy()
    ref = condense(fresh, 10.0, [0, 1])
    np.testing.assert_array_equal(red.Z, ref.Z)
