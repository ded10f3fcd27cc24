"""Numba kernels of the time-domain reference solvers: the integration loops
(:mod:`fretwear.timedomain.integrate`, :mod:`fretwear.timedomain.quasistatic`).

* :func:`run_dynamic` -- the fixed-step time loop of the dynamic solver (two-step form of the
  trapezoidal / Newmark rule with the contact problem solved at every step).
* :func:`run_quasistatic` -- load steps through cycles with Archard wear applied as it goes
  (the integrand of :func:`fretwear.wear.kernels.archard_integrand`).

Both solve the contact problem of every step with
:func:`fretwear.timedomain.contact_solve.solve_contact`, described by the records of that
module (:class:`~fretwear.timedomain.contact_solve.Contact`,
:class:`~fretwear.timedomain.contact_solve.Settings`,
:class:`~fretwear.timedomain.contact_solve.ContactState`) on arrays allocated once by
:func:`~fretwear.timedomain.contact_solve.contact_buffers`. Their own records (named tuples of
arrays and scalars, grouped by meaning): for the dynamic loop :class:`StepOperator` (the
reduced model's step), :class:`EnergyTerms` (what the energy balance needs),
:class:`DynamicState`, :class:`Records` (output buffers); for the quasi-static loop
:class:`LoadCycle` (loads and wear law), :class:`WearState`, :class:`WearRecords`. Every array
is C-contiguous (float64 unless said otherwise) and every scalar a Python bool, float or int,
so that each loop is compiled once.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from fretwear.timedomain.contact_solve import (
    FASTMATH,
    SLIP,
    ContactState,
    contact_buffers,
    solve_contact,
)
from fretwear.wear.kernels import archard_integrand


# --------------------------------------------------------------------------------------------
# records
# --------------------------------------------------------------------------------------------
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
# the loops
# --------------------------------------------------------------------------------------------
@njit(cache=True, fastmath=FASTMATH)
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
    con : :class:`~fretwear.timedomain.contact_solve.Contact` with ``A`` the inverse Delassus
        operator ``W^-1`` [N/m] and ``gap`` the gap + wear [m].
    opt : :class:`~fretwear.timedomain.contact_solve.Settings` of the contact solver.
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
    zero_b = np.zeros(m)
    xref, x, lam, cols, rows_node, rows_comp, J, rhs = contact_buffers(m)
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


@njit(cache=True, fastmath=FASTMATH)
def run_quasistatic(con, cyc, opt, st, rec):
    """Quasi-static load steps through cycles with Archard wear applied as it goes.

    Each step solves ``lam = b_k - A x`` (static condensation, ``A`` the condensed stiffness
    in the local frame [N/m], ``b_k`` the condensed load at phase k [N]) with the exact
    contact law, the slip measured from the previous step; then every slipping node gets
    ``dw = kw / area * lam_N |x_T - xprev_T|`` added to its wear (which opens the gap), with
    the integrand of :func:`fretwear.wear.kernels.archard_integrand` (paper eq. 12, 29).

    Parameters
    ----------
    con : :class:`~fretwear.timedomain.contact_solve.Contact` with ``gap`` the initial gap [m]
        (the wear is added to it).
    cyc : :class:`LoadCycle`: ``btab`` the condensed loads at phases ``tau_k = 2 pi k / N``,
        k = 0..N-1 (the first computed cycle starts with a step at phase 0 from ``x`` as
        given, e.g. unloaded), the areas, the Archard coefficient, and ``jumps`` the number of
        cycles each computed cycle stands for.
    opt : :class:`~fretwear.timedomain.contact_solve.Settings` of the contact solver.
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
    geff = np.zeros(nc)
    dwc = np.zeros(nc)
    psum = np.zeros(nc)
    ssum = np.zeros(nc)
    xref, _x, lam, cols, rows_node, rows_comp, J, rhs = contact_buffers(m)
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
