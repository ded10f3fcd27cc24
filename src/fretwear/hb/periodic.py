"""DLFT harmonic balance: residual, Jacobian and the periodic solve (paper eq. 19-28).

Unknowns are the real Fourier coefficients ``U~`` of the contact-local displacements
(``m = n_contact * d`` DOFs, ``H = 1 + 2k`` coefficients each), stored *DOF-major* as an
``(m, H)`` array. The residual is (eq. 22)

    f(U~) = eps (U~ - W~ - X~),         X~ = lambda_x~ / eps,

with ``lambda_x`` from the time-domain law of :mod:`fretwear.hb.contact` applied to
``lambda_u = F~ - Z U~ + eps (U~ - W~)`` (eq. 23). ``W~`` holds gap + wear on the normal DOFs
(static term). The Jacobian is ``J = eps I - G (eps I - Z)`` with ``G = d lambda_x~/d lambda_u~``
block-diagonal per node.
"""

from __future__ import annotations

import dataclasses
import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from fretwear.errors import InputError
from fretwear.hb import contact as law
from fretwear.hb import small
from fretwear.hb.connectors import Connected, connect, node_displacements, springs
from fretwear.hb.fallback import TimeDomainFallback
from fretwear.hb.fourier import FourierBasis, amplitude
from fretwear.hb.krylov import HarmonicBlocks, KrylovJacobian
from fretwear.hb.penalty import penalty
from fretwear.hb.reduce import (
    Reduced,
    _recover,
    condense,
    exact_condenser,
    loads_to_real,
    to_real_blocks,
)
from fretwear.hb.solvers import SolveStats, solve, vector_norm
from fretwear.limits import check_range
from fretwear.model.core import ContactInterface, Model

#: how the Newton step is computed: ``"dense"`` (LAPACK LU of the formed Jacobian),
#: ``"krylov"`` (GMRES on the Jacobian as an operator, :mod:`fretwear.hb.krylov`), ``"auto"``
JACOBIANS = ("auto", "dense", "krylov")
#: ``"auto"`` forms the Jacobian up to this many unknowns ``m H`` (docs/theory.md, "Large
#: interfaces": measured crossover, benchmarks/scale_3d.py)
DENSE_JACOBIAN_MAX = 3000
#: relative residual and iteration limit of the static contact problem under the preload
#: (:func:`preload_anchor`, :func:`preload_contact`)
STATIC_TOL = 1e-10
STATIC_MAX_ITER = 100


