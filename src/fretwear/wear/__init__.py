"""Fretting wear on the slow time scale: "DLFT with wear" (paper section 3.3, eq. 29-30).

One job per module:

* :mod:`~fretwear.wear.laws`: the wear laws (Archard, eq. 29; energy) and worn volumes;
* :mod:`~fretwear.wear.kernels`: the numba kernels of the wear rate on the DLFT samples;
* :mod:`~fretwear.wear.options`: :class:`WearOptions`, the one definition of every wear option
  and its default (case files included);
* :mod:`~fretwear.wear.slow_problem`: :class:`SlowProblem`, the coupled problem of a slow step;
* :mod:`~fretwear.wear.schemes`: the slow steps on periodic balances (explicit Euler, eq. 30;
  linearly implicit and backward Euler); :mod:`~fretwear.wear.step_control`: their error
  estimate and jumps; :mod:`~fretwear.wear.time_steps`: the steps from time integrations;
* :mod:`~fretwear.wear.state`: what one slow step produces, its record
  (:class:`StepRecord`) and the state the next step starts from (:class:`SlowStep`), with
  :class:`Rescue`, how the step got its rate;
* :mod:`~fretwear.wear.history`: the recorded history and the result of a run;
* :mod:`~fretwear.wear.checkpoint`: checkpoints (interrupt and resume to the same result);
* :mod:`~fretwear.wear.simulate`: :func:`simulate_wear`, the driver, with its settings records
  :class:`BalanceSetup` and :class:`RunControl`;
* :mod:`~fretwear.wear.worn_frf`: :func:`frf_worn`, the FRF of a worn interface (Fig. 24).
"""

from fretwear.wear.checkpoint import load_checkpoint, read_history, save_checkpoint
from fretwear.wear.history import HISTORY_FIELDS, WearHistory, WearResult
from fretwear.wear.laws import LAWS, wear_coefficients, wear_per_cycle, worn_volume, zero_wear_zones
from fretwear.wear.options import SCHEMES, STOP_REASONS, WearOptions
from fretwear.wear.simulate import BalanceSetup, RunControl, simulate_wear
from fretwear.wear.slow_problem import SlowProblem
from fretwear.wear.state import Rescue, SlowStep, StepRecord
from fretwear.wear.time_steps import without_growth
from fretwear.wear.worn_frf import frf_worn

__all__ = [
    "HISTORY_FIELDS", "LAWS", "SCHEMES", "STOP_REASONS", "BalanceSetup", "Rescue", "RunControl",
    "SlowProblem", "SlowStep", "StepRecord", "WearHistory", "WearOptions", "WearResult",
    "frf_worn", "load_checkpoint", "read_history", "save_checkpoint", "simulate_wear",
    "wear_coefficients", "wear_per_cycle", "without_growth", "worn_volume", "zero_wear_zones",
]
