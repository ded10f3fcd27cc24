"""What the harmonic-balance and wear drivers may ask of a time integration.

Where a periodic balance fails (near a frictional resonance, on a worn interface, where the
structure bifurcates), a careful analyst integrates in time: either the structure settles to
a periodic state that restarts the balance, or it shows that there is none, and a wear run
can still take its wear rate from the integration (docs/wear.md). The harmonic balance
(:mod:`fretwear.hb`) and the slow-scale wear (:mod:`fretwear.wear`) never import the
time-domain solver (it is an independent reference that sits beside the chain): they take
these two operations as a :class:`TimeDomainFallback`, which :mod:`fretwear.timedomain.fallback`
provides and the analysis layer (and the public API) passes in.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass


@dataclass(frozen=True)
class TimeDomainFallback:
    """The time-domain operations a periodic or wear driver may fall back on.

    Attributes
    ----------
    start : ``start(model, frequency, basis, solution | None, *, max_periods) ->
        (message, U0 | None, anchor | None)``: integrate at ``frequency`` [Hz] (from a
        neighbouring :class:`~fretwear.hb.solution.PeriodicSolution` when given) until the
        response is classified; if it settles to a periodic state, its contact harmonics
        ``U0`` (nc, d, H) [m] and mean tangential positions ``anchor`` (nc, d-1) [m] start a
        balance; ``message`` says what the structure does.
    averaged_rate : ``averaged_rate(model, frequency, basis, coef, wear, *, U0, V0, settle,
        average, steps_per_period)``: the wear rate averaged over a time integration at wear
        ``wear`` (nc,) [m] from the full-field state ``U0``, ``V0``; returns an object with the
        attributes of :class:`fretwear.timedomain.averaged_rate.TimeAveragedRate`.
    """

    start: Callable
    averaged_rate: Callable