class DLFTProblem:
    """Residual and Jacobian of the DLFT balance for one reduced model (one frequency).

    Parameters
    ----------
    reduced : :class:`~fretwear.hb.reduce.Reduced` on the orders ``[0] + basis.harmonics``.
    contact : the contact record (friction coefficient per node: ``contact.mu_nodes()``).
    basis : Fourier basis.
    gap : (nc,) normal gap + wear ``W`` [m].
    eps : DLFT penalty: ``"auto"`` (default) the spectral radius of ``Z_r`` (paper, section
        3.2), ``"static"`` that of the static ``K_r``, or a positive number [N/m]
        (:func:`fretwear.hb.penalty.penalty`).
    anchor : (nc, d-1) stick anchors: where a node that sticks all period sticks [m]
        (tangential, contact-local). Default 0.
    jacobian : how the Newton step is computed (:data:`JACOBIANS`): ``"auto"`` (default)
        forms the Jacobian up to :data:`DENSE_JACOBIAN_MAX` unknowns and uses it as an
        operator (GMRES with per-harmonic factorisations) above.

    Contact springs of the interface (``contact.kn``, ``contact.kt``) are applied to
    ``reduced`` here (:func:`fretwear.hb.connectors.connect`): the unknowns are then the
    contact points in series with the springs. Nodes with a prescribed normal load
    (``contact.normal_load``) take ``lambda_N = N(t)`` and the slip threshold ``mu N(t)``.
    """

    def __init__(self, reduced: Reduced, contact: ContactInterface, basis: FourierBasis,
                 gap=None, eps="auto", anchor=None, periodicity_tol=1e-12, max_sweeps=200,
                 jacobian="auto"):
        nc, d = contact.dofs.shape
        self.nc, self.d, self.basis = nc, d, basis
        self.H = basis.size
        self.m = nc * d
        exp = np.array([0, *basis.harmonics])
        if not np.array_equal(np.asarray(reduced.orders), exp):
            raise InputError(f"reduced model orders {list(reduced.orders)} != basis {list(exp)}")
        self._springs = springs(contact)
        if self._springs is not None:
            reduced = connect(reduced, contact, self._springs)
        self.reduced = reduced
        self.contact = contact
        self.blocks = HarmonicBlocks(reduced.Z)
        self._Z = None
        self._zu = None
        if jacobian not in JACOBIANS:
            raise InputError(f"jacobian = {jacobian!r}: expected one of {JACOBIANS}")
        if jacobian == "auto":
            jacobian = "dense" if self.m * self.H <= DENSE_JACOBIAN_MAX else "krylov"
        self.jacobian = jacobian
        self.F = loads_to_real(reduced.F)
        self._eps_rule = eps
        self.eps = penalty(eps, reduced=reduced, contact=contact)
        self._Fnorm = None
        self.mu = contact.mu_nodes()
        self.normal = contact.normal_force_samples(basis.tau)  # None: all unilateral
        self.set_gap(contact.gap if gap is None else gap)
        self.anchor = np.zeros((nc, d - 1)) if anchor is None else np.array(anchor, float)
        self.P, self.Q = basis.matrices()
        # small problems: residual and Jacobian in one compiled call (hb/small.py)
        self.small = self.jacobian == "dense" and self.m * self.H <= small.SMALL_MAX
        self._normal = law._normal(self.normal, np.empty((nc, d, basis.n_samples)))
        self.tol = periodicity_tol
        self.max_sweeps = max_sweeps
        self.nfev = 0

    def at(self, reduced: Reduced, anchor) -> DLFTProblem:
        """The same problem (interface, basis, gap, eps rule, settings) on the reduced model
        of another frequency (same orders), with the stick anchors ``anchor`` (nc, d-1) [m].
        What does not depend on the frequency (the Fourier matrices, friction coefficients,
        prescribed normal forces, a numeric eps, the contact springs) is shared, not rebuilt:
        a sweep makes one problem per frequency."""
        if isinstance(self._eps_rule, str):  # a rule evaluated on each reduced model
            return DLFTProblem(reduced, self.contact, self.basis, gap=self.gap,
                               eps=self._eps_rule, anchor=anchor, periodicity_tol=self.tol,
                               max_sweeps=self.max_sweeps, jacobian=self.jacobian)
        new = object.__new__(DLFTProblem)  # a shallow copy (copy.copy: slower)
        new.__dict__.update(self.__dict__)
        if self._springs is not None:
            reduced = connect(reduced, self.contact, self._springs)
        new.reduced = reduced
        new.blocks = HarmonicBlocks(reduced.Z)
        new._Z = new._zu = None
        new.F = loads_to_real(reduced.F)
        new._Fnorm = None
        new.anchor = (np.zeros((self.nc, self.d - 1)) if anchor is None
                      else np.array(anchor, float))
        new.nfev = 0
        return new

    def with_eps(self, eps: float) -> DLFTProblem:
        """The same problem (reduced model, gap, anchors) with the penalty ``eps`` [N/m]."""
        return DLFTProblem(self.reduced, self.contact, self.basis, gap=self.gap, eps=eps,
                           anchor=self.anchor, periodicity_tol=self.tol,
                           max_sweeps=self.max_sweeps, jacobian=self.jacobian)

    def set_gap(self, gap):
        gap = np.broadcast_to(np.asarray(gap, dtype=float), (self.nc,))
        W = np.zeros((self.m, self.H))
        W[0 :: self.d, 0] = gap
        self.gap = np.array(gap)
        self.W = W

    @property
    def Z(self) -> np.ndarray:
        """The real block operator ``Z~`` (m*H, m*H), DOF-major
        (:func:`~fretwear.hb.reduce.to_real_blocks`), formed on first use."""
        if self._Z is None:
            self._Z = to_real_blocks(self.reduced.Z, self.reduced.orders)
        return self._Z

    def apply_Z(self, U) -> np.ndarray:
        """``Z~ U~`` (m, H): with the formed ``Z~`` on the dense path, by harmonic blocks
        (:class:`~fretwear.hb.krylov.HarmonicBlocks`) on the operator path; always the same
        way for one problem, so that a result re-assembled from saved harmonics is bitwise
        the one of the solve."""
        if self.jacobian == "dense":
            return (self.Z @ np.reshape(U, -1)).reshape(self.m, self.H)
        return self.blocks.apply(U)

    # -- evaluation ---------------------------------------------------------------------
    def lambda_u(self, U):
        """``lambda_u~ = F~ - Z U~ + eps (U~ - W~)`` (m, H) (eq. 23)."""
        ZU = self.apply_Z(U)
        if self.jacobian == "krylov":  # |Z U~| of the convergence test at the same U~
            self._zu = (np.array(U, dtype=float), vector_norm(ZU))
        return self.F - ZU + self.eps * (U - self.W)

    def time_law(self, U):
        """Time-domain law: ``(lam_u, lam_x, state, sweeps)`` with samples (nc, d, N)."""
        if self.small:
            return small.time_law(self._flat(U), self.Z, self.F.reshape(-1),
                                  self.W.reshape(-1), self.eps, self.Q, self.mu,
                                  self._x_start(), self.tol, self.max_sweeps, self._normal,
                                  self.nc, self.d)
        lu = self.basis.to_time(self.lambda_u(U)).reshape(self.nc, self.d, -1)
        lu = np.ascontiguousarray(lu)
        lx, state, sweeps = law.dlft_time(lu, self.mu, self.eps * self.anchor, self.tol,
                                          self.max_sweeps, self.normal)
        return lu, lx, state, sweeps

    def to_freq(self, samples) -> np.ndarray:
        """Real coefficients (k, H) of time samples (k, N), as the residual takes them: by
        the forward matrix ``P`` on the small-problem path, by FFT otherwise."""
        if self.small:
            return samples @ self.P.T
        return self.basis.to_freq(samples)

    def _flat(self, U):
        return np.ascontiguousarray(U, dtype=float).reshape(-1)

    def _x_start(self):
        return np.ascontiguousarray(self.eps * self.anchor, dtype=float).reshape(self.nc,
                                                                                  self.d - 1)

    def residual(self, U, jacobian=True):
        """``f`` (m*H,) and, if asked, ``J`` (m*H, m*H) at ``U`` (m, H)."""
        self.nfev += 1
        if self.small:
            f, J = small.residual(self._flat(U), self.Z, self.F.reshape(-1),
                                  self.W.reshape(-1), self.eps, self.P, self.Q, self.mu,
                                  self._x_start(), self.tol, self.max_sweeps, self._normal,
                                  self.nc, self.d, bool(jacobian))
            return f, (J if jacobian else None)
        lu, lx, state, _ = self.time_law(U)
        Lx = self.basis.to_freq(lx.reshape(self.m, -1))
        f = (self.eps * (U - self.W) - Lx).reshape(-1)
        if not jacobian:
            return f, None
        G = law.dlft_jacobian(lu, lx, state, self.mu, self.P, self.Q, self.eps * self.anchor,
                              self.tol, self.max_sweeps, self.normal)
        if self.jacobian == "krylov":
            return f, KrylovJacobian(G, self.blocks, self.eps, self.d, owner=self)
        n = self.m * self.H
        dH = self.d * self.H
        # J = eps I - G (eps I - Z) = eps (I - G) + G Z, G block-diagonal per node
        GZ = np.matmul(G, self.Z.reshape(self.nc, dH, n)).reshape(n, n)
        J = GZ
        for p in range(self.nc):
            sl = slice(p * dH, (p + 1) * dH)
            J[sl, sl] -= self.eps * G[p]
        J[np.diag_indices(n)] += self.eps
        return f, J

    def scale(self, U):
        """Reference magnitude of the convergence test: ``|Z_r U~|`` (section 3.2), or |F~|
        when that vanishes."""
        kept = self._zu
        if kept is not None and np.array_equal(kept[0], U):  # from the residual at this U
            zu = kept[1]
        else:
            zu = vector_norm(self.apply_Z(U))
        if self._Fnorm is None:
            self._Fnorm = float(np.linalg.norm(self.F))
        return max(zu, self._Fnorm, 1e-300)

    def initial_guess(self):
        """Contact closed, tangential positions at the anchors, no vibration."""
        U = np.zeros((self.m, self.H))
        U[0 :: self.d, 0] = self.gap
        for c in range(self.d - 1):
            U[1 + c :: self.d, 0] = self.anchor[:, c]
        return U


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
    """One attempt of a periodic solve (:func:`solve_strategy`, the sweeps).

    method : what was tried: ``"start"`` (the solver from the given start), ``"best-point"``
        (the other solver from the best iterate so far), ``"eps-continuation"`` (converged at
        another penalty, then stepped back to the target one: the answer is at the target
        eps), ``"harmonic-continuation"`` (the first harmonic alone, then all of them),
        ``"time-start"`` (from a time integration), and for sweeps ``"grid"``, ``"substep"``,
        ``"retry"``, ``"arclength"``, ``"fresh-start"`` (the first harmonic alone with the
        static anchors, then ``"start"`` and ``"eps-continuation"`` with a single solve's
        iterations).
    solver : the nonlinear solver; eps : the penalty of the answer [N/m]; success, residual
    (relative), iterations, wall_time [s], message : as :class:`~fretwear.hb.solvers.SolveStats`.
    """

    method: str
    solver: str
    eps: float
    success: bool
    residual: float
    iterations: int
    wall_time: float
    message: str

    @classmethod
    def of(cls, method: str, eps: float, st: SolveStats, message: str | None = None):
        return cls(method, st.solver, float(eps), bool(st.success), float(st.residual),
                   int(st.iterations), float(st.wall_time),
                   st.message if message is None else message)


