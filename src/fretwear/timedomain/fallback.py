"""The time-domain fallback of the periodic and wear drivers (:class:`TimeDomainFallback`).

The analysis layer and the public API pass :data:`FALLBACK` to :func:`fretwear.hb.sweep.sweep`
and :func:`fretwear.wear.simulate.simulate_wear`; the numerical core never imports this
package itself.
"""

from __future__ import annotations

from fretwear.hb.fallback import TimeDomainFallback
from fretwear.timedomain.averaged_rate import time_averaged_rate
from fretwear.timedomain.stability import time_domain_start

#: the time integration with exact contact (:mod:`fretwear.timedomain.integrate`) as a fallback
FALLBACK = TimeDomainFallback(start=time_domain_start, averaged_rate=time_averaged_rate)
