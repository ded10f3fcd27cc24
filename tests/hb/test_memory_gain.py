"""The split ``G(s) = G_c + sum_I w_I(z) r_I^T`` (fretwear.hb.memory_gain) against the
recursion of :func:`fretwear.hb.stability.shifted_gain`, and the evaluation of ``T(s)`` in one
compiled call that it allows against the pieces one by one."""

import numpy as np
import pytest

from fretwear.hb import contact as law
from fretwear.hb.dynamics import structure_dynamics
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.memory_gain import memory_gain
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.stability import (
    HillProblem,
    _decoupled_normals,
    _evaluate,
    _pair,
    _residuals,
    problem_of,
    shifted_gain,
)
from fretwear.model.build import Damping
from fretwear.model.core import Load
from fretwear.model.matrices import ContactDofs, from_matrices


def _law_samples(rng, normal_force: bool, N: int):
    """Two 2D nodes, smooth random samples: with a unilateral normal they stick, slip and
    separate within the period; with a prescribed normal force they stick and slip."""
    t = 2 * np.pi * np.arange(N) / N
    lu = np.empty((2, 2, N))
    for p in range(2):
        lu[p, 0] = 0.2 + np.cos(t + rng.uniform(0, 6))
        lu[p, 1] = 1.5 * np.cos(t + rng.uniform(0, 6)) + 0.4 * np.sin(2 * t)
    mu = np.array([0.5, 0.7])
    normal = np.vstack([1 + 0.5 * np.cos(t), 2 + np.cos(t)]) if normal_force else None
    lx, state, _ = law.dlft_time(lu, mu, np.zeros((2, 1)), 1e-14, 200, normal)
    # the same periodic state from another instant: a stick interval across the period's end
    stick = state[0] == law.STICK
    i = int(np.flatnonzero(stick & np.roll(stick, 1))[0])
    roll = [np.roll(a, -i, axis=-1) for a in (lu, lx, state)]
    return *roll, mu, None if normal is None else np.roll(normal, -i, axis=-1)


@pytest.mark.parametrize("normal_force", [False, True])
def test_split_gain_is_the_recursion(normal_force):
    """At ``z = 1``, on the unit circle, inside and outside it, the split equals the
    recursion of ``shifted_gain`` (the same terms summed in another order: rounding, 1e-14 of
    the largest entry; measured 2e-16-1e-15), with stick, slip and (unilateral) separation
    intervals, one of which wraps around the period's end."""
    rng = np.random.default_rng(3)
    basis = FourierBasis.up_to(3, 48)
    P, Q = basis.matrices()
    lu, lx, state, mu, normal = _law_samples(rng, normal_force, basis.n_samples)
    kinds = set(np.unique(state).tolist())
    assert {law.STICK, law.SLIP} <= kinds
    assert normal_force or law.SEPARATION in kinds
    assert np.any((state[:, 0] == law.STICK) & (state[:, -1] == law.STICK))  # wraps around
    mg = memory_gain(lu, lx, state, mu, P, Q, law._normal(normal, lu))
    assert mg is not None and mg.node.size >= 1
    for z in (1.0, np.exp(-0.3j), np.exp(0.2 - 0.5j), 0.7):
        ref = shifted_gain(lu, lx, state, mu, P, Q, z, normal)
        assert np.abs(mg.at(z) - ref).max() <= 1e-14 * np.abs(ref).max()


def test_split_gain_refuses_what_it_does_not_cover():
    """A node that sticks all period (the recursion's singular seed) and a 3D contact keep
    the recursion: None."""
    basis = FourierBasis.up_to(2, 16)
    P, Q = basis.matrices()
    N = basis.n_samples
    lu = np.zeros((1, 2, N))
    lu[0, 0] = 1.0
    state = np.full((1, N), law.STICK, dtype=np.int8)
    normal = law._normal(None, lu)
    assert memory_gain(lu, lu.copy(), state, np.array([0.5]), P, Q, normal) is None
    lu3 = np.zeros((1, 3, N))
    assert memory_gain(lu3, lu3, state, np.array([0.5]), P, Q, normal) is None


