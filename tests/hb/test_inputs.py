"""The checks of a periodic solve's arguments (:func:`fretwear.hb.inputs.check_inputs`): one
InputError (or TypeError for an object of the wrong kind) naming the argument, the value and
what is expected. The public entry points are exercised in tests/test_api.py."""

import numpy as np
import pytest
from helpers.models import oscillator

from fretwear.errors import InputError
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.inputs import check_inputs

BASIS = FourierBasis.up_to(3, 32)


def test_good_inputs_return_the_frequency_as_a_float():
    f = check_inputs(oscillator(), BASIS, 15)
    assert f == 15.0 and type(f) is float


@pytest.mark.parametrize("kw, match", [
    ({"anchor": np.zeros((1, 2))}, r"anchor has shape \(1, 2\)"),
    ({"anchor": np.array([[np.nan]])}, "anchor has shape .* expected finite"),
    ({"U0": np.zeros((3, 7))}, r"U0 has shape \(3, 7\)"),
])
def test_bad_arrays_are_named(kw, match):
    with pytest.raises(InputError, match=match):
        check_inputs(oscillator(), BASIS, 15.0, **kw)


def test_a_dynamic_solve_needs_a_positive_frequency():
    with pytest.raises(InputError, match="frequency = 0.0 Hz: expected > 0"):
        check_inputs(oscillator(), BASIS, 0.0)
    assert check_inputs(oscillator(), BASIS, 0.0, quasi_static=True) == 0.0


def test_objects_of_the_wrong_kind():
    with pytest.raises(TypeError, match="expected a fretwear Model"):
        check_inputs("model", BASIS, 15.0)
    with pytest.raises(TypeError, match="expected a fretwear FourierBasis"):
        check_inputs(oscillator(), (1, 2, 3), 15.0)


def test_the_frequency_is_required_unless_quasi_static():
    """No silent 1 Hz: a dynamic solve without a frequency is refused in one line; a
    quasi-static one runs at QUASI_STATIC_FREQUENCY (it only sets the time scale)."""
    from fretwear.hb.inputs import QUASI_STATIC_FREQUENCY
    from fretwear.hb.periodic import solve_periodic

    with pytest.raises(InputError, match="^frequency is missing: expected the excitation "
                                         r"frequency \[Hz\] > 0") as err:
        solve_periodic(oscillator(), BASIS)
    assert "\n" not in str(err.value)
    assert check_inputs(oscillator(), BASIS, None, quasi_static=True) == QUASI_STATIC_FREQUENCY
