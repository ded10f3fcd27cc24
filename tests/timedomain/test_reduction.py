"""The reduced model of the time integration (fretwear.timedomain.reduction): Craig-Bampton
on the contact DOFs with fixed-interface modes and static load modes, diagonalised, and the
split of the damping into a Rayleigh part and a low-rank rest.

References independent of the code under test: a direct sparse solve of the full model
(statics), the dense generalised eigenvalues of the full model and the Rayleigh-Ritz bound
(a reduced model's eigenvalues are never below the full model's), a damping matrix built
here from known coefficients, and scipy's dense eigensolver against the Lanczos path.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from helpers.models import chain, truss

from fretwear.errors import InputError
from fretwear.timedomain import reduction


def test_reduction_is_exact_in_statics():
    """Craig-Bampton on the contact DOFs plus one static mode per load vector: the static
    response to any contact force and to the loads is exact. Compared with a direct sparse
    solve of the full model (round-off, 1e-9), with no fixed-interface mode kept."""
    model = chain(ks_normal=50.0)
    red = reduction.reduce_dynamics(model, 1.0, modal_cutoff=None, n_modes=0,
                                    steps_per_period=64)
    assert red.basis.shape[1] < model.ndof
    rng = np.random.default_rng(1)
    lam = rng.normal(size=2)
    F = sum(ld.vector for ld in model.loads) - model.contact.local_transform(model.ndof).T @ lam
    u_full = spla.spsolve(model.K.tocsc(), F)
    B = red.basis
    K = B.T @ (model.K @ B)
    u_red = B @ np.linalg.solve(K, B.T @ F)
    np.testing.assert_allclose(u_red, u_full, rtol=1e-9, atol=1e-12 * np.abs(u_full).max())


def full_eigenvalues(model) -> np.ndarray:
    free = model.free_dofs()
    K = model.K.toarray()[np.ix_(free, free)]
    M = model.M.toarray()[np.ix_(free, free)]
    return sla.eigh(K, M, eigvals_only=True)


def test_no_reduction_keeps_the_spectrum_and_cutoffs_bound_it_from_above():
    """With modal_cutoff="all" the reduced model is the free structure in its modal
    coordinates: its eigenvalues (the diagonal stiffness, unit modal masses) are the full
    model's to rounding (1e-9 relative: one dense eigensolve each). With a cutoff, the
    Craig-Bampton model is a Rayleigh-Ritz projection: each of its r eigenvalues lies at or
    above the full model's of the same rank (min-max theorem; 1e-9 for rounding), and the
    lowest ones, far below the cutoff, agree to 1e-3."""
    model = truss(damping="rayleigh")
    ref = full_eigenvalues(model)
    red = reduction.reduce_dynamics(model, 2 * np.pi * 100.0, modal_cutoff="all",
                                    n_modes=None, steps_per_period=64)
    assert red.diag and red.modal and red.info["reduction"] == "none"
    np.testing.assert_allclose(np.sort(red.K), ref, rtol=1e-9)
    np.testing.assert_allclose(red.M, 1.0, rtol=1e-12)
    f_cut = 1.5 * np.sqrt(ref[12]) / (2 * np.pi)  # keeps a few fixed-interface modes only
    cb = reduction.reduce_dynamics(model, 2 * np.pi * 100.0, modal_cutoff=f_cut,
                                   n_modes=None, steps_per_period=64)
    assert cb.info["reduction"] == "craig-bampton" and cb.basis.shape[1] < ref.size
    w2 = np.sort(cb.K)
    assert np.all(w2 >= ref[: w2.size] * (1 - 1e-9))
    np.testing.assert_allclose(w2[:3], ref[:3], rtol=1e-3)


def test_modal_basis_is_mass_orthonormal_and_observes_its_points():
    """``basis^T M basis = I`` and ``basis^T K basis = diag(K)`` in the full model's matrices
    (1e-9 of the largest entry: dense products of ~40 terms); the observed rows are the
    basis rows of their DOFs (zero for a fixed DOF); Tx is the contact transform of the
    basis."""
    model = truss(damping="rayleigh")
    red = reduction.reduce_dynamics(model, 2 * np.pi * 100.0, modal_cutoff=None, n_modes=4,
                                    steps_per_period=64)
    free, B = red.free, red.basis
    M = model.M.toarray()[np.ix_(free, free)]
    K = model.K.toarray()[np.ix_(free, free)]
    np.testing.assert_allclose(B.T @ M @ B, np.eye(B.shape[1]), atol=1e-9)
    KB = B.T @ K @ B
    np.testing.assert_allclose(KB, np.diag(red.K), atol=1e-9 * np.abs(KB).max())
    pos = -np.ones(model.ndof, dtype=np.int64)
    pos[free] = np.arange(free.size)
    for p, sl in zip(model.observed, red.obs_slices, strict=True):
        for row, dof in zip(red.obs[sl], p.dofs, strict=True):
            expected = B[pos[dof]] if pos[dof] >= 0 else np.zeros(B.shape[1])
            np.testing.assert_array_equal(row, expected)
    T = model.contact.local_transform(model.ndof).toarray()[:, free]
    np.testing.assert_allclose(red.Tx, T @ B, rtol=0, atol=1e-12 * np.abs(T @ B).max())


def test_damping_split_recovers_rayleigh_coefficients_and_the_springs_rest():
    """``C = a K + b M + R`` with R on two DOFs (dashpots to ground): the fit returns a, b
    (1e-9 relative: a least-squares fit on exact data) and R on exactly those DOFs (1e-6:
    R is what is left of C after the fit, with the fit's error times entries of K of 1e7)."""
    model = truss(damping=None)
    K, M = model.K, model.M
    a, b = 2e-7, 30.0
    R = sp.csr_matrix(([5.0, 3.0, -1.0, -1.0], ([4, 9, 4, 9], [4, 9, 9, 4])), shape=K.shape)
    got_a, got_b, S, Rs = reduction.damping_split(K, M, (a * K + b * M + R).tocsr())
    assert got_a == pytest.approx(a, rel=1e-9) and got_b == pytest.approx(b, rel=1e-9)
    assert S.tolist() == [4, 9]
    np.testing.assert_allclose(Rs, [[5.0, -1.0], [-1.0, 3.0]], rtol=1e-6)
    assert reduction.damping_split(K, M, sp.csr_matrix(K.shape))[:2] == (0.0, 0.0)


def test_interior_modes_by_lanczos_equal_the_dense_ones(monkeypatch):
    """The interior (contact held) eigenpairs of a large model come from shift-invert
    Lanczos; forced here on the small truss, they equal the dense eigensolver's to 1e-8
    (Lanczos converged to its default tolerance), by count and below a cutoff."""
    model = truss()
    free = model.free_dofs()
    held = np.isin(free, model.contact.dofs.ravel())
    K = model.K.tocsr()[free][:, free]
    M = model.M.tocsr()[free][:, free]
    Kii, Mii = K[~held][:, ~held].tocsc(), M[~held][:, ~held].tocsc()
    dense, _ = reduction.fixed_interface_modes(Kii, Mii, None, 5)
    w_cut = 1.01 * np.sqrt(dense[3])
    below, _ = reduction.fixed_interface_modes(Kii, Mii, w_cut, None)
    monkeypatch.setattr(reduction, "DENSE_EIG_LIMIT", 0)
    lanczos, V = reduction.fixed_interface_modes(Kii, Mii, None, 5)
    np.testing.assert_allclose(lanczos, dense, rtol=1e-8)
    np.testing.assert_allclose(V.T @ (Mii @ V), np.eye(5), atol=1e-8)
    cut, _ = reduction.fixed_interface_modes(Kii, Mii, w_cut, None)
    assert below.size == cut.size == 4
    np.testing.assert_allclose(cut, below, rtol=1e-8)


def test_bad_cutoffs_are_refused():
    model = chain()
    for bad, words in (("some", "modal_cutoff = 'some'"), (-1.0, "modal_cutoff = -1.0")):
        with pytest.raises(InputError, match=words):
            reduction.reduce_dynamics(model, 1.0, modal_cutoff=bad, n_modes=None,
                                      steps_per_period=64)
    with pytest.raises(InputError, match="n_modes"):
        reduction.reduce_dynamics(model, 1.0, modal_cutoff=None, n_modes=-1,
                                  steps_per_period=64)
