"""The nonlinear solvers of the DLFT (fretwear.hb.solvers) on small systems with known roots.

References independent of the code under test:

* a 2 x 2 analytic system, ``x^2 + y^2 = 4``, ``x - y = 0``, whose root in the positive
  quadrant is ``(sqrt 2, sqrt 2)`` (closed form);
* a smooth n-dimensional problem ``A x + 0.1 x^3 = A x* + 0.1 x*^3`` with ``A`` symmetric
  positive definite (a strictly monotone map: its only root is the ``x*`` it was built from);
* ``numpy.linalg.solve`` of the dense system for :func:`solve_identity_rows`.

The solvers stop at ``|f| <= tol * scale``; with tol = 1e-12 and Jacobians of condition < 10 the
error of the root is below 1e-10 relative (the residual divided by the smallest singular
value), so the roots are compared to 1e-9 relative.
"""

import numpy as np
import pytest
from helpers.kinked import kinked

from fretwear.errors import InputError
from fretwear.hb.solvers import SOLVERS, SolveStats, solve, solve_identity_rows

RNG = np.random.default_rng(3)


def circle_line(x, need_jacobian):
    f = np.array([x[0] ** 2 + x[1] ** 2 - 4.0, x[0] - x[1]])
    J = np.array([[2 * x[0], 2 * x[1]], [1.0, -1.0]]) if need_jacobian else None
    return f, J


def monotone(n=12, rng=None):
    """A smooth monotone problem of n unknowns and its root (drawn from ``rng``, default
    the module's generator)."""
    rng = RNG if rng is None else rng
    B = rng.standard_normal((n, n))
    A = B @ B.T / n + np.eye(n)
    x_star = rng.standard_normal(n)
    rhs = A @ x_star + 0.1 * x_star**3

    def fun(x, need_jacobian):
        f = A @ x + 0.1 * x**3 - rhs
        return f, (A + np.diag(0.3 * x**2)) if need_jacobian else None

    return fun, x_star, np.abs(rhs).max()


@pytest.mark.parametrize("method", SOLVERS)
def test_two_by_two_analytic_root(method):
    x, f, st = solve(circle_line, [1.0, 0.5], lambda x: 4.0, method=method, tol=1e-12)
    assert isinstance(st, SolveStats) and st.success, st.message
    assert st.solver == method and st.message
    np.testing.assert_allclose(x, [np.sqrt(2), np.sqrt(2)], rtol=1e-9)
    assert np.linalg.norm(f) <= 1e-12 * 4.0 and st.residual <= 1e-12


@pytest.mark.parametrize("method", SOLVERS)
def test_smooth_n_dimensional_root(method):
    fun, x_star, scale = monotone()
    x, _, st = solve(fun, np.zeros_like(x_star), lambda x: scale, method=method, tol=1e-12)
    assert st.success, st.message
    np.testing.assert_allclose(x, x_star, rtol=1e-9, atol=1e-9 * np.abs(x_star).max())


@pytest.mark.parametrize("method", SOLVERS)
def test_a_failed_solve_says_so(method):
    """No real root (``x^2 + 1 = 0``): the solve fails and says why, within its iterations."""
    def fun(x, need_jacobian):
        return np.array([x[0] ** 2 + 1.0]), (np.array([[2 * x[0]]]) if need_jacobian else None)

    x, f, st = solve(fun, [0.3], lambda x: 1.0, method=method, tol=1e-12, max_iter=20)
    assert st.success is False or st.success == 0
    assert isinstance(st.message, str) and st.message and st.message != "converged"
    assert st.residual >= 1.0 - 1e-12  # |x^2 + 1| >= 1 everywhere


def test_unknown_method_is_refused():
    with pytest.raises(InputError, match="solver = 'broyden'"):
        solve(circle_line, [1.0, 0.5], lambda x: 4.0, method="broyden")


@pytest.mark.parametrize("k", [1, 3])
def test_identity_rows_against_a_dense_solve(k):
    """Rows holding only their diagonal (a sticking node's ``eps I``) mixed with a full block:
    the same X as numpy's dense solve to 1e-12 relative (condition < 100)."""
    n = 9
    J = RNG.standard_normal((n, n)) + 5 * np.eye(n)
    ident = [0, 4, 7]
    J[ident] = 0.0
    J[ident, ident] = [2.0, 3.0, 0.5]
    B = RNG.standard_normal((n, k)) if k > 1 else RNG.standard_normal(n)
    np.testing.assert_allclose(solve_identity_rows(J, B), np.linalg.solve(J, B), rtol=1e-12,
                               atol=1e-12)
    full = RNG.standard_normal((4, 4)) + 4 * np.eye(4)  # no identity rows: plain dense solve
    b = RNG.standard_normal(4)
    np.testing.assert_allclose(solve_identity_rows(full, b), np.linalg.solve(full, b),
                               rtol=1e-12)


