"""Time integration with exact contact and friction, the reference beside the harmonic balance.

The package :mod:`fretwear.timedomain` holds: this integrator; :mod:`.steady` (integrate until
the response repeats, classify it); :mod:`.quasistatic` (incremental wear by load steps);
:mod:`.reduction` (the reduced dynamic model); :mod:`.results` (what they return).

* :func:`integrate` -- fixed-step time integration of ``M U'' + C U' + K U + T^T lam = F(t)``
  with unilateral contact and Coulomb friction solved exactly at every step (no penalty, no
  regularisation).
* :func:`steady_state` -- integrate until the response repeats every period, and classify it
  (periodic, subharmonic, drifting, quasi-periodic), with the harmonics of the last period.
* :func:`incremental_wear` -- quasi-static load steps through each cycle with exact contact and
  friction and Archard wear applied as it goes (in the spirit of Stromberg 1997), optionally
  with cycle jumps.

Scheme (see ``docs/transient.md`` for the derivation and the choices)
-------------------------------------------------------------------
The linear part is Newmark's rule written in its two-step form (``beta = 1/4, gamma = 1/2``
by default: the trapezoidal rule, second order, energy conserving)::

    M (q+ - 2q + q-) + h C [g q+ + (1-2g) q + (g-1) q-]
        + h^2 K [b q+ + (1/2-2b+g) q + (1/2+b-g) q-] = h^2 (F~_n - T^T lam_n)

with ``q+- = q_{n+-1}``, ``F~_n`` the same weighted average of the loads, and the contact
force ``lam_n`` (the force at ``t_n``) chosen so that the positions ``q_{n+1}`` satisfy
Signorini exactly and the slip increment ``x_T(n+1) - x_T(n)`` satisfies Coulomb exactly
(stick: the increment is exactly zero). With ``gamma = 1/2`` the discrete energy
``E_{n+1/2} = 1/2 w^T M w + 1/2 qm^T K qm`` (``w = (q_{n+1} - q_n)/h``,
``qm = (q_{n+1} + q_n)/2``) obeys exactly
``E_{n+1/2} - E_{n-1/2} = F~_n . (q_{n+1} - q_{n-1})/2 - damping - lam_n . (x_{n+1} - x_{n-1})/2``.

Speed: for a fixed step the step matrix is constant, so the structure is reduced exactly
(Craig-Bampton on the contact DOFs with the fixed-interface modes below a cutoff and one
static mode per load vector), diagonalised, and each step is a small dense update plus one
contact problem (numba kernels in :mod:`fretwear.timedomain.kernels` and
:mod:`fretwear.timedomain.contact_solve`).

Damping: the viscous ``C`` as given; the hysteretic ``D`` has no causal time-domain form and
is replaced by the equivalent viscous damping at the forcing frequency, ``C_eq = D / omega``.
"""

from __future__ import annotations

import time
import warnings

import numpy as np
import scipy.linalg as sla

from fretwear.errors import InputError
from fretwear.limits import check_range
from fretwear.model.core import Model
from fretwear.resources import require_memory
from fretwear.timedomain.checks import c_float, count, node_wear, positive
from fretwear.timedomain.contact_solve import OPEN, STICK, Contact, ContactState, Settings
from fretwear.timedomain.kernels import (
    DynamicState,
    EnergyTerms,
    Records,
    StepOperator,
    run_dynamic,
)
from fretwear.timedomain.options import (
    DEFAULT_STEPS,
    INTEGRATION,
    InitialState,
    IntegrationOptions,
)
from fretwear.timedomain.reduction import HF_GAMMA, HF_LIMIT, reduce_dynamics, submatrix
from fretwear.timedomain.results import TransientResult

__all__ = ["DEFAULT_STEPS", "InitialState", "IntegrationOptions", "Integrator", "integrate"]

CHUNK_STEPS = 2_000_000  # steps per kernel call (progress, interruption)


