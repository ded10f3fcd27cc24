"""Numba kernels of the contact problem of the time-domain solvers: one exact frictional
contact problem on the contact DOFs per call.

:func:`solve_contact` solves it in *primal* form ``lam = b - A (x - xref)`` (``x`` local
contact displacements [m], ``lam`` contact forces [N], ``A`` a dense condensed stiffness
[N/m]): Signorini ``x_N <= g, lam_N >= 0, lam_N (x_N - g) = 0`` and incremental Coulomb on the
slip increment ``xi = x_T - xprev_T`` (stick ``xi = 0``, ``|lam_T| <= mu lam_N``; slip
``lam_T = mu lam_N xi / |xi|``, the isotropic cone in 3D). In 2D, a primal-dual active set
method: statuses (open, stick, slip) are guessed, the (small) system for the free components
is solved, statuses are corrected, until nothing changes. In 3D (:func:`_solve_contact_cone`),
a semismooth Newton method on the Alart-Curnier equations with a backtracking line search (the
active set cycled there: the slip direction is an unknown). Both solve only for the free
components (open nodes, tangential components of slipping nodes), so a step where most nodes
stick costs a few small solves, and both are warm-started from the previous step's statuses.

The loops of :mod:`fretwear.timedomain.kernels` describe the problem with the records
:class:`Contact` (the contact problem), :class:`Settings` (the solver's settings) and
:class:`ContactState` (statuses and slip directions, the warm start), allocate the arrays of a
solve once with :func:`contact_buffers`, and call :func:`solve_contact` on plain arrays at
every step: passing it records instead cost up to a quarter more time per step on a one-node
3D problem (measured), and nothing on large ones.

Status codes: 0 = open (separation), 1 = stick, 2 = slip.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

#: fast-math flags of the kernels: reassociation lets LLVM vectorise the dot products (no
#: NaN/Inf assumptions)
FASTMATH = {"reassoc", "contract", "nsz", "arcp"}

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

class ContactBuffers(NamedTuple):
    """The arrays of one contact solve (``m = nc * d``), allocated once per loop call by
    :func:`contact_buffers` and passed to :func:`solve_contact` one by one."""

    xref: np.ndarray  #: (m,) free (reference) local displacements [m]
    x: np.ndarray  #: (m,) out: local displacements [m]
    lam: np.ndarray  #: (m,) out: contact forces [N]
    cols: np.ndarray  #: (m,) int64 work array
    rows_node: np.ndarray  #: (m,) int64 work array
    rows_comp: np.ndarray  #: (m,) int64 work array
    J: np.ndarray  #: (m, m) work array
    rhs: np.ndarray  #: (m,) work array


@njit(cache=True, inline="always")
def contact_buffers(m):
    """Zeroed :class:`ContactBuffers` for ``m`` local contact components.

    Inlined into the loops (numba IR): their results are then the same, bit for bit, as with
    the arrays allocated in their own body. Called instead, the loops' results moved in the
    last bits (measured; presumably LLVM then no longer knows that the arrays are new and
    alias nothing, and vectorises the loops' sums differently)."""
    return ContactBuffers(np.zeros(m), np.zeros(m), np.zeros(m), np.zeros(m, dtype=np.int64),
                          np.zeros(m, dtype=np.int64), np.zeros(m, dtype=np.int64),
                          np.zeros((m, m)), np.zeros(m))


# --------------------------------------------------------------------------------------------
# the contact problem
# --------------------------------------------------------------------------------------------
@njit(cache=True, fastmath=FASTMATH)
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


@njit(cache=True, fastmath=FASTMATH, inline="always")
def _forces(A, b, x, xref, lam):
    """The contact forces ``lam = b - A (x - xref)`` [N] in full (into ``lam``). Inlined (numba
    IR) where it is called, as :func:`contact_buffers` is, so that the callers compile as with
    the loop written out in them."""
    m = lam.shape[0]
    for r in range(m):
        s = b[r]
        for c in range(m):
            s -= A[r, c] * (x[c] - xref[c])
        lam[r] = s


@njit(cache=True, fastmath=FASTMATH)
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


@njit(cache=True, fastmath=FASTMATH)
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
    _forces(A, b, x, xref, lam)
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
            _forces(A, b, x, xref, lam)
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


@njit(cache=True, fastmath=FASTMATH)
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
            _forces(A, b, x, xref, lam)
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
