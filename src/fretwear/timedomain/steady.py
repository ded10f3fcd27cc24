"""Integrate until the response repeats every period and classify it (periodic, subharmonic,
drifting, quasi-periodic, irregular), with the harmonics of the last period."""

from __future__ import annotations

import time

import numpy as np

from fretwear.errors import InputError
from fretwear.limits import check_range
from fretwear.model.core import Model
from fretwear.timedomain.checks import positive
from fretwear.timedomain.integrate import Integrator
from fretwear.timedomain.options import (
    INTEGRATION,
    STEADY_STATE,
    InitialState,
    IntegrationOptions,
    SteadyStateOptions,
)
from fretwear.timedomain.results import Classification, SteadyStateResult


# --------------------------------------------------------------------------------------------
# small helpers
# --------------------------------------------------------------------------------------------
def fourier_coefficients(samples: np.ndarray, harmonics: int) -> np.ndarray:
    """Real Fourier coefficients of samples over exactly one period (axis 0).

    ``harmonics`` (``nh``) is the highest harmonic kept. Returns ``(2 nh + 1, ...)``:
    ``[a0, a1..a_nh, b1..b_nh]`` with ``a0`` the mean, ``a_n = 2 Re X_n / N``,
    ``b_n = -2 Im X_n / N`` (``X = rfft(samples)``), so that
    ``x(t_k) = a0 + sum a_n cos(2 pi n k / N) + b_n sin(2 pi n k / N)``.
    """
    x = np.asarray(samples, dtype=float)
    N = x.shape[0]
    nh = int(harmonics)
    if nh < 0 or 2 * nh >= N:
        raise InputError(f"harmonics = {harmonics}: need 0 <= harmonics < N/2 = {N / 2:g} "
                         "(samples per period)")
    X = np.fft.rfft(x, axis=0)
    out = np.empty((2 * nh + 1,) + x.shape[1:])
    out[0] = X[0].real / N
    out[1:nh + 1] = 2.0 * X[1:nh + 1].real / N
    out[nh + 1:] = -2.0 * X[1:nh + 1].imag / N
    return out


