"""The result of a periodic solve: :class:`PeriodicSolution` (harmonics, time histories,
contact states, observed points, solver statistics), the record of one attempt
(:class:`Attempt`), the post-processing of converged harmonics (:func:`assemble_solution`) and
the full-field state at ``t = 0`` (:func:`initial_state`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from fretwear.hb import contact as law
from fretwear.hb.connectors import Connected, node_displacements
from fretwear.hb.fourier import FourierBasis, amplitude
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.reduce import _recover
from fretwear.hb.solvers import SolveStats
from fretwear.model.core import Model


@dataclass
class PeriodicSolution:
    """A periodic solution of the DLFT balance at one frequency (the result of
    :func:`solve_periodic`).

    ``success`` says whether the balance converged and ``message`` why the solver stopped (as
    :class:`scipy.optimize.OptimizeResult`); a solution with ``success`` False is the last
    iterate of a failed solve, assembled so that it can be inspected, and is never a result.
    All contact quantities are in contact-local frames ``[N, T1, (T2)]``; forces are those the
    structure exerts on the obstacle (``N`` >= 0 in compression).

    Attributes
    ----------
    success : the convergence test ``|f| <= tol |Z_r U|`` was met (``stats.success``).
    message : why the solver stopped (``stats.message``).
    frequency : excitation frequency [Hz] (as given to :func:`solve_periodic`).
    omega : circular frequency ``2 pi frequency`` [rad/s] (0 for quasi-static).
    quasi_static : inertia and damping dropped.
    basis : the Fourier basis.
    U : (nc, d, H) displacement harmonics of the contact nodes [m].
    lam : (nc, d, H) contact force harmonics [N].
    X : (nc, d, H) corrected displacement harmonics [m] (satisfy the contact law).
    lam_t : (nc, d, N) contact forces in time [N].
    x_t : (nc, d, N) corrected displacements in time [m].
    state : (nc, N) int8: 0 separation, 1 stick, 2 slip.
    gap : (nc,) gap + wear ``W`` used [m].
    anchor : (nc, d-1) stick anchors used [m].
    eps : DLFT penalty [N/m].
    observed : name -> (d, H) displacement harmonics of observed points [m].
    area : (nc,) tributary areas [m^2].
    stats : solver statistics (:class:`~fretwear.hb.solvers.SolveStats`).
    flags : reasons for caution (e.g. time-domain findings of a sweep's stability check).
    U_node : (nc, d, H) displacement harmonics of the structure's contact nodes [m] when the
        interface has contact springs (``U`` is then the contact points'); None otherwise.
    attempts : the attempts of the solve strategy, in order (:class:`Attempt`; the last one
        gave this solution).
    time_domain : what a time integration found where the balance failed (``"time-start"``
        of :func:`solve_periodic`; e.g. "quasi-periodic ...: no periodic steady state"), ``""``
        when none ran.
    warnings : reasons for caution about the inputs of the solve, one line each (e.g. the
        static preload solve that gives the default stick anchors did not converge).
    fallback_seconds : wall time [s] of the attempts after the first one
        (:mod:`fretwear.hb.fallbacks`).
    """

    frequency: float
    omega: float
    quasi_static: bool
    basis: FourierBasis
    U: np.ndarray
    lam: np.ndarray
    X: np.ndarray
    lam_t: np.ndarray
    x_t: np.ndarray
    state: np.ndarray
    gap: np.ndarray
    anchor: np.ndarray
    eps: float
    observed: dict
    area: np.ndarray
    coords: np.ndarray
    stats: SolveStats
    flags: list = field(default_factory=list)
    U_node: np.ndarray | None = None
    attempts: list = field(default_factory=list)
    time_domain: str = ""
    warnings: list = field(default_factory=list)
    fallback_seconds: float = 0.0

    @property
    def success(self) -> bool:
        """The balance converged (``stats.success``)."""
        return bool(self.stats.success)

    @property
    def message(self) -> str:
        """Why the solver stopped (``stats.message``)."""
        return self.stats.message

    @property
    def tau(self):
        return self.basis.tau

    @property
    def time(self):
        """Sample times over one period [s] (angles ``tau`` when quasi-static)."""
        return self.tau / self.omega if self.omega > 0 else self.tau

    # -- interface quantities ----------------------------------------------------------------
    def pressure_t(self):
        """Normal contact pressure per node and instant (nc, N) [Pa]."""
        return self.lam_t[:, 0, :] / self.area[:, None]

    def pressure_stats(self):
        """Pressure per node: ``(mean, max, amplitude of harmonic 1..)`` [Pa]."""
        p = self.pressure_t()
        return p.mean(axis=1), p.max(axis=1), 0.5 * (p.max(axis=1) - p.min(axis=1))

    def slip_t(self):
        """Corrected slip increments per node and instant (nc, N) [m]."""
        return law.slip_increments(self.x_t, self.state)

    def slip_stats(self):
        """Per node: total slip path per period [m], peak-to-peak tangential displacement
        amplitude (half range) [m] and mean tangential position [m] (first tangent)."""
        xt = self.x_t[:, 1, :]
        return self.slip_t().sum(axis=1), 0.5 * (xt.max(axis=1) - xt.min(axis=1)), xt.mean(1)

    def friction_energy(self):
        """Energy dissipated by friction per period and node (nc,) [J]."""
        return law.friction_work(self.lam_t, self.x_t, self.state)

    def state_fractions(self):
        """Fraction of the period in separation, stick, slip per node (nc, 3)."""
        return np.stack([(self.state == s).mean(axis=1) for s in range(3)], axis=1)

    # -- observed points --------------------------------------------------------------------
    def observed_time(self, name):
        """Displacement (d, N) [m] and velocity (d, N) [m/s] of an observed point over a period."""
        c = self.observed[name]
        u = self.basis.to_time(c)
        v = self.basis.to_time(c @ self.basis.derivative_matrix(max(self.omega, 0.0)).T)
        return u, v

    def observed_amplitude(self, name):
        """Amplitude per kept harmonic (d, k) [m]."""
        return amplitude(self.observed[name], self.basis)

    def stops_per_period(self, name, axis=0, rel_tol=5e-2):
        """How many times per period the point stops along ``axis``: the paper's "P_e stops
        twice per period at 10 kHz and four times at 79 kHz" (section 4.2.3).

        A stop is an instant where the velocity vanishes: a sign change of the velocity (a
        turning point) or an interval where ``|v|`` stays below ``rel_tol`` times its peak
        (a dwell, with or without reversal). A harmonic motion stops twice per period. The
        velocity is that of the kept harmonics, so a dwell of the true motion shows as a ripple
        around zero (Gibbs: up to ~9 % of the velocity jump): hence the default ``rel_tol`` of
        5 %. On the paper's beam at 79 kHz (7 harmonics) the count is 6, 5, 4 for ``rel_tol`` =
        0.1 %, 2 %, 5 %; at 10 kHz it is 2 for all of them.
        """
        _, v = self.observed_time(name)
        va = v[axis]
        peak = max(np.abs(va).max(), 1e-300)
        sgn = np.where(np.abs(va) <= rel_tol * peak, 0, np.sign(va)).astype(int)
        if not sgn.any():
            return 0
        # rotate so that the sequence starts on a moving sample, then walk the circle
        start = int(np.flatnonzero(sgn)[0])
        seq = np.roll(sgn, -start)
        stops = 0
        prev = seq[0]
        in_dwell = False
        for s_ in seq[1:].tolist() + [seq[0]]:
            if s_ == 0:
                if not in_dwell:
                    stops += 1
                    in_dwell = True
                continue
            if not in_dwell and s_ != prev:
                stops += 1  # direct sign change between two samples
            in_dwell = False
            prev = s_
        return stops


@dataclass
class Attempt:
    """One attempt of a periodic solve (a rung of :mod:`fretwear.hb.attempts`).

    method : what was tried: ``"start"`` (the solver from the given start), ``"best-point"``
        (the other solver from the best iterate so far), ``"eps-continuation"`` (converged at
        another penalty, then stepped back to the target one: the answer is at the target
        eps), ``"harmonic-continuation"`` (the first harmonic alone, then all of them),
        ``"time-start"`` (from a time integration), and for sweeps ``"grid"``, ``"substep"``,
        ``"retry"``, ``"arclength"``, ``"jump"`` (from a fold the arclength turned back at),
        ``"fresh-start"`` (the first harmonic alone with the static anchors, then ``"start"``
        and ``"eps-continuation"`` with a single solve's
        iterations).
    solver : the nonlinear solver; eps : the penalty of the answer [N/m]; success, residual
    (relative), iterations, wall_time [s], message : as :class:`~fretwear.hb.solvers.SolveStats`.
    from_hz : for a ``"jump"``, the frequency of the fold it left [Hz]; None otherwise.
    """

    method: str
    solver: str
    eps: float
    success: bool
    residual: float
    iterations: int
    wall_time: float
    message: str
    from_hz: float | None = None

    @classmethod
    def of(cls, method: str, eps: float, st: SolveStats, message: str | None = None,
           from_hz: float | None = None):
        return cls(method, st.solver, float(eps), bool(st.success), float(st.residual),
                   int(st.iterations), float(st.wall_time),
                   st.message if message is None else message,
                   None if from_hz is None else float(from_hz))


def assemble_solution(prob: DLFTProblem, U, model: Model, stats: SolveStats) -> PeriodicSolution:
    """Post-process ``U`` (m, H) into a :class:`PeriodicSolution` (converged or not: its
    ``success`` is ``stats.success``)."""
    lu, lx, state, _ = prob.time_law(U)
    lam_t = lu - lx
    x_t = lx / prob.eps
    b = prob.basis
    nc, d, H = prob.nc, prob.d, prob.H
    both = prob.to_freq(np.concatenate([lam_t, lx]).reshape(2 * prob.m, -1))
    lam = both[: prob.m].reshape(nc, d, H)
    X = both[prob.m :].reshape(nc, d, H) / prob.eps
    X[:, 0, 0] += prob.gap  # X~ = U~ - W~ at convergence; report positions
    x_t[:, 0, :] += prob.gap[:, None]
    red = prob.reduced
    observed = {}
    U_node = None
    Uc = b.to_complex(U)  # (k+1, m) complex
    if isinstance(red, Connected):
        U_node = b.from_complex(node_displacements(red, Uc)).reshape(nc, d, H)
    if red.obs_dofs.size:
        Uo = (red.obs_A @ Uc[:, :, None])[:, :, 0] + red.obs_b
        real = b.from_complex(Uo)  # (no, H)
        i = 0
        for p in model.observed:
            nd = len(p.dofs)
            observed[p.name] = real[i : i + nd]
            i += nd
    sol = PeriodicSolution(
        frequency=red.frequency, omega=red.omega, quasi_static=red.quasi_static, basis=b,
        U=U.reshape(nc, d, H).copy(),
        lam=lam, X=X, lam_t=lam_t, x_t=x_t, state=state, gap=prob.gap.copy(),
        anchor=prob.anchor.copy(), eps=prob.eps, observed=observed,
        area=np.asarray(model.contact.area, float), coords=np.asarray(model.contact.coords),
        stats=stats, U_node=U_node,
    )
    bad = non_finite(sol)
    if bad and stats.success:  # never a converged solution that holds NaN or inf
        stats.success = False
        stats.message = f"the solution holds non-finite values (NaN or inf) in {bad}"
    return sol


#: the arrays of a :class:`PeriodicSolution` that must be finite, with what they hold
FINITE_ARRAYS = {"U": "U (the contact displacement harmonics)",
                 "lam": "lam (the contact force harmonics)",
                 "X": "X (the corrected displacement harmonics)",
                 "lam_t": "lam_t (the contact forces in time)",
                 "x_t": "x_t (the corrected displacements in time)"}


def non_finite(sol: PeriodicSolution) -> str:
    """What of ``sol`` holds NaN or inf (the arrays of :data:`FINITE_ARRAYS`, then the
    observed points), ``""`` when all is finite."""
    for name, what in FINITE_ARRAYS.items():
        if not np.all(np.isfinite(getattr(sol, name))):
            return what
    for name, values in sol.observed.items():
        if not np.all(np.isfinite(values)):
            return f"the displacement of the observed point {name!r}"
    return ""


def initial_state(model: Model, sol: PeriodicSolution, condenser=None):
    """Full-field displacement [m] and velocity [m/s] at ``t = 0`` of a periodic solution
    (the exact recovery of the condensation, eq. 19; ``condenser``: the model's, as the solve
    had it, None a new exact one)."""
    b = sol.basis
    m = sol.U.shape[0] * sol.U.shape[1]
    U = sol.U if sol.U_node is None else sol.U_node  # the structure's contact nodes
    Uc = b.to_complex(U.reshape(m, -1))  # (k+1, m) complex amplitudes
    orders = np.array([0, *b.harmonics])
    Ufull = _recover(model, sol.omega, orders, Uc, quasi_static=sol.quasi_static,
                     condenser=condenser)
    U0 = Ufull.real.sum(axis=0)
    V0 = -(orders[:, None] * sol.omega * Ufull.imag).sum(axis=0)
    return U0, V0
