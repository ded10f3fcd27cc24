"""The wear rate's derivatives on the operator path of large interfaces (fretwear.hb.krylov:
no formed ``Z~``, the step reduced to the active nodes or solved by GMRES) against the dense
path of the same SlowProblem.

Reference: the dense path forms ``eps I - Z~`` (reduce.to_real_blocks) and the Jacobian and
solves by LAPACK LU, independently of the harmonic-block products and the active-node or
GMRES solves tested here. Small 2D and 3D blocks with separation, stick and slip during the
period (tests/helpers/blocks.py; asserted in tests/hb/test_krylov.py). Tolerances: the
gradient is the same sums in another order (1e-12 of the largest entry); dU/dW and the slow
Jacobian go through the step, exact to rounding by LU (1e-10) and to GMRES's 1e-10 relative
residual (1e-8, the acceptance of issue 16).
"""

import functools

import numpy as np
import pytest
from helpers.blocks import block

from fretwear.hb import krylov, problem
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.krylov import KrylovJacobian
from fretwear.hb.options import SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.preload import static_anchor
from fretwear.hb.reduce import condense
from fretwear.wear.slow_problem import SlowProblem


@functools.cache
def make_case(dim):
    model = block(dim)
    basis = FourierBasis.up_to(3, 32)
    red = condense(model, 2000.0, basis.orders)
    anchor = static_anchor(model)
    sol = solve_periodic(model, basis, frequency=2000.0, reduced=red, anchor=anchor,
                         options=SolveOptions(tol=1e-12))
    assert sol.success
    coef = np.full(model.contact.n_nodes, 1e-15)
    return model, basis, red, anchor, sol.U.reshape(-1, basis.size), coef


def slow(case, monkeypatch, operator):
    model, basis, red, anchor, _, coef = case
    if operator:
        monkeypatch.setattr(problem, "DENSE_JACOBIAN_MAX", 0)
    sp = SlowProblem(model, red, basis, coef, anchor=anchor)
    assert (sp.prob.jacobian == "krylov") == operator
    return sp


@pytest.mark.parametrize("dim, step", [(2, "active"), (3, "active"), (2, "gmres")])
def test_slow_jacobian_equals_dense_path(dim, step, monkeypatch):
    """g, dg/dU~, dg/dW, dU~/dW and the slow Jacobian of the operator path equal the dense
    path's (every contact state present, slipping nodes wear; GMRES, one solve per node, in
    2D only, for time)."""
    case = make_case(dim)
    U = case[4]
    ref = slow(case, monkeypatch, False)
    g0, gU0, gW0, _ = ref.rate_and_gradient(U)
    Js0, dUdW0 = ref.slow_jacobian(U, with_dUdW=True)
    if step == "gmres":
        monkeypatch.setattr(krylov, "ACTIVE_DENSE_MAX", -1)
    op = slow(case, monkeypatch, True)
    assert isinstance(op.balance(U)[1], KrylovJacobian)
    assert op._epsI_Z is None
    g, gU, gW, _ = op.rate_and_gradient(U)
    assert np.any(g > 0) and np.abs(gU).max() > 0
    np.testing.assert_allclose(g, g0, rtol=1e-12)
    np.testing.assert_allclose(gW, gW0, rtol=1e-12)
    assert np.abs(gU - gU0).max() <= 1e-12 * np.abs(gU0).max()
    Js, dUdW = op.slow_jacobian(U, with_dUdW=True)
    assert op._epsI_Z is None  # the n x n matrix was never formed
    assert np.abs(dUdW - dUdW0).max() <= 1e-8 * np.abs(dUdW0).max()
    assert np.abs(Js - Js0).max() <= 1e-8 * np.abs(Js0).max()


@pytest.mark.parametrize("dim", [2])
def test_slow_radius_from_products_equals_the_eigenvalues(dim, monkeypatch):
    """With the GMRES step the spectral radius of the slow Jacobian comes from ARPACK on its
    products (no nc solves); it equals the largest |eigenvalue| of the dense path's formed
    slow Jacobian (numpy.linalg.eigvals) to the 1e-3 asked of ARPACK."""
    case = make_case(dim)
    U = case[4]
    ref = slow(case, monkeypatch, False)
    assert not ref.needs_iterative_solves(U)
    rho0 = float(np.max(np.abs(np.linalg.eigvals(ref.slow_jacobian(U)))))
    assert ref.slow_radius(U) == rho0
    monkeypatch.setattr(krylov, "ACTIVE_DENSE_MAX", -1)
    op = slow(case, monkeypatch, True)
    assert op.needs_iterative_solves(U)
    assert abs(op.slow_radius(U) - rho0) <= 1e-3 * rho0


def test_implicit_schemes_refused_when_the_step_is_iterative(monkeypatch):
    """A wear run whose balance needs GMRES (active set above the direct size) refuses the
    linearly implicit default with one message naming the scheme, instead of running one
    iterative solve per node at every step; the explicit scheme runs."""
    from fretwear.errors import InputError
    from fretwear.wear import BalanceSetup, WearOptions, simulate_wear

    model, basis, red, anchor, U, _ = make_case(2)
    monkeypatch.setattr(problem, "DENSE_JACOBIAN_MAX", 0)
    monkeypatch.setattr(krylov, "ACTIVE_DENSE_MAX", -1)
    kw = dict(frequency=2000.0, balance=BalanceSetup(reduced=red, anchor=anchor, U0=U))
    with pytest.raises(InputError, match="scheme = 'rosenbrock'"):
        simulate_wear(model, basis, options=WearOptions(max_steps=1), **kw)
    res = simulate_wear(model, basis, options=WearOptions(max_steps=1, scheme="explicit"),
                        **kw)
    assert res.success
