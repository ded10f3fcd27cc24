"""The harmonic split of Hill's quadratic pencil (fretwear.hb.hill_tracking) against dense
linear algebra, and the shifted copy against the definition of the shift."""

import numpy as np
import scipy.linalg as sla
from helpers.models import two_dof

from fretwear.hb.dynamics import structure_dynamics
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.hill_tracking import (
    _demote,
    _split_factor,
    _split_solve,
    harmonic_split,
    no_split,
    shift_block,
    split_work,
)
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.stability import (
    HillProblem,
    _block_mats,
    _column_norms,
    _companion_eigen,
    _inverse_iteration,
    _kept_settled,
    _pencil_into,
    _ruhe,
    hill_stability,
    problem_of,
    reduce_quadratic,
)


def _structured(seed, k=6):
    """A quadratic problem on two coordinates with the kept harmonics 0..k in the
    real-coefficient layout (``H = 1 + 2k`` unknowns each): coordinate 0 couples all its
    harmonics (a dense block, as the law's G does), coordinate 1 couples only the cosine and
    sine of one harmonic, to itself and to coordinate 0's same harmonic (as a structure's
    ``Z(lambda)`` does). Returns ``(B0, B1, B2, harm)`` real."""
    rng = np.random.default_rng(seed)
    H = 1 + 2 * k
    c = np.arange(H)
    h = np.where(c > k, c - k, c)
    harm = np.concatenate([h, h])
    n = 2 * H
    same = harm[:, None] == harm[None, :]
    mats = []
    for scale in (3.0, 0.5, 1.0):
        B = np.where(same, rng.standard_normal((n, n)), 0.0)
        B[:H, :H] = rng.standard_normal((H, H))  # coordinate 0: every harmonic
        B += scale * n * np.eye(n) if scale == 1.0 else 0.0
        mats.append(B)
    return mats[0], mats[1], mats[2], harm


def test_split_finds_the_local_unknowns_and_solves_as_lapack():
    """The split of the structured problem: coordinate 1's unknowns local, coordinate 0's the
    core; ``P(sigma)^-1 b`` by the split equals LAPACK's solve of the whole ``P`` within
    1e-12 (relative): the same system eliminated in another order, ``P`` well conditioned
    here (the identity-weighted ``B2`` keeps it away from singular at these ``sigma``), so
    both are accurate to rounding times its condition (checked below 1e3)."""
    B0, B1, B2, harm = _structured(3)
    H = harm.size // 2
    split = harmonic_split(B0, B1, B2, harm, 1e-13)
    loc, lptr, core, cpos, cptr = split
    np.testing.assert_array_equal(np.sort(loc), np.arange(H, 2 * H))
    np.testing.assert_array_equal(core, np.arange(H))
    n = harm.size
    rng = np.random.default_rng(5)
    for sigma in (0.3 + 0.2j, -0.1 + 1.4j, 2.0 + 0.0j):
        A = np.empty((n, n), dtype=complex)
        _pencil_into(*(X.astype(complex) for X in (B0, B1, B2)), sigma, A)
        assert np.linalg.cond(A) < 1e3
        b = rng.standard_normal(n) + 1j * rng.standard_normal(n)
        work = split_work(split, n)
        piv, bad = _split_factor(A, split, work)
        assert bad == -1
        x = _split_solve(A, split, work, piv, b)
        ref = np.linalg.solve(A, b)
        assert np.linalg.norm(x - ref) <= 1e-12 * np.linalg.norm(ref)


