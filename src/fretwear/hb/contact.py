"""DLFT contact law in the time domain and its quasi-analytic Jacobian (paper eq. 23-28).

Sign convention (see :mod:`fretwear.model.core`): ``lambda`` is the force the structure exerts
on the rigid obstacle in the node's local frame ``[N, T1, (T2)]``; ``lambda_N >= 0`` in
compression (the paper's ``lambda_N`` is negative in compression, so its "separation when
``lambda_pre,N >= 0``" reads "``<= 0``" here).

For every contact node and every instant ``n`` of ``N`` per period, given the time samples of

    lambda_u = F - Z U + eps (U - W)                      (eq. 23)

the correction ``lambda_x`` is built by prediction / correction:

* prediction (eq. 24): ``pre_T = lambda_u,T(n) - lambda_x,T(n-1)``, ``pre_N = lambda_u,N(n)``;
* separation ``pre_N <= 0``: ``lambda_x(n) = lambda_u(n)`` (eq. 26), so ``lambda(n) = 0``;
* stick ``|pre_T| < mu pre_N``: ``lambda_x,N = 0``, ``lambda_x,T(n) = lambda_x,T(n-1)`` (eq. 27);
* slip: ``lambda_x,N = 0``, ``lambda_x,T(n) = lambda_x,T(n-1) + pre_T (1 - mu pre_N/|pre_T|)``
  (eq. 28), i.e. ``lambda_T(n) = mu pre_N pre_T/|pre_T|`` on the Coulomb cone (vector norm in 3D);

and ``lambda = lambda_u - lambda_x`` (eq. 25, corrected), ``X = lambda_x / eps``.

Periodicity: the state before ``n = 0`` is the state at the end of the period. Each node's
period is swept repeatedly, each pass starting from where the last one ended, until the start
state repeats to a tolerance. A node that sticks for the whole period keeps the start state it
was given: its *stick anchor* ``eps * X_a`` (``X_a`` = where it sticks), which selects the mean
tangential position when it is not unique (docs/theory.md, "Full stick").

Jacobian (Salles et al. 2009, as the method notes describe it): the recursion is differentiated
with respect to the real Fourier coefficients of ``lambda_u``; stick carries the derivative of
``lambda_x(n-1)``, including across the wrap-around of the period (solved exactly as a small
linear fixed point), slip differentiates the projection on the cone, separation gives a zero
force derivative.
"""

from __future__ import annotations

import numpy as np
from numba import njit

SEPARATION = 0
STICK = 1
SLIP = 2
STATE_NAMES = ("separation", "stick", "slip")
ROUND = 1e-13  # relative rounding margin of the stick test (see _sweep)
#: passes over a node's period after which its periodic start state is sought by Newton's
#: method (:func:`_newton_start`): nodes whose start state repeats by then (every node in 2D,
#: where the state after a slip does not depend on the state before it) take passes only
NEWTON_AFTER = 3
#: Newton steps on the start state allowed without a decrease of its change before the passes
#: go on from the start state alone (which converge, geometrically)
NEWTON_IDLE = 3
#: smallest singular value of ``I - d Phi / d start`` below which the periodic start state is
#: not isolated (:func:`_newton_start`, :func:`_dlft_jacobian`)
SINGULAR_START = 1e-8


