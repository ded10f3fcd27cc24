"""What the time-domain solvers return (fretwear.timedomain.results): the energy balance of a
transient result and its frequency.

Reference: energies built here so that the balance ``dE = W_ext - D_fric - D_normal - D_damp
- D_num`` holds exactly but at one sample, by a known amount; the residual must be that
amount.
"""

from __future__ import annotations

import numpy as np
import pytest

from fretwear.timedomain.results import TransientResult


def result(n: int, energy: dict) -> TransientResult:
    z = np.zeros((n, 1, 2))
    return TransientResult(t=np.arange(n) * 0.1, observed={}, velocities={}, u_loc=z, lam=z,
                           state=np.zeros((n, 1), np.int8), energy=energy, n_periods=1,
                           steps_per_period=n, omega=2 * np.pi * 50.0, wall_time=0.0,
                           U=np.zeros(2), V=np.zeros(2))


def test_energy_residual_is_the_largest_imbalance():
    """Random cumulative dissipations and work (0 at the first recorded sample, as the
    solvers count them); the mechanical energy set from the balance,
    then one sample off by 0.25 J: the residual is 0.25 J (to rounding of sums of O(10) J,
    1e-12), and 0 for a balanced record and for an empty one. The frequency is omega/2pi."""
    rng = np.random.default_rng(5)
    n = 20
    e = {k: np.cumsum(np.r_[0.0, rng.uniform(0.0, 1.0, n - 1)]) for k in
         ("external", "friction", "normal", "damping", "numerical")}  # from 0 at the start
    e["mechanical"] = 3.0 + e["external"] - e["friction"] - e["normal"] - e["damping"] \
        - e["numerical"]
    r = result(n, e)
    assert r.energy_residual() == pytest.approx(0.0, abs=1e-12)
    e["mechanical"][7] -= 0.25
    assert r.energy_residual() == pytest.approx(0.25, abs=1e-12)
    e["mechanical"][0] += 1.0  # the reference sample: every other sample is now off by 1
    assert r.energy_residual() == pytest.approx(1.25, abs=1e-12)
    empty = result(0, {k: np.zeros(0) for k in e})
    assert empty.energy_residual() == 0.0
    assert r.frequency == pytest.approx(50.0, rel=1e-15)
