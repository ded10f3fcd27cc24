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

from fretwear.hb.fourier import FourierBasis
from fretwear.hb.krylov import HarmonicBlocks, KrylovJacobian
from fretwear.hb.modal import BlockedModalCondenser, ModalCondenser
from fretwear.hb.modal_operator import ReducedOperator
from fretwear.hb.operator_blocks import OperatorBlocks
from fretwear.hb.options import SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.preload import static_anchor
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.reduce import exact_condenser
from fretwear.model import ContactSpec, Damping, Material, Spring, Traction, box, from_mesh

F_MAX = 20e3  # Hz (as test_modal.py)
ORDERS = np.arange(8)


def block(damping=None, traction=3e5):
    """test_modal.py's 10 x 10 x 5 mm steel block on a rigid flat, optionally damped."""
    return from_mesh(box(0.01, 0.01, 0.005, 4, 4, 2), Material(210e9, 0.3, 7800.0),
                     damping=damping,
                     supports=[Spring("zmax", "x", 1e7), Spring("zmax", "y", 1e7)],
                     loads=[Traction("zmax", pressure=1e6),
                            Traction("zmax", traction=(traction, 0.5 * traction, 0.0),
                                     waveform="cos")],
                     contact=ContactSpec("zmin", mu=0.5),
                     observed={"corner": (0.01, 0.01, 0.005)})


def rel(a, b):
    return np.abs(np.asarray(a) - np.asarray(b)).max() / np.abs(np.asarray(b)).max()


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
    w = 2 * np.pi * 15e3
    a, b = mc.reduced(w, ORDERS), bc.reduced(w, ORDERS)
    assert isinstance(b.Z, ReducedOperator) and b.Z.shape == a.Z.shape
    assert b.Z.real == (damping is None)
    # m x m storage: K^cc and M^cc (+ C^cc, D^cc when damped), not one block per harmonic
    assert len(b.Z.mats) == (2 if damping is None else 4)
    for n in ORDERS:
        assert rel(b.Z[n], a.Z[n]) < 1e-12, n
    for name in ("F", "obs_A", "obs_b"):
        assert rel(getattr(b, name), getattr(a, name)) < 1e-12, name
    u = np.random.default_rng(1).standard_normal((ORDERS.size, a.m)) + 0j
    assert rel(bc.recover(w, ORDERS, u), mc.recover(w, ORDERS, u)) < 1e-12
    ex = exact_condenser(model).reduced(w, ORDERS[:1])
    assert rel(b.Z[0], ex.Z[0]) < 1e-10 and rel(b.F[0], ex.F[0]) < 1e-10
    # a slice is the operator of those harmonics (the one-harmonic start takes Z[:2])
    assert rel(b.Z[:2][1], a.Z[1]) < 1e-12