def _jenkins_point():
    """A damped Jenkins oscillator (mu N 0.5, kt 0.5) forced near its resonance, 3
    harmonics, 32 samples: its periodic problem and Hill problem (it sticks and slips)."""
    model = from_matrices([[1.0]], [[1.0]],
                          contact=ContactDofs(normal_dofs=None, tangential_dofs=[0], mu=0.5,
                                              normal_load=1.0, kt=0.5),
                          damping=Damping(C=[[0.02]]), loads=[Load(np.array([0.2]), "cos")])
    sol = solve_periodic(model, FourierBasis.up_to(3, 32), frequency=1.18 / (2 * np.pi),
                         time_domain=None)
    prob = problem_of(model, sol)
    return prob, HillProblem(prob, sol.U.reshape(prob.m, prob.H), structure_dynamics(model))


def test_fused_evaluation_is_the_pieces_one_by_one():
    """:meth:`HillProblem.evaluate` by the one compiled call (:func:`_evaluate`, which a 2D
    Jenkins solution that sticks and slips takes) equals the pieces called one by one
    (:meth:`HillProblem.matrix`, :func:`_pair`, :func:`_residuals`): the same kernels, so
    the same values bit for bit, at ``s = 0``, on and off the imaginary axis; and it counts
    its evaluations."""
    prob, hp = _jenkins_point()
    assert hp._fused is not None and law.STICK in hp.state and law.SLIP in hp.state
    rng = np.random.default_rng(1)
    v = rng.standard_normal(prob.m * prob.H) + 1j * rng.standard_normal(prob.m * prob.H)
    for sigma, mu0 in ((0.0, 0.0), (0.9j, 0.01), (-0.03 + 1.02j, 0.0)):
        T, mu, y, lu, res, pair = hp.evaluate(sigma, v, mu0)
        T1 = hp.matrix(sigma)
        mu1, y1, lu1 = _pair(T1, v, mu0)
        res1, pair1 = _residuals(T1, y1, complex(mu1), 0.0)
        assert lu is None and lu1 is None
        assert np.array_equal(T, T1) and mu == mu1 and np.array_equal(y, y1)
        assert res == res1 and pair == pair1
    assert hp.evaluations == 6


def test_pair_on_the_tangential_unknowns_is_the_whole_matrix_s():
    """A Jenkins oscillator's normal coordinate (a prescribed normal force on a coordinate of
    its own) is decoupled: ``T(s)`` block-diagonal (the off-diagonal blocks exactly zero) and
    :func:`_evaluate` works on the tangential unknowns (``HillProblem._keep``). From a start
    without a normal part its pair, eigenvector and residuals equal, bit for bit, those on
    the whole matrix (``keep`` every unknown): partial pivoting never leaves the tangential
    block, the exact zeros add nothing, the 1-norm takes the dropped columns' sums; a start
    with a normal part takes the whole matrix; a structure that couples the normal
    coordinate keeps every unknown. The dropped columns' largest sum is the same number at
    every ``s`` (the block does not depend on it): given, it is not computed again and the
    evaluation is the same bit for bit."""
    prob, hp = _jenkins_point()
    n, H = prob.m * prob.H, prob.H
    assert hp._fused is not None and np.array_equal(hp._keep, np.arange(H, n))
    every = np.arange(n, dtype=np.int64)
    rng = np.random.default_rng(2)
    v = rng.standard_normal(n) + 1j * rng.standard_normal(n)
    vt = v.copy()
    vt[:H] = 0.0
    sums = []
    for sigma, mu0 in ((0.0, 0.0), (0.9j, 0.01), (-0.03 + 1.02j, 0.0)):
        z = np.exp(-2.0 * np.pi * sigma / hp.N)
        args = (*hp._fused, complex(z), *hp._structure, prob.m, hp.harmonics, hp.omega,
                complex(sigma), float(prob.eps))
        T = _evaluate(*args, vt, complex(mu0), 2, every, -1.0, True)[0]
        assert not T[:H, H:].any() and not T[H:, :H].any()
        for start in (vt, v):
            a = _evaluate(*args, start, complex(mu0), 2, hp._keep, -1.0, True)
            b = _evaluate(*args, start, complex(mu0), 2, every, -1.0, True)
            assert a[3] == b[3] == 0 and a[1] == b[1] and np.array_equal(a[2], b[2])
            assert a[4] == b[4] and a[5] == b[5]
            assert start is v or not a[2][:H].any()
        fresh = _evaluate(*args, vt, complex(mu0), 2, hp._keep, -1.0, True)
        sums.append(fresh[6])
        for form in (True, False):  # (without: only the kept block formed)
            given = _evaluate(*args, vt, complex(mu0), 2, hp._keep, sums[0], form)
            assert fresh[6] > 0 and given[6] == sums[0]
            assert given[1] == fresh[1] and np.array_equal(given[2], fresh[2])
            assert given[4] == fresh[4] and given[5] == fresh[5]
            assert given[0].shape == ((n, n) if form else (0, 0))
    assert sums[0] == sums[1] == sums[2]
    T = _evaluate(*args, vt, 0j, 2, every, -1.0, True)[0]  # the dropped block's sums
    assert sums[0] == pytest.approx(np.abs(T[:, :H]).sum(axis=0).max(), rel=1e-14)  # (order)
    K, M, C, D = (x.copy() for x in hp._structure)
    K[0, 1] = K[1, 0] = 0.1
    assert np.array_equal(_decoupled_normals(hp._memory, (K, M, C, D), H, prob.eps), every)


