"""Stability along a frequency sweep: Hill's method (:mod:`fretwear.hb.stability`) at every
converged point, and the points where the branch changes its character between neighbours.

Along a branch of periodic solutions the Floquet multipliers move continuously; the
solution changes stability where one leaves the unit circle:

* a real multiplier through ``+1``: a turning point (fold) of the response curve, or a branch
  point. There the Jacobian of the balance ``J = T(0)`` (the solve's own, eq. 22-28) is
  singular: its determinant changes sign between the two neighbours (``det J`` is the
  product of the ``T(0)`` eigenvalues, and an exponent through 0 is an eigenvalue of ``T(0)``
  through 0). A sweep in increasing frequency that passes a fold jumps to another branch,
  which the sign change of ``det J`` shows too;
* a real multiplier through ``-1``: a period-doubling point;
* a complex pair through the unit circle: a Neimark-Sacker point (a quasi-periodic
  response is born).

:func:`sweep_stability` computes the multipliers and ``sign det J`` of every converged point
(each point's candidates continued from those of the nearest point already computed,
:func:`nearest`) and :func:`branch_events` lists these changes between neighbouring
converged points (the event lies between the two frequencies; its kind is read from the
multipliers of the unstable neighbour, nearest the unit circle's crossing).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from fretwear.errors import InputError
from fretwear.hb.dynamics import StructureDynamics, structure_dynamics
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.stability import (
    FloquetResult,
    HillOptions,
    HillProblem,
    hill_stability,
    problem_of,
)
from fretwear.hb.sweep_result import SweepResult
from fretwear.model.checks import model_argument
from fretwear.model.core import Model
from fretwear.threads import limited
from fretwear.validate import instance

#: |Im rho| / |rho| below this: the multiplier is real (period doubling / fold, not
#: Neimark-Sacker)
REAL_TOL = 1e-6


@dataclass
class BranchEvent:
    """A change along the branch between two neighbouring converged points.

    kind : ``"fold"`` (``det J`` changes sign: a turning point or a branch point),
    ``"period-doubling"``, ``"Neimark-Sacker"`` or ``"real multiplier through +1"`` (a
    stability change by a real positive multiplier without a sign change of ``det J``: two
    crossed, or a branch point). f_lo, f_hi : the neighbours' frequencies [Hz]; multiplier :
    the critical multiplier of the unstable neighbour (NaN where the stability does not
    change); change : ``"stable -> unstable"``, ``"unstable -> stable"`` (with increasing
    frequency) or ``""`` (the stability does not change: a fold between two unstable
    points, or between two stable ones that another multiplier separates).
    """

    kind: str
    f_lo: float
    f_hi: float
    multiplier: complex
    change: str = ""

    def line(self) -> str:
        m = self.multiplier
        text = [self.change] if self.change else []
        if np.isfinite(abs(m)):
            text.append(f"critical multiplier {m.real:.4g}{m.imag:+.4g}j "
                        f"(|rho| = {abs(m):.4g})")
        more = f" ({', '.join(text)})" if text else ""
        return f"{self.kind} between {self.f_lo:.6g} and {self.f_hi:.6g} Hz{more}"


@dataclass
class SweepStability:
    """Stability of the points of a sweep (:func:`sweep_stability`), in the sweep's order.

    stable : (n,) int8: 1 stable, 0 unstable, -1 not computed (not converged, or Hill's
    method refused the point: ``notes``). max_multiplier : (n,) largest ``|rho|`` [-] (NaN
    where not computed). det_sign : (n,) int8 sign of ``det J`` (0: not computed).
    floquet : (n,) the :class:`~fretwear.hb.stability.FloquetResult` or None. events : the
    :class:`BranchEvent` list. wall_time : (n,) seconds of Hill's method per point. notes :
    reasons a point was not computed, one line each.
    """

    stable: np.ndarray
    max_multiplier: np.ndarray
    det_sign: np.ndarray
    floquet: list
    events: list = field(default_factory=list)
    wall_time: np.ndarray | None = None
    notes: list = field(default_factory=list)


def jacobian_sign(hp: HillProblem) -> int:
    """Sign of ``det J``, ``J = T(0)`` the balance's Jacobian (real at ``s = 0``)."""
    sign, _ = np.linalg.slogdet(hp.jacobian())
    return int(np.sign(sign))


@model_argument
@limited
def sweep_stability(model: Model, result: SweepResult, *, options: HillOptions | None = None,
                    dyn: StructureDynamics | None = None, condenser=None) -> SweepStability:
    """Hill's method at every converged point of ``result`` (a sweep of ``model``) and the
    branch events between them (module docstring), each on the problem its point was solved
    on (:func:`point_problem`). ``dyn``: the model's
    :func:`~fretwear.hb.dynamics.structure_dynamics` if already made; ``condenser``: the
    model's condenser as the sweep had it (for the problems rebuilt from the solutions)."""
    instance(result, SweepResult, "result", "the SweepResult of fretwear.sweep (or frf_worn)")
    n = len(result.points)
    stable = np.full(n, -1, dtype=np.int8)
    rho = np.full(n, np.nan)
    det = np.zeros(n, dtype=np.int8)
    wall = np.zeros(n)
    floquet: list = [None] * n
    notes: list = []
    if dyn is None:
        try:
            dyn = structure_dynamics(model, condenser)
        except InputError as exc:
            notes.append(f"stability not computed: {exc}")
            return SweepStability(stable, rho, det, floquet, [], wall, notes)
    seen = Computed()  # the points computed, for the nearest one's candidates
    for i, p in enumerate(result.points):
        if not p.success:
            continue
        t0 = time.perf_counter()
        try:
            prob = point_problem(model, p, condenser)
            fl = hill_stability(prob, p.solution.U.reshape(prob.m, prob.H), dyn,
                                options=options, previous=nearest(p.solution.U, seen))
            seen.append((np.ravel(p.solution.U), fl))
            det[i] = fl.det_sign
        except InputError as exc:
            notes.append(f"{p.frequency_hz:.6g} Hz: stability not computed: {exc}")
            continue
        finally:
            wall[i] = time.perf_counter() - t0
        floquet[i] = fl
        stable[i] = 1 if fl.stable else 0
        rho[i] = fl.max_multiplier
    out = SweepStability(stable, rho, det, floquet, [], wall, notes)
    out.events = branch_events(result.frequency_hz, out)
    return out


