"""The DLFT residual and Jacobian of a small problem in one compiled call (paper eq. 22-28).

For a problem of a few contact DOFs (``m H <= SMALL_MAX`` unknowns) the arithmetic of one
residual is a few thousand operations, and the Python work around it (the FFTs' set-up, the
reshapes, the Jacobian's per-node products) cost ten times more. This kernel does the same
computation as :meth:`fretwear.hb.problem.DLFTProblem.residual` on plain arrays:

    lambda_u~ = F~ - Z~ U~ + eps (U~ - W~)                       (eq. 23)
    lambda_u(t_n) = Q lambda_u~,   lambda_x = the DLFT law       (eq. 24-28, :mod:`.contact`)
    f = eps (U~ - W~) - P lambda_x                               (eq. 22)
    J = eps I - G (eps I - Z~),    G = d lambda_x~ / d lambda_u~  (block-diagonal per node)

with the time samples taken by the matrices of the real Fourier basis (``Q`` (N, H) the
inverse transform, ``P`` (H, N) the forward one, ``P Q = I``) instead of FFTs: exact, and
cheaper than an FFT's set-up for a few DOFs. The law and its Jacobian are the kernels of
:mod:`fretwear.hb.contact` (one implementation of the law). The converged answers equal those
of the general path to rounding (tests/hb/test_small.py).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from fretwear.hb.contact import _dlft_jacobian, _dlft_time

#: ``DLFTProblem`` takes this path up to this many unknowns ``m H`` (the formed Jacobian is
#: then at most 2 MiB; benchmarks/peers.py measures the gain on one- and two-DOF models)
SMALL_MAX = 512


@njit(cache=True)
def time_law(U, Z, F, W, eps, Q, mu, x_start, tol, max_sweeps, normal, nc, d):
    """``(lambda_u, lambda_x, state, sweeps)`` at the real coefficients ``U`` (m*H,),
    DOF-major: ``lambda_u`` and ``lambda_x`` samples (nc, d, N), the law's state (nc, N) and
    the passes per node (:func:`fretwear.hb.contact.dlft_time`)."""
    N, H = Q.shape
    lu_c = F - np.dot(Z, U) + eps * (U - W)
    lam_u = np.empty((nc, d, N))
    for p in range(nc):
        for c in range(d):
            row = (p * d + c) * H
            for t in range(N):
                acc = 0.0
                for h in range(H):
                    acc += Q[t, h] * lu_c[row + h]
                lam_u[p, c, t] = acc
    lam_x, state, sweeps = _dlft_time(lam_u, mu, x_start, tol, max_sweeps, normal)
    return lam_u, lam_x, state, sweeps


@njit(cache=True)
def residual(U, Z, F, W, eps, P, Q, mu, x_start, tol, max_sweeps, normal, nc, d, jacobian):
    """``(f (m*H,), J (m*H, m*H))`` of the DLFT balance at ``U`` (m*H,) (module docstring);
    ``J`` is an empty (0, 0) array unless ``jacobian``. ``Z`` (m*H, m*H) the real block
    operator, ``F``, ``W`` (m*H,) the loads and the gap (DOF-major), ``x_start`` (nc, d-1) the
    stick anchors ``eps X_a``, ``normal`` (nc, N) the prescribed normal forces (NaN rows:
    unilateral)."""
    n = U.size
    H, N = P.shape
    lam_u, lam_x, state, _ = time_law(U, Z, F, W, eps, Q, mu, x_start, tol, max_sweeps,
                                      normal, nc, d)
    f = np.empty(n)
    for p in range(nc):
        for c in range(d):
            row = (p * d + c) * H
            for h in range(H):
                acc = 0.0
                for t in range(N):
                    acc += P[h, t] * lam_x[p, c, t]
                f[row + h] = eps * (U[row + h] - W[row + h]) - acc
    if not jacobian:
        return f, np.empty((0, 0))
    G = _dlft_jacobian(lam_u, lam_x, state, mu, P, Q, x_start, tol, max_sweeps, normal)
    dH = d * H
    J = np.empty((n, n))
    for p in range(nc):
        r0 = p * dH
        J[r0:r0 + dH, :] = np.dot(G[p], np.ascontiguousarray(Z[r0:r0 + dH, :]))  # G Z
        for i in range(dH):
            for j in range(dH):
                J[r0 + i, r0 + j] -= eps * G[p, i, j]
    for i in range(n):
        J[i, i] += eps
    return f, J