# --------------------------------------------------------------------------------------------
# steady state and its classification
# --------------------------------------------------------------------------------------------
def classify_sequence(poincare, means=None, *, tol: float = 1e-6, scale: float | None = None,
                      n_confirm: int = 3, min_window: int = 64, max_order: int = 8,
                      decay_limit: float = 0.95, peak_limit: float = 20.0) -> Classification:
    """Classify a sequence of once-per-period samples (Poincare section).

    Parameters
    ----------
    poincare : (K, nmon) samples at the start of each period, oldest first.
    means : (K, nmon) mean over each period (default: ``poincare``), used for the drift.
    tol : relative tolerance of "repeats" (relative to ``scale``).
    scale : amplitude of the response (e.g. the peak-to-peak over one period); default the
        largest absolute sample.
    n_confirm : consecutive periods that must repeat.
    min_window : fewest samples before "drifting", "quasi-periodic" or "irregular" is said.
    max_order : largest subharmonic order tested.
    decay_limit : ``decay`` above which the deviations are taken as sustained.
    peak_limit : spectral peak over median above which a peak is dominant.

    Returns
    -------
    :class:`Classification`. Rules, in order: periodic if the distance to a periodic orbit
    estimated from the last ``n_confirm`` differences ``|P_k - P_{k-1}|`` (see
    ``periodicity_error``) is below ``tol * scale``; subharmonic of order p if the same holds
    for ``|P_k - P_{k-p}|``; with at least ``min_window`` samples, drifting if the period
    means follow a straight line (residual < 10 % of the change) whose change over the
    window exceeds ``10 tol scale`` and whose increments do not decay (second half / first
    half > 0.8);
    quasi-periodic if the detrended deviations are sustained (``decay > decay_limit``), above
    ``tol * scale``, and their spectrum has a dominant peak at a non-zero frequency; irregular
    if sustained without a dominant peak; otherwise transient.
    """
    P = np.asarray(poincare, dtype=float)
    if P.ndim == 1:
        P = P[:, None]
    K = P.shape[0]
    Mn = P if means is None else np.asarray(means, dtype=float).reshape(K, -1)
    if scale is None or not scale > 0:
        scale = float(np.abs(P).max(initial=0.0)) or 1.0
    thr = tol * scale

    def rep_err(p):
        """Distance to a p-periodic orbit: the last differences ``|P_k - P_{k-p}|`` divided by
        ``1 - rho`` (rho, the observed contraction of the differences, capped at 0.99), so that
        a slow geometric convergence is not taken for convergence."""
        if K < p + n_confirm + p:
            return np.inf
        d = np.abs(P[p:] - P[:-p]).max(axis=1)[-(n_confirm + 1):]
        with np.errstate(divide="ignore", invalid="ignore"):
            ratios = d[1:] / d[:-1]
        rho = float(np.nanmax(ratios)) if np.any(np.isfinite(ratios)) else 0.0
        rho = min(max(rho, 0.0), 0.99)
        return float(d[1:].max() / (1.0 - rho))

    e1 = rep_err(1)
    out = Classification(kind="transient", periodicity_error=e1 / scale, scale=scale, n=K)
    if e1 <= thr:
        out.kind, out.order = "periodic", 1
        return out
    for p in range(2, max_order + 1):
        if rep_err(p) <= thr:
            out.kind, out.order = "subharmonic", p
            return out
    if K < max(min_window, 8):
        return out
    k = np.arange(K, dtype=float)
    kc = k - k.mean()
    # drift of the period means
    slope = (kc @ (Mn - Mn.mean(axis=0))) / (kc @ kc)
    j = int(np.argmax(np.abs(slope)))
    s = float(slope[j])
    out.drift_rate = s
    fit = Mn[:, j].mean() + s * kc
    resid = float(np.sqrt(np.mean((Mn[:, j] - fit) ** 2)))
    inc = np.diff(Mn[:, j])
    h2 = inc.size // 2
    grow = abs(inc[h2:].mean()) / max(abs(inc[:h2].mean()), 1e-300)
    change = abs(s) * (K - 1)
    if change > 10.0 * thr and resid < 0.1 * change and grow > 0.8:
        out.kind = "drifting"
        return out
    # sustained deviations of the Poincare samples (detrended)
    slopes = (kc @ (P - P.mean(axis=0))) / (kc @ kc)
    D = P - P.mean(axis=0) - np.outer(kc, slopes)
    half = K // 2
    a1 = float(np.sqrt(np.mean(D[:half] ** 2)))
    a2 = float(np.sqrt(np.mean(D[half:] ** 2)))
    out.decay = a2 / a1 if a1 > 0 else float("nan")
    if not (a2 > thr and out.decay > decay_limit):
        return out
    win = np.hanning(K)
    spec = (np.abs(np.fft.rfft(D * win[:, None], axis=0)) ** 2).sum(axis=1)
    spec[0] = 0.0
    ib = int(np.argmax(spec))
    med = float(np.median(spec[1:])) if spec.size > 2 else 0.0
    out.peak_ratio = float(spec[ib] / med) if med > 0 else np.inf
    nu = ib / K
    if 0 < ib < spec.size - 1:  # parabolic refinement on the log spectrum
        y0, y1, y2 = np.log(spec[ib - 1:ib + 2] + 1e-300)
        den = y0 - 2 * y1 + y2
        if den < 0:
            nu = (ib + 0.5 * (y0 - y2) / den) / K
    out.rotation = float(min(max(nu, 0.0), 0.5))
    out.kind = "quasi-periodic" if out.peak_ratio > peak_limit else "irregular"
    return out


def steady_state(model: Model, frequency: float, *, options: SteadyStateOptions = STEADY_STATE,
                 integration: IntegrationOptions = INTEGRATION,
                 start: InitialState | None = None, progress: bool = False
                 ) -> SteadyStateResult:
    """Integrate until the response is periodic (or classified otherwise).

    The monitored quantities are the observed DOFs and the local contact displacements,
    sampled once per period (Poincare section) and averaged over each period. Every
    ``check_every`` periods (the interval doubles up to 512) the last ``window`` periods are
    classified by :func:`classify_sequence` with ``scale`` = the largest peak-to-peak of the
    monitored quantities over the last period. The run stops when the response is periodic
    (or subharmonic), or when it is drifting / quasi-periodic / irregular at two consecutive
    checks with at least ``min_periods`` samples, or at ``max_periods``. One more period is
    then recorded at every step and its harmonics computed (:func:`fourier_coefficients`).

    Parameters
    ----------
    model, frequency : as :func:`~fretwear.timedomain.integrate.integrate` (``frequency``
        [Hz]).
    options : :class:`~fretwear.timedomain.options.SteadyStateOptions`: the period budget
        ``max_periods``, the periodicity tolerance ``tol`` (see :func:`classify_sequence`),
        the highest harmonic reported ``harmonics``, ``check_every``, ``window``,
        ``min_periods``.
    integration, start : the time scheme and the initial state, as
        :func:`~fretwear.timedomain.integrate.integrate` takes them.
    progress : print the classification at every check.

    Returns
    -------
    :class:`SteadyStateResult`: ``success`` when the response was classified with every
    contact solve settled; ``classification`` and ``message`` say what it is.
    """
    omega = 2 * np.pi * check_range(positive(frequency, "frequency"), "frequency", "frequency")
    return steady_state_at_omega(model, omega, options=options, integration=integration,
                                 start=start, progress=progress)


