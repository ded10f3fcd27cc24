"""Wear rate averaged over a time integration: the slow-scale rate where no periodic balance is.

The "DLFT with wear" method (paper section 3, Fig. 3) takes the wear per cycle (eq. 29) from the
periodic solution of the harmonic balance. Along a wear history the balance can stop existing:
the structure may bifurcate to a subharmonic or quasi-periodic response, or the truncated balance
(a few harmonics, sampled stick-slip transitions) may lose its solution while the structure still
vibrates periodically. In both cases the wear per cycle is still well defined as the mean, over
many vibration periods, of Archard's integrand (eq. 12, 29) on what the structure does. This
module computes that mean with the exact time integration of :mod:`fretwear.timedomain.integrate`
(Newmark with unilateral contact and Coulomb friction, no regularisation):

    dW1_p = c_p S_p,    S_p = (1/K) sum_n lambda_N,p(t_n) |x_T,p(t_n+1) - x_T,p(t_n)|

over the steps ``n`` of ``K`` periods in which node ``p`` slips (the integrand of
:func:`fretwear.wear.kernels.archard_integrand`)

with ``c_p`` the factor of the wear law (:func:`fretwear.wear.laws.wear_coefficients`): ``k_w /
area`` for Archard, ``k_e mu / area`` for the energy law, exactly as on the DLFT samples. A node
that sticks wears exactly nothing (its slip increments are zero by the exact stick constraint).

The integration starts from a state the caller gives (the last periodic solution, or the end of
the previous time-averaged step, so that the slow drift of the mean position and the transient
carry over), runs ``settle`` periods, then averages over ``average`` periods
(:class:`~fretwear.timedomain.options.AveragingOptions`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from fretwear.hb import contact as law
from fretwear.hb.fourier import FourierBasis
from fretwear.model.core import Model
from fretwear.timedomain.integrate import integrate
from fretwear.timedomain.options import (
    AVERAGING,
    AveragingOptions,
    InitialState,
    IntegrationOptions,
)
from fretwear.timedomain.steady import classify_sequence, fourier_coefficients
from fretwear.wear.kernels import slip_work_samples

#: response kinds of :func:`fretwear.timedomain.steady.classify_sequence`, coded in wear
# histories
RESPONSE_KINDS = ("periodic", "subharmonic", "drifting", "quasi-periodic", "irregular",
                  "transient")


@dataclass
class TimeAveragedRate:
    """Outcome of :func:`time_averaged_rate` (nc contact nodes, d components).

    Attributes
    ----------
    g : (nc,) wear depth per cycle [m] (mean over the averaging window).
    slip_work : (nc,) ``S_p`` [N m] per cycle.
    pressure_mean, pressure_max : (nc,) normal pressure over the window [Pa].
    slip_amplitude : (nc,) half range of the tangential displacement over the window [m].
    slip_path : (nc,) slip path per cycle [m].
    state_fraction : (nc, 3) fraction of the window in separation, stick, slip.
    friction_energy : (nc,) energy dissipated by friction per cycle [J].
    U, lam : (nc, d, H) Fourier coefficients (on ``basis``) of the contact displacements [m]
        and forces [N] over the last period of the window.
    anchor : (nc, d-1) mean tangential positions over the last period [m].
    kind : response over the window (one of :data:`RESPONSE_KINDS`); rotation : dominant
        frequency of the once-per-period samples [cycles per period] (quasi-periodic);
        order : repetition period in forcing periods (periodic 1, subharmonic p, else 0).
    U_end, V_end : (ndof,) full-field displacement [m] and velocity [m/s] at the end, to
        continue the integration exactly.
    scatter : statistical uncertainty of the averaged worn-volume rate: ``|v1 - v2| / (v1 +
        v2)`` with ``v1, v2`` the worn-volume rates averaged over the two halves of the window
        (half their difference is the standard error of their mean); 0 when nothing wears.
    periods : periods integrated; wall_time : [s].
    """

    g: np.ndarray
    slip_work: np.ndarray
    pressure_mean: np.ndarray
    pressure_max: np.ndarray
    slip_amplitude: np.ndarray
    slip_path: np.ndarray
    state_fraction: np.ndarray
    friction_energy: np.ndarray
    U: np.ndarray
    lam: np.ndarray
    anchor: np.ndarray
    kind: str
    rotation: float
    order: int
    U_end: np.ndarray
    V_end: np.ndarray
    periods: int
    wall_time: float
    scatter: float

    @property
    def kind_code(self) -> int:
        return RESPONSE_KINDS.index(self.kind)


def default_steps(basis: FourierBasis, steps: int | None = None) -> int:
    """Time steps per period of a time-averaged rate: ``steps``, or by default
    ``max(128, 8 x`` the highest harmonic of ``basis``) (8 steps per period of the highest
    harmonic the balance resolves)."""
    hmax = max(basis.harmonics) if basis.harmonics else 1
    return int(steps or max(128, 8 * hmax))


def window_samples(u_loc, lam, state):
    """The recorded samples of :func:`fretwear.timedomain.integrate.integrate` in the DLFT layout.

    The integrator records ``x(t_n)``, the force ``lambda_n`` that acts over the step
    ``t_n -> t_n+1`` and the state of that step. Returns ``(x, lam, state)`` as (nc, d, ns),
    (nc, d, ns), (nc, ns) with column ``j`` holding ``x(t_j)`` and the force and state of the
    step that *ends* at ``t_j`` (the DLFT convention: the slip of instant ``j`` is
    ``X(j) - X(j-1)``). Column 0 has no step before it in the window and is marked as stick.
    """
    x = np.moveaxis(np.asarray(u_loc, float), 0, -1)
    f = np.moveaxis(np.asarray(lam, float), 0, -1)
    s = np.asarray(state).T
    f = np.concatenate([f[..., :1], f[..., :-1]], axis=-1)
    s = np.concatenate([np.full((s.shape[0], 1), law.STICK, s.dtype), s[:, :-1]], axis=1)
    return x, f, s


def _sum_in_time(a: np.ndarray) -> np.ndarray:
    """Row sums of ``a`` (nc, ns) accumulated in time order, one step after the other: the
    same additions in the same order whatever the memory layout of ``a`` (numpy's ``sum``
    pairs terms differently for contiguous and strided rows, which moves the last bits)."""
    if a.shape[1] == 0:
        return np.zeros(a.shape[0])
    return np.cumsum(a, axis=1)[:, -1]


def time_averaged_rate(model: Model, frequency: float, basis: FourierBasis, coef, wear, *, U0, V0,
                       options: AveragingOptions = AVERAGING) -> TimeAveragedRate:
    """Mean wear per cycle over a time integration at wear ``wear`` (module docstring).

    Parameters
    ----------
    model : the structure; frequency : excitation frequency [Hz] (dynamic only).
    basis : Fourier basis on which the last period's harmonics are returned.
    coef : (nc,) factor ``c_p`` of the wear law [1/N] (``dW1 = c S``).
    wear : (nc,) wear depth [m] (opens the normal gap).
    U0, V0 : (ndof,) start state [m], [m/s].
    options : :class:`~fretwear.timedomain.options.AveragingOptions`: ``settle`` periods
        integrated before averaging, ``average`` periods averaged (>= 2), ``steps_per_period``
        (default: :func:`default_steps`), ``classify_tol`` the relative periodicity tolerance
        of the response classification.
    """

    t0 = time.perf_counter()
    hmax = max(basis.harmonics) if basis.harmonics else 1
    nsteps = default_steps(basis, options.steps_per_period)
    settle = int(options.settle)
    average = max(int(options.average), 2)
    r = integrate(model, frequency, n_periods=settle + average,
                  options=IntegrationOptions(steps_per_period=nsteps), record=average,
                  start=InitialState(U0=U0, V0=V0, wear=wear))
    x, f, s = window_samples(r.u_loc, r.lam, r.state)
    nc, d, ns = x.shape
    cycles = (ns - 1) / nsteps  # steps whose slip is counted, in periods
    # slip and slip work (Archard's integrand) of each step ending at column j, zero unless
    # slip; column 0 is marked stick
    inc, work = slip_work_samples(np.ascontiguousarray(f[:, 0, :]), np.ascontiguousarray(x),
                                  np.ascontiguousarray(s))
    S = _sum_in_time(work) / cycles
    area = np.asarray(model.contact.area, float)
    c_area = area * np.asarray(coef, float)  # worn volume per unit slip work
    mid = ns // 2  # columns 1..mid-1 and mid..ns-1: the steps of each half of the window
    v = [float(c_area @ _sum_in_time(work[:, cols])) * nsteps / n
         for cols, n in ((slice(1, mid), mid - 1), (slice(mid, ns), ns - mid))]
    scatter = abs(v[0] - v[1]) / (v[0] + v[1]) if v[0] + v[1] > 0 else 0.0
    p = f[:, 0, :] / area[:, None]
    xt = x[:, 1:, :]
    half = 0.5 * (xt.max(axis=2) - xt.min(axis=2))
    last = slice(ns - nsteps, ns)
    cu = fourier_coefficients(np.moveaxis(x[..., last], -1, 0), hmax)
    cl = fourier_coefficients(np.moveaxis(f[..., last], -1, 0), hmax)
    idx = basis.rows_in_full(hmax)
    U = np.moveaxis(cu[idx], 0, -1).copy()
    lam_h = np.moveaxis(cl[idx], 0, -1).copy()
    # response over the window: once-per-period samples of the contact displacements
    poinc = x[..., ::nsteps].reshape(nc * d, -1).T
    ptp = float(np.ptp(x[..., last], axis=-1).max())
    c = classify_sequence(poinc, tol=options.classify_tol, scale=max(ptp, 1e-300),
                          min_window=min(64, poinc.shape[0]))
    return TimeAveragedRate(
        g=np.asarray(coef, float) * S, slip_work=S, pressure_mean=p[:, 1:].mean(axis=1),
        pressure_max=p.max(axis=1), slip_amplitude=np.sqrt((half**2).sum(axis=1)),
        slip_path=_sum_in_time(inc) / cycles,
        state_fraction=np.stack([(s[:, 1:] == k).mean(axis=1) for k in range(3)], axis=1),
        friction_energy=law.friction_work(f, x, s) / cycles, U=U, lam=lam_h,
        anchor=U[:, 1:, 0].copy(), kind=c.kind, rotation=float(c.rotation), order=int(c.order),
        U_end=r.U, V_end=r.V, periods=settle + average,
        wall_time=time.perf_counter() - t0, scatter=float(scatter))

