"""Numba kernels of the time-domain reference solvers (:mod:`fretwear.timedomain.integrate`).

Three pieces, all on plain arrays:

* :func:`solve_contact` -- one exact frictional contact problem on the contact DOFs in
  *primal* form ``lam = b - A (x - xref)`` (``x`` local contact displacements [m], ``lam``
  contact forces [N], ``A`` a dense condensed stiffness [N/m]): Signorini
  ``x_N <= g, lam_N >= 0, lam_N (x_N - g) = 0`` and incremental Coulomb on the slip increment
  ``xi = x_T - xprev_T`` (stick ``xi = 0``, ``|lam_T| <= mu lam_N``; slip
  ``lam_T = mu lam_N xi / |xi|``). Solved by a primal-dual active set / semismooth Newton
  method: statuses (open, stick, slip) are guessed, the (small) system for the free components
  is solved, statuses are corrected, until nothing changes. The unknowns are only the free
  components (open nodes, tangential components of slipping nodes), so a step where most
  nodes stick costs a few small solves. Warm-started from the previous step's statuses.
* :func:`run_dynamic` -- the fixed-step time loop of the dynamic solver (two-step form of the
  trapezoidal / Newmark rule with the contact problem solved at every step).
* :func:`run_quasistatic` -- load steps through cycles with Archard wear applied as it goes.

Status codes: 0 = open (separation), 1 = stick, 2 = slip.
"""

from __future__ import annotations

import numpy as np
from numba import njit

# reassociation lets LLVM vectorise the dot products (no NaN/Inf assumptions)
_FAST = {"reassoc", "contract", "nsz", "arcp"}

OPEN = 0
STICK = 1
SLIP = 2


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
def solve_contact(A, b, xref, gap, xprev, mu, d, status, tdir, x, lam, tol, fscale, maxit,
                  cols, rows_node, rows_comp, J, rhs):
    """Solve one frictional contact problem exactly (see module docstring).

    Parameters
    ----------
    A : (m, m) condensed stiffness in the local frame [N/m], ``m = nc * d``.
    b, xref : (m,) with ``lam = b - A (x - xref)`` ([N], [m]).
    gap : (nc,) gap including wear [m]; ``x_N <= gap``.
    xprev : (m,) local displacements at the previous step [m] (tangential part used).
    mu : friction coefficient [-]. d : 2 or 3.
    status : (nc,) int8, in: guess (warm start), out: solution statuses.
    tdir : (nc, d-1), in/out: unit slip direction (2D: +1 or -1).
    x, lam : (m,) out: local displacements [m] and contact forces [N].
    tol : relative tolerance; fscale : force scale [N] (forces below ``tol*fscale`` are zero).
    maxit : maximum active-set iterations.
    cols, rows_node, rows_comp, J, rhs : work arrays (m,), (m,), (m,), (m, m), (m,).

    Returns
    -------
    Number of iterations, or ``-1`` if the active set did not settle within ``maxit``.
    """
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
                rhs[k] = -(lam[ri] - mu * lam[i0] * ec)
                for j in range(nf):
                    cj = cols[j]
                    v = -A[ri, cj] + mu * ec * A[i0, cj]
                    if cj >= i0 + 1 and cj < i0 + d:
                        v -= mu * lam[i0] * de[c - 1, cj - i0 - 1]
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
                    new = STICK if nt <= mu * sn else SLIP
                    viol = sn / eps_f
            elif sn < -eps_f:
                new = OPEN
                viol = -sn / eps_f
            elif st == STICK:
                if nt > mu * sn + eps_f:
                    new = SLIP
                    viol = (nt - mu * sn) / eps_f
            elif nt < mu * sn - eps_f:
                new = STICK
                viol = (mu * sn - nt) / eps_f
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
                            r_ = abs(lam[i0 + c] - mu * lam[i0] * (x[i0 + c] - xprev[i0 + c])
                                     / nxi)
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


