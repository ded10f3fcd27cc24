"""Fallbacks said as they happen and summed up with their cost at the end.

A periodic solve, a sweep point or a wear step whose first attempt does not converge goes
down the attempt ladder (:mod:`fretwear.hb.attempts`): other solvers, eps and harmonic
continuations, a time integration. Each rung can cost far more than the first attempt (a
time integration: minutes), so each is said when it starts, as a log line of the logger
``"fretwear"`` at level INFO (the command line prints them; from Python,
``logging.basicConfig(level=logging.INFO)`` shows them), and the run's summary gives their
count and the wall time spent after the first attempt (:class:`FallbackCost`), with the
setting that may avoid them (:func:`eps_hint`).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

#: the logger of the lines said as fallbacks happen
log = logging.getLogger("fretwear")
#: the share of the run's time in fallbacks above which the summary names a setting to try
HINT_SHARE = 0.2
#: the rungs of a sweep point that are the sweep's own path along its branch, not fallbacks:
#: the grid step, its halving, the pseudo-arclength continuation past a fold and the jump
#: from a fold the continuation turned back at (the sweep's first attempt from the fold's
#: point, as a stepped-sine test jumps there; said and listed in the summary); a point that
#: needed only these is counted apart, :attr:`FallbackCost.continued`
CONTINUATION = ("grid", "substep", "arclength", "jump")


def said(message: str) -> None:
    """Say ``message`` now (an INFO line of the ``"fretwear"`` logger)."""
    log.info(message)


@dataclass
class FallbackCost:
    """What fallbacks cost a run: ``count`` solves (or steps) that needed more than their
    first attempt, ``time_domain`` of them from a time integration, ``seconds`` of wall time
    after their first attempt, out of the run's ``total`` seconds."""

    count: int = 0
    time_domain: int = 0
    seconds: float = 0.0
    total: float = 0.0
    continued: int = 0
    continued_seconds: float = 0.0
    jumps: list = field(default_factory=list)
    no_periodic: int = 0

    @property
    def share(self) -> float:
        """The fraction of the run's time spent in fallbacks."""
        return self.seconds / self.total if self.total > 0 else 0.0

    def add(self, seconds: float, time_domain: bool = False) -> None:
        """Count one solve that fell back for ``seconds``."""
        self.count += 1
        self.seconds += float(seconds)
        self.time_domain += bool(time_domain)

    def line(self, what: str = "solves", hint: str = "") -> str:
        """One summary line ("" without fallbacks)."""
        if not self.count:
            return ""
        td = f", {self.time_domain} from a time integration" if self.time_domain else ""
        share = f" ({100 * self.share:.0f} % of {self.total:.1f} s)" if self.total > 0 else ""
        tail = f"; {hint}" if hint and self.share >= HINT_SHARE else ""
        if self.no_periodic:  # no setting of the balance finds what the structure lacks
            tail = ("; the structure has no periodic response at "
                    + ("them" if self.no_periodic == self.count
                       else f"{self.no_periodic} of them")
                    + " (a time integration found none)"
                    + (tail if self.no_periodic < self.count else ""))
        return (f"fallbacks: {self.count} {what} needed more than their first attempt{td}: "
                f"{self.seconds:.1f} s{share}{tail}")

    def continuation_line(self, what: str = "frequencies") -> str:
        """One summary line of the time in the sweep's own continuation (:data:`CONTINUATION`:
        halved steps and the arclength past a fold; "" without it), said apart from the
        fallbacks, since following the branch is the sweep's path, which a different default
        would not avoid: the points that needed nothing else (``continued``) and the
        continuation's time at every point (``continued_seconds``)."""
        if not (self.continued or self.continued_seconds > 0):
            return ""
        share = (f" ({100 * self.continued_seconds / self.total:.0f} % of {self.total:.1f} s)"
                 if self.total > 0 else "")
        jumps = f"; jumps at folds: {', '.join(self.jumps)}" if self.jumps else ""
        return (f"continuation (halved steps, arclength past a fold: the sweep's own path, not "
                f"fallbacks): {self.continued_seconds:.1f} s{share}; {self.continued} {what} "
                f"needed nothing else{jumps}")


