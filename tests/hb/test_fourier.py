"""Tests of the real Fourier basis and the alternating frequency/time transforms.

Every reference value is computed independently of :mod:`fretwear.hb.fourier`: trigonometric
polynomials are evaluated directly with ``numpy.cos``/``numpy.sin``, derivatives by hand, and
integrals over a period by the rectangle rule, which is exact for trigonometric polynomials of
degree < N. Tolerances are a few hundred ulps of the data (FFT rounding grows like log N).
"""

import numpy as np
import pytest

from fretwear.errors import InputError
from fretwear.hb.fourier import FourierBasis, amplitude

RNG = np.random.default_rng(12345)
TOL = 1e-12  # FFT of O(1) data with N <= 256: rounding ~ 1e-15 * log2(N); margin 100x


def trig_poly(tau, a0, a, b, harmonics):
    """Direct evaluation of a0 + sum a_h cos(h tau) + b_h sin(h tau) (the reference)."""
    h = np.asarray(harmonics, dtype=float)
    return a0 + np.cos(np.outer(tau, h)) @ a + np.sin(np.outer(tau, h)) @ b


def random_coeffs(basis, *lead):
    return RNG.standard_normal(lead + (basis.size,))


@pytest.mark.parametrize("harmonics, n", [((1, 2, 3, 4, 5, 6, 7), 64), ((1, 3, 5, 7), 128),
                                          ((2, 5), 11)])
def test_to_time_matches_direct_evaluation(harmonics, n):
    """Inverse transform vs the trigonometric polynomial evaluated term by term."""
    basis = FourierBasis(harmonics, n)
    c = random_coeffs(basis)
    k = basis.k
    ref = trig_poly(basis.tau, c[0], c[1 : 1 + k], c[1 + k :], harmonics)
    np.testing.assert_allclose(basis.to_time(c), ref, rtol=0, atol=TOL)
    np.testing.assert_allclose(basis.inverse_matrix() @ c, ref, rtol=0, atol=TOL)


@pytest.mark.parametrize("harmonics, n", [((1, 2, 3, 4, 5, 6, 7), 64), ((1, 3, 5, 7), 16),
                                          ((3,), 7)])
def test_round_trip_batched(harmonics, n):
    """Frequency -> time -> frequency is the identity on the kept harmonics (batched axes)."""
    basis = FourierBasis(harmonics, n)
    c = random_coeffs(basis, 4, 3)
    np.testing.assert_allclose(basis.to_freq(basis.to_time(c)), c, rtol=0, atol=TOL)
    # the matrix forms are inverse to each other and agree with the FFT forms
    P, Q = basis.forward_matrix(), basis.inverse_matrix()
    np.testing.assert_allclose(P @ Q, np.eye(basis.size), rtol=0, atol=TOL)
    samples = RNG.standard_normal((5, n))
    np.testing.assert_allclose(basis.to_freq(samples), samples @ P.T, rtol=0, atol=TOL)


def test_derivative_operator_against_analytic_derivative():
    """D @ c vs the hand-differentiated polynomial: d/dt [a cos(h w t) + b sin(h w t)] =
    h w (b cos - a sin). omega = 2 pi 37 Hz gives derivatives ~1e3: tolerance scaled."""
    harmonics = (1, 2, 5, 7)
    basis = FourierBasis(harmonics, 32)
    omega = 2 * np.pi * 37.0
    c = random_coeffs(basis)
    k = basis.k
    h = np.asarray(harmonics, dtype=float)
    a, b = c[1 : 1 + k], c[1 + k :]
    deriv_ref = trig_poly(basis.tau, 0.0, h * omega * b, -h * omega * a, harmonics)
    d = basis.derivative_matrix(omega) @ c
    np.testing.assert_allclose(basis.to_time(d), deriv_ref, rtol=0, atol=TOL * omega * h.max())
    # constant term has zero derivative; D is skew-symmetric (energy-neutral)
    assert d[0] == 0.0
    D = basis.derivative_matrix(omega)
    np.testing.assert_array_equal(D, -D.T)


def test_projection_keeps_only_the_kept_harmonics():
    """A signal with all harmonics 0..9 projected on the odd basis (1, 3, 5, 7) keeps exactly
    the odd coefficients and drops the even ones (orthogonality over the N samples)."""
    basis = FourierBasis((1, 3, 5, 7), 64)
    full = tuple(range(1, 10))
    a0 = 0.7
    a = RNG.standard_normal(9)
    b = RNG.standard_normal(9)
    samples = trig_poly(basis.tau, a0, a, b, full)
    c = basis.to_freq(samples)
    odd = np.array([0, 2, 4, 6])  # harmonics 1, 3, 5, 7 in the full list
    np.testing.assert_allclose(c, np.concatenate([[a0], a[odd], b[odd]]), rtol=0, atol=TOL)


def test_aliasing_guard():
    """N must exceed 2 max(H): N = 2 h is the Nyquist sample count where cos and sin of h
    cannot both be represented; the constructor must refuse it with an InputError."""
    with pytest.raises(InputError, match="n_samples"):
        FourierBasis((1, 2, 3), 6)
    with pytest.raises(InputError):
        FourierBasis.up_to(7, 14)
    with pytest.raises(InputError):
        FourierBasis((1, 9), 10)
    FourierBasis((1, 2, 3), 7)  # smallest admissible N
    with pytest.raises(InputError, match="increasing"):
        FourierBasis((3, 1), 16)
    with pytest.raises(InputError):
        FourierBasis((0, 1), 16)


def test_parseval():
    """Mean square over a period: (1/N) sum u_j^2 = a0^2 + 1/2 sum (a_h^2 + b_h^2), exact for
    trigonometric polynomials of degree < N/2 (rectangle rule)."""
    basis = FourierBasis.up_to(7, 64)
    c = random_coeffs(basis)
    u = basis.to_time(c)
    k = basis.k
    energy = c[0] ** 2 + 0.5 * np.sum(c[1:] ** 2)
    assert np.mean(u**2) == pytest.approx(energy, rel=1e-13)
    np.testing.assert_allclose(amplitude(c, basis), np.hypot(c[1 : 1 + k], c[1 + k :]))


def test_complex_convention():
    """from_complex/to_complex follow u(tau) = Re sum_n U_n e^{i n tau} (checked by evaluating
    that sum directly) and are inverse to each other."""
    basis = FourierBasis((1, 2, 4), 16)
    U = RNG.standard_normal((basis.k + 1, 3)) + 1j * RNG.standard_normal((basis.k + 1, 3))
    U[0] = U[0].real
    c = basis.from_complex(U)
    assert c.shape == (3, basis.size)
    n = np.asarray(basis.orders, dtype=float)
    ref = np.real(np.exp(1j * np.outer(basis.tau, n)) @ U).T  # (3, N)
    np.testing.assert_allclose(basis.to_time(c), ref, rtol=0, atol=TOL)
    np.testing.assert_allclose(basis.to_complex(c), U, rtol=0, atol=TOL)
