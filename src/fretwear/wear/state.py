"""What one slow step of a wear run produces: its :class:`StepRecord` (one row of the history)
and the :class:`SlowStep` the next step starts from (also what a checkpoint stores), with
:class:`Rescue`, how the step got its wear rate.

Every field says its units, its meaning and its shape (field metadata, :func:`quantity`) in
the dimensions of the model: ``nc`` contact nodes, ``d`` components, ``H`` Fourier
coefficients, ``m = nc d``; the checkpoint (:mod:`fretwear.wear.checkpoint`) and the history
(:mod:`fretwear.wear.history`) read them from there.

Each has one constructor per origin of the step's rate: a periodic balance
(:meth:`StepRecord.balanced`, :meth:`SlowStep.balanced`; paper eq. 29 on the DLFT solution)
or a rate averaged over a time integration (:meth:`StepRecord.time_averaged`,
:meth:`SlowStep.time_averaged`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from enum import IntEnum

import numpy as np

from fretwear.hb.solution import PeriodicSolution
from fretwear.wear.laws import worn_volume


class Rescue(IntEnum):
    """How a slow step got its wear rate. The integer is what the history's ``rescued`` and
    the results file's ``time_domain_start`` hold (a public format: the values never change).
    """

    #: periodic balance warm-started from the previous step
    BALANCED = 0
    #: periodic balance started from a time integration (its harmonics and stick anchors)
    TIME_START = 1
    #: wear rate averaged over a time integration (no periodic balance)
    TIME_AVERAGED = 2


def quantity(units: str, doc: str, shape: tuple | None = (), *, empty: bool = False,
             **kwargs):
    """A dataclass field with its ``units``, its meaning ``doc`` and its ``shape`` in the
    dimensions of the model (``"nc"``, ``"d"``, ``"d-1"``, ``"m"``, ``"H"`` or a number;
    ``()`` a scalar, ``None`` any shape), kept in the field's metadata; ``empty``: the
    field may also be an empty array (nothing kept)."""
    return field(metadata={"units": units, "doc": doc, "shape": shape, "empty": empty},
                 **kwargs)


def nothing() -> np.ndarray:
    """An empty array: no time integration carried over, no slow Jacobian kept."""
    return np.zeros(0)


def shape_of(f, dims: dict) -> tuple | None:
    """The shape of the field ``f`` (:func:`quantity`) for the dimensions ``dims``
    (e.g. ``{"nc": 11, "d": 2, "d-1": 1, "m": 22, "H": 7}``); None: any shape."""
    shape = f.metadata["shape"]
    return None if shape is None else tuple(dims.get(n, n) for n in shape)


@dataclass
class StepRecord:
    """One row of the wear history: the state reached by a slow step and what it cost
    (:class:`~fretwear.wear.history.WearHistory` stacks them; step 0 is the start)."""

    cycles: float = quantity("1", "physical cycle count N")
    jump: float = quantity("1", "cycles jumped by the step (0 for the initial state)")
    wear_depth: np.ndarray = quantity("m", "wear depth W", ("nc",))
    wear_rate: np.ndarray = quantity("m", "wear depth per cycle dW1 (eq. 29)", ("nc",))
    pressure_mean: np.ndarray = quantity(
        "Pa", "normal contact pressure, mean over the period", ("nc",))
    pressure_max: np.ndarray = quantity(
        "Pa", "normal contact pressure, maximum over the period", ("nc",))
    slip_amplitude: np.ndarray = quantity(
        "m", "tangential displacement amplitude (half range over the period)", ("nc",))
    slip_path: np.ndarray = quantity(
        "m", "slip path per cycle, sum of |X_T(n) - X_T(n-1)| over slip instants", ("nc",))
    state_fraction: np.ndarray = quantity(
        "1", "fraction of the period in separation, stick, slip", ("nc", 3))
    friction_energy: np.ndarray = quantity(
        "J", "energy dissipated by friction per cycle", ("nc",))
    worn_volume: float = quantity("m^3", "worn volume sum area W")
    volume_rate: float = quantity("m^3", "worn volume per cycle")
    newton_iterations: int = quantity(
        "1", "nonlinear solver iterations of the step, retries included")
    rejected: int = quantity("1", "attempts of the step rejected (error test or failed solve)")
    error_estimate: float = quantity(
        "1", "local error estimate relative to the maximum wear depth")
    wall_time: float = quantity("s", "wall time of the step")
    U: np.ndarray = quantity(
        "m", "Fourier coefficients of the contact displacements", ("nc", "d", "H"))
    lam: np.ndarray = quantity("N", "Fourier coefficients of the contact forces",
                               ("nc", "d", "H"))
    anchor: np.ndarray = quantity("m", "stick anchors used by the periodic solve",
                                  ("nc", "d-1"))
    rescued: Rescue = quantity(
        "1", "0: balanced step warm-started from the previous one; 1: balance started "
        "from a time integration; 2: wear rate averaged over a time integration")
    response: int = quantity(
        "1", "kind of the step's time-integrated response (index in "
        "fretwear.timedomain.averaged_rate.RESPONSE_KINDS), -1 when none was integrated")
    rate_scatter: float = quantity(
        "1", "steps with time-averaged rates: |v1 - v2| / (v1 + v2), v1, v2 the "
        "worn-volume rates of the two halves of the averaging window (relative "
        "standard error of the rate); NaN on balanced steps (exact periodic rate)")

    @classmethod
    def balanced(cls, sol: PeriodicSolution, W, g, stats: StepStats, *,
                 rescued: Rescue = Rescue.BALANCED, response: int = -1) -> StepRecord:
        """The record of a step whose rate comes from the converged periodic solution ``sol``
        at the wear depths ``W`` (nc,) [m], ``g`` (nc,) its rate [m/cycle] (eq. 29);
        ``rescued`` :attr:`Rescue.TIME_START` and the ``response`` of the integration when the
        balance was started from a time integration."""
        p = sol.pressure_t()
        xt = sol.x_t[:, 1:, :]
        half = 0.5 * (xt.max(axis=2) - xt.min(axis=2))
        area = sol.area
        return cls(
            **stats.columns(), wear_depth=np.array(W, float), wear_rate=np.array(g, float),
            pressure_mean=p.mean(axis=1), pressure_max=p.max(axis=1),
            slip_amplitude=np.sqrt((half**2).sum(axis=1)), slip_path=sol.slip_t().sum(axis=1),
            state_fraction=sol.state_fractions(), friction_energy=sol.friction_energy(),
            worn_volume=worn_volume(W, area), volume_rate=float(np.dot(area, g)),
            U=sol.U.copy(), lam=sol.lam.copy(), anchor=np.array(sol.anchor, float),
            rescued=rescued, response=int(response), rate_scatter=math.nan)

    @classmethod
    def time_averaged(cls, tr, area, W, stats: StepStats) -> StepRecord:
        """The record of a step whose rate was averaged over a time integration ``tr``
        (:class:`~fretwear.timedomain.averaged_rate.TimeAveragedRate`) at the wear depths
        ``W`` (nc,) [m]; ``area`` (nc,) the contact areas [m^2]."""
        return cls(
            **stats.columns(), wear_depth=np.array(W, float), wear_rate=tr.g,
            pressure_mean=tr.pressure_mean, pressure_max=tr.pressure_max,
            slip_amplitude=tr.slip_amplitude, slip_path=tr.slip_path,
            state_fraction=tr.state_fraction, friction_energy=tr.friction_energy,
            worn_volume=worn_volume(W, area), volume_rate=float(np.dot(area, tr.g)),
            U=tr.U, lam=tr.lam, anchor=np.array(tr.anchor, float),
            rescued=Rescue.TIME_AVERAGED, response=tr.kind_code,
            rate_scatter=float(tr.scatter))

    @property
    def has_balance(self) -> bool:
        """Whether the step's rate comes from a periodic balance (it has a periodic
        solution)."""
        return self.rescued != Rescue.TIME_AVERAGED

    def non_finite(self) -> str:
        """The first column of the record that holds NaN or inf where a value is due ("" if
        none): every physical column, and ``rate_scatter`` on time-averaged steps (NaN on
        balanced steps by definition)."""
        for name in FINITE_COLUMNS:
            if not np.all(np.isfinite(np.asarray(getattr(self, name), dtype=float))):
                return name
        if not self.has_balance and not math.isfinite(self.rate_scatter):
            return "rate_scatter"
        return ""


#: the columns of a step record that are finite whenever the step succeeded
FINITE_COLUMNS = ("cycles", "jump", "wear_depth", "wear_rate", "pressure_mean", "pressure_max",
                  "slip_amplitude", "slip_path", "state_fraction", "friction_energy",
                  "worn_volume", "volume_rate", "U", "lam", "anchor")


#: the columns of the history: name -> (units, long name)
RECORD_COLUMNS = {f.name: (f.metadata["units"], f.metadata["doc"]) for f in fields(StepRecord)}


@dataclass(frozen=True)
class StepStats:
    """Where a step ended and what it cost: the cycle count ``cycles`` reached and the
    ``jump`` taken [cycles], the nonlinear ``iterations`` (retries included), the
    ``rejected`` attempts, the local ``error`` estimate (relative to the maximum wear depth)
    and the ``wall`` time [s]."""

    cycles: float
    jump: float
    iterations: int
    rejected: int
    error: float
    wall: float

    def columns(self) -> dict:
        """The record's columns of these numbers."""
        return {"cycles": float(self.cycles), "jump": float(self.jump),
                "newton_iterations": int(self.iterations), "rejected": int(self.rejected),
                "error_estimate": float(self.error), "wall_time": float(self.wall)}


