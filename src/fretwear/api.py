"""The drivers of the public API whose numerical core takes the time-domain fallback as an
argument: here it is on by default, as in case files (one default for both).

:func:`fretwear.hb.sweep.sweep` and :func:`fretwear.wear.simulate.simulate_wear` never import
the time-domain solver (:mod:`fretwear.hb.fallback`); these wrappers pass
:data:`fretwear.timedomain.fallback.FALLBACK` unless ``time_domain=False``. Everything else is
passed through unchanged.
"""

from __future__ import annotations

from fretwear import wear as _wear
from fretwear.hb import periodic as _periodic
from fretwear.hb import sweep as _sweep
from fretwear.hb.options import sweep_options
from fretwear.timedomain.fallback import FALLBACK
from fretwear.wear.worn_frf import WORN_FRF


def _fallback(time_domain: bool):
    if not isinstance(time_domain, bool):
        raise TypeError(f"time_domain = {time_domain!r}: expected True or False")
    return FALLBACK if time_domain else None


def solve_periodic(model, basis, *, time_domain: bool = True,
                   **kwargs) -> _periodic.PeriodicSolution:
    """Periodic response of ``model`` at the excitation ``frequency`` [Hz] (keyword, required
    unless ``quasi_static``) with the DLFT (paper section 3.1-3.2).

    :func:`fretwear.hb.periodic.solve_periodic` (every other keyword: ``frequency``,
    ``quasi_static``, ``options`` (:class:`~fretwear.hb.options.SolveOptions`: ``solver``,
    ``tol``, ``max_iter``, ``strategy``, ``time_domain_periods``, ...), ``gap`` [m], ``eps``,
    ``anchor``, ``U0``, ``condenser``, ...) with the time-domain fallback
    when every attempt of the solve strategy failed (``time_domain=True``, as the case-file
    key ``time_domain`` of a periodic analysis): a periodic steady state of a time integration
    starts one more solve; any other response is reported (``solution.time_domain``).

    Returns
    -------
    :class:`~fretwear.hb.solution.PeriodicSolution`: ``success``, ``message``, ``attempts``,
    the harmonics and time histories of the contact (see its docstring).
    """
    return _periodic.solve_periodic(model, basis, time_domain=_fallback(time_domain), **kwargs)


def sweep(model, basis, f_min: float, f_max: float, n_points: int, *, time_domain: bool = True,
          **kwargs) -> _sweep.SweepResult:
    """Nonlinear FRF: periodic solutions of the DLFT from ``f_min`` to ``f_max`` [Hz] on
    ``n_points`` grid frequencies, each starting from its neighbours (continuation).

    :func:`fretwear.hb.sweep.sweep` (every other keyword: ``options``
    (:class:`~fretwear.hb.options.SweepOptions`: ``solve``, ``spacing``, ``eps`` [N/m or
    "top"/"static"/"auto"], ``continuation``, ``flag``, ``checkpoint``, ``resume``, ...; or a
    :class:`~fretwear.hb.options.SolveOptions`), ``gap`` [m], ``anchor``, ``condenser``) with
    the time-domain fallback at points whose balance fails (``time_domain=True``, as the
    case-file key ``time_domain`` of a sweep; it replaces ``options.time_domain``).

    Returns
    -------
    :class:`~fretwear.hb.sweep.SweepResult`: ``success`` (every point converged),
    ``message`` (how many did), ``points`` (each a :class:`~fretwear.hb.sweep.SweepPoint`
    with ``frequency_hz`` [Hz], ``solution`` or None, ``success``, ``message``, ``flags``),
    ``frequency_hz`` [Hz], ``point_success``, ``amplitude(point, axis)`` [m].
    """
    options = sweep_options(kwargs.pop("options", None))
    return _sweep.sweep(model, basis, f_min, f_max, n_points,
                        options=options.replace(time_domain=_fallback(time_domain)), **kwargs)


def simulate_wear(model, basis, *, time_domain: bool = True, **kwargs) -> _wear.WearResult:
    """Fretting wear on the slow time scale (paper section 3.3, eq. 29-30) at the excitation
    ``frequency`` [Hz] (keyword, default 1 Hz) or ``quasi_static=True``.

    :func:`fretwear.wear.simulate.simulate_wear` (every other keyword: ``frequency``,
    ``quasi_static``, ``options`` (:class:`~fretwear.wear.options.WearOptions`), ``eps``,
    ``W0`` [m], ``checkpoint``, ``resume``, ...) with the time-domain fallback of steps whose
    balance fails (``time_domain=True``; whether it is used is
    ``options.time_domain_rescue``, default true, as in case files).

    Returns
    -------
    :class:`~fretwear.wear.history.WearResult`: ``success`` (False when a solve failed even
    with smaller jumps), ``message`` (why and when it stopped), ``stop_reason``, ``history``
    (one row per slow step: cycles, wear depth [m], pressure [Pa], slip [m], ...),
    ``final_wear`` [m], ``initial`` and ``final`` periodic solutions (None where the rate came
    from a time integration).
    """
    return _wear.simulate_wear(model, basis, time_domain=_fallback(time_domain), **kwargs)


def frf_worn(model, wear, frequencies_hz, basis, *, time_domain: bool = True, **kwargs):
    """Nonlinear FRF with the worn gap ``gap + wear`` (paper Fig. 24), ``wear`` (nc,) [m],
    ``frequencies_hz = (f_min, f_max, n_points)`` [Hz]: :func:`fretwear.wear.worn_frf.frf_worn`
    with the time-domain fallback (``time_domain=True``; it replaces ``options.time_domain``).

    Returns
    -------
    :class:`~fretwear.hb.sweep.SweepResult` (``success``, ``message``, as :func:`sweep`).
    """
    options = sweep_options(kwargs.pop("options", None), WORN_FRF)
    return _wear.frf_worn(model, wear, frequencies_hz, basis,
                          options=options.replace(time_domain=_fallback(time_domain)), **kwargs)
