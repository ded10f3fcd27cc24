"""The structure's dynamic stiffness at complex Laplace variables, condensed on the contact
(fretwear.hb.dynamics).

References independent of the code under test: the balance's own condensation
(:func:`fretwear.hb.reduce.condense`, then :func:`fretwear.hb.connectors.connect` through
contact springs) at ``lambda = i n w``; and, at complex ``lambda``, the Schur complement of
``K + lambda^2 M + lambda C + c D`` formed here from the model's dense matrices and rotated into
the contact frames by hand (eq. 19).
"""

import numpy as np
import pytest
from helpers.models import truss, two_dof

from fretwear.errors import InputError
from fretwear.hb import dynamics
from fretwear.hb.connectors import connect
from fretwear.hb.dynamics import structure_dynamics
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.reduce import condense


def test_condensed_stiffness_equals_the_balance_s_condensation_through_springs():
    """At ``lambda = i n w`` the structure's coordinates ``(x, q)`` with the contact springs as
    massless points give the reduced model of the balance (eq. 19 then
    ``connectors.connect``), to rounding: the same Schur complement two ways."""
    model = two_dof(kn=7.0)
    basis = FourierBasis.up_to(5, 32)
    w = 0.61
    ref = connect(condense(model, w / (2 * np.pi), basis.orders), model.contact).Z
    lam = 1j * w * basis.orders
    Z = structure_dynamics(model).condensed(lam * lam, lam, 1j * np.sign(lam.imag))
    assert np.abs(Z - ref).max() <= 1e-12 * np.abs(ref).max()


def dense_reference(model, lam, hyst):
    """``R (Z_cc - Z_ci Z_ii^-1 Z_ic) R^T`` of ``Z = K + lam^2 M + lam C + hyst D`` on the free
    DOFs, contact DOFs ``c`` in the model's node order, ``R`` the contact frames (block
    diagonal), and the static load condensed the same way (``lam = 0``, no D)."""
    free = model.free_dofs()
    c = model.contact.dofs.ravel()
    i = np.setdiff1d(free, c)
    Z = model.K.toarray() + lam**2 * model.M.toarray()
    if model.C is not None:
        Z = Z + lam * model.C.toarray()
    if model.D is not None:
        Z = Z + hyst * model.D.toarray()
    S = Z[np.ix_(c, c)] - Z[np.ix_(c, i)] @ np.linalg.solve(Z[np.ix_(i, i)], Z[np.ix_(i, c)])
    nc, d = model.contact.dofs.shape
    R = np.zeros((nc * d, nc * d))
    for p in range(nc):
        R[p * d:(p + 1) * d, p * d:(p + 1) * d] = model.contact.frame[p]
    K = model.K.toarray()
    F = model.load_harmonics(0)[0].real
    Fc = F[c] - K[np.ix_(c, i)] @ np.linalg.solve(K[np.ix_(i, i)], F[i])
    return R @ S @ R.T, R @ Fc, F[i]


@pytest.mark.parametrize("damping", ["hysteretic", "rayleigh", "both"])
def test_condensed_stiffness_at_complex_lambda_is_the_dense_schur_complement(damping):
    """The braced truss (21 interior DOFs, tilted contact frames) at three complex values of
    lambda, one of them in the left half-plane: ``Z_r`` equals the dense reference to 1e-10
    of its largest entry (two dense solves of 21 unknowns with entries up to 1e7, whose
    conditioning is far below 1e5); the condensed static load the same to 1e-10."""
    model = truss(damping=damping)
    dyn = structure_dynamics(model)
    assert dyn.exact and dyn.m == 12 and dyn.q == 21
    lams = np.array([2j * np.pi * 300.0, 150.0 + 2j * np.pi * 900.0, -80.0 + 4000j])
    hyst = 1j * np.sign(lams.imag)
    Z = dyn.condensed(lams**2, lams, hyst)
    for k, lam in enumerate(lams):
        ref, load_x, load_q = dense_reference(model, lam, hyst[k])
        assert np.abs(Z[k] - ref).max() <= 1e-10 * np.abs(ref).max()
    np.testing.assert_allclose(dyn.load_x, load_x, rtol=0, atol=1e-10 * np.abs(load_x).max())
    np.testing.assert_array_equal(dyn.load_q, load_q)


