"""The drivers of the public API whose numerical core takes the time-domain fallback as an
argument: here it is on by default, as in case files (one default for both).

:func:`fretwear.hb.sweep.sweep` and :func:`fretwear.wear.simulate.simulate_wear` never import
the time-domain solver (:mod:`fretwear.hb.fallback`); these wrappers pass
:data:`fretwear.timedomain.fallback.FALLBACK` unless ``time_domain=False``. Everything else is
passed through unchanged.
"""

from __future__ import annotations

from fretwear import wear as _wear
from fretwear.hb import sweep as _sweep
from fretwear.timedomain.fallback import FALLBACK


def _fallback(time_domain: bool):
    if not isinstance(time_domain, bool):
        raise TypeError(f"time_domain = {time_domain!r}: expected True or False")
    return FALLBACK if time_domain else None


def sweep(model, basis, f_min: float, f_max: float, n_points: int, *, time_domain: bool = True,
          **kwargs) -> _sweep.SweepResult:
    """Nonlinear FRF from ``f_min`` to ``f_max`` [Hz]: :func:`fretwear.hb.sweep.sweep` with the
    time-domain fallback at points whose balance fails (``time_domain=True``, as the case-file
    key ``time_domain`` of a sweep)."""
    return _sweep.sweep(model, basis, f_min, f_max, n_points,
                        time_domain=_fallback(time_domain), **kwargs)


def simulate_wear(model, basis, *, time_domain: bool = True, **kwargs) -> _wear.WearResult:
    """Fretting wear on the slow time scale: :func:`fretwear.wear.simulate.simulate_wear` with
    the time-domain fallback of steps whose balance fails (``time_domain=True``; whether it
    is used is ``options.time_domain_rescue``, default true, as in case files)."""
    return _wear.simulate_wear(model, basis, time_domain=_fallback(time_domain), **kwargs)


def frf_worn(model, wear, frequencies_hz, basis, *, time_domain: bool = True, **kwargs):
    """Nonlinear FRF with the worn gap (paper Fig. 24): :func:`fretwear.wear.worn_frf.frf_worn`
    with the time-domain fallback (``time_domain=True``)."""
    return _wear.frf_worn(model, wear, frequencies_hz, basis,
                          time_domain=_fallback(time_domain), **kwargs)