@pytest.mark.parametrize("method", ["powell", "newton"])
def test_progress_test_stops_a_solve_without_progress(method):
    """``max_slow`` (MINPACK hybrj's "not making good progress" test): on ``x^2 + 1 = 0`` (no
    real root, |f| >= 1 everywhere, so no iteration can decrease |f|^2 by 10 % for long) the
    solve stops unconverged after ``max_slow`` Jacobians in a row without such an iteration,
    and says so; without the test it goes on until another stop (82 Powell iterations
    measured, 11 Newton ones). The count is checked against the definition: at most
    ``max_slow`` + 1 Jacobian evaluations after the last iteration with 10 % decrease."""
    def fun(x, need_jacobian):
        return np.array([x[0] ** 2 + 1.0]), (np.array([[2 * x[0]]]) if need_jacobian else None)

    _, _, free = solve(fun, [0.3], lambda x: 1.0, method=method, tol=1e-12, max_iter=200)
    norms = []
    x, _, st = solve(fun, [0.3], lambda x: 1.0, method=method, tol=1e-12, max_iter=200,
                     max_slow=3, callback=lambda it, x, fn: norms.append(fn))
    assert not st.success and st.message.startswith("not making good progress")
    assert st.iterations < free.iterations
    good = [i for i in range(1, len(norms)) if norms[i] ** 2 <= 0.9 * norms[i - 1] ** 2]
    last = good[-1] if good else 0
    accepted = sum(1 for i in range(last + 1, len(norms)) if norms[i] < norms[i - 1])
    assert accepted <= 3


@pytest.mark.parametrize("method", ["powell", "newton"])
def test_progress_test_leaves_a_converging_solve_unchanged(method):
    """A solve that converges makes good progress: the same iterates, bit for bit, with and
    without ``max_slow``."""
    fun, x_star, scale = monotone()
    x0 = np.zeros_like(x_star)
    a, _, sa = solve(fun, x0, lambda x: scale, method=method, tol=1e-12)
    b, _, sb = solve(fun, x0, lambda x: scale, method=method, tol=1e-12, max_slow=5)
    assert sa.success and sb.success and sa.iterations == sb.iterations
    np.testing.assert_array_equal(a, b)


def test_powell_solves_once_per_jacobian(monkeypatch):
    """A rejected step keeps the iterate, its Jacobian and residual: Powell's next iteration
    reuses the Newton step (one linear solve per Jacobian, not per iteration; the solve of a
    large interface is a GMRES run). Counted on the problem without a root, where steps are
    rejected (82 iterations, 18 Jacobians)."""
    from fretwear.hb import solvers

    calls = []
    step = solvers._lu_step
    monkeypatch.setattr(solvers, "_lu_step", lambda J, f, *a: calls.append(1) or step(J, f, *a))

    def fun(x, need_jacobian):
        return np.array([x[0] ** 2 + 1.0]), (np.array([[2 * x[0]]]) if need_jacobian else None)

    _, _, st = solve(fun, [0.3], lambda x: 1.0, method="powell", tol=1e-12, max_iter=200)
    assert st.iterations > st.njev and len(calls) <= st.njev


class InexactOperator:
    """A formed Jacobian seen as an operator (as fretwear.hb.krylov.KrylovJacobian): its
    ``solve(b, rtol)`` returns the exact solution plus an error whose residual is ``rtol``
    times ``|b|`` (the most an iterative solver to that tolerance leaves), and records the
    tolerances asked for."""

    def __init__(self, J, asked, norms=None):
        self.J, self.asked = J, asked
        self.norms = [] if norms is None else norms  # |b| of every request
        self.shape = J.shape

    def __matmul__(self, x):
        return self.J @ x

    @property
    def T(self):
        return self.J.T

    def column_norms(self):
        return np.linalg.norm(self.J, axis=0)

    def solve(self, b, rtol=None):
        self.asked.append(rtol)
        self.norms.append(np.linalg.norm(b))
        x = np.linalg.solve(self.J, b)
        if rtol is None:
            return x
        e = np.linalg.solve(self.J, np.ones_like(b))  # residual along (1, .., 1)
        return x + rtol * np.linalg.norm(b) / np.linalg.norm(self.J @ e) * e


