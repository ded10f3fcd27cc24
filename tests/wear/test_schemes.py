"""Tests of the slow-scale integrators (:mod:`fretwear.wear.schemes`: explicit Euler, eq. 30;
linearly implicit and backward Euler; fixed and adaptive jumps).

References, each independent of the code under test:

* uniform sliding, whose wear grows linearly (a uniform gap does not change a load-controlled
  contact): W(N) = initial rate x N;
* a fine-jump explicit Euler run, for large implicit jumps and the adaptive schemes.

Moved unchanged from tests/wear/test_simulate.py.
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers.models import sliders
from helpers.wear_block import BASIS

from fretwear.hb.fourier import FourierBasis
from fretwear.wear import BalanceSetup, WearOptions, simulate_wear


@pytest.mark.parametrize("scheme", ["implicit", "explicit"])
def test_uniform_sliding_wears_linearly(scheme):
    """Uniform wear opens a uniform gap, which does not change a load-controlled contact (the
    normal spring is 1 N/m: the load it takes after 1e5 cycles is 6e-8 of P A), so W(N) is the
    initial rate x N at every node: checked to 1e-6."""
    m = sliders()
    b = FourierBasis.up_to(3, 32)
    r = simulate_wear(m, b, quasi_static=True,
                      options=WearOptions(scheme=scheme, max_cycles=1e5, initial_jump=1e4,
                                          adaptive=False))
    h = r.history
    assert r.stop_reason == "max_cycles" and h.cycles[-1] == pytest.approx(1e5)
    np.testing.assert_allclose(h.wear_depth[-1], h.wear_rate[0] * 1e5, rtol=1e-6)


@pytest.fixture(scope="module")
def explicit_reference(blk):
    """Explicit Euler with fixed jumps of 2e4 cycles (the stability limit 2/rho is ~9e4 at
    the start) up to N = 2e6: 100 steps."""
    m, red, anc = blk
    r = simulate_wear(m, BASIS, quasi_static=True, balance=BalanceSetup(reduced=red, anchor=anc),
                      options=WearOptions(scheme="explicit", adaptive=False, initial_jump=2e4,
                                          max_cycles=2e6))
    return r


def test_implicit_large_jumps_and_adaptive_match_fine_explicit(blk, explicit_reference):
    """Implicit Euler with jumps of 5e5 cycles (5.5x the explicit stability limit 2/rho) and
    the adaptive backward Euler, linearly implicit and explicit schemes (tolerance 1e-2) reach
    the profile of the fine explicit reference at N = 2e6 (max difference relative to the
    maximum depth). Measured: 3.7% (7 steps: first order with jumps 25x the reference's);
    1.2%, 1.0% and 0.7% for the adaptive schemes (the global error of first-order steps at a
    local tolerance of 1e-2, one-sided because the rates decrease as wear grows). The
    reference itself is 0.2% from jumps of 2e3. Bounds: 8%, 3%, 3%, 3%. Explicit Euler with
    the same 5e5 jumps is unstable: 76% off (checked > 5x the implicit error)."""
    m, red, anc = blk
    ref = explicit_reference.history.wear_depth[-1]
    assert explicit_reference.stability_jump == pytest.approx(9e4, rel=0.5)

    def run(**kw):
        o = WearOptions(max_cycles=2e6, **kw)
        r = simulate_wear(m, BASIS, quasi_static=True,
                          balance=BalanceSetup(reduced=red, anchor=anc), options=o)
        assert r.success and r.history.cycles[-1] == pytest.approx(2e6)
        return np.abs(r.history.wear_depth[-1] - ref).max() / ref.max(), r

    e_big, r_big = run(scheme="implicit", adaptive=False, initial_jump=5e5)
    # jumps of 5e5 except where a growing mode (eigenvalue > 0 of the slow Jacobian) limits
    assert r_big.history.n_steps <= 8 and r_big.history.jump.max() == 5e5
    e_ad, _ = run(scheme="implicit", tolerance=1e-2)
    e_ro, _ = run(scheme="rosenbrock", tolerance=1e-2)
    e_ex, _ = run(scheme="explicit", tolerance=1e-2)
    e_unstable, _ = run(scheme="explicit", adaptive=False, initial_jump=5e5)
    assert e_big < 0.08
    assert e_ad < 0.03
    assert e_ro < 0.03
    assert e_ex < 0.03
    assert e_unstable > 5 * e_big
