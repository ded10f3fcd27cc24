"""The settings records of the time-domain solvers (fretwear.timedomain.options).

References: the defaults the solvers had as keyword arguments before the records existed
(recorded here as numbers: 256 steps per period, gamma 1/2, contact tolerance 1e-10, 20000
periods, periodicity tolerance 1e-6, 7 harmonics, 16 / 512 / 128 periods, 300 + 500 averaged
periods, 64 load steps per cycle), which every shipped example's results depend on; and the
one-line messages that name a bad setting.
"""

import dataclasses
import math

import pytest

from fretwear.errors import InputError
from fretwear.timedomain.options import (
    AVERAGING,
    INCREMENTAL_WEAR,
    INTEGRATION,
    STEADY_STATE,
    AveragingOptions,
    IncrementalWearOptions,
    InitialState,
    IntegrationOptions,
    SteadyStateOptions,
)


def test_defaults_are_those_the_solvers_had():
    assert dataclasses.astuple(INTEGRATION) == (256, 0.5, False, None, None, 1e-10)
    assert dataclasses.astuple(STEADY_STATE) == (20_000, 1e-6, 7, 16, 512, 128)
    assert dataclasses.astuple(AVERAGING) == (300, 500, None, 1e-4)
    assert dataclasses.astuple(INCREMENTAL_WEAR) == (64, 1, 1, 1e-10)
    assert dataclasses.astuple(InitialState()) == (None, None, None, None)
    assert INTEGRATION == IntegrationOptions() and STEADY_STATE == SteadyStateOptions()
    assert AVERAGING == AveragingOptions() and INCREMENTAL_WEAR == IncrementalWearOptions()


@pytest.mark.parametrize("make, match", [
    (lambda: IntegrationOptions(steps_per_period=3), r"steps_per_period = 3; expected an "
                                                     r"integer >= 4"),
    (lambda: IntegrationOptions(steps_per_period=64.0), "steps_per_period = 64.0"),
    (lambda: IntegrationOptions(gamma=0.4), r"gamma = 0.4; expected 0.5 .* to 1"),
    (lambda: IntegrationOptions(gamma="fast"), "gamma = 'fast'"),
    (lambda: IntegrationOptions(contact_tol=0.0), "contact_tol = 0.0"),
    (lambda: SteadyStateOptions(max_periods=0), "max_periods = 0"),
    (lambda: SteadyStateOptions(window=7), r"window = 7; expected an integer >= 8"),
    (lambda: SteadyStateOptions(check_every=True), "check_every = True"),
    (lambda: SteadyStateOptions(tol=math.nan), "tol = nan"),
    (lambda: IncrementalWearOptions(steps_per_cycle=1), "steps_per_cycle = 1"),
    (lambda: IncrementalWearOptions(cycle_jump=0), "cycle_jump = 0"),
    (lambda: IncrementalWearOptions(record_every=-1), "record_every = -1"),
    (lambda: IncrementalWearOptions(contact_tol=-1e-10), "contact_tol = -1e-10"),
])
def test_a_bad_setting_is_named(make, match):
    with pytest.raises(InputError, match=match):
        make()


def test_records_are_frozen_and_replaced_checked():
    """A record cannot change under a solver that holds it; ``replace`` gives a checked
    copy."""
    with pytest.raises(dataclasses.FrozenInstanceError):
        INTEGRATION.steps_per_period = 64
    fine = INTEGRATION.replace(steps_per_period=64, hf_damping=True)
    assert (fine.steps_per_period, fine.hf_damping, INTEGRATION.steps_per_period) == (64, True,
                                                                                        256)
    with pytest.raises(InputError, match="gamma = 2"):
        INTEGRATION.replace(gamma=2)
    assert STEADY_STATE.replace(tol=1e-8).tol == 1e-8
    assert isinstance(IntegrationOptions(gamma=1).gamma, float)