@pytest.mark.parametrize("damping", [None, Damping(loss_factor=0.02)])
def test_operator_blocks_products_equal_stored_blocks(damping):
    """Every product of OperatorBlocks equals HarmonicBlocks' on the formed blocks (the dense
    path), to rounding (measured <= 7e-16)."""
    model = block(damping)
    red = BlockedModalCondenser(model, F_MAX, 7, tol=1e-2).reduced(2 * np.pi * 15e3, ORDERS)
    ob = OperatorBlocks(red.Z)
    hb = HarmonicBlocks(np.stack(list(red.Z)))
    rng = np.random.default_rng(2)
    U = rng.standard_normal((ob.m, ob.H))
    assert rel(ob.apply(U), hb.apply(U)) < 1e-13
    assert rel(ob.apply_T(U), hb.apply_T(U)) < 1e-13
    rows, cols = np.arange(5, 20), np.arange(3, 30)
    X = rng.standard_normal((cols.size, ob.H, 2))
    assert rel(ob.apply_sub(rows, cols, X), hb.apply_sub(rows, cols, X)) < 1e-13
    V = rng.standard_normal((ob.m // 3, 3 * ob.H))
    assert rel(ob.node_rows(V), hb.node_rows(V)) < 1e-13
    assert rel(ob.sub(rows).dense(), hb.sub(rows).dense()) < 1e-13
    assert rel(ob.leading(2).dense(), hb.leading(2).dense()) < 1e-13


def test_operator_jacobian_against_dense_and_finite_differences():
    """In partial slip: the operator Jacobian's products, transposed products, column norms
    and Newton step on the ReducedOperator equal the formed dense Jacobian of the same
    problem (to 1e-10: GMRES_RTOL is 1e-10 for the step); one product against central finite
    differences of the residual (step 1e-7 of |U|: truncation and rounding leave ~1e-6)."""
    model = block(traction=4.5e5)
    bc = BlockedModalCondenser(model, F_MAX, 7, tol=1e-2)
    basis = FourierBasis.up_to(3, 64)
    anchor = static_anchor(model, condenser=bc)
    sol = solve_periodic(model, basis, frequency=12e3, anchor=anchor, condenser=bc)
    assert sol.success
    red = bc.reduced(2 * np.pi * 12e3, basis.orders)
    kw = dict(eps=sol.eps, anchor=sol.anchor)
    pk = DLFTProblem(red, model.contact, basis, jacobian="krylov", **kw)
    pd = DLFTProblem(red, model.contact, basis, jacobian="dense", **kw)
    U = sol.U.reshape(pk.m, pk.H)  # near the solution, off it (a residual to compare)
    U = U * (1.0 + 1e-3 * np.random.default_rng(4).standard_normal(U.shape))
    fk, J = pk.residual(U)
    fd, Jd = pd.residual(U)
    assert isinstance(J, KrylovJacobian) and isinstance(J.Z, OperatorBlocks)
    assert J.active_nodes().size > 0  # partial slip: the step is not trivial
    assert rel(fk, fd) < 1e-10
    v = np.random.default_rng(3).standard_normal(pk.m * pk.H)
    assert rel(J @ v, Jd @ v) < 1e-12
    assert rel(J.T @ v, Jd.T @ v) < 1e-12
    assert rel(J.column_norms(), np.linalg.norm(Jd, axis=0)) < 1e-12
    assert rel(J.solve(v), np.linalg.solve(Jd, v)) < 1e-8
    h = 1e-7 * np.linalg.norm(U) / np.linalg.norm(v)
    fp, _ = pk.residual(U + h * v.reshape(U.shape), False)
    fm, _ = pk.residual(U - h * v.reshape(U.shape), False)
    assert rel(J @ v, (fp - fm) / (2 * h)) < 1e-5


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


def test_bounded_preconditioner_factors_give_the_same_step(monkeypatch):
    """The GMRES step on operator blocks with the preconditioner's factors bounded to one
    factorisation (every harmonic shares it) equals the dense solve of the formed Jacobian
    (GMRES_RTOL 1e-10: asserted 1e-8), in partial slip."""
    from fretwear.hb import krylov, operator_blocks

    monkeypatch.setattr(krylov, "ACTIVE_DENSE_MAX", 0)  # GMRES whatever the size
    monkeypatch.setattr(operator_blocks.OperatorBlocks, "factor_budget", 1)  # one LU
    model = block(traction=4.5e5)
    bc = BlockedModalCondenser(model, F_MAX, 7, tol=1e-2)
    basis = FourierBasis.up_to(3, 64)
    sol = solve_periodic(model, basis, frequency=12e3, condenser=bc,
                         anchor=static_anchor(model, condenser=bc))
    red = bc.reduced(2 * np.pi * 12e3, basis.orders)
    kw = dict(eps=sol.eps, anchor=sol.anchor)
    pk = DLFTProblem(red, model.contact, basis, jacobian="krylov", **kw)
    pd = DLFTProblem(red, model.contact, basis, jacobian="dense", **kw)
    U = sol.U.reshape(pk.m, pk.H)
    _, J = pk.residual(U)
    _, Jd = pd.residual(U)
    v = np.random.default_rng(5).standard_normal(pk.m * pk.H)
    assert rel(J.solve(v), np.linalg.solve(Jd, v)) < 1e-8
    # without sharing by closeness, only the bound makes the harmonics share one LU
    act = J.active_nodes()
    dofs = (act[:, None] * 3 + np.arange(3)).reshape(-1)
    gbar = J.G[act].reshape(act.size, 3, basis.size, 3, basis.size)[:, :, 0, :, 0]
    pc = krylov.MeanGainPreconditioner(np.ascontiguousarray(gbar), J.Z.sub(dofs), J.eps,
                                       share=False)
    assert len(pc.factors) == basis.k + 1 and len({id(f) for f in pc.factors}) == 1
    monkeypatch.undo()
    pc = krylov.MeanGainPreconditioner(np.ascontiguousarray(gbar), J.Z.sub(dofs), J.eps,
                                       share=False)
    assert len({id(f) for f in pc.factors}) == basis.k + 1


def test_operator_arrays_determine_it():
    """``arrays()`` (what a wear checkpoint's fingerprint hashes instead of the formed
    blocks) changes with the frequency and is the same for the same frequency."""
    bc = BlockedModalCondenser(block(), F_MAX, 7, tol=1e-2)
    a, b, c = (bc.reduced(2 * np.pi * f, ORDERS).Z.arrays() for f in (12e3, 12e3, 13e3))
    assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))
    assert not all(np.array_equal(x, y) for x, y in zip(a, c, strict=True))