def test_compiled_refinement_is_the_python_steps():
    """The refinement from a neighbour's start in one compiled call (:func:`_refine`) takes
    the steps of :func:`_track` one by one (the same kernels and arithmetic): along a Jenkins
    sweep's neighbouring points, the exponent, eigenvector, residual, slope and number of
    evaluations equal, bit for bit, those of the Python steps (the compiled path switched off
    on a copy of the problem)."""
    import copy

    from fretwear.hb.stability import HillOptions, Refined, _track, hill_stability

    model = from_matrices([[1.0]], [[1.0]],
                          contact=ContactDofs(normal_dofs=None, tangential_dofs=[0], mu=0.5,
                                              normal_load=1.0, kt=0.5),
                          damping=Damping(C=[[0.02]]), loads=[Load(np.array([0.2]), "cos")])
    dyn = structure_dynamics(model)
    opt = HillOptions()
    prev = None
    checked = 0
    for w in (1.16, 1.17, 1.18):
        sol = solve_periodic(model, FourierBasis.up_to(3, 32), frequency=w / (2 * np.pi),
                             time_domain=None)
        prob = problem_of(model, sol)
        U = sol.U.reshape(prob.m, prob.H)
        if prev is not None:
            r = next(x for x in prev.track.refined if x is not None)
            warm = Refined(r.candidate, r.sigma, r.v, r.slope)
            hp = HillProblem(prob, U, dyn)
            slow = copy.copy(hp)
            slow._fused = None
            a = _track(hp, r.candidate, r.v, opt, warm)
            b = _track(slow, r.candidate, r.v, opt, warm)
            assert a[3] and b[3] and a[0] == b[0] and np.array_equal(a[1], b[1])
            assert a[2] == b[2] and a[4] == b[4] and hp.evaluations == slow.evaluations >= 2
            checked += 1
        prev = hill_stability(prob, U, dyn)
    assert checked == 2


def test_kept_rows_of_hill_matrix_are_the_whole_matrix_s():
    """:func:`_hill_rows` forms the rows and columns it keeps as :func:`_hill_matrix` forms
    the whole ``T(s)`` (the same operations per entry): bit for bit its submatrix, for the
    tangential unknowns of a Jenkins point and for a scattered subset, at several ``s``."""
    from fretwear.hb.memory_gain import _gain_at
    from fretwear.hb.stability import _condensed_at, _hill_matrix, _hill_rows

    prob, hp = _jenkins_point()
    n, H = prob.m * prob.H, prob.H
    scattered = np.array([0, 3, H, H + 2, n - 1], dtype=np.int64)
    for sigma in (0.0, 0.9j, -0.03 + 1.02j):
        z = complex(np.exp(-2.0 * np.pi * sigma / hp.N))
        G = _gain_at(*hp._fused, z)
        Zr, ok = _condensed_at(*hp._structure, prob.m, hp.harmonics, hp.omega, complex(sigma))
        assert ok
        T = _hill_matrix(G, Zr, float(prob.eps))
        for keep in (hp._keep, scattered):
            at = np.full(n, -1, dtype=np.int64)
            at[keep] = np.arange(keep.size)
            Tk = _hill_rows(G, Zr, float(prob.eps), at, keep.size)
            assert np.array_equal(Tk, T[np.ix_(keep, keep)])
        assert np.abs(T[np.ix_(hp._keep, hp._keep)]).max() > 0


