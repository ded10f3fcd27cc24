"""The blocked modal condensation (fretwear.hb.modal: no Psi held, Z_r as a
ReducedOperator of shared matrices and a low-rank term per harmonic) against the dense modal
condensation of fretwear.hb.modal (itself checked against the exact condensation in
test_modal.py), the exact condensation, the dense Jacobian and finite differences.

Tolerances: the two modal condensations are the same algebra in another order of operations
(Psi^T W by a second solve instead of a product with the stored Psi): they agree to rounding,
measured 1.5e-16 to 3e-15 relative, asserted 1e-12 (a projection conditioned ~1e3 and
rounding of 1e-16 leave a margin of 1e3). The periodic solves stop at the solver's tolerance
(1e-9 of |Z U|) from the same start with the same iterates up to rounding: asserted 1e-8.
"""

import numpy as np
import pytest
from helpers.operator_models import (
    F_MAX,
    ORDERS,
    block,
    rel,
    same_partial_slip_solution,
    same_reductions,
)

from fretwear.hb.fourier import FourierBasis
from fretwear.hb.modal import BlockedModalCondenser, ModalCondenser
from fretwear.hb.modal_operator import ReducedOperator
from fretwear.hb.options import SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.preload import static_anchor
from fretwear.model import Damping


@pytest.mark.parametrize("damping", [None, Damping(loss_factor=0.02, rayleigh_mass=100.0,
                                                   rayleigh_stiffness=1e-7)])
def test_blocked_equals_dense_modal_condensation(damping):
    """Z_r (every harmonic), loads, observed rows and recovery: the blocked condenser equals
    the dense one to rounding; its check error is the same; harmonic 0 equals the exact
    condensation (static constraint modes: exact)."""
    model = block(damping)
    mc = ModalCondenser(model, F_MAX, 7, tol=1e-2)
    bc = BlockedModalCondenser(model, F_MAX, 7, tol=1e-2)
    assert bc.n_modes == mc.n_modes and abs(bc.error - mc.error) <= 1e-9 * mc.error
    a, b = same_reductions(model, mc, bc, 1e-12)
    assert isinstance(b.Z, ReducedOperator) and b.Z.shape == a.Z.shape
    assert b.Z.real == (damping is None)
    # m x m storage: K^cc and M^cc (+ C^cc, D^cc when damped), not one block per harmonic
    assert len(b.Z.mats) == (2 if damping is None else 4)
    # a slice is the operator of those harmonics (the one-harmonic start takes Z[:2])
    assert rel(b.Z[:2][1], a.Z[1]) < 1e-12


def test_periodic_solve_in_partial_slip_equals_dense_modal_path():
    """The periodic solve through the blocked condenser (operator Jacobian) reaches the
    solution of the dense modal condenser with the formed Jacobian, in partial slip."""
    model = block(traction=4.5e5)
    basis = FourierBasis.up_to(3, 64)  # 27 % of area x period slips, 6.5 % separates
    out = []
    for cond, jac in ((ModalCondenser(model, F_MAX, 7, tol=1e-2), "dense"),
                      (BlockedModalCondenser(model, F_MAX, 7, tol=1e-2), "krylov")):
        sol = solve_periodic(model, basis, frequency=12e3, options=SolveOptions(jacobian=jac),
                             anchor=static_anchor(model, condenser=cond), condenser=cond)
        assert sol.success
        out.append(sol)
    slip = out[1].state_fractions().mean(axis=0)[2]
    assert 0.02 < slip < 0.98  # partial slip
    assert rel(out[1].U, out[0].U) < 1e-8


@pytest.mark.parametrize("damping", [None, Damping(loss_factor=0.02, rayleigh_mass=100.0,
                                                   rayleigh_stiffness=1e-7)])
def test_dense_condenser_as_operator_equals_its_blocks(damping):
    """ModalCondenser with ``representation="operator"`` (what "auto" takes on large
    interfaces) against the same condenser's dense blocks: the same projections summed in
    another order, so equal to rounding (1e-12, as above); "auto" keeps the blocks on this
    small model; a periodic solve in partial slip through the operator reaches the dense
    path's solution (1e-8: both stop at the solver's tolerance)."""
    model = block(damping)
    mc = ModalCondenser(model, F_MAX, 7, tol=1e-2)
    oc = ModalCondenser(model, F_MAX, 7, tol=1e-2, representation="operator")
    w = 2 * np.pi * 15e3
    a, b = mc.reduced(w, ORDERS), oc.reduced(w, ORDERS)
    assert isinstance(a.Z, np.ndarray) and isinstance(b.Z, ReducedOperator)
    assert len(b.Z.mats) == (2 if damping is None else 4)
    for n in range(ORDERS.size):
        assert rel(b.Z[n], a.Z[n]) < 1e-12, n
    for name in ("F", "obs_A", "obs_b"):
        assert rel(getattr(b, name), getattr(a, name)) < 1e-12, name
    if damping is not None:
        return
    same_partial_slip_solution(
        lambda m: ModalCondenser(m, F_MAX, 7, tol=1e-2, representation="dense"),
        lambda m: ModalCondenser(m, F_MAX, 7, tol=1e-2, representation="operator"))


def test_representation_is_checked():
    """A representation that is not one of the three is one InputError naming it."""
    from fretwear.errors import InputError

    with pytest.raises(InputError, match="representation = 'sparse'"):
        ModalCondenser(block(None), F_MAX, 3, tol=1e-2, representation="sparse")


def test_projections_taken_while_psi_is_in_hand():
    """The blocked condenser takes the rows of ``X^cq = X_ci V + Psi^T X_ii V`` from each
    block of ``Psi`` while it is in hand: against the same products formed independently
    with SciPy's sparse LU (``Psi`` whole, from ``-K_ii^-1 K_ic``) to 1e-12 (rounding of a
    projection conditioned ~1e3, as above); ``K^qc`` is zero (``K_ii Psi = -K_ic``) and
    ``K^cq`` vanishes to rounding of the static condensation's size; its many-column solves'
    panels are dropped once the projections are made."""
    import scipy.sparse.linalg as spla

    model = block(Damping(loss_factor=0.02, rayleigh_mass=100.0, rayleigh_stiffness=1e-7))
    bc = BlockedModalCondenser(model, F_MAX, 7, tol=1e-2)
    Psi = -spla.splu(bc.K.ii.tocsc()).solve(bc.K.ic.toarray())
    for nm in ("M", "C", "D"):
        X = getattr(bc, nm)
        cq = bc.R @ (X.ci @ bc.V + Psi.T @ (X.ii @ bc.V))
        assert rel(bc.proj_local[nm][1], cq) < 1e-12, nm
    cc, cq, qc, _ = bc.proj_local["K"]
    assert not np.any(qc)
    assert np.abs(cq).max() < 1e-12 * np.abs(cc).max() * np.sqrt(bc.m)
    assert getattr(bc._lu0, "_sn", None) is None
