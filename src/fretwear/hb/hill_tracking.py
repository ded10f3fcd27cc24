"""Solves with the pencil ``P(sigma) = B0 + sigma B1 + sigma^2 B2`` of Hill's quadratic
problem by its harmonic structure, for the inverse iterations that continue the candidates
along a sweep (:func:`fretwear.hb.stability.track_eigen`), and the small dense LU they share
with the rest of :mod:`fretwear.hb.stability`.

The structure
-------------
In the real-coefficient layout (``[a0, a1..ak, b1..bk]`` per coordinate) the structure's
blocks ``Z(lambda)`` couple the cosine and the sine of one harmonic only; the law's ``G``,
which varies over the period, couples harmonics, but only on the coordinates it acts on (a
contact point, and after the elimination of the massless contact points, the coordinate
behind its spring). A coordinate-harmonic unknown ``i`` is *local* when every nonzero entry
of its row and its column of ``B0``, ``B1``, ``B2`` lies at an unknown of its own harmonic;
the others are the *core*. Ordered local first, grouped by harmonic,

    P = [[P_LL, P_LC], [P_CL, P_CC]]

has ``P_LL`` block-diagonal (one small block per harmonic: the cosine and sine of the local
coordinates), and ``P_LC``, ``P_CL`` join a local unknown to core unknowns of its harmonic
only (an entry ``P[c, l]`` is in ``l``'s column). The Schur complement
``S = P_CC - P_CL P_LL^-1 P_LC`` is thus formed harmonic by harmonic, and a solve costs the
LU of ``S`` (the core's size) instead of that of ``P``: on the benchmark's two-DOF
unilateral oscillator (15 harmonics) a block of 62 unknowns has a core of 31 (the coordinate
behind the contact spring; the other mass is local).

The elimination is exact (the same linear system, eliminated in another order) up to the
entries that the local/core test takes as zero (below ``DECOUPLED_TOL`` of the block's
largest, :mod:`fretwear.hb.stability`): the result differs from the LU of the whole ``P``
by rounding and by those. Pivots are not chosen across the local groups, so where a group's
LU (partial pivoting within the group) has a pivot below :data:`SPLIT_PIVOT` times the
group's largest entry that group joins the core (``sigma`` near an eigenvalue of a local
coordinate held). For the usual group, a coordinate's cosine and sine (2 x 2), this bounds
the growth of its elimination by about ``1 / SPLIT_PIVOT``; for a larger group the test is
a guard against a near-singular block, not a proved bound.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: a local group's LU whose smallest pivot is below this times the group's largest entry
#: makes :func:`_split_factor` refuse, and the group joins the core (:func:`_demote`; for a
#: cosine-sine group of 2 x 2 its elimination's growth stays below about the inverse)
SPLIT_PIVOT = 1e-3
#: the split is used where the core has at most this fraction of the block's unknowns (the
#: LU's cost goes with the cube of its size; a large core saves less than the bookkeeping)
SPLIT_MAX_SHARE = 0.75


@njit(cache=True)
def _lu_into(A, piv):
    """LU with partial pivoting of ``A`` (n, n) complex in place (``L`` unit lower below the
    diagonal, ``U`` on and above), the row order written into ``piv`` (n,): False at a zero
    pivot (where LAPACK's ``zgetrf`` reports a singular ``U``). The pivot search keeps the
    largest magnitude found so far (one ``abs`` per entry: the same pivots as comparing both
    magnitudes at every step, half the square roots)."""
    n = A.shape[0]
    for col in range(n):
        piv[col] = col
    for col in range(n):
        p = col
        big = abs(A[col, col])
        for r in range(col + 1, n):
            a = abs(A[r, col])
            if a > big:
                p, big = r, a
        if A[p, col] == 0:
            return False
        if p != col:
            for j in range(n):
                A[col, j], A[p, j] = A[p, j], A[col, j]
            piv[col], piv[p] = piv[p], piv[col]
        d = A[col, col]
        for r in range(col + 1, n):
            f = A[r, col] / d
            A[r, col] = f
            for j in range(col + 1, n):
                A[r, j] -= f * A[col, j]
    return True


@njit(cache=True)
def _lu_small(A):
    """:func:`_lu_into` with its pivots made here: ``(piv, ok)``."""
    piv = np.empty(A.shape[0], dtype=np.int64)
    ok = _lu_into(A, piv)
    return piv, ok


@njit(cache=True)
def _lu_solve_into(A, piv, b, x):
    """``x`` (n,), written, with ``A0 x = b`` from the LU of ``A0`` by :func:`_lu_into`."""
    n = A.shape[0]
    for i in range(n):
        x[i] = b[piv[i]]
    for i in range(n):
        acc = x[i]
        for j in range(i):
            acc -= A[i, j] * x[j]
        x[i] = acc
    for i in range(n - 1, -1, -1):
        acc = x[i]
        for j in range(i + 1, n):
            acc -= A[i, j] * x[j]
        x[i] = acc / A[i, i]


@njit(cache=True)
def _lu_solve_small(A, piv, b):
    """``x`` with ``A0 x = b`` from the LU of ``A0`` by :func:`_lu_small`."""
    x = np.empty(A.shape[0], dtype=np.complex128)
    _lu_solve_into(A, piv, b, x)
    return x


def no_split() -> tuple:
    """The split of a block solved whole (:func:`harmonic_split` found none)."""
    e = np.zeros(0, dtype=np.int64)
    return (e, np.zeros(1, dtype=np.int64), e, e, np.zeros(1, dtype=np.int64))


def harmonic_split(B0: np.ndarray, B1: np.ndarray, B2: np.ndarray, harm: np.ndarray,
                   tol: float) -> tuple:
    """The local unknowns and the core of the block ``B0 + s B1 + s^2 B2`` (module docstring)
    whose unknowns have the harmonics ``harm``: ``(loc, lptr, core, cpos, cptr)``, ``loc``
    the local unknowns grouped by harmonic (group ``g`` is ``loc[lptr[g]:lptr[g + 1]]``),
    ``core`` the others, ``cpos[cptr[g]:cptr[g + 1]]`` the positions in ``core`` of the
    core unknowns of group ``g``'s harmonic; :func:`no_split` where the core holds more than
    :data:`SPLIT_MAX_SHARE` of the unknowns."""
    harm = np.ascontiguousarray(harm, dtype=np.int64)
    return split_of(B0, B1, B2, harm, float(tol), SPLIT_MAX_SHARE)


@njit(cache=True)
def split_of(B0, B1, B2, harm, tol, share):
    """:func:`harmonic_split` compiled (``share``: :data:`SPLIT_MAX_SHARE`): one call from
    Python (:func:`fretwear.hb.stability._block_mats`)."""
    local = _local_unknowns(B0, B1, B2, harm, tol)
    nc = 0
    for i in range(local.size):
        nc += not local[i]
    if harm.size == 0 or nc > share * harm.size:
        e = np.zeros(0, dtype=np.int64)
        return e, np.zeros(1, dtype=np.int64), e.copy(), e.copy(), np.zeros(1, dtype=np.int64)
    return _groups(local, harm)


@njit(cache=True)
def _groups(local, harm):
    """:func:`harmonic_split`'s arrays from the local unknowns ``local`` (n,) and the
    harmonics ``harm`` (n,), compiled (the groups in increasing harmonic)."""
    n = harm.size
    top = 0
    for i in range(n):
        top = max(top, harm[i])
    core = np.flatnonzero(~local)
    nl = n - core.size
    count_l = np.zeros(top + 1, dtype=np.int64)
    count_c = np.zeros(top + 1, dtype=np.int64)
    for i in range(n):
        if local[i]:
            count_l[harm[i]] += 1
    for p in range(core.size):
        count_c[harm[core[p]]] += 1
    ng = 0
    for h in range(top + 1):
        ng += count_l[h] > 0
    loc = np.empty(nl, dtype=np.int64)
    cpos = np.empty(core.size, dtype=np.int64)
    lptr = np.zeros(ng + 1, dtype=np.int64)
    cptr = np.zeros(ng + 1, dtype=np.int64)
    g = 0
    for h in range(top + 1):
        if count_l[h] == 0:
            continue
        a, c = lptr[g], cptr[g]
        for i in range(n):
            if local[i] and harm[i] == h:
                loc[a] = i
                a += 1
        for p in range(core.size):
            if harm[core[p]] == h:
                cpos[c] = p
                c += 1
        lptr[g + 1], cptr[g + 1] = a, c
        g += 1
    return loc, lptr, core.astype(np.int64), cpos[:cptr[ng]].copy(), cptr


@njit(cache=True)
def _local_unknowns(B0, B1, B2, harm, tol):
    """Per unknown, whether its row and column of the three matrices are zero outside its
    harmonic, up to ``tol`` times the largest entry of their matrix
    (:func:`harmonic_split`)."""
    n = harm.size
    local = np.ones(n, dtype=np.bool_)
    t0, t1, t2 = 0.0, 0.0, 0.0
    for i in range(n):
        for j in range(n):
            t0 = max(t0, abs(B0[i, j]))
            t1 = max(t1, abs(B1[i, j]))
            t2 = max(t2, abs(B2[i, j]))
    t0, t1, t2 = tol * t0, tol * t1, tol * t2
    for i in range(n):
        for j in range(n):
            if harm[i] != harm[j] and (abs(B0[i, j]) > t0 or abs(B1[i, j]) > t1
                                       or abs(B2[i, j]) > t2):
                local[i] = False
                local[j] = False
    return local


@njit(cache=True)
def split_work(split, n):
    """The work arrays of :func:`_split_factor` for a block of ``n`` unknowns."""
    loc, lptr, core, cpos, cptr = split
    smax = 1
    cmax = 1
    for g in range(lptr.size - 1):
        smax = max(smax, lptr[g + 1] - lptr[g])
        cmax = max(cmax, cptr[g + 1] - cptr[g])
    F = np.zeros((max(loc.size, 1), smax), dtype=np.complex128)
    fpiv = np.zeros(max(loc.size, 1), dtype=np.int64)
    W = np.zeros((max(loc.size, 1), cmax), dtype=np.complex128)
    S = np.zeros((core.size, core.size), dtype=np.complex128)
    return F, fpiv, W, S


@njit(cache=True)
def _split_factor(A, split, work):
    """Factor ``A = P(sigma)`` (n, n) by its split (module docstring): each local group's LU
    (in ``work``'s ``F``, ``fpiv``), ``W = P_LL^-1 P_LC`` per group, the Schur complement
    ``S`` and its LU (in place). ``A`` is not changed. Returns ``(piv, bad)``: ``S``'s
    pivots, and ``bad`` -1 (factored), the first group whose LU has a pivot below
    :data:`SPLIT_PIVOT` of its largest entry (:func:`_demote` moves it to the core), or -2
    where ``S`` has a zero pivot. The groups are factored and solved in the work arrays
    (:func:`_group_lu`, :func:`_group_solve`: :func:`_lu_small`'s and
    :func:`_lu_solve_small`'s operations, without a temporary per group)."""
    loc, lptr, core, cpos, cptr = split
    F, fpiv, W, S = work
    nc = core.size
    for i in range(nc):
        for j in range(nc):
            S[i, j] = A[core[i], core[j]]
    for g in range(lptr.size - 1):
        a, b = lptr[g], lptr[g + 1]
        ca, cb = cptr[g], cptr[g + 1]
        s = b - a
        big = 0.0
        for i in range(s):
            for j in range(s):
                F[a + i, j] = A[loc[a + i], loc[a + j]]
                big = max(big, abs(F[a + i, j]))
        if not _group_lu(F, fpiv, a, s):
            return np.arange(nc), g
        for i in range(s):
            if abs(F[a + i, i]) < SPLIT_PIVOT * big:
                return np.arange(nc), g
        for t in range(ca, cb):
            col = core[cpos[t]]
            for i in range(s):
                W[a + i, t - ca] = A[loc[a + fpiv[a + i]], col]
            _group_solve(F, a, s, W, t - ca)
        for u in range(ca, cb):
            row = core[cpos[u]]
            for t in range(ca, cb):
                acc = 0j
                for i in range(s):
                    acc += A[row, loc[a + i]] * W[a + i, t - ca]
                S[cpos[u], cpos[t]] -= acc
    piv, ok = _lu_small(S)
    return piv, -1 if ok else -2


@njit(cache=True)
def _group_lu(F, fpiv, a, s):
    """:func:`_lu_small` of the group held in rows ``a..a+s`` (columns ``0..s``) of ``F``,
    in place, its row permutation in ``fpiv[a:a+s]`` (positions within the group); False at
    a zero pivot."""
    for i in range(s):
        fpiv[a + i] = i
    for col in range(s):
        p = col
        big = abs(F[a + col, col])
        for r in range(col + 1, s):
            m = abs(F[a + r, col])
            if m > big:
                p, big = r, m
        if F[a + p, col] == 0:
            return False
        if p != col:
            for j in range(s):
                F[a + col, j], F[a + p, j] = F[a + p, j], F[a + col, j]
            fpiv[a + col], fpiv[a + p] = fpiv[a + p], fpiv[a + col]
        d = F[a + col, col]
        for r in range(col + 1, s):
            f = F[a + r, col] / d
            F[a + r, col] = f
            for j in range(col + 1, s):
                F[a + r, j] -= f * F[a + col, j]
    return True


@njit(cache=True)
def _group_solve(F, a, s, X, c):
    """Column ``c`` of rows ``a..a+s`` of ``X`` (the right side, already permuted by the
    group's pivots) overwritten by the solution with the group's LU (:func:`_group_lu`;
    :func:`_lu_solve_small`'s operations)."""
    for i in range(s):
        acc = X[a + i, c]
        for j in range(i):
            acc -= F[a + i, j] * X[a + j, c]
        X[a + i, c] = acc
    for i in range(s - 1, -1, -1):
        acc = X[a + i, c]
        for j in range(i + 1, s):
            acc -= F[a + i, j] * X[a + j, c]
        X[a + i, c] = acc / F[a + i, i]


@njit(cache=True)
def _demote(split, g):
    """The split with local group ``g`` moved to the core (appended; the other groups'
    positions in the core do not change, and no other group has its harmonic): where
    ``sigma`` is near an eigenvalue of that group's coordinates held, the Schur complement
    pivots across it instead (:func:`_split_factor`)."""
    loc, lptr, core, cpos, cptr = split
    a, b = lptr[g], lptr[g + 1]
    ca, cb = cptr[g], cptr[g + 1]
    s, sc = b - a, cb - ca
    loc2 = np.concatenate((loc[:a], loc[b:]))
    cpos2 = np.concatenate((cpos[:ca], cpos[cb:]))
    lptr2 = np.concatenate((lptr[:g + 1], lptr[g + 2:] - s))
    cptr2 = np.concatenate((cptr[:g + 1], cptr[g + 2:] - sc))
    return loc2, lptr2, np.concatenate((core, loc[a:b])), cpos2, cptr2


@njit(cache=True)
def _split_solve(A, split, work, piv, b):
    """``P(sigma)^-1 b`` from :func:`_split_factor`'s factors (``piv``: ``S``'s pivots):
    each group's ``t = P_LL^-1 b_L``, the core from ``S x_C = b_C - P_CL t``, then
    ``x_L = t - W x_C``."""
    loc, lptr, core, cpos, cptr = split
    F, fpiv, W, S = work
    n = b.size
    x = np.empty(n, dtype=np.complex128)
    t = np.empty((max(loc.size, 1), 1), dtype=np.complex128)
    r = np.empty(core.size, dtype=np.complex128)
    for i in range(core.size):
        r[i] = b[core[i]]
    for g in range(lptr.size - 1):
        a, bb = lptr[g], lptr[g + 1]
        ca, cb = cptr[g], cptr[g + 1]
        s = bb - a
        for i in range(s):
            t[a + i, 0] = b[loc[a + fpiv[a + i]]]
        _group_solve(F, a, s, t, 0)
        for u in range(ca, cb):
            row = core[cpos[u]]
            acc = 0j
            for i in range(s):
                acc += A[row, loc[a + i]] * t[a + i, 0]
            r[cpos[u]] -= acc
    xc = _lu_solve_small(S, piv, r)
    for i in range(core.size):
        x[core[i]] = xc[i]
    for g in range(lptr.size - 1):
        a, bb = lptr[g], lptr[g + 1]
        ca, cb = cptr[g], cptr[g + 1]
        for i in range(bb - a):
            acc = t[a + i, 0]
            for u in range(ca, cb):
                acc -= W[a + i, u - ca] * xc[cpos[u]]
            x[loc[a + i]] = acc
    return x


@njit(cache=True)
def shift_block(y, idx, H, k, side):
    """The vector ``y`` on the pencil's unknowns ``idx`` (DOF-major: ``coordinate H + c``,
    coefficient ``c`` of ``[a0, a_1..a_k, b_1..b_k]``) with each coordinate's
    complex-exponential coefficient ``n`` taken from ``n + side`` (``p e^{-i side w t}``, the
    copy of an eigenvector at ``s + i side``; :func:`fretwear.hb.stability._shifted_copy`),
    on the same unknowns (zero where the source lies outside them or the kept harmonics).
    The shift acts on each coordinate alone, so the unknowns outside ``idx`` do not enter."""
    r = 0
    for i in range(idx.size):
        r = max(r, idx[i] // H + 1)
    p = np.zeros((r, H), dtype=np.complex128)
    for i in range(idx.size):
        p[idx[i] // H, idx[i] % H] = y[i]
    c = np.zeros(2 * k + 1, dtype=np.complex128)  # orders -k..k
    out = np.zeros(2 * k + 1, dtype=np.complex128)
    q = np.zeros((r, H), dtype=np.complex128)
    for j in range(r):
        c[k] = p[j, 0]
        for n in range(k):
            a, b = p[j, 1 + n], p[j, 1 + k + n]
            c[k + 1 + n] = (a - 1j * b) / 2.0
            c[k - 1 - n] = (a + 1j * b) / 2.0
        out[:] = 0.0
        if side > 0:
            out[:-1] = c[1:]
        else:
            out[1:] = c[:-1]
        q[j, 0] = out[k]
        for n in range(k):
            q[j, 1 + n] = out[k + 1 + n] + out[k - 1 - n]
            q[j, 1 + k + n] = 1j * (out[k + 1 + n] - out[k - 1 - n])
    v = np.empty(idx.size, dtype=np.complex128)
    for i in range(idx.size):
        v[i] = q[idx[i] // H, idx[i] % H]
    return v
