"""Settings of the time-domain solvers: one frozen record per family of options, each with its
defaults defined here once, checked at construction (one InputError naming the option).

* :class:`IntegrationOptions` -- the time scheme and its contact solver (``integrate``,
  ``steady_state``, the stability check, the time-domain start).
* :class:`InitialState` -- where an integration starts (displacement, velocity, wear, stick
  anchors): a state, not a setting, but grouped the same way.
* :class:`SteadyStateOptions` -- when a run that integrates until the response repeats stops,
  and what it reports.
* :class:`AveragingOptions` -- the window of a time-averaged wear rate.
* :class:`IncrementalWearOptions` -- the load steps of quasi-static incremental wear.

Case files keep their keys (``steps_per_period``, ``max_periods``, ...); the analyses build
these records from them and take their defaults from here.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from fretwear.errors import InputError
from fretwear.timedomain.checks import count, positive

#: time steps per forcing period (case files take it too)
DEFAULT_STEPS = 256
#: relative tolerance of the status tests of the contact solver
CONTACT_TOL = 1e-10


def _set(record, name: str, value) -> None:
    object.__setattr__(record, name, value)


@dataclass(frozen=True)
class IntegrationOptions:
    """The fixed-step time scheme with exact contact (:mod:`fretwear.timedomain.integrate`).

    Attributes
    ----------
    steps_per_period : fixed steps per period (``h = T / steps_per_period``, >= 4). Guidance:
        >= 20 steps per period of the highest harmonic you want accurate (phase error of the
        trapezoidal rule ``(omega h)^2 / 12``); stick-slip events are first order in ``h``.
    gamma : Newmark gamma (``beta = (gamma + 1/2)^2 / 4``), 0.5 to 1; 0.5 (default) is the
        trapezoidal rule (second order, energy conserving); larger values damp the highest
        frequencies (first order).
    hf_damping : integrate the modes of the reduced model that the step does not resolve
        (``omega_j h > 1``, fewer than 2 pi steps per period) with ``gamma = 1`` (spectral
        radius 1/3 at infinity) instead of ``gamma``: removes their spurious ringing, at the
        cost of numerical dissipation (``energy["numerical"]``) and of whatever physics they
        carry (a friction-induced self-excited oscillation may need them: off by default).
    modal_cutoff : frequency [Hz] below which the fixed-interface modes are kept
        (Craig-Bampton); default ``steps_per_period * f / 8`` (modes the step resolves with
        at least 8 steps per period); ``"all"`` for no reduction. The truncated modes keep
        their static contribution (constraint modes and one static mode per load vector).
    n_modes : keep exactly this many fixed-interface modes instead (overrides the cutoff).
    contact_tol : relative tolerance of the contact solver's status tests.
    """

    steps_per_period: int = DEFAULT_STEPS
    gamma: float = 0.5
    hf_damping: bool = False
    modal_cutoff: float | str | None = None
    n_modes: int | None = None
    contact_tol: float = CONTACT_TOL

    def __post_init__(self):
        _set(self, "steps_per_period", count(self.steps_per_period, "steps_per_period", 4))
        try:
            gamma = float(self.gamma) if not isinstance(self.gamma, str | bool) else np.nan
        except (TypeError, ValueError):
            gamma = np.nan
        if not (0.5 <= gamma <= 1.0):
            raise InputError(f"gamma = {self.gamma!r}; expected 0.5 (trapezoidal, default) to 1")
        _set(self, "gamma", gamma)
        _set(self, "contact_tol", positive(self.contact_tol, "contact_tol"))

    def replace(self, **changes) -> IntegrationOptions:
        """A copy with ``changes`` (checked)."""
        return dataclasses.replace(self, **changes)


@dataclass(frozen=True)
class InitialState:
    """Where an integration starts (checked against the model by the integrator).

    Attributes
    ----------
    U0, V0 : (ndof,) initial displacement [m] and velocity [m/s] at ``t = 0``; default rest.
        ``result.U, result.V`` of a run continue it exactly.
    wear : (nc,) wear depth per contact node [m] (opens the gap).
    anchor : (nc, d-1) tangential positions [m] from which the first step's slip is measured
        (the stick anchors; default: those of ``U0``).
    """

    U0: object = None
    V0: object = None
    wear: object = None
    anchor: object = None


@dataclass(frozen=True)
class SteadyStateOptions:
    """When :func:`fretwear.timedomain.steady.steady_state` stops and what it reports.

    Attributes
    ----------
    max_periods : give up after this many periods (classification then as found).
    tol : relative periodicity tolerance (see
        :func:`fretwear.timedomain.steady.classify_sequence`).
    harmonics : highest harmonic of the last period reported (1 .. harmonics).
    check_every : periods between the first two classifications (the interval then doubles
        up to 512).
    window : the last periods classified (>= 8).
    min_periods : fewest periods before "drifting", "quasi-periodic" or "irregular" is said.
    """

    max_periods: int = 20_000
    tol: float = 1e-6
    harmonics: int = 7
    check_every: int = 16
    window: int = 512
    min_periods: int = 128

    def __post_init__(self):
        _set(self, "max_periods", count(self.max_periods, "max_periods", 1))
        _set(self, "check_every", count(self.check_every, "check_every", 1))
        _set(self, "window", count(self.window, "window", 8))
        _set(self, "tol", positive(self.tol, "tol", high=1.0))
        _set(self, "harmonics", count(self.harmonics, "harmonics", 1))

    def replace(self, **changes) -> SteadyStateOptions:
        """A copy with ``changes`` (checked)."""
        return dataclasses.replace(self, **changes)


@dataclass(frozen=True)
class AveragingOptions:
    """The window of a time-averaged wear rate
    (:func:`fretwear.timedomain.averaged_rate.time_averaged_rate`).

    Attributes
    ----------
    settle : periods integrated before averaging.
    average : periods averaged (at least 2 are).
    steps_per_period : time steps per period; None: ``max(128, 8 x`` the highest harmonic of
        the basis) (:func:`fretwear.timedomain.averaged_rate.default_steps`).
    classify_tol : relative periodicity tolerance of the response classification.
    """

    settle: int = 300
    average: int = 500
    steps_per_period: int | None = None
    classify_tol: float = 1e-4


@dataclass(frozen=True)
class IncrementalWearOptions:
    """The load steps of :func:`fretwear.timedomain.quasistatic.incremental_wear`.

    Attributes
    ----------
    steps_per_cycle : load steps per cycle (>= 2).
    cycle_jump : cycles represented by each computed cycle (explicit Euler on the slow
        scale).
    record_every : record every this many computed cycles (and the last).
    contact_tol : relative tolerance of the contact solver's status tests.
    """

    steps_per_cycle: int = 64
    cycle_jump: int = 1
    record_every: int = 1
    contact_tol: float = CONTACT_TOL

    def __post_init__(self):
        _set(self, "steps_per_cycle", count(self.steps_per_cycle, "steps_per_cycle", 2))
        _set(self, "cycle_jump", count(self.cycle_jump, "cycle_jump", 1))
        _set(self, "record_every", count(self.record_every, "record_every", 1))
        _set(self, "contact_tol", positive(self.contact_tol, "contact_tol"))


#: the defaults of each family, the default arguments of the solvers
INTEGRATION = IntegrationOptions()
STEADY_STATE = SteadyStateOptions()
AVERAGING = AveragingOptions()
INCREMENTAL_WEAR = IncrementalWearOptions()
