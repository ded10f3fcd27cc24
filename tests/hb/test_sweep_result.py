"""The result of a sweep (:mod:`fretwear.hb.sweep_result`): counts, summary and amplitudes of its
points, against hand-built points and the observed amplitude of a solution
(:meth:`~fretwear.hb.solution.PeriodicSolution.observed_amplitude`, fretwear.hb.fourier's
amplitude: another path to the same numbers)."""

import numpy as np
from helpers.models import oscillator

from fretwear.hb.fourier import FourierBasis
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.solvers import SolveStats
from fretwear.hb.sweep_result import SweepPoint, SweepResult


def failed(f, on_grid=True, timed=""):
    st = SolveStats(False, 1.0, 3, 3, 3, 0.0, "stalled", "powell")
    return SweepPoint(f, None, st, "grid", ["not converged: stalled"], on_grid, timed)


def test_counts_and_summary_over_the_grid_frequencies():
    """Intermediate points (not on the grid) are not counted; failed grid points and those the
    time integration flagged are."""
    sol = solve_periodic(oscillator(), FourierBasis.up_to(3, 32), frequency=15.0)
    ok = SweepPoint(15.0, sol, sol.stats, "grid", [], True)
    res = SweepResult([ok, failed(15.5, on_grid=False), failed(16.0, timed="quasi-periodic"),
                       failed(17.0)])
    assert not res.success and res.point_success.tolist() == [True, False, False, False]
    assert res.message == "1 of 3 points converged; 2 not converged (1 flagged by the time " \
                          "integration)"
    lines = res.summary().splitlines()
    assert lines[0] == "sweep_converged=1/3" and len(lines) == 4
    amp = res.amplitude("x", 0, 1)
    assert np.isnan(amp[1:]).all()
    np.testing.assert_allclose(amp[0], sol.observed_amplitude("x")[0][0], rtol=1e-14)
