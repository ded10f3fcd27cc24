"""Does the structure settle to a DLFT periodic solution? A time-domain check.

A converged harmonic-balance solution is a periodic orbit of the truncated problem; it may be
unstable, one member of a family of periodic states (the mean tangential position is not
unique), or absent from what the structure does in time (a self-excited friction oscillation
at an incommensurate frequency riding on the forced response). The analytic tools for the
stability of non-smooth periodic orbits are not robust enough to trust blindly, so fretwear
checks the way a careful analyst would: it starts the exact time integration of the same model
(:mod:`fretwear.timedomain.integrate`, unilateral contact and Coulomb friction without
regularisation)
from the periodic solution, slightly perturbed, and lets it run until its response is
classified (periodic, drifting, quasi-periodic, irregular). The verdict compares the settled
response with the periodic solution.

See docs/theory.md, "Checking a periodic solution in time".
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from fretwear.hb.fourier import FourierBasis
from fretwear.hb.solution import PeriodicSolution, initial_state
from fretwear.model.checks import model_argument
from fretwear.model.core import Model
from fretwear.timedomain.options import InitialState, IntegrationOptions, SteadyStateOptions
from fretwear.timedomain.steady import steady_state, steady_state_at_omega
from fretwear.validate import instance

VERDICTS = ("stable", "settles elsewhere", "drifting", "quasi-periodic", "irregular",
            "undecided")

#: steps per period of the reduced model's highest mode below which a verdict other than
#: "stable" says that it may come from the step (on the 3D pad of the tests: 1.7 steps
#: gave "settles elsewhere", 3.4 "stable")
RESOLVED_STEPS = 3.0


@dataclass
class StabilityCheck:
    """Verdict of :func:`check_periodic`.

    verdict : one of :data:`VERDICTS`: ``"stable"`` (the time integration settles back to the
        periodic solution), ``"settles elsewhere"`` (to another periodic state, e.g. another
        member of a family in the mean position), ``"drifting"`` (ratchets: the period means
        move steadily), ``"quasi-periodic"`` (a sustained oscillation at another frequency
        rides on the forced response: no periodic steady state), ``"irregular"``, or
        ``"undecided"`` (still converging after ``max_periods``).
    distance : relative distance between the settled response of the observed points over one
        period and the periodic solution (max over points/axes of ``max|u_td - u_hb| / ptp``).
    periods : forcing periods integrated. wall_time : seconds. message : one line for users.
    """

    verdict: str
    distance: float
    periods: int
    wall_time: float
    message: str

    def flags(self) -> list[str]:
        return [] if self.verdict == "stable" else [f"{self.verdict}: {self.message}"]


@model_argument
def check_periodic(model: Model, sol: PeriodicSolution, *, max_periods: int = 3000,
                   steps_per_period: int | None = None, perturbation: float = 1e-3,
                   tolerance: float = 0.2, periodicity_tol: float = 1e-4,
                   seed: int = 0, condenser=None) -> StabilityCheck:
    """Integrate in time from the periodic solution and say whether the structure stays on it.

    Parameters
    ----------
    model, sol : the model and a converged periodic solution of it (dynamic, not quasi-static).
    max_periods : forcing periods allowed for the time integration to settle.
    steps_per_period : time steps per period (default: ``8 x`` the highest kept harmonic, at
        least 128).
    perturbation : relative random perturbation of the initial velocity (a stable orbit
        must attract a perturbed start).
    tolerance : largest relative distance (see :class:`StabilityCheck`) accepted as "the same
        periodic state". The harmonic balance truncates a non-smooth response, so the two
        methods differ by the truncation error even for a stable orbit; 0.2 is well above the
        truncation error measured on the paper's beam with 7 harmonics (docs/verification.md).
    periodicity_tol : relative periodicity tolerance of the time integration's classification.
    seed : of the random perturbation.
    condenser : the condenser that condensed ``sol`` (:func:`fretwear.hb.reduce.exact_condenser`
        or :func:`fretwear.hb.modal.modal_condenser`): the start of the integration is the full
        field it recovers; None: a new exact one.

    Returns
    -------
    :class:`StabilityCheck`: ``verdict`` (``"stable"`` when the structure settles back to the
    solution), ``distance`` [-], ``periods`` integrated, ``wall_time`` [s], ``message`` (one
    line), ``flags()`` for a sweep point. The integration runs at the solution's own circular
    frequency ``sol.omega`` [rad/s] (``sol.frequency`` [Hz]). When the verdict is not
    ``"stable"`` and the step resolves the highest mode of the reduced model (in practice the
    contact nodes' own dynamics, MHz on a fine 3D interface) with fewer than
    :data:`RESOLVED_STEPS` steps, the message says so and gives the ``steps_per_period`` that
    would: stick-slip there depends on the step, and so may the verdict.
    """
    instance(sol, PeriodicSolution, "sol", "the PeriodicSolution of fretwear.solve_periodic")

    t0 = time.perf_counter()
    if sol.quasi_static or sol.omega <= 0:
        return StabilityCheck("stable", 0.0, 0, 0.0, "quasi-static: no dynamics to check")
    U0, V0 = initial_state(model, sol, condenser)
    rng = np.random.default_rng(seed)
    vmax = np.abs(V0).max()
    V0 = V0 + perturbation * vmax * rng.standard_normal(V0.shape)
    nsteps = steps_per_period or max(128, 8 * max(sol.basis.harmonics))
    res = steady_state_at_omega(
        model, sol.omega,
        options=SteadyStateOptions(max_periods=max_periods, tol=periodicity_tol,
                                   harmonics=max(sol.basis.harmonics)),
        integration=IntegrationOptions(steps_per_period=nsteps),
        start=InitialState(U0=U0, V0=V0, wear=sol.gap - np.asarray(model.contact.gap, float)))
    kind = res.classification
    # distance between the settled period and the periodic solution, on the observed points
    dist = 0.0
    tau = 2 * np.pi * np.arange(nsteps) / nsteps

    bt = FourierBasis.up_to(max(sol.basis.harmonics), nsteps)
    for name, c_hb in sol.observed.items():
        c_td = np.asarray(res.harmonics[name]).T  # (d, 2nh+1) [a0, a.., b..]
        u_td = bt.to_time(c_td)
        u_hb = sol.basis.to_time(c_hb)
        if u_hb.shape[-1] != u_td.shape[-1]:
            idx = np.round(tau / (2 * np.pi) * u_hb.shape[-1]).astype(int) % u_hb.shape[-1]
            u_hb = u_hb[:, idx]
        ptp = np.ptp(u_hb, axis=-1)
        scale = np.maximum(ptp, 1e-12 * np.abs(u_hb).max() + 1e-300)
        dist = max(dist, float(np.max(np.abs(u_td - u_hb).max(axis=-1) / scale)))
    wall = time.perf_counter() - t0
    n = res.n_periods
    if kind == "periodic" and dist <= tolerance:
        return StabilityCheck("stable", dist, n, wall,
                              f"time integration settles back to it in {n} periods "
                              f"(distance {dist:.2g})")
    chk = _verdict(kind, dist, n, wall, tolerance, res)
    per = float(res.info.get("steps_per_highest_period", np.inf))
    if per < RESOLVED_STEPS:
        # the contact nodes' own dynamics are not resolved: stick-slip and the mean position
        # then depend on the step (docs/transient.md, "3D contact"), and so may the verdict
        need = int(np.ceil(nsteps * RESOLVED_STEPS / per))
        chk.message += (f"; the time step resolves the highest mode of the reduced model with "
                        f"{per:.2g} steps per its period only: check again with "
                        f"steps_per_period >= {need}")
    return chk


def _verdict(kind, dist, n, wall, tolerance, res) -> StabilityCheck:
    """The verdict of a response that did not settle back to the periodic solution."""
    if kind in ("periodic", "subharmonic"):
        why = (f"distance {dist:.2g} > {tolerance:g}" if dist > tolerance else
               f"distance {dist:.2g} <= {tolerance:g} but not of the solution's period")
        return StabilityCheck("settles elsewhere", dist, n, wall,
                              f"time integration settles to another {kind} state after {n} "
                              f"periods ({why})")
    if kind == "drifting":
        return StabilityCheck("drifting", dist, n, wall,
                              f"time integration ratchets away (period means drift) over {n} "
                              "periods: the periodic state is not where the structure settles")
    if kind == "quasi-periodic":
        return StabilityCheck("quasi-periodic", dist, n, wall,
                              f"time integration shows a sustained oscillation at another "
                              f"frequency after {n} periods (rotation "
                              f"{res.diagnostics.rotation:.3g} cycles/period): no periodic "
                              "steady state; the periodic solution is at best an unstable orbit")
    if kind == "irregular":
        return StabilityCheck("irregular", dist, n, wall,
                              f"time integration stays irregular over {n} periods")
    return StabilityCheck("undecided", dist, n, wall,
                          f"time integration not settled after {n} periods")


def sweep_check(model: Model, **kwargs):
    """The ``flag`` callable of a sweep (:class:`fretwear.hb.options.SweepOptions`): flags
    from :func:`check_periodic`."""

    def check(sol: PeriodicSolution) -> list[str]:
        return check_periodic(model, sol, **kwargs).flags()

    return check


def time_domain_start(model: Model, frequency: float, basis,
                      start: PeriodicSolution | None = None, *, max_periods: int = 3000,
                      steps_per_period: int | None = None, periodicity_tol: float = 1e-4):
    """Integrate in time at ``frequency`` [Hz] until the response is classified; return what
    the structure does there and, if it settles to a periodic state, a starting point for the
    harmonic balance taken from it.

    This is what a careful analyst does when a periodic solve fails: the time integration (from
    a neighbouring periodic solution when given) either settles to a periodic state, whose
    harmonics and mean tangential positions then start the DLFT solve (the loading history
    selects the member of a family of periodic states), or shows that there is no periodic
    steady state (drifting, quasi-periodic, irregular).

    Returns ``(message, U0 (nc, d, H) or None, anchor (nc, d-1) or None)``.
    """

    U0 = V0 = None
    wear = None
    if start is not None:
        U0, V0 = initial_state(model, start)
        wear = start.gap - np.asarray(model.contact.gap, float)
    hmax = max(basis.harmonics) if basis.harmonics else 1
    nsteps = steps_per_period or max(128, 8 * hmax)
    res = steady_state(model, frequency,
                       options=SteadyStateOptions(max_periods=max_periods, tol=periodicity_tol,
                                                  harmonics=hmax),
                       integration=IntegrationOptions(steps_per_period=nsteps),
                       start=InitialState(U0=U0, V0=V0, wear=wear))
    kind = res.classification
    n = res.n_periods
    if kind == "periodic":
        c = np.asarray(res.contact_harmonics["u_loc"])  # (2 hmax + 1, nc, d): [a0, a.., b..]
        Ut = np.moveaxis(c[basis.rows_in_full(hmax)], 0, -1).copy()  # (nc, d, H)
        anchor = Ut[:, 1:, 0].copy()
        return (f"time integration: periodic steady state after {n} periods", Ut, anchor)
    if kind == "subharmonic":
        return (f"time integration: subharmonic steady state (order "
                f"{res.diagnostics.order}) after {n} periods: no periodic state at the forcing "
                "period", None, None)
    if kind == "drifting":
        return (f"time integration: still drifting (ratcheting) after {n} periods: the "
                "structure has not settled at the mean position this history gives", None, None)
    if kind == "quasi-periodic":
        return (f"time integration: quasi-periodic over {n} periods (self-excited oscillation, "
                f"Poincare rotation {res.diagnostics.rotation:.3g} cycles/period): no periodic "
                "steady state", None, None)
    return f"time integration: {kind} over {n} periods", None, None