@dataclass
class SlowStep:
    """The state of a wear run after a slow step: what the next step starts from, and what a
    checkpoint stores (with the history) to resume the run to the same result.

    ``W``, ``U``, ``anchor``, ``g``, ``cycles`` and ``volume_rate`` are those of the step's
    :class:`StepRecord`; ``time_U``, ``time_V`` and ``Js`` are kept while the steps are taken
    from time integrations (:mod:`fretwear.wear.time_steps`), empty otherwise.
    """

    step: int = quantity("1", "index of the step (0: the initial state)")
    cycles: float = quantity("1", "physical cycle count N [cycles]")
    W: np.ndarray = quantity("m", "wear depth per contact node", ("nc",))
    U: np.ndarray = quantity("m", "Fourier coefficients of the contact displacements, DOF "
                             "by DOF (the unknowns of the balance)", ("m", "H"))
    anchor: np.ndarray = quantity("m", "stick anchors of the step's balance", ("nc", "d-1"))
    g: np.ndarray = quantity("m", "wear depth per cycle dW1 at W (eq. 29)", ("nc",))
    jump: float = quantity("1", "jump proposed for the next step [cycles]")
    volume_rate: float = quantity("m^3", "worn volume per cycle at W")
    volume_rate0: float = quantity("m^3", "worn volume per cycle of the initial state (the "
                                   "plateau test)")
    stability_jump: float = quantity("1", "explicit Euler's stability limit 2/rho at the "
                                     "start [cycles]; nan: not computed")
    time_U: np.ndarray = quantity("m", "full-field displacement at the end of the last "
                                  "step's time integration (empty: the step was balanced)",
                                  None, default_factory=nothing)
    time_V: np.ndarray = quantity("m/s", "full-field velocity at the end of that integration",
                                  None, default_factory=nothing)
    retry_balance_at: float = quantity("1", "cycle count before which a failed balance of a "
                                       "time-domain step is not tried again", default=0.0)
    Js: np.ndarray = quantity("1", "slow Jacobian dg/dW [1/cycle] of the last balanced state "
                              "used by time-domain steps (empty: none kept)", ("nc", "nc"),
                              empty=True, default_factory=nothing)
    stop_reason: str = quantity("", "why the run stopped (one of "
                                "fretwear.wear.options.STOP_REASONS; \"\" while running)",
                                default="")

    @classmethod
    def balanced(cls, record: StepRecord, jump: float, before: SlowStep | None = None, *,
                 stability_jump: float = math.nan) -> SlowStep:
        """The state after a step balanced on a periodic solution (``record``), ``jump`` the
        next step's [cycles]: the first state (``before`` None, with explicit Euler's
        ``stability_jump`` [cycles]) or the one after ``before``. Nothing of a time
        integration is kept."""
        first = before is None
        return cls(step=0 if first else before.step + 1, **_common(record), jump=float(jump),
                   volume_rate0=record.volume_rate if first else before.volume_rate0,
                   stability_jump=float(stability_jump) if first else before.stability_jump)

    @classmethod
    def time_averaged(cls, record: StepRecord, jump: float, end, before: SlowStep | None = None,
                      *, Js=None, retry_balance_at: float = 0.0) -> SlowStep:
        """The state after a step whose rate was averaged over a time integration
        (``record``), ``jump`` the next step's [cycles], ``end = (U_end, V_end)`` the state
        at the end of the integration (the next step continues it): the first state
        (``before`` None) or the one after ``before``; ``Js`` the slow Jacobian of the last
        balanced state without its growing modes, ``retry_balance_at`` [cycles]."""
        first = before is None
        return cls(step=0 if first else before.step + 1, **_common(record), jump=float(jump),
                   volume_rate0=record.volume_rate if first else before.volume_rate0,
                   stability_jump=math.nan if first else before.stability_jump,
                   time_U=end[0], time_V=end[1], retry_balance_at=float(retry_balance_at),
                   Js=nothing() if Js is None else Js)

    @property
    def in_time_integration(self) -> bool:
        """Whether the step was taken from a time integration that the next one continues."""
        return bool(np.size(self.time_U))


def _common(record: StepRecord) -> dict:
    """The fields of a :class:`SlowStep` that are those of its step's record."""
    U = np.asarray(record.U, float)
    return {"cycles": float(record.cycles), "W": np.array(record.wear_depth, float),
            "U": U.reshape(-1, U.shape[-1]).copy(), "anchor": np.array(record.anchor, float),
            "g": np.array(record.wear_rate, float), "volume_rate": float(record.volume_rate)}