@njit(cache=True)
def _sweep(lu, mu, xprev, lx, state, nfix, S):
    """One pass over the period for one node; returns the final tangential correction.

    lu : (d, N) lambda_u samples; xprev : (d-1,) lambda_x,T before n = 0 (overwritten);
    lx : (d, N) output; state : (N,) output; nfix : (N,) prescribed normal force samples, or
    NaN in ``nfix[0]`` for a unilateral contact; S : (d-1, d-1), on entry the identity, on
    exit ``d lambda_x,T(N-1) / d lambda_x,T(-1)``, the derivative of the pass's end state with
    respect to its start state (a slip instant maps it by ``B = mu pre_N (I - t t^T)/|pre_T|``,
    ``t = pre_T/|pre_T|``, as in :func:`slip_derivative_step`; a separation resets it to 0;
    a stick carries it): :func:`_dlft_time`'s Newton step on the start state. The samples
    ``lx`` do not depend on it.
    """
    d, N = lu.shape
    dt = d - 1
    pre = np.empty(dt)
    fixed = not np.isnan(nfix[0])
    for n in range(N):
        pn = nfix[n] if fixed else lu[0, n]
        if pn <= 0.0:
            for c in range(d):
                lx[c, n] = lu[c, n]
            if fixed:  # no normal force, hence no friction: lambda = (pn, 0)
                lx[0, n] = lu[0, n] - pn
            state[n] = SEPARATION
        else:
            nrm2 = 0.0
            for c in range(dt):
                pre[c] = lu[1 + c, n] - xprev[c]
                nrm2 += pre[c] * pre[c]
            nrm = np.sqrt(nrm2)
            lx[0, n] = lu[0, n] - pn if fixed else 0.0
            cap = mu * pn
            # rounding margin: a periodic state set by a slip at this instant in an earlier
            # pass sits on the cone up to the rounding of lam_u,T - lam_x,T; it must stay
            # "slip" (with a vanishing increment) so that its dependence on U is kept.
            mag = 0.0
            for c in range(dt):
                mag += abs(lu[1 + c, n]) + abs(xprev[c])
            if nrm < cap - ROUND * mag:
                for c in range(dt):
                    lx[1 + c, n] = xprev[c]
                state[n] = STICK
            else:
                f = 1.0 - cap / nrm if nrm > 0.0 else 1.0  # no cone (mu = 0): free
                for c in range(dt):
                    lx[1 + c, n] = xprev[c] + pre[c] * f
                state[n] = SLIP
                _slip_map(S, pre, cap, nrm)
        for c in range(dt):
            xprev[c] = lx[1 + c, n]
        if state[n] == SEPARATION:
            S[:, :] = 0.0
    return xprev


@njit(cache=True)
def _slip_map(S, pre, cap, nrm):
    """``S <- B S`` over a slip instant, ``B = (cap/nrm) (I - t t^T)``, ``t = pre/nrm``
    (``d lambda_x,T(n) / d lambda_x,T(n-1)`` of eq. 28); ``B = 0`` without a cone."""
    dt = pre.shape[0]
    if nrm <= 0.0 or cap <= 0.0:
        S[:, :] = 0.0
        return
    g = cap / nrm
    for j in range(dt):
        proj = 0.0
        for a in range(dt):
            proj += pre[a] * S[a, j]
        proj /= nrm * nrm
        for a in range(dt):
            S[a, j] = g * (S[a, j] - pre[a] * proj)


def dlft_time(lam_u, mu, x_start, tol, max_sweeps, normal=None):
    """Corrections ``lambda_x`` for all nodes over one period (eq. 24-28): see
    :func:`_dlft_time`. ``normal`` (nc, N): prescribed normal force samples [N] per node, NaN
    rows for unilateral contacts; None: every node unilateral."""
    return _dlft_time(lam_u, mu, x_start, tol, max_sweeps, _normal(normal, lam_u))


def _normal(normal, lam_u):
    """The prescribed normal force samples (nc, N) [N] given to the kernels (NaN: unilateral)."""
    nc, _, N = lam_u.shape
    if normal is None:
        return np.full((nc, N), np.nan)
    return np.array(np.broadcast_to(np.asarray(normal, float), (nc, N)), order="C")


def kernel_array(a) -> np.ndarray:
    """``a`` as the compiled kernels take every array: float64, C-ordered and writable (a
    copy only where it is not). Numba compiles a kernel once per layout and writability of
    its arguments: read-only, Fortran-ordered or broadcast views would each cost another
    compilation (seconds) of the same kernel."""
    return np.require(a, np.float64, ["C", "W"])


