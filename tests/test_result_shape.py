"""Every result object says whether it succeeded and why it stopped, in one shape (as
:class:`scipy.optimize.OptimizeResult`): ``success`` (a bool) and ``message`` (a non-empty
str), plus its details.

Tiny models (a one-node friction oscillator, three independent sliders) so that each call is
cheap; where a failure can be provoked cheaply (one solver iteration, a time integration too
short to classify the response, a forced failure of the slow steps, a coarse time step
where a contact solve does not settle) it is checked too; the incremental wear has no cheap
failure to provoke.
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers.cases import FIXED, small_case
from helpers.models import K_, M_, oscillator, sliders

from fretwear.analyses.run import load_case
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SWEEP_POINT, SolveOptions, SweepOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.sweep import sweep
from fretwear.io.case import build_model
from fretwear.timedomain.integrate import integrate
from fretwear.timedomain.options import (
    IncrementalWearOptions,
    IntegrationOptions,
    SteadyStateOptions,
)
from fretwear.timedomain.quasistatic import incremental_wear
from fretwear.timedomain.steady import steady_state
from fretwear.wear import SlowProblem, WearOptions, simulate_wear

BASIS = FourierBasis.up_to(3, 32)
F_HZ = 0.7 * np.sqrt(K_ / M_) / (2 * np.pi)  # [Hz] continuous slip, below the resonance


def check_shape(result, success: bool):
    assert isinstance(result.success, bool) and result.success is success, result.message
    assert isinstance(result.message, str) and result.message


def test_solve_periodic():
    model = oscillator()
    sol = solve_periodic(model, BASIS, frequency=F_HZ)
    check_shape(sol, True)
    assert sol.message == sol.stats.message
    bad = solve_periodic(model, BASIS, frequency=F_HZ, options=SolveOptions(max_iter=1, tol=1e-14))
    check_shape(bad, False)
    assert bad.stats.success is False and bad.U.shape == sol.U.shape  # the last iterate


def test_sweep():
    model = oscillator()
    res = sweep(model, BASIS, 0.9 * F_HZ, 1.1 * F_HZ, 3)
    check_shape(res, True)
    assert res.message == "3 of 3 points converged"
    assert res.point_success.tolist() == [True] * 3
    for p in res.points:
        check_shape(p, True)
    bad = sweep(model, BASIS, 0.9 * F_HZ, 1.1 * F_HZ, 3,
                options=SweepOptions(solve=SWEEP_POINT.replace(max_iter=1, tol=1e-15),
                                     continuation=False, max_bisections=1))
    check_shape(bad, False)
    assert bad.message == "0 of 3 points converged; 3 not converged"
    assert not bad.point_success.any()
    for p in bad.points:
        check_shape(p, False)


def test_simulate_wear(monkeypatch):
    model = sliders()
    res = simulate_wear(model, BASIS, quasi_static=True, options=WearOptions(max_steps=2))
    check_shape(res, True)
    assert res.stop_reason == "max_steps"

    real = SlowProblem.solve_balance

    def failing(self, *a, **k):
        U, st = real(self, *a, **k)
        st.success = False
        st.message = "forced failure"
        return U, st

    monkeypatch.setattr(SlowProblem, "solve_balance", failing)
    bad = simulate_wear(model, BASIS, quasi_static=True,
                        options=WearOptions(max_steps=2, max_retries=0))
    check_shape(bad, False)
    assert bad.stop_reason == "solver_failed" and "forced failure" in bad.message


def test_integrate(tmp_path):
    res = integrate(oscillator(), F_HZ, n_periods=2,
                    options=IntegrationOptions(steps_per_period=64))
    check_shape(res, True)
    # the 10 x 2 beam of tests/analyses/test_transient.py at 1 kHz with a coarse step: one
    # contact solve of its third period does not settle (measured; the run warns and says so)
    model = build_model(load_case(small_case(tmp_path, FIXED)))
    with pytest.warns(RuntimeWarning, match="did not settle"):
        bad = integrate(model, 1e3, options=IntegrationOptions(steps_per_period=64), n_periods=3)
    check_shape(bad, False)
    assert "did not settle" in bad.message


def test_steady_state():
    model = oscillator()
    res = steady_state(model, F_HZ, integration=IntegrationOptions(steps_per_period=64))
    check_shape(res, True)
    assert res.classification == "periodic" and res.periodic
    short = steady_state(model, F_HZ, options=SteadyStateOptions(max_periods=2),
                         integration=IntegrationOptions(steps_per_period=64))
    check_shape(short, False)
    assert short.classification == "transient" and not short.periodic


@pytest.mark.parametrize("raise_on_failure", [True, False])
def test_incremental_wear(raise_on_failure):
    res = incremental_wear(sliders(), options=IncrementalWearOptions(steps_per_cycle=16),
                           n_cycles=3, raise_on_failure=raise_on_failure)
    check_shape(res, True)