def _decoupled_normals_steps(mg, structure, H, eps):
    """The tests of :func:`_decoupled_normals` as numpy steps (the previous code path, with
    ``np.linalg.cond``), for the compiled one to be compared with."""
    Kf, Mf, Cf, Df = structure
    nc, dH, _ = mg.constant.shape
    every = np.arange(nc * dH, dtype=np.int64)
    if dH != 2 * H:
        return every
    for p in range(nc):
        a = 2 * p
        Gp = mg.constant[p]
        if Gp[:H, H:].any() or Gp[H:, :H].any() or np.any(mg.rows[mg.node == p][:, :H]):
            return every
        for M in Kf, Mf, Cf, Df:
            off = M[a].copy()
            off[a] = 0.0
            col = M[:, a].copy()
            col[a] = 0.0
            if off.any() or col.any():
                return every
        if Mf[a, a] != 0.0 or Cf[a, a] != 0.0 or Df[a, a] != 0.0:
            return every
        block = eps * np.eye(H) - (eps - Kf[a, a]) * Gp[:H, :H]
        if not np.linalg.cond(block) < 1e8:
            return every
    return np.concatenate([np.arange((2 * p + 1) * H, (2 * p + 2) * H) for p in range(nc)])


def test_decoupled_normals_compiled_is_the_numpy_steps():
    """:func:`_decoupled_normals` (its tests in one compiled call, a bound on the condition
    number of a normal block near a multiple of the identity, LAPACK's singular values for
    the others) keeps the unknowns the numpy steps with ``np.linalg.cond`` keep, on a Jenkins
    point (its normal block ``k I`` settled by the bound) and on variants of it that take
    each branch: a normal block of condition number 100 (the bound leaves it open, the
    singular values keep it), 1e9 and singular (every unknown), and a coupling in ``G``, in
    a stick interval's row, in the stiffness and a mass on the normal coordinate."""
    import dataclasses

    prob, hp = _jenkins_point()
    mg, st, H, eps = hp._memory, hp._structure, prob.H, float(prob.eps)
    n = prob.m * H
    k = st[0][0, 0]

    def with_block(B):  # G_N such that eps I - (eps - k) G_N = B
        G = mg.constant.copy()
        G[0, :H, :H] = (eps * np.eye(H) - B) / (eps - k)
        return dataclasses.replace(mg, constant=G)

    def coupled_g():
        G = mg.constant.copy()
        G[0, 2, H + 1] = 1e-3
        return dataclasses.replace(mg, constant=G)

    def coupled_row():
        R = mg.rows.copy()
        R[0, 1] = 1e-3
        return dataclasses.replace(mg, rows=R)

    def changed(i, a, b, x):
        out = [M.copy() for M in st]
        out[i][a, b] = x
        return tuple(out)

    spread = np.diag(np.linspace(1.0, 100.0, H))
    ill = np.diag(np.r_[np.ones(H - 1), 1e-9])
    singular = np.diag(np.r_[np.ones(H - 1), 0.0])
    cases = [(mg, st, True), (with_block(spread), st, True), (with_block(ill), st, False),
             (with_block(singular), st, False), (coupled_g(), st, False),
             (coupled_row(), st, False), (mg, changed(0, 0, 1, 0.1), False),
             (mg, changed(0, 1, 0, 0.1), False), (mg, changed(1, 0, 0, 1.0), False)]
    assert mg.node.size >= 1
    for m_, s_, kept in cases:
        got = _decoupled_normals(m_, s_, H, eps)
        assert np.array_equal(got, _decoupled_normals_steps(m_, s_, H, eps))
        assert np.array_equal(got, np.arange(H, n) if kept else np.arange(n))
