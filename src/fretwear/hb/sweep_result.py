"""The result of a frequency sweep: one :class:`SweepPoint` per frequency computed, gathered in a
:class:`SweepResult` (the nonlinear FRF)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from fretwear.errors import InputError
from fretwear.hb.solution import PeriodicSolution
from fretwear.hb.solvers import SolveStats

_AXES = {"x": 0, "y": 1, "z": 2}


def _axis_index(axis, d: int) -> int:
    """Component index of ``axis`` (``"x"``/``"y"``/``"z"`` or an index) for a point with
    ``d`` components; an InputError names the axes there are."""
    names = "'x', 'y'" + (", 'z'" if d == 3 else "")
    if isinstance(axis, str):
        k = _AXES.get(axis.strip().lower())
    elif isinstance(axis, int | np.integer) and not isinstance(axis, bool):
        k = int(axis)
    else:
        k = None
    if k is None or not 0 <= k < d:
        raise InputError(f"amplitude: axis = {axis!r}: expected {names} or an index 0..{d - 1}")
    return k


@dataclass
class SweepPoint:
    """One frequency of a sweep.

    frequency_hz : the frequency [Hz]; solution : the converged periodic solution, or None
    when the solve did not converge (a failed solve is never kept as a solution); stats :
    solver statistics of the last solve; how : ``"grid"``, ``"substep"``, ``"retry"``,
    ``"arclength"``, ``"jump"``, ``"eps-continuation"``, ``"harmonic-continuation"``,
    ``"fresh-start"`` or ``"time-start"``; attempts : every attempt made at this frequency, in order
    (:class:`~fretwear.hb.solution.Attempt`); flags : reasons for caution
    (``"not converged: ..."``, time-domain findings); on_grid : a requested grid frequency
    (False for the intermediate points the sweep added); time_domain : what the time
    integration found at a point whose balance failed (``""`` when none ran);
    fallback_seconds : wall time [s] spent after the first attempt
    (:mod:`fretwear.hb.fallbacks`); problem : the
    :class:`~fretwear.hb.problem.DLFTProblem` the solution was solved on, kept for Hill's
    method (:func:`fretwear.hb.sweep_stability.sweep_stability`) when its reduced model is
    small (None otherwise, and for a point read from a checkpoint: rebuilt from the solution);
    seconds, cpu_seconds : wall and CPU time [s] the sweep spent on this point since the
    previous point was recorded (:meth:`fretwear.hb.branch.Branch.lap`): the predictor, the
    condensations, every attempt, failed ones included, the polish and the flags; a grid
    point's and the intermediate points' its ladder added sum to the ladder's cost (0 for a
    point read from a checkpoint). The arclength records its points after computing them all:
    the first of them holds the whole continuation's time, the others only their recording.
    """

    frequency_hz: float
    solution: PeriodicSolution | None
    stats: SolveStats
    how: str = "grid"
    flags: list = field(default_factory=list)
    on_grid: bool = False
    time_domain: str = ""
    attempts: list = field(default_factory=list)
    fallback_seconds: float = 0.0
    problem: object = field(default=None, repr=False, compare=False)
    seconds: float = field(default=0.0, compare=False)
    cpu_seconds: float = field(default=0.0, compare=False)

    @property
    def success(self) -> bool:
        """The periodic solve converged (``solution`` is not None)."""
        return self.solution is not None

    @property
    def message(self) -> str:
        """Why the last solve stopped (``stats.message``)."""
        return self.stats.message


@dataclass
class SweepResult:
    """The points of a sweep, in the order computed (increasing frequency).

    ``success`` is True when every point converged; ``message`` counts the converged and
    failed grid frequencies; ``point_success`` is the per-point array; ``resumed_from`` is the
    number of grid frequencies read from a checkpoint (-1: none was read); ``warnings`` are
    reasons for caution that concern the whole sweep (e.g. the static preload solve that gives
    the stick anchors did not converge), one line each. ``condensations`` counts how the
    frequencies of the sweep were condensed (:class:`fretwear.hb.branch.Problems`):
    ``"exact"`` (exact condensations, the polishes' among them), ``"nearby"`` (frequencies
    the continuation added, condensed on a local basis of the latest exact condensations),
    ``"polished"`` and ``"polish_failed"`` (points from a local basis re-solved on their exact
    condensation before they were recorded).
    """

    points: list
    wall_time: float = 0.0
    resumed_from: int = -1
    warnings: list = field(default_factory=list)
    condensations: dict = field(default_factory=dict)

    @property
    def frequency_hz(self) -> np.ndarray:
        return np.array([p.frequency_hz for p in self.points])

    @property
    def point_success(self) -> np.ndarray:
        """(n,) bool: whether each point converged."""
        return np.array([p.success for p in self.points], dtype=bool)

    @property
    def success(self) -> bool:
        """Every point converged."""
        return bool(all(p.success for p in self.points))

    @property
    def message(self) -> str:
        """E.g. ``"187 of 200 points converged; 13 not converged (12 flagged by the time
        integration)"``, over the requested grid frequencies."""
        grid = [p for p in self.points if p.on_grid]
        failed = [p for p in grid if not p.success]
        text = f"{len(grid) - len(failed)} of {len(grid)} points converged"
        if failed:
            timed = sum(1 for p in failed if p.time_domain)
            text += f"; {len(failed)} not converged"
            if timed:
                text += f" ({timed} flagged by the time integration)"
        return text

    def amplitude(self, point: str, axis: int | str = 0,
                  harmonic: int | None = 1) -> np.ndarray:
        """Amplitude of an observed point [m] per sweep point (nan where not converged):
        of one harmonic, or (``harmonic=None``) half the peak-to-peak range over the period.

        point : the name of an observed point; axis : ``"x"``, ``"y"``, ``"z"`` or a component
        index (0, 1, 2) in the model's global frame; harmonic : a kept harmonic order, or
        None."""
        solved = [p.solution for p in self.points if p.solution is not None]
        if not solved:
            return np.full(len(self.points), np.nan)
        first = solved[0]
        if point not in first.observed:
            names = ", ".join(repr(n) for n in first.observed) or "none"
            raise InputError(f"amplitude: no observed point {point!r}; the model observes: "
                             f"{names}")
        k = _axis_index(axis, first.observed[point].shape[0])
        if harmonic is not None and harmonic not in first.basis.harmonics:
            raise InputError(f"amplitude: harmonic = {harmonic!r} is not kept; expected one "
                             f"of {list(first.basis.harmonics)} or None (peak-to-peak)")
        out = np.full(len(self.points), np.nan)
        for i, p in enumerate(self.points):
            s = p.solution
            if s is None:
                continue
            c = s.observed[point][k]
            if harmonic is None:
                u = s.basis.to_time(c)
                out[i] = 0.5 * (u.max() - u.min())
            else:
                j = s.basis.harmonics.index(harmonic)
                out[i] = np.hypot(c[1 + j], c[1 + s.basis.k + j])
        return out

    def summary(self) -> str:
        """``sweep_converged=k/n`` over the grid frequencies, then every flagged point."""
        grid = [p for p in self.points if p.on_grid]
        k = sum(p.success for p in grid)
        lines = [f"sweep_converged={k}/{len(grid)}"]
        for p in self.points:
            if p.flags:
                lines.append(f"  {p.frequency_hz:12.6g} Hz: " + "; ".join(p.flags))
        return "\n".join(lines)

