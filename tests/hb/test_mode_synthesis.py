"""Forced response synthesised from one nonlinear mode (fretwear.hb.mode_synthesis) against
the direct frequency sweep of the same oscillator.

The oscillator: m = k = kt = 1, a Jenkins element (mu N = 0.1) and a cosine load, one harmonic,
the same samples in the sweep and the backbone. The backbone is computed at exactly the
amplitudes the sweep reached (no interpolation between backbone points), so the only
differences are those of the theory and of the sampling:

* without viscous damping, single-mode theory in its hysteretic reading is exact for this
  oscillator (its describing function depends on the amplitude only, not on the frequency):
  the synthesis passes through the sweep's points to the sampling error of the stick-slip
  instants, which differ between the free mode's phase and the forced one's (measured
  5.8e-5 at 256 samples, 8.2e-6 at 1024: O(N^-2));
* with viscous damping c, the EPMC's reading damps ``xi W`` where the joint damps
  ``(xi - c) w + c W``: the modulus of the synthesis equation at a sweep point differs from
  the load by at most ``(xi - c) |w - W| a`` (triangle inequality), a bound it reaches
  (measured at 0.98-0.999 of it: the terms are nearly in phase near resonance).
"""

import numpy as np
import pytest

from fretwear.errors import InputError
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.mode_synthesis import excitation_frequencies, modal_forces, synthesize
from fretwear.hb.nonlinear_modes import nonlinear_mode
from fretwear.hb.options import SweepOptions
from fretwear.hb.sweep import sweep
from fretwear.model.build import Damping
from fretwear.model.core import Load
from fretwear.model.matrices import ContactDofs, from_matrices

SAMPLING = 2e-4  # sampling error at 256 samples, 3x the measured 5.8e-5


def forced_jenkins(force, c):
    return from_matrices([[1.0]], [[1.0]],
                         contact=ContactDofs(normal_dofs=None, tangential_dofs=[0], mu=0.1,
                                             normal_load=1.0, kt=1.0),
                         damping=Damping(C=[[c]] if c else None),
                         loads=[Load(np.array([force]), "cos")], observed={"x": 0})


def sweep_and_backbone(force, c):
    model = forced_jenkins(force, c)
    basis = FourierBasis((1,), 256)
    res = sweep(model, basis, 0.15, 0.2, 11, options=SweepOptions(spacing="linear"))
    assert res.success
    W = 2 * np.pi * res.frequency_hz
    A = res.amplitude("x")
    order = np.argsort(A)
    bb = nonlinear_mode(model, basis, A[order])
    assert bb.success and len(bb.points) == A.size
    assert np.allclose(bb.array("amplitude"), A[order], rtol=1e-12)
    return model, bb, W[order], A[order]


def test_hysteretic_synthesis_is_the_sweep_without_viscous_damping():
    force = 0.1  # bounded resonance: 4 mu N > pi F
    model, bb, W, A = sweep_and_backbone(force, 0.0)
    f = modal_forces(model, bb)
    assert np.allclose(f, force, rtol=1e-12)  # one DOF, unit mass: phi = 1
    w, xi = bb.array("omega"), bb.array("xi")
    resid = np.abs(np.abs(w ** 2 - W ** 2 + 1j * xi * w) * A / force - 1.0)
    assert resid.max() <= SAMPLING
    syn = synthesize(bb, f, damping="hysteretic")
    roots = np.stack([syn.omega_lo, syn.omega_hi])
    assert np.nanmin(np.abs(roots / W - 1.0), axis=0).max() <= SAMPLING
    # the sweep went past the peak, which the synthesis reaches too
    assert 0 <= syn.peak < A.size and np.all(np.isfinite(syn.omega_hi[:syn.peak + 1]))
    assert syn.observed.shape == (A.size, 1)
    assert np.allclose(syn.observed[:, 0], A, rtol=1e-10)


def test_viscous_synthesis_differs_from_the_sweep_by_the_damping_reading():
    force, c = 0.2, 0.02
    model, bb, W, A = sweep_and_backbone(force, c)
    syn = synthesize(bb, modal_forces(model, bb))
    w, xi = bb.array("omega"), bb.array("xi")
    resid = np.abs(np.abs(w ** 2 - W ** 2 + 1j * xi * W) * A / force - 1.0)
    bound = (xi - c) * np.abs(w - W) * A / force
    assert np.all(resid <= bound + SAMPLING)
    assert resid.max() >= 0.5 * bound.max()  # the bound is what the difference is
    roots = np.stack([syn.omega_lo, syn.omega_hi])
    assert np.nanmin(np.abs(roots / W - 1.0), axis=0).max() <= 0.01


def test_excitation_frequencies_closed_form_and_bad_input():
    """The roots solve the modulus equation they come from; none above the peak."""
    w, xi, a, f = 2.0, 0.1, 1.0, 0.5
    for damping, damp in (("viscous", lambda W: xi * W), ("hysteretic", lambda W: xi * w)):
        lo, hi = excitation_frequencies(w, xi, a, f, damping)
        for W in (lo, hi):
            assert abs(abs(w * w - W * W + 1j * damp(W)) * a - f) <= 1e-12
        lo, hi = excitation_frequencies(w, xi, 100.0, f, damping)
        assert np.isnan(lo) and np.isnan(hi)
    with pytest.raises(InputError, match="damping"):
        excitation_frequencies(w, xi, a, f, "coulomb")