def test_blocks_of_z_are_those_of_each_matrix_entry_by_entry():
    """``assemble`` forms ``Z = K + a M + b C + c D`` once on the whole matrices
    (``StructureDynamics.full``) and cuts it into ``(xx, xq, qx, qq)``: bit for bit the same as
    forming it block by block from ``blocks`` (the same operations on every entry), checked
    on the braced truss with both dampings at two complex coefficients, and ``full`` is
    ``[[xx, xq], [qx, qq]]`` of each matrix."""
    dyn = structure_dynamics(truss(damping="both"))
    lam = np.array([150.0 + 2j * np.pi * 900.0, -80.0 + 4000j])
    a, b, c = lam**2, lam, 1j * np.sign(lam.imag)
    got = dyn.assemble(a, b, c)
    for i in range(4):
        ref = a[:, None, None] * dyn.blocks["M"][i] + dyn.blocks["K"][i]
        ref = ref + b[:, None, None] * dyn.blocks["C"][i]
        ref = ref + c[:, None, None] * dyn.blocks["D"][i]
        np.testing.assert_array_equal(got[i], ref)
    for name, (xx, xq, qx, qq) in dyn.blocks.items():
        np.testing.assert_array_equal(dyn.full[name], np.block([[xx, xq], [qx, qq]]))


def test_a_large_interior_needs_a_modal_representation(monkeypatch):
    """Above DENSE_INTERIOR_MAX interior DOFs the exact transformation is not formed: one
    InputError saying how many and what to do."""
    monkeypatch.setattr(dynamics, "DENSE_INTERIOR_MAX", 20)
    with pytest.raises(InputError, match=r"21 interior DOFs.*modal_condenser"):
        structure_dynamics(truss())


@pytest.mark.parametrize("damping", ["rayleigh", "both"])
def test_modal_condensation_equals_the_interior_solve(damping, monkeypatch):
    """With proportional damping every interior block is diagonal in the held structure's
    modes, and ``Z_r`` through them (``m^2 q`` a value) equals the one by a solve with
    ``Z^qq`` (the path below ``MODAL_FROM`` interior DOFs, forced here) to 1e-12 of its
    largest entry at three complex values (both are backward stable; the truss's ``Z^qq``
    is far from singular there), and its Schur correction ``Z^xx - Z_r`` to 1e-10 of the
    correction's own size. A damper on one interior DOF (not diagonal in the modes)
    takes the solve."""
    dyn = structure_dynamics(truss(damping=damping))
    assert dyn.q >= dynamics.MODAL_FROM and dyn._modal_interior is not None
    lams = np.array([2j * np.pi * 300.0, 150.0 + 2j * np.pi * 900.0, -80.0 + 4000j])
    args = (lams**2, lams, 1j * np.sign(lams.imag))
    got = dyn.condensed(*args)
    monkeypatch.setattr(dynamics, "MODAL_FROM", 10**9)
    ref = dyn.condensed(*args)
    assert np.abs(got - ref).max() <= 1e-12 * np.abs(ref).max()
    # and the Schur correction alone (1e-5 to 1e-3 of Z_r on the truss), to 1e-10 of its own
    # size: a dropped mode moves it by 3e-9 (the highest) to 1e-5 (the lowest)
    xx = dyn.assemble(*args)[0]
    corr = xx - ref
    assert np.abs((xx - got) - corr).max() <= 1e-10 * np.abs(corr).max()
    C = dyn.blocks["C"]
    damper = C[3].copy()
    damper[0, 0] += 10.0 * np.abs(C[3]).max()
    dyn.blocks["C"] = (C[0], C[1], C[2], damper)
    assert dynamics.StructureDynamics(dyn.blocks, dyn.load_x, dyn.load_q,
                                      dyn.exact)._modal_interior is None