#: the attempts of :func:`solve_strategy`, in order; :func:`solve_periodic` adds
#: ``"time-start"`` when it is given a time-domain fallback
STRATEGY = ("start", "best-point", "eps-continuation", "harmonic-continuation", "time-start")
#: penalties tried by the eps continuation, as factors of the target eps, and the number of
#: geometric steps back to the target (the first try: a failed step is halved in log eps)
EPS_FACTORS = (10.0, 0.1)
EPS_STEPS = 4
#: the eps continuation gives up when a step would be smaller than this ratio of penalties
EPS_MIN_RATIO = 1.02
#: iterations allowed to one step of the eps continuation (it starts from the answer at a
#: nearby eps: a step that needs more is better halved)
EPS_STEP_MAX_ITER = 20


def _eps_path(prob, x, st, eps_from, solver, tol, max_iter):
    """From the converged ``x`` at ``eps_from`` back to ``prob.eps`` by geometric steps: a
    step that fails is halved (in log eps) and retried from the last converged answer, a step
    that converges grows by 1.5, until ``prob.eps`` is reached or a step would be below
    :data:`EPS_MIN_RATIO`. On the paper's beam at 79.34 kHz the four equal steps from 10 eps
    failed where steps of 10 % converge in 3-4 iterations each (docs/studies/eps-rule.md).
    Returns ``(x, stats, path)``: ``path`` the penalties of the converged answers and, last,
    that of the failed step if it did not reach ``prob.eps``."""
    target = float(prob.eps)
    cur = float(eps_from)
    step = np.log(target / cur) / EPS_STEPS
    path = [cur]
    while cur != target:
        remaining = np.log(target / cur)
        last = abs(remaining) <= abs(step) * (1.0 + 1e-12)
        e = target if last else float(cur * np.exp(step))
        xn, stn = _run(prob if last else prob.with_eps(e), x, solver, tol,
                       min(max_iter, EPS_STEP_MAX_ITER))
        if stn.success:
            cur, x, st = e, xn, stn
            path.append(e)
            step *= 1.5
            continue
        step *= 0.5
        if abs(step) < np.log(EPS_MIN_RATIO):
            path.append(e)
            return xn, stn, path
    return x, st, path