# --------------------------------------------------------------------------------------------
# the time stepper
# --------------------------------------------------------------------------------------------
class Integrator:
    """Holds the reduced step operator and the current state; runs whole periods."""

    def __init__(self, model: Model, omega: float, options: IntegrationOptions = INTEGRATION,
                 start: InitialState | None = None):
        """The step operator of ``model`` at ``omega`` [rad/s] with ``options``, in the state
        ``start`` (default: rest, unworn)."""
        if not isinstance(options, IntegrationOptions):
            raise InputError(f"options = {options!r}; expected an IntegrationOptions(...)")
        start = InitialState() if start is None else start
        if not isinstance(start, InitialState):
            raise InputError(f"start = {start!r}; expected an InitialState(U0, V0, wear, "
                             "anchor)")
        self.model = model
        self.omega = positive(omega, "omega")
        self.N = N = options.steps_per_period
        self.gamma = gamma = options.gamma
        self.tol = options.contact_tol
        t0 = time.perf_counter()
        red = self.red = reduce_dynamics(model, self.omega, modal_cutoff=options.modal_cutoff,
                                         n_modes=options.n_modes, steps_per_period=N)
        c = model.contact
        self.nc, self.d = c.dofs.shape
        self.m = self.nc * self.d
        self.h = h = 2.0 * np.pi / (self.omega * N)
        r = red.basis.shape[1]
        # Newmark parameters, per mode in modal coordinates (high modes may get more damping)
        g = np.full(r, gamma)
        if red.diag and options.hf_damping:
            g[np.sqrt(np.maximum(red.K, 0.0)) * h > HF_LIMIT] = HF_GAMMA
        b = 0.25 * (g + 0.5) ** 2
        self.g_modes = g
        w1, w0, wm = b, 0.5 - 2 * b + g, 0.5 + b - g
        # loads per phase, reduced, and the two-step weighted average F~_k
        tau = 2.0 * np.pi * np.arange(N) / N
        Ft = model.load_time(tau)[:, red.free] if model.loads else np.zeros((N, red.free.size))
        self.fscale = float(np.abs(Ft).max()) if Ft.size else 0.0
        Fr = Ft @ red.basis
        self.Fr = Fr
        self.ftil = w1 * np.roll(Fr, -1, axis=0) + w0 * Fr + wm * np.roll(Fr, 1, axis=0)
        z0 = np.zeros((0, 0))
        if red.diag:
            G = self._diagonal_step(g, b, wm)
        else:
            G = self._dense_step(b[0], wm[0])
        self.ftab = np.ascontiguousarray(self.ftab)
        self.G = np.ascontiguousarray(G)
        self.A = self._inverse_delassus(G)
        self.gap = np.asarray(c.gap, dtype=float) + node_wear(start.wear, self.nc)
        if red.diag:
            m_v, k_v, c_v = red.M, red.K, red.C
            m_m = k_m = c_m = z0
        else:
            m_v = k_v = c_v = np.zeros(0)
            m_m, k_m, c_m = red.M, red.K, red.C
        red.Tx = c_float(red.Tx)
        red.obs = c_float(red.obs)
        # the kernel's records; one compiled specialisation: every array is C-contiguous
        # float64 and every scalar a Python bool, float or int
        self.op = StepOperator(
            bool(red.diag), *(c_float(a) for a in (
                self.a_v, self.b_v, self.ds, self.hc, self.U, self.R, self.P, self.Qt,
                self.bq_m, self.bd_m, self.ftab, self.G, red.Tx, red.obs)))
        self.energy = EnergyTerms(float(h), *(c_float(a) for a in (
            self.ftil, m_v, k_v, c_v, m_m, k_m, c_m)))
        self.contact = Contact(self.A, c_float(self.gap), c_float(c.mu_nodes()), int(self.d))
        self.settings = Settings(float(self.tol), float(self.fscale), int(60 + 4 * self.nc))
        self.setup_time = time.perf_counter() - t0
        self.r = r
        # initial state
        self._set_state(start.U0, start.V0, start.anchor)
        self.periods_done = 0
        self.n_fail = 0
        self.max_it = 0
        self.first_fail_time = None

    # the step operator -------------------------------------------------------------------------
    def _diagonal_step(self, g, b, wm):
        """The step in modal coordinates (diagonal mass, stiffness and damping plus the
        low-rank ``U R U^T``): its per-mode weights, the Woodbury factors of ``S^-1``, the
        forcing increments ``ftab``; returns ``G = h^2 S^-1 Tx^T``."""
        red, h = self.red, self.h
        k, mm, cc, U, R = red.K, red.M, red.C, red.U, red.R
        ds = mm + g * h * cc + b * h * h * k
        self.a_v = mm - (1 - g) * h * cc + wm * h * h * k
        self.b_v = -h * h * k
        self.ds = ds
        self.hc = (1 - g) * h
        # S^-1 = (Ds + Gam U R U^T)^-1 = Ds^-1 - P Qt (Woodbury), Gam = diag(g h)
        self.P = np.ascontiguousarray((g * h / ds)[:, None] * U)
        core = np.eye(U.shape[1]) + R @ (U.T @ self.P)
        self.Qt = np.ascontiguousarray(np.linalg.solve(core, R @ (U.T / ds[None, :])))
        self.U, self.R = U, R

        def s_inv(Y):
            return Y / ds[:, None] - self.P @ (self.Qt @ Y)

        self.bq_m = self.bd_m = np.zeros((0, 0))
        self.ftab = h * h * s_inv(self.ftil.T).T
        return h * h * s_inv(red.Tx.T)

    def _dense_step(self, b: float, wm: float):
        """The step with dense reduced matrices (one LU of ``S``): ``S^-1 B_q``, ``S^-1 B_d``,
        the forcing increments ``ftab``; returns ``G = h^2 S^-1 Tx^T``."""
        red, h, gamma, r = self.red, self.h, self.gamma, self.red.basis.shape[1]
        z0 = np.zeros((0, 0))
        S2 = red.M + gamma * h * red.C + b * h * h * red.K
        lu = sla.lu_factor(S2)
        self.bq_m = -h * h * sla.lu_solve(lu, red.K)
        self.bd_m = sla.lu_solve(lu, red.M - (1 - gamma) * h * red.C + wm * h * h * red.K)
        self.a_v = self.b_v = self.ds = self.hc = np.zeros(0)
        self.U, self.R, self.P, self.Qt = np.zeros((r, 0)), z0, np.zeros((r, 0)), z0
        self.ftab = h * h * sla.lu_solve(lu, self.ftil.T).T
        return h * h * sla.lu_solve(lu, red.Tx.T)

    def _inverse_delassus(self, G) -> np.ndarray:
        """``A = W^-1``, ``W = Tx G`` the contact DOFs' step mobility (symmetrised)."""
        W = self.red.Tx @ G
        W = 0.5 * (W + W.T)
        try:
            cf = sla.cho_factor(W)
            A = sla.cho_solve(cf, np.eye(self.m))
        except np.linalg.LinAlgError:
            raise InputError("the contact DOFs' step mobility (Delassus operator) is singular: "
                             "a contact direction carries no mass nor stiffness") from None
        return np.ascontiguousarray(0.5 * (A + A.T))

    # state <-> full vectors ------------------------------------------------------------------
    def _project(self, U, what):
        n = self.model.ndof
        U = np.asarray(U, dtype=float)
        if U.shape != (n,) or not np.all(np.isfinite(U)):
            raise InputError(f"{what} has shape {U.shape}; expected ({n},) finite values")
        Uf = U[self.red.free]
        if self.red.modal:  # M-orthogonal projection (exact for vectors of the basis)
            Mf = submatrix(self.model.M.tocsr(), self.red.free, self.red.free)
            return self.red.basis.T @ (Mf @ Uf)
        return np.linalg.lstsq(self.red.basis, Uf, rcond=None)[0]

    def _accel(self, q, k):
        """Reduced acceleration without damping and contact at phase k (restart convention)."""
        red = self.red
        if red.diag:
            return (self.Fr[k] - red.K * q) / red.M
        try:
            return np.linalg.solve(red.M, self.Fr[k] - red.K @ q)
        except np.linalg.LinAlgError:
            return np.zeros(self.r)

    def _set_state(self, U0, V0, anchor):
        q = np.zeros(self.r) if U0 is None else self._project(U0, "U0")
        v = np.zeros(self.r) if V0 is None else self._project(V0, "V0")
        # midpoint velocity w_{-1/2} = V0 - h/2 a0 (a0 without damping and contact)
        w = v - 0.5 * self.h * self._accel(q, 0)
        self.q = q
        self.dq = self.h * w
        Tx = self.red.Tx
        self.xprev = Tx @ q
        self.xprev2 = Tx @ (q - self.dq)
        d = self.d
        if anchor is not None:
            a = np.asarray(anchor, dtype=float)
            if a.shape == (self.nc,) and d == 2:
                a = a[:, None]
            if a.shape != (self.nc, d - 1):
                raise InputError(f"anchor has shape {a.shape}; expected ({self.nc}, "
                                 f"{d - 1}) tangential positions [m]")
            xp = self.xprev.reshape(self.nc, d)
            xp[:, 1:] = a
        xN = self.xprev.reshape(self.nc, d)[:, 0]
        tolx = 1e-9 * max(np.abs(self.xprev).max(initial=0.0), np.abs(self.gap).max(initial=0.0),
                          1e-30)
        self.status = np.where(xN >= self.gap - tolx, STICK, OPEN).astype(np.int8)
        self.tdir = np.zeros((self.nc, d - 1))
        self.tdir[:, 0] = 1.0

    def full_state(self):
        """Final ``(U, V)`` full vectors with the restart convention ``V = w + h/2 a``."""
        n = self.model.ndof
        U = np.zeros(n)
        V = np.zeros(n)
        U[self.red.free] = self.red.basis @ self.q
        w = self.dq / self.h
        v = w + 0.5 * self.h * self._accel(self.q, 0)
        V[self.red.free] = self.red.basis @ v
        return U, V

    # running -----------------------------------------------------------------------------------
    def run(self, n_periods: int, n_record: int = 0, n_keep: int = 0, progress=False):
        """Run ``n_periods`` periods; record every step of the last ``n_record`` periods and
        keep the once-per-period monitors of the last ``n_keep`` periods."""
        N, m, nc = self.N, self.m, self.nc
        no = self.red.obs.shape[0]
        ns = n_record * N
        r_obs = np.zeros((ns, no))
        r_vobs = np.zeros((ns, no))
        r_x = np.zeros((ns, m))
        r_lam = np.zeros((ns, m))
        r_state = np.zeros((ns, nc), dtype=np.int8)
        r_energy = np.zeros((ns, 6))
        nmon = no + m
        mon_start = np.zeros((n_keep, nmon))
        mon_mean = np.zeros((n_keep, nmon))
        mon_ptp = np.zeros((n_keep, nmon))
        p0 = self.periods_done
        rec_from = (p0 + n_periods - n_record) * N
        keep_from = p0 + n_periods - n_keep
        chunk = max(1, CHUNK_STEPS // N)
        bar = None
        if progress:
            try:
                from tqdm import tqdm

                bar = tqdm(total=n_periods, unit="period")
            except ImportError:  # pragma: no cover
                bar = None
        state = DynamicState(self.q, self.dq, self.xprev, self.xprev2,
                             ContactState(self.status, self.tdir))
        rec = Records(int(keep_from), mon_start, mon_mean, mon_ptp, int(rec_from), r_obs,
                      r_vobs, r_x, r_lam, r_state, r_energy)
        done = 0
        while done < n_periods:
            k = min(chunk, n_periods - done)
            nfail, maxit, ff = run_dynamic(self.op, self.energy, self.contact, self.settings,
                                           state, rec, k, self.periods_done * N)
            if nfail and self.first_fail_time is None:
                self.first_fail_time = ff * self.h
            self.n_fail += nfail
            self.max_it = max(self.max_it, maxit)
            self.periods_done += k
            done += k
            if bar is not None:
                bar.update(k)
        if bar is not None:
            bar.close()
        return dict(obs=r_obs, vobs=r_vobs, x=r_x, lam=r_lam, state=r_state, energy=r_energy,
                    mon_start=mon_start, mon_mean=mon_mean, mon_ptp=mon_ptp,
                    t0=rec_from * self.h)

    def result(self, raw, n_periods, wall) -> TransientResult:
        N, nc, d = self.N, self.nc, self.d
        ns = raw["obs"].shape[0]
        t = raw["t0"] + self.h * np.arange(ns)
        observed, velocities, poinc, pmean = {}, {}, {}, {}
        for name, sl in zip(self.red.obs_names, self.red.obs_slices, strict=True):
            observed[name] = raw["obs"][:, sl].copy()
            velocities[name] = raw["vobs"][:, sl].copy()
            poinc[name] = raw["mon_start"][:, sl].copy()
            pmean[name] = raw["mon_mean"][:, sl].copy()
        e = raw["energy"]
        energy = {"external": e[:, 0].copy(), "friction": e[:, 1].copy(),
                  "normal": e[:, 2].copy(), "damping": e[:, 3].copy(),
                  "mechanical": e[:, 4].copy(), "numerical": e[:, 5].copy()}
        U, V = self.full_state()
        info = dict(self.red.info)
        wmax = float(np.sqrt(max(np.max(np.diag(self.red.K) if self.red.K.ndim == 2
                                        else self.red.K), 0.0)))
        info.update(h=self.h, gamma=self.gamma, setup_time=self.setup_time,
                    steps_per_highest_period=(2 * np.pi / (wmax * self.h)) if wmax > 0 else np.inf,
                    hf_damped_modes=int(np.sum(self.g_modes > self.gamma)),
                    failed_steps=self.n_fail, max_active_set_iterations=self.max_it,
                    first_failure_time=self.first_fail_time, periods_total=self.periods_done)
        message = f"integrated {n_periods} periods"
        if self.n_fail:
            message = (f"{self.n_fail} contact solves did not settle (first at t = "
                       f"{self.first_fail_time:.6g} s)")
            warnings.warn(f"{message}; results there are approximate", RuntimeWarning,
                          stacklevel=3)
        return TransientResult(
            t=t, observed=observed, velocities=velocities,
            u_loc=raw["x"].reshape(ns, nc, d), lam=raw["lam"].reshape(ns, nc, d),
            state=raw["state"], energy=energy, n_periods=n_periods, steps_per_period=N,
            omega=self.omega, wall_time=wall, U=U, V=V, poincare=poinc, period_mean=pmean,
            info=info, success=not self.n_fail, message=message)


def integrate(model: Model, frequency: float, *, n_periods: int,
              options: IntegrationOptions = INTEGRATION, start: InitialState | None = None,
              record="last", keep_poincare: int = 10_000, progress: bool = False
              ) -> TransientResult:
    """Integrate the forced response in time with exact contact and friction.

    Parameters
    ----------
    model : the structure (:class:`~fretwear.model.core.Model`).
    frequency : forcing frequency ``f`` [Hz]; the loads are ``F(omega t)``, ``omega = 2 pi f``.
    n_periods : number of forcing periods ``T = 1 / f`` to simulate.
    options : :class:`~fretwear.timedomain.options.IntegrationOptions`: steps per period,
        Newmark gamma, high-frequency damping, modal reduction, contact solver tolerance.
    start : :class:`~fretwear.timedomain.options.InitialState`: initial displacement and
        velocity (default rest; ``result.U, result.V`` continue a run exactly), wear, stick
        anchors.
    record : ``"last"`` (the last period) or the number of periods recorded at the end
        (every step), 0 for none.
    keep_poincare : once-per-period samples kept (the last ones).
    progress : show a progress bar.

    Returns
    -------
    :class:`TransientResult`: ``success`` (every contact solve settled), ``message``, the
    recorded samples (times [s], displacements [m], forces [N], energies [J]) and the final
    state ``U, V`` to continue the run.
    """
    n_periods = count(n_periods, "n_periods", 1)
    if record == "last":
        n_rec = 1
    else:
        n_rec = count(record, "record", 0)
        if n_rec > n_periods:
            raise InputError(f"record = {record} periods but n_periods = {n_periods}")
    n_keep = min(count(keep_poincare, "keep_poincare", 0), n_periods)
    omega = 2 * np.pi * check_range(positive(frequency, "frequency"), "frequency", "frequency")
    if not isinstance(options, IntegrationOptions):
        raise InputError(f"options = {options!r}; expected an IntegrationOptions(...)")
    steps = options.steps_per_period
    # recorded samples: observed displacements and velocities, contact positions and forces,
    # states and six energy terms per step [8 bytes each]
    width = 2 * model.ndof + 2 * model.contact.dofs.size + model.contact.n_nodes + 6
    require_memory(8.0 * n_rec * steps * width,
                   f"recording {n_rec} periods of {steps} time steps")
    integ = Integrator(model, omega, options, start)
    # once-per-period monitors of the kept periods: start, mean and range of the observed and
    # contact coordinates [8 bytes each]
    require_memory(8.0 * 3 * n_keep * (integ.red.obs.shape[0] + integ.m),
                   f"keeping the once-per-period samples of {n_keep} periods")
    t0 = time.perf_counter()
    raw = integ.run(n_periods, n_rec, n_keep, progress=progress)
    wall = time.perf_counter() - t0
    return integ.result(raw, n_periods, wall)
