"""The slowest direction of a periodic DLFT solution: the balance's near-null direction and the
real Floquet multiplier nearest 1 it carries (how fast a start elsewhere relaxes to the state).

Why
---
Where every contact node slips at some instant of the period, Coulomb's law does not see a
rigid tangential shift of the interface: the slip intervals, and so the friction forces, are
unchanged. What holds the interface's mean tangential position is then only the structure
(e.g. a weak spring, or the tangential stiffness of a body that the interface alone supports):
the balance's Jacobian ``J = T(0)`` (eq. 22-28 differentiated) is nearly singular along that
shift. In time, a start at another mean position does not jump back: it ratchets back, by a
small fraction of the offset per period, and a time integration stopped after a few thousand
periods is still "drifting" (:func:`fretwear.timedomain.stability.check_periodic`) although
the periodic state is where the drift ends. (Where nodes stick all period the shift is an
exact family, pinned by the stick anchors: :attr:`fretwear.hb.stability.FloquetResult.neutral`.)

How
---
Along such a direction the Floquet exponent ``s`` is small: it is the root nearest 0 of the
eigenvalue ``mu(sigma)`` of Hill's matrix ``T(s)`` (:class:`fretwear.hb.stability.HillProblem`,
``sigma = s / w``) that vanishes at ``sigma = 0`` for an exact family. With ``v`` and ``u`` the
right and left eigenvectors of ``J`` for its eigenvalue nearest 0 (inverse iteration from the
rigid tangential shift of the interface at harmonic 0), first-order perturbation of
``T(sigma) v = mu v`` gives ``mu(sigma) ~ (u^T T(sigma) v) / (u^T v)``, and Newton's method on
it (the derivative by central differences of ``T``) gives ``sigma``; the multiplier is
``rho = e^{2 pi sigma}``. A few evaluations of ``T`` and one LU of ``J``: it needs no
eigensolve of Hill's quadratic problem, so it runs where that is too large (``m H`` at most
:data:`fretwear.hb.stability.DENSE_MAX`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from fretwear.hb.dynamics import StructureDynamics
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.stability import NEGLIGIBLE, HillProblem

#: a relaxation slower than this many periods (``1 / |1 - rho|``) is reported as slow: the
#: default time-domain check (:func:`fretwear.timedomain.stability.check_periodic`, 3000
#: periods) sees a drift, not the state
SLOW_PERIODS = 1000.0
#: the eigenvalue of ``J`` nearest 0, relative to ``eps``, below which ``J`` is taken as nearly
#: singular and the first-order estimate is made (on a Jenkins element held by a weak spring,
#: against the monodromy of the exact integration: 1e-4 gave ``1 - rho`` within 0.5 %, 1e-3
#: within 5 %, 1e-2 a real multiplier where the integration has a complex pair)
NEAR_NULL = 1e-3
#: step of the central difference of ``T`` in ``sigma = s / w``
STEP = 1e-6


@dataclass
class SlowMode:
    """The slowest direction of a periodic solution (:func:`slow_mode`).

    multiplier : the real Floquet multiplier nearest 1 [-] (below 1: a start elsewhere along
        the direction relaxes to the state by the fraction ``1 - multiplier`` per period;
        above 1: it moves away; 0: it decays within a period; NaN: ``J`` is not nearly
        singular, its eigenvalue nearest 0 above :data:`NEAR_NULL` times ``eps``, or ``mu``
        has no root near 0).
    exponent : its Floquet exponent ``s`` [1/s].
    eigenvalue : the eigenvalue of ``J`` nearest 0 relative to ``eps`` [-] (``J`` is nearly
        singular along the direction when this is small).
    rigid : the part of the direction that is the rigid tangential shift of the interface at
        harmonic 0, ``|<v, e>|`` with unit vectors [-] (1: the interface's mean position).
    iterations : Newton iterations on ``mu(sigma)``.
    """

    multiplier: float
    exponent: float
    eigenvalue: float
    rigid: float
    iterations: int

    @property
    def periods(self) -> float:
        """Periods over which an offset along the direction relaxes (or grows) by ``e``."""
        gap = abs(1.0 - self.multiplier)
        if not math.isfinite(gap):
            return math.nan
        return math.inf if gap == 0 else 1.0 / gap

    def slow(self, periods: float = SLOW_PERIODS) -> bool:
        """The relaxation takes more than ``periods`` periods (False where the multiplier
        could not be found: NaN)."""
        return bool(self.periods > periods)

    def line(self) -> str:
        """One line for a summary: what the direction is and what a time integration sees."""
        what = ("the interface's mean tangential position" if self.rigid >= 0.9 else
                "the balance's slowest direction")
        rho = self.multiplier
        near = f"1 {'-' if rho < 1 else '+'} {abs(1 - rho):.2g}"
        head = f"{what} is held only weakly: Floquet multiplier {near} along it"
        if rho > 1:
            return (f"{what} is not held: Floquet multiplier {near} along it: a start next "
                    f"to this state moves away from it (UNSTABLE), an offset growing e-fold "
                    f"over about {self.periods:.2g} periods")
        if not self.slow():
            return (f"{what}: Floquet multiplier {near} along it (relaxes over "
                    f"{self.periods:.2g} periods)")
        return (f"{head} (Jacobian nearly singular there: eigenvalue {self.eigenvalue:.2g} "
                f"of eps): a start at another position relaxes to this state over about "
                f"{self.periods:.2g} periods, so a time integration is still drifting towards "
                "it when it stops (check_periodic: \"drifting\"); the state is where that "
                "drift ends, not the response of the first periods")


def rigid_shift(prob: DLFTProblem) -> np.ndarray:
    """(m H, d-1) unit vectors: the interface's tangential positions shifted rigidly, one
    column per tangential axis of the contact frames, harmonic 0 (the mean)."""
    m, H, d = prob.m, prob.H, prob.d
    E = np.zeros((m, H, d - 1))
    for a in range(d - 1):
        E[1 + a::d, 0, a] = 1.0
    E = E.reshape(m * H, d - 1)
    return E / np.linalg.norm(E, axis=0)


def _near_null(lu, x: np.ndarray, trans: int, iterations: int = 3) -> np.ndarray:
    """Inverse iteration on ``J`` (``trans`` 0) or ``J^T`` (1) from ``x``."""
    for _ in range(iterations):
        x = sla.lu_solve(lu, x, trans=trans)
        x = x / np.linalg.norm(x)
    return x


def slow_mode(prob: DLFTProblem, U, dyn: StructureDynamics, *,
              max_iter: int = 4) -> SlowMode:
    """The real Floquet multiplier of ``U`` (m, H), a converged solution of ``prob``, along
    the balance's near-null direction (module docstring); ``dyn`` the structure
    (:func:`fretwear.hb.dynamics.structure_dynamics` of the model, as for Hill's method).
    Raises :class:`~fretwear.errors.InputError` where :class:`HillProblem` cannot be formed
    (quasi-static, ``m H`` above its dense limit)."""
    hp = HillProblem(prob, U, dyn)
    J = np.real(hp.matrix(0.0))
    lu = sla.lu_factor(J)
    E = rigid_shift(prob)
    # the tangential axis whose rigid shift J resists least starts the inverse iteration
    start = E[:, int(np.argmin(np.linalg.norm(J @ E, axis=0)))]
    v = _near_null(lu, start, 0)
    u = _near_null(lu, start, 1)
    uv = float(u @ v)
    if not abs(uv) > 1e-12:  # left and right vectors orthogonal (a Jordan block): no estimate
        return SlowMode(math.nan, math.nan, math.nan, float(np.max(np.abs(E.T @ v))), 0)

    def mu(sigma: float) -> float:
        return float(np.real(u @ (hp.matrix(sigma) @ v))) / uv

    mu0 = float(u @ (J @ v)) / uv
    rigid = float(np.max(np.abs(E.T @ v)))
    if not abs(mu0) <= NEAR_NULL * prob.eps:  # no near-null direction: nothing slow
        return SlowMode(math.nan, math.nan, mu0 / prob.eps, rigid, 0)
    sigma, value, it = 0.0, mu0, 0
    for it in range(1, max_iter + 1):
        slope = (mu(sigma + STEP) - mu(sigma - STEP)) / (2.0 * STEP)
        if not (np.isfinite(slope) and slope != 0.0):
            sigma = math.nan  # no root of mu near 0: J is not nearly singular
            break
        step = -value / slope
        sigma += step
        if 2.0 * np.pi * sigma < math.log(NEGLIGIBLE):  # decays within a period: not slow
            sigma = -math.inf
            break
        if abs(step) <= 1e-6 * max(abs(sigma), 1e-12) or it == max_iter:
            break
        value = mu(sigma)
    return SlowMode(multiplier=float(np.exp(2.0 * np.pi * sigma)),
                    exponent=float(sigma * hp.omega), eigenvalue=mu0 / prob.eps,
                    rigid=rigid, iterations=it)
