"""Time-domain reference solvers, independent of the harmonic balance.

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
contact problem (numba kernels in :mod:`fretwear.timedomain.kernels`).

Damping: the viscous ``C`` as given; the hysteretic ``D`` has no causal time-domain form and
is replaced by the equivalent viscous damping at the forcing frequency, ``C_eq = D / omega``.
"""

from __future__ import annotations

import inspect
import math
import time
import warnings
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from fretwear.errors import ConvergenceError, InputError
from fretwear.hb.reduce import condense_static
from fretwear.limits import check_range
from fretwear.model.core import Model
from fretwear.timedomain.kernels import (
    OPEN,
    STICK,
    Contact,
    ContactState,
    DynamicState,
    EnergyTerms,
    LoadCycle,
    Records,
    Settings,
    StepOperator,
    WearRecords,
    WearState,
    run_dynamic,
    run_quasistatic,
)

__all__ = [
    "Classification",
    "IncrementalWearResult",
    "SteadyStateResult",
    "TransientResult",
    "classify_sequence",
    "fourier_coefficients",
    "incremental_wear",
    "integrate",
    "steady_state",
]

DEFAULT_STEPS = 256  # time steps per forcing period (case files take it too)
CUTOFF_STEPS = 8  # default cutoff: modes whose period spans at least this many steps
DENSE_EIG_LIMIT = 3000  # interior DOFs up to which the fixed-interface modes are found densely
CHUNK_STEPS = 2_000_000  # steps per kernel call (progress, interruption)
HF_LIMIT = 1.0  # hf_damping: modes with omega_j h above this (< 2 pi steps per period) ...
HF_GAMMA = 1.0  # ... are integrated with this Newmark gamma (spectral radius 1/3 at infinity)


# --------------------------------------------------------------------------------------------
# results
# --------------------------------------------------------------------------------------------
@dataclass
class TransientResult:
    """Output of :func:`integrate`.

    ``success`` is True when the integration completed with every contact solve settled;
    ``message`` says what happened (e.g. ``"integrated 100 periods"``, ``"12 contact solves
    did not settle (first at t = 0.0123 s)"``). Samples are taken at ``t_n = n h``
    (``h = T / steps_per_period``) for every step of the recorded periods (the last
    ``record`` periods), ``t`` counted from the start of the run.

    Attributes
    ----------
    t : (ns,) times [s].
    observed : name -> (ns, d) displacement of each observed point [m].
    velocities : name -> (ns, d) velocity [m/s] (``(U_{n+1} - U_{n-1}) / 2h``).
    u_loc : (ns, nc, d) local contact displacements ``[u_N, u_T...]`` [m].
    lam : (ns, nc, d) contact forces in the local frame [N] (the force at ``t_n``).
    state : (ns, nc) int8: 0 = separation, 1 = stick, 2 = slip (over the step ``t_n -> t_n+1``).
    energy : name -> (ns,) [J]: ``"external"`` work of the loads, ``"friction"`` dissipation,
        ``"normal"`` work of the normal contact forces (impacts, >= 0), ``"damping"``
        dissipation, each cumulative from the first recorded sample; ``"mechanical"`` kinetic +
        elastic energy at ``t_n + h/2``; ``"numerical"`` the algorithmic dissipation (zero to
        round-off for ``gamma = 1/2``). Balance:
        ``mechanical[j] - mechanical[0] = external - friction - normal - damping - numerical``.
    n_periods : forcing periods simulated. steps_per_period : steps per period.
    omega : forcing circular frequency ``2 pi frequency`` [rad/s] (``frequency``: [Hz]).
    wall_time : [s].
    U, V : (ndof,) final displacement [m] and velocity [m/s] (pass them as ``U0, V0`` to
        continue the run exactly).
    poincare : name -> (np, d) observed displacement at the start of each kept period [m].
    period_mean : name -> (np, d) mean over each kept period [m].
    info : reduction and solver statistics.
    success : every contact solve settled; message : what happened.
    """

    t: np.ndarray
    observed: dict
    velocities: dict
    u_loc: np.ndarray
    lam: np.ndarray
    state: np.ndarray
    energy: dict
    n_periods: int
    steps_per_period: int
    omega: float
    wall_time: float
    U: np.ndarray
    V: np.ndarray
    poincare: dict = field(default_factory=dict)
    period_mean: dict = field(default_factory=dict)
    info: dict = field(default_factory=dict)
    success: bool = True
    message: str = ""

    @property
    def frequency(self) -> float:
        """Forcing frequency [Hz]."""
        return self.omega / (2 * np.pi)

    def energy_residual(self) -> float:
        """Largest ``|dE - (W_ext - D_fric - D_normal - D_damp - D_num)|`` over the record [J]."""
        e = self.energy
        if self.t.size == 0:
            return 0.0
        lhs = e["mechanical"] - e["mechanical"][0]
        rhs = e["external"] - e["friction"] - e["normal"] - e["damping"] - e["numerical"]
        return float(np.max(np.abs(lhs - rhs)))


@dataclass
class Classification:
    """Verdict of :func:`classify_sequence` on a sequence of once-per-period samples.

    kind : ``"periodic"`` (repeats every period to ``tol``), ``"subharmonic"`` (repeats every
        ``order`` periods), ``"drifting"`` (the period means move steadily: ratcheting),
        ``"quasi-periodic"`` (bounded, not decaying, not repeating, with a spectral peak at a
        non-zero frequency of the Poincare sequence), ``"irregular"`` (bounded, not decaying,
        no dominant peak), or ``"transient"`` (still converging: undecided).
    periodicity_error : estimated distance to a periodic orbit over ``scale``: the largest
        ``|P_k - P_{k-1}|`` over the last ``n_confirm`` periods divided by ``1 - rho``, rho the
        observed contraction ratio of these differences (capped at 0.99).
    scale : amplitude used to make the errors relative (unit of the samples).
    order : repetition period in forcing periods (1 if periodic, 0 if none).
    drift_rate : largest slope of the period means [unit per period].
    decay : rms deviation of the Poincare samples in the second half of the window over that
        in the first half (< 1: decaying transient; ~1: sustained).
    rotation : dominant frequency of the Poincare sequence [cycles per period], in (0, 0.5];
        the physical frequency is ``(j +- rotation) f`` for an unknown integer ``j`` (aliasing).
    peak_ratio : spectral peak over the median of the spectrum.
    n : number of samples used.
    """

    kind: str
    periodicity_error: float
    scale: float
    order: int = 0
    drift_rate: float = 0.0
    decay: float = float("nan")
    rotation: float = 0.0
    peak_ratio: float = 0.0
    n: int = 0


