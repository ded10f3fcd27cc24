"""One run of a solver on a DLFT balance (:mod:`fretwear.hb.runs`), the one the attempt ladder
and a sweep's polish share, checked against the balance itself and the solver called
directly."""

import numpy as np
from helpers.models import oscillator

from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.reduce import condense
from fretwear.hb.runs import run
from fretwear.hb.solvers import solve


def _balance():
    """The one-node friction oscillator (continuous slip) at 15 Hz, 3 harmonics, eps the
    spectral radius: its DLFT balance (Powell takes 21 iterations from the contact-closed
    guess)."""
    model = oscillator()
    basis = FourierBasis.up_to(3, 32)
    red = condense(model, 15.0, basis.orders)
    return DLFTProblem(red, model.contact, basis, eps=red.spectral_radius())


def test_a_run_is_the_solver_on_the_balance_from_either_shape_of_start():
    """Converged: the returned harmonics (m, H) satisfy a fresh problem's balance to the
    run's tolerance (the relative residual the solvers test, evaluated independently of
    their statistics), and equal bit for bit the solver called directly on the flattened
    balance, from the start as (m, H) or flattened (the same numbers in the same order).
    Capped at one iteration: not converged, the last iterate returned with its count."""
    prob = _balance()
    opts = SolveOptions(tol=1e-10)
    x0 = prob.initial_guess()
    x, st = run(prob, x0, opts)
    assert st.success and st.iterations > 1 and x.shape == (prob.m, prob.H)
    fresh = _balance()
    f, _ = fresh.residual(x, False)
    assert np.linalg.norm(f) <= 1e-10 * fresh.scale(x)
    direct, _, _ = solve(lambda v, jac=True: prob.residual(v.reshape(prob.m, prob.H), jac),
                         x0.reshape(-1), lambda v: prob.scale(v.reshape(prob.m, prob.H)),
                         method=opts.solver, tol=opts.tol, max_iter=opts.max_iter)
    assert np.array_equal(x.reshape(-1), direct)
    assert np.array_equal(run(prob, x0.reshape(-1), opts)[0], x)
    x1, st1 = run(prob, x0, opts.replace(max_iter=1))
    assert not st1.success and st1.iterations <= 1 and x1.shape == x.shape


def test_the_local_phase_is_offered_unless_the_krylov_options_turn_it_off(monkeypatch):
    """A run hands Powell the local phase of fretwear.hb.kinks (a callable) by default and
    none with ``KrylovOptions(local_phase=False)``; the solve itself is the same call (the
    solver is replaced by one that records its ``local`` and returns the start)."""
    from fretwear.hb import runs
    from fretwear.hb.options import KrylovOptions
    from fretwear.hb.solvers import SolveStats

    seen = []

    def record(fun, x0, scale, **kw):
        seen.append(kw["local"])
        return x0, fun(x0, False)[0], SolveStats(False, 1.0, 0, 0, 0, 0.0, "recorded", "")

    monkeypatch.setattr(runs, "solve", record)
    prob = _balance()
    run(prob, prob.initial_guess(), SolveOptions())
    prob.krylov = KrylovOptions(local_phase=False)
    run(prob, prob.initial_guess(), SolveOptions())
    assert callable(seen[0]) and seen[1] is None
