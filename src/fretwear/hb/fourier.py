"""Real Fourier basis, alternating frequency/time transforms (paper eq. 15-16).

A periodic signal of period ``T = 2 pi / omega`` is written (eq. 15)

    u(tau) = a_0 + sum_{h in H} a_h cos(h tau) + b_h sin(h tau),    tau = omega t,

and stored as the real vector ``[a_0, a_h1, .., a_hk, b_h1, .., b_hk]`` (eq. 16): the static
term, the cosines, then the sines, for the kept harmonics ``H = (h1 < .. < hk)`` (all up to
``Nh``, or any list such as the odd ones). ``N`` time samples ``tau_j = 2 pi j / N`` per
period; transforms use the real FFT. ``N`` must exceed ``2 max(H)`` (no aliasing of the kept
harmonics).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from fretwear.errors import InputError
from fretwear.resources import require_memory


@dataclass(frozen=True)
class FourierBasis:
    """Kept harmonics and time sampling of one period.

    Attributes
    ----------
    harmonics : (k,) int array of kept harmonics (>= 1, strictly increasing).
    n_samples : time samples per period ``N``.
    """

    harmonics: tuple
    n_samples: int

    def __post_init__(self):
        try:
            h = tuple(self.harmonics)
        except TypeError:
            raise InputError(f"harmonics = {self.harmonics!r}: expected a sequence of "
                             "integers >= 1") from None
        try:
            bad = any(isinstance(x, bool) or int(x) != x for x in h)
        except (TypeError, ValueError, OverflowError):
            bad = True
        if bad:
            raise InputError(f"harmonics = {list(h)[:8]}: expected integers >= 1")
        h = tuple(int(x) for x in h)
        object.__setattr__(self, "harmonics", h)
        n = self.n_samples
        if isinstance(n, bool) or not isinstance(n, int | np.integer):
            raise InputError(f"n_samples = {n!r}: expected an integer number of samples")
        object.__setattr__(self, "n_samples", int(n))
        if any(x < 1 for x in h) or any(b <= a for a, b in zip(h, h[1:], strict=False)):
            raise InputError(
                f"harmonics must be strictly increasing integers >= 1, got {list(h)}"
            )
        if not h and self.n_samples != 1:
            raise InputError("harmonics = (): expected at least one harmonic >= 1 (e.g. "
                             "FourierBasis.up_to(7, 128)); the basis of the static part alone "
                             "is FourierBasis.static()")
        hmax = max(h) if h else 0
        if self.n_samples <= 2 * hmax:
            raise InputError(
                f"n_samples = {self.n_samples} is too small for harmonic {hmax}: "
                f"expected more than {2 * hmax} samples per period"
            )
        # the basis matrices (N x (2 k + 1)) and the DLFT's per-node sample arrays
        require_memory(8.0 * self.n_samples * (2 * len(h) + 1) * 4,
                       f"a Fourier basis of {len(h)} harmonics and {self.n_samples} samples")

    @classmethod
    def up_to(cls, nh: int = 7, n_samples: int = 128) -> FourierBasis:
        """All harmonics ``1..nh`` with ``n_samples`` samples per period (default: the
        paper's 7 harmonics and 128 samples, section 4.2)."""
        if isinstance(nh, bool) or not isinstance(nh, int | np.integer) or nh < 1:
            raise InputError(f"nh = {nh!r}: expected a whole number of harmonics >= 1")
        if isinstance(n_samples, int | np.integer) and not isinstance(n_samples, bool) \
                and n_samples <= 2 * nh:
            raise InputError(f"n_samples = {n_samples} is too small for harmonic {nh}: "
                             f"expected more than {2 * nh} samples per period")
        return cls(tuple(range(1, nh + 1)), n_samples)

    @classmethod
    def static(cls) -> FourierBasis:
        """The basis of the static part alone (no harmonic, one sample): static contact
        solves."""
        return cls((), 1)

    @property
    def k(self) -> int:
        return len(self.harmonics)

    @property
    def size(self) -> int:
        """Number of real coefficients ``1 + 2k``."""
        return 1 + 2 * len(self.harmonics)

    @property
    def orders(self) -> np.ndarray:
        """Harmonic orders of the complex blocks: ``[0, h1, .., hk]``."""
        return np.array((0,) + self.harmonics, dtype=np.int64)

    @property
    def tau(self) -> np.ndarray:
        """Sample angles ``tau_j = 2 pi j / N`` [rad]."""
        return 2.0 * np.pi * np.arange(self.n_samples) / self.n_samples

    def rows_in_full(self, hmax: int) -> np.ndarray:
        """Rows of a full real spectrum ``[a0, a1..a_hmax, b1..b_hmax]`` (the layout of
        :func:`fretwear.timedomain.integrate.fourier_coefficients`) that hold this basis's
        coefficients
        ``[0, c_h.., s_h..]``."""
        h = list(self.harmonics)
        if h and max(h) > hmax:
            raise InputError(f"harmonic {max(h)} is not in a spectrum up to {hmax}")
        return np.array([0] + h + [hmax + k for k in h], dtype=np.int64)

    def labels(self) -> list[str]:
        return ["0"] + [f"c{h}" for h in self.harmonics] + [f"s{h}" for h in self.harmonics]

    # --- transforms ---------------------------------------------------------------------
    def to_time(self, coeffs: np.ndarray) -> np.ndarray:
        """Samples ``(..., N)`` from real coefficients ``(..., 1+2k)`` (inverse DFT)."""
        coeffs = np.asarray(coeffs, dtype=float)
        k, n = self.k, self.n_samples
        spec = np.zeros(coeffs.shape[:-1] + (n // 2 + 1,), dtype=complex)
        spec[..., 0] = coeffs[..., 0] * n
        idx = np.asarray(self.harmonics, dtype=np.int64)
        spec[..., idx] = 0.5 * n * (coeffs[..., 1 : 1 + k] - 1j * coeffs[..., 1 + k :])
        return np.fft.irfft(spec, n=n, axis=-1)

    def to_freq(self, samples: np.ndarray) -> np.ndarray:
        """Real coefficients ``(..., 1+2k)`` of samples ``(..., N)`` (DFT, projection on the
        kept harmonics; energy in other harmonics is discarded)."""
        samples = np.asarray(samples, dtype=float)
        n = self.n_samples
        spec = np.fft.rfft(samples, axis=-1) / n
        idx = np.asarray(self.harmonics, dtype=np.int64)
        out = np.empty(samples.shape[:-1] + (self.size,))
        out[..., 0] = spec[..., 0].real
        out[..., 1 : 1 + self.k] = 2.0 * spec[..., idx].real
        out[..., 1 + self.k :] = -2.0 * spec[..., idx].imag
        return out

    def inverse_matrix(self) -> np.ndarray:
        """``Q`` (N, 1+2k) with ``samples = Q @ coeffs``."""
        tau = self.tau
        h = np.asarray(self.harmonics, dtype=float)
        return np.hstack([np.ones((self.n_samples, 1)), np.cos(np.outer(tau, h)),
                          np.sin(np.outer(tau, h))])

    def forward_matrix(self) -> np.ndarray:
        """``P`` (1+2k, N) with ``coeffs = P @ samples`` (so that ``P @ Q = I``)."""
        q = self.inverse_matrix()
        p = np.ascontiguousarray(q.T) * (2.0 / self.n_samples)  # C-ordered, as kernels take it
        p[0] *= 0.5
        return p

    def matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """``(P, Q)``: :meth:`forward_matrix` and :meth:`inverse_matrix`, computed once per
        basis and shared (read-only arrays: a sweep builds a problem per frequency)."""
        return _matrices(self)

    def derivative_matrix(self, omega: float) -> np.ndarray:
        """``D`` (1+2k, 1+2k) with ``coeffs(du/dt) = D @ coeffs(u)`` [1/s]."""
        k = self.k
        d = np.zeros((self.size, self.size))
        h = np.asarray(self.harmonics, dtype=float) * omega
        i = np.arange(k)
        d[1 + i, 1 + k + i] = h  # cos coefficient of u' = h w b_h
        d[1 + k + i, 1 + i] = -h  # sin coefficient of u' = -h w a_h
        return d

    # --- complex <-> real ---------------------------------------------------------------
    def from_complex(self, amps: np.ndarray) -> np.ndarray:
        """Real coefficients ``(..., 1+2k)`` from complex amplitudes ``(k+1, ...)`` ordered as
        :attr:`orders`, with ``u = Re sum_n U_n e^{i n tau}`` (so ``a = Re U``, ``b = -Im U``)."""
        amps = np.asarray(amps)
        if amps.ndim == 2:  # (k+1, m) -> (m, 1+2k): the common case, without concatenations
            k = amps.shape[0] - 1
            out = np.empty((amps.shape[1], 1 + 2 * k))
            out[:, 0] = amps[0].real
            out[:, 1 : 1 + k] = amps[1:].real.T
            out[:, 1 + k :] = -amps[1:].imag.T
            return out
        a0 = amps[0].real
        a = amps[1:].real
        b = -amps[1:].imag
        return np.concatenate([a0[None], a, b], axis=0).transpose(
            tuple(range(1, amps.ndim)) + (0,)
        )

    def to_complex(self, coeffs: np.ndarray) -> np.ndarray:
        """Inverse of :meth:`from_complex`: complex amplitudes ``(k+1, ...)``."""
        coeffs = np.asarray(coeffs, dtype=float)
        k = self.k
        c = coeffs.T if coeffs.ndim <= 2 else np.moveaxis(coeffs, -1, 0)
        out = np.empty((k + 1,) + c.shape[1:], dtype=complex)
        out[0] = c[0]
        out[1:] = c[1 : 1 + k] - 1j * c[1 + k :]
        return out


@lru_cache(maxsize=64)
def _matrices(basis: FourierBasis) -> tuple[np.ndarray, np.ndarray]:
    P, Q = basis.forward_matrix(), basis.inverse_matrix()
    for a in (P, Q):
        a.flags.writeable = False
    return P, Q


def amplitude(coeffs: np.ndarray, basis: FourierBasis) -> np.ndarray:
    """Amplitude per kept harmonic ``sqrt(a_h^2 + b_h^2)`` (..., k)."""
    k = basis.k
    return np.hypot(coeffs[..., 1 : 1 + k], coeffs[..., 1 + k :])