def _run(prob: DLFTProblem, x0, solver, tol, max_iter):
    """One solver run on ``prob`` from ``x0`` (m, H): ``(x (m, H), stats)``."""

    def fun(x, jac=True):
        return prob.residual(x.reshape(prob.m, prob.H), jac)

    t0 = time.perf_counter()
    x, _, st = solve(fun, np.asarray(x0, float).reshape(-1),
                     lambda x: prob.scale(x.reshape(prob.m, prob.H)), method=solver, tol=tol,
                     max_iter=max_iter)
    st.wall_time = time.perf_counter() - t0
    return x.reshape(prob.m, prob.H), st


def solve_strategy(prob: DLFTProblem, x0, *, solver="powell", tol=1e-8, max_iter=200,
                   attempts: list | None = None, steps=STRATEGY):
    """Solve the balance of ``prob`` from ``x0`` (m, H), trying in order until one converges
    (``steps``, a subset of :data:`STRATEGY`):

    1. ``"start"``: ``solver`` from ``x0``;
    2. ``"best-point"``: the other solver (Newton after Powell, Powell after Newton or hybr)
       from the best iterate so far (Newton converges where Powell's trust region stalls, and
       the reverse, on the paper's beam);
    3. ``"eps-continuation"``: the balance at ``10 eps`` (then ``eps / 10``) from ``x0`` (the
       solver, then the other one, then the solver from the first harmonic alone at that
       eps), and from there geometric steps back to ``eps`` (:func:`_eps_path`: halved where
       one fails), each starting from the previous answer: the answer is that of the target
       eps (no eps jump);
    4. ``"harmonic-continuation"``: the first harmonic alone from the contact-closed guess,
       then all harmonics from it.

    Every attempt is appended to ``attempts`` (:class:`Attempt`). Returns ``(x, stats)``: the
    converged answer, or the iterate with the smallest residual when none converged.
    """
    attempts = [] if attempts is None else attempts
    other = "newton" if solver != "newton" else "powell"
    best = None

    def keep(x, st):
        nonlocal best
        if best is None or st.success or st.residual < best[1].residual:
            best = (x, st)
        return st.success

    x0 = np.asarray(x0, float).reshape(prob.m, prob.H)
    if "start" in steps:
        x, st = _run(prob, x0, solver, tol, max_iter)
        attempts.append(Attempt.of("start", prob.eps, st))
        if keep(x, st):
            return best
    if "best-point" in steps:
        start = x0 if best is None else best[0]
        x, st = _run(prob, start, other, tol, max_iter)
        attempts.append(Attempt.of("best-point", prob.eps, st))
        if keep(x, st):
            return best
    if "eps-continuation" in steps:
        for factor in EPS_FACTORS:
            t0 = time.perf_counter()
            shifted = prob.with_eps(factor * prob.eps)
            x, st = _run(shifted, x0, solver, tol, max_iter)
            if not st.success:  # the other solver at the shifted eps
                x, st = _run(shifted, x0, other, tol, max_iter)
            if not st.success and prob.basis.k > 1:  # the first harmonic alone, at that eps
                U1 = _first_harmonic_start(shifted, solver, tol, max_iter)
                if U1 is not None:
                    x, st = _run(shifted, U1, solver, tol, max_iter)
            path = [factor * prob.eps]
            if st.success:
                x, st, path = _eps_path(prob, x, st, factor * prob.eps, solver, tol, max_iter)
            st.wall_time = time.perf_counter() - t0
            msg = (f"{st.message} (eps path {', '.join(f'{e:.3g}' for e in path)} N/m)")
            attempts.append(Attempt.of("eps-continuation", prob.eps if st.success else
                                       path[-1], st, msg))
            if st.success and path[-1] == prob.eps:
                keep(x, st)
                return best
    if "harmonic-continuation" in steps and prob.basis.k > 1:
        t0 = time.perf_counter()
        U1 = _first_harmonic_start(prob, solver, tol, max_iter)
        if U1 is not None:
            x, st = _run(prob, U1, solver, tol, max_iter)
            st.wall_time = time.perf_counter() - t0
            attempts.append(Attempt.of("harmonic-continuation", prob.eps, st))
            if keep(x, st):
                return best
        else:
            attempts.append(Attempt("harmonic-continuation", solver, prob.eps, False,
                                    float("nan"), 0, time.perf_counter() - t0,
                                    "the first harmonic alone did not converge"))
    if best is None:  # nothing ran at the target eps: the start, unconverged
        tried = ", ".join(a.method for a in attempts) or "none"
        x0 = np.asarray(x0, float).reshape(prob.m, prob.H)
        f, _ = prob.residual(x0, False)  # the start's relative residual, as the solvers give
        rel = float(vector_norm(f) / max(prob.scale(x0), 1e-300))
        best = (x0, SolveStats(False, rel, 0, 1, 0, 0.0, f"no attempt converged ({tried})",
                               solver))
    return best


