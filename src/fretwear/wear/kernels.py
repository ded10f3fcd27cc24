"""Numba kernels of the wear rate (paper eq. 29) and its derivative for the implicit scheme.

Archard's integrand ``lambda_N |dx_T|`` of one node over one step is written once,
:func:`archard_integrand`; the DLFT slip work below, the time-averaged rate
(:mod:`fretwear.timedomain.averaged_rate`, through :func:`slip_work_samples`) and the quasi-static
load steps (:func:`fretwear.timedomain.kernels.run_quasistatic`) all sum it.

For every contact node ``p`` the kernel :func:`slip_work` evaluates the *slip work integral*

    S_p = sum over slip instants n of  lambda_N(n) |X_T(n) - X_T(n-1)|        [N m]

on the converged DLFT samples (:mod:`fretwear.hb.contact`): ``lambda_N(n) = lambda_u,N(n)`` in
slip (``lambda_x,N = 0``), ``X = lambda_x / eps`` and ``X_T(-1) = X_T(N-1)`` (periodic). With
Archard's law the wear depth per cycle is ``k_w S_p / area_p`` (eq. 29 with the corrected slip);
with Coulomb slip the friction energy per cycle is exactly ``mu S_p``.

The derivative ``dS_p / d lambda_u~`` (with respect to the real Fourier coefficients of the
node's ``lambda_u``) follows the recursion of :func:`fretwear.hb.contact.dlft_jacobian`:
``A(n) = d lambda_x(n) / d lambda_u~ = A0(n) + S(n) seed`` with ``seed = A_T(-1) = A_T(N-1)``
(the wrap-around of the period, solved exactly), and

    dS_p = sum_slip  |dX(n)| Q[n, :] e_N  +  lambda_N(n) t(n) . (A_T(n) - A_T(n-1)) / eps,

``t(n) = dX_T(n) / |dX_T(n)|`` (zero when the node does not move). Everything here works on
plain arrays; the bookkeeping (areas, coefficients, chaining with ``d lambda_u~ / dU``) is in
:mod:`fretwear.wear.simulate`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from fretwear.hb.contact import SEPARATION, SLIP, STICK, slip_derivative_step


@njit(cache=True)
def archard_integrand(lam_n, x_now, x_before):
    """Archard's integrand for one node over one step (paper eq. 12, 29): ``lambda_N |dx_T|``.

    Parameters
    ----------
    lam_n : normal contact force over the step [N] (compression positive).
    x_now, x_before : (d,) the node's local components ``[N, T1, (T2)]`` at the end and at
        the start of the step (only the tangential ones are used). Displacements [m]; the DLFT
        passes ``lambda_x = eps X`` [N] and divides the sum by ``eps``.

    Returns
    -------
    ``(slip, work)``: the slip increment length ``|x_T(now) - x_T(before)|`` and
    ``lam_n * slip``. Every wear integral of fretwear (the DLFT samples, the time integration,
    the quasi-static load steps) sums this over the slip steps of a node.
    """
    s2 = 0.0
    for c in range(1, x_now.shape[0]):
        dx = x_now[c] - x_before[c]
        s2 += dx * dx
    slip = np.sqrt(s2)
    return slip, lam_n * slip


@njit(cache=True)
def slip_work_samples(lam_n, x, state):
    """Archard's integrand at every instant of a periodic sequence of samples.

    Parameters
    ----------
    lam_n : (nc, N) normal contact force of the step ending at each instant [N].
    x : (nc, d, N) local displacements at the instants [m]; the step ending at instant 0
        starts at instant ``N - 1`` (periodic).
    state : (nc, N) int8 contact state of the step ending at each instant.

    Returns
    -------
    ``(slip, work)``, (nc, N) each: :func:`archard_integrand` of each step, zero unless the
    node slips over it [m], [N m].
    """
    nc, d, N = x.shape
    slip = np.zeros((nc, N))
    work = np.zeros((nc, N))
    for p in range(nc):
        for n in range(N):
            if state[p, n] != SLIP:
                continue
            m = n - 1 if n > 0 else N - 1
            slip[p, n], work[p, n] = archard_integrand(lam_n[p, n], x[p, :, n], x[p, :, m])
    return slip, work


@njit(cache=True)
def slip_work(lam_u, lam_x, state, eps):
    """Slip work integral ``S_p`` per node (nc,) [N m] (see module docstring).

    Parameters
    ----------
    lam_u, lam_x : (nc, d, N) DLFT samples of ``lambda_u`` and ``lambda_x`` [N].
    state : (nc, N) int8 contact states (0 separation, 1 stick, 2 slip).
    eps : DLFT penalty [N/m].
    """
    nc, d, N = lam_u.shape
    out = np.zeros(nc)
    for p in range(nc):
        acc = 0.0
        for n in range(N):
            if state[p, n] != SLIP:
                continue
            m = n - 1 if n > 0 else N - 1
            acc += archard_integrand(lam_u[p, 0, n], lam_x[p, :, n], lam_x[p, :, m])[1]
        out[p] = acc / eps
    return out


@njit(cache=True)
def slip_work_gradient(lam_u, lam_x, state, mu, Q, eps):
    """``S_p`` (nc,) [N m] and ``dS_p / d lambda_u~`` (nc, d*H) [m] per node.

    Parameters
    ----------
    lam_u, lam_x : (nc, d, N) converged DLFT samples [N].
    state : (nc, N) int8 contact states.
    mu : (nc,) friction coefficients.
    Q : (N, H) inverse real DFT (samples = Q @ coefficients).
    eps : DLFT penalty [N/m].

    Returns
    -------
    S : (nc,) slip work; dS : (nc, d*H) with columns ordered ``c*H + h`` (component ``c`` of
    the node, real Fourier coefficient ``h``), as the blocks of
    :func:`fretwear.hb.contact.dlft_jacobian`. Nodes that stick (or are separated) all period
    have ``S = 0`` and a zero gradient.
    """
    nc, d, N = lam_u.shape
    H = Q.shape[1]
    dt = d - 1
    dH = d * H
    S_out = np.zeros(nc)
    G_out = np.zeros((nc, dH))
    A0 = np.zeros((d, dH))  # seed-independent part of A(n)
    Sd = np.zeros((d, dt))  # d lambda_x(n) / d seed
    A0p = np.zeros((dt, dH))  # tangential rows at n-1
    Sdp = np.zeros((dt, dt))
    B = np.zeros((dt, dt))
    that = np.zeros(dt)
    tdx = np.zeros(dt)
    tmpA = np.zeros((dt, dH))
    tmpS = np.zeros((dt, dt))
    gs = np.zeros(dt)  # accumulated coefficient of the seed
    for p in range(nc):
        A0[:, :] = 0.0
        Sd[:, :] = 0.0
        for c in range(dt):
            Sd[1 + c, c] = 1.0
        gs[:] = 0.0
        grad = G_out[p]
        acc = 0.0
        any_slip = False
        for n in range(N):
            # keep A_T(n-1) before updating to A_T(n)
            for a in range(dt):
                for j in range(dH):
                    A0p[a, j] = A0[1 + a, j]
                for j in range(dt):
                    Sdp[a, j] = Sd[1 + a, j]
            st = state[p, n]
            if st == SEPARATION:
                A0[:, :] = 0.0
                for c in range(d):
                    for h in range(H):
                        A0[c, c * H + h] = Q[n, h]
                Sd[:, :] = 0.0
            elif st == STICK:
                A0[0, :] = 0.0
                Sd[0, :] = 0.0
            else:
                any_slip = True
                pn = lam_u[p, 0, n]
                m = n - 1 if n > 0 else N - 1
                slip_derivative_step(lam_u[p], lam_x[p], n, m, mu[p], Q, A0, Sd, that, B,
                                     tmpA, tmpS, np.nan)
                # the wear integrand pn |dX| and its derivative
                sl, w = archard_integrand(pn, lam_x[p, :, n], lam_x[p, :, m])
                acc += w
                for a in range(dt):
                    tdx[a] = lam_x[p, 1 + a, n] - lam_x[p, 1 + a, m]
                for h in range(H):
                    grad[h] += sl * Q[n, h]  # d pn / d lambda_u~ = Q[n, :] on component N
                if sl > 0.0:
                    w = pn / sl
                    for a in range(dt):
                        ca = w * tdx[a]
                        for j in range(dH):
                            grad[j] += ca * (A0[1 + a, j] - A0p[a, j])
                        for j in range(dt):
                            gs[j] += ca * (Sd[1 + a, j] - Sdp[a, j])
        gs_zero = True
        for j in range(dt):
            if gs[j] != 0.0:
                gs_zero = False
        if not any_slip:
            continue
        if gs_zero:  # S does not depend on the state before n = 0
            S_out[p] = acc / eps
            for j in range(dH):
                grad[j] /= eps
            continue
        # seed = A_T(N-1) = A0_T(N-1) + S_T(N-1) seed  ->  (I - S_T) seed = A0_T
        M = np.eye(dt)
        for a in range(dt):
            for b in range(dt):
                M[a, b] -= Sd[1 + a, b]
        seed = np.linalg.solve(M, A0[1:, :].copy())
        for j in range(dH):
            s = 0.0
            for b in range(dt):
                s += gs[b] * seed[b, j]
            grad[j] += s
        S_out[p] = acc / eps
        for j in range(dH):
            grad[j] /= eps
    return S_out, G_out