def test_a_near_singular_group_is_moved_to_the_core():
    """Where ``sigma`` makes one local group singular (its 2 x 2 block zeroed here: no pivot
    within the group), ``_split_factor`` names that group, ``_demote`` moves it to the core,
    and the solve then equals LAPACK's within 1e-12 (the core's LU pivots across it). A
    problem with no structure (every unknown coupled to every harmonic) has no split."""
    B0, B1, B2, harm = _structured(4)
    n = harm.size
    H = n // 2
    split = harmonic_split(B0, B1, B2, harm, 1e-13)
    sigma = 0.4 + 0.1j
    A = np.empty((n, n), dtype=complex)
    _pencil_into(*(X.astype(complex) for X in (B0, B1, B2)), sigma, A)
    g = 2  # the group of harmonic 2: coordinate 1's cosine and sine of harmonic 2
    rows = split[0][split[1][g]:split[1][g + 1]]
    A[np.ix_(rows, rows)] = 0.0
    work = split_work(split, n)
    _, bad = _split_factor(A, split, work)
    assert bad == g
    split2 = _demote(split, g)
    assert split2[2].size == H + rows.size
    work = split_work(split2, n)
    piv, bad = _split_factor(A, split2, work)
    assert bad == -1
    b = np.arange(1.0, n + 1.0) + 0j
    ref = np.linalg.solve(A, b)
    x = _split_solve(A, split2, work, piv, b)
    assert np.linalg.norm(x - ref) <= 1e-12 * np.linalg.norm(ref)
    rng = np.random.default_rng(1)
    dense = rng.standard_normal((n, n))
    assert harmonic_split(dense, dense, dense, harm, 1e-13)[2].size == 0  # no_split()
    assert all(np.array_equal(a, b) for a, b in zip(harmonic_split(dense, dense, dense, harm,
                                                                   1e-13), no_split(),
                                                    strict=True))