@dataclass
class SteadyStateResult:
    """Output of :func:`steady_state`.

    Attributes
    ----------
    success : the response was classified (not ``"transient"`` at ``max_periods``) and every
        contact solve settled.
    message : what happened, e.g. ``"periodic after 412 periods"``, ``"still transient after
        20000 periods"``, ``"...; 12 contact solves did not settle"``.
    classification : see :class:`Classification` (``kind``).
    n_periods : periods integrated (including the recorded last one).
    periodic : True for ``"periodic"`` (and ``"subharmonic"``).
    last : :class:`TransientResult` of the last period (every step recorded).
    harmonics : name -> (2 nh + 1, d) real Fourier coefficients of the observed displacement
        over the last period [m], basis ``[a0, a1..a_nh, b1..b_nh]``
        (``x(t) = a0 + sum a_n cos(n w t) + b_n sin(n w t)``, t from the period start).
    contact_harmonics : ``"lam"`` -> (2 nh + 1, nc, d) [N], ``"u_loc"`` -> (2 nh + 1, nc, d) [m].
    diagnostics : the final :class:`Classification`.
    poincare : (np, nmon) once-per-period samples of the monitored quantities (observed DOFs
        then contact local displacements) over the last window [m].
    U, V : final state [m], [m/s]. wall_time : [s]. info : solver statistics.
    """

    success: bool
    message: str
    classification: str
    n_periods: int
    periodic: bool
    last: TransientResult
    harmonics: dict
    contact_harmonics: dict
    diagnostics: Classification
    poincare: np.ndarray
    U: np.ndarray
    V: np.ndarray
    wall_time: float
    info: dict = field(default_factory=dict)


@dataclass
class IncrementalWearResult:
    """Output of :func:`incremental_wear` (one row per recorded computed cycle).

    success : every load step's contact problem settled; message : what happened (e.g.
    ``"100 cycles (100 computed, 6400 load steps)"``, or how many load steps did not settle).

    cycles : (nrec,) number of load cycles done (computed cycles times their jumps).
    wear : (nrec, nc) wear depth [m] at the end of the cycle.
    pressure : (nrec, nc) contact pressure ``lam_N / area`` averaged over the cycle [Pa].
    slip : (nrec, nc) slip distance over the computed cycle [m].
    worn_volume : (nrec,) ``sum wear * area`` [m^3].
    dissipation : (nrec,) friction dissipation over the computed cycle [J].
    computed_cycles, cycle_jump, steps_per_cycle, k_w [1/Pa], wall_time [s].
    U : (ndof,) final displacement [m] (end of the last cycle, phase 0).
    lam : (nc, d) final contact forces [N]. info : solver statistics.
    """

    success: bool
    message: str
    cycles: np.ndarray
    wear: np.ndarray
    pressure: np.ndarray
    slip: np.ndarray
    worn_volume: np.ndarray
    dissipation: np.ndarray
    computed_cycles: int
    cycle_jump: int
    steps_per_cycle: int
    k_w: float
    wall_time: float
    U: np.ndarray
    lam: np.ndarray
    info: dict = field(default_factory=dict)


# --------------------------------------------------------------------------------------------
# small helpers
# --------------------------------------------------------------------------------------------
def fourier_coefficients(samples: np.ndarray, harmonics: int) -> np.ndarray:
    """Real Fourier coefficients of samples over exactly one period (axis 0).

    ``harmonics`` (``nh``) is the highest harmonic kept. Returns ``(2 nh + 1, ...)``:
    ``[a0, a1..a_nh, b1..b_nh]`` with ``a0`` the mean, ``a_n = 2 Re X_n / N``,
    ``b_n = -2 Im X_n / N`` (``X = rfft(samples)``), so that
    ``x(t_k) = a0 + sum a_n cos(2 pi n k / N) + b_n sin(2 pi n k / N)``.
    """
    x = np.asarray(samples, dtype=float)
    N = x.shape[0]
    nh = int(harmonics)
    if nh < 0 or 2 * nh >= N:
        raise InputError(f"harmonics = {harmonics}: need 0 <= harmonics < N/2 = {N / 2:g} "
                         "(samples per period)")
    X = np.fft.rfft(x, axis=0)
    out = np.empty((2 * nh + 1,) + x.shape[1:])
    out[0] = X[0].real / N
    out[1:nh + 1] = 2.0 * X[1:nh + 1].real / N
    out[nh + 1:] = -2.0 * X[1:nh + 1].imag / N
    return out


def _positive(value, what: str) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{what} = {value!r}; expected a positive number") from None
    if not (math.isfinite(v) and v > 0.0):
        raise InputError(f"{what} = {value!r}; expected a positive finite number")
    return v


def _count(value, what: str, minimum: int = 1) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise InputError(f"{what} = {value!r}; expected an integer >= {minimum}")
    if value < minimum:
        raise InputError(f"{what} = {value}; expected an integer >= {minimum}")
    return int(value)


def _c_float(a) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=float)


def _check_contact(model: Model) -> None:
    c = model.contact
    dofs = np.asarray(c.dofs)
    if dofs.ndim != 2 or dofs.shape[0] == 0 or dofs.shape[1] not in (2, 3):
        raise InputError(f"contact.dofs has shape {dofs.shape}; expected (nc >= 1, 2 or 3)")
    if np.unique(dofs).size != dofs.size:
        raise InputError("contact.dofs: a DOF belongs to two contact nodes (or twice to one); "
                         "the time-domain solver needs distinct contact DOFs")
    fixed = np.intersect1d(dofs.ravel(), np.asarray(model.fixed_dofs, dtype=np.int64))
    if fixed.size:
        raise InputError(f"contact DOF {int(fixed[0])} is also a fixed DOF; a contact node must "
                         "be free to move in all its directions for the time-domain solver")
    if not (np.isfinite(c.mu) and c.mu >= 0.0):
        raise InputError(f"contact.mu = {c.mu!r}; expected a friction coefficient >= 0")


def _node_wear(wear, nc: int, what: str = "wear") -> np.ndarray:
    if wear is None:
        return np.zeros(nc)
    w = np.asarray(wear, dtype=float)
    if w.shape != (nc,) or not np.all(np.isfinite(w)):
        raise InputError(f"{what} has shape {w.shape}; expected ({nc},) finite depths [m] (one "
                         "per contact node)")
    return w.copy()


