"""Numba kernels of the time-domain reference solvers (:mod:`fretwear.timedomain.integrate`).

Three pieces, on plain arrays:

* :func:`solve_contact` -- one exact frictional contact problem on the contact DOFs in
  *primal* form ``lam = b - A (x - xref)`` (``x`` local contact displacements [m], ``lam``
  contact forces [N], ``A`` a dense condensed stiffness [N/m]): Signorini
  ``x_N <= g, lam_N >= 0, lam_N (x_N - g) = 0`` and incremental Coulomb on the slip increment
  ``xi = x_T - xprev_T`` (stick ``xi = 0``, ``|lam_T| <= mu lam_N``; slip
  ``lam_T = mu lam_N xi / |xi|``, the isotropic cone in 3D). In 2D, a primal-dual active set
  method: statuses (open, stick, slip) are guessed, the (small) system for the free
  components is solved, statuses are corrected, until nothing changes. In 3D
  (:func:`_solve_contact_cone`), a semismooth Newton method on the Alart-Curnier equations
  with a backtracking line search (the active set cycled there: the slip direction is an
  unknown). Both solve only for the free components (open nodes, tangential components of
  slipping nodes), so a step where most nodes stick costs a few small solves, and both are
  warm-started from the previous step's statuses.
* :func:`run_dynamic` -- the fixed-step time loop of the dynamic solver (two-step form of the
  trapezoidal / Newmark rule with the contact problem solved at every step).
* :func:`run_quasistatic` -- load steps through cycles with Archard wear applied as it goes
  (the integrand of :func:`fretwear.wear.kernels.archard_integrand`).

The two loops take a few small records (named tuples of arrays and scalars, grouped by
meaning): :class:`Contact` (the contact problem), :class:`Settings` (contact solver settings),
:class:`ContactState` (statuses and slip directions, the warm start); for the dynamic loop
:class:`StepOperator` (the reduced model's step), :class:`EnergyTerms` (what the energy balance
needs), :class:`DynamicState`, :class:`Records` (output buffers); for the quasi-static loop
:class:`LoadCycle` (loads and wear law), :class:`WearState`, :class:`WearRecords`. Every array is
C-contiguous (float64 unless said otherwise) and every scalar a Python bool, float or int, so
that each loop is compiled once. The loops unpack their records once and call
:func:`solve_contact` on plain arrays at every step: passing it records instead cost up to a
quarter more time per step on a one-node 3D problem (measured), and nothing on large ones.

Status codes: 0 = open (separation), 1 = stick, 2 = slip.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from fretwear.wear.kernels import archard_integrand

# reassociation lets LLVM vectorise the dot products (no NaN/Inf assumptions)
_FAST = {"reassoc", "contract", "nsz", "arcp"}

OPEN = 0
STICK = 1
SLIP = 2


# --------------------------------------------------------------------------------------------
# records
# --------------------------------------------------------------------------------------------
class Contact(NamedTuple):
    """The contact problem on the contact DOFs (``m = nc * d`` local components, node-major
    ``[N, T1, (T2)]``)."""

    A: np.ndarray  #: (m, m) symmetric condensed stiffness in the local frame [N/m]
    gap: np.ndarray  #: (nc,) gap, wear included [m] (``x_N <= gap``)
    mu: np.ndarray  #: (nc,) friction coefficient of every node [-]
    d: int  #: components per node, 2 or 3


class Settings(NamedTuple):
    """Settings of the active-set contact solver."""

    tol: float  #: relative tolerance of the status tests
    fscale: float  #: force scale [N]: forces below ``tol * fscale`` are zero
    maxit: int  #: largest number of active-set iterations


class ContactState(NamedTuple):
    """Contact statuses and slip directions: the warm start of a solve (in/out)."""

    status: np.ndarray  #: (nc,) int8: 0 open, 1 stick, 2 slip
    tdir: np.ndarray  #: (nc, d-1) unit slip direction (2D: +1 or -1)


class StepOperator(NamedTuple):
    """The reduced model's step (see :func:`run_dynamic`; ``r`` reduced coordinates, ``s``
    columns of the low-rank damping, ``N`` steps per period)."""

    diag: bool  #: modal coordinates (diagonal mass, stiffness, damping + ``U R U^T``)
    a_v: np.ndarray  #: (r,) diag: weight of ``dq`` in the free increment
    b_v: np.ndarray  #: (r,) diag: weight of ``q``
    ds: np.ndarray  #: (r,) diag: diagonal of the step matrix ``S``
    hc: np.ndarray  #: (r,) diag: ``(1 - gamma) h`` per mode
    U: np.ndarray  #: (r, s) low-rank damping factor
    R: np.ndarray  #: (s, s) low-rank damping core
    P: np.ndarray  #: (r, s) Woodbury factor of ``S^-1``
    Qt: np.ndarray  #: (s, r) Woodbury factor of ``S^-1``
    bq_m: np.ndarray  #: (r, r) dense: ``S^-1 B_q``
    bd_m: np.ndarray  #: (r, r) dense: ``S^-1 B_d``
    ftab: np.ndarray  #: (N, r) free-motion forcing increment per phase [m]
    G: np.ndarray  #: (r, m) response of the increment to the contact forces [m/N]
    Tx: np.ndarray  #: (m, r) local contact displacements of the reduced coordinates
    obs: np.ndarray  #: (no, r) rows of the observed DOFs


class EnergyTerms(NamedTuple):
    """What the energy balance of the recorded steps needs (diagonal ``_v`` with the
    low-rank damping of :class:`StepOperator` added, or dense ``_m``)."""

    h: float  #: time step [s]
    ftil: np.ndarray  #: (N, r) weighted average of the applied generalised forces [N]
    m_v: np.ndarray  #: (r,) mass
    k_v: np.ndarray  #: (r,) stiffness
    c_v: np.ndarray  #: (r,) damping
    m_m: np.ndarray  #: (r, r) mass
    k_m: np.ndarray  #: (r, r) stiffness
    c_m: np.ndarray  #: (r, r) damping


class DynamicState(NamedTuple):
    """State of the dynamic loop (in/out)."""

    q: np.ndarray  #: (r,) reduced coordinates at t_n [m]
    dq: np.ndarray  #: (r,) ``q_n - q_{n-1}`` [m]
    xprev: np.ndarray  #: (m,) local contact displacements at t_n [m]
    xprev2: np.ndarray  #: (m,) at t_{n-1} [m]
    contact: ContactState  #: warm start of the contact solver


class Records(NamedTuple):
    """Output buffers of :func:`run_dynamic` (``no`` observed DOFs, ``ns`` recorded steps)."""

    keep_from: int  #: first global period whose once-per-period monitors are stored
    mon_start: np.ndarray  #: (n_keep, no + m) monitors at the start of each period
    mon_mean: np.ndarray  #: (n_keep, no + m) their mean over the period
    mon_ptp: np.ndarray  #: (n_keep, no + m) their peak-to-peak over the period
    rec_from: int  #: first global step recorded (every step from there)
    obs: np.ndarray  #: (ns, no) observed displacements [m]
    vobs: np.ndarray  #: (ns, no) observed velocities [m/s]
    x: np.ndarray  #: (ns, m) local contact displacements [m]
    lam: np.ndarray  #: (ns, m) contact forces [N]
    state: np.ndarray  #: (ns, nc) int8 statuses
    energy: np.ndarray  #: (ns, 6) energy terms [J] (see :func:`run_dynamic`)


class LoadCycle(NamedTuple):
    """The load cycle and the wear law of :func:`run_quasistatic`."""

    btab: np.ndarray  #: (N, m) condensed loads at phases ``2 pi k / N`` [N]
    area: np.ndarray  #: (nc,) tributary areas [m^2]
    kw: float  #: Archard coefficient [1/Pa]
    jumps: np.ndarray  #: (n_computed,) int64 cycles each computed cycle stands for


class WearState(NamedTuple):
    """State of the quasi-static loop (in/out)."""

    x: np.ndarray  #: (m,) local contact displacements [m]
    wear: np.ndarray  #: (nc,) wear depth [m]
    contact: ContactState  #: warm start of the contact solver


class WearRecords(NamedTuple):
    """Output buffers of :func:`run_quasistatic` (``nrec`` records)."""

    every: int  #: record every this many computed cycles (and the last)
    wear: np.ndarray  #: (nrec, nc) wear [m]
    press: np.ndarray  #: (nrec, nc) cycle-mean pressure [Pa]
    slip: np.ndarray  #: (nrec, nc) slip distance over the cycle [m]
    diss: np.ndarray  #: (nrec,) friction dissipation over the cycle [J]
    cycle: np.ndarray  #: (nrec,) int64 cycle count


# --------------------------------------------------------------------------------------------
# the contact problem
# --------------------------------------------------------------------------------------------
@njit(cache=True, fastmath=_FAST)
def _gauss_solve(a, rhs, n):
    """Solve ``a[:n, :n] y = rhs[:n]`` in place by Gaussian elimination with partial pivoting.

    ``rhs[:n]`` receives ``y``; ``a`` is destroyed. Returns False when a pivot is below
    ``1e-14`` times the largest entry (singular system).
    """
    big_all = 0.0
    for i in range(n):
        for j in range(n):
            v = abs(a[i, j])
            if v > big_all:
                big_all = v
    if n > 0 and big_all == 0.0:
        return False
    for k in range(n):
        p = k
        big = abs(a[k, k])
        for i in range(k + 1, n):
            v = abs(a[i, k])
            if v > big:
                big = v
                p = i
        if not big > 1e-14 * big_all:
            return False
        if p != k:
            for j in range(k, n):
                t = a[k, j]
                a[k, j] = a[p, j]
                a[p, j] = t
            t = rhs[k]
            rhs[k] = rhs[p]
            rhs[p] = t
        piv = a[k, k]
        for i in range(k + 1, n):
            f = a[i, k] / piv
            if f != 0.0:
                for j in range(k + 1, n):
                    a[i, j] -= f * a[k, j]
                rhs[i] -= f * rhs[k]
    for k in range(n - 1, -1, -1):
        s = rhs[k]
        for j in range(k + 1, n):
            s -= a[k, j] * rhs[j]
        rhs[k] = s / a[k, k]
    return True


@njit(cache=True, fastmath=_FAST)
def _cone_residual(A, x, lam, gap, xprev, mu, rn, rt, F, st):
    """Alart-Curnier residual of the 3D contact problem at ``x`` (``lam`` the matching forces).

    Per node, with ``sN = lam_N + rn (x_N - g)`` and ``sT = lam_T + rt xi``
    (``xi = x_T - xprev_T``): open (``sN <= 0``) ``F = lam``; else ``F_N = -rn (x_N - g)`` and
    stick (``|sT| <= mu sN``) ``F_T = -rt xi`` or slip ``F_T = lam_T - mu sN sT / |sT|``. The
    roots of ``F`` are exactly the solutions of Signorini and incremental Coulomb on the
    isotropic cone, whatever ``rn, rt > 0``. ``st`` receives the statuses. Returns
    ``(0.5 |F|^2, max |F|)``.
    """
    nc = gap.shape[0]
    phi = 0.0
    fmax = 0.0
    for i in range(nc):
        i0 = 3 * i
        sn = lam[i0] + rn[i] * (x[i0] - gap[i])
        s1 = lam[i0 + 1] + rt[i] * (x[i0 + 1] - xprev[i0 + 1])
        s2 = lam[i0 + 2] + rt[i] * (x[i0 + 2] - xprev[i0 + 2])
        if sn <= 0.0:
            st[i] = OPEN
            F[i0] = lam[i0]
            F[i0 + 1] = lam[i0 + 1]
            F[i0 + 2] = lam[i0 + 2]
        else:
            F[i0] = -rn[i] * (x[i0] - gap[i])
            ns = np.sqrt(s1 * s1 + s2 * s2)
            rad = mu[i] * sn
            if ns <= rad:
                st[i] = STICK
                F[i0 + 1] = -rt[i] * (x[i0 + 1] - xprev[i0 + 1])
                F[i0 + 2] = -rt[i] * (x[i0 + 2] - xprev[i0 + 2])
            else:
                st[i] = SLIP
                F[i0 + 1] = lam[i0 + 1] - rad * s1 / ns
                F[i0 + 2] = lam[i0 + 2] - rad * s2 / ns
        for c in range(3):
            v = F[i0 + c]
            phi += 0.5 * v * v
            if abs(v) > fmax:
                fmax = abs(v)
    return phi, fmax


@njit(cache=True, fastmath=_FAST)
def _solve_contact_cone(A, b, xref, gap, xprev, mu, status, tdir, x, lam, tol, fscale, maxit,
                        cols, J, rhs):
    """The 3D contact problem on the exact isotropic Coulomb cone (see :func:`solve_contact`).

    Semismooth Newton method on the Alart-Curnier equations (:func:`_cone_residual`, with
    ``rn, rt`` the diagonal of ``A``: stiffness-scaled augmentation, no regularisation),
    globalised by a backtracking (Armijo) line search on ``0.5 |F|^2``. The rows of closed
    normals and sticking tangents are ``x_c = target``: their Newton increments are known and
    only the other components (open nodes, slipping tangents) are solved for. Converged when
    ``max |F| <= tol * max(fscale, max |lam|)``; the prescribed components are then set
    exactly (a sticking node does not move by one rounding unit) and the test repeated with
    the forces recomputed in full. The Alart-Curnier residual is then below
    ``tol * fscale`` (a force); the direction of a slip ``xi`` is fixed to about
    ``tol * fscale / (rt |xi|)`` rad (docs/transient.md, section 2).

    Returns the number of Newton iterations, or ``-1`` when ``maxit`` iterations did not
    converge, a Newton system was singular or the line search found no decrease (a problem
    without a solution, e.g. a structure that the contact does not hold).
    """
    nc = gap.shape[0]
    m = 3 * nc
    rn = np.empty(nc)
    rt = np.empty(nc)
    dmax = 0.0
    for i in range(nc):
        rn[i] = A[3 * i, 3 * i]
        rt[i] = 0.5 * (A[3 * i + 1, 3 * i + 1] + A[3 * i + 2, 3 * i + 2])
        if rn[i] > dmax:
            dmax = rn[i]
    if dmax <= 0.0:
        dmax = 1.0
    for i in range(nc):
        if not rn[i] > 0.0:
            rn[i] = dmax
        if not rt[i] > 0.0:
            rt[i] = dmax
    # start from the warm-start statuses: closed normals at the gap, sticking and slipping
    # tangents where they were, open nodes at their free position
    for i in range(nc):
        i0 = 3 * i
        if status[i] == OPEN:
            for c in range(3):
                x[i0 + c] = xref[i0 + c]
        else:
            x[i0] = gap[i]
            x[i0 + 1] = xprev[i0 + 1]
            x[i0 + 2] = xprev[i0 + 2]
    for r in range(m):
        s = b[r]
        for c in range(m):
            s -= A[r, c] * (x[c] - xref[c])
        lam[r] = s
    F = np.empty(m)
    dx = np.empty(m)
    adx = np.empty(m)
    xt = np.empty(m)
    lt = np.empty(m)
    Ft = np.empty(m)
    st = np.empty(nc, dtype=np.int8)
    stt = np.empty(nc, dtype=np.int8)
    phi, fmax = _cone_residual(A, x, lam, gap, xprev, mu, rn, rt, F, st)
    it = 0
    while it < maxit:
        it += 1
        fs = fscale
        for r in range(m):
            if abs(lam[r]) > fs:
                fs = abs(lam[r])
        if fs == 0.0:
            for r in range(m):
                v = dmax * max(abs(xref[r]), abs(x[r]))
                if v > fs:
                    fs = v
            if fs == 0.0:
                fs = 1e-300
        eps_f = tol * fs
        if fmax <= eps_f:
            # set the prescribed components exactly, recompute the forces in full, retest
            for i in range(nc):
                i0 = 3 * i
                if st[i] != OPEN:
                    x[i0] = gap[i]
                if st[i] == STICK:
                    x[i0 + 1] = xprev[i0 + 1]
                    x[i0 + 2] = xprev[i0 + 2]
            for r in range(m):
                s = b[r]
                for c in range(m):
                    s -= A[r, c] * (x[c] - xref[c])
                lam[r] = s
            phi, fmax = _cone_residual(A, x, lam, gap, xprev, mu, rn, rt, F, st)
            if fmax <= eps_f:
                for i in range(nc):
                    status[i] = st[i]
                    if st[i] == SLIP:
                        i0 = 3 * i
                        t1 = x[i0 + 1] - xprev[i0 + 1]
                        t2 = x[i0 + 2] - xprev[i0 + 2]
                        nt = np.sqrt(t1 * t1 + t2 * t2)
                        if nt == 0.0:  # slipping by less than a rounding unit: the force
                            t1 = lam[i0 + 1]
                            t2 = lam[i0 + 2]
                            nt = np.sqrt(t1 * t1 + t2 * t2)
                        if nt > 0.0:
                            tdir[i, 0] = t1 / nt
                            tdir[i, 1] = t2 / nt
                return it
        # Newton step: increments of the prescribed components, then the free ones
        nf = 0
        for i in range(nc):
            i0 = 3 * i
            if st[i] == OPEN:
                for c in range(3):
                    cols[nf] = i0 + c
                    nf += 1
            else:
                dx[i0] = gap[i] - x[i0]
                if st[i] == STICK:
                    dx[i0 + 1] = xprev[i0 + 1] - x[i0 + 1]
                    dx[i0 + 2] = xprev[i0 + 2] - x[i0 + 2]
                else:
                    cols[nf] = i0 + 1
                    cols[nf + 1] = i0 + 2
                    nf += 2
        for k in range(nf):
            dx[cols[k]] = 0.0
        for k in range(nf):
            row = cols[k]
            i = row // 3
            i0 = 3 * i
            # full row of the Jacobian into rhs-free storage: J[k, :] over the free columns,
            # and the prescribed columns' contribution to the right-hand side
            if st[i] == OPEN:
                s = -F[row]
                for c in range(m):
                    s += A[row, c] * dx[c]  # dx is zero on the free columns
                rhs[k] = s
                for j in range(nf):
                    J[k, j] = -A[row, cols[j]]
            else:
                a = row - i0 - 1  # 0 or 1
                sn = lam[i0] + rn[i] * (x[i0] - gap[i])
                s1 = lam[i0 + 1] + rt[i] * (x[i0 + 1] - xprev[i0 + 1])
                s2 = lam[i0 + 2] + rt[i] * (x[i0 + 2] - xprev[i0 + 2])
                ns = np.sqrt(s1 * s1 + s2 * s2)
                n0 = s1 / ns
                n1 = s2 / ns
                na = n0 if a == 0 else n1
                g = mu[i] * sn / ns
                # dF_Ta = dlam_Ta - mu n_a dsN - g sum_b (delta_ab - n_a n_b) dsT_b
                # dsN = -A[N,:] dx + rn dx_N;  dsT_b = -A[T_b,:] dx + rt dx_Tb
                p0 = g * ((1.0 if a == 0 else 0.0) - na * n0)
                p1 = g * ((1.0 if a == 1 else 0.0) - na * n1)
                s = -F[row]
                for c in range(m):
                    v = (-A[row, c] + mu[i] * na * A[i0, c] + p0 * A[i0 + 1, c]
                         + p1 * A[i0 + 2, c])
                    if c == i0:
                        v -= mu[i] * na * rn[i]
                    elif c == i0 + 1:
                        v -= p0 * rt[i]
                    elif c == i0 + 2:
                        v -= p1 * rt[i]
                    Ft[c] = v
                    s -= v * dx[c]
                rhs[k] = s
                for j in range(nf):
                    J[k, j] = Ft[cols[j]]
        if nf > 0:
            if not _gauss_solve(J, rhs, nf):
                return -1
            for k in range(nf):
                dx[cols[k]] = rhs[k]
        for r in range(m):
            s = 0.0
            for c in range(m):
                s += A[r, c] * dx[c]
            adx[r] = s
        # backtracking line search on 0.5 |F|^2 (Armijo, sigma = 1e-4)
        alpha = 1.0
        accepted = False
        for _ls in range(30):
            for r in range(m):
                xt[r] = x[r] + alpha * dx[r]
                lt[r] = lam[r] - alpha * adx[r]
            phit, fmt = _cone_residual(A, xt, lt, gap, xprev, mu, rn, rt, Ft, stt)
            if phit <= (1.0 - 2e-4 * alpha) * phi:
                accepted = True
                break
            alpha *= 0.5
        if not accepted:
            return -1
        for r in range(m):
            x[r] = xt[r]
            lam[r] = lt[r]
            F[r] = Ft[r]
        for i in range(nc):
            st[i] = stt[i]
        phi, fmax = phit, fmt
    return -1


@njit(cache=True, fastmath=_FAST)
def solve_contact(A, b, xref, gap, xprev, mu, d, status, tdir, x, lam, tol, fscale, maxit,
                  cols, rows_node, rows_comp, J, rhs):
    """Solve one frictional contact problem exactly (see module docstring).

    Parameters
    ----------
    A : (m, m) condensed stiffness in the local frame [N/m], ``m = nc * d``.
    b, xref : (m,) with ``lam = b - A (x - xref)`` ([N], [m]).
    gap : (nc,) gap including wear [m]; ``x_N <= gap``.
    xprev : (m,) local displacements at the previous step [m] (tangential part used).
    mu : (nc,) friction coefficient of every node [-]. d : 2 or 3.
    status : (nc,) int8, in: guess (warm start), out: solution statuses.
    tdir : (nc, d-1), in/out: unit slip direction (2D: +1 or -1).
    x, lam : (m,) out: local displacements [m] and contact forces [N].
    tol : relative tolerance; fscale : force scale [N] (forces below ``tol*fscale`` are zero).
    maxit : maximum iterations (active-set in 2D, Newton in 3D).
    cols, rows_node, rows_comp, J, rhs : work arrays (m,), (m,), (m,), (m, m), (m,).

    Returns
    -------
    Number of iterations, or ``-1`` if the solve did not settle within ``maxit`` (2D: the
    active set; 3D: see :func:`_solve_contact_cone`).
    """
    if d == 3:
        return _solve_contact_cone(A, b, xref, gap, xprev, mu, status, tdir, x, lam, tol,
                                   fscale, maxit, cols, J, rhs)
    nc = gap.shape[0]
    m = nc * d
    dmax = 0.0
    for i in range(m):
        if A[i, i] > dmax:
            dmax = A[i, i]
    if dmax <= 0.0:
        dmax = 1.0
    # initial values of the free components
    for i in range(nc):
        i0 = i * d
        if status[i] == OPEN:
            for c in range(d):
                x[i0 + c] = xref[i0 + c]
        elif status[i] == SLIP:
            for c in range(1, d):
                x[i0 + c] = xprev[i0 + c]
    e = np.zeros(3)
    de = np.zeros((3, 3))
    xi = np.zeros(3)
    new_st = np.zeros(nc, dtype=np.int8)
    xs = np.zeros(m)
    new_dir = np.zeros((nc, d - 1))
    it = 0
    while it < maxit:
        it += 1
        # prescribed components and the list of unknowns
        nf = 0
        for i in range(nc):
            i0 = i * d
            st = status[i]
            if st == OPEN:
                for c in range(d):
                    cols[nf] = i0 + c
                    rows_node[nf] = i
                    rows_comp[nf] = c
                    nf += 1
            else:
                x[i0] = gap[i]
                if st == STICK:
                    for c in range(1, d):
                        x[i0 + c] = xprev[i0 + c]
                else:
                    for c in range(1, d):
                        cols[nf] = i0 + c
                        rows_node[nf] = i
                        rows_comp[nf] = c
                        nf += 1
        # contact forces at the current iterate: in full at the first iteration, then
        # updated with the components whose prescribed value changed (A is symmetric)
        if it == 1:
            for r in range(m):
                s = b[r]
                for c in range(m):
                    s -= A[r, c] * (x[c] - xref[c])
                lam[r] = s
        else:
            for c in range(m):
                dx = x[c] - xs[c]
                if dx != 0.0:
                    for r in range(m):
                        lam[r] -= A[c, r] * dx
        for c in range(m):
            xs[c] = x[c]
        fs = fscale
        for r in range(m):
            if abs(lam[r]) > fs:
                fs = abs(lam[r])
        if fs == 0.0:
            # no load and no force yet: the force of moving a node by the largest displacement
            for r in range(m):
                v = dmax * max(abs(xref[r]), abs(x[r]))
                if v > fs:
                    fs = v
            for i in range(nc):
                if dmax * abs(gap[i]) > fs:
                    fs = dmax * abs(gap[i])
            if fs == 0.0:
                fs = 1e-300
        eps_f = tol * fs
        eps_x = eps_f / dmax
        # residual and Jacobian of the equations of the free components
        for k in range(nf):
            i = rows_node[k]
            c = rows_comp[k]
            i0 = i * d
            ri = i0 + c
            if status[i] == OPEN:
                rhs[k] = -lam[ri]
                for j in range(nf):
                    J[k, j] = -A[ri, cols[j]]
            else:
                # slip: lam_T - mu lam_N e(xi) = 0
                nxi = 0.0
                for cc in range(1, d):
                    xi[cc - 1] = x[i0 + cc] - xprev[i0 + cc]
                    nxi += xi[cc - 1] ** 2
                nxi = np.sqrt(nxi)
                for a_ in range(d - 1):
                    for b_ in range(d - 1):
                        de[a_, b_] = 0.0
                if d == 2 or nxi <= eps_x:
                    for cc in range(d - 1):
                        e[cc] = tdir[i, cc]
                else:
                    for cc in range(d - 1):
                        e[cc] = xi[cc] / nxi
                    for a_ in range(d - 1):
                        for b_ in range(d - 1):
                            de[a_, b_] = ((1.0 if a_ == b_ else 0.0) - e[a_] * e[b_]) / nxi
                ec = e[c - 1]
                rhs[k] = -(lam[ri] - mu[i] * lam[i0] * ec)
                for j in range(nf):
                    cj = cols[j]
                    v = -A[ri, cj] + mu[i] * ec * A[i0, cj]
                    if cj >= i0 + 1 and cj < i0 + d:
                        v -= mu[i] * lam[i0] * de[c - 1, cj - i0 - 1]
                    J[k, j] = v
        res = 0.0
        for k in range(nf):
            if abs(rhs[k]) > res:
                res = abs(rhs[k])
        if nf > 0 and res > 0.0:
            if not _gauss_solve(J, rhs, nf):
                return -1
            for k in range(nf):
                x[cols[k]] += rhs[k]
                xs[cols[k]] = x[cols[k]]
            # update the forces: lam -= A[:, F] dy
            for r in range(m):
                s = 0.0
                for k in range(nf):
                    s += A[r, cols[k]] * rhs[k]
                lam[r] -= s
        # status update by the augmented (Alart-Curnier) multipliers
        #   sN = lam_N + cN (x_N - g),  sT = lam_T + cT xi
        # open if sN < 0; else stick if |sT| <= mu sN; else slip along sT. At a solution
        # these reproduce the current statuses; away from it they are the semismooth Newton
        # update (an open node that penetrates may close directly in slip).
        n_change = 0
        best = 0.0
        best_node = -1
        resid = 0.0
        for i in range(nc):
            i0 = i * d
            sn = lam[i0] + A[i0, i0] * (x[i0] - gap[i])
            nt = 0.0
            for c in range(1, d):
                e[c - 1] = lam[i0 + c] + A[i0 + 1, i0 + 1] * (x[i0 + c] - xprev[i0 + c])
                nt += e[c - 1] ** 2
            nt = np.sqrt(nt)
            st = status[i]
            new = st
            viol = 0.0
            if st == OPEN:
                if sn > eps_f:
                    new = STICK if nt <= mu[i] * sn else SLIP
                    viol = sn / eps_f
            elif sn < -eps_f:
                new = OPEN
                viol = -sn / eps_f
            elif st == STICK:
                if nt > mu[i] * sn + eps_f:
                    new = SLIP
                    viol = (nt - mu[i] * sn) / eps_f
            elif nt < mu[i] * sn - eps_f:
                new = STICK
                viol = (mu[i] * sn - nt) / eps_f
            else:
                dot = 0.0
                for c in range(d - 1):
                    dot += e[c] * tdir[i, c]
                if d == 2 and dot < 0.0 and nt > eps_f:
                    viol = nt / eps_f  # the slip reverses
                elif d == 3:
                    # residual of the cone equation with the current slip direction
                    nxi = 0.0
                    for c in range(1, d):
                        nxi += (x[i0 + c] - xprev[i0 + c]) ** 2
                    nxi = np.sqrt(nxi)
                    for c in range(d - 1):
                        xi[c] = tdir[i, c]
                    if nxi > eps_x:
                        for c in range(1, d):
                            r_ = abs(lam[i0 + c]
                                     - mu[i] * lam[i0] * (x[i0 + c] - xprev[i0 + c]) / nxi)
                            if r_ > resid:
                                resid = r_
                        for c in range(1, d):
                            xi[c - 1] = (x[i0 + c] - xprev[i0 + c]) / nxi
            new_st[i] = new
            if new == SLIP:
                if viol > 0.0 and nt > 0.0:
                    for c in range(d - 1):
                        new_dir[i, c] = e[c] / nt
                elif d == 3 and st == SLIP:
                    for c in range(d - 1):
                        new_dir[i, c] = xi[c]
                else:
                    for c in range(d - 1):
                        new_dir[i, c] = tdir[i, c]
            if viol > 0.0:
                n_change += 1
                if viol > best:
                    best = viol
                    best_node = i
        if n_change == 0 and resid <= eps_f:
            return it
        # apply the changes (only the largest one once many iterations have passed, which
        # breaks cycles); with no change (3D), Newton goes on with the new slip directions
        one_only = n_change > 0 and it > maxit // 2
        for i in range(nc):
            if one_only and i != best_node:
                continue
            status[i] = new_st[i]
            if new_st[i] == SLIP:
                for c in range(d - 1):
                    tdir[i, c] = new_dir[i, c]
    return -1



# --------------------------------------------------------------------------------------------
# the loops
# --------------------------------------------------------------------------------------------
@njit(cache=True, fastmath=_FAST)
def run_dynamic(op, en, con, opt, st, rec, n_periods, step0):
    """Advance the reduced dynamic model ``n_periods`` forcing periods with fixed steps.

    Scheme (two-step form of Newmark's rule, contact force ``lam_n`` at t_n and constraints on
    ``q_{n+1}``; see :mod:`fretwear.timedomain.integrate`)::

        dq_{n+1} = S^-1 (B_d dq_n + B_q q_n) + ftab[k] - G lam_n,   q_{n+1} = q_n + dq_{n+1}
        x_{n+1} = Tx q_{n+1} = xref - W lam_n,   A = W^-1

    with ``dq_n = q_n - q_{n-1}``.

    Parameters
    ----------
    op : :class:`StepOperator`. ``diag`` True: modal coordinates, diagonal mass and stiffness
        and damping ``diag(c) + U R U^T``; the free increment is
        ``y = a_v dq + b_v q - hc * (U R U^T dq)``, ``S^-1 y = y / ds - P (Qt y)`` (Woodbury).
        False: dense ``bq_m q + bd_m dq``.
    en : :class:`EnergyTerms` (step ``h`` [s], applied forces, mass, stiffness, damping).
    con : :class:`Contact` with ``A`` the inverse Delassus operator ``W^-1`` [N/m] and ``gap``
        the gap + wear [m].
    opt : :class:`Settings` of the contact solver.
    st : :class:`DynamicState` (in/out): ``q, dq`` reduced state [m], ``xprev, xprev2``
        contact displacements at t_n, t_{n-1}, the contact statuses (warm start).
    rec : :class:`Records`: once-per-period monitors (observed DOFs then contact
        displacements) of the periods from ``keep_from`` on, every step from ``rec_from`` on:
        ``energy`` (ns, 6) holds the external work, friction, normal contact work, damping,
        mechanical energy at t_n + h/2, numerical residual (cumulative from the first recorded
        step) [J].
    n_periods : periods to run; step0 : global index of the first step (for recording).

    Returns
    -------
    (n_failed_steps, max_iterations, first_failed_global_step)
    """
    diag, a_v, b_v, ds, hc = op.diag, op.a_v, op.b_v, op.ds, op.hc
    U, R, P, Qt, bq_m, bd_m = op.U, op.R, op.P, op.Qt, op.bq_m, op.bd_m
    ftab, G, Tx, obs = op.ftab, op.G, op.Tx, op.obs
    h, ftil = en.h, en.ftil
    m_v, k_v, c_v, m_m, k_m, c_m = en.m_v, en.k_v, en.c_v, en.m_m, en.k_m, en.c_m
    A, gap, mu, d = con.A, con.gap, con.mu, con.d
    tol, fscale, maxit = opt.tol, opt.fscale, opt.maxit
    q, dq, xprev, xprev2 = st.q, st.dq, st.xprev, st.xprev2
    status, tdir = st.contact.status, st.contact.tdir
    keep_from, rec_from = rec.keep_from, rec.rec_from
    mon_start, mon_mean, mon_ptp = rec.mon_start, rec.mon_mean, rec.mon_ptp
    r_obs, r_vobs, r_x, r_lam = rec.obs, rec.vobs, rec.x, rec.lam
    r_state, r_energy = rec.state, rec.energy
    r = q.shape[0]
    m = xprev.shape[0]
    nc = gap.shape[0]
    no = obs.shape[0]
    N = ftab.shape[0]
    nmon = no + m
    ns = r_obs.shape[0]
    nl = U.shape[1]
    dqf = np.zeros(r)
    y = np.zeros(r)
    z = np.zeros(nl)
    z2 = np.zeros(nl)
    xref = np.zeros(m)
    x = np.zeros(m)
    lam = np.zeros(m)
    zero_b = np.zeros(m)
    cols = np.zeros(m, dtype=np.int64)
    rows_node = np.zeros(m, dtype=np.int64)
    rows_comp = np.zeros(m, dtype=np.int64)
    J = np.zeros((m, m))
    rhs = np.zeros(m)
    mon = np.zeros(nmon)
    msum = np.zeros(nmon)
    mmin = np.zeros(nmon)
    mmax = np.zeros(nmon)
    tmp = np.zeros(r)
    n_fail = 0
    first_fail = -1
    max_it = 0
    step = step0
    for _ in range(n_periods):
        gp = step // N
        for k in range(N):
            # free increment
            if diag:
                for j in range(r):
                    y[j] = a_v[j] * dq[j] + b_v[j] * q[j]
                if nl > 0:
                    for l in range(nl):
                        s = 0.0
                        for j in range(r):
                            s += U[j, l] * dq[j]
                        z[l] = s
                    for l in range(nl):
                        s = 0.0
                        for l2 in range(nl):
                            s += R[l, l2] * z[l2]
                        z2[l] = s
                    for j in range(r):
                        s = 0.0
                        for l in range(nl):
                            s += U[j, l] * z2[l]
                        y[j] -= hc[j] * s
                    for l in range(nl):
                        s = 0.0
                        for j in range(r):
                            s += Qt[l, j] * y[j]
                        z[l] = s
                    for j in range(r):
                        s = 0.0
                        for l in range(nl):
                            s += P[j, l] * z[l]
                        dqf[j] = y[j] / ds[j] - s + ftab[k, j]
                else:
                    for j in range(r):
                        dqf[j] = y[j] / ds[j] + ftab[k, j]
            else:
                for j in range(r):
                    s = ftab[k, j]
                    for l in range(r):
                        s += bq_m[j, l] * q[l] + bd_m[j, l] * dq[l]
                    dqf[j] = s
            for j in range(r):
                tmp[j] = q[j] + dqf[j]
            for i in range(m):
                s = 0.0
                for j in range(r):
                    s += Tx[i, j] * tmp[j]
                xref[i] = s
            its = solve_contact(A, zero_b, xref, gap, xprev, mu, d, status, tdir, x, lam, tol,
                                fscale, maxit, cols, rows_node, rows_comp, J, rhs)
            if its < 0:
                n_fail += 1
                if first_fail < 0:
                    first_fail = step
            elif its > max_it:
                max_it = its
            # contact increment: dq_{n+1} = dqf - G lam
            for j in range(r):
                s = dqf[j]
                for i in range(m):
                    s -= G[j, i] * lam[i]
                dqf[j] = s
            # once-per-period monitors (values at t_n)
            if gp >= keep_from:
                for i in range(no):
                    s = 0.0
                    for j in range(r):
                        s += obs[i, j] * q[j]
                    mon[i] = s
                for i in range(m):
                    mon[no + i] = xprev[i]
                ip = gp - keep_from
                if k == 0:
                    for i in range(nmon):
                        mon_start[ip, i] = mon[i]
                        msum[i] = mon[i]
                        mmin[i] = mon[i]
                        mmax[i] = mon[i]
                else:
                    for i in range(nmon):
                        msum[i] += mon[i]
                        if mon[i] < mmin[i]:
                            mmin[i] = mon[i]
                        if mon[i] > mmax[i]:
                            mmax[i] = mon[i]
                if k == N - 1:
                    for i in range(nmon):
                        mon_mean[ip, i] = msum[i] / N
                        mon_ptp[ip, i] = mmax[i] - mmin[i]
            # recording of every step (values at t_n, force lam_n)
            if step >= rec_from and step - rec_from < ns:
                js = step - rec_from
                for i in range(no):
                    s = 0.0
                    sv = 0.0
                    for j in range(r):
                        s += obs[i, j] * q[j]
                        sv += obs[i, j] * (dq[j] + dqf[j])
                    r_obs[js, i] = s
                    r_vobs[js, i] = sv / (2.0 * h)
                for i in range(m):
                    r_x[js, i] = xprev[i]
                    r_lam[js, i] = lam[i]
                for i in range(nc):
                    r_state[js, i] = status[i]
                # energy: E_{n+1/2} and the works of this step
                emech = 0.0
                if diag:
                    for j in range(r):
                        w = dqf[j] / h
                        qm = q[j] + 0.5 * dqf[j]
                        emech += 0.5 * (m_v[j] * w * w + k_v[j] * qm * qm)
                else:
                    for j in range(r):
                        tmp[j] = q[j] + 0.5 * dqf[j]
                    for j in range(r):
                        sm = 0.0
                        sk = 0.0
                        for l in range(r):
                            sm += m_m[j, l] * dqf[l]
                            sk += k_m[j, l] * tmp[l]
                        emech += 0.5 * (sm * dqf[j] / (h * h) + sk * tmp[j])
                if js > 0:
                    wext = 0.0
                    wdmp = 0.0
                    for j in range(r):
                        tmp[j] = dqf[j] + dq[j]
                        wext += 0.5 * ftil[k, j] * tmp[j]
                    if diag:
                        for j in range(r):
                            wdmp += c_v[j] * tmp[j] * tmp[j]
                        for l in range(nl):
                            s = 0.0
                            for j in range(r):
                                s += U[j, l] * tmp[j]
                            z[l] = s
                        for l in range(nl):
                            for l2 in range(nl):
                                wdmp += z[l] * R[l, l2] * z[l2]
                    else:
                        for j in range(r):
                            sc = 0.0
                            for l in range(r):
                                sc += c_m[j, l] * tmp[l]
                            wdmp += sc * tmp[j]
                    wdmp /= 4.0 * h
                    wn = 0.0
                    wt = 0.0
                    for i in range(nc):
                        i0 = i * d
                        wn += 0.5 * lam[i0] * (x[i0] - xprev2[i0])
                        for c in range(1, d):
                            wt += 0.5 * lam[i0 + c] * (x[i0 + c] - xprev2[i0 + c])
                    # cumulative from the first recorded sample: added to the previous
                    # recorded row (not a local sum, which would restart at every call of
                    # this kernel, i.e. at every chunk of CHUNK_STEPS steps)
                    de_ = emech - r_energy[js - 1, 4]
                    r_energy[js, 0] = r_energy[js - 1, 0] + wext
                    r_energy[js, 1] = r_energy[js - 1, 1] + wt
                    r_energy[js, 2] = r_energy[js - 1, 2] + wn
                    r_energy[js, 3] = r_energy[js - 1, 3] + wdmp
                    r_energy[js, 5] = r_energy[js - 1, 5] + (wext - wt - wn - wdmp - de_)
                r_energy[js, 4] = emech
            # advance
            for j in range(r):
                q[j] += dqf[j]
                dq[j] = dqf[j]
            for i in range(m):
                xprev2[i] = xprev[i]
                xprev[i] = x[i]
            step += 1
    return n_fail, max_it, first_fail


@njit(cache=True, fastmath=_FAST)
def run_quasistatic(con, cyc, opt, st, rec):
    """Quasi-static load steps through cycles with Archard wear applied as it goes.

    Each step solves ``lam = b_k - A x`` (static condensation, ``A`` the condensed stiffness
    in the local frame [N/m], ``b_k`` the condensed load at phase k [N]) with the exact
    contact law, the slip measured from the previous step; then every slipping node gets
    ``dw = kw / area * lam_N |x_T - xprev_T|`` added to its wear (which opens the gap), with
    the integrand of :func:`fretwear.wear.kernels.archard_integrand` (paper eq. 12, 29).

    Parameters
    ----------
    con : :class:`Contact` with ``gap`` the initial gap [m] (the wear is added to it).
    cyc : :class:`LoadCycle`: ``btab`` the condensed loads at phases ``tau_k = 2 pi k / N``,
        k = 0..N-1 (the first computed cycle starts with a step at phase 0 from ``x`` as
        given, e.g. unloaded), the areas, the Archard coefficient, and ``jumps`` the number of
        cycles each computed cycle stands for.
    opt : :class:`Settings` of the contact solver.
    st : :class:`WearState` (in/out): local displacements ``x`` [m], ``wear`` [m], the contact
        statuses (warm start).
    rec : :class:`WearRecords` filled every ``rec.every`` computed cycles (and the last): wear
        [m], cycle-mean pressure [Pa], slip distance over the cycle [m], friction dissipation
        over the cycle [J], cycle count.

    Returns
    -------
    (n_records, n_failed_steps, max_iterations)
    """
    A, gap, mu, d = con.A, con.gap, con.mu, con.d
    tol, fscale, maxit = opt.tol, opt.fscale, opt.maxit
    btab, area, kw, jumps = cyc.btab, cyc.area, cyc.kw, cyc.jumps
    x, wear, status, tdir = st.x, st.wear, st.contact.status, st.contact.tdir
    nc = gap.shape[0]
    m = nc * d
    N = btab.shape[0]
    ncomp = jumps.shape[0]
    xprev = x.copy()
    xref = np.zeros(m)
    lam = np.zeros(m)
    geff = np.zeros(nc)
    dwc = np.zeros(nc)
    psum = np.zeros(nc)
    ssum = np.zeros(nc)
    cols = np.zeros(m, dtype=np.int64)
    rows_node = np.zeros(m, dtype=np.int64)
    rows_comp = np.zeros(m, dtype=np.int64)
    J = np.zeros((m, m))
    rhs = np.zeros(m)
    n_fail = 0
    max_it = 0
    nrec = 0
    cycles = 0
    for c in range(ncomp):
        for i in range(nc):
            dwc[i] = 0.0
            psum[i] = 0.0
            ssum[i] = 0.0
        diss = 0.0
        k_first = 0 if c == 0 else 1
        for k in range(k_first, N + 1):
            bk = btab[k % N]
            for i in range(nc):
                geff[i] = gap[i] + wear[i]
            its = solve_contact(A, bk, xref, geff, xprev, mu, d, status, tdir, x, lam, tol,
                                fscale, maxit, cols, rows_node, rows_comp, J, rhs)
            if its < 0:
                n_fail += 1
            elif its > max_it:
                max_it = its
            for i in range(nc):
                i0 = i * d
                ln = lam[i0] if lam[i0] > 0.0 else 0.0
                if status[i] == SLIP:
                    s, work = archard_integrand(ln, x[i0:i0 + d], xprev[i0:i0 + d])
                    ww = kw * work / area[i]
                    wear[i] += ww
                    dwc[i] += ww
                    ssum[i] += s
                    tw = 0.0
                    for cc in range(1, d):
                        tw += lam[i0 + cc] * (x[i0 + cc] - xprev[i0 + cc])
                    diss += tw
                if k >= 1:
                    psum[i] += ln / area[i]
            for i in range(m):
                xprev[i] = x[i]
        jc = jumps[c]
        for i in range(nc):
            wear[i] += (jc - 1) * dwc[i]
        cycles += jc
        if (c + 1) % rec.every == 0 or c == ncomp - 1:
            for i in range(nc):
                rec.wear[nrec, i] = wear[i]
                rec.press[nrec, i] = psum[i] / N
                rec.slip[nrec, i] = ssum[i]
            rec.diss[nrec] = diss
            rec.cycle[nrec] = cycles
            nrec += 1
    return nrec, n_fail, max_it
