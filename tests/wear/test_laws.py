"""Tests of the wear laws (:mod:`fretwear.wear.laws`): wear per cycle, Archard's and the
energy law, and the zones left unworn.

References, each independent of the code under test:

* the friction energy of :func:`fretwear.hb.contact.friction_work` (a separate code path): with
  Archard's law and Coulomb slip, worn volume per cycle = k_w / mu x friction energy, exactly
  on the same samples; and the energy law with k_e = k_w / mu gives Archard's wear;
* the closed-form quasi-static Coulomb oscillator (a contact node on a tangential spring k_t
  under a constant normal load and a sinusoidal tangential load of amplitude Q > mu P A):
  slip path 4 (Q - mu P A) / k_t per cycle, so Archard's rate is k_w P x that path;
* a hand-made wear profile for the unworn zones.

Moved unchanged from tests/wear/test_simulate.py.
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers.models import sliders
from helpers.wear_block import KW, MU

from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.wear import wear_per_cycle


def test_archard_volume_equals_friction_energy_over_mu(sol_block):
    """Worn volume per cycle = k_w / mu x friction energy per cycle (Coulomb slip: lambda_T is
    mu lambda_N along the slip increment). Same samples, so only rounding separates them:
    1e-12 relative."""
    sol = sol_block
    dw = wear_per_cycle(sol, wear_coefficient=KW)
    volume = float(sol.area @ dw)
    energy = float(sol.friction_energy().sum())
    assert energy > 0
    assert volume == pytest.approx(KW / MU * energy, rel=1e-12)
    # node by node, and the energy law with k_e = k_w / mu gives Archard's wear
    np.testing.assert_allclose(sol.area * dw, KW / MU * sol.friction_energy(), rtol=1e-12,
                               atol=1e-30)
    de = wear_per_cycle(sol, law_name="energy", energy_coefficient=KW / MU)
    np.testing.assert_allclose(de, dw, rtol=1e-12, atol=1e-30)


def test_uniform_sliding_analytic_rate():
    """Independent sliders (normal force exactly P A): Archard's rate is k_w P x slip path,
    uniform, and the path is the closed form 4 (Q - mu P A)/k_t of the quasi-static Coulomb
    oscillator. With the default penalty eps = k_t, lambda_u = F - k_t U + eps U = F does not
    depend on U: the DLFT is then exact at the samples whatever the harmonics (1e-12). With
    eps = 10 k_t the truncated harmonics smooth the stick corners; measured path errors
    2.8% (3 harmonics), 1.5% (7), 0.36% (15), 0.012% (31): checked to 1e-3 at 31 and
    decreasing."""
    P, A, kt, ratio = 1e6, 1e-4, 1e8, 3.0
    m = sliders(P=P, A=A, kt=kt, ratio=ratio)
    exact_path = 4 * (ratio - 1) * MU * P * A / kt
    errors = []
    for nh, eps in ((3, "auto"), (3, 10 * kt), (7, 10 * kt), (31, 10 * kt)):
        b = FourierBasis.up_to(nh, 16 * nh + 16)
        sol = solve_periodic(m, b, quasi_static=True, options=SolveOptions(tol=1e-12), eps=eps)
        st = sol.stats
        assert st.success
        np.testing.assert_array_equal(sol.pressure_t(), P)  # exact normal force
        rate = wear_per_cycle(sol, wear_coefficient=KW)
        np.testing.assert_allclose(rate, KW * P * sol.slip_t().sum(axis=1), rtol=1e-13)
        assert np.ptp(rate) <= 1e-12 * rate.max()  # uniform
        errors.append(abs(rate[0] / (KW * P * exact_path) - 1))
    assert errors[0] < 1e-12
    assert errors[3] < 1e-3
    assert errors[1] > errors[2] > errors[3]


def test_zero_wear_zones_are_runs_of_unworn_nodes():
    """Hand-made profile (unordered x): the zones are the runs of nodes at most 1 % of the
    deepest, in x order, ends included."""
    from fretwear.wear import zero_wear_zones

    x = np.array([0.5, 0.0, 0.1, 0.2, 0.3, 0.4, 0.6])
    w = np.array([0.0, 0.0, 0.005, 1.0, 0.0, 0.3, 0.02])
    assert zero_wear_zones(x, w) == [[0.0, 0.1], [0.3, 0.3], [0.5, 0.5]]
    assert zero_wear_zones(x, w, fraction=0.03) == [[0.0, 0.1], [0.3, 0.3], [0.5, 0.6]]