@pytest.mark.parametrize("seed", range(8))
def test_powell_inexact_newton_steps_reach_the_same_root(seed):
    """With an operator Jacobian, Powell asks for inexact Newton steps (Eisenstat-Walker
    forcing terms: FORCING_MAX first, then at most FORCING_GAMMA (|f_k|/|f_k-1|)^2, never
    tighter than a tenth of the convergence test) and still converges to the root of the
    smooth monotone problem (closed form: the x* it was built from; 1e-9 relative as above).
    Checked on eight problems, each drawn from its own seeded generator (the property of the
    method, not of one draw): the first request is FORCING_MAX; every one asks for an
    absolute residual rtol |f| of at least a tenth of the convergence test (tol * scale, to
    rounding), and none is looser than FORCING_MAX unless it is that tenth (near the test);
    as |f| falls superlinearly the forcing falls below 1e-3. (The last request may be looser
    than the one before: the single draw this test used to make failed on that alone.)"""
    from fretwear.hb import solvers

    fun, x_star, scale = monotone(rng=np.random.default_rng(100 + seed))
    asked, norms = [], []

    def op(x, need_jacobian):
        f, J = fun(x, need_jacobian)
        return f, (InexactOperator(J, asked, norms) if need_jacobian else None)

    tol = 1e-12
    x, _, st = solve(op, np.zeros_like(x_star), lambda x: scale, tol=tol)
    assert st.success, st.message
    np.testing.assert_allclose(x, x_star, rtol=1e-9, atol=1e-9 * np.abs(x_star).max())
    loose = [(a, nb) for a, nb in zip(asked, norms, strict=True) if a is not None]
    assert loose and loose[0][0] == solvers.FORCING_MAX
    floor = 0.1 * tol * scale  # the absolute residual of a tenth of the convergence test
    assert all(a * nb >= floor * (1 - 1e-12) for a, nb in loose)
    assert all(a <= solvers.FORCING_MAX or abs(a * nb - floor) <= 1e-9 * floor
               for a, nb in loose)
    assert min(a for a, _ in loose) < 1e-3


@pytest.mark.parametrize("first", [True, False])
def test_powell_keeps_the_first_scales_on_an_operator_that_asks(first):
    """An operator Jacobian whose options keep the first Jacobian's variable scales
    (``KrylovOptions.first_scales``) has its column norms computed once; one that does not,
    at every new Jacobian (MINPACK's running maximum). Either way Powell reaches the root of
    the smooth monotone problem (closed form: the x* it was built from; 1e-9 relative as
    above): the scales change the path, not the root."""
    fun, x_star, scale = monotone(rng=np.random.default_rng(7))
    calls, jacobians = [], []

    class Scaled(InexactOperator):
        first_scales = first

        def column_norms(self):
            calls.append(1)
            return super().column_norms()

    def op(x, need_jacobian):
        f, J = fun(x, need_jacobian)
        if need_jacobian:
            jacobians.append(1)
        return f, (Scaled(J, []) if need_jacobian else None)

    x, _, st = solve(op, np.zeros_like(x_star), lambda x: scale, tol=1e-12)
    assert st.success, st.message
    np.testing.assert_allclose(x, x_star, rtol=1e-9, atol=1e-9 * np.abs(x_star).max())
    assert len(jacobians) > 2
    assert len(calls) == (1 if first else len(jacobians))


def _powell_without_root():
    """Powell on x^2 + 1 = 0 (no root: every step is poor) from x = 0.3 with an inexact
    operator Jacobian: ``(stats, asked, at)``, the ``rtol`` of every solve request (None:
    full accuracy) and the Jacobian each was made with."""
    asked, at = [], []

    class Recording(InexactOperator):
        def solve(self, b, rtol=None):
            at.append(self.J[0, 0])
            return super().solve(b, rtol)

    def op(x, need_jacobian):
        f = np.array([x[0] ** 2 + 1.0])
        return f, (Recording(np.array([[2 * x[0]]]), asked) if need_jacobian else None)

    _, _, st = solve(op, [0.3], lambda x: 1.0, tol=1e-12, max_iter=30)
    return st, asked, at


