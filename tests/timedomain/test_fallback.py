"""The time-domain fallback the analysis layer passes to the drivers
(fretwear.timedomain.fallback): the time integration's start of a harmonic balance.

Reference: the closed-form steady state of a linear oscillator. Without friction (mu = 0) the
friction oscillator of tests/helpers/models.py is a mass-spring-dashpot under ``F0 cos(w t)``,
held on the obstacle by its normal load: ``x = Re(X e^{i w t})``, ``X = F0 / (k - m w^2 +
i c w)``, and the normal displacement is 0. What FALLBACK.start returns must be that steady
state, laid out as the basis's harmonics.
"""

from __future__ import annotations

import numpy as np
from helpers.models import F0, K_, M_, ZETA, oscillator

from fretwear.hb.fourier import FourierBasis
from fretwear.timedomain import fallback
from fretwear.timedomain.fallback import FALLBACK
from fretwear.timedomain.stability import time_domain_start


def test_the_fallback_is_the_time_integration(monkeypatch):
    """FALLBACK's start is the time integration's; its averaged rate is the adapter that
    hands the wear driver's keywords to time_averaged_rate as an AveragingOptions record
    (checked by recording the call)."""
    assert FALLBACK.start is time_domain_start
    seen = {}
    monkeypatch.setattr(fallback, "time_averaged_rate",
                        lambda *a, **kw: seen.update(args=a, **kw) or "rate")
    out = FALLBACK.averaged_rate("m", 7.0, "b", "c", "w", U0="u", V0="v", settle=3,
                                 average=4, steps_per_period=64)
    assert out == "rate" and seen["args"] == ("m", 7.0, "b", "c", "w")
    assert (seen["U0"], seen["V0"]) == ("u", "v")
    opts = seen["options"]
    assert (opts.settle, opts.average, opts.steps_per_period) == (3, 4, 64)


def test_start_returns_the_steady_state_in_the_layout_of_the_basis():
    """At 5 Hz (a third of the natural frequency) with the basis of harmonics 1 and 3: the
    returned U0 (nc, d, H) holds ``[a0, a1, a3, b1, b3]`` of the contact's local displacement
    with ``a1 = Re X``, ``b1 = -Im X`` and everything else 0, and the anchor is the mean
    tangential position 0. Tolerance 1e-3 of |X|: the integration stops when the response
    repeats to 1e-4 per period (periodicity_tol), and the trapezoidal rule's frequency
    warping ``(w h)^2 / 12`` at 128 steps per period (2e-4) changes |X| by less than 1e-4
    this far below resonance."""
    model = oscillator()
    model.contact.mu = 0.0
    f = 5.0
    w = 2 * np.pi * f
    X = F0 / (K_ - M_ * w**2 + 2j * ZETA * np.sqrt(K_ * M_) * w)
    basis = FourierBasis((1, 3), 32)
    message, U0, anchor = FALLBACK.start(model, f, basis, None, max_periods=500)
    assert message.startswith("time integration: periodic steady state after")
    assert U0.shape == (1, 2, 5) and anchor.shape == (1, 1)
    expected = np.zeros((1, 2, 5))
    expected[0, 1, 1], expected[0, 1, 3] = X.real, -X.imag
    np.testing.assert_allclose(U0, expected, rtol=0, atol=1e-3 * abs(X))
    np.testing.assert_allclose(anchor, U0[:, 1:, 0])
    assert abs(anchor[0, 0]) <= 1e-3 * abs(X)
