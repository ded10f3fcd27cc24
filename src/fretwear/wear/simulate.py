"""Fretting wear on the slow time scale: "DLFT with wear" (paper section 3.3, eq. 29-30).

Two time scales (paper section 2): the vibration period (fast) is solved by the DLFT harmonic
balance (:mod:`fretwear.hb.periodic`); the wear depth ``W`` of every contact node evolves over the
cycle count ``N`` (slow) by

    dW/dN = g(W),       g_p = dW1_p = wear depth per cycle of node p on the periodic
                        solution balanced with the normal gap ``gap + W``          (eq. 29)

Wear laws (per node, per cycle, evaluated on the converged DLFT samples with the *corrected*
slip ``X_T(n) - X_T(n-1)``, which is exactly zero in stick):

* Archard (eq. 29): ``dW1_p = k_w sum_n p_N(n) |X_T(n) - X_T(n-1)|``, ``p_N = lambda_N/area``;
* energy (Fouvry et al. 2003): worn volume = ``k_e`` x friction energy, so
  ``dW1_p = k_e E_p / area_p`` with ``E_p = sum_n lambda_T(n).(X_T(n) - X_T(n-1))``.

With Coulomb slip ``E_p = mu sum_n lambda_N |dX_T|`` exactly, so both laws are ``c_p S_p`` with
the slip work ``S_p`` of :mod:`fretwear.wear.kernels` and ``c_p = k_w / area_p`` or
``k_e mu / area_p``; the worn volume per cycle of Archard's law is ``k_w / mu`` times the
friction energy per cycle.

Slow-scale schemes (:func:`simulate_wear`):

* ``"explicit"``: explicit Euler with cycle jumps ``dN`` (eq. 30), as the paper;
* ``"rosenbrock"`` (default): linearly implicit Euler ``W_{k+1} = W_k + dN (I - dN Js)^-1 g``
  with the slow Jacobian ``Js = dg/dW`` along balanced solutions, then the balance;
* ``"implicit"``: backward Euler ``W_{k+1} = W_k + dN g(W_{k+1})``, by a damped Newton method
  on ``W`` over balanced solutions (or, ``implicit_newton = "coupled"``, Newton on the coupled
  unknowns ``(U~, W_{k+1})`` with residuals ``f(U~; W_{k+1})`` (DLFT, eq. 22) and
  ``eps (W_{k+1} - W_k - dN g(U~, W_{k+1}))``).

The implicit schemes are stable for any jump, which explicit Euler is not (``dN < 2/rho(Js)``):
docs/wear.md measures all of them.

Every scheme may adapt its jump to a tolerance on the local error, estimated by the defect
against the trapezoidal rule ``|W_{k+1} - W_k - dN (g(W_k) + g(W_{k+1}))/2|`` (no extra solve),
relative to the current maximum wear depth.

Each step starts from the previous periodic solution (warm start) and keeps the stick anchors
of its mean tangential position (the loading history rule of :mod:`fretwear.hb.sweep`). A step
whose solve fails is retried with a smaller jump; when that fails too the run stops, says so,
and keeps every converged step. A checkpoint (``.npz``, written atomically) holds the complete
state, so that an interrupted run resumes to the same result.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from fretwear.errors import ConvergenceError, InputError
from fretwear.files import atomic_write
from fretwear.hb import contact as law
from fretwear.hb import solvers
from fretwear.hb.fallback import TimeDomainFallback
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.periodic import (
    DLFTProblem,
    PeriodicSolution,
    assemble_solution,
    initial_state,
    solve_periodic,
    static_anchor,
)
from fretwear.hb.reduce import Reduced, condense
from fretwear.hb.solvers import SOLVERS, SolveStats, solve, solve_identity_rows
from fretwear.model.core import Model
from fretwear.wear.kernels import slip_work, slip_work_gradient

LAWS = ("archard", "energy")
SCHEMES = ("implicit", "rosenbrock", "explicit")
STOP_REASONS = ("max_cycles", "max_depth", "plateau", "no_wear", "max_steps", "solver_failed")
CHECKPOINT_VERSION = 2
#: retried jumps are not cut below this fraction of the cycle count
MIN_JUMP_FRACTION = 1e-5
#: with a time-domain step behind, failed solves do not cut the jump below this fraction of N
RESCUE_START_FRACTION = 1e-3
#: iteration cap of a balance started from a time integration
RESCUE_MAX_ITER = 400
#: periods integrated from rest when the unworn interface has no periodic balance
START_SETTLE = 2000
#: first jump of such a run [cycles] (no slow Jacobian to size it)
START_JUMP = 1e4
#: responses of a time-domain step from which the balance is tried (see _time_domain_step)
BALANCE_KINDS = ("periodic", "drifting", "transient")
#: implicit schemes keep dN lam <= this for the growing modes (lam > 0) of the slow Jacobian
GROWTH_LIMIT = 0.5


# --------------------------------------------------------------------------------------------
# wear laws
# --------------------------------------------------------------------------------------------
def wear_coefficients(model: Model, law_name: str = "archard",
                      energy_coefficient: float | None = None) -> np.ndarray:
    """Per-node factor ``c_p`` [1/N] with ``dW1_p = c_p S_p`` (module docstring).

    Parameters
    ----------
    model : the model (``contact.wear_coefficient`` k_w [1/Pa], ``contact.area`` [m^2],
        ``contact.mu``).
    law_name : ``"archard"`` (eq. 29, ``c = k_w / area``) or ``"energy"``
        (``c = k_e mu / area``).
    energy_coefficient : ``k_e`` [m^3/J] of the energy law.
    """
    c = model.contact
    area = np.asarray(c.area, dtype=float)
    if law_name == "archard":
        k = float(c.wear_coefficient)
        if not k >= 0:
            raise InputError(f"wear_coefficient = {k!r}: expected k_w >= 0 [1/Pa]")
        return k / area
    if law_name == "energy":
        if energy_coefficient is None or not float(energy_coefficient) >= 0:
            raise InputError(f"energy_coefficient = {energy_coefficient!r}: the energy law needs "
                             "k_e >= 0 [m^3/J]")
        return float(energy_coefficient) * float(c.mu) / area
    raise InputError(f"law = {law_name!r}: expected one of {LAWS}")


def wear_per_cycle(sol: PeriodicSolution, *, law_name: str = "archard",
                   wear_coefficient: float = 0.0,
                   energy_coefficient: float | None = None) -> np.ndarray:
    """Wear depth per cycle ``dW1`` per node (nc,) [m] of a converged periodic solution.

    Archard (eq. 29 with the corrected slip): ``k_w sum_n p_N(n) |X_T(n) - X_T(n-1)|``, from
    :meth:`~fretwear.hb.periodic.PeriodicSolution.pressure_t` and
    :meth:`~fretwear.hb.periodic.PeriodicSolution.slip_t` (zero in stick, so a node that sticks all
    period does not wear). Energy law (Fouvry et al. 2003): ``k_e E_p / area_p`` with ``E_p``
    from :meth:`~fretwear.hb.periodic.PeriodicSolution.friction_energy`.

    This is the post-processing route; the integrators use the kernel
    :func:`fretwear.wear.kernels.slip_work`, which gives the same numbers.
    """
    if law_name == "archard":
        return float(wear_coefficient) * np.sum(sol.pressure_t() * sol.slip_t(), axis=1)
    if law_name == "energy":
        if energy_coefficient is None:
            raise InputError("the energy law needs energy_coefficient k_e [m^3/J]")
        return float(energy_coefficient) * sol.friction_energy() / sol.area
    raise InputError(f"law = {law_name!r}: expected one of {LAWS}")


def worn_volume(wear: np.ndarray, area: np.ndarray) -> float:
    """Worn volume ``sum_p area_p W_p`` [m^3] of wear depths ``W`` [m]."""
    return float(np.dot(np.asarray(area, float), np.asarray(wear, float)))


def zero_wear_zones(x, wear, fraction: float = 0.01) -> list[list[float]]:
    """Intervals ``[x_first, x_last]`` [m] of consecutive contact nodes (ordered by ``x``)
    whose wear depth is at most ``fraction`` of the deepest: the "pillars" and nodal zones of
    the paper (section 4.2.2-4.2.3)."""
    x = np.asarray(x, float)
    w = np.asarray(wear, float)
    order = np.argsort(x)
    x, w = x[order], w[order]
    low = w <= fraction * max(float(w.max()), 1e-300)
    zones, start = [], None
    for i, z in enumerate(low):
        if z and start is None:
            start = i
        if not z and start is not None:
            zones.append([float(x[start]), float(x[i - 1])])
            start = None
    if start is not None:
        zones.append([float(x[start]), float(x[-1])])
    return zones


# --------------------------------------------------------------------------------------------
# linear algebra: identity rows of the DLFT Jacobian
# --------------------------------------------------------------------------------------------
def newton(fun, x0, scale, *, tol=1e-9, max_iter=30) -> tuple[np.ndarray, SolveStats]:
    """Newton's method of :mod:`fretwear.hb.solvers` (backtracking on ``|f|^2``, the LU of the
    rows that are not plain identity rows) for the warm-started balances of the slow steps.
    Returns ``(x, stats)``."""
    x, _, st = solvers.newton(fun, x0, scale, tol=tol, max_iter=max_iter)
    return x, st


# --------------------------------------------------------------------------------------------
# the coupled problem of one slow step
# --------------------------------------------------------------------------------------------
class SlowProblem:
    """The DLFT balance with wear as a function of the wear depths (one frequency).

    Parameters
    ----------
    model : the model; reduced : its condensation on ``[0] + basis.harmonics``.
    basis : Fourier basis.
    coef : (nc,) wear factors ``c_p`` [1/N] (:func:`wear_coefficients`).
    eps : DLFT penalty [N/m] (None: spectral radius of ``Z_r``).
    anchor : (nc, d-1) stick anchors [m].

    The wear depths ``W`` (nc,) [m] enter the DLFT as the normal gap ``gap0 + W``; ``E_W`` puts
    ``W_p`` into the static coefficient of the normal DOF of node ``p``.
    """

    def __init__(self, model: Model, reduced: Reduced, basis: FourierBasis, coef, *, eps=None,
                 anchor=None, time_domain: TimeDomainFallback | None = None):
        self.model = model
        self.time_domain = time_domain  # fallback of failed balances (None: none)
        self.gap0 = np.broadcast_to(np.asarray(model.contact.gap, float),
                                    (model.contact.n_nodes,)).copy()
        self.prob = DLFTProblem(reduced, model.contact, basis, gap=self.gap0, eps=eps,
                                anchor=anchor)
        p = self.prob
        self.nc, self.d, self.H, self.m = p.nc, p.d, p.H, p.m
        self.n = p.m * p.H
        self.dH = p.d * p.H
        self.eps = p.eps
        self.coef = np.asarray(coef, float)
        # index of (node p, normal component, static coefficient) in the DOF-major unknowns
        self.iw = np.arange(self.nc) * self.dH
        self._epsI_Z = None

    # -- helpers --------------------------------------------------------------------------
    def set_state(self, W, anchor):
        self.prob.set_gap(self.gap0 + np.asarray(W, float))
        self.prob.anchor = np.array(anchor, float)

    def epsI_minus_Z(self):
        """``d lambda_u~ / dU~ = eps I - Z`` (n, n), cached."""
        if self._epsI_Z is None:
            A = -self.prob.Z.copy()
            A[np.diag_indices(self.n)] += self.eps
            self._epsI_Z = A
        return self._epsI_Z

    def rate(self, U):
        """Wear depth per cycle ``g = c S`` (nc,) [m] at ``U`` (m, H) with the current gap."""
        lu, lx, state, _ = self.prob.time_law(U)
        return self.coef * slip_work(lu, lx, state, self.eps)

    def rate_and_gradient(self, U):
        """``g`` (nc,) [m], ``dg/dU~`` (nc, n) [m/m] and ``dg/dW`` (nc,) [-] (diagonal) at the
        current gap: ``dg/dU~ = c dS/dlambda_u~ (eps I - Z)``, ``dg/dW = -eps c dS/dlambda_u,N0``.
        """
        p = self.prob
        lu, lx, state, _ = p.time_law(U)
        S, dS = slip_work_gradient(lu, lx, state, p.mu, p.Q, self.eps)
        g = self.coef * S
        A = self.epsI_minus_Z().reshape(self.nc, self.dH, self.n)
        gU = self.coef[:, None] * np.einsum("pi,pij->pj", dS, A)
        gW = -self.eps * self.coef * dS[:, 0]
        return g, gU, gW, (lu, lx, state)

    def dfdW(self, lu, lx, state):
        """``df/dW`` (n, nc) = ``-eps E_W + eps G E_W`` (G block-diagonal per node)."""
        p = self.prob
        # same arguments as DLFTProblem.residual (stick anchors for all-stick nodes)
        G = law.dlft_jacobian(lu, lx, state, p.mu, p.P, p.Q, self.eps * p.anchor, p.tol,
                              p.max_sweeps)
        out = np.zeros((self.n, self.nc))
        for q in range(self.nc):
            rows = slice(q * self.dH, (q + 1) * self.dH)
            out[rows, q] = self.eps * G[q][:, 0]
            out[q * self.dH, q] -= self.eps
        return out

    # -- residuals -------------------------------------------------------------------------
    def balance(self, U, jacobian=True):
        """DLFT residual ``f`` (n,) and Jacobian (n, n) at ``U`` (m, H), current gap."""
        return self.prob.residual(U, jacobian)

    def coupled(self, x, W_k, dN, jacobian=True):
        """Backward Euler residual on ``x = [U~ (n), W (nc)]``.

        ``R = [f(U~; W), eps (W - W_k - dN g(U~, W))]`` and its Jacobian
        ``[[J, df/dW], [-eps dN dg/dU~, eps (I - dN dg/dW)]]``.
        """
        U = x[: self.n].reshape(self.m, self.H)
        W = x[self.n :]
        self.prob.set_gap(self.gap0 + W)
        f, J = self.prob.residual(U, jacobian)
        if not jacobian:
            g = self.rate(U)
            return np.concatenate([f, self.eps * (W - W_k - dN * g)]), None
        g, gU, gW, (lu, lx, state) = self.rate_and_gradient(U)
        R = np.concatenate([f, self.eps * (W - W_k - dN * g)])
        n, nc = self.n, self.nc
        JJ = np.empty((n + nc, n + nc))
        JJ[:n, :n] = J
        JJ[:n, n:] = self.dfdW(lu, lx, state)
        JJ[n:, :n] = -self.eps * dN * gU
        JJ[n:, n:] = 0.0
        JJ[n + np.arange(nc), n + np.arange(nc)] = self.eps * (1.0 - dN * gW)
        return R, JJ

    def slow_jacobian(self, U, with_dUdW=False):
        """Total ``dg/dW`` (nc, nc) [-] along the balanced solution at ``U`` (current gap):
        ``dg/dW + dg/dU~ dU~/dW`` with ``dU~/dW = -J^-1 df/dW`` (implicit function theorem on
        the DLFT balance). Its eigenvalues set the stability limit of explicit Euler,
        ``dN < 2 / rho``. With ``with_dUdW`` also returns ``dU~/dW`` (n, nc)."""
        f, J = self.balance(U, True)
        g, gU, gW, (lu, lx, state) = self.rate_and_gradient(U)
        dUdW = -solve_identity_rows(J, self.dfdW(lu, lx, state))
        Js = np.diag(gW) + gU @ dUdW
        return (Js, dUdW) if with_dUdW else Js

    # -- solves --------------------------------------------------------------------------
    def solve_balance(self, W, anchor, U0, *, solver, tol, max_iter, fast=True):
        """Periodic solution at wear ``W`` from ``U0``: ``(U (m, H), stats)``.

        With ``fast``, :func:`newton` first (warm starts converge in a few steps); if it fails,
        ``solver`` of :mod:`fretwear.hb.solvers` from the same start."""
        self.set_state(W, anchor)
        p = self.prob

        def fun(x, jac=True):
            return p.residual(x.reshape(self.m, self.H), jac)

        def scale(x):
            return p.scale(x.reshape(self.m, self.H))

        x0 = np.asarray(U0, float).reshape(-1)
        its = 0
        if fast:
            x, st = newton(fun, x0, scale, tol=tol, max_iter=min(max_iter, 15))
            if st.converged:
                return x.reshape(self.m, self.H), st
            its = st.iterations
        x, _, st = solve(fun, x0, scale, method=solver, tol=tol, max_iter=max_iter)
        st.iterations += its
        return x.reshape(self.m, self.H), st

    def solve_implicit(self, W_k, dN, anchor, U0, W0, *, solver, tol, max_iter):
        """Backward Euler step: ``(U, W_{k+1}, stats)`` from the guess ``(U0, W0)``."""
        self.set_state(W0, anchor)
        p = self.prob
        W_k = np.asarray(W_k, float)

        def fun(x, jac=True):
            return self.coupled(x, W_k, dN, jac)

        x0 = np.concatenate([np.asarray(U0, float).reshape(-1), np.asarray(W0, float)])
        x, _, st = solve(fun, x0, lambda x: p.scale(x[: self.n].reshape(self.m, self.H)),
                         method=solver, tol=tol, max_iter=max_iter)
        return x[: self.n].reshape(self.m, self.H), x[self.n :].copy(), st

    def solution(self, U, W, anchor, stats) -> PeriodicSolution:
        """Post-processed periodic solution at ``(U, W)``."""
        self.set_state(W, anchor)
        return assemble_solution(self.prob, U, self.model, stats)

    def shift_guess(self, U, dW):
        """Warm start for a wear change ``dW``: nodes in contact follow the gap (``X_N = 0``
        means ``U_N,0 = gap + W``)."""
        U1 = np.array(U, float).reshape(self.nc, self.d, self.H)
        U1[:, 0, 0] += dW
        return U1.reshape(self.m, self.H)


# --------------------------------------------------------------------------------------------
# options, history, result
# --------------------------------------------------------------------------------------------
@dataclass
class WearOptions:
    """Settings of a wear simulation (:func:`simulate_wear`).

    Attributes
    ----------
    law : ``"archard"`` (eq. 29, coefficient ``model.contact.wear_coefficient`` [1/Pa]) or
        ``"energy"`` (Fouvry et al. 2003, ``energy_coefficient`` [m^3/J]).
    energy_coefficient : ``k_e`` [m^3/J] of the energy law.
    scheme : ``"rosenbrock"`` (linearly implicit Euler with the slow Jacobian; default: the
        cheapest for a given accuracy, docs/wear.md), ``"implicit"`` (backward Euler, every
        iterate a balanced solution) or ``"explicit"`` (explicit Euler, eq. 30).
    implicit_newton : how ``"implicit"`` solves its step: ``"nested"`` (Newton on W over
        balanced solutions) or ``"coupled"`` (Newton on (U~, W1) together).
    adaptive : adapt the jump to ``tolerance``; otherwise every jump is ``initial_jump``.
    tolerance : local error allowed per step, relative to the current maximum wear depth.
    initial_jump : first jump [cycles]; None: ``2 tolerance / rho`` with ``rho`` the spectral
        radius of the slow Jacobian at the start (adaptive), or ``1 / rho`` (fixed jumps: half
        the explicit stability limit).
    max_jump : cap on the jump [cycles] (the paper's 1e8 / 1e7).
    min_jump : smallest jump tried when retrying failed solves [cycles]; the floor is also at
        least 1e-5 of the cycle count (smaller jumps cannot change the outcome).
    max_cycles : stop at this cycle count.
    max_depth : stop when a wear depth reaches this [m].
    plateau_rate : stop when the worn-volume rate falls below this fraction of its initial
        value (the plateau of paper Fig. 25).
    max_steps : stop after this many slow steps.
    solver, tol, max_iter : nonlinear solver (:func:`fretwear.hb.solvers.solve`), its relative
        residual tolerance ``eps_r`` and iteration cap.
    max_retries : jump reductions (by 4) tried after a failed solve before stopping.
    time_domain_rescue : (dynamic cases) when a step's periodic balance fails, take the step
        from a time integration at the predicted wear (:func:`_time_domain_step`): from its
        periodic state when it has one and the balance converges from there, otherwise with the
        wear rate averaged over its periods (:mod:`fretwear.timedomain.averaged_rate`).
    time_domain_settle, time_domain_average : periods integrated before averaging, and
        averaged, by such a step.
    time_domain_steps : time steps per period of such a step (default ``max(128, 8 x`` the
        highest harmonic)); stick-slip events are first order in the step (docs/wear.md).
    checkpoint_every_s : write the checkpoint at most this often [s] (0: every step).
    """

    law: str = "archard"
    energy_coefficient: float | None = None
    scheme: str = "rosenbrock"
    adaptive: bool = True
    tolerance: float = 1e-2
    initial_jump: float | None = None
    max_jump: float = math.inf
    min_jump: float = 1.0
    max_cycles: float = 1e15
    max_depth: float = math.inf
    plateau_rate: float = 1e-3
    max_steps: int = 100_000
    solver: str = "powell"
    tol: float = 1e-9
    max_iter: int = 60
    max_iter_coupled: int = 20
    max_iter_implicit: int = 8
    implicit_newton: str = "nested"
    max_retries: int = 6
    time_domain_rescue: bool = True
    time_domain_settle: int = 300
    time_domain_average: int = 500
    time_domain_steps: int | None = None
    checkpoint_every_s: float = 10.0

    def check(self) -> WearOptions:
        """Validate; raise InputError naming the bad value."""
        if self.law not in LAWS:
            raise InputError(f"law = {self.law!r}: expected one of {LAWS}")
        if self.scheme not in SCHEMES:
            raise InputError(f"scheme = {self.scheme!r}: expected one of {SCHEMES}")
        if self.solver not in SOLVERS:
            raise InputError(f"solver = {self.solver!r}: expected one of {SOLVERS}")
        for name in ("tolerance", "max_jump", "min_jump", "max_cycles", "max_depth", "tol"):
            v = getattr(self, name)
            if not (isinstance(v, int | float) and v > 0):
                raise InputError(f"{name} = {v!r}: expected a positive number")
        if self.initial_jump is not None and not self.initial_jump > 0:
            raise InputError(f"initial_jump = {self.initial_jump!r}: expected > 0 cycles")
        for name in ("time_domain_settle", "time_domain_average"):
            v = getattr(self, name)
            if not (isinstance(v, int) and v >= (0 if name.endswith("settle") else 2)):
                raise InputError(f"{name} = {v!r}: expected a whole number of periods"
                                 + (" >= 0" if name.endswith("settle") else " >= 2"))
        ts = self.time_domain_steps
        if ts is not None and not (isinstance(ts, int) and ts >= 8):
            raise InputError(f"time_domain_steps = {ts!r}: expected a whole number >= 8 of "
                             "time steps per period")
        if not self.plateau_rate >= 0:
            raise InputError(f"plateau_rate = {self.plateau_rate!r}: expected >= 0")
        return self

    def trajectory_key(self) -> dict:
        """The options that change the computed trajectory (for checkpoint matching). The stop
        criteria are not among them: a finished run can be extended (e.g. a larger
        ``max_cycles``) by resuming from its checkpoint."""
        d = asdict(self)
        for k in ("checkpoint_every_s", "max_cycles", "max_depth", "plateau_rate", "max_steps"):
            d.pop(k)
        return d


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


@dataclass
class WearHistory:
    """The wear history, one row per slow step (step 0 is the unworn start).

    Arrays (s = steps, nc = contact nodes, d = components, H = Fourier coefficients): see
    :data:`HISTORY_FIELDS` for units; ``wear_depth``, ``wear_rate``, ``pressure_*``,
    ``slip_*``, ``friction_energy`` are (s, nc); ``state_fraction`` (s, nc, 3);
    ``U``, ``lam`` (s, nc, d, H); ``anchor`` (s, nc, d-1); the others (s,).
    ``stop_reason`` says why the run ended (one of :data:`STOP_REASONS`, or "" while running).
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
    """Outcome of :func:`simulate_wear`.

    history : :class:`WearHistory`; initial, final : periodic solutions at the first and last
    balanced steps (steps whose rate was averaged over a time integration, ``rescued = 2``,
    have no periodic solution; None when no step was balanced); penalty : the DLFT eps [N/m];
    stop_reason : why it stopped; message : one line for the user;
    converged : False when it stopped on a failed solve (every recorded step converged);
    wall_time : [s]; stability_jump : explicit Euler's stability limit ``2/rho`` estimated
    from the slow Jacobian at the start [cycles] (nan if not computed).
    """

    history: WearHistory
    initial: PeriodicSolution
    final: PeriodicSolution
    stop_reason: str
    message: str
    converged: bool
    wall_time: float
    stability_jump: float = math.nan
    resumed_from: int = -1
    penalty: float = math.nan
    extra: dict = field(default_factory=dict)

    @property
    def final_wear(self) -> np.ndarray:
        return self.history.wear_depth[-1]


def _row(sol: PeriodicSolution, W, g, cycles, jump, iters, rejected, err, wall) -> dict:
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


# --------------------------------------------------------------------------------------------
# checkpoints
# --------------------------------------------------------------------------------------------
def fingerprint(model: Model, reduced: Reduced, basis: FourierBasis, eps: float, coef,
                options: WearOptions, W0, anchor0) -> str:
    """SHA-256 of everything that determines the trajectory (model data after condensation,
    basis, penalty, wear factors, options, initial state)."""
    h = hashlib.sha256()
    for a in (reduced.Z, reduced.F, np.asarray(model.contact.gap, float),
              np.asarray(model.contact.area, float), np.asarray(coef, float),
              np.asarray(W0, float), np.asarray(anchor0, float)):
        h.update(np.ascontiguousarray(a).tobytes())
    meta = {"basis": [list(basis.harmonics), basis.n_samples], "eps": float(eps),
            "mu": float(model.contact.mu), "omega": float(reduced.omega),
            "quasi_static": bool(reduced.quasi_static), "options": options.trajectory_key()}
    h.update(json.dumps(meta, sort_keys=True, default=str).encode())
    return h.hexdigest()


def save_checkpoint(path: Path | str, state: dict, rows: list[dict], key: str) -> Path:
    """Write the state and the history so far to ``path`` (``.npz``) atomically."""
    arrays = {f"state_{k}": np.asarray(v) for k, v in state.items()}
    hist = WearHistory.from_rows(rows)
    arrays.update({f"hist_{k}": getattr(hist, k) for k in HISTORY_FIELDS})
    arrays["fingerprint"] = np.asarray(key)
    arrays["version"] = np.asarray(CHECKPOINT_VERSION)

    def write(tmp: Path):
        with open(tmp, "wb") as fh:
            np.savez(fh, **arrays)

    return atomic_write(path, write)


def _read_checkpoint(path: Path | str) -> dict:
    """The arrays of a checkpoint of this format version (:func:`save_checkpoint`)."""
    try:
        with np.load(path, allow_pickle=False) as z:
            data = {k: z[k] for k in z.files}
    except (OSError, ValueError) as exc:
        raise InputError(f"cannot read the wear checkpoint {str(path)!r}: {exc}") from None
    if int(data.get("version", -1)) != CHECKPOINT_VERSION:
        raise InputError(f"wear checkpoint {str(path)!r} has another format version; delete it "
                         "to start again")
    return data


#: history fields added within the current checkpoint format: NaN (not measured) when absent
LATE_HISTORY_FIELDS = ("rate_scatter",)


def _history(data) -> WearHistory:
    """The history arrays of a checkpoint (:data:`LATE_HISTORY_FIELDS` filled with NaN in
    checkpoints written before they were recorded)."""
    n = len(data["hist_cycles"])
    late = {k: np.full(n, np.nan) for k in LATE_HISTORY_FIELDS if f"hist_{k}" not in data}
    return WearHistory(**{k: late[k] if k in late else data[f"hist_{k}"]
                          for k in HISTORY_FIELDS})


def read_history(path: Path | str) -> WearHistory:
    """The wear history stored in a checkpoint, whatever case wrote it (to look at a run that
    is going on or was interrupted; :func:`load_checkpoint` to resume one)."""
    return _history(_read_checkpoint(path))


def load_checkpoint(path: Path | str, key: str) -> tuple[dict, list[dict]]:
    """Read a checkpoint written by :func:`save_checkpoint` for the same trajectory ``key``.

    Raises
    ------
    InputError
        The file is unreadable, of another version, or written for a different case.
    """
    data = _read_checkpoint(path)
    if str(data["fingerprint"]) != key:
        raise InputError(f"wear checkpoint {str(path)!r} was written for a different model or "
                         "different wear settings; delete it (or run without --resume) to start "
                         "again")
    state = {k[6:]: data[k] for k in data if k.startswith("state_")}
    return state, _history(data).rows()


# --------------------------------------------------------------------------------------------
# the slow-scale driver
# --------------------------------------------------------------------------------------------
def _error(dN, W1, W_k, g1, g0) -> float:
    """Local error estimate: the defect of the step against the trapezoidal rule,
    ``max |W1 - W_k - dN (g0 + g1) / 2|``, relative to ``max W1``.

    For explicit and backward Euler it is ``0.5 dN max|g1 - g0|`` (the classical estimate of
    their local error); for the linearly implicit step it also catches an increment that does
    not match the rates at either end (a slow Jacobian made stale by a change of contact states).
    """
    scale = float(np.max(np.abs(W1))) if np.size(W1) else 0.0
    defect = np.asarray(W1) - np.asarray(W_k) - 0.5 * dN * (np.asarray(g0) + np.asarray(g1))
    num = float(np.max(np.abs(defect))) if np.size(defect) else 0.0
    if num == 0.0:
        return 0.0
    return num / scale if scale > 0 else math.inf


def _progress_fraction(cycles, vrate, vrate0, wmax, opts: WearOptions) -> float:
    """How far the run is towards its nearest stop criterion, in [0, 1]."""
    fr = [math.log1p(cycles) / math.log1p(opts.max_cycles)]
    if vrate0 > 0 and opts.plateau_rate > 0 and vrate > 0:
        fr.append(math.log(vrate / vrate0) / math.log(opts.plateau_rate))
    if math.isfinite(opts.max_depth):
        fr.append(wmax / opts.max_depth)
    return min(1.0, max(0.0, max(fr)))


def _stop_reason(st: dict, opts: WearOptions) -> str:
    if float(st["vrate0"]) <= 0.0:
        return "no_wear"
    if float(st["cycles"]) >= opts.max_cycles * (1 - 1e-12):
        return "max_cycles"
    if float(np.max(st["W"])) >= opts.max_depth:
        return "max_depth"
    if float(st["vrate"]) <= opts.plateau_rate * float(st["vrate0"]):
        return "plateau"
    if int(st["step"]) >= opts.max_steps:
        return "max_steps"
    return ""


def _message(reason: str, st: dict, opts: WearOptions, extra: str = "") -> str:
    n = float(st["cycles"])
    txt = {
        "max_cycles": f"reached max_cycles = {opts.max_cycles:.4g}",
        "max_depth": f"a wear depth reached max_depth = {opts.max_depth:.4g} m",
        "plateau": (f"plateau: worn-volume rate {float(st['vrate']):.3g} m^3/cycle <= "
                    f"{opts.plateau_rate:g} x initial {float(st['vrate0']):.3g}"),
        "no_wear": "no wear: no contact node slips (worn-volume rate 0)",
        "max_steps": f"reached max_steps = {opts.max_steps}",
        "solver_failed": "stopped: a periodic solve failed even with smaller jumps",
    }[reason]
    return f"{txt} after {int(st['step'])} steps, N = {n:.4g} cycles{extra}"


def simulate_wear(model: Model, basis: FourierBasis, *, omega: float = 2 * np.pi,
                  quasi_static: bool = False, options: WearOptions | None = None,
                  reduced: Reduced | None = None, eps: float | None = None, anchor=None,
                  W0=None, U0=None, checkpoint: Path | str | None = None, resume: bool = False,
                  progress: bool = False, callback: Callable | None = None,
                  time_domain: TimeDomainFallback | None = None) -> WearResult:
    """Integrate fretting wear over the slow time scale (paper Fig. 3, eq. 29-30).

    Parameters
    ----------
    model : the structure (``contact.wear_coefficient`` k_w [1/Pa] for Archard's law).
    basis : Fourier basis of the periodic solutions.
    omega : excitation circular frequency [rad/s] (only scales time when ``quasi_static``).
    quasi_static : drop inertia and damping.
    options : :class:`WearOptions` (defaults: adaptive linearly implicit, tolerance 1e-2).
    reduced : precomputed condensation on ``[0] + basis.harmonics``.
    eps : DLFT penalty [N/m] (default: spectral radius of ``Z_r``).
    anchor : (nc, d-1) stick anchors of the first solve [m] (default: static preload state).
    W0 : (nc,) initial wear [m] (default 0).
    U0 : (nc, d, H) or (m, H) start of the first periodic solve.
    checkpoint : ``.npz`` file for the state (written atomically as the run goes).
    resume : continue from ``checkpoint`` when it exists (same model and options).
    progress : show a tqdm bar (cycles, worn volume, rate, time left).
    callback : ``callback(step, history_row)`` after each accepted step (and after the
        checkpoint is written); raising ``KeyboardInterrupt`` there stops the run as Ctrl-C.
    time_domain : the :class:`~fretwear.hb.fallback.TimeDomainFallback` of the steps whose
        balance fails (``options.time_domain_rescue``, dynamic cases); ``None``: no fallback
        (a failed balance stops the run). :func:`fretwear.simulate_wear` passes
        :data:`fretwear.timedomain.fallback.FALLBACK`.

    Returns
    -------
    :class:`WearResult`.

    Raises
    ------
    ConvergenceError
        The first periodic solve (unworn interface) did not converge and no time-domain start
        is allowed (quasi-static, or ``time_domain_rescue = False``): nothing to integrate.
    KeyboardInterrupt
        On Ctrl-C (the last accepted state is in the checkpoint first).
    """
    opts = (options or WearOptions()).check()
    t_start = time.perf_counter()
    nc, d = model.contact.dofs.shape
    if reduced is None:
        reduced = condense(model, omega, basis.orders, quasi_static=quasi_static)
    coef = wear_coefficients(model, opts.law, opts.energy_coefficient)
    W0 = np.zeros(nc) if W0 is None else np.broadcast_to(np.asarray(W0, float), (nc,)).copy()
    if anchor is None:
        anchor = static_anchor(model)
    anchor = np.array(anchor, float).reshape(nc, d - 1)
    sp = SlowProblem(model, reduced, basis, coef, eps=eps, anchor=anchor,
                     time_domain=time_domain if opts.time_domain_rescue and not quasi_static
                     else None)
    key = fingerprint(model, reduced, basis, sp.eps, coef, opts, W0, anchor)
    ckpt = Path(checkpoint) if checkpoint is not None else None

    state, rows, resumed_from = None, [], -1
    if resume and ckpt is not None and ckpt.is_file():
        state, rows = load_checkpoint(ckpt, key)
        resumed_from = int(state["step"])
    if state is None:
        state, rows = _start(sp, W0, anchor, U0, opts)
    balanced = [r for r in rows if int(r["rescued"]) != 2]
    initial = _assemble(sp, balanced[0]) if balanced else None

    bar = _Bar(progress, opts, model.contact.area)
    last_ckpt = -math.inf
    reason = _stop_reason(state, opts)
    extra = ""
    try:
        bar.show(state)
        while not reason:
            if np.size(state["td_U"]):  # the previous step came from a time integration
                new_state, row, failure = _time_domain_step(sp, state, opts)
            else:
                new_state, row, failure = _advance(sp, state, opts)
                if failure and sp.time_domain is not None:
                    new_state, row, why = _time_domain_step(sp, state, opts)
                    failure = f"{failure}; {why}" if why else ""
            if failure:
                reason, extra = "solver_failed", f": {failure}"
                break
            state = new_state
            rows.append(row)
            bar.show(state)
            if ckpt is not None and (time.perf_counter() - last_ckpt >= opts.checkpoint_every_s):
                save_checkpoint(ckpt, state, rows, key)
                last_ckpt = time.perf_counter()
            if callback is not None:
                callback(int(state["step"]), row)
            reason = _stop_reason(state, opts)
    except KeyboardInterrupt:
        if ckpt is not None:
            save_checkpoint(ckpt, state, rows, key)
        bar.close()
        raise
    bar.close()
    state["stop_reason"] = np.asarray(reason)
    if ckpt is not None:
        save_checkpoint(ckpt, state, rows, key)
    hist = WearHistory.from_rows(rows, reason)
    last = [r for r in rows if int(r["rescued"]) != 2]
    final = _assemble(sp, last[-1]) if last else None
    return WearResult(hist, initial, final, reason, _message(reason, state, opts, extra),
                      reason != "solver_failed", time.perf_counter() - t_start,
                      float(state["stability_jump"]), resumed_from, penalty=sp.eps)


def _assemble(sp: SlowProblem, row: dict) -> PeriodicSolution:
    """The periodic solution of a recorded step (no solve: ``U`` is converged)."""
    U = np.asarray(row["U"], float).reshape(sp.m, sp.H)
    stats = SolveStats(True, 0.0, int(row["newton_iterations"]), 0, 0, float(row["wall_time"]),
                       "recorded", "")
    return sp.solution(U, row["wear_depth"], row["anchor"], stats)


def _start(sp: SlowProblem, W0, anchor, U0, opts: WearOptions) -> tuple[dict, list[dict]]:
    """The balanced initial state (step 0)."""
    t0 = time.perf_counter()
    sp.set_state(W0, anchor)
    # the first balance goes through solve_periodic (its start strategies for a cold start)
    sol0, st = solve_periodic(sp.model, sp.prob.basis, omega=sp.prob.reduced.omega,
                              quasi_static=sp.prob.reduced.quasi_static,
                              reduced=sp.prob.reduced, gap=sp.gap0 + W0, eps=sp.eps,
                              anchor=anchor, U0=U0, solver=opts.solver, tol=opts.tol,
                              max_iter=max(opts.max_iter, 200))
    if sol0 is None or not st.converged:
        if sp.time_domain is not None:
            return _time_domain_start(sp, W0, opts, st, t0)
        raise ConvergenceError(
            f"the periodic solve of the unworn interface did not converge ({st.message}, "
            f"relative residual {st.residual:.3g} > {opts.tol:g}): no wear computed"
        )
    U = sol0.U.reshape(sp.m, sp.H)
    g = sp.rate(U)
    rho = 0.0
    if np.any(g > 0):
        ev = np.linalg.eigvals(sp.slow_jacobian(U))
        rho = float(np.max(np.abs(ev)))
    stab = 2.0 / rho if rho > 0 else math.inf
    if opts.initial_jump is not None:
        jump = float(opts.initial_jump)
    elif opts.adaptive:
        jump = opts.tolerance * stab if math.isfinite(stab) else 1.0
    else:
        jump = 0.5 * stab if math.isfinite(stab) else 1.0
    sol = sp.solution(U, W0, anchor, st)
    row = _row(sol, W0, g, 0.0, 0.0, st.iterations, 0, 0.0, time.perf_counter() - t0)
    state = {
        "step": 0, "cycles": 0.0, "W": np.array(W0, float), "U": U.copy(),
        "anchor": np.array(anchor, float), "g": g, "jump": float(jump),
        "vrate": row["volume_rate"], "vrate0": row["volume_rate"],
        "stability_jump": float(stab), "stop_reason": np.asarray(""),
        "td_U": np.zeros(0), "td_V": np.zeros(0), "td_retry_at": 0.0, "Js": np.zeros(0),
    }
    return state, [row]


def _time_domain_start(sp: SlowProblem, W0, opts: WearOptions, st: SolveStats, t0: float):
    """Step 0 from a time integration when the unworn interface has no periodic balance
    (dynamic cases; e.g. a subharmonic or quasi-periodic response): the structure is integrated
    from rest for ``START_SETTLE`` periods, then its wear rate is averaged as in
    :func:`_time_domain_step`, and the run goes on with time-domain steps (which go back to the
    DLFT as soon as a balance converges). The first jump is ``initial_jump``, default
    ``START_JUMP`` cycles (no slow Jacobian without a balance; the error control adapts it)."""
    tr = sp.time_domain.averaged_rate(sp.model, sp.prob.reduced.omega, sp.prob.basis, sp.coef, W0,
                            U0=None, V0=None,
                            settle=max(opts.time_domain_settle, START_SETTLE),
                            average=opts.time_domain_average,
                            steps_per_period=opts.time_domain_steps)
    row = _time_row(tr, sp.model.contact.area, W0, 0.0, 0.0, st.iterations, 1, 0.0,
                    time.perf_counter() - t0)
    jump = float(opts.initial_jump) if opts.initial_jump is not None else START_JUMP
    state = {
        "step": 0, "cycles": 0.0, "W": np.array(W0, float),
        "U": tr.U.reshape(sp.m, sp.H).copy(), "anchor": np.array(tr.anchor, float), "g": tr.g,
        "jump": jump, "vrate": row["volume_rate"], "vrate0": row["volume_rate"],
        "stability_jump": math.nan, "stop_reason": np.asarray(""), "td_U": tr.U_end,
        "td_V": tr.V_end, "td_retry_at": 0.0, "Js": np.zeros(0),
    }
    return state, [row]


def _advance(sp: SlowProblem, st: dict, opts: WearOptions):
    """One accepted slow step from state ``st``: ``(new_state, row, failure_message)``.

    Retries a failed solve with the jump divided by 4 (up to ``max_retries`` times, not below
    ``min_jump``); with ``adaptive``, rejects a step whose error estimate exceeds the
    tolerance and retries with the jump the controller proposes.
    """
    t0 = time.perf_counter()
    W_k, U_k, g_k = st["W"], st["U"], st["g"]
    anchor = U_k.reshape(sp.nc, sp.d, sp.H)[:, 1:, 0].copy()  # history rule: previous mean
    dN = min(float(st["jump"]), opts.max_jump, opts.max_cycles - float(st["cycles"]))
    floor = max(opts.min_jump, MIN_JUMP_FRACTION * float(st["cycles"]))  # error control
    rescue = sp.time_domain is not None
    # failed solves: with a time-domain rescue behind, stop cutting where the rescue starts
    fail_floor = max(floor, RESCUE_START_FRACTION * float(st["cycles"])) if rescue else floor
    iters = rejected = failures = 0
    lin = None
    if opts.scheme != "explicit":
        sp.set_state(W_k, anchor)
        lin = sp.slow_jacobian(U_k, with_dUdW=True)  # Js, dU/dW at the start of the step
        iters += 1
        # a growing mode (eigenvalue lam > 0: wear moving load onto a neighbour) is only
        # followed accurately with dN lam small, and I - dN Js is singular at dN lam = 1
        lam_plus = float(np.max(np.linalg.eigvals(lin[0]).real))
        if lam_plus > 0:
            dN = min(dN, GROWTH_LIMIT / lam_plus)
    while True:
        W1, U1, stats = _attempt(sp, opts, W_k, U_k, g_k, anchor, dN, lin)
        iters += stats.iterations
        if not stats.converged:
            failures += 1
            rejected += 1
            if failures > opts.max_retries or dN <= fail_floor:
                return None, None, (f"{stats.message} at N = {float(st['cycles']):.4g} with a "
                                    f"jump of {dN:.3g} cycles after {failures} attempts")
            dN = max(dN / 4.0, fail_floor)
            continue
        sp.set_state(W1, anchor)
        g1 = sp.rate(U1)
        err = _error(dN, W1, W_k, g1, g_k)
        if opts.adaptive and err > opts.tolerance and dN > floor:
            rejected += 1
            dN = max(dN * max(0.1, 0.9 * math.sqrt(opts.tolerance / err)), floor)
            continue
        break
    # no growth right after a failed solve (stiff ODE practice)
    jump = _next_jump(dN, err, opts, float(st["jump"]), 1.0 if failures else 5.0)
    sol = sp.solution(U1, W1, anchor, stats)
    cycles = float(st["cycles"]) + dN
    row = _row(sol, W1, g1, cycles, dN, iters, rejected, err, time.perf_counter() - t0)
    new = dict(st)
    new.update({"step": int(st["step"]) + 1, "cycles": cycles, "W": np.array(W1, float),
                "U": U1.copy(), "anchor": anchor, "g": g1, "jump": float(jump),
                "vrate": row["volume_rate"]})
    return new, row, ""


def _attempt(sp: SlowProblem, opts: WearOptions, W_k, U_k, g_k, anchor, dN, lin):
    """One try of a slow step of ``dN`` cycles: ``(W1, U1, stats)``.

    explicit (eq. 30): ``W1 = W_k + dN g_k``, then the balance at ``W1``;
    rosenbrock: ``W1 = W_k + dN (I - dN Js)^-1 g_k``, then the balance at ``W1``;
    implicit: backward Euler from the Rosenbrock predictor (:func:`_backward_euler`, or the
    Newton method on the coupled unknowns ``(U~, W1)`` when ``implicit_newton = "coupled"``).
    """
    kw = {"solver": opts.solver, "tol": opts.tol, "max_iter": opts.max_iter}
    if opts.scheme == "explicit":
        W1 = W_k + dN * g_k
        U1, stats = sp.solve_balance(W1, anchor, sp.shift_guess(U_k, W1 - W_k), **kw)
        return W1, U1, stats
    Js, dUdW = lin
    dW = dN * np.linalg.solve(np.eye(sp.nc) - dN * Js, g_k)
    dW = np.maximum(dW, 0.0)  # a node's wear never decreases (g >= 0)
    Wp = W_k + dW
    Up = U_k + (dUdW @ dW).reshape(sp.m, sp.H)
    if opts.scheme == "rosenbrock":
        U1, stats = sp.solve_balance(Wp, anchor, Up, **kw)
        if not stats.converged:
            its = stats.iterations
            U1, stats = sp.solve_balance(Wp, anchor, sp.shift_guess(U_k, dW), **kw)
            stats.iterations += its
        return Wp, U1, stats
    if opts.implicit_newton == "coupled":
        kw["max_iter"] = opts.max_iter_coupled
        U1, W1, stats = sp.solve_implicit(W_k, dN, anchor, Up, Wp, **kw)
        return W1, U1, stats
    return _backward_euler(sp, opts, W_k, U_k, dN, anchor, Up, Wp, Js, dUdW)


def _backward_euler(sp: SlowProblem, opts: WearOptions, W_k, U_start, dN, anchor, U, W, Js,
                    dUdW):
    """Backward Euler ``W1 = W_k + dN g(W1)`` by a damped Newton method on ``W``.

    Every iterate is a converged periodic balance at its ``W`` (the ordinary DLFT solve,
    warm-started), so no unbalanced state is ever returned. The BE defect
    ``r = W - W_k - dN g(W)`` is reduced with the iteration matrix ``I - dN Js``: frozen while
    the defect contracts well, refreshed at the current iterate otherwise, with backtracking
    when a full step does not decrease ``max|r|``. It stops when
    ``max|r| <= 0.1 tolerance max W`` (the algebraic error an order below the local error
    allowed, as in stiff ODE codes). ``g`` is only piecewise smooth (contact states switch),
    and the iteration can stall at a kink: the best iterate is then returned if
    ``max|r| <= 0.5 tolerance max W``. The step's error estimate (:func:`_error`) contains
    ``r``, so the error test judges such a step.

    Returns ``(W1, U1, stats)``; ``stats.converged`` is False when the balance or the
    iteration fails.
    """
    t0 = time.perf_counter()
    kw = {"solver": opts.solver, "tol": opts.tol, "max_iter": opts.max_iter}
    its = 0
    msg = "backward Euler iteration did not converge"

    def evaluate(W, U):
        nonlocal its
        U1, st = sp.solve_balance(W, anchor, U, **kw)
        its += st.iterations
        if not st.converged:  # retry from the previous balance, shifted by the wear change
            U1, st = sp.solve_balance(W, anchor, sp.shift_guess(U_start, W - W_k), **kw)
            its += st.iterations
        if not st.converged:
            return None
        U = U1
        r = W - W_k - dN * sp.rate(U)
        return U, r, float(np.max(np.abs(r))), st.residual

    ev = evaluate(W, U)
    if ev is None:
        return W, U, SolveStats(False, math.inf, its, 0, 0, time.perf_counter() - t0,
                                "balance failed at the predictor", opts.solver)
    U, r, rn, res = ev
    best = (rn, W, U, res)
    M = np.eye(sp.nc) - dN * Js
    fresh = True
    for _k in range(opts.max_iter_implicit):
        if rn <= 0.1 * opts.tolerance * max(float(np.max(W)), 1e-300):
            break
        dW = -np.linalg.solve(M, r)
        t, accepted = 1.0, False
        for _ls in range(4):
            W_try = np.maximum(W + t * dW, W_k)  # BE keeps W1 >= W_k since g >= 0
            ev = evaluate(W_try, U + (dUdW @ (W_try - W)).reshape(sp.m, sp.H))
            if ev is not None and ev[2] < (1.0 - 1e-4 * t) * rn:
                accepted = True
                break
            t *= 0.5
        if not accepted:
            if fresh:
                msg = "backward Euler iteration stalled (no decrease of the defect)"
                break
            Js, dUdW = sp.slow_jacobian(U, with_dUdW=True)  # retry with a fresh Jacobian
            its += 1
            M = np.eye(sp.nc) - dN * Js
            fresh = True
            continue
        contraction = ev[2] / rn
        W, (U, r, rn, res) = W_try, ev
        if rn < best[0]:
            best = (rn, W, U, res)
        if contraction > 0.5:  # poor contraction: Jacobian at the new iterate
            Js, dUdW = sp.slow_jacobian(U, with_dUdW=True)
            its += 1
            M = np.eye(sp.nc) - dN * Js
            fresh = True
        else:
            fresh = False
    rn, W, U, res = best
    if rn <= 0.5 * opts.tolerance * max(float(np.max(W)), 1e-300):
        return W, U, SolveStats(True, res, its, 0, 0, time.perf_counter() - t0, "converged",
                                opts.solver)
    return W, U, SolveStats(False, math.inf, its, 0, 0, time.perf_counter() - t0, msg,
                            opts.solver)


def _time_domain_step(sp: SlowProblem, st: dict, opts: WearOptions):
    """A slow step taken from a time integration: ``(state, row, failure)``.

    Used where the periodic balance fails (dynamic cases). The wear is advanced from the rate at
    the start of the step: by explicit Euler (eq. 30), ``W1 = W_k + dN g_k``, with
    ``scheme = "explicit"``; otherwise by the linearly implicit predictor
    ``W1 = W_k + dN (I - dN Js+)^-1 g_k`` with ``Js+`` the slow Jacobian of the last balanced
    state (no balance, no fresher one) without its growing modes (:func:`without_growth`; a
    W-method: first order with any matrix). The stiff part of ``Js`` is local (wear unloads the
    node that slips) and changes little, and without it the jumps stay at the explicit
    stability limit with rates that flip from step to step. Then the
    structure is integrated in time at ``W1``
    (:func:`fretwear.timedomain.averaged_rate.time_averaged_rate`),
    continuing the previous time integration when there is one (so that the transient and the
    slow drift of the mean position carry over), else from the last periodic solution. The rate
    at ``W1`` is the mean of Archard's integrand over ``time_domain_average`` periods; the
    error test compares it with ``g_k`` as for every step (:func:`_error`), and a rejected jump
    is retried smaller.

    Unless the integrated response is clearly not periodic (subharmonic, quasi-periodic,
    irregular), the balance at ``W1`` is tried from the harmonics of its last period
    with its mean tangential positions as stick anchors (the history selects where nodes that
    stop slipping stick): if it converges and passes the error test the step is an ordinary
    balanced step (``rescued = 1``) and the next step goes back to the DLFT. Otherwise the step
    keeps the time-averaged rate (``rescued = 2``), and so do the next steps until the balance
    converges again. A balance that failed is not retried before the cycle count has doubled
    (each try costs up to hundreds of iterations).
    """
    t0 = time.perf_counter()
    W_k, g_k, cycles = st["W"], st["g"], float(st["cycles"])
    if np.size(st["td_U"]):
        U0, V0 = st["td_U"], st["td_V"]
    else:
        last = sp.solution(st["U"], W_k, st["anchor"], SolveStats(True, 0.0, 0, 0, 0, 0.0, "", ""))
        U0, V0 = initial_state(sp.model, last)
    dN = min(float(st["jump"]), opts.max_jump, opts.max_cycles - cycles)
    floor = max(opts.min_jump, MIN_JUMP_FRACTION * cycles)
    rejected = iters = 0
    Js = np.asarray(st["Js"], float)
    if opts.scheme != "explicit" and Js.size == 0 and not np.size(st["td_U"]):
        sp.set_state(W_k, st["anchor"])  # the last balanced state: its slow Jacobian
        Js = sp.slow_jacobian(st["U"])
        iters += 1
    if Js.size:
        # Js is the Jacobian of an older (balanced) state: its growing modes are not those of
        # the current wear and must not cap the jump. Without them the predictor is explicit
        # Euler along those modes and linearly implicit along the others (a W-method).
        Js = without_growth(Js)
    while True:
        if Js.size:  # linearly implicit (the scheme's predictor) with that Jacobian
            W1 = W_k + np.maximum(dN * np.linalg.solve(np.eye(sp.nc) - dN * Js, g_k), 0.0)
        else:
            W1 = W_k + dN * g_k
        try:
            tr = sp.time_domain.averaged_rate(sp.model, sp.prob.reduced.omega, sp.prob.basis,
            sp.coef,
                                    W1, U0=U0, V0=V0, settle=opts.time_domain_settle,
                                    average=opts.time_domain_average,
                                    steps_per_period=opts.time_domain_steps)
        except ConvergenceError as exc:
            return None, None, f"time integration at N + {dN:.3g}: {exc}"
        err = _error(dN, W1, W_k, tr.g, g_k)
        if opts.adaptive and err > opts.tolerance and dN > floor:
            rejected += 1
            dN = max(dN * max(0.1, 0.9 * math.sqrt(opts.tolerance / err)), floor)
            continue
        break
    cycles1 = cycles + dN
    new = dict(st)
    new.update({"step": int(st["step"]) + 1, "cycles": cycles1, "W": np.array(W1, float)})
    if tr.kind in BALANCE_KINDS and cycles1 >= float(st["td_retry_at"]):
        U1, stats = sp.solve_balance(W1, tr.anchor, tr.U.reshape(sp.m, sp.H),
                                     solver=opts.solver, tol=opts.tol,
                                     max_iter=max(opts.max_iter, RESCUE_MAX_ITER))
        iters += stats.iterations
        if stats.converged:
            sp.set_state(W1, tr.anchor)
            g1 = sp.rate(U1)
            err_b = _error(dN, W1, W_k, g1, g_k)
            if not opts.adaptive or err_b <= opts.tolerance:
                sol = sp.solution(U1, W1, tr.anchor, stats)
                row = _row(sol, W1, g1, cycles1, dN, iters, rejected, err_b,
                           time.perf_counter() - t0)
                row.update({"rescued": 1, "response": tr.kind_code})
                new.update({"U": U1.copy(), "anchor": np.array(tr.anchor, float), "g": g1,
                            "jump": _next_jump(dN, err_b, opts, float(st["jump"]), 1.0),
                            "vrate": row["volume_rate"], "td_U": np.zeros(0),
                            "td_V": np.zeros(0), "td_retry_at": 0.0, "Js": np.zeros(0)})
                return new, row, ""
        new["td_retry_at"] = 2.0 * cycles1
    row = _time_row(tr, sp.model.contact.area, W1, cycles1, dN, iters, rejected, err,
                    time.perf_counter() - t0)
    new.update({"U": tr.U.reshape(sp.m, sp.H).copy(), "anchor": np.array(tr.anchor, float),
                "g": tr.g, "jump": _next_jump(dN, err, opts, float(st["jump"])),
                "vrate": row["volume_rate"],
                "td_U": tr.U_end, "td_V": tr.V_end, "Js": Js})
    return new, row, ""


def without_growth(Js: np.ndarray, max_condition: float = 1e8) -> np.ndarray:
    """``Js`` with the real part of every eigenvalue ``mu`` with ``Re mu > 0`` set to zero,
    eigenvectors unchanged: ``Js - V diag(max(Re mu, 0)) V^-1`` (real: conjugate pairs get
    the same shift).

    Used as the matrix of the linearly implicit predictor of time-domain steps (an old slow
    Jacobian): along a growing mode the step is then explicit Euler, along every other mode it
    is the linearly implicit step with the mode's own eigenvalue, so neutral and decaying
    modes keep their accuracy and ``I - dN Js+`` is never singular. Where the eigenvectors are
    too ill-conditioned for the projection (``cond V > max_condition``) the whole matrix is
    shifted by the largest growth rate instead (stable, but it damps every mode by
    ``1 / (1 + dN lam_+)``: a first-order error that the error test sees).
    """
    Js = np.asarray(Js, float)
    mu, V = np.linalg.eig(Js)
    shift = np.maximum(mu.real, 0.0)
    if not np.any(shift > 0):
        return Js
    if np.linalg.cond(V) > max_condition:
        return Js - float(shift.max()) * np.eye(Js.shape[0])
    return (Js - (V * shift) @ np.linalg.inv(V)).real


def _time_row(tr, area, W, cycles, jump, iters, rejected, err, wall) -> dict:
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


def _next_jump(dN: float, err: float, opts: WearOptions, fixed: float,
               grow_limit: float = 5.0) -> float:
    """The jump proposed after an accepted step of ``dN`` cycles with error estimate ``err``
    (``fixed``, the jump in force, without ``adaptive``)."""
    if not opts.adaptive:
        return fixed
    grow = 5.0 if err == 0.0 else min(5.0, max(0.2, 0.9 * math.sqrt(opts.tolerance / err)))
    return dN * min(grow, grow_limit)


class _Bar:
    """tqdm progress towards the nearest stop criterion, with cycles, worn volume and rate."""

    def __init__(self, enabled: bool, opts: WearOptions, area):
        self.opts = opts
        self.area = np.asarray(area, float)
        self.bar = None
        if enabled:
            from tqdm import tqdm

            self.bar = tqdm(total=1000, desc="wear", unit="", leave=False,
                            bar_format="{desc}: {percentage:3.0f}%|{bar}| {postfix} "
                            "[{elapsed}<{remaining}]")

    def show(self, st: dict):
        if self.bar is None:
            return
        frac = _progress_fraction(float(st["cycles"]), float(st["vrate"]), float(st["vrate0"]),
                                  float(np.max(st["W"])), self.opts)
        self.bar.n = max(self.bar.n, int(1000 * frac))
        vol = worn_volume(st["W"], self.area)
        self.bar.set_postfix_str(f"N={float(st['cycles']):.3g} cycles, worn {vol:.3g} m^3, "
                                 f"rate {float(st['vrate']):.3g} m^3/cycle, "
                                 f"step {int(st['step'])}", refresh=False)
        self.bar.refresh()

    def close(self):
        if self.bar is not None:
            self.bar.close()


# --------------------------------------------------------------------------------------------
# FRF of a worn interface (paper Fig. 24)
# --------------------------------------------------------------------------------------------
def frf_worn(model: Model, wear, frequencies_hz, basis: FourierBasis, *, anchor=None,
             point: str | None = None, solver: str = "powell", spacing: str = "linear",
             **kwargs):
    """Nonlinear FRF with the worn gap ``gap + wear`` (paper Fig. 24).

    Parameters
    ----------
    model : the structure; wear : (nc,) wear depths [m] (e.g. ``result.final_wear``, or 0).
    frequencies_hz : ``(f_min, f_max, n_points)`` [Hz].
    basis : Fourier basis.
    anchor : stick anchors of the first point (default: static preload).
    point : unused here (kept for the documented signature); read amplitudes with
        ``SweepResult.amplitude(point, axis)``.
    solver, spacing, **kwargs : passed to :func:`fretwear.hb.sweep.sweep`.

    Returns
    -------
    :class:`fretwear.hb.sweep.SweepResult`.
    """
    from fretwear.hb.sweep import sweep

    f_min, f_max, n_points = frequencies_hz
    gap = np.broadcast_to(np.asarray(model.contact.gap, float), (model.contact.n_nodes,))
    gap = gap + np.asarray(wear, float)
    return sweep(model, basis, float(f_min), float(f_max), int(n_points), spacing=spacing,
                 gap=gap, anchor=anchor, solver=solver, **kwargs)


__all__ = [
    "HISTORY_FIELDS", "LAWS", "SCHEMES", "STOP_REASONS", "SlowProblem", "WearHistory",
    "WearOptions", "WearResult", "frf_worn", "load_checkpoint", "read_history",
    "save_checkpoint", "simulate_wear", "wear_coefficients", "wear_per_cycle", "without_growth",
    "worn_volume",
]