@njit(cache=True)
def _dlft_time(lam_u, mu, x_start, tol, max_sweeps, normal):
    """Corrections ``lambda_x`` for all nodes over one period, made periodic (eq. 24-28).

    Parameters
    ----------
    lam_u : (nc, d, N) samples of ``lambda_u`` [N].
    mu : (nc,) friction coefficients.
    x_start : (nc, d-1) stick anchors ``eps X_a`` [N]: the tangential correction before the
        first pass (kept by nodes that stick all period).
    tol : relative tolerance of the periodicity test (on ``max |lambda_u|`` of the node).
    max_sweeps : passes allowed per node.
    normal : (nc, N) prescribed normal forces ``N(t)`` [N] (friction under a prescribed normal
        load: ``lambda_N = N(t)``, the slip threshold is ``mu N(t)``), NaN rows for nodes in
        unilateral contact (the normal force then comes from ``lambda_u,N``).

    Returns
    -------
    lam_x : (nc, d, N); state : (nc, N) int8; sweeps : (nc,) passes used (``> max_sweeps``
    flags a node whose start state did not repeat).
    """
    nc, d, N = lam_u.shape
    dt = d - 1
    lam_x = np.empty((nc, d, N))
    state = np.empty((nc, N), dtype=np.int8)
    sweeps = np.zeros(nc, dtype=np.int64)
    start = np.empty(dt)
    S = np.empty((dt, dt))
    for p in range(nc):
        scale = 0.0
        for c in range(d):
            for n in range(N):
                a = abs(lam_u[p, c, n])
                if a > scale:
                    scale = a
        thr = tol * max(scale, 1e-300)
        for c in range(dt):
            start[c] = x_start[p, c]
        k = 0
        best = np.inf  # smallest change of the start state so far
        idle = 0  # Newton steps since it last decreased
        while True:
            k += 1
            xprev = start.copy()
            S[:, :] = 0.0
            for c in range(dt):
                S[c, c] = 1.0
            end = _sweep(lam_u[p], mu[p], xprev, lam_x[p], state[p], normal[p], S)
            diff = 0.0
            for c in range(dt):
                diff = max(diff, abs(end[c] - start[c]))
            if diff <= thr:
                break
            if k > max_sweeps:
                k += 1
                break
            if diff < best:
                best, idle = diff, 0
            elif k > NEWTON_AFTER:
                idle += 1
            # Newton's step until it stops reducing the change (it may change the instants
            # that slip on its way: a step or two without decrease are allowed), then passes
            if k >= NEWTON_AFTER and idle < NEWTON_IDLE and _newton_start(start, end, S):
                continue
            for c in range(dt):
                start[c] = end[c]
        sweeps[p] = k
    return lam_x, state, sweeps


@njit(cache=True)
def _newton_start(start, end, S):
    """Newton's step on the periodicity of the start state, ``start = Phi(start)`` with
    ``Phi`` one pass over the period (:func:`_sweep`) and ``S = d Phi / d start``:
    ``start <- start + (I - S)^-1 (Phi(start) - start)``. In 3D a node in partial slip
    approaches its periodic state geometrically, by the factor ``mu pre_N / |pre_T|`` of each
    slip instant per pass across the slip direction (0.95 per pass measured on a pad near
    its slip limit: more than 200 passes), where Newton's step converges in a few passes to
    the same fixed point. False (``start`` unchanged) when ``I - S`` is singular: a node
    whose periodic state is not isolated (it sticks all period, or touches the cone without
    slipping), whose passes go on from the start state as before."""
    dt = start.shape[0]
    M = -S.copy()
    for c in range(dt):
        M[c, c] += 1.0
    if np.linalg.svd(M)[1].min() <= SINGULAR_START:
        return False
    r = np.empty((dt, 1))
    for c in range(dt):
        r[c, 0] = end[c] - start[c]
    step = np.linalg.solve(M, r)
    for c in range(dt):
        start[c] += step[c, 0]
    return True