def point_problem(model: Model, point, condenser=None) -> DLFTProblem:
    """The :class:`~fretwear.hb.problem.DLFTProblem` a converged sweep point was solved on:
    the one the sweep kept (:attr:`~fretwear.hb.sweep_result.SweepPoint.problem`, small
    models), otherwise rebuilt from its solution (:func:`~fretwear.hb.stability.problem_of`,
    ``condenser`` the model's). The sweep's own saves the condensation and the problem's
    set-up, 1.1-1.5 ms a point on the benchmark's models (docs/studies/method-costs.md)."""
    prob = getattr(point, "problem", None)
    if isinstance(prob, DLFTProblem) and prob.m * prob.H == np.size(point.solution.U):
        return prob
    return problem_of(model, point.solution, condenser=condenser)


class Computed:
    """The points of a sweep already computed, for :func:`nearest`: ``append((U, result))``
    as a list of pairs takes them; the harmonics of those whose candidates can be continued
    are kept stacked (one array per size, grown by doubling), so that the nearest is one
    array operation instead of a norm a point (owned by the caller: :func:`sweep_stability`
    makes one per sweep)."""

    def __init__(self):
        self._groups: dict = {}  # size -> [array (rows, size), rows used, results]
        self._count = 0

    def __len__(self) -> int:
        return self._count

    def append(self, item) -> None:
        U, fl = item
        self._count += 1
        if fl.track is None:
            return
        U = np.ravel(U)
        group = self._groups.setdefault(U.size, [np.empty((8, U.size), dtype=U.dtype), 0, []])
        X, n, results = group
        if n == X.shape[0]:
            X = group[0] = np.concatenate([X, np.empty_like(X)])
        X[n] = U
        group[1] = n + 1
        results.append(fl)

    def nearest(self, U) -> FloquetResult | None:
        """:func:`nearest` among the points appended."""
        U = np.ravel(U)
        group = self._groups.get(U.size)
        if group is None:
            return None
        X, n, results = group
        gaps = X[:n] - U
        return results[int(np.argmin(np.einsum("ij,ij->i", gaps, gaps)))]


def nearest(U, seen) -> FloquetResult | None:
    """The result, among ``seen`` (``(U, FloquetResult)`` of the points already computed),
    at the solution nearest ``U`` (Euclidean norm of the harmonics) of those whose candidates
    can be continued (:attr:`FloquetResult.track`): the previous point of the sweep's list
    is not always the neighbour on the branch (the arclength through a fold records points
    of two branches in turn; on the benchmark's unilateral two-DOF sweep, 25 of 46 points
    tracked from the nearest against 15 from the previous, the same multipliers)."""
    if isinstance(seen, Computed):
        return seen.nearest(U)
    U = np.ravel(U)
    cands = [(np.ravel(V), fl) for V, fl in seen if fl.track is not None]
    cands = [(V, fl) for V, fl in cands if V.shape == U.shape]
    if not cands:
        return None
    gaps = np.stack([V for V, _ in cands]) - U  # one array operation, not a norm a point
    d = np.einsum("ij,ij->i", gaps, gaps)
    return cands[int(np.argmin(d))][1]  # the first of equal distances, as the loop had it


def _critical(fl: FloquetResult | None) -> complex:
    if fl is None or fl.multipliers.size == 0:
        return complex(np.nan)
    return complex(fl.critical(1)[0])


def branch_events(freqs, st: SweepStability) -> list:
    """The :class:`BranchEvent` list between neighbouring points where both were computed:
    a sign change of ``det J`` (a fold), or a change of stability (classified by the critical
    multiplier of the unstable neighbour)."""
    done = np.flatnonzero(st.stable >= 0)
    events = []
    for a, b in zip(done[:-1], done[1:], strict=True):
        fa, fb = float(freqs[a]), float(freqs[b])
        changed = st.stable[a] != st.stable[b]
        change = ("" if not changed else "stable -> unstable" if st.stable[a] == 1
                  else "unstable -> stable")
        unstable = a if st.stable[a] == 0 else b
        crit = _critical(st.floquet[unstable]) if changed else complex(np.nan)
        if st.det_sign[a] * st.det_sign[b] < 0:
            events.append(BranchEvent("fold", fa, fb, crit, change))
        elif changed:
            real = abs(crit.imag) <= REAL_TOL * max(abs(crit), 1e-300)
            kind = ("Neimark-Sacker" if not real else
                    "period-doubling" if crit.real < 0 else "real multiplier through +1")
            events.append(BranchEvent(kind, fa, fb, crit, change))
    return events
