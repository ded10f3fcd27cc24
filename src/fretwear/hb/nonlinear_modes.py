"""Nonlinear modes by the Extended Periodic Motion Concept (Krack, J. Sound Vib. 2015), on the
DLFT contact law with the static preload.

The autonomous structure (no periodic load; the static loads stay) with a negative
mass-proportional damping term

    M u'' + (C - xi M) u' + K u + T^T lambda(u) = F_static

has, for the right ``xi``, a periodic motion: the mode at that amplitude. ``xi`` is the
damping the term compensates: the damping ratio of the mode is ``zeta = xi / (2 w)``. The
unknowns are the harmonics of the motion, its circular frequency ``w`` and ``xi``, at a
prescribed modal amplitude ``a`` (the mass norm of the fundamental harmonic,
``a = sqrt(U_1^H M U_1)`` over the whole structure, ``u = Re(U_1 e^{i w t}) + ...``), with a
phase condition (the sine coefficient of the fundamental harmonic of the master coordinate is
zero). Harmonic ``n`` of the structure has the dynamic stiffness (eq. 18 with the extra term)

    Z_n = K + i D - (n w)^2 M + i n w (C - xi M),      Z_0 = K.

Coordinates. The contact law acts on the contact points ``x`` (:mod:`fretwear.hb.dynamics`:
the contact DOFs, or the massless points behind contact springs); the balance condenses
everything else onto them. A mode in which the interface sticks lives in the condensed part
(the contact points do not move), where the condensation has a pole, so the unknowns here
are ``x`` and the *master* coordinates ``eta`` of the structure with its contact points held
(the modes of ``(K_qq, M_qq)``: the stuck-interface modes) nearest the mode followed; the other
coordinates are condensed exactly harmonic by harmonic (a Schur complement at ``(w, xi)``).
The contact rows are the DLFT residual (eq. 22-23) with ``lambda_u = F_x - Z_xy y + eps (x -
W)``, the master rows the structure's balance ``Z_eta y = F_eta``.

Continuation over ``log a`` from the linear stuck mode: a secant predictor in ``log a`` and
a corrector at fixed ``a`` (the solvers of :mod:`fretwear.hb.solvers`), the step halved where
the corrector fails.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from fretwear.errors import InputError
from fretwear.hb import contact as law
from fretwear.hb.dynamics import StructureDynamics, structure_dynamics
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.penalty import penalty
from fretwear.hb.reduce import to_real_blocks
from fretwear.hb.solvers import solve
from fretwear.model.core import Model
from fretwear.resources import require_memory

#: relative step of the finite differences in ``w`` and ``xi`` (the Jacobian's last columns)
FD_STEP = 1e-7
#: the corrector of a continuation step gets this many halvings of the step in ``log a``
MAX_HALVINGS = 6


@dataclass
class ModeSystem:
    """The structure in the coordinates of a nonlinear mode: the contact points ``x`` (m) and
    the master coordinates ``eta`` (nm), the rest condensed (module docstring).

    dyn : the structure (:class:`~fretwear.hb.dynamics.StructureDynamics`); phi : (q, q)
    its held modes (mass-normalised columns), ``q = phi eta``; omega_held : (q,) their
    circular frequencies [rad/s]; masters : indices of the master coordinates in ``eta``.
    """

    dyn: StructureDynamics
    phi: np.ndarray
    omega_held: np.ndarray
    masters: np.ndarray

    @property
    def m(self) -> int:
        return self.dyn.m

    @property
    def size(self) -> int:
        return self.dyn.m + self.masters.size

    #: the matrices on ``(x, eta)`` by name (:meth:`full`), projected once per system
    _full: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def _blocks(self, name):
        xx, xq, qx, qq = (np.asarray(b) for b in self.dyn.blocks[name])
        P = self.phi
        return xx, xq @ P, P.T @ qx, P.T @ qq @ P

    def full(self, name) -> np.ndarray:
        """The structure's matrix ``name`` (K, M, C, D) on ``(x, eta)``, (m + q, m + q):
        projected on the held modes once (every corrector iteration uses it)."""
        if name not in self._full:
            xx, xe, ex, ee = self._blocks(name)
            self._full[name] = np.block([[xx, xe], [ex, ee]]) if self.phi.shape[1] else xx
        return self._full[name]

    def stiffness(self, omega: float, xi: float, orders) -> tuple[np.ndarray, np.ndarray]:
        """``(Z, S)``: ``Z`` (nb, n, n) complex on ``(x, eta_masters)`` per harmonic order at
        ``(omega, xi)`` with the rest condensed, and the recovery ``S`` (nb, nr, n) of the
        rest: ``eta_rest = S y`` (no load on the dynamic harmonics)."""
        orders = np.asarray(orders)
        lam = 1j * orders * omega
        mass = lam * lam - xi * lam
        hyst = np.where(orders > 0, 1j, 0.0)
        mass[orders == 0] = 0.0
        names = [nm for nm in ("K", "M", "C", "D") if nm in self.dyn.blocks]
        coef = {"K": np.ones(orders.size), "M": mass, "C": lam, "D": hyst}
        m, q = self.m, self.phi.shape[1]
        nfull = m + q
        Zf = np.zeros((orders.size, nfull, nfull), dtype=complex)
        for nm in names:
            Zf += coef[nm][:, None, None] * self.full(nm)
        keep = np.concatenate([np.arange(m), m + self.masters])
        rest = np.setdiff1d(np.arange(nfull), keep)
        Zkk = Zf[:, keep[:, None], keep]
        if not rest.size:
            return Zkk, np.zeros((orders.size, 0, keep.size), dtype=complex)
        S = -np.linalg.solve(Zf[:, rest[:, None], rest], Zf[:, rest[:, None], keep])
        return Zkk + Zf[:, keep[:, None], rest] @ S, S

    def loads(self) -> np.ndarray:
        """Static loads (n,) on ``(x, eta_masters)`` [N], the rest condensed statically."""
        m, q = self.m, self.phi.shape[1]
        F = np.concatenate([self.dyn.load_x, self.phi.T @ self.dyn.load_q])
        Z, _ = self.stiffness(1.0, 0.0, [0])
        keep = np.concatenate([np.arange(m), m + self.masters])
        rest = np.setdiff1d(np.arange(m + q), keep)
        if not rest.size:
            return F[keep]
        K = self._full_static()
        return F[keep] - K[np.ix_(keep, rest)] @ np.linalg.solve(K[np.ix_(rest, rest)], F[rest])

    def _full_static(self) -> np.ndarray:
        return self.full("K")

    def coordinates(self, Y: np.ndarray, omega: float, xi: float,
                    basis: FourierBasis) -> np.ndarray:
        """Real harmonics (m + q, H) of the structure's coordinates ``(x, q)`` of the mode
        ``Y`` (n, H) at ``(omega, xi)``: the condensed master coordinates recovered harmonic
        by harmonic (:meth:`stiffness`; harmonic 0 with the static loads), ``q = phi eta``."""
        m, q = self.m, self.phi.shape[1]
        orders = basis.orders
        Yc = basis.to_complex(Y)  # (nb, n)
        keep = np.concatenate([np.arange(m), m + self.masters])
        rest = np.setdiff1d(np.arange(m + q), keep)
        full = np.zeros((orders.size, m + q), dtype=complex)
        full[:, keep] = Yc
        if rest.size:
            _, S = self.stiffness(omega, xi, orders)
            full[:, rest] = np.einsum("brn,bn->br", S, Yc)
            if 0 in orders:  # the static loads on the condensed coordinates
                K = self._full_static()
                F = np.concatenate([self.dyn.load_x, self.phi.T @ self.dyn.load_q])
                b0 = int(np.flatnonzero(orders == 0)[0])
                full[b0, rest] += np.linalg.solve(K[np.ix_(rest, rest)], F[rest])
        full[:, m:] = full[:, m:] @ self.phi.T
        return basis.from_complex(full)

    def observed(self, Y: np.ndarray, omega: float, xi: float,
                 basis: FourierBasis) -> np.ndarray | None:
        """Real harmonics (no, H) of the observed DOFs [m] (``dyn.observe``; None without)."""
        if self.dyn.observe is None:
            return None
        return self.dyn.observe @ self.coordinates(Y, omega, xi, basis)

    def mass(self, S1: np.ndarray) -> np.ndarray:
        """``T^H M T`` (n, n) at harmonic 1 for the recovery ``eta_rest = S1 y``: the
        structure's mass seen by the kept coordinates (the modal amplitude's norm)."""
        m, q = self.m, self.phi.shape[1]
        Mf = self.full("M")
        keep = np.concatenate([np.arange(m), m + self.masters])
        rest = np.setdiff1d(np.arange(m + q), keep)
        T = np.zeros((m + q, keep.size), dtype=complex)
        T[keep, np.arange(keep.size)] = 1.0
        if rest.size:
            T[rest] = S1
        return T.conj().T @ Mf @ T


def mode_system(model: Model, omega_target: float | None = None, *, masters: int = 1,
                dyn: StructureDynamics | None = None) -> ModeSystem:
    """The :class:`ModeSystem` of ``model`` with the ``masters`` held modes nearest
    ``omega_target`` [rad/s] (default: the lowest) as master coordinates."""
    dyn = structure_dynamics(model) if dyn is None else dyn
    q = dyn.q
    if q == 0:
        return ModeSystem(dyn, np.zeros((0, 0)), np.zeros(0), np.zeros(0, dtype=np.int64))
    Kqq = np.asarray(dyn.blocks["K"][3], dtype=float)
    Mqq = np.asarray(dyn.blocks["M"][3], dtype=float)
    try:
        w2, phi = sla.eigh(0.5 * (Kqq + Kqq.T), 0.5 * (Mqq + Mqq.T))
    except np.linalg.LinAlgError:
        raise InputError("nonlinear modes need a positive definite mass on the structure's "
                         "coordinates with the contact points held (a massless DOF other "
                         "than a contact point)") from None
    om = np.sqrt(np.maximum(w2, 0.0))
    target = om[0] if omega_target is None else float(omega_target)
    nm = int(min(max(masters, 1), q))
    chosen = np.sort(np.argsort(np.abs(om - target), kind="stable")[:nm])
    return ModeSystem(dyn, phi, om, chosen.astype(np.int64))


@dataclass
class ModePoint:
    """The nonlinear mode at one amplitude.

    amplitude : modal amplitude ``a`` [m sqrt(kg)] (mass norm of the fundamental harmonic).
    omega : circular frequency [rad/s]; frequency : [Hz]; xi : the compensated
    mass-proportional damping [1/s]; damping_ratio : ``xi / (2 omega)`` [-].
    Y : (n, H) harmonics of the contact points [m] and master coordinates [m sqrt(kg)].
    state : (nc, N) contact states (0 separation, 1 stick, 2 slip); energy : friction
    energy dissipated per cycle [J]; node_energy : (nc,) its share per contact node [J].
    success, residual, iterations : of the corrector.
    observed : (no, H) real harmonics of the observed DOFs [m], in the order of
    ``model.observed`` (:meth:`ModeSystem.observed`; None when the structure has no map).
    """

    amplitude: float
    omega: float
    xi: float
    Y: np.ndarray
    state: np.ndarray
    energy: float
    success: bool
    residual: float
    iterations: int
    node_energy: np.ndarray | None = None
    observed: np.ndarray | None = None

    @property
    def frequency(self) -> float:
        return self.omega / (2.0 * np.pi)

    @property
    def damping_ratio(self) -> float:
        return self.xi / (2.0 * self.omega)


@dataclass
class Backbone:
    """A nonlinear mode over amplitude (:func:`nonlinear_mode`): ``points`` in increasing
    amplitude (converged ones; a failed continuation ends the list, ``message`` says why),
    the basis, the penalty ``eps`` [N/m], the master coordinates and the wall time [s]."""

    points: list
    basis: FourierBasis
    eps: float
    masters: np.ndarray
    wall_time: float
    message: str = ""
    notes: list = field(default_factory=list)

    @property
    def success(self) -> bool:
        return self.message == ""

    def array(self, name: str) -> np.ndarray:
        """One field over the points (``"amplitude"``, ``"frequency"``, ``"damping_ratio"``,
        ``"energy"``, ``"omega"``, ``"xi"``)."""
        return np.array([getattr(p, name) for p in self.points])


class ModeProblem:
    """Residual and Jacobian of the EPMC balance at a prescribed amplitude (module docstring).

    Unknowns ``z = [Y (n H, DOF-major), w, xi]``; equations: the DLFT rows of the contact
    points, the balance of the master coordinates, the amplitude and the phase conditions.
    """

    def __init__(self, system: ModeSystem, contact, basis: FourierBasis, eps: float,
                 anchor: np.ndarray, gap: np.ndarray):
        self.sys, self.contact, self.basis = system, contact, basis
        self._operators: dict = {}  # (w, xi) -> operator(w, xi), the last three
        nc, d = contact.dofs.shape
        self.nc, self.d = nc, d
        self.m, self.n, self.H = system.m, system.size, basis.size
        self.eps = float(eps)
        self.mu = contact.mu_nodes()
        self.normal = contact.normal_force_samples(basis.tau)
        self.anchor = np.asarray(anchor, dtype=float).reshape(nc, d - 1)
        self.W = np.zeros((self.m, self.H))
        self.W[0::d, 0] = gap
        self.P, self.Q = (law.kernel_array(a) for a in basis.matrices())
        F = np.zeros((self.n, self.H))
        F[:, 0] = system.loads()
        self.F = F
        self.orders = basis.orders
        self.amplitude = 1.0
        # the fundamental harmonic's cosine column (None for the static problem alone)
        self.h1 = int(np.flatnonzero(self.orders == 1)[0]) if 1 in self.orders else None
        # phase: the sine of the fundamental of the first master (or, without masters, of the
        # first tangential contact point) is zero
        first = self.m if system.masters.size else 1
        self.phase_row = (first * self.H + self.h1 + basis.k) if self.h1 is not None else 0

    # -- pieces -------------------------------------------------------------------------------
    def operator(self, omega, xi):
        """``(Z~ (n H, n H) real, S1)``: the real block operator at ``(w, xi)`` and the
        recovery of the condensed coordinates at harmonic 1."""
        key = (float(omega), float(xi))
        if key not in self._operators:  # the corrector asks again at the same (w, xi)
            Zc, S = self.sys.stiffness(omega, xi, self.orders)
            if len(self._operators) >= 3:  # the point and its two difference steps
                self._operators.pop(next(iter(self._operators)))
            self._operators[key] = (to_real_blocks(Zc, self.orders), S[self.h1])
        return self._operators[key]

    def amplitude_of(self, Y, S1):
        """Modal amplitude of ``Y`` (n, H) and its gradient (n, H)."""
        k = self.basis.k
        c1 = Y[:, self.h1] - 1j * Y[:, self.h1 + k]  # complex amplitude of harmonic 1
        Mk = self.sys.mass(S1)
        Mc = Mk @ c1
        a = float(np.sqrt(max(np.real(np.vdot(c1, Mc)), 0.0)))
        g = np.zeros_like(Y)
        if a > 0:
            # a^2 = c^H M c with c = y_a - i y_b: d/dy_a = 2 Re(M c), d/dy_b = 2 Im(M c)
            g[:, self.h1] = np.real(Mc) / a
            g[:, self.h1 + k] = np.imag(Mc) / a
        return a, g

    def law(self, Y, Zt):
        """``(lam_u, lam_x, state)`` samples (nc, d, N) of the contact points."""
        ZY = (Zt @ Y.reshape(-1)).reshape(self.n, self.H)
        lu_c = self.F[:self.m] - ZY[:self.m] + self.eps * (Y[:self.m] - self.W)
        lu = np.ascontiguousarray((lu_c @ self.Q.T).reshape(self.nc, self.d, -1))
        lx, state, _ = law.dlft_time(lu, self.mu, self.eps * self.anchor, 1e-12, 200,
                                     self.normal)
        return lu, lx, state, ZY

    def residual(self, z, jacobian=True):
        n, H, m = self.n, self.H, self.m
        Y = z[:n * H].reshape(n, H)
        omega, xi = float(z[-2]), float(z[-1])
        Zt, S1 = self.operator(omega, xi)
        lu, lx, state, ZY = self.law(Y, Zt)
        Lx = lx.reshape(m, -1) @ self.P.T
        f = np.empty(n * H + 2)
        fx = self.eps * (Y[:m] - self.W) - Lx
        fe = ZY[m:] - self.F[m:]
        a, ga = self.amplitude_of(Y, S1)
        scale_a = self.eps * max(self.amplitude, 1e-300)
        f[:m * H] = fx.reshape(-1)
        f[m * H:n * H] = fe.reshape(-1)
        f[-2] = scale_a * (a / self.amplitude - 1.0)
        f[-1] = self.eps * Y.reshape(-1)[self.phase_row]
        if not jacobian:
            return f, None
        G = law.dlft_jacobian(lu, lx, state, self.mu, self.P, self.Q, self.eps * self.anchor,
                              1e-12, 200, self.normal)
        N = n * H
        J = np.zeros((N + 2, N + 2))
        dH = self.d * H
        # contact rows: eps I - G (eps E_x - Z_x.), G block-diagonal per node
        Zx = Zt[:m * H]
        GZ = np.matmul(G, Zx.reshape(self.nc, dH, N)).reshape(m * H, N)
        J[:m * H, :N] = GZ
        for p in range(self.nc):
            sl = slice(p * dH, (p + 1) * dH)
            J[sl, sl] -= self.eps * G[p]
        J[np.arange(m * H), np.arange(m * H)] += self.eps
        J[m * H:N, :N] = Zt[m * H:]
        J[-2, :N] = scale_a / self.amplitude * ga.reshape(-1)
        J[-1, self.phase_row] = self.eps
        # w and xi by forward differences of the operator (the law's derivative chained)
        for col, (dw, dx) in ((-2, (1.0, 0.0)), (-1, (0.0, 1.0))):
            hstep = FD_STEP * max(abs(omega), 1.0)
            Zt2, S2 = self.operator(omega + hstep * dw, xi + hstep * dx)
            dZY = ((Zt2 - Zt) @ Y.reshape(-1)).reshape(n, H) / hstep
            J[:m * H, col] = np.einsum("pij,pj->pi", G, dZY[:m].reshape(self.nc, dH)).ravel()
            J[m * H:N, col] = dZY[m:].reshape(-1)
            a2, _ = self.amplitude_of(Y, S2)
            J[-2, col] = scale_a / self.amplitude * (a2 - a) / hstep
        return f, J

    def scale(self, z):
        n, H = self.n, self.H
        Zt, _ = self.operator(float(z[-2]), float(z[-1]))
        return max(float(np.linalg.norm(Zt @ z[:n * H])), float(np.linalg.norm(self.F)),
                   self.eps * self.amplitude, 1e-300)

    def point(self, z, st) -> ModePoint:
        n, H = self.n, self.H
        Y = z[:n * H].reshape(n, H)
        Zt, _ = self.operator(float(z[-2]), float(z[-1]))
        lu, lx, state, _ = self.law(Y, Zt)
        lam = lu - lx
        node = np.asarray(law.friction_work(lam, lx / self.eps, state), dtype=float)
        omega, xi = float(z[-2]), float(z[-1])
        return ModePoint(self.amplitude, omega, xi, Y.copy(), state, float(node.sum()),
                         bool(st.success), float(st.residual), int(st.iterations), node,
                         self.sys.observed(Y, omega, xi, self.basis))


def _static_start(problem: ModeProblem, omega0: float):
    """The preload state: the balance at harmonic 0 alone (the static contact problem from a
    stress-free state, anchors 0), as the periodic solves take it."""
    basis0 = FourierBasis.static()
    p0 = ModeProblem(problem.sys, problem.contact, basis0, problem.eps,
                     np.zeros_like(problem.anchor), problem.W[0::problem.d, 0])
    n = p0.n

    def fun(x, jac=True):
        Y = x.reshape(n, 1)
        Zt, _ = p0.operator(omega0, 0.0)
        lu, lx, state, ZY = p0.law(Y, Zt)
        f = np.concatenate([(p0.eps * (Y[:p0.m] - p0.W) - lx.reshape(p0.m, -1) @ p0.P.T),
                            ZY[p0.m:] - p0.F[p0.m:]]).reshape(-1)
        if not jac:
            return f, None
        G = law.dlft_jacobian(lu, lx, state, p0.mu, p0.P, p0.Q, p0.eps * p0.anchor, 1e-12,
                              200, p0.normal)
        J = np.array(Zt, dtype=float)
        dH = p0.d
        Jx = np.matmul(G, Zt[:p0.m].reshape(p0.nc, dH, n)).reshape(p0.m, n)
        for p in range(p0.nc):
            sl = slice(p * dH, (p + 1) * dH)
            Jx[sl, sl] -= p0.eps * G[p]
        Jx[np.arange(p0.m), np.arange(p0.m)] += p0.eps
        J[:p0.m] = Jx
        return f, J

    x0 = np.zeros(n)
    x0[:p0.m] = p0.W[:, 0]
    x, _, st = solve(fun, x0, lambda x: max(float(np.linalg.norm(p0.F)), 1e-300),
                     method="powell", tol=1e-10, max_iter=100)
    return x, st


def nonlinear_mode(model: Model, basis: FourierBasis, amplitudes, *, omega_target=None,
                   masters: int = 1, eps="top", options: SolveOptions | None = None,
                   dyn: StructureDynamics | None = None, wear0=None) -> Backbone:
    """The nonlinear mode of ``model`` over the modal ``amplitudes`` (increasing, [m sqrt(kg)])
    by the EPMC (module docstring), from the linear mode of the structure with its contact
    points stuck nearest ``omega_target`` [rad/s] (default: the lowest).

    Parameters
    ----------
    basis : kept harmonics (the fundamental among them) and samples per period.
    amplitudes : (k,) the amplitudes of the result, increasing and positive; the continuation
        inserts intermediate steps where a step fails.
    masters : held modes kept as unknowns (the rest condensed).
    eps : DLFT penalty: a rule of :func:`fretwear.hb.penalty.penalty` (``"top"``: the
        contact spring itself where there is one, the exact value) or a number [N/m].
    options : the corrector's solver, tolerance and iteration cap
        (:class:`~fretwear.hb.options.SolveOptions`; ``strategy`` and ``jacobian`` unused).
    wear0 : (nc,) or a number: wear depths [m]; the mode of the worn interface, whose gap is
        ``gap + wear0`` (as :func:`fretwear.wear.worn_frf.frf_worn`; the static preload
        solved on it). None: the new interface.
    """
    t0 = time.perf_counter()
    opt = SolveOptions() if options is None else options
    amps = np.asarray(amplitudes, dtype=float).ravel()
    if amps.size == 0 or np.any(~np.isfinite(amps)) or np.any(amps <= 0) or np.any(
            np.diff(amps) <= 0):
        raise InputError(f"amplitudes = {amplitudes!r}: expected increasing positive values")
    if 1 not in basis.harmonics:
        raise InputError(f"basis keeps harmonics {list(basis.harmonics)}: nonlinear modes "
                         "need the fundamental (1)")
    system = mode_system(model, omega_target, masters=masters, dyn=dyn)
    # the dense Jacobian of the corrector and the real operator Z~ (n H each side, with
    # their factorisation and products), the complex blocks on every structure coordinate
    # per harmonic order with their condensation, and the points of the backbone
    unknowns = system.size * basis.size + 2
    full = system.m + system.phi.shape[1]
    require_memory(8.0 * 6 * unknowns**2 + 48.0 * basis.orders.size * full**2
                   + 32.0 * amps.size * unknowns,
                   f"a nonlinear mode of {unknowns:,} unknowns ({system.size:,} coordinates x "
                   f"{basis.size} Fourier coefficients) at {amps.size:,} amplitudes")
    c = model.contact
    w0 = (float(system.omega_held[system.masters[0]]) if system.masters.size
          else float(omega_target or 1.0))
    eps_value = (float(eps) if not isinstance(eps, str)
                 else penalty(eps, model=model, frequency=w0 / (2 * np.pi),
                              orders=basis.orders))
    gap = np.broadcast_to(np.asarray(c.gap, dtype=float), (c.n_nodes,)).copy()
    if wear0 is not None:
        w = np.asarray(wear0, dtype=float)
        if w.ndim > 1 or w.size not in (1, c.n_nodes) or not np.all(np.isfinite(w)):
            raise InputError(f"wear0 = {wear0!r}: expected a finite number or {c.n_nodes} "
                             "wear depths [m], one per contact node")
        gap = gap + w
    prob = ModeProblem(system, c, basis, eps_value, np.zeros((c.n_nodes, c.dim - 1)), gap)
    xs, st0 = _static_start(prob, w0)
    notes = []
    if not st0.success:
        notes.append(f"the static preload problem did not converge ({st0.message}): anchors 0")
    n, H, m = prob.n, prob.H, prob.m
    Ys = xs.reshape(n, 1)
    anchor = Ys[:m, 0].reshape(c.n_nodes, c.dim)[:, 1:] if st0.success else prob.anchor
    prob = ModeProblem(system, c, basis, eps_value, anchor, gap)
    # linear start: the static state plus the master mode on the fundamental cosine
    z = np.zeros(n * H + 2)
    Y = z[:n * H].reshape(n, H)
    Y[:, 0] = Ys[:, 0]
    C = system.dyn.blocks.get("C")
    xi0 = 0.0
    if C is not None and system.masters.size:
        ph = system.phi[:, system.masters[0]]
        xi0 = float(ph @ np.asarray(C[3]) @ ph)  # modal damping 2 zeta w of the held mode
    z[-2], z[-1] = w0, xi0
    if system.masters.size:
        Y[m, prob.h1] = 1.0
    else:
        Y[1, prob.h1] = 1.0
    prob.amplitude = amps[0]
    _, S1 = prob.operator(w0, xi0)
    a, _ = prob.amplitude_of(Y, S1)
    Y[:, 1:] *= amps[0] / max(a, 1e-300)
    points: list = []
    history: list = []  # (log a, z) of converged points
    message = ""
    targets = [(float(x), True) for x in amps]  # (amplitude, is a point of the result)
    min_step = max(np.log(amps[-1] / amps[0]), 1.0) / (amps.size * 2 ** MAX_HALVINGS)
    while targets:
        a_t, output = targets[0]
        prob.amplitude = a_t
        zp = _predict(history, np.log(a_t), z, prob)

        def fun(x, jac=True):
            return prob.residual(x, jac)

        zn, _, st = solve(fun, zp, prob.scale, method=opt.solver, tol=opt.tol,
                          max_iter=opt.max_iter)
        if st.success:
            z = zn
            history.append((np.log(a_t), zn.copy()))
            if output:
                points.append(prob.point(zn, st))
            targets.pop(0)
            continue
        if not history or np.log(a_t) - history[-1][0] < 2.0 * min_step:
            message = (f"the corrector did not converge at amplitude {a_t:.4g} "
                       f"({st.message}, relative residual {st.residual:.2g})")
            break
        targets.insert(0, (float(np.exp(0.5 * (history[-1][0] + np.log(a_t)))), False))
    return Backbone(points, basis, eps_value, system.masters, time.perf_counter() - t0,
                    message, notes)


def _predict(history, la, z, prob: ModeProblem):
    """Predictor at ``log a = la``: the secant in ``log a`` through the last two converged
    points for ``w``, ``xi``, the static coefficients and the *shape* of the harmonics (the
    harmonics divided by the amplitude), then scaled to the new amplitude; the last point
    scaled when there is one only; ``z`` (the linear start) when there is none."""
    if not history:
        return z

    def split(lz):
        l_, v = lz
        n, H = prob.n, prob.H
        Y = v[:n * H].reshape(n, H)
        a = np.exp(l_)
        return np.concatenate([Y[:, 0], (Y[:, 1:] / a).ravel(), v[-2:]])

    if len(history) >= 2:
        (l1, _), (l2, _) = history[-2], history[-1]
        s1, s2 = split(history[-2]), split(history[-1])
        t = (la - l2) / (l2 - l1) if l2 != l1 else 0.0
        sp = s2 + t * (s2 - s1)
    else:
        sp = split(history[-1])
    n, H = prob.n, prob.H
    out = np.empty(n * H + 2)
    Y = out[:n * H].reshape(n, H)
    Y[:, 0] = sp[:n]
    Y[:, 1:] = sp[n:n + n * (H - 1)].reshape(n, H - 1) * np.exp(la)
    out[-2:] = sp[-2:]
    return out