@njit(cache=True)
def _slip_gain(lu, lx, n, prev, mu, pn, that, B):
    """The slip instant ``n``'s direction and gain (:func:`slip_derivative_step`): on the
    cone ``lambda_T(n) = lambda_u,T(n) - lambda_x,T(n) = mu pn t``, so ``that`` (d-1,) gets
    ``t``, and ``B`` (d-1, d-1) gets ``mu pn (I - t t^T) / |lambda_u,T(n) - prev|``, ``prev``
    (d-1,) the tangential ``lambda_x`` of the instant before; ``lu``, ``lx`` the node's (d, N)
    samples."""
    dt = that.shape[0]
    nrm2 = 0.0
    for c in range(dt):
        that[c] = lu[1 + c, n] - lx[1 + c, n]
        nrm2 += that[c] * that[c]
    lam_t = np.sqrt(nrm2)
    for c in range(dt):
        that[c] = that[c] / lam_t if lam_t > 0.0 else 0.0
    nrm2 = 0.0
    for c in range(dt):
        v = lu[1 + c, n] - prev[c]
        nrm2 += v * v
    rho = np.sqrt(nrm2)
    g = mu * pn / rho if rho > 0.0 else 0.0
    for a in range(dt):
        for b in range(dt):
            B[a, b] = g * ((1.0 if a == b else 0.0) - that[a] * that[b])


@njit(cache=True)
def _times_gain(B, D, tmp):
    """``D <- B D`` in place (``D`` (d-1, k): derivatives of the tangential ``lambda_x``,
    carried through a slip instant), ``tmp`` (d-1, k) a work array."""
    dt, k = D.shape
    for a in range(dt):
        for j in range(k):
            acc = 0.0
            for b in range(dt):
                acc += B[a, b] * D[b, j]
            tmp[a, j] = acc
    for a in range(dt):
        for j in range(k):
            D[a, j] = tmp[a, j]


@njit(cache=True)
def _slip_phi(D, n, Q, that, B, dcap):
    """``D <- D + (I - B) e_T phi(n) - dcap t e_N phi(n)`` (``D`` (d-1, dH), rows the
    tangential components): the slip instant ``n``'s own dependence on ``lambda_u~``
    (``dcap = mu``, or 0 under a prescribed normal force)."""
    dt = D.shape[0]
    H = Q.shape[1]
    for a in range(dt):
        for h in range(H):
            qh = Q[n, h]
            for b in range(dt):
                D[a, (1 + b) * H + h] += ((1.0 if a == b else 0.0) - B[a, b]) * qh
            D[a, h] += -dcap * that[a] * qh


@njit(cache=True)
def _propagate(lu, lx, state, mu, Q, xprev0, D, nfix):
    """Derivative of one pass of :func:`_sweep`: on entry ``D`` (d-1, dH) is
    ``d lambda_x,T(-1) / d lambda_u~`` (the derivative of the pass's start state); on exit it is
    the derivative of ``lambda_x,T(N-1)`` (the pass's end state)."""
    d, N = lu.shape
    dt = d - 1
    H = Q.shape[1]
    dH = d * H
    that = np.zeros(dt)
    B = np.zeros((dt, dt))
    tmp = np.zeros((dt, dH))
    fixed = not np.isnan(nfix[0])
    dcap = 0.0 if fixed else mu  # d (mu pn) / d lambda_u,N
    for n in range(N):
        st = state[n]
        if st == SEPARATION:
            D[:, :] = 0.0
            for c in range(dt):
                for h in range(H):
                    D[c, (1 + c) * H + h] = Q[n, h]
        elif st == SLIP:
            _slip_gain(lu, lx, n, lx[1:, n - 1] if n > 0 else xprev0,
                       mu, nfix[n] if fixed else lu[0, n], that, B)
            _times_gain(B, D, tmp)
            _slip_phi(D, n, Q, that, B, dcap)
        # STICK: D carried unchanged


@njit(cache=True)
def _start_derivative(lu, mu, Q, x_start, tol, max_sweeps, nfix):
    """Derivative of the start state of the final pass of :func:`dlft_time`, obtained by
    differentiating the passes actually made from the fixed ``x_start`` (used when the
    periodic fixed point is not isolated, e.g. a 3D node that touches the cone without
    slipping: then the result depends on the history of the passes, not on the fixed point)."""
    d, N = lu.shape
    dt = d - 1
    H = Q.shape[1]
    scale = 0.0
    for c in range(d):
        for n in range(N):
            a = abs(lu[c, n])
            if a > scale:
                scale = a
    thr = tol * max(scale, 1e-300)
    start = x_start.copy()
    D = np.zeros((dt, d * H))
    lxk = np.empty((d, N))
    stk = np.empty(N, dtype=np.int8)
    k = 0
    while True:
        k += 1
        xprev = start.copy()
        end = _sweep(lu, mu, xprev, lxk, stk, nfix, np.eye(dt))
        diff = 0.0
        for c in range(dt):
            diff = max(diff, abs(end[c] - start[c]))
        if diff <= thr or k > max_sweeps:
            return D
        Dn = D.copy()
        _propagate(lu, lxk, stk, mu, Q, start, Dn, nfix)
        D = Dn
        for c in range(dt):
            start[c] = end[c]