# --------------------------------------------------------------------------------------------
# reduction (Craig-Bampton on the contact DOFs + static load modes, then diagonalised)
# --------------------------------------------------------------------------------------------
@dataclass
class _Reduced:
    free: np.ndarray  # free DOFs of the model
    basis: np.ndarray  # (nf, r): U_free = basis @ q
    K: np.ndarray  # (r,) if diag else (r, r)
    M: np.ndarray
    C: np.ndarray  # (r,) diagonal part if diag (the damping is diag(C) + U R U^T)
    U: np.ndarray  # (r, s) low-rank damping factor (diag only)
    R: np.ndarray  # (s, s)
    diag: bool
    modal: bool  # basis M-orthonormal (basis^T M basis = I)
    Tx: np.ndarray  # (m, r) local contact displacements
    obs: np.ndarray  # (no, r) rows of the observed DOFs
    obs_names: list
    obs_slices: list
    info: dict


def _sub(A, rows, cols):
    return A[rows][:, cols]


def _fixed_interface_modes(Kii, Mii, w_cut: float | None, n_modes: int | None):
    """Eigenpairs of ``Kii phi = w^2 Mii phi`` (mass-normalised), below ``w_cut`` or the first
    ``n_modes``."""
    ni = Kii.shape[0]
    if ni == 0 or n_modes == 0:
        return np.zeros(0), np.zeros((ni, 0))
    if ni <= DENSE_EIG_LIMIT:
        Kd, Md = Kii.toarray(), Mii.toarray()
        try:
            if n_modes is not None:
                k = min(n_modes, ni)
                w2, V = sla.eigh(Kd, Md, subset_by_index=(0, k - 1))
            else:
                w2, V = sla.eigh(Kd, Md, subset_by_value=(-np.inf, w_cut**2))
        except np.linalg.LinAlgError as exc:
            raise InputError("the interior mass matrix (contact DOFs held) is not positive "
                             f"definite ({exc}); use modal_cutoff='all'") from None
        return w2, V
    # large models: shift-invert Lanczos, increasing the count until past the cutoff
    k = n_modes if n_modes is not None else 20
    while True:
        k = min(k, ni - 2)
        w2, V = spla.eigsh(Kii.tocsc(), k=k, M=Mii.tocsc(), sigma=0.0, which="LM")
        order = np.argsort(w2)
        w2, V = w2[order], V[:, order]
        if n_modes is not None:
            return w2, V
        if w2[-1] > w_cut**2 or k >= ni - 2:
            keep = w2 <= w_cut**2
            return w2[keep], V[:, keep]
        k *= 2


def _damping_split(K, M, C):
    """Write ``C = a K + b M + R`` with ``R`` non-zero on few DOFs.

    Structural damping is usually Rayleigh-like (``a K0 + b M``, or ``eta K0 / omega`` for a
    hysteretic loss factor) while springs to ground are undamped, so ``C - a K - b M`` lives
    on the spring DOFs only. ``a, b`` are fitted on the entries of the matrices, leaving out
    the rows that do not fit (robust least squares). Returns ``(a, b, S, R_SS)`` with ``S``
    the DOFs where ``R`` is non-zero; ``S`` may be large when ``C`` has no such structure.
    """
    scale = abs(C).max() if C.nnz else 0.0
    if scale == 0.0:
        return 0.0, 0.0, np.zeros(0, dtype=np.int64), np.zeros((0, 0))
    pat = (abs(K) + abs(M) + abs(C)).tocoo()
    rows, cols = pat.row, pat.col
    kv = np.asarray(K[rows, cols]).ravel()
    mv = np.asarray(M[rows, cols]).ravel()
    cv = np.asarray(C[rows, cols]).ravel()
    sk = np.abs(kv).max() or 1.0
    sm = np.abs(mv).max() or 1.0
    kn, mn = kv / sk, mv / sm
    # per-row 2x2 least squares, then the median over the rows (outlier rows are few)
    n = K.shape[0]
    skk = np.bincount(rows, kn * kn, n)
    skm = np.bincount(rows, kn * mn, n)
    smm = np.bincount(rows, mn * mn, n)
    skc = np.bincount(rows, kn * cv, n)
    smc = np.bincount(rows, mn * cv, n)
    det = skk * smm - skm**2
    ok = det > 1e-12 * (skk * smm + 1e-300)
    if ok.any():
        a = float(np.median((smm * skc - skm * smc)[ok] / det[ok]))
        b = float(np.median((skk * smc - skm * skc)[ok] / det[ok]))
    else:
        coef = np.linalg.lstsq(np.column_stack([kn, mn]), cv, rcond=None)[0]
        a, b = float(coef[0]), float(coef[1])
    # refit on the entries of the rows that agree
    bad = np.abs(cv - a * kn - b * mn) > 1e-8 * scale
    out = np.union1d(rows[bad], cols[bad])
    keep = ~(np.isin(rows, out) | np.isin(cols, out))
    if keep.sum() >= 2:
        coef = np.linalg.lstsq(np.column_stack([kn[keep], mn[keep]]), cv[keep], rcond=None)[0]
        a, b = float(coef[0]), float(coef[1])
    a, b = a / sk, b / sm
    if abs(b) * sm <= 1e-13 * scale:
        b = 0.0
    if abs(a) * sk <= 1e-13 * scale:
        a = 0.0
    Rm = (C - a * K - b * M).tocoo()
    big = np.abs(Rm.data) > 1e-12 * scale
    S = np.union1d(Rm.row[big], Rm.col[big]).astype(np.int64)
    Rs = np.asarray((C - a * K - b * M).tocsr()[S][:, S].todense()) if S.size else np.zeros((0, 0))
    return float(a), float(b), S, 0.5 * (Rs + Rs.T)