def _orders(basis):
    return np.array([0, *basis.harmonics], dtype=np.int64)


#: highest harmonic inspected when checking that the loads act on the kept harmonics
LOAD_CHECK_HARMONICS = 64


def check_inputs(model, basis, frequency, *, quasi_static: bool = False, anchor=None,
                 U0=None) -> float:
    """Check the arguments of a periodic solve (and of the drivers built on it); return the
    frequency as a float [Hz].

    Raises TypeError for a model or basis of the wrong kind and InputError (a ValueError)
    naming the argument for: a basis with no harmonic; a frequency outside
    :data:`fretwear.limits.RANGES` or not > 0 for a dynamic solve; an ``anchor`` or ``U0`` of
    the wrong shape or not finite; loads whose periodic part acts only on harmonics the basis
    does not keep (the response would be static, reported as a converged solution).
    """
    if not isinstance(model, Model):
        raise TypeError(f"model = {model!r}: expected a fretwear Model (fretwear.from_mesh, "
                        "fretwear.from_matrices)")
    if not isinstance(basis, FourierBasis):
        raise TypeError(f"basis = {basis!r}: expected a fretwear FourierBasis")
    if not basis.harmonics:
        raise InputError("basis keeps no harmonic: expected at least one (e.g. "
                         "FourierBasis.up_to(7, 128))")
    f = check_range(frequency, "frequency", "frequency")
    if not quasi_static and f <= 0.0:
        raise InputError(f"frequency = {frequency!r} Hz: expected > 0 for a dynamic solve "
                         "(quasi_static=True drops inertia and damping)")
    nc, d = model.contact.n_nodes, model.contact.dim
    for name, value, shapes in (("anchor", anchor, [(nc, d - 1)]),
                                ("U0", U0, [(nc, d, basis.size), (nc * d, basis.size)])):
        if value is None:
            continue
        a = np.asarray(value)
        if a.dtype.kind not in "fiu" or a.shape not in shapes or not np.all(np.isfinite(a)):
            raise InputError(f"{name} has shape {a.shape} (dtype {a.dtype}): expected finite "
                             f"real values of shape {' or '.join(map(str, shapes))}")
    nmax = max(LOAD_CHECK_HARMONICS, max(basis.harmonics))
    acting = set()
    for load in model.loads:  # the waveforms' coefficients: no (harmonics x DOFs) array
        a, b = load.fourier_coefficients(nmax)
        vec = np.asarray(load.vector)
        if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))
                and np.all(np.isfinite(vec))):
            raise InputError(f"load {load.name!r} holds non-finite values (nan or inf)")
        if np.any(vec != 0):
            acting |= {n for n in range(1, nmax + 1) if a[n] != 0 or b[n] != 0}
    acting = sorted(acting)
    if acting and not set(acting) & set(basis.harmonics):
        raise InputError(f"the periodic loads act on harmonics {acting[:8]} but the basis "
                         f"keeps {list(basis.harmonics)}: the response would be static; keep "
                         "the harmonics of the loads")
    return f


@dataclass
class StaticAnchor:
    """The stick anchors of the preload state (:func:`preload_anchor`).

    values : (nc, d-1) tangential positions of the contact nodes [m] after the static loads
    are applied from rest; 0 (the undeformed position) when the static contact problem did not
    converge. success : that problem converged. message : why its solver stopped.
    """

    values: np.ndarray
    success: bool
    message: str

    @property
    def warning(self) -> str:
        """One line for the user when the static solve failed (``""`` when it converged)."""
        if self.success:
            return ""
        return (f"the static contact problem under the preload did not converge "
                f"({self.message}): the stick anchors are set to 0 (the undeformed position) "
                "instead of the preload state, so the mean tangential positions of stuck "
                "nodes may be wrong")


