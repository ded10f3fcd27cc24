"""The family of FRFs over the excitation level (fretwear.levels) and the sweep key
``excitation_scale``.

References: a Jenkins oscillator (mass m on a spring k, tied to the ground through a
tangential spring kt in series with a Coulomb slider under a normal load N), whose response
below the slip limit mu N / kt is the stuck linear one, u = F / (k + kt - m w^2), in closed
form: at low levels the FRF equals it and scales exactly with the level; above the limit the
element slips and the structure is softer (a larger response below resonance). The load's
scaling is checked on the model's own vectors (the constant load kept).
"""

from __future__ import annotations

import numpy as np
import pytest

import fretwear as fw
from fretwear.errors import InputError
from fretwear.levels import excitation_scaled, load_levels
from fretwear.model.core import Load
from fretwear.model.matrices import ContactDofs, from_matrices

K, M, KT, MU, N = 2e5, 0.5, 2e5, 0.3, 10.0  # slip limit mu N / kt = 15 um


def jenkins():
    return from_matrices([[K]], [[M]], contact=ContactDofs(
        normal_dofs=None, tangential_dofs=[0], mu=MU, normal_load=N, kt=KT),
        loads=[Load(np.array([1.0]), "cos", name="shake"),
               Load(np.array([0.5]), "constant", name="static")], observed={"mass": 0})


def test_excitation_scale_multiplies_the_time_varying_loads_only():
    model = jenkins()
    scaled = excitation_scaled(model, 3.0)
    assert excitation_scaled(model, 1.0) is model
    np.testing.assert_array_equal(scaled.loads[0].vector, 3.0 * model.loads[0].vector)
    np.testing.assert_array_equal(scaled.loads[1].vector, model.loads[1].vector)
    for bad in (0.0, -1.0, float("nan"), True):
        with pytest.raises(InputError, match="level = "):
            excitation_scaled(model, bad)


def test_low_levels_are_the_stuck_linear_frf_and_a_high_level_slips():
    """Levels 0.5 and 1 N (response below 15 um on 50-90 Hz): the amplitude equals the
    closed-form stuck response to 1e-8 relative (the balance's tolerance; one harmonic is
    exact for a linear response) and scales exactly with the level; at 10 N the element
    slips (response up to 42 um stuck) and the response is larger than the stuck one."""
    model = jenkins()
    basis = fw.FourierBasis((1,), 64)
    fam = load_levels(model, basis, 50.0, 90.0, 5, [10.0, 0.5, 1.0])
    assert fam.levels == [0.5, 1.0, 10.0] and fam.success, fam.message
    w = 2 * np.pi * fam.results[0].frequency_hz
    stuck = 1.0 / (K + KT - M * w**2)
    for level, r in zip(fam.levels[:2], fam.results[:2], strict=True):
        np.testing.assert_allclose(r.amplitude("mass", 0, 1), level * stuck, rtol=1e-8)
    slip = fam.results[2].amplitude("mass", 0, 1)
    assert np.all(slip[-2:] > 1.05 * 10.0 * stuck[-2:])
    amp, freq = fam.peaks("mass")
    np.testing.assert_allclose(amp[:2], [0.5 * stuck[-1], stuck[-1]], rtol=1e-8)
    np.testing.assert_array_equal(freq, [90.0, 90.0, 90.0])
    with pytest.raises(InputError, match="levels = "):
        load_levels(model, basis, 50.0, 90.0, 5, [])