def test_powell_redoes_a_poor_inexact_step_exactly(monkeypatch):
    """With ``POOR_STEP_FULL_ACCURACY``, an inexact step that the model served poorly (ratio
    of actual to predicted decrease below 0.1) and that did not decrease |f| is redone on
    the same Jacobian to the full accuracy (``rtol`` None) before the next iteration: on
    x^2 + 1 = 0 (no root) every first step on a new Jacobian fails, so every loose request
    is followed by an exact one with the same Jacobian (the iterate unchanged in between)."""
    from fretwear.hb import solvers

    monkeypatch.setattr(solvers, "POOR_STEP_FULL_ACCURACY", True)
    st, asked, at = _powell_without_root()
    assert not st.success and len(asked) > 4
    for i, a in enumerate(asked[:-1]):
        if a is not None:
            assert asked[i + 1] is None and at[i + 1] == at[i]


def test_powell_keeps_inexact_steps_after_a_poor_step_by_default():
    """By default (``POOR_STEP_FULL_ACCURACY`` False) a poor inexact step is neither redone
    nor followed by full-accuracy steps: on x^2 + 1 = 0 (no root: every step is poor, the
    case where the other setting asks for an exact step after each loose one) every request
    is loose (``rtol`` given) and no Jacobian is solved twice."""
    from fretwear.hb import solvers

    assert solvers.POOR_STEP_FULL_ACCURACY is False
    st, asked, at = _powell_without_root()
    assert not st.success and len(asked) > 4
    assert all(a is not None for a in asked)
    assert all(at[i + 1] != at[i] for i in range(len(at) - 1))


def test_powell_watchdog_crosses_kinks_where_the_monotone_test_crawls(monkeypatch):
    """Near a kink the Newton step of a piecewise-linear residual crosses it and ``|f|``
    rises at the trial point: the monotone ratio test rejects it and the trust region
    crawls. With the watchdog stretches (fretwear.hb.solvers.WATCHDOG_AFTER) Powell takes
    such a step and Newton steps from it, and returns if they do not get below the start.
    On the kinked problem of seed 7 (drawn once; the counts are recorded, not tuned) the
    monotone Powell takes 48 iterations and the watchdog 15; over 40 seeds the watchdog
    never takes more (1690 iterations in all against 1893) and every solve reaches the root
    ``x*`` the problem was built from (independent of the solver: its only root) to 1e-11 of
    its largest entry (the last Newton step, on the root's linear piece, is exact: the
    solves end at ``x*`` to rounding, 1e-15). The problems' Jacobians are formed, so the
    stretches are switched on for them (``WATCHDOG_FORMED``; by default they serve only
    operator Jacobians).

    The stretches from the full Newton step after dog-leg steps that crawl
    (``WATCHDOG_CLIPPED``, off in the first two runs) cut the 40 solves to 370 iterations in
    all (recorded; at most 29 for one draw, where the watchdog alone took up to 123), every
    one reaching ``x*``, none taking more iterations than with the watchdog alone."""
    from fretwear.hb import solvers

    monkeypatch.setattr(solvers, "WATCHDOG_FORMED", True)
    counts = {}
    for name, after, clipped in (("monotone", 10**9, 10**9),
                                 ("watchdog", solvers.WATCHDOG_AFTER, 10**9),
                                 ("clipped", solvers.WATCHDOG_AFTER, solvers.WATCHDOG_CLIPPED)):
        monkeypatch.setattr(solvers, "WATCHDOG_AFTER", after)
        monkeypatch.setattr(solvers, "WATCHDOG_CLIPPED", clipped)
        its = []
        for seed in range(40):
            fun, x_star, scale = kinked(seed)
            x, _, st = solve(fun, np.zeros_like(x_star), lambda x, s=scale: s, tol=1e-12)
            assert st.success, (name, seed, st.message)
            np.testing.assert_allclose(x, x_star, rtol=0, atol=1e-11 * np.abs(x_star).max())
            its.append(st.iterations)
        counts[name] = its
    old, new, clip = counts["monotone"], counts["watchdog"], counts["clipped"]
    assert old[7] >= 40 and new[7] <= 20
    assert all(b <= a for a, b in zip(old, new, strict=True)) and sum(new) < sum(old)
    assert sum(clip) < 0.3 * sum(new) and max(clip) <= 30
    assert all(c <= b for b, c in zip(new, clip, strict=True))
