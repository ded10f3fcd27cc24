"""Tests of the steady-state search of the time-domain solver
(:mod:`fretwear.timedomain.steady`): the classification of once-per-period sequences, the
Fourier coefficients of a sampled period and :func:`steady_state` on oscillators whose nature
is known by construction.

Every test compares with something independent of the code under test (synthetic sequences
with a known answer, a trigonometric signal with known coefficients, an event-driven
integration written with ``scipy.integrate.solve_ivp``) and says why its tolerance is what it
is. Moved unchanged from tests/timedomain/test_integrate.py.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from helpers.models import chain
from helpers.oscillators import event_driven, hz, slider

from fretwear.model.core import ContactInterface, Load, Model, ObservedPoint
from fretwear.timedomain import steady
from fretwear.timedomain.options import InitialState, IntegrationOptions, SteadyStateOptions


# --------------------------------------------------------------------------------------------
# classification
# --------------------------------------------------------------------------------------------
def test_classifier_on_synthetic_sequences():
    """Once-per-period sequences with a known nature (2 monitored signals, scale 1)."""
    k = np.arange(512)[:, None]
    base = np.array([[0.3, -0.2]])
    # geometric convergence, well converged
    conv = base + 1e-3 * 0.5**k
    c = steady.classify_sequence(conv, tol=1e-6, scale=1.0)
    assert c.kind == "periodic"
    # slower geometric convergence (ratio 0.97): after 100 periods the last difference is
    # 1.5e-6 but the distance to the limit is 5e-5: not yet periodic at tol 1e-5
    slow = base + 1e-3 * 0.97**k
    c = steady.classify_sequence(slow[:100], tol=1e-5, scale=1.0)
    assert np.abs(np.diff(slow[:100], axis=0)).max(axis=1)[-1] < 1e-5
    assert c.kind == "transient" and c.periodicity_error > 1e-5
    # repeats every 3 periods
    sub = base + 1e-2 * np.cos(2 * np.pi * k / 3)
    c = steady.classify_sequence(sub, tol=1e-6, scale=1.0)
    assert c.kind == "subharmonic" and c.order == 3
    # steady drift (ratcheting) with an oscillation on top
    rng = np.random.default_rng(0)
    drift = base + 1e-4 * k + 1e-6 * rng.normal(size=(512, 2))
    c = steady.classify_sequence(drift, tol=1e-6, scale=1.0)
    assert c.kind == "drifting" and c.drift_rate == pytest.approx(1e-4, rel=1e-3)
    # incommensurate oscillation: bounded, sustained, a spectral peak at the rotation number
    nu = (np.sqrt(5) - 1) / 4  # 0.309...
    qp = base + 1e-2 * np.cos(2 * np.pi * nu * k + np.array([[0.0, 1.0]]))
    c = steady.classify_sequence(qp, tol=1e-6, scale=1.0)
    assert c.kind == "quasi-periodic"
    assert abs(c.rotation - nu) < 1.0 / 512
    # the same but decaying (a transient still dying out): not quasi-periodic
    c = steady.classify_sequence(base + 1e-2 * 0.995**k * np.cos(2 * np.pi * nu * k), tol=1e-6,
                             scale=1.0)
    assert c.kind == "transient" and c.decay < 0.5
    # too few samples to say anything but periodic
    assert steady.classify_sequence(qp[:20], tol=1e-6, scale=1.0).kind == "transient"


def test_fourier_coefficients_convention():
    """a0 = mean, a_n = 2 Re X_n / N, b_n = -2 Im X_n / N on a known trigonometric signal."""
    N = 64
    t = 2 * np.pi * np.arange(N) / N
    x = 0.5 + 2.0 * np.cos(t) - 3.0 * np.sin(t) + 0.25 * np.sin(3 * t)
    c = steady.fourier_coefficients(x, 3)
    np.testing.assert_allclose(c, [0.5, 2.0, 0.0, 0.0, -3.0, 0.0, 0.25], atol=1e-13)


def test_steady_state_classifies_real_responses():
    """steady_state on three oscillators whose nature is known by construction.

    * stick-slip with stops: stops erase the memory, so the response becomes periodic; its
      first harmonic matches the event-driven reference to the scheme's error (1e-3).
    * ratcheting: a constant tangential pull below mu N and a normal load that drops below
      pull/mu once per period, no spring: the node slides forward a little every period.
    * undamped, stuck: a free vibration at w0 = 1 started by V0 superposes on the forced one
      at w = (sqrt 5 - 1)/2, never decays and never repeats; the Poincare rotation number is
      ``w0 / w mod 1`` folded into [0, 1/2] (w0 slightly warped by the trapezoidal rule,
      ``(w0 h)^2 / 12`` = 2e-4 relative, well inside the spectral resolution 2 / n).
    """
    m = k = F0 = 1.0
    Ff, w = 0.5, 0.5
    ss = steady.steady_state(slider(mu=Ff), hz(w), options=SteadyStateOptions(tol=1e-8),
                             integration=IntegrationOptions(steps_per_period=512))
    assert ss.classification == "periodic" and ss.periodic and ss.success, ss.message
    T = 2 * np.pi / w
    n = ss.n_periods
    ref, _ = event_driven(m=m, k=k, Ff=Ff, F0=F0, w=w, t_end=n * T + 1e-9, t_eval=ss.last.t)
    cref = steady.fourier_coefficients(ref, 7)
    c = ss.harmonics["x"][:, 0]
    assert np.max(np.abs(c - cref)) < 1e-3 * np.abs(cref).max()
    assert ss.contact_harmonics["lam"].shape == (15, 1, 2)

    # ratcheting
    Kd = sp.csr_matrix(np.diag([0.0, 0.0]))
    contact = ContactInterface(dofs=np.array([[0, 1]]), frame=np.eye(2)[None],
                               gap=np.zeros(1), area=np.ones(1), mu=0.5, coords=np.zeros((1, 2)))
    loads = [Load(np.array([1.0, 0.3]), "constant"), Load(np.array([0.6, 0.0]), "cos")]
    rat = Model(K=Kd, M=sp.identity(2, format="csr"), contact=contact, loads=loads,
                observed=[ObservedPoint("x", np.array([1]), np.zeros(1))])
    ss = steady.steady_state(rat, hz(1.0),
                             options=SteadyStateOptions(min_periods=64, check_every=32),
                             integration=IntegrationOptions(steps_per_period=64))
    assert ss.classification == "drifting"
    assert ss.diagnostics.drift_rate > 0

    # quasi-periodic: a mass on a spring k = 1 attached to a stuck contact node, undamped
    wq = (np.sqrt(5) - 1) / 2
    model = chain(n=1, k=1.0, kg=0.0, mu=10.0, N=1.0, F=0.5)
    V0 = np.zeros(model.ndof)
    V0[2] = 0.2
    ss = steady.steady_state(model, hz(wq),
                             options=SteadyStateOptions(min_periods=64, max_periods=600),
                             integration=IntegrationOptions(steps_per_period=64),
                             start=InitialState(V0=V0))
    assert ss.classification == "quasi-periodic"
    assert np.all(ss.last.state == 1)
    nu = np.mod(1.0 / wq, 1.0)
    nu = min(nu, 1 - nu)
    assert abs(ss.diagnostics.rotation - nu) < 2.0 / ss.diagnostics.n