def _reduce(model: Model, omega: float, *, modal_cutoff, n_modes, steps_per_period) -> _Reduced:
    """Reduce the free structure onto the contact DOFs (see module docstring)."""
    _check_contact(model)
    n = model.ndof
    free = model.free_dofs()
    nf = free.size
    pos = -np.ones(n, dtype=np.int64)
    pos[free] = np.arange(nf)
    K = _sub(model.K.tocsr(), free, free)
    M = _sub(model.M.tocsr(), free, free)
    C = sp.csr_matrix((nf, nf))
    if model.C is not None:
        C = C + _sub(model.C.tocsr(), free, free)
    if model.D is not None:
        C = C + _sub(model.D.tocsr(), free, free) / omega  # equivalent viscous at omega
    T = model.contact.local_transform(n).tocsr()[:, free]
    bnd = pos[np.asarray(model.contact.dofs).ravel()]
    nb = bnd.size
    mask = np.ones(nf, dtype=bool)
    mask[bnd] = False
    inner = np.flatnonzero(mask)
    ni = inner.size
    f = omega / (2.0 * np.pi)
    if modal_cutoff is None:
        f_cut = steps_per_period * f / CUTOFF_STEPS
    elif isinstance(modal_cutoff, str):
        if modal_cutoff != "all":
            raise InputError(f"modal_cutoff = {modal_cutoff!r}; expected a frequency [Hz], "
                             "None (default) or 'all'")
        f_cut = np.inf
    else:
        f_cut = _positive(modal_cutoff, "modal_cutoff")
    if n_modes is not None:
        n_modes = _count(n_modes, "n_modes", 0)
    info = {"n_dof_free": nf, "n_boundary": nb, "n_interior": ni}
    if ni == 0 or (np.isinf(f_cut) and n_modes is None):
        # no reduction: all free DOFs kept (boundary first)
        order = np.concatenate([bnd, inner])
        Phi = np.zeros((nf, nf))
        Phi[order, np.arange(nf)] = 1.0
        info.update(n_modes=ni, n_load_modes=0, cutoff_hz=np.inf, reduction="none")
    else:
        Kii = _sub(K, inner, inner).tocsc()
        Kib = _sub(K, inner, bnd)
        Mii = _sub(M, inner, inner).tocsc()
        try:
            lu = spla.splu(Kii)
        except RuntimeError:
            raise InputError("the stiffness with the contact DOFs held is singular (a part of "
                             "the structure moves freely without touching the contact); use "
                             "modal_cutoff='all' or hold that part") from None
        Psi = -lu.solve(Kib.toarray())
        w2, Vm = _fixed_interface_modes(Kii, Mii, 2 * np.pi * f_cut, n_modes)
        # static response of the interior to each load vector (contact DOFs held), with the
        # retained modes removed: the quasi-static contribution of the truncated modes
        extra = []
        for load in model.loads:
            Fi = np.asarray(load.vector, dtype=float)[free][inner]
            if not np.any(Fi):
                continue
            psi = lu.solve(Fi)
            nrm0 = math.sqrt(abs(psi @ (Kii @ psi))) or 1.0
            for _ in range(2):  # twice for round-off
                if Vm.shape[1]:
                    psi -= Vm @ (Vm.T @ (Mii @ psi))
                for v in extra:
                    psi -= v * (v @ (Mii @ psi))
            nrm = math.sqrt(abs(psi @ (Mii @ psi)))
            if math.sqrt(abs(psi @ (Kii @ psi))) > 1e-8 * nrm0 and nrm > 0.0:
                extra.append(psi / nrm)
        Pl = np.column_stack(extra) if extra else np.zeros((ni, 0))
        r = nb + Vm.shape[1] + Pl.shape[1]
        Phi = np.zeros((nf, r))
        Phi[bnd, np.arange(nb)] = 1.0
        Phi[np.ix_(inner, np.arange(nb))] = Psi
        Phi[np.ix_(inner, np.arange(nb, nb + Vm.shape[1]))] = Vm
        Phi[np.ix_(inner, np.arange(nb + Vm.shape[1], r))] = Pl
        info.update(n_modes=int(Vm.shape[1]), n_load_modes=int(Pl.shape[1]), cutoff_hz=f_cut,
                    reduction="craig-bampton",
                    highest_mode_hz=float(np.sqrt(max(w2[-1], 0.0)) / (2 * np.pi))
                    if w2.size else 0.0)
    Kr = Phi.T @ (K @ Phi)
    Mr = Phi.T @ (M @ Phi)
    Cr = Phi.T @ (C @ Phi)
    Kr = 0.5 * (Kr + Kr.T)
    Mr = 0.5 * (Mr + Mr.T)
    Cr = 0.5 * (Cr + Cr.T)
    diag = False
    Ul, Rl = np.zeros((0, 0)), np.zeros((0, 0))
    try:
        w2, V = sla.eigh(Kr, Mr)
    except np.linalg.LinAlgError:
        V = None
    if V is not None:
        basis = Phi @ V
        Cm = V.T @ Cr @ V
        Cm = 0.5 * (Cm + Cm.T)
        big = np.abs(Cm).max() if Cm.size else 0.0
        # damping in modal coordinates: a w^2 + b + low rank (undamped springs), if it fits
        a, b, S, Rs = _damping_split(K, M, C)
        Ul = basis[S].T if S.size else np.zeros((basis.shape[1], 0))
        approx = a * np.diag(w2) + b * np.eye(w2.size) + Ul @ Rs @ Ul.T
        fits = big == 0.0 or np.abs(Cm - approx).max() <= 1e-9 * big
        if fits and S.size <= max(8, basis.shape[1] // 4):
            diag = True
            Kred, Mred, Cred, Rl = w2.copy(), np.ones_like(w2), a * w2 + b, Rs
            info["damping"] = {"a_K": a, "b_M": b, "low_rank": int(S.size)}
        else:
            Kred, Mred, Cred = np.diag(w2), np.eye(w2.size), Cm
            Ul = np.zeros((0, 0))
        info["highest_frequency_hz"] = float(np.sqrt(max(w2.max(), 0.0)) / (2 * np.pi))
    else:
        basis, Kred, Mred, Cred = Phi, Kr, Mr, Cr
    info["r"] = int(basis.shape[1])
    info["diagonal"] = diag
    Tx = np.asarray(T @ basis)
    names, slices, rows = [], [], []
    start = 0
    for p in model.observed:
        d = np.asarray(p.dofs, dtype=np.int64).ravel()
        rr = np.zeros((d.size, basis.shape[1]))
        ok = pos[d] >= 0
        rr[ok] = basis[pos[d[ok]]]
        slices.append(slice(start, start + d.size))
        start += d.size
        rows.append(rr)
        names.append(p.name)
    obs = np.vstack(rows) if rows else np.zeros((0, basis.shape[1]))
    if not diag:
        Ul, Rl = np.zeros((basis.shape[1], 0)), np.zeros((0, 0))
    return _Reduced(free=free, basis=basis, K=Kred, M=Mred, C=Cred, U=np.ascontiguousarray(Ul),
                    R=np.ascontiguousarray(Rl), diag=diag, modal=V is not None, Tx=Tx, obs=obs,
                    obs_names=names, obs_slices=slices, info=info)


# --------------------------------------------------------------------------------------------
# the time stepper
# --------------------------------------------------------------------------------------------
class _Integrator:
    """Holds the reduced step operator and the current state; runs whole periods."""

    def __init__(self, model: Model, omega: float, *, steps_per_period, modal_cutoff, n_modes,
                 gamma, tol, wear, U0, V0, stick_anchor, hf_damping=False):
        self.model = model
        self.omega = _positive(omega, "omega")
        self.N = N = _count(steps_per_period, "steps_per_period", 4)
        gamma = float(gamma)
        if not (0.5 <= gamma <= 1.0):
            raise InputError(f"gamma = {gamma!r}; expected 0.5 (trapezoidal, default) to 1")
        self.gamma = gamma
        self.tol = _positive(tol, "tol")
        t0 = time.perf_counter()
        red = self.red = _reduce(model, self.omega, modal_cutoff=modal_cutoff, n_modes=n_modes,
                                 steps_per_period=N)
        c = model.contact
        self.nc, self.d = c.dofs.shape
        self.m = self.nc * self.d
        self.h = h = 2.0 * np.pi / (self.omega * N)
        r = red.basis.shape[1]
        # Newmark parameters, per mode in modal coordinates (high modes may get more damping)
        g = np.full(r, gamma)
        if red.diag and hf_damping:
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

            self.bq_m = self.bd_m = z0
            self.ftab = h * h * s_inv(self.ftil.T).T
            G = h * h * s_inv(red.Tx.T)
        else:
            S2 = red.M + gamma * h * red.C + b[0] * h * h * red.K
            lu = sla.lu_factor(S2)
            self.bq_m = -h * h * sla.lu_solve(lu, red.K)
            self.bd_m = sla.lu_solve(lu, red.M - (1 - gamma) * h * red.C
                                     + wm[0] * h * h * red.K)
            self.a_v = self.b_v = self.ds = self.hc = np.zeros(0)
            self.U, self.R, self.P, self.Qt = np.zeros((r, 0)), z0, np.zeros((r, 0)), z0
            self.ftab = h * h * sla.lu_solve(lu, self.ftil.T).T
            G = h * h * sla.lu_solve(lu, red.Tx.T)
        self.ftab = np.ascontiguousarray(self.ftab)
        self.G = np.ascontiguousarray(G)
        W = red.Tx @ G
        W = 0.5 * (W + W.T)
        try:
            cf = sla.cho_factor(W)
            self.A = sla.cho_solve(cf, np.eye(self.m))
        except np.linalg.LinAlgError:
            raise InputError("the contact DOFs' step mobility (Delassus operator) is singular: "
                             "a contact direction carries no mass nor stiffness") from None
        self.A = np.ascontiguousarray(0.5 * (self.A + self.A.T))
        self.gap = np.asarray(c.gap, dtype=float) + _node_wear(wear, self.nc)
        if red.diag:
            m_v, k_v, c_v = red.M, red.K, red.C
            m_m = k_m = c_m = z0
        else:
            m_v = k_v = c_v = np.zeros(0)
            m_m, k_m, c_m = red.M, red.K, red.C
        red.Tx = _c_float(red.Tx)
        red.obs = _c_float(red.obs)
        # the kernel's records; one compiled specialisation: every array is C-contiguous
        # float64 and every scalar a Python bool, float or int
        self.op = StepOperator(
            bool(red.diag), *(_c_float(a) for a in (
                self.a_v, self.b_v, self.ds, self.hc, self.U, self.R, self.P, self.Qt,
                self.bq_m, self.bd_m, self.ftab, self.G, red.Tx, red.obs)))
        self.energy = EnergyTerms(float(h), *(_c_float(a) for a in (
            self.ftil, m_v, k_v, c_v, m_m, k_m, c_m)))
        self.contact = Contact(self.A, _c_float(self.gap), float(c.mu), int(self.d))
        self.settings = Settings(float(self.tol), float(self.fscale), int(60 + 4 * self.nc))
        self.setup_time = time.perf_counter() - t0
        self.r = r
        # initial state
        self._set_state(U0, V0, stick_anchor)
        self.periods_done = 0
        self.n_fail = 0
        self.max_it = 0
        self.first_fail_time = None

    # state <-> full vectors ------------------------------------------------------------------
    def _project(self, U, what):
        n = self.model.ndof
        U = np.asarray(U, dtype=float)
        if U.shape != (n,) or not np.all(np.isfinite(U)):
            raise InputError(f"{what} has shape {U.shape}; expected ({n},) finite values")
        Uf = U[self.red.free]
        if self.red.modal:  # M-orthogonal projection (exact for vectors of the basis)
            Mf = _sub(self.model.M.tocsr(), self.red.free, self.red.free)
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

    def _set_state(self, U0, V0, stick_anchor):
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
        if stick_anchor is not None:
            a = np.asarray(stick_anchor, dtype=float)
            if a.shape == (self.nc,) and d == 2:
                a = a[:, None]
            if a.shape != (self.nc, d - 1):
                raise InputError(f"stick_anchor has shape {a.shape}; expected ({self.nc}, "
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
              steps_per_period: int = DEFAULT_STEPS, record="last", U0=None, V0=None,
              wear=None, stick_anchor=None, modal_cutoff=None, n_modes=None,
              gamma: float = 0.5, hf_damping: bool = False, keep_poincare: int = 10_000,
              tol: float = 1e-10, progress: bool = False) -> TransientResult:
    """Integrate the forced response in time with exact contact and friction.

    Parameters
    ----------
    model : the structure (:class:`~fretwear.model.core.Model`).
    frequency : forcing frequency ``f`` [Hz]; the loads are ``F(omega t)``, ``omega = 2 pi f``.
    n_periods : number of forcing periods ``T = 1 / f`` to simulate.
    steps_per_period : fixed steps per period (``h = T / steps_per_period``). Guidance: >= 20
        steps per period of the highest harmonic you want accurate (phase error of the
        trapezoidal rule ``(omega h)^2 / 12``); stick-slip events are first order in ``h``.
    record : ``"last"`` (the last period) or the number of periods recorded at the end
        (every step), 0 for none.
    U0, V0 : (ndof,) initial displacement [m] and velocity [m/s] at ``t = 0``; default rest.
        ``result.U, result.V`` continue a run exactly.
    wear : (nc,) wear depth per contact node [m] (opens the gap).
    stick_anchor : (nc, d-1) tangential positions [m] from which the first step's slip is
        measured (default: those of ``U0``).
    modal_cutoff : frequency [Hz] below which the fixed-interface modes are kept
        (Craig-Bampton); default ``steps_per_period * f / 8`` (modes the step resolves with at
        least 8 steps per period); ``"all"`` for no reduction. The truncated modes keep their
        static contribution (constraint modes and one static mode per load vector).
    n_modes : keep exactly this many fixed-interface modes instead (overrides the cutoff).
    gamma : Newmark gamma (``beta = (gamma + 1/2)^2 / 4``); 0.5 (default) is the trapezoidal
        rule (second order, energy conserving); larger values damp the highest frequencies
        (first order).
    hf_damping : integrate the modes of the reduced model that the step does not resolve
        (``omega_j h > 1``, fewer than 2 pi steps per period) with ``gamma = 1`` (spectral
        radius 1/3 at infinity) instead of ``gamma``: removes their spurious ringing, at the
        cost of numerical dissipation (``energy["numerical"]``) and of whatever physics they
        carry (a friction-induced self-excited oscillation may need them: off by default).
    keep_poincare : once-per-period samples kept (the last ones).
    tol : relative tolerance of the contact solver status tests.
    progress : show a progress bar.

    Returns
    -------
    :class:`TransientResult`: ``success`` (every contact solve settled), ``message``, the
    recorded samples (times [s], displacements [m], forces [N], energies [J]) and the final
    state ``U, V`` to continue the run.
    """
    n_periods = _count(n_periods, "n_periods", 1)
    if record == "last":
        n_rec = 1
    else:
        n_rec = _count(record, "record", 0)
        if n_rec > n_periods:
            raise InputError(f"record = {record} periods but n_periods = {n_periods}")
    n_keep = min(_count(keep_poincare, "keep_poincare", 0), n_periods)
    omega = 2 * np.pi * check_range(_positive(frequency, "frequency"), "frequency", "frequency")
    integ = _Integrator(model, omega, steps_per_period=steps_per_period,
                        modal_cutoff=modal_cutoff, n_modes=n_modes, gamma=gamma, tol=tol,
                        wear=wear, U0=U0, V0=V0, stick_anchor=stick_anchor,
                        hf_damping=hf_damping)
    t0 = time.perf_counter()
    raw = integ.run(n_periods, n_rec, n_keep, progress=progress)
    wall = time.perf_counter() - t0
    return integ.result(raw, n_periods, wall)


# --------------------------------------------------------------------------------------------
# steady state and its classification
# --------------------------------------------------------------------------------------------
def classify_sequence(poincare, means=None, *, tol: float = 1e-6, scale: float | None = None,
                      n_confirm: int = 3, min_window: int = 64, max_order: int = 8,
                      decay_limit: float = 0.95, peak_limit: float = 20.0) -> Classification:
    """Classify a sequence of once-per-period samples (Poincare section).

    Parameters
    ----------
    poincare : (K, nmon) samples at the start of each period, oldest first.
    means : (K, nmon) mean over each period (default: ``poincare``), used for the drift.
    tol : relative tolerance of "repeats" (relative to ``scale``).
    scale : amplitude of the response (e.g. the peak-to-peak over one period); default the
        largest absolute sample.
    n_confirm : consecutive periods that must repeat.
    min_window : fewest samples before "drifting", "quasi-periodic" or "irregular" is said.
    max_order : largest subharmonic order tested.
    decay_limit : ``decay`` above which the deviations are taken as sustained.
    peak_limit : spectral peak over median above which a peak is dominant.

    Returns
    -------
    :class:`Classification`. Rules, in order: periodic if the distance to a periodic orbit
    estimated from the last ``n_confirm`` differences ``|P_k - P_{k-1}|`` (see
    ``periodicity_error``) is below ``tol * scale``; subharmonic of order p if the same holds
    for ``|P_k - P_{k-p}|``; with at least ``min_window`` samples, drifting if the period
    means follow a straight line (residual < 10 % of the change) whose change over the
    window exceeds ``10 tol scale`` and whose increments do not decay (second half / first
    half > 0.8);
    quasi-periodic if the detrended deviations are sustained (``decay > decay_limit``), above
    ``tol * scale``, and their spectrum has a dominant peak at a non-zero frequency; irregular
    if sustained without a dominant peak; otherwise transient.
    """
    P = np.asarray(poincare, dtype=float)
    if P.ndim == 1:
        P = P[:, None]
    K = P.shape[0]
    Mn = P if means is None else np.asarray(means, dtype=float).reshape(K, -1)
    if scale is None or not scale > 0:
        scale = float(np.abs(P).max(initial=0.0)) or 1.0
    thr = tol * scale

    def rep_err(p):
        """Distance to a p-periodic orbit: the last differences ``|P_k - P_{k-p}|`` divided by
        ``1 - rho`` (rho, the observed contraction of the differences, capped at 0.99), so that
        a slow geometric convergence is not taken for convergence."""
        if K < p + n_confirm + p:
            return np.inf
        d = np.abs(P[p:] - P[:-p]).max(axis=1)[-(n_confirm + 1):]
        with np.errstate(divide="ignore", invalid="ignore"):
            ratios = d[1:] / d[:-1]
        rho = float(np.nanmax(ratios)) if np.any(np.isfinite(ratios)) else 0.0
        rho = min(max(rho, 0.0), 0.99)
        return float(d[1:].max() / (1.0 - rho))

    e1 = rep_err(1)
    out = Classification(kind="transient", periodicity_error=e1 / scale, scale=scale, n=K)
    if e1 <= thr:
        out.kind, out.order = "periodic", 1
        return out
    for p in range(2, max_order + 1):
        if rep_err(p) <= thr:
            out.kind, out.order = "subharmonic", p
            return out
    if K < max(min_window, 8):
        return out
    k = np.arange(K, dtype=float)
    kc = k - k.mean()
    # drift of the period means
    slope = (kc @ (Mn - Mn.mean(axis=0))) / (kc @ kc)
    j = int(np.argmax(np.abs(slope)))
    s = float(slope[j])
    out.drift_rate = s
    fit = Mn[:, j].mean() + s * kc
    resid = float(np.sqrt(np.mean((Mn[:, j] - fit) ** 2)))
    inc = np.diff(Mn[:, j])
    h2 = inc.size // 2
    grow = abs(inc[h2:].mean()) / max(abs(inc[:h2].mean()), 1e-300)
    change = abs(s) * (K - 1)
    if change > 10.0 * thr and resid < 0.1 * change and grow > 0.8:
        out.kind = "drifting"
        return out
    # sustained deviations of the Poincare samples (detrended)
    slopes = (kc @ (P - P.mean(axis=0))) / (kc @ kc)
    D = P - P.mean(axis=0) - np.outer(kc, slopes)
    half = K // 2
    a1 = float(np.sqrt(np.mean(D[:half] ** 2)))
    a2 = float(np.sqrt(np.mean(D[half:] ** 2)))
    out.decay = a2 / a1 if a1 > 0 else float("nan")
    if not (a2 > thr and out.decay > decay_limit):
        return out
    win = np.hanning(K)
    spec = (np.abs(np.fft.rfft(D * win[:, None], axis=0)) ** 2).sum(axis=1)
    spec[0] = 0.0
    ib = int(np.argmax(spec))
    med = float(np.median(spec[1:])) if spec.size > 2 else 0.0
    out.peak_ratio = float(spec[ib] / med) if med > 0 else np.inf
    nu = ib / K
    if 0 < ib < spec.size - 1:  # parabolic refinement on the log spectrum
        y0, y1, y2 = np.log(spec[ib - 1:ib + 2] + 1e-300)
        den = y0 - 2 * y1 + y2
        if den < 0:
            nu = (ib + 0.5 * (y0 - y2) / den) / K
    out.rotation = float(min(max(nu, 0.0), 0.5))
    out.kind = "quasi-periodic" if out.peak_ratio > peak_limit else "irregular"
    return out


def steady_state(model: Model, frequency: float, *, max_periods: int = 20_000, tol: float = 1e-6,
                 steps_per_period: int = DEFAULT_STEPS, harmonics: int = 7,
                 check_every: int = 16, window: int = 512, min_periods: int = 128, U0=None,
                 V0=None, wear=None, stick_anchor=None, modal_cutoff=None, n_modes=None,
                 gamma: float = 0.5, hf_damping: bool = False, contact_tol: float = 1e-10,
                 progress: bool = False) -> SteadyStateResult:
    """Integrate until the response is periodic (or classified otherwise).

    The monitored quantities are the observed DOFs and the local contact displacements,
    sampled once per period (Poincare section) and averaged over each period. Every
    ``check_every`` periods (the interval doubles up to 512) the last ``window`` periods are
    classified by :func:`classify_sequence` with ``scale`` = the largest peak-to-peak of the
    monitored quantities over the last period. The run stops when the response is periodic
    (or subharmonic), or when it is drifting / quasi-periodic / irregular at two consecutive
    checks with at least ``min_periods`` samples, or at ``max_periods``. One more period is
    then recorded at every step and its harmonics computed (:func:`fourier_coefficients`).

    Parameters
    ----------
    model, frequency : as :func:`integrate` (``frequency`` [Hz]).
    max_periods : give up after this many periods (classification then as found).
    tol : relative periodicity tolerance (see :func:`classify_sequence`).
    harmonics : highest harmonic of the last period reported (1 .. harmonics).
    Others as :func:`integrate` (``contact_tol`` is its ``tol``).

    Returns
    -------
    :class:`SteadyStateResult`: ``success`` when the response was classified with every
    contact solve settled; ``classification`` and ``message`` say what it is.
    """
    return _steady_state(model, 2 * np.pi * check_range(_positive(frequency, "frequency"),
                                                         "frequency", "frequency"),
                         max_periods=max_periods, tol=tol, steps_per_period=steps_per_period,
                         harmonics=harmonics, check_every=check_every, window=window,
                         min_periods=min_periods, U0=U0, V0=V0, wear=wear,
                         stick_anchor=stick_anchor, modal_cutoff=modal_cutoff, n_modes=n_modes,
                         gamma=gamma, hf_damping=hf_damping, contact_tol=contact_tol,
                         progress=progress)


def _steady_state_at_omega(model: Model, omega: float, **kwargs) -> SteadyStateResult:
    """:func:`steady_state` at the circular frequency ``omega`` [rad/s] of a periodic solution
    (no conversion to Hz and back), with its keywords and defaults."""
    bound = inspect.signature(steady_state).bind(model, 0.0, **kwargs)
    bound.apply_defaults()
    args = dict(bound.arguments)
    del args["model"], args["frequency"]
    return _steady_state(model, omega, **args)


def _steady_state(model: Model, omega: float, *, max_periods, tol, steps_per_period, harmonics,
                  check_every, window, min_periods, U0, V0, wear, stick_anchor, modal_cutoff,
                  n_modes, gamma, hf_damping, contact_tol, progress) -> SteadyStateResult:
    """:func:`steady_state` at the circular frequency ``omega`` [rad/s] (every argument
    given)."""
    max_periods = _count(max_periods, "max_periods", 1)
    check_every = _count(check_every, "check_every", 1)
    window = _count(window, "window", 8)
    tol = _positive(tol, "tol")
    t_start = time.perf_counter()
    integ = _Integrator(model, omega, steps_per_period=steps_per_period,
                        modal_cutoff=modal_cutoff, n_modes=n_modes, gamma=gamma, tol=contact_tol,
                        wear=wear, U0=U0, V0=V0, stick_anchor=stick_anchor,
                        hf_damping=hf_damping)
    P = np.zeros((0, integ.red.obs.shape[0] + integ.m))
    Mn = P.copy()
    chunk = check_every
    prev = None
    cls = Classification(kind="transient", periodicity_error=np.inf, scale=1.0)
    history = []
    done = 0
    while done < max_periods:
        k = min(chunk, max_periods - done)
        raw = integ.run(k, 0, k, progress=False)
        done += k
        P = np.vstack([P, raw["mon_start"]])[-window:]
        Mn = np.vstack([Mn, raw["mon_mean"]])[-window:]
        scale = float(raw["mon_ptp"][-1].max())
        cls = classify_sequence(P, Mn, tol=tol, scale=scale, min_window=min_periods)
        history.append((done, cls.kind, cls.periodicity_error))
        if progress:
            print(f"[steady_state] {done} periods: {cls.kind}, periodicity error "
                  f"{cls.periodicity_error:.3g}")
        if cls.kind in ("periodic", "subharmonic"):
            break
        if cls.kind in ("drifting", "quasi-periodic", "irregular") and cls.kind == prev:
            break
        prev = cls.kind
        chunk = min(2 * chunk, 512)
    t0 = time.perf_counter()
    raw = integ.run(1, 1, 1)
    last = integ.result(raw, 1, time.perf_counter() - t0)
    harm = {name: fourier_coefficients(x, harmonics) for name, x in last.observed.items()}
    charm = {"lam": fourier_coefficients(last.lam, harmonics),
             "u_loc": fourier_coefficients(last.u_loc, harmonics)}
    info = dict(last.info)
    info["history"] = history
    n = done + 1
    classified = cls.kind != "transient"
    message = (f"{cls.kind} after {n} periods" if classified
               else f"still transient after {n} periods")
    if integ.n_fail:
        message += f"; {integ.n_fail} contact solves did not settle"
    return SteadyStateResult(
        success=classified and not integ.n_fail, message=message,
        classification=cls.kind, n_periods=n,
        periodic=cls.kind in ("periodic", "subharmonic"), last=last, harmonics=harm,
        contact_harmonics=charm, diagnostics=cls, poincare=P, U=last.U, V=last.V,
        wall_time=time.perf_counter() - t_start, info=info)


# --------------------------------------------------------------------------------------------
# quasi-static incremental wear
# --------------------------------------------------------------------------------------------
def incremental_wear(model: Model, *, steps_per_cycle: int = 64, n_cycles: int = 100,
                     cycle_jump: int = 1, k_w: float | None = None, record_every: int = 1,
                     wear0=None, tol: float = 1e-10, progress: bool = False,
                     raise_on_failure: bool = True) -> IncrementalWearResult:
    """Quasi-static fretting wear by load steps (in the spirit of Stromberg 1997).

    At every load step ``tau_k = 2 pi k / steps_per_cycle`` the static equilibrium
    ``K U + T^T lam = F(tau_k)`` is solved with exact Signorini and incremental Coulomb
    friction (the slip is the tangential increment since the previous step), after an exact
    static condensation onto the contact DOFs (``K`` is constant, so each step is a small dense
    contact problem, solved by the same numba kernel as the dynamic solver). After each step,
    every node's wear grows by Archard's law ``dW = k_w * p_N * |delta u_T|``
    (``p_N = lam_N / area``), which opens its gap for the next step. The run starts from the
    unloaded, unworn state (``U = 0``) with one step at ``tau = 0``.

    With ``cycle_jump = J > 1`` the wear of each computed cycle (after the first, which
    includes the initial loading) is counted ``J`` times (explicit Euler on the slow scale):
    ``ceil((n_cycles - 1) / J) + 1`` cycles are computed, the last jump shortened so that the
    total is ``n_cycles``.

    Parameters
    ----------
    model : the structure (inertia and damping are ignored).
    steps_per_cycle : load steps per cycle.
    n_cycles : number of load cycles (physical, counting the jumps).
    cycle_jump : cycles represented by each computed cycle.
    k_w : Archard coefficient [1/Pa]; default ``model.contact.wear_coefficient``.
    record_every : record every this many computed cycles (and the last).
    wear0 : (nc,) initial wear [m].
    tol : relative tolerance of the contact solver.
    raise_on_failure : raise :class:`~fretwear.errors.ConvergenceError` when the contact
        problem of some load step does not settle (default); False: return the result with
        ``success`` False and the count in ``message``.

    Returns
    -------
    :class:`IncrementalWearResult`: ``success``, ``message``, and per recorded cycle the
    wear [m], pressure [Pa], slip [m], worn volume [m^3] and dissipation [J].
    """
    N = _count(steps_per_cycle, "steps_per_cycle", 2)
    n_cycles = _count(n_cycles, "n_cycles", 1)
    J = _count(cycle_jump, "cycle_jump", 1)
    rec_every = _count(record_every, "record_every", 1)
    kw = model.contact.wear_coefficient if k_w is None else k_w
    kw = float(kw)
    if not (math.isfinite(kw) and kw >= 0.0):
        raise InputError(f"k_w = {k_w!r}; expected an Archard coefficient >= 0 [1/Pa]")
    t0 = time.perf_counter()
    c = model.contact
    nc, d = c.dofs.shape
    area = np.asarray(c.area, dtype=float)
    if area.shape != (nc,) or np.any(area <= 0):
        raise InputError(f"contact.area must be ({nc},) positive areas [m^2]")
    _check_contact(model)
    cond = condense_static(model)
    A = cond.K
    tau = 2.0 * np.pi * np.arange(N) / N
    Ft = model.load_time(tau) if model.loads else np.zeros((N, model.ndof))
    btab = np.ascontiguousarray(cond.loads(Ft))
    fscale = float(np.abs(btab).max(initial=0.0))
    jumps = [1]
    left = n_cycles - 1
    while left > 0:
        jumps.append(min(J, left))
        left -= jumps[-1]
    jumps = np.asarray(jumps, dtype=np.int64)
    ncomp = jumps.size
    nrec = sum(1 for i in range(ncomp) if (i + 1) % rec_every == 0 or i == ncomp - 1)
    wear = _node_wear(wear0, nc, "wear0")
    gap = np.asarray(c.gap, dtype=float).copy()
    x = np.zeros(nc * d)
    status = np.where(gap <= 0.0, STICK, OPEN).astype(np.int8)
    tdir = np.zeros((nc, d - 1))
    tdir[:, 0] = 1.0
    rec = WearRecords(rec_every, np.zeros((nrec, nc)), np.zeros((nrec, nc)),
                      np.zeros((nrec, nc)), np.zeros(nrec), np.zeros(nrec, dtype=np.int64))
    nr, nfail, maxit = run_quasistatic(
        Contact(A, gap, float(c.mu), int(d)), LoadCycle(btab, _c_float(area), kw, jumps),
        Settings(float(tol), fscale, 60 + 4 * nc), WearState(x, wear, ContactState(status, tdir)),
        rec)
    if nfail and raise_on_failure:
        raise ConvergenceError(f"incremental_wear: {nfail} load steps where the contact active "
                               "set did not settle (singular or cycling); check that the "
                               "contact holds the structure (rigid motions) and the loads")
    message = (f"{n_cycles} cycles ({ncomp} computed, {ncomp * N} load steps)" if not nfail
               else f"{nfail} load steps where the contact active set did not settle")
    lam = np.asarray(A @ (-x) + btab[0]).reshape(nc, d)
    U = cond.recover(x, model.load_time(np.zeros(1))[0] if model.loads
                     else np.zeros(model.ndof))
    return IncrementalWearResult(
        success=not nfail, message=message, cycles=rec.cycle, wear=rec.wear, pressure=rec.press,
        slip=rec.slip,
        worn_volume=rec.wear @ area, dissipation=rec.diss, computed_cycles=ncomp, cycle_jump=J,
        steps_per_cycle=N, k_w=kw, wall_time=time.perf_counter() - t0, U=U, lam=lam,
        info={"max_active_set_iterations": int(maxit), "records": int(nr)})