def preload_anchor(model: Model, *, quasi: Reduced | None = None, eps="auto",
                   condenser=None) -> StaticAnchor:
    """Tangential positions of the contact nodes after the static loads are applied from rest,
    with whether the static solve converged.

    Solves the static contact problem (one instant) starting from a stress-free state in which
    every node that touches sticks where it is (anchor 0): the loading history "preload first,
    then vibrate". ``eps``: the penalty of this static solve (the rule or a number, as for
    :class:`DLFTProblem`). When it does not converge the anchors are 0 and the result says so
    (``success``, ``warning``): the callers put the warning in their results. ``condenser``:
    the condenser of ``model`` (:func:`fretwear.hb.reduce.exact_condenser`; None: a new one).
    """
    prob, x, st = _static_solve(model, quasi, eps, condenser)
    if not st.success:
        return StaticAnchor(np.zeros((prob.nc, prob.d - 1)), False, st.message)
    U = x.reshape(prob.nc, prob.d, 1)
    return StaticAnchor(U[:, 1:, 0].copy(), True, st.message)


def static_anchor(model: Model, *, quasi: Reduced | None = None, eps="auto",
                  condenser=None) -> np.ndarray:
    """The anchors of :func:`preload_anchor` alone, (nc, d-1) [m]; a
    :class:`RuntimeWarning` says when the static solve did not converge (the anchors are then
    0)."""
    a = preload_anchor(model, quasi=quasi, eps=eps, condenser=condenser)
    if not a.success:
        warnings.warn(a.warning, RuntimeWarning, stacklevel=2)
    return a.values


def _static_solve(model: Model, quasi: Reduced | None, eps, condenser=None):
    """The static contact problem of :func:`static_anchor`: ``(problem, x, stats)``."""
    basis = FourierBasis((), 1)
    red = quasi if quasi is not None else condense(model, 0.0, [0], quasi_static=True,
                                                   condenser=condenser)
    prob = DLFTProblem(red, model.contact, basis, eps=eps)
    U0 = prob.initial_guess()

    def fun(x, jac=True):
        return prob.residual(x.reshape(prob.m, prob.H), jac)

    x, _, st = solve(fun, U0.reshape(-1), lambda x: prob.scale(x.reshape(prob.m, prob.H)),
                     method="powell", tol=STATIC_TOL, max_iter=STATIC_MAX_ITER)
    return prob, x, st


@dataclass
class PreloadContact:
    """The contact of every interface under the static loads alone (the preload), applied
    from rest: what a vibration or a wear run starts from.

    normal_force : (nc,) normal contact force of each node [N] (compression positive; 0 where
        the node is open or touches without force), None when the static contact problem did
        not converge; loaded : (nc,) bool, nodes that carry a normal force (more than ``1e-9``
        of the largest static load or contact force) or have a prescribed normal load;
    names : the interface names; closed : (n_interfaces,) number of loaded nodes of each.
    """

    normal_force: np.ndarray | None
    loaded: np.ndarray
    names: tuple
    closed: np.ndarray
    message: str = ""

    @property
    def success(self) -> bool:
        """The static contact problem converged."""
        return self.normal_force is not None

    def open_interfaces(self) -> list[str]:
        """Names of the interfaces with no node in contact under the preload."""
        return [n for n, k in zip(self.names, self.closed, strict=True) if k == 0]


def preload_contact(model: Model, *, eps="static", condenser=None) -> PreloadContact:
    """Which contact nodes of ``model`` are pressed by its static loads (the preload).

    The static contact problem of :func:`static_anchor` (exact contact, Coulomb friction,
    loads applied from rest), solved once. An interface on which no node carries a normal
    force under the preload (opened by its gap, pulled away, or touching without force) is
    almost always a mistake in a vibration or wear run: its friction can only act where the
    vibration itself closes it. Nodes with a prescribed normal load count as in contact.
    ``condenser``: the condenser of ``model`` (None: a new exact one).
    """
    c = model.contact
    names = c.names()
    where = c.interface_index()
    prescribed = np.zeros(c.n_nodes, dtype=bool)
    if c.normal_load is not None:
        prescribed = np.isfinite(np.asarray(c.normal_load.vector, dtype=float))
    prob, x, st = _static_solve(model, None, eps, condenser)
    if not st.success:
        loaded = prescribed
        lam_n = None
    else:
        lu, lx, _, _ = prob.time_law(x.reshape(prob.m, prob.H))
        lam = (lu - lx).reshape(prob.nc, prob.d)
        lam_n = lam[:, 0].copy()
        scale = max(float(np.max(np.abs(lam), initial=0.0)),
                    float(np.max(np.abs(prob.F), initial=0.0)))
        loaded = prescribed | (lam_n > 1e-9 * scale) if scale > 0 else prescribed.copy()
    closed = np.bincount(where[loaded], minlength=len(names))
    return PreloadContact(lam_n, loaded, tuple(names), closed,
                          st.message if not st.success else "converged")