def dlft_jacobian(lam_u, lam_x, state, mu, P, Q, x_start=None, tol=1e-12, max_sweeps=200,
                  normal=None):
    """Derivative ``G = d lambda_x~ / d lambda_u~`` per node (nc, d*H, d*H); see
    :func:`_dlft_jacobian`. ``x_start`` (nc, d-1) are the stick anchors ``eps X_a`` given to
    :func:`dlft_time` (default zero), ``tol``, ``max_sweeps`` and ``normal`` (prescribed
    normal forces) its settings."""
    nc, d, _ = lam_u.shape
    if x_start is None:
        x_start = np.zeros((nc, d - 1))
    return _dlft_jacobian(lam_u, lam_x, state, mu, kernel_array(P), kernel_array(Q),
                          kernel_array(x_start), float(tol), int(max_sweeps),
                          _normal(normal, lam_u))


@njit(cache=True)
def slip_derivative_step(lu, lx, n, m, mu, Q, A0, S, that, B, tmpA, tmpS, pfix):
    """Advance the derivative of the recursion over a *slip* instant ``n`` (previous ``m``).

    ``A0`` (d, dH) holds ``d lambda_x(n-1) / d lambda_u~`` (seed-free part) and ``S`` (d, d-1)
    its dependence on the seed ``d lambda_x,T(-1)``; on exit they hold those of instant ``n``:
    with ``t = pre_T/|pre_T|`` and ``B = mu pre_N (I - t t^T)/|pre_T|``,
    ``A0_T(n) = (I - B) e_T phi(n) - mu t e_N phi(n) + B A0_T(n-1)``, ``S_T(n) = B S_T(n-1)``,
    ``A0_N = S_N = 0``. ``lu``, ``lx`` are the node's (d, N) samples; ``that`` (d-1,),
    ``B`` (d-1, d-1), ``tmpA`` (d-1, dH), ``tmpS`` (d-1, d-1) are work arrays (``that`` is
    left holding the slip direction). ``pfix``: the prescribed normal force at ``n`` [N], or
    NaN for a unilateral contact; when prescribed the threshold ``mu pfix`` does not depend on
    ``lambda_u`` (no ``- mu t e_N`` term) and ``lambda_x,N = lambda_u,N - pfix`` gives
    ``A0_N = e_N phi(n)``.
    """
    H = Q.shape[1]
    fixed = not np.isnan(pfix)
    pn = pfix if fixed else lu[0, n]
    dcap = 0.0 if fixed else mu
    _slip_gain(lu, lx, n, lx[1:, m], mu, pn, that, B)
    _times_gain(B, A0[1:], tmpA)
    _slip_phi(A0[1:], n, Q, that, B, dcap)
    _times_gain(B, S[1:], tmpS)
    A0[0, :] = 0.0
    S[0, :] = 0.0
    if fixed:
        for h in range(H):
            A0[0, h] = Q[n, h]


