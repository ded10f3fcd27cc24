"""One run of a solver on a DLFT balance (:mod:`fretwear.hb.runs`), the one the attempt ladder
and a sweep's polish share, checked against the balance itself and the solver called
directly."""

import numpy as np

from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.reduce import condense
from fretwear.hb.runs import run
from fretwear.hb.solvers import solve
from fretwear.model.build import Damping
from fretwear.model.core import Load
from fretwear.model.matrices import ContactDofs, from_matrices


def _chain():
    """A two-DOF chain, mass 2 rubbing on the ground under a prescribed normal force, at its
    resonance (stick and slip in its period), at 3 harmonics: its DLFT balance (Powell takes
    7 iterations from the contact-closed guess)."""
    model = from_matrices(np.array([[2.0, -1.0], [-1.0, 1.0]]), np.eye(2),
                          contact=ContactDofs(normal_dofs=None, tangential_dofs=[1], mu=0.5,
                                              normal_load=1.0),
                          damping=Damping(C=0.02 * np.eye(2)),
                          loads=[Load(np.array([0.2, 0.0]), "cos")], observed={"x": 0})
    basis = FourierBasis.up_to(3, 32)
    red = condense(model, 1.4905405 / (2 * np.pi), basis.orders)
    return DLFTProblem(red, model.contact, basis, eps=10.0)


def test_a_run_is_the_solver_on_the_balance_from_either_shape_of_start():
    """Converged: the returned harmonics (m, H) satisfy a fresh problem's balance to the
    run's tolerance (the relative residual the solvers test, evaluated independently of
    their statistics), and equal bit for bit the solver called directly on the flattened
    balance, from the start as (m, H) or flattened (the same numbers in the same order).
    Capped at one iteration: not converged, the last iterate returned with its count."""
    prob = _chain()
    opts = SolveOptions(tol=1e-10)
    x0 = prob.initial_guess()
    x, st = run(prob, x0, opts)
    assert st.success and st.iterations > 1 and x.shape == (prob.m, prob.H)
    fresh = _chain()
    f, _ = fresh.residual(x, False)
    assert np.linalg.norm(f) <= 1e-10 * fresh.scale(x)
    direct, _, _ = solve(lambda v, jac=True: prob.residual(v.reshape(prob.m, prob.H), jac),
                         x0.reshape(-1), lambda v: prob.scale(v.reshape(prob.m, prob.H)),
                         method=opts.solver, tol=opts.tol, max_iter=opts.max_iter)
    assert np.array_equal(x.reshape(-1), direct)
    assert np.array_equal(run(prob, x0.reshape(-1), opts)[0], x)
    x1, st1 = run(prob, x0, opts.replace(max_iter=1))
    assert not st1.success and st1.iterations <= 1 and x1.shape == x.shape
