"""The time-domain fallback of the periodic and wear drivers (:class:`TimeDomainFallback`).

The analysis layer and the public API pass :data:`FALLBACK` to :func:`fretwear.hb.sweep.sweep`
and :func:`fretwear.wear.simulate.simulate_wear`; the numerical core never imports this
package itself.
"""

from __future__ import annotations

from fretwear.hb.fallback import TimeDomainFallback
from fretwear.timedomain.averaged_rate import time_averaged_rate
from fretwear.timedomain.options import AveragingOptions
from fretwear.timedomain.stability import time_domain_start


def averaged_rate(model, frequency, basis, coef, wear, *, U0, V0, **averaging):
    """:func:`~fretwear.timedomain.averaged_rate.time_averaged_rate` with the call of
    :attr:`TimeDomainFallback.averaged_rate`: the fields of
    :class:`~fretwear.timedomain.options.AveragingOptions` (``settle``, ``average``,
    ``steps_per_period``) as keywords, since the wear driver that calls it cannot import the
    time-domain package and its records."""
    return time_averaged_rate(model, frequency, basis, coef, wear, U0=U0, V0=V0,
                              options=AveragingOptions(**averaging))


#: the time integration with exact contact (:mod:`fretwear.timedomain.integrate`) as a fallback
FALLBACK = TimeDomainFallback(start=time_domain_start, averaged_rate=averaged_rate)