@njit(cache=True)
def _dlft_jacobian(lam_u, lam_x, state, mu, P, Q, x_start, tol, max_sweeps, normal):
    """Derivative ``G = d lambda_x~ / d lambda_u~`` per node (nc, d*H, d*H).

    Rows and columns are ordered ``c*H + h`` (component ``c`` of the node, real Fourier
    coefficient ``h``). ``P`` (H, N) is the forward DFT, ``Q`` (N, H) the inverse.
    Differentiates the converged periodic recursion of :func:`dlft_time`; the dependence on
    the state before ``n = 0`` (equal to the state at ``n = N-1``) is solved exactly. A node
    that sticks all period keeps its anchor, which does not depend on ``U``.
    """
    nc, d, N = lam_u.shape
    H = P.shape[0]
    dt = d - 1
    dH = d * H
    G = np.zeros((nc, dH, dH))
    A0 = np.zeros((d, dH))  # d lambda_x(n) / d lambda_u~ (part independent of the seed)
    S = np.zeros((d, dt))  # d lambda_x(n) / d seed, seed = d lambda_x,T(-1)
    PS = np.zeros((dH, dt))
    B = np.zeros((dt, dt))
    that = np.zeros(dt)
    tmpA = np.zeros((dt, dH))
    tmpS = np.zeros((dt, dt))
    Abuf = np.empty((d, N, dH))  # A0 and S at every instant, per component
    Sbuf = np.empty((d, N, dt))
    P = np.ascontiguousarray(P)
    for p in range(nc):
        A0[:, :] = 0.0
        S[:, :] = 0.0
        for c in range(dt):
            S[1 + c, c] = 1.0
        PS[:, :] = 0.0
        all_stick = True
        Gp = G[p]
        fixed = not np.isnan(normal[p, 0])
        for n in range(N):
            st = state[p, n]
            if st == SEPARATION:
                all_stick = False
                A0[:, :] = 0.0
                for c in range(d):
                    for h in range(H):
                        A0[c, c * H + h] = Q[n, h]
                S[:, :] = 0.0
            elif st == STICK:
                A0[0, :] = 0.0
                S[0, :] = 0.0
                if fixed:  # lambda_x,N = lambda_u,N - N(t)
                    for h in range(H):
                        A0[0, h] = Q[n, h]
            else:
                all_stick = False
                slip_derivative_step(lam_u[p], lam_x[p], n, n - 1 if n > 0 else N - 1, mu[p],
                                     Q, A0, S, that, B, tmpA, tmpS, normal[p, n])
            # keep the derivative at instant n; its DFT is taken below by one product per
            # component (BLAS: the per-instant accumulation dominated the Jacobian's cost)
            for c in range(d):
                for j in range(dH):
                    Abuf[c, n, j] = A0[c, j]
                for j in range(dt):
                    Sbuf[c, n, j] = S[c, j]
        for c in range(d):
            Gp[c * H:(c + 1) * H, :] = np.dot(P, Abuf[c])
            PS[c * H:(c + 1) * H, :] = np.dot(P, Sbuf[c])
        # seed = A_T(-1) = A_T(N-1) = A0_T(N-1) + S_T(N-1) seed  ->  (I - S_T) seed = A0_T
        M = np.eye(dt)
        for a in range(dt):
            for b in range(dt):
                M[a, b] -= S[1 + a, b]
        smin = np.linalg.svd(M)[1].min() if not all_stick else 0.0
        if smin > SINGULAR_START:
            seed = np.linalg.solve(M, A0[1:, :].copy())
        else:
            # not an isolated fixed point (all stick, or touching the cone without slipping):
            # the result depends on the passes made from x_start; differentiate them
            seed = _start_derivative(lam_u[p], mu[p], Q, x_start[p].copy(), tol, max_sweeps,
                                         normal[p])
        for row in range(dH):
            for j in range(dH):
                acc = 0.0
                for b in range(dt):
                    acc += PS[row, b] * seed[b, j]
                Gp[row, j] += acc
    return G


def friction_work(lam, x, state):
    """Energy dissipated by friction per period and node [J]: ``sum_n lambda_T(n).(X_T(n) -
    X_T(n-1))`` over slip instants (zero where the node sticks), (nc,)."""
    dx = x[:, 1:, :] - np.roll(x[:, 1:, :], 1, axis=2)
    work = np.einsum("pcn,pcn->pn", lam[:, 1:, :], dx)
    work[state != SLIP] = 0.0
    return work.sum(axis=1)


def slip_increments(x, state):
    """Corrected slip ``|X_T(n) - X_T(n-1)|`` per node and instant (nc, N) [m] (0 unless slip)."""
    dx = x[:, 1:, :] - np.roll(x[:, 1:, :], 1, axis=2)
    s = np.sqrt(np.einsum("pcn,pcn->pn", dx, dx))
    s[state != SLIP] = 0.0
    return s