def of_solutions(points, total: float) -> FallbackCost:
    """The cost of the fallbacks of periodic solutions or sweep points (anything with
    ``fallback_seconds`` and ``attempts``), out of ``total`` seconds. The time of the rungs
    of :data:`CONTINUATION` after the first attempt (each attempt's ``wall_time``; the
    arclength's is its whole continuation) is the sweep's path, counted apart
    (``continued_seconds``); a point that needed only these is counted apart
    (``continued``), any other is a fallback with the rest of its time after the first
    attempt. A point reached by a jump from a fold (``"jump"``) is listed (``jumps``: the
    fold's frequency and the point's)."""
    cost = FallbackCost(total=float(total))
    for p in points:
        attempts = getattr(p, "attempts", [])
        for a in attempts:  # a jump at a fold (fretwear.hb.attempts.jump): where from, to
            if a.method == "jump" and a.success and hasattr(p, "frequency_hz"):
                fold = "a fold" if a.from_hz is None else f"{a.from_hz:.6g} Hz"
                cost.jumps.append(f"{fold} -> {p.frequency_hz:.6g} Hz")
        if len(attempts) > 1 or (attempts and not attempts[0].success):
            seconds = float(getattr(p, "fallback_seconds", 0.0))
            later = attempts[1:]
            path = min(sum(float(a.wall_time) for a in later if a.method in CONTINUATION),
                       seconds)
            cost.continued_seconds += path
            if all(a.method in CONTINUATION for a in later):
                cost.continued += 1
                cost.continued_seconds += seconds - path  # the rungs' overheads
                continue
            cost.add(seconds - path, any(a.method == "time-start" for a in attempts))
    return cost


#: the codes of the history's ``response`` (:data:`fretwear.timedomain.averaged_rate.
#: RESPONSE_KINDS`) of a time integration that found no periodic response: subharmonic,
#: drifting, quasi-periodic, irregular (not "transient": out of periods before it settled).
#: Drifting included as measured: the paper's beam at 79 kHz drifts at every step, and with
#: ``eps = "static"`` its steps came from time integrations all the same (the same worn
#: volume; docs/studies/fallbacks.md)
NOT_PERIODIC = (1, 2, 3, 4)


def of_wear(rescued, wall_time, total: float, response=None) -> FallbackCost:
    """The cost of the fallbacks of a wear run from its history: the steps whose rate did not
    come from a balance warm-started from the previous step (``rescued`` > 0: started from or
    averaged over a time integration) and their ``wall_time`` [s], out of ``total``; with
    the history's ``response`` (the kind of each step's time integration), the steps whose
    integration found no periodic response (:data:`NOT_PERIODIC`) are counted
    (``no_periodic``), and the summary line says so instead of a setting that could not
    avoid them (the paper's beam at 30, 70 and 79 kHz: quasi-periodic or drifting;
    docs/studies/fallbacks.md)."""
    cost = FallbackCost(total=float(total))
    response = [-1] * len(rescued) if response is None else response
    for r, w, k in zip(rescued, wall_time, response, strict=True):
        if int(r) > 0:
            cost.add(float(w), True)
            cost.no_periodic += int(k) in NOT_PERIODIC
    return cost


def eps_hint(eps_given: bool) -> str:
    """The setting that may avoid the fallbacks of a run whose penalty came from the default
    rule (``eps_given`` False): the static contact stiffness, which converged at the first
    attempt where the default rule fell back to time integrations (a 3D lap joint worn to
    1e7 cycles: 6.4 s against 923 s, the same depth within 0.3 %, while single solves with
    three harmonics started from the contact-closed guess; from the first harmonic alone
    both penalties converge at the first attempt there: docs/studies/fallbacks.md)."""
    if eps_given:
        return ""
    return ('eps = "static" (the static contact stiffness as the penalty) may avoid them; '
            'compare the results of both')