def solve_periodic(model: Model, basis: FourierBasis, *, frequency: float = 1.0,
                   quasi_static: bool = False, reduced: Reduced | None = None, gap=None,
                   eps="auto", anchor=None, U0=None, solver="powell", tol=1e-8, max_iter=200,
                   raise_on_failure=False, strategy=STRATEGY,
                   time_domain: TimeDomainFallback | None = None,
                   time_domain_periods: int = 3000, condenser=None) -> PeriodicSolution:
    """Periodic response of ``model`` at the excitation ``frequency`` [Hz] with the DLFT
    (section 3.1-3.2).

    Parameters
    ----------
    basis : kept harmonics and samples per period.
    frequency : excitation frequency [Hz] (default 1 Hz, as case files: with
        ``quasi_static`` it only scales time, a 1 s cycle).
    quasi_static : drop inertia and damping (slow cyclic loading).
    reduced : a precomputed condensation on ``[0] + basis.harmonics`` (else computed here).
    gap : (nc,) gap + wear [m] (default: the model's initial gap).
    eps : DLFT penalty: ``"auto"`` (default) the spectral radius of ``Z_r`` over the kept
        harmonics (the paper), ``"static"`` that of the static ``K_r``, or a positive number
        [N/m] (:func:`fretwear.hb.penalty.penalty`).
    anchor : (nc, d-1) stick anchors [m]; default: the static preload state
        (:func:`preload_anchor`), the documented rule for the mean tangential position (when
        that static solve does not converge the anchors are 0 and ``warnings`` says so).
    U0 : (nc, d, H) starting point (e.g. a neighbouring solution).
    solver : ``"powell"`` (dog-leg at LAPACK speed), ``"newton"`` or ``"hybr"`` (MINPACK).
    tol : relative residual ``eps_r`` of the test ``|f| <= eps_r |Z_r U|``.

    raise_on_failure : raise :class:`~fretwear.errors.ConvergenceError` when the solve does
        not converge instead of returning a solution with ``success`` False.
    strategy : the attempts made until one converges (:func:`solve_strategy`; default all of
        :data:`STRATEGY`; ``("start",)``: the solver alone). Each is recorded in the result's
        ``attempts``.
    time_domain : a :class:`~fretwear.hb.fallback.TimeDomainFallback`
        (:data:`fretwear.timedomain.fallback.FALLBACK`, which :func:`fretwear.solve_periodic`
        passes by default; None: none). When every attempt of ``strategy`` failed, integrate
        in time from rest for at most ``time_domain_periods`` periods: a periodic steady state
        starts one more solve (attempt ``"time-start"``, its mean tangential positions as
        anchors); any other response (drifting, quasi-periodic, subharmonic) is what the result
        reports (``time_domain``, ``flags``): the solve then failed because there is no periodic
        state to find, or none the integration reached. Not with ``quasi_static``, a ``gap``
        other than the model's, contact springs or prescribed normal loads (the time-domain
        solver models none of these).
    condenser : the condenser of ``model`` (:func:`fretwear.hb.reduce.exact_condenser` or
        :func:`fretwear.hb.modal.modal_condenser`) used by every condensation of the solve;
        None: a new exact one, built once for the solve.

    Returns
    -------
    :class:`PeriodicSolution`: ``success`` True when the balance converged; otherwise
    ``success`` False, ``message`` says why (``stats`` has the residual and counts) and the
    fields hold the last iterate (for inspection, never a result).
    """
    frequency = check_inputs(model, basis, frequency, quasi_static=quasi_static,
                             anchor=anchor, U0=U0)
    if condenser is None and (reduced is None or anchor is None):
        condenser = exact_condenser(model)  # one for the solve's condensations
    if reduced is None:
        reduced = condense(model, frequency, _orders(basis), quasi_static=quasi_static,
                           condenser=condenser)
    reduced = connect(reduced, model.contact)
    eps = penalty(eps, model=model, reduced=reduced, condenser=condenser)
    preload = None
    if anchor is None:
        preload = preload_anchor(model, condenser=condenser)
        anchor = preload.values
    prob = DLFTProblem(reduced, model.contact, basis, gap=gap, eps=eps, anchor=anchor)
    if U0 is None and basis.k > 3:
        U0 = _harmonic_continuation_start(model, basis, reduced, prob, solver, tol, max_iter)
    x0 = (prob.initial_guess() if U0 is None else np.asarray(U0, float).reshape(prob.m, prob.H))
    attempts: list = []
    t0 = time.perf_counter()
    x, st = solve_strategy(prob, x0, solver=solver, tol=tol, max_iter=max_iter,
                           attempts=attempts, steps=strategy)
    found = ""
    if not st.success and _time_start_applies(model, time_domain, quasi_static, gap, strategy):
        found, prob2, x2, st2 = _time_start(model, basis, frequency, reduced, prob, time_domain,
                                            time_domain_periods, solver, tol, max_iter)
        if st2 is not None:
            attempts.append(Attempt.of("time-start", prob2.eps, st2))
            if st2.success or st2.residual < st.residual:
                prob, x, st = prob2, x2, st2
        else:
            attempts.append(Attempt("time-start", solver, prob.eps, False, float("nan"), 0,
                                    0.0, found))
    st.wall_time = time.perf_counter() - t0
    if not st.success and raise_on_failure:
        from fretwear.errors import ConvergenceError

        raise ConvergenceError(
            f"periodic solve at f = {reduced.frequency:.6g} Hz did not converge: "
            f"{st.message} (relative residual {st.residual:.3g} > {tol:g}; "
            f"{len(attempts)} attempts: {', '.join(a.method for a in attempts)})"
        )
    sol = assemble_solution(prob, x.reshape(prob.m, prob.H), model, st)
    sol.attempts = attempts
    if found:
        sol.time_domain = found
        if not sol.success:
            sol.flags.append(found)
    if preload is not None and not preload.success:
        sol.warnings.append(preload.warning)
    return sol