def steady_state_at_omega(model: Model, omega: float, *,
                          options: SteadyStateOptions = STEADY_STATE,
                          integration: IntegrationOptions = INTEGRATION,
                          start: InitialState | None = None,
                          progress: bool = False) -> SteadyStateResult:
    """:func:`steady_state` at the circular frequency ``omega`` [rad/s] of a periodic solution
    (no conversion to Hz and back), with its keywords and defaults."""
    if not isinstance(options, SteadyStateOptions):
        raise InputError(f"options = {options!r}; expected a SteadyStateOptions(...)")
    t_start = time.perf_counter()
    integ = Integrator(model, omega, integration, start)
    cls, P, done, history = _run_until_classified(integ, options, progress)
    t0 = time.perf_counter()
    raw = integ.run(1, 1, 1)
    last = integ.result(raw, 1, time.perf_counter() - t0)
    harmonics = options.harmonics
    harm = {name: fourier_coefficients(x, harmonics) for name, x in last.observed.items()}
    charm = {"lam": fourier_coefficients(last.lam, harmonics),
             "u_loc": fourier_coefficients(last.u_loc, harmonics)}
    info = dict(last.info)
    info["history"] = history
    n = done + 1
    classified = cls.kind != "transient"
    message = (f"{cls.kind} after {n} periods" if classified
               else f"still transient after {n} periods")
    if integ.n_fail:
        message += f"; {integ.n_fail} contact solves did not settle"
    return SteadyStateResult(
        success=classified and not integ.n_fail, message=message,
        classification=cls.kind, n_periods=n,
        periodic=cls.kind in ("periodic", "subharmonic"), last=last, harmonics=harm,
        contact_harmonics=charm, diagnostics=cls, poincare=P, U=last.U, V=last.V,
        wall_time=time.perf_counter() - t_start, info=info)


def _run_until_classified(integ: Integrator, options: SteadyStateOptions, progress: bool):
    """Run ``integ`` in chunks of periods (``check_every``, doubling up to 512), classifying
    the last ``window`` once-per-period samples after each, until the response is classified
    (see :func:`steady_state`) or ``max_periods``. Returns ``(classification, poincare,
    periods, history)``."""
    window = options.window
    P = np.zeros((0, integ.red.obs.shape[0] + integ.m))
    Mn = P.copy()
    chunk = options.check_every
    prev = None
    cls = Classification(kind="transient", periodicity_error=np.inf, scale=1.0)
    history = []
    done = 0
    while done < options.max_periods:
        k = min(chunk, options.max_periods - done)
        raw = integ.run(k, 0, k, progress=False)
        done += k
        P = np.vstack([P, raw["mon_start"]])[-window:]
        Mn = np.vstack([Mn, raw["mon_mean"]])[-window:]
        scale = float(raw["mon_ptp"][-1].max())
        cls = classify_sequence(P, Mn, tol=options.tol, scale=scale,
                                min_window=options.min_periods)
        history.append((done, cls.kind, cls.periodicity_error))
        if progress:
            print(f"[steady_state] {done} periods: {cls.kind}, periodicity error "
                  f"{cls.periodicity_error:.3g}")
        if cls.kind in ("periodic", "subharmonic"):
            break
        if cls.kind in ("drifting", "quasi-periodic", "irregular") and cls.kind == prev:
            break
        prev = cls.kind
        chunk = min(2 * chunk, 512)
    return cls, P, done, history
