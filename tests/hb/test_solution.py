"""The result of a periodic solve (:mod:`fretwear.hb.solution`): the post-processing of converged
harmonics (:func:`~fretwear.hb.solution.assemble_solution`), the full-field state at ``t = 0``
(:func:`~fretwear.hb.solution.initial_state`) and the stops of an observed point per period.

References: the balance itself (at convergence the corrected displacements equal the unknowns,
eq. 22), the observed rows of the condensation (an independent path to the displacement of a
point: the full recovery is not used there), and hand-counted zeros of a trigonometric
velocity.
"""

import dataclasses

import numpy as np
import pytest
from helpers.models import oscillator

from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.solution import initial_state

BASIS = FourierBasis.up_to(5, 64)
TOL = 1e-11


@pytest.fixture(scope="module")
def solved():
    model = oscillator()
    sol = solve_periodic(model, BASIS, frequency=15.0, options=SolveOptions(tol=TOL))
    assert sol.success, sol.message
    return model, sol


def test_corrected_displacements_equal_the_unknowns_at_convergence(solved):
    """At a converged balance ``eps (U~ - W~ - X~) = f`` with ``|f| <= tol |Z_r U~|`` (eq. 22), and
    the reported positions add the gap back: ``X = U`` to ``tol |Z_r U| / eps``. X comes from
    the time law and its FFT (assemble_solution), U from the solver: a wrong sign of the gap or
    a harmonic out of place differs by the size of U itself."""
    model, sol = solved
    scale = np.abs(sol.lam).max() + sol.eps * np.abs(sol.U).max()
    np.testing.assert_allclose(sol.X, sol.U, rtol=0, atol=10 * TOL * scale / sol.eps)


def test_initial_state_matches_the_observed_point(solved):
    """initial_state (exact recovery of every DOF from the contact harmonics) at the observed
    DOF against the observed harmonics at ``tau = 0`` (the observed rows of the condensation):
    displacement and velocity. Both are exact linear maps of the same harmonics: they agree to
    rounding (1e-10 of the amplitude)."""
    model, sol = solved
    U0, V0 = initial_state(model, sol)
    u, v = sol.observed_time("x")
    dof = model.observed[0].dofs
    np.testing.assert_allclose(U0[dof], u[:, 0], rtol=0, atol=1e-10 * np.abs(u).max())
    np.testing.assert_allclose(V0[dof], v[:, 0], rtol=0, atol=1e-10 * np.abs(v).max())


@pytest.mark.parametrize("a3, stops", [(0.0, 2), (0.5, 6)])
def test_stops_per_period_counts_the_zeros_of_the_velocity(solved, a3, stops):
    """``u = cos tau + a3 cos 3 tau``: ``v ~ sin tau (1 + 3 a3 (3 - 4 sin^2 tau))`` vanishes at
    ``sin tau = 0`` (two stops) and, for ``a3 = 0.5``, at ``sin^2 tau = 11/12`` (four more):
    2 and 6 stops, counted with a threshold (0.1 % of the peak velocity) well below the
    smallest velocity between neighbouring zeros."""
    _, sol = solved
    c = np.zeros((1, BASIS.size))
    c[0, 1] = 1.0  # cos tau
    c[0, 3] = a3  # cos 3 tau
    probe = dataclasses.replace(sol, observed={"p": c})
    assert probe.stops_per_period("p", rel_tol=1e-3) == stops


def _nan_ladder(real):
    """A ladder that answers a converged statistics with one NaN harmonic (what a
    diverging linear solve could give), to check that it is never taken as a solution."""
    def ladder(*args, **kwargs):
        best = real(*args, **kwargs)
        x = np.array(best.x, dtype=float)
        x.flat[0] = np.nan
        return dataclasses.replace(best, x=x, stats=dataclasses.replace(best.stats,
                                                                        success=True))
    return ladder


def test_a_solution_holding_nan_is_a_failure_naming_the_variable(monkeypatch):
    """A ladder that claims convergence with a NaN harmonic: solve_periodic reports a failure
    whose message names U (the harmonic given NaN here, by construction), never a success;
    with raise_on_failure it raises. The reference is the construction itself."""
    from fretwear.errors import ConvergenceError
    from fretwear.hb import attempts, periodic

    monkeypatch.setattr(periodic, "solve_ladder", _nan_ladder(attempts.solve_ladder))
    model = oscillator()
    sol = solve_periodic(model, FourierBasis.up_to(1, 16), frequency=15.0)
    assert not sol.success
    assert "non-finite" in sol.message and "U (the contact displacement harmonics)" in sol.message
    with pytest.raises(ConvergenceError, match="non-finite"):
        solve_periodic(model, FourierBasis.up_to(1, 16), frequency=15.0, raise_on_failure=True)


def test_a_sweep_point_holding_nan_is_not_converged(monkeypatch):
    """A converged answer given one NaN harmonic as a grid point adopts it (every rung of a
    point's ladder ends in ``Point.adopt``): each point is recorded as not converged with the
    message naming U, and no solution is kept."""
    from fretwear.hb import attempts
    from fretwear.hb.sweep import sweep

    real = attempts.Point.adopt

    def adopt(self, prob, U, stats, how):
        U = np.array(U, dtype=float)
        U.flat[0] = np.nan
        return real(self, prob, U, stats, how)

    monkeypatch.setattr(attempts.Point, "adopt", adopt)
    res = sweep(oscillator(), FourierBasis.up_to(1, 16), 14.0, 16.0, 2)
    assert not any(res.point_success)
    for p in res.points:
        assert p.solution is None or not p.solution.success
        assert any("non-finite" in f and "U (" in f for f in p.flags), p.flags