def test_inverse_iteration_with_the_split_finds_the_dense_eigenvalues():
    """Inverse iteration by the split, from 1e-3 off each of six eigenvalues of the
    structured problem (start vectors perturbed), converges to the companion eigensolve's
    eigenvalue within 1e-11 of ``max(1, |s|)`` and to the same eigenvalue as without the
    split within 1e-12: both stop at a Newton step below 1e-14 or where the quadratic
    convergence predicts the next one below 1e-15 (stability._settled; from 1e-3 off, no
    first step is small enough to stop on the prediction), the eigenvalues are simple (the
    closest two are checked 1e-2 apart) and the dense ones backward stable."""
    B0, B1, B2, harm = _structured(7)
    split = harmonic_split(B0, B1, B2, harm, 1e-13)
    vals, Y = _companion_eigen(B0, B1, B2)
    rng = np.random.default_rng(2)
    gap = (np.abs(vals[:, None] - vals[None, :]) + np.eye(vals.size)).min(axis=1)
    chosen = np.flatnonzero(gap > 3e-2)
    assert chosen.size >= 6
    for i in chosen[::max(1, chosen.size // 6)][:6]:
        v = vals[i]
        y0 = Y[:, i] + 1e-3 * (rng.standard_normal(harm.size) + 0j)
        start = v + 1e-3 * (1 + 1j)
        s1, _, ok = _inverse_iteration(B0, B1, B2, start, y0, split=split)
        s2, _, ok2 = _inverse_iteration(B0, B1, B2, start, y0)
        assert ok and ok2
        assert abs(s1 - v) <= 1e-11 * max(1.0, abs(v))
        assert abs(s1 - s2) <= 1e-12 * max(1.0, abs(s2))


def test_shift_block_is_the_shift_of_the_complex_exponential_coefficients():
    """``shift_block`` against the definition: a vector of two coordinates built from random
    complex-exponential coefficients ``c_n`` (``a_n = c_n + c_-n``, ``b_n = i (c_n - c_-n)``)
    is shifted to ``c_{n + side}`` (zero past the kept orders); the shift is exact algebra
    (additions and halvings), so the two agree to 1e-15. Restricted to a subset of the
    coordinates it gives the same entries (the shift acts on each coordinate alone)."""
    k, r = 5, 2
    H = 1 + 2 * k
    rng = np.random.default_rng(9)
    c = rng.standard_normal((r, 2 * k + 1)) + 1j * rng.standard_normal((r, 2 * k + 1))

    def real_layout(cc):
        p = np.empty((r, H), dtype=complex)
        p[:, 0] = cc[:, k]
        p[:, 1:1 + k] = cc[:, k + 1:] + cc[:, :k][:, ::-1]
        p[:, 1 + k:] = 1j * (cc[:, k + 1:] - cc[:, :k][:, ::-1])
        return p

    p = real_layout(c)
    idx = np.arange(r * H)
    for side in (1, -1):
        shifted = np.zeros_like(c)
        if side > 0:
            shifted[:, :-1] = c[:, 1:]
        else:
            shifted[:, 1:] = c[:, :-1]
        ref = real_layout(shifted).reshape(-1)
        got = shift_block(p.reshape(-1), idx, H, k, side)
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-15 * np.abs(ref).max())
        part = idx[H:]  # the second coordinate alone
        np.testing.assert_array_equal(shift_block(p.reshape(-1)[part], part, H, k, side),
                                      got[part])
    assert sla.norm(p) > 0


def test_inverse_iteration_demotes_a_group_held_near_its_eigenvalue():
    """Started 1e-7 from an eigenvalue of one local group held (its 2 x 2 block
    ``P_LL(s)`` singular there: the split's pivot test refuses it, checked), the inverse
    iteration with the split (which moves that group to the core inside the compiled
    iteration) converges to the same eigenvalue as without the split, within 1e-12 of
    ``max(1, |s|)`` (both stop by the same rule from the same start; the eigenvalue is the
    companion eigensolve's, checked within 1e-10: the iterations' stopping rule, not the
    start, bounds their error)."""
    B0, B1, B2, harm = _structured(4)
    n = harm.size
    split = harmonic_split(B0, B1, B2, harm, 1e-13)
    loc, lptr = split[0], split[1]
    g = 2
    rows = loc[lptr[g]:lptr[g + 1]]
    held = [X[np.ix_(rows, rows)] for X in (B0, B1, B2)]
    s_held = _companion_eigen(*held)[0]
    start = complex(s_held[np.argmax(np.abs(s_held.imag))]) + 1e-7
    A = np.empty((n, n), dtype=complex)
    _pencil_into(*(X.astype(complex) for X in (B0, B1, B2)), start, A)
    assert _split_factor(A, split, split_work(split, n))[1] == g
    vals, _ = _companion_eigen(B0, B1, B2)
    y0 = np.random.default_rng(3).standard_normal(n) + 0j
    s1, _, ok = _inverse_iteration(B0, B1, B2, start, y0, split=split)
    s2, _, ok2 = _inverse_iteration(B0, B1, B2, start, y0)
    assert ok and ok2
    assert abs(s1 - s2) <= 1e-12 * max(1.0, abs(s2))
    assert np.min(np.abs(vals - s1)) <= 1e-10 * max(1.0, abs(s1))


def test_a_first_small_step_is_not_taken_for_convergence():
    """Ruhe's stopping rule (stability._settled) trusts a predicted step only after one that
    contracted: from a RANDOM start vector 9e-8 off an eigenvalue of a 6 x 6 matrix built
    with known eigenvalues (``A = V diag(lam) V^-1``, the pencil ``-A + s I``; independent of
    the iteration), with a second eigenvalue 1e-2 to 1e-5 away, both the compiled and the
    Python iterations end within 1e-14 of it (measured 5e-16 to 1.3e-15; a first step of
    about 1e-8 taken as converged before ended 2.4e-13 to 2.5e-10 away, its vector still
    carrying the start's error)."""
    from fretwear.hb.stability import _inverse_iteration_py

    n = 6
    for gap in (1e-2, 1e-4, 1e-5):
        rng = np.random.default_rng(1)
        lam = np.array([1.0 + 0.5j, 1.0 + 0.5j + gap, 2, 3, 4, 5])
        V = rng.standard_normal((n, n)) + 1j * rng.standard_normal((n, n))
        A = V @ np.diag(lam) @ np.linalg.inv(V)
        B0, B1, B2 = -A, np.eye(n, dtype=complex), np.zeros((n, n), complex)
        y = rng.standard_normal(n) + 0j
        for it in (_inverse_iteration, _inverse_iteration_py):
            s, _, ok = it(B0, B1, B2, lam[0] + 9e-8, y, 10)
            assert ok and abs(s - lam[0]) <= 1e-14, (gap, it.__name__, abs(s - lam[0]))


def test_kept_step_is_its_formula_with_lapack():
    """A step on a kept LU (stability._kept_step, Neumaier's residual inverse iteration)
    against its formula with LAPACK's solves of the whole ``P(tau)``: ``u0 = P(tau)^-1
    P(sigma) x``, ``u1 = P(tau)^-1 P'(sigma) x``, ``sigma' = sigma - (x^H u0) / (x^H u1)``
    and ``x - (u0 + (sigma' - sigma) u1)`` normalised, with the factors of the split
    (``how`` 2) and of the compiled LU (``how`` 0), on the structured problem at ``tau``
    1e-3 from ``sigma``: within 1e-12 (the same quantities, the solves eliminated in another
    order; ``P(tau)`` well conditioned there, checked). With ``tau = sigma`` the eigenvalue
    is Ruhe's step (stability._ruhe_update): ``x^H P(sigma)^-1 P(sigma) x = 1`` to rounding.
    The backward error that stability._residual_into measures on the way is
    stability._backward_error's (the residual summed from the three products) to 1e-14 of
    it."""
    from fretwear.hb.hill_tracking import _lu_small
    from fretwear.hb.stability import (
        _backward_error,
        _kept_step,
        _residual_into,
        _ruhe_update,
        _transposes,
    )

    B0, B1, B2, harm = _structured(5)
    n = harm.size
    split = harmonic_split(B0, B1, B2, harm, 1e-13)
    norms = _column_norms(B0, B1, B2)
    T = _transposes(B0, B1, B2)
    rng = np.random.default_rng(4)
    x = rng.standard_normal(n) + 1j * rng.standard_normal(n)
    x /= np.linalg.norm(x)
    vecs = np.empty((4, n), dtype=complex)
    for sigma in (0.3 + 0.2j, -0.1 + 1.4j):
        for tau in (sigma + 1e-3 * (1 - 1j), sigma):
            P = B0 + tau * B1 + tau ** 2 * B2
            assert np.linalg.cond(P) < 1e3
            u0 = np.linalg.solve(P, (B0 + sigma * B1 + sigma ** 2 * B2) @ x)
            u1 = np.linalg.solve(P, (B1 + 2 * sigma * B2) @ x)
            step = np.vdot(x, u0) / np.vdot(x, u1)
            ref = sigma - step
            v = x - (u0 - step * u1)
            v /= np.linalg.norm(v)
            for how in (0, 2):
                A = np.empty((n, n), dtype=complex)
                _pencil_into(B0, B1, B2, tau, A)
                work = split_work(split, n)
                piv = _split_factor(A, split, work)[0] if how == 2 else _lu_small(A)[0]
                eta = _residual_into(T, sigma, x, vecs, norms)
                assert abs(eta - _backward_error(B0, B1, B2, sigma, x, norms)) <= 1e-14 * eta
                s, y, t = _kept_step(A, piv, how, split, work, sigma, x, vecs)
                assert abs(s - ref) <= 1e-12 * max(1.0, abs(ref)), (how, abs(s - ref))
                assert abs(t - abs(sigma - ref)) <= 1e-12 * max(1.0, abs(ref))
                np.testing.assert_allclose(y, v, rtol=0, atol=1e-12)
                if tau == sigma:
                    ruhe = _ruhe_update(sigma, x, u1, np.inf)[0]
                    assert abs(s - ruhe) <= 1e-12 * max(1.0, abs(ruhe))


def test_kept_lu_converges_to_the_dense_eigenpair():
    """Steps on ONE kept LU (stability._kept_step, ``tau`` 1e-4 and 1e-5 off an eigenvalue
    of the structured problem, the start pair perturbed by 1e-6) converge to the companion
    eigensolve's eigenpair: the backward error at or below ``COPY_EXACT`` within 8 steps,
    the eigenvalue within 1e-12 of the dense one and the vector's direction within 1e-10
    (the dense eigensolve's own rounding; the eigenvalues are simple, the nearest other one
    checked 3e-2 away). The fixed point of Neumaier's step is an eigenpair of ``P`` itself:
    with the vector moved by the inverse iteration ``P(tau)^-1 P'(sigma) x`` instead (the
    kept LU's step before), the backward error stalls near ``|tau - lambda|^2`` (2e-11 to
    4e-9 measured here) and the test fails (planted, checked)."""
    from fretwear.hb.hill_tracking import _lu_small
    from fretwear.hb.stability import COPY_EXACT, _kept_step, _residual_into, _transposes

    B0, B1, B2, harm = _structured(7)
    n = harm.size
    split = harmonic_split(B0, B1, B2, harm, 1e-13)
    norms = _column_norms(B0, B1, B2)
    T = _transposes(B0, B1, B2)
    vals, Y = _companion_eigen(B0, B1, B2)
    gap = (np.abs(vals[:, None] - vals[None, :]) + np.eye(vals.size)).min(axis=1)
    chosen = np.flatnonzero((gap > 3e-2) & (np.abs(vals) < 5))
    assert chosen.size >= 4
    rng = np.random.default_rng(8)
    vecs = np.empty((4, n), dtype=complex)
    for i in chosen[:4]:
        lam, y = vals[i], Y[:, i] / np.linalg.norm(Y[:, i])
        for off in (1e-4, 1e-5):
            tau = lam + off * np.exp(2j * np.pi * rng.random())
            for how in (0, 2):
                A = np.empty((n, n), dtype=complex)
                _pencil_into(B0, B1, B2, tau, A)
                work = split_work(split, n)
                piv = _split_factor(A, split, work)[0] if how == 2 else _lu_small(A)[0]
                sigma = lam + 1e-6 * (1 + 1j)
                x = y + 1e-6 * (rng.standard_normal(n) + 1j * rng.standard_normal(n))
                x /= np.linalg.norm(x)
                for _ in range(8):
                    if _residual_into(T, sigma, x, vecs, norms) <= COPY_EXACT:
                        break
                    sigma, x, t = _kept_step(A, piv, how, split, work, sigma, x, vecs)
                    assert t >= 0
                assert _residual_into(T, sigma, x, vecs, norms) <= COPY_EXACT, (i, off, how)
                assert abs(sigma - lam) <= 1e-12 * max(1.0, abs(lam))
                ph = np.vdot(y, x)
                assert np.linalg.norm(x - ph / abs(ph) * y) <= 1e-10


def test_steps_on_a_kept_lu_end_where_ruhe_s_steps_end():
    """The iteration with steps on the LU of a step before (stability._ruhe, ``reuse`` 6:
    after a Ruhe step within ``KEPT_FROM`` of the eigenvalue, ended by the pair's backward
    error at rounding) against Ruhe's steps alone (``reuse`` 0), on the blocks of a point of
    the two-DOF unilateral oscillator (15 harmonics, the contact closing and opening: its
    62-unknown block split, its 31-unknown block whole), from 3e-3 and 1e-4 off each member
    found by the dense eigensolve (the track of ``hill_stability``), start vectors perturbed
    as much: the same eigenvalue within 4e-15 of ``max(1, |s|)`` and eigenvector within
    1e-12 (both iterations end converged to rounding), both within 1e-13 of the dense
    eigenvalue. The kept LU's steps are taken (some results differ from Ruhe's alone in
    their last bits). A kept step scaled by 0.9 fails it (the kept step's vector moved by
    the inverse iteration instead does not: the iteration then ends on Ruhe's own rule;
    test_kept_lu_converges_to_the_dense_eigenpair catches that one)."""
    model = two_dof()
    basis = FourierBasis.up_to(15, 256)
    sol = solve_periodic(model, basis, frequency=0.6 / (2 * np.pi), time_domain=None)
    prob = problem_of(model, sol)
    dyn = structure_dynamics(model)
    U = sol.U.reshape(prob.m, prob.H)
    red = reduce_quadratic(*HillProblem(prob, U, dyn).pencil())
    track = hill_stability(prob, U, dyn).track
    shape = (prob.m + dyn.q, prob.H, len(basis.harmonics))
    mats: dict = {}
    rng = np.random.default_rng(3)
    differ = 0
    for j, (s, b) in enumerate(zip(track.sigma, track.block, strict=True)):
        B, split, _, _, _, norms = _block_mats(red, b, shape, mats)
        y = track.Y[red.blocks[b], j]
        for off in (3e-3, 1e-4):
            for _ in range(3):
                y0 = y + off * (rng.standard_normal(y.size) + 1j * rng.standard_normal(y.size))
                start = s + off * np.exp(2j * np.pi * rng.random())
                s1, x1, ok1 = _ruhe(*B, start, y0, 10, split, 6, norms)
                s2, x2, ok2 = _ruhe(*B, start, y0, 10, split, 0, norms)
                assert ok1 and ok2
                assert abs(s1 - s2) <= 4e-15 * max(1.0, abs(s)), abs(s1 - s2)
                ph = np.vdot(x2, x1)
                assert np.linalg.norm(x1 - ph / abs(ph) * x2) <= 1e-12
                assert max(abs(s1 - s), abs(s2 - s)) <= 1e-13 * max(1.0, abs(s))
                differ += s1 != s2
    assert differ > 0


def test_kept_lu_stop_rule_is_the_linear_contraction():
    """stability._kept_settled, the stop of a pair certified by its backward error, against
    the rule its docstring derives: a step ``t`` ends the iteration when it is below 1e-14 of
    the scale, or when the error after it, ``t^2 / before`` (the contraction ``t / before``
    once more), is predicted below 1e-15 of the scale; after a first step (``before``
    infinite) the first test only. Values either side of each bound by a factor 10
    (``return True`` fails it, and so does the quadratic prediction ``t^3 / before^2``)."""
    for scale in (1.0, 7.0):
        assert _kept_settled(1e-15 * scale, 1e-8, scale)  # below 1e-14 of the scale
        assert _kept_settled(1e-15 * scale, np.inf, scale)
        assert not _kept_settled(1e-13 * scale, np.inf, scale)  # a first step: no prediction
        # contraction 1e-12 / 1e-8 = 1e-4: predicted 1e-16 of the scale, settled
        assert _kept_settled(1e-12 * scale, 1e-8 * scale, scale)
        # predicted 1e-14: another step
        assert not _kept_settled(1e-11 * scale, 1e-8 * scale, scale)
        # a slower contraction, 1e-12 / 1e-10 = 1e-2: predicted 1e-14, not settled
        assert not _kept_settled(1e-12 * scale, 1e-10 * scale, scale)
        assert _kept_settled(1e-13 * scale, 1e-10 * scale, scale)


def _lu_reference(A):
    """Partial pivoting written from its definition, in Python: at each column the first row
    of largest magnitude at or below the diagonal (``np.argmax`` of ``abs``), rows swapped,
    the column's multipliers stored below the diagonal. Returns the factors and the row of
    ``A`` each row of ``L U`` holds."""
    A = A.copy()
    n = A.shape[0]
    perm = np.arange(n)
    for col in range(n):
        p = col + int(np.argmax(np.abs(A[col:, col])))
        A[[col, p]] = A[[p, col]]
        perm[[col, p]] = perm[[p, col]]
        A[col + 1:, col] /= A[col, col]
        A[col + 1:, col + 1:] -= np.outer(A[col + 1:, col], A[col, col + 1:])
    return A, perm


def test_compiled_lu_pivots_as_partial_pivoting_defines():
    """The compiled LU (hill_tracking._lu_small, whose pivot search keeps the largest
    magnitude found so far) and a group's LU (_group_lu, rows ``a..a+s`` of a work array)
    against partial pivoting written from its definition (_lu_reference): the same row
    permutation, exactly (the same magnitudes compared; ties, planted as rows of equal
    magnitude below the diagonal, go to the first), and ``L U`` equal to the permuted
    matrix within 1e-13 of its norm (rounding of a 31 x 31 elimination of entries O(1)).
    A search that keeps the last larger entry, or compares with the diagonal only, picks
    other rows and fails the permutation."""
    from fretwear.hb.hill_tracking import _group_lu, _lu_small

    rng = np.random.default_rng(11)
    for n in (2, 5, 31):
        A = rng.standard_normal((n, n)) + 1j * rng.standard_normal((n, n))
        if n > 2:  # ties: rows 1 and 2 of the first column of equal magnitude, above row 0
            A[0, 0] = 0.1
            A[1, 0] = 2.0
            A[2, 0] = -2.0j
        ref, perm = _lu_reference(A)
        X = A.copy()
        piv, ok = _lu_small(X)
        assert ok
        np.testing.assert_array_equal(piv, perm)
        L = np.tril(X, -1) + np.eye(n)
        np.testing.assert_allclose(L @ np.triu(X), A[piv], rtol=0,
                                   atol=1e-13 * np.linalg.norm(A))
        np.testing.assert_allclose(X, ref, rtol=0, atol=1e-13 * np.linalg.norm(A))
        F = np.zeros((n + 3, n), dtype=complex)
        F[3:] = A
        fpiv = np.zeros(n + 3, dtype=np.int64)
        assert _group_lu(F, fpiv, 3, n)
        np.testing.assert_array_equal(fpiv[3:], perm)
        np.testing.assert_allclose(F[3:], X, rtol=0, atol=1e-13 * np.linalg.norm(A))
