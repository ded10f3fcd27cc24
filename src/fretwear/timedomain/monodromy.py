"""Floquet multipliers from the exact time integration: the monodromy matrix of one period.

The time integrator (:mod:`fretwear.timedomain.integrate`) advances the state ``x = (q, dq)``
(reduced coordinates at ``t_n`` and their last increment) with unilateral contact and Coulomb
friction solved exactly at every step. Over one forcing period this is a map ``x -> P(x)``; a
periodic response is a fixed point ``x* = P(x*)`` and its Floquet multipliers are the
eigenvalues of the monodromy matrix ``dP/dx`` there (Floquet's theorem for the discrete map:
the same multipliers as the continuous flow, to the accuracy of the step).

:func:`monodromy` finds the fixed point by Newton's method on ``P(x) - x`` (shooting, the
Jacobian by forward differences) from a start (e.g. the state at ``t = 0`` of a harmonic-balance
solution, :func:`fretwear.hb.solution.initial_state`), so that unstable periodic responses are
found too, and then forms ``dP/dx`` by central differences of ``2 r`` periods. The map is
piecewise smooth (a node's stick/slip/open decision at a step switches where the perturbation
moves it across a threshold); the differences are small enough (``perturbation`` of the state's
scale) not to cross one.

It is the independent check of Hill's method (:mod:`fretwear.hb.stability`), which computes the
same multipliers from the harmonic balance's own linearisation. The state of the integrator has
a position and an increment per reduced coordinate, so a node that sticks has two multipliers
the balance does not have: its velocity is reset to zero by the stick (multiplier 0) and its
position is neutral (multiplier 1, a family of stuck states).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from fretwear.model.core import Model
from fretwear.timedomain.checks import count, positive
from fretwear.timedomain.integrate import Integrator
from fretwear.timedomain.options import InitialState, IntegrationOptions

#: the integration of the shooting: no modal reduction (the multipliers are those of the
#: model), 1024 steps per period, a contact tolerance of 1e-12
SHOOTING = IntegrationOptions(steps_per_period=1024, modal_cutoff="all", contact_tol=1e-12)


@dataclass
class Monodromy:
    """Floquet multipliers of a periodic response of the time integration (:func:`monodromy`).

    multipliers : (2r,) complex eigenvalues of ``matrix``, by decreasing modulus [-].
    matrix : (2r, 2r) ``dP/dx`` in the integrator's coordinates ``x = (q, dq)``.
    state : (2r,) the fixed point ``x*``.
    U0, V0 : (ndof,) full displacement [m] and velocity [m/s] of the fixed point at ``t = 0``.
    residual : ``|P(x*) - x*| / |x*|`` of the fixed point.
    iterations : Newton iterations of the shooting.
    success : the shooting converged (``residual <= tol``); message : why it stopped.
    steps_per_period : time steps per period; wall_time : seconds.
    """

    multipliers: np.ndarray
    matrix: np.ndarray
    state: np.ndarray
    U0: np.ndarray
    V0: np.ndarray
    residual: float
    iterations: int
    success: bool
    message: str
    steps_per_period: int
    wall_time: float

    @property
    def max_multiplier(self) -> float:
        return float(np.max(np.abs(self.multipliers), initial=0.0))

    def critical(self, count: int = 2) -> np.ndarray:
        """The ``count`` multipliers of largest modulus."""
        return self.multipliers[:count]


class PeriodMap:
    """``x -> P(x)``: one forcing period of an :class:`~fretwear.timedomain.integrate.Integrator`
    from the state ``x = (q, dq)``; the contact solver's warm start (statuses, slip
    directions) is the same at every call, so that ``P`` is a function of ``x`` alone."""

    def __init__(self, integ: Integrator):
        self.integ = integ
        self.r = integ.r
        self.status0 = integ.status.copy()
        self.tdir0 = integ.tdir.copy()
        self.calls = 0

    def state(self) -> np.ndarray:
        return np.concatenate([self.integ.q, self.integ.dq])

    def __call__(self, x: np.ndarray) -> np.ndarray:
        integ, r = self.integ, self.r
        Tx = integ.red.Tx
        integ.q[:] = x[:r]
        integ.dq[:] = x[r:]
        integ.xprev[:] = Tx @ integ.q
        integ.xprev2[:] = Tx @ (integ.q - integ.dq)
        integ.status[:] = self.status0
        integ.tdir[:] = self.tdir0
        integ.run(1)
        self.calls += 1
        return self.state()


def _scales(x: np.ndarray, r: int) -> np.ndarray:
    """Perturbation scale per component: the size of the positions for ``q``, of the
    increments for ``dq``."""
    sq = max(float(np.abs(x[:r]).max(initial=0.0)), 1e-300)
    sd = max(float(np.abs(x[r:]).max(initial=0.0)), 1e-3 * sq)
    return np.concatenate([np.full(r, sq), np.full(r, sd)])


def _jacobian(P: PeriodMap, x: np.ndarray, h: np.ndarray, central: bool) -> np.ndarray:
    n = x.size
    J = np.empty((n, n))
    base = None if central else P(x)
    for j in range(n):
        e = np.zeros(n)
        e[j] = h[j]
        if central:
            J[:, j] = (P(x + e) - P(x - e)) / (2.0 * h[j])
        else:
            J[:, j] = (P(x + e) - base) / h[j]
    return J


def monodromy(model: Model, frequency: float, *, start: InitialState,
              integration: IntegrationOptions = SHOOTING, perturbation: float = 1e-6,
              tol: float = 1e-10, max_iter: int = 20) -> Monodromy:
    """Floquet multipliers of the periodic response of ``model`` at ``frequency`` [Hz] by the
    exact time integration (module docstring).

    Parameters
    ----------
    start : :class:`~fretwear.timedomain.options.InitialState`: the start of the shooting,
        ``U0, V0`` (ndof,) displacement [m] and velocity [m/s] at ``t = 0`` (e.g.
        :func:`fretwear.hb.solution.initial_state` of a harmonic-balance solution), and the
        ``anchor`` (nc, d-1) tangential positions [m] the first step's slip is measured from
        (default: those of ``U0``).
    integration : :class:`~fretwear.timedomain.options.IntegrationOptions` of the period map
        (default :data:`SHOOTING`: 1024 steps per forcing period (>= 8), ``modal_cutoff =
        "all"``: no reduction, every DOF of the model, so the multipliers are those of that
        model; contact tolerance 1e-12).
    perturbation : relative size of the finite differences.
    tol : relative residual ``|P(x) - x| / |x|`` of the fixed point.
    max_iter : Newton iterations of the shooting.

    Returns
    -------
    :class:`Monodromy` (``success`` False, with the reason in ``message``, when the shooting did
    not converge: the multipliers are then those at the last iterate).
    """
    t0 = time.perf_counter()
    f = positive(frequency, "frequency")
    steps = count(integration.steps_per_period, "steps_per_period", 8)
    count(max_iter, "max_iter", 0)
    positive(perturbation, "perturbation")
    positive(tol, "tol")
    integ = Integrator(model, 2.0 * np.pi * f, integration, start)
    P = PeriodMap(integ)
    x = P.state()
    r = P.r
    res, it = np.inf, 0
    for it in range(max_iter + 1):
        Px = P(x)
        res = float(np.linalg.norm(Px - x) / max(np.linalg.norm(x), 1e-300))
        if res <= tol or it == max_iter:
            break
        J = _jacobian(P, x, perturbation * _scales(x, r), central=False)
        # least squares: a multiplier exactly 1 (a node stuck all period: a family of
        # periodic states) leaves the member nearest the start
        dx = np.linalg.lstsq(J - np.eye(x.size), -(Px - x), rcond=1e-12)[0]
        x = x + dx
    ok = res <= tol
    Mx = _jacobian(P, x, perturbation * _scales(x, r), central=True)
    mult = np.linalg.eigvals(Mx)
    mult = mult[np.argsort(-np.abs(mult), kind="stable")]
    P(x)  # the integrator's state at the fixed point, for the full fields
    integ.q[:] = x[:r]
    integ.dq[:] = x[r:]
    U, V = integ.full_state()
    msg = (f"periodic state found in {it} Newton iterations (residual {res:.2e})" if ok else
           f"shooting did not converge in {max_iter} iterations (residual {res:.2e} > {tol:g})")
    return Monodromy(mult, Mx, x, U, V, res, it, ok, msg, steps, time.perf_counter() - t0)
