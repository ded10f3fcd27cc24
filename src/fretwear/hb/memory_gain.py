"""The law's derivative with its memory, ``G(s)`` (:func:`fretwear.hb.stability.shifted_gain`),
split once per solution into the part that does not depend on ``s`` and one outer product per
stick interval, for the evaluations of ``T(s)`` of Hill's refinement (2D contact: one
tangential direction).

In 2D a slipping sample carries nothing from the previous one (the slip gain ``B`` of
:func:`fretwear.hb.contact._slip_gain` is ``g (1 - t^2) = 0`` for ``t = +-1``) and neither
does a separated one, so the tangential row of the recursion of
:func:`~fretwear.hb.stability.shifted_gain` at a sample ``n`` that sticks since the last
sample ``l`` that did not is ``z^(n - l)`` times the row at ``l`` (``z = e^{-s h}``, one
sample step ``h``; the period wraps around), and every other row is free of ``z``. With
``P`` the forward transform, for each node

    G(s) = G_c + sum over stick intervals I of w_I(z) r_I^T,
    w_I(z) = sum_{k=1..L_I} z^k P[:, l_I + k]

(``G_c`` the rows of the samples that do not stick and the normal rows, real; ``r_I`` the
tangential row at the sample ``l_I`` that opens the interval, real): the same terms as the
recursion, summed in another order, for ``O(N H)`` operations an evaluation instead of the
``O(N H d H)`` of the samples' products. A node that sticks all period (its wrap-around is
the singular seed of :func:`~fretwear.hb.stability.shifted_gain`), a 3D contact or a slip
with a nonzero gain (``lambda_T = 0`` exactly) keep the recursion (:func:`memory_gain`
returns None).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from fretwear.hb.contact import SEPARATION, STICK, _slip_gain


@dataclass(frozen=True)
class MemoryGain:
    """``G(s)`` of one solution's law as ``G_c + sum_I w_I(z) r_I^T`` (module docstring).

    constant : (nc, dH, dH) real ``G_c``; node, start, length : (k,) per stick interval its
    node, the sample that opens it and how many samples stick; rows : (k, dH) real ``r_I``;
    P : (H, N) the forward transform."""

    constant: np.ndarray
    node: np.ndarray
    start: np.ndarray
    length: np.ndarray
    rows: np.ndarray
    P: np.ndarray

    def at(self, z: complex) -> np.ndarray:
        """``G(s)`` (nc, dH, dH) complex for ``z = e^{-s h}``."""
        return _gain_at(self.constant, self.node, self.start, self.length, self.rows,
                        self.P, complex(z))


def memory_gain(lam_u, lam_x, state, mu, P, Q, normal) -> MemoryGain | None:
    """The split of ``G(s)`` (module docstring) for the law's samples ``lam_u``, ``lam_x``
    (nc, 2, N), ``state`` (nc, N), ``mu`` (nc,), the transforms ``P`` (H, N), ``Q`` (N, H) and
    ``normal`` (nc, N) the prescribed normal forces (NaN rows: unilateral), as
    :func:`~fretwear.hb.stability.shifted_gain`'s kernel takes them; None where it does not
    apply (not 2D, a node that sticks all period, a slip sample with a nonzero gain)."""
    if lam_u.ndim != 3 or lam_u.shape[1] != 2:
        return None
    P = np.ascontiguousarray(P, dtype=float)
    out = _parts(np.ascontiguousarray(lam_u, dtype=float),
                 np.ascontiguousarray(lam_x, dtype=float), state,
                 np.ascontiguousarray(mu, dtype=float), P,
                 np.ascontiguousarray(Q, dtype=float), np.ascontiguousarray(normal, dtype=float))
    constant, node, start, length, rows, ok = out
    if not ok:
        return None
    return MemoryGain(constant, node, start, length, rows, P)


@njit(cache=True)
def _parts(lu, lx, state, mu, P, Q, normal):
    """:func:`memory_gain` compiled: ``(G_c, node, start, length, rows, ok)``."""
    nc, d, N = lu.shape
    H = P.shape[0]
    dH = d * H
    Gc = np.zeros((nc, dH, dH))
    node = np.empty(nc * N, dtype=np.int64)
    start = np.empty(nc * N, dtype=np.int64)
    length = np.empty(nc * N, dtype=np.int64)
    rows = np.zeros((nc * N, dH))
    R = np.empty((N, dH))
    R0 = np.empty((N, H))
    that = np.zeros(1)
    B = np.zeros((1, 1))
    k = 0
    for p in range(nc):
        fixed = not np.isnan(normal[p, 0])
        dcap = 0.0 if fixed else mu[p]
        R[:, :] = 0.0
        R0[:, :] = 0.0
        free = False
        for n in range(N):
            st = state[p, n]
            if st == STICK:
                if fixed:
                    for h in range(H):
                        R0[n, h] = Q[n, h]
                continue
            free = True
            if st == SEPARATION:
                for h in range(H):
                    R[n, H + h] = Q[n, h]
                    R0[n, h] = Q[n, h]
                continue
            m = n - 1 if n > 0 else N - 1
            pn = normal[p, n] if fixed else lu[p, 0, n]
            _slip_gain(lu[p], lx[p], n, lx[p, 1:, m], mu[p], pn, that, B)
            if B[0, 0] != 0.0:
                return Gc, node[:0], start[:0], length[:0], rows[:0], False
            for h in range(H):
                R[n, H + h] = Q[n, h]
                R[n, h] = -dcap * that[0] * Q[n, h]
                if fixed:
                    R0[n, h] = Q[n, h]
        if not free:  # sticks all period: the recursion's singular seed
            return Gc, node[:0], start[:0], length[:0], rows[:0], False
        Gc[p, H:, :] = np.dot(P, R)
        Gc[p, :H, :H] = np.dot(P, R0)
        for n in range(N):
            if state[p, n] == STICK or state[p, (n + 1) % N] != STICK:
                continue
            L = 0
            j = (n + 1) % N
            while state[p, j] == STICK:
                L += 1
                j = (j + 1) % N
            node[k] = p
            start[k] = n
            length[k] = L
            rows[k, :] = R[n, :]
            k += 1
    return Gc, node[:k].copy(), start[:k].copy(), length[:k].copy(), rows[:k].copy(), True


@njit(cache=True)
def _gain_at(Gc, node, start, length, rows, P, z):
    """:meth:`MemoryGain.at` compiled."""
    nc, dH, _ = Gc.shape
    H, N = P.shape
    G = np.empty((nc, dH, dH), dtype=np.complex128)
    for p in range(nc):
        for i in range(dH):
            for j in range(dH):
                G[p, i, j] = Gc[p, i, j]
    w = np.empty(H, dtype=np.complex128)
    for i in range(node.size):
        w[:] = 0.0
        f = 1.0 + 0.0j
        n = start[i]
        for _ in range(length[i]):
            f *= z
            n += 1
            if n == N:
                n = 0
            for h in range(H):
                w[h] += P[h, n] * f
        p = node[i]
        for a in range(H):
            wa = w[a]
            for j in range(dH):
                r = rows[i, j]
                if r != 0.0:
                    G[p, H + a, j] += wa * r
    return G
