"""What a wear simulation records: the :class:`WearHistory` of a run, one row per slow step
(a :class:`~fretwear.wear.state.StepRecord`, columns :data:`HISTORY_FIELDS`), and the
:class:`WearResult` of :func:`~fretwear.wear.simulate.simulate_wear`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from fretwear.hb.solution import PeriodicSolution
from fretwear.wear.state import RECORD_COLUMNS, Rescue, StepRecord

#: per-step arrays of :class:`WearHistory`: name -> (units, long name), the columns of
#: :class:`~fretwear.wear.state.StepRecord`
HISTORY_FIELDS = RECORD_COLUMNS


#: history fields added within the current checkpoint format: NaN (not measured) when absent
LATE_HISTORY_FIELDS = ("rate_scatter",)


@dataclass
class WearHistory:
    """The wear history, one row per slow step (step 0 is the unworn start).

    Arrays (s = steps, nc = contact nodes, d = components, H = Fourier coefficients): see
    :data:`HISTORY_FIELDS` for units; ``wear_depth``, ``wear_rate``, ``pressure_*``,
    ``slip_*``, ``friction_energy`` are (s, nc); ``state_fraction`` (s, nc, 3);
    ``U``, ``lam`` (s, nc, d, H); ``anchor`` (s, nc, d-1); the others (s,).
    ``stop_reason`` says why the run ended (one of
    :data:`~fretwear.wear.options.STOP_REASONS`, or "" while running).
    """

    cycles: np.ndarray
    jump: np.ndarray
    wear_depth: np.ndarray
    wear_rate: np.ndarray
    pressure_mean: np.ndarray
    pressure_max: np.ndarray
    slip_amplitude: np.ndarray
    slip_path: np.ndarray
    state_fraction: np.ndarray
    friction_energy: np.ndarray
    worn_volume: np.ndarray
    volume_rate: np.ndarray
    newton_iterations: np.ndarray
    rejected: np.ndarray
    error_estimate: np.ndarray
    wall_time: np.ndarray
    U: np.ndarray
    lam: np.ndarray
    anchor: np.ndarray
    rescued: np.ndarray
    response: np.ndarray
    rate_scatter: np.ndarray
    stop_reason: str = ""

    @classmethod
    def from_records(cls, records: list[StepRecord], stop_reason: str = "") -> WearHistory:
        """The history of the steps ``records`` (one array per column, step first)."""
        return cls(**{k: np.array([getattr(r, k) for r in records]) for k in HISTORY_FIELDS},
                   stop_reason=stop_reason)

    def records(self) -> list[StepRecord]:
        """The steps of the history, one :class:`~fretwear.wear.state.StepRecord` each."""
        return [StepRecord(**{k: getattr(self, k)[i] for k in HISTORY_FIELDS}
                           | {"rescued": Rescue(int(self.rescued[i]))})
                for i in range(self.n_steps)]

    @property
    def n_steps(self) -> int:
        return int(self.cycles.shape[0])


@dataclass
class WearResult:
    """Outcome of :func:`~fretwear.wear.simulate.simulate_wear`.

    success : False when the run stopped on a failed solve (``stop_reason`` ``"solver_failed"``;
    every recorded step converged all the same); message : one line for the user (why it
    stopped, after how many steps and cycles); stop_reason : why it stopped (one of
    :data:`~fretwear.wear.options.STOP_REASONS`); history : :class:`WearHistory`;
    initial, final : periodic solutions at the first and last balanced steps, or None: steps
    whose rate was averaged over a time integration (``rescued`` ``Rescue.TIME_AVERAGED``, 2)
    have no periodic
    solution, so ``initial`` is None when the run started from a time integration (the unworn
    interface had no balance) and both are None when no step was balanced; penalty : the
    DLFT eps [N/m]; wall_time : [s]; stability_jump : explicit Euler's stability limit
    ``2/rho`` estimated from the slow Jacobian at the start [cycles] (nan if not computed);
    warnings : reasons for caution about the whole run, one line each (e.g. the static preload
    solve that gives the stick anchors did not converge).
    """

    history: WearHistory
    initial: PeriodicSolution | None
    final: PeriodicSolution | None
    stop_reason: str
    message: str
    success: bool
    wall_time: float
    stability_jump: float = math.nan
    resumed_from: int = -1
    penalty: float = math.nan
    extra: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)

    @property
    def final_wear(self) -> np.ndarray:
        return self.history.wear_depth[-1]