@njit(cache=True, fastmath=_FAST)
def run_dynamic(q, dq, diag, a_v, b_v, ds, hc, U, R, P, Qt, bq_m, bd_m, ftab, G, Tx, A, gap,
                xprev, xprev2, mu, d, status, tdir, n_periods, step0, tol, fscale, maxit,
                obs, keep_from, mon_start, mon_mean, mon_ptp, rec_from, h, ftil, m_v, k_v, c_v,
                m_m, k_m, c_m, r_obs, r_vobs, r_x, r_lam, r_state, r_energy):
    """Advance the reduced dynamic model ``n_periods`` forcing periods with fixed steps.

    Scheme (two-step form of Newmark's rule, contact force ``lam_n`` at t_n and constraints on
    ``q_{n+1}``; see :mod:`fretwear.timedomain.integrate`)::

        dq_{n+1} = S^-1 (B_d dq_n + B_q q_n) + ftab[k] - G lam_n,   q_{n+1} = q_n + dq_{n+1}
        x_{n+1} = Tx q_{n+1} = xref - W lam_n,   A = W^-1

    with ``dq_n = q_n - q_{n-1}``.

    Parameters
    ----------
    q, dq : (r,) reduced state (in/out) [m].
    diag : bool. True: modal coordinates, diagonal mass and stiffness and damping
        ``diag(c) + U R U^T``; the free increment is
        ``y = a_v dq + b_v q - hc * (U R U^T dq)``, ``S^-1 y = y / ds - P (Qt y)`` (Woodbury).
        False: dense ``bq_m q + bd_m dq``.
    ftab : (N, r) free-motion forcing increment per phase of the period [m].
    G : (r, m) response of the increment to the contact forces [m/N].
    Tx : (m, r) local contact displacements of the reduced coordinates.
    A : (m, m) inverse Delassus operator [N/m].
    gap : (nc,) gap + wear [m]. xprev, xprev2 : (m,) contact displacements at t_n, t_{n-1}.
    status, tdir : contact statuses / slip directions (warm start, in/out).
    n_periods : periods to run; step0 : global index of the first step (for recording).
    obs : (no, r) observed DOFs rows. keep_from : first global period whose once-per-period
        monitors (``mon_*``, (n_keep, no + m)) are stored.
    rec_from : first global step recorded in ``r_*`` (every step from there).
    h : step [s]; ftil : (N, r) applied generalised forces [N] (energy); m_*, k_*, c_* : mass,
        stiffness, damping (diagonal ``_v``, with ``U R U^T`` added to the damping, or dense
        ``_m``) for the energy.
    r_obs, r_vobs : (ns, no); r_x, r_lam : (ns, m); r_state : (ns, nc) int8;
    r_energy : (ns, 6): external work, friction, normal contact work, damping, mechanical
        energy at t_n + h/2, numerical residual (cumulative from the first recorded step) [J].

    Returns
    -------
    (n_failed_steps, max_iterations, first_failed_global_step)
    """
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
    cum = np.zeros(6)
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
                    cum[0] += wext
                    cum[1] += wt
                    cum[2] += wn
                    cum[3] += wdmp
                    de_ = emech - r_energy[js - 1, 4]
                    cum[5] += wext - wt - wn - wdmp - de_
                r_energy[js, 0] = cum[0]
                r_energy[js, 1] = cum[1]
                r_energy[js, 2] = cum[2]
                r_energy[js, 3] = cum[3]
                r_energy[js, 4] = emech
                r_energy[js, 5] = cum[5]
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
def run_quasistatic(A, btab, gap, wear, area, mu, kw, d, jumps, x, status, tdir, tol,
                    fscale, maxit, rec_every, r_wear, r_press, r_slip, r_diss, r_cycle):
    """Quasi-static load steps through cycles with Archard wear applied as it goes.

    Each step solves ``lam = b_k - A x`` (static condensation, ``A`` the condensed stiffness
    in the local frame [N/m], ``b_k`` the condensed load at phase k [N]) with the exact
    contact law, the slip measured from the previous step; then every node gets
    ``dw = kw * (lam_N / area) * |x_T - xprev_T|`` added to its wear (which opens the gap).

    Parameters
    ----------
    btab : (N, m) condensed loads at phases ``tau_k = 2 pi k / N``, k = 0..N-1 [N]. The first
        computed cycle starts with a step at phase 0 from ``x`` as given (e.g. unloaded).
    gap : (nc,) initial gap [m]; wear : (nc,) in/out wear depth [m].
    area : (nc,) tributary areas [m^2]; kw : Archard coefficient [1/Pa].
    jumps : (n_computed,) number of cycles each computed cycle stands for.
    x : (m,) in/out local displacements [m]; status, tdir : warm start (in/out).
    rec_every : record every ``rec_every`` computed cycles (and the last).
    r_wear, r_press, r_slip : (nrec, nc); r_diss : (nrec,); r_cycle : (nrec,) int64 outputs:
        wear [m], cycle-mean pressure [Pa], slip distance over the cycle [m], friction
        dissipation over the cycle [J], cycle count.

    Returns
    -------
    (n_records, n_failed_steps, max_iterations)
    """
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
                s = 0.0
                for cc in range(1, d):
                    s += (x[i0 + cc] - xprev[i0 + cc]) ** 2
                s = np.sqrt(s)
                ln = lam[i0] if lam[i0] > 0.0 else 0.0
                if status[i] != SLIP:
                    s = 0.0
                ww = kw * ln / area[i] * s
                wear[i] += ww
                dwc[i] += ww
                ssum[i] += s
                if k >= 1:
                    psum[i] += ln / area[i]
                tw = 0.0
                for cc in range(1, d):
                    tw += lam[i0 + cc] * (x[i0 + cc] - xprev[i0 + cc])
                if status[i] == SLIP:
                    diss += tw
            for i in range(m):
                xprev[i] = x[i]
        jc = jumps[c]
        for i in range(nc):
            wear[i] += (jc - 1) * dwc[i]
        cycles += jc
        if (c + 1) % rec_every == 0 or c == ncomp - 1:
            for i in range(nc):
                r_wear[nrec, i] = wear[i]
                r_press[nrec, i] = psum[i] / N
                r_slip[nrec, i] = ssum[i]
            r_diss[nrec] = diss
            r_cycle[nrec] = cycles
            nrec += 1
    return nrec, n_fail, max_it