def _time_start_applies(model: Model, time_domain, quasi_static: bool, gap, strategy) -> bool:
    if time_domain is None or quasi_static or "time-start" not in strategy:
        return False
    if model.contact.has_connectors:  # the time-domain solver has rigid contacts only
        return False
    return gap is None or np.array_equal(np.broadcast_to(np.asarray(gap, float),
                                                         model.contact.gap.shape),
                                         model.contact.gap)


def _time_start(model, basis, frequency, reduced, prob, time_domain, periods, solver, tol,
                max_iter):
    """The ``"time-start"`` attempt: ``(message, problem, x, stats)``; ``stats`` None when
    the integration did not settle to a periodic state (the message says what it does)."""
    t0 = time.perf_counter()
    msg, Ut, anchor = time_domain.start(model, frequency, basis, None, max_periods=periods)
    if Ut is None:
        return msg, prob, None, None
    prob2 = DLFTProblem(reduced, model.contact, basis, gap=prob.gap, eps=prob.eps,
                        anchor=anchor, jacobian=prob.jacobian)
    x, st = _run(prob2, np.asarray(Ut, float).reshape(prob2.m, prob2.H), solver, tol,
                 2 * max_iter)
    st.wall_time = time.perf_counter() - t0
    return msg, prob2, x, st


def _harmonic_continuation_start(model, basis, reduced, prob, solver, tol, max_iter):
    """A starting point for a many-harmonic solve: the solution on the first kept harmonic,
    embedded in the full basis (None if that fails). From the contact-closed guess, the
    solvers can stall with 15+ harmonics where the one-harmonic problem converges and then
    starts the full one within a few iterations (docs/verification.md)."""
    return _first_harmonic_start(prob, solver, tol, max_iter)


def _first_harmonic_start(prob, solver, tol, max_iter):
    """:func:`_harmonic_continuation_start` from the problem alone."""
    basis, reduced = prob.basis, prob.reduced
    sub = FourierBasis(basis.harmonics[:1], basis.n_samples)
    cut = {k: getattr(reduced, k)[:2] for k in ("orders", "Z", "F", "obs_A", "obs_b")}
    if isinstance(reduced, Connected):  # already seen through the contact springs
        cut.update(node_A=reduced.node_A[:2], node_b=reduced.node_b[:2])
    red = dataclasses.replace(reduced, **cut)
    p1 = DLFTProblem(red, prob.contact, sub, gap=prob.gap, eps=prob.eps, anchor=prob.anchor)
    if p1.jacobian == "krylov":  # the full problem's blocks (and their real copies), shared
        p1.blocks = prob.blocks.leading(2)

    def fun(x, jac=True):
        return p1.residual(x.reshape(p1.m, p1.H), jac)

    x, _, st = solve(fun, p1.initial_guess().reshape(-1),
                     lambda x: p1.scale(x.reshape(p1.m, p1.H)), method=solver, tol=tol,
                     max_iter=max_iter)
    if not st.success:
        return None
    U = np.zeros((prob.m, prob.H))
    x = x.reshape(p1.m, p1.H)
    U[:, 0] = x[:, 0]
    U[:, 1] = x[:, 1]
    U[:, 1 + basis.k] = x[:, 2]
    return U


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
    return PeriodicSolution(
        frequency=red.frequency, omega=red.omega, quasi_static=red.quasi_static, basis=b,
        U=U.reshape(nc, d, H).copy(),
        lam=lam, X=X, lam_t=lam_t, x_t=x_t, state=state, gap=prob.gap.copy(),
        anchor=prob.anchor.copy(), eps=prob.eps, observed=observed,
        area=np.asarray(model.contact.area, float), coords=np.asarray(model.contact.coords),
        stats=stats, U_node=U_node,
    )


def initial_state(model: Model, sol: PeriodicSolution, condenser=None):
    """Full-field displacement [m] and velocity [m/s] at ``t = 0`` of a periodic solution
    (recovered by ``condenser``, the solution's; None: a new exact one)."""
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
