"""What the time-domain solvers return (one result shape: ``success``, ``message`` and the
details)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


# --------------------------------------------------------------------------------------------
# results
# --------------------------------------------------------------------------------------------
@dataclass
class TransientResult:
    """Output of :func:`integrate`.

    ``success`` is True when the integration completed with every contact solve settled;
    ``message`` says what happened (e.g. ``"integrated 100 periods"``, ``"12 contact solves
    did not settle (first at t = 0.0123 s)"``). Samples are taken at ``t_n = n h``
    (``h = T / steps_per_period``) for every step of the recorded periods (the last
    ``record`` periods), ``t`` counted from the start of the run.

    Attributes
    ----------
    t : (ns,) times [s].
    observed : name -> (ns, d) displacement of each observed point [m].
    velocities : name -> (ns, d) velocity [m/s] (``(U_{n+1} - U_{n-1}) / 2h``).
    u_loc : (ns, nc, d) local contact displacements ``[u_N, u_T...]`` [m].
    lam : (ns, nc, d) contact forces in the local frame [N] (the force at ``t_n``).
    state : (ns, nc) int8: 0 = separation, 1 = stick, 2 = slip (over the step ``t_n -> t_n+1``).
    energy : name -> (ns,) [J]: ``"external"`` work of the loads, ``"friction"`` dissipation,
        ``"normal"`` work of the normal contact forces (impacts, >= 0), ``"damping"``
        dissipation, each cumulative from the first recorded sample; ``"mechanical"`` kinetic +
        elastic energy at ``t_n + h/2``; ``"numerical"`` the algorithmic dissipation (zero to
        round-off for ``gamma = 1/2``). Balance:
        ``mechanical[j] - mechanical[0] = external - friction - normal - damping - numerical``.
    n_periods : forcing periods simulated. steps_per_period : steps per period.
    omega : forcing circular frequency ``2 pi frequency`` [rad/s] (``frequency``: [Hz]).
    wall_time : [s].
    U, V : (ndof,) final displacement [m] and velocity [m/s] (pass them as ``U0, V0`` to
        continue the run exactly).
    poincare : name -> (np, d) observed displacement at the start of each kept period [m].
    period_mean : name -> (np, d) mean over each kept period [m].
    info : reduction and solver statistics.
    success : every contact solve settled; message : what happened.
    """

    t: np.ndarray
    observed: dict
    velocities: dict
    u_loc: np.ndarray
    lam: np.ndarray
    state: np.ndarray
    energy: dict
    n_periods: int
    steps_per_period: int
    omega: float
    wall_time: float
    U: np.ndarray
    V: np.ndarray
    poincare: dict = field(default_factory=dict)
    period_mean: dict = field(default_factory=dict)
    info: dict = field(default_factory=dict)
    success: bool = True
    message: str = ""

    @property
    def frequency(self) -> float:
        """Forcing frequency [Hz]."""
        return self.omega / (2 * np.pi)

    def energy_residual(self) -> float:
        """Largest ``|dE - (W_ext - D_fric - D_normal - D_damp - D_num)|`` over the record [J]."""
        e = self.energy
        if self.t.size == 0:
            return 0.0
        lhs = e["mechanical"] - e["mechanical"][0]
        rhs = e["external"] - e["friction"] - e["normal"] - e["damping"] - e["numerical"]
        return float(np.max(np.abs(lhs - rhs)))


@dataclass
class Classification:
    """Verdict of :func:`classify_sequence` on a sequence of once-per-period samples.

    kind : ``"periodic"`` (repeats every period to ``tol``), ``"subharmonic"`` (repeats every
        ``order`` periods), ``"drifting"`` (the period means move steadily: ratcheting),
        ``"quasi-periodic"`` (bounded, not decaying, not repeating, with a spectral peak at a
        non-zero frequency of the Poincare sequence), ``"irregular"`` (bounded, not decaying,
        no dominant peak), or ``"transient"`` (still converging: undecided).
    periodicity_error : estimated distance to a periodic orbit over ``scale``: the largest
        ``|P_k - P_{k-1}|`` over the last ``n_confirm`` periods divided by ``1 - rho``, rho the
        observed contraction ratio of these differences (capped at 0.99).
    scale : amplitude used to make the errors relative (unit of the samples).
    order : repetition period in forcing periods (1 if periodic, 0 if none).
    drift_rate : largest slope of the period means [unit per period].
    decay : rms deviation of the Poincare samples in the second half of the window over that
        in the first half (< 1: decaying transient; ~1: sustained).
    rotation : dominant frequency of the Poincare sequence [cycles per period], in (0, 0.5];
        the physical frequency is ``(j +- rotation) f`` for an unknown integer ``j`` (aliasing).
    peak_ratio : spectral peak over the median of the spectrum.
    n : number of samples used.
    """

    kind: str
    periodicity_error: float
    scale: float
    order: int = 0
    drift_rate: float = 0.0
    decay: float = float("nan")
    rotation: float = 0.0
    peak_ratio: float = 0.0
    n: int = 0


@dataclass
class SteadyStateResult:
    """Output of :func:`steady_state`.

    Attributes
    ----------
    success : the response was classified (not ``"transient"`` at ``max_periods``) and every
        contact solve settled.
    message : what happened, e.g. ``"periodic after 412 periods"``, ``"still transient after
        20000 periods"``, ``"...; 12 contact solves did not settle"``.
    classification : see :class:`Classification` (``kind``).
    n_periods : periods integrated (including the recorded last one).
    periodic : True for ``"periodic"`` (and ``"subharmonic"``).
    last : :class:`TransientResult` of the last period (every step recorded).
    harmonics : name -> (2 nh + 1, d) real Fourier coefficients of the observed displacement
        over the last period [m], basis ``[a0, a1..a_nh, b1..b_nh]``
        (``x(t) = a0 + sum a_n cos(n w t) + b_n sin(n w t)``, t from the period start).
    contact_harmonics : ``"lam"`` -> (2 nh + 1, nc, d) [N], ``"u_loc"`` -> (2 nh + 1, nc, d) [m].
    diagnostics : the final :class:`Classification`.
    poincare : (np, nmon) once-per-period samples of the monitored quantities (observed DOFs
        then contact local displacements) over the last window [m].
    U, V : final state [m], [m/s]. wall_time : [s]. info : solver statistics.
    """

    success: bool
    message: str
    classification: str
    n_periods: int
    periodic: bool
    last: TransientResult
    harmonics: dict
    contact_harmonics: dict
    diagnostics: Classification
    poincare: np.ndarray
    U: np.ndarray
    V: np.ndarray
    wall_time: float
    info: dict = field(default_factory=dict)


@dataclass
class IncrementalWearResult:
    """Output of :func:`incremental_wear` (one row per recorded computed cycle).

    success : every load step's contact problem settled; message : what happened (e.g.
    ``"100 cycles (100 computed, 6400 load steps)"``, or how many load steps did not settle).

    cycles : (nrec,) number of load cycles done (computed cycles times their jumps).
    wear : (nrec, nc) wear depth [m] at the end of the cycle.
    pressure : (nrec, nc) contact pressure ``lam_N / area`` averaged over the cycle [Pa].
    slip : (nrec, nc) slip distance over the computed cycle [m].
    worn_volume : (nrec,) ``sum wear * area`` [m^3].
    dissipation : (nrec,) friction dissipation over the computed cycle [J].
    computed_cycles, cycle_jump, steps_per_cycle, k_w [1/Pa], wall_time [s].
    U : (ndof,) final displacement [m] (end of the last cycle, phase 0).
    lam : (nc, d) final contact forces [N]. info : solver statistics.
    """

    success: bool
    message: str
    cycles: np.ndarray
    wear: np.ndarray
    pressure: np.ndarray
    slip: np.ndarray
    worn_volume: np.ndarray
    dissipation: np.ndarray
    computed_cycles: int
    cycle_jump: int
    steps_per_cycle: int
    k_w: float
    wall_time: float
    U: np.ndarray
    lam: np.ndarray
    info: dict = field(default_factory=dict)
