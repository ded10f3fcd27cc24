"""What a wear simulation records: one row per slow step (:data:`HISTORY_FIELDS`), the
:class:`WearHistory` of a run, the :class:`WearResult` of
:func:`~fretwear.wear.simulate.simulate_wear`, and the builders of a row from a periodic
solution (:func:`solution_row`) or from a time-averaged rate (:func:`time_row`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from fretwear.hb.solution import PeriodicSolution
from fretwear.wear.laws import worn_volume

#: per-step arrays of :class:`WearHistory`: name -> (units, long name)
HISTORY_FIELDS = {
    "cycles": ("1", "physical cycle count N"),
    "jump": ("1", "cycles jumped by the step (0 for the initial state)"),
    "wear_depth": ("m", "wear depth W"),
    "wear_rate": ("m", "wear depth per cycle dW1 (eq. 29)"),
    "pressure_mean": ("Pa", "normal contact pressure, mean over the period"),
    "pressure_max": ("Pa", "normal contact pressure, maximum over the period"),
    "slip_amplitude": ("m", "tangential displacement amplitude (half range over the period)"),
    "slip_path": ("m", "slip path per cycle, sum of |X_T(n) - X_T(n-1)| over slip instants"),
    "state_fraction": ("1", "fraction of the period in separation, stick, slip"),
    "friction_energy": ("J", "energy dissipated by friction per cycle"),
    "worn_volume": ("m^3", "worn volume sum area W"),
    "volume_rate": ("m^3", "worn volume per cycle"),
    "newton_iterations": ("1", "nonlinear solver iterations of the step, retries included"),
    "rejected": ("1", "attempts of the step rejected (error test or failed solve)"),
    "error_estimate": ("1", "local error estimate relative to the maximum wear depth"),
    "wall_time": ("s", "wall time of the step"),
    "U": ("m", "Fourier coefficients of the contact displacements"),
    "lam": ("N", "Fourier coefficients of the contact forces"),
    "anchor": ("m", "stick anchors used by the periodic solve"),
    "rescued": ("1", "0: balanced step warm-started from the previous one; 1: balance started "
                "from a time integration; 2: wear rate averaged over a time integration"),
    "response": ("1", "kind of the step's time-integrated response (index in "
                 "fretwear.timedomain.averaged_rate.RESPONSE_KINDS), -1 when none was integrated"),
    "rate_scatter": ("1", "steps with time-averaged rates: |v1 - v2| / (v1 + v2), v1, v2 the "
                     "worn-volume rates of the two halves of the averaging window (relative "
                     "standard error of the rate); NaN on balanced steps (exact periodic rate)"),
}


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
    def from_rows(cls, rows: list[dict], stop_reason: str = "") -> WearHistory:
        return cls(**{k: np.array([r[k] for r in rows]) for k in HISTORY_FIELDS},
                   stop_reason=stop_reason)

    def rows(self) -> list[dict]:
        return [{k: getattr(self, k)[i] for k in HISTORY_FIELDS} for i in range(self.n_steps)]

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
    whose rate was averaged over a time integration (``rescued = 2``) have no periodic
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


def solution_row(sol: PeriodicSolution, W, g, cycles, jump, iters, rejected, err, wall) -> dict:
    """One history row from a converged periodic solution."""
    p = sol.pressure_t()
    xt = sol.x_t[:, 1:, :]
    half = 0.5 * (xt.max(axis=2) - xt.min(axis=2))
    area = sol.area
    return {
        "cycles": float(cycles), "jump": float(jump), "wear_depth": np.array(W, float),
        "wear_rate": np.array(g, float), "pressure_mean": p.mean(axis=1),
        "pressure_max": p.max(axis=1), "slip_amplitude": np.sqrt((half**2).sum(axis=1)),
        "slip_path": sol.slip_t().sum(axis=1), "state_fraction": sol.state_fractions(),
        "friction_energy": sol.friction_energy(), "worn_volume": worn_volume(W, area),
        "volume_rate": float(np.dot(area, g)), "newton_iterations": int(iters),
        "rejected": int(rejected), "error_estimate": float(err), "wall_time": float(wall),
        "U": sol.U.copy(), "lam": sol.lam.copy(), "anchor": np.array(sol.anchor, float),
        "rescued": 0, "response": -1, "rate_scatter": math.nan,
    }


def time_row(tr, area, W, cycles, jump, iters, rejected, err, wall) -> dict:
    """One history row from a time-averaged rate
    (:class:`~fretwear.timedomain.averaged_rate.TimeAveragedRate`;
    ``rescued = 2``)."""
    return {
        "cycles": float(cycles), "jump": float(jump), "wear_depth": np.array(W, float),
        "wear_rate": tr.g, "pressure_mean": tr.pressure_mean, "pressure_max": tr.pressure_max,
        "slip_amplitude": tr.slip_amplitude, "slip_path": tr.slip_path,
        "state_fraction": tr.state_fraction, "friction_energy": tr.friction_energy,
        "worn_volume": worn_volume(W, area), "volume_rate": float(np.dot(area, tr.g)),
        "newton_iterations": int(iters), "rejected": int(rejected), "error_estimate": float(err),
        "wall_time": float(wall), "U": tr.U, "lam": tr.lam,
        "anchor": np.array(tr.anchor, float), "rescued": 2, "response": tr.kind_code,
        "rate_scatter": float(tr.scatter),
    }
