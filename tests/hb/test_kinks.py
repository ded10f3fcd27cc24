"""The local phase of Powell's solve (fretwear.hb.kinks: nonlinear elimination of the contact
nodes that hold the residual) on small DLFT problems and in fretwear.hb.solvers.powell.

References independent of the code under test: the full problem's residual and formed
Jacobian (fretwear.hb.problem.DLFTProblem with jacobian="dense"), a root of the full problem
found by Powell with LU steps to 1e-12, and the known root of the piecewise-linear problems of
tests/helpers/kinked.py. Tolerances: the subproblem's residual and Jacobian are the same sums
as the full problem's in another order (1e-12 relative to their largest entry); the root after
the local phase is that of a subproblem solved to 1e-3 of its start and a Newton step of the
whole (quadratic from 1e-3: below the 1e-12 test), compared at 1e-9 relative.
"""

import numpy as np
import pytest
from helpers.blocks import block
from helpers.kinked import kinked

from fretwear.hb import contact as law
from fretwear.hb import kinks, solvers
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.preload import static_anchor
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.reduce import condense
from fretwear.hb.solvers import solve
from fretwear.model.build import Damping
from fretwear.model.core import Load
from fretwear.model.matrices import ContactDofs, from_matrices


@pytest.fixture(scope="module")
def solved():
    """A 3D block in partial slip (separation, stick and slip during the period, asserted)
    and its root by the dense path's Powell to 1e-12."""
    model = block(3, 0.0)
    basis = FourierBasis.up_to(3, 32)
    red = condense(model, 2000.0, basis.orders)
    prob = DLFTProblem(red, model.contact, basis, eps="auto", anchor=static_anchor(model),
                       jacobian="dense")

    def fun(x, jac=True):
        return prob.residual(x.reshape(prob.m, prob.H), jac)

    x, _, st = solve(fun, prob.initial_guess().reshape(-1),
                     lambda x: prob.scale(x.reshape(prob.m, prob.H)), tol=1e-12)
    assert st.success, st.message
    _, _, state, _ = prob.time_law(x.reshape(prob.m, prob.H))
    for s in (law.SEPARATION, law.STICK, law.SLIP):
        assert np.any(state == s), law.STATE_NAMES[s]
    return prob, x


def perturbed(prob, x, nodes, size, seed=0):
    """``x`` with the unknowns of ``nodes`` moved by ``size`` times their largest entry."""
    rng = np.random.default_rng(seed)
    U = x.reshape(prob.m, prob.H).copy()
    dofs = (np.asarray(nodes)[:, None] * prob.d + np.arange(prob.d)).reshape(-1)
    U[dofs] += size * np.abs(U).max() * rng.standard_normal((dofs.size, prob.H))
    return U


def test_subproblem_is_the_full_problem_on_its_rows(solved):
    """The subproblem of two nodes (the others held) at a point off the root: its residual
    and Jacobian at moved unknowns equal the full problem's rows (and rows and columns) of
    those nodes with the same unknowns moved (reference: DLFTProblem.residual, dense)."""
    prob, x = solved
    nodes = np.array([0, prob.nc - 1])
    U = perturbed(prob, x, np.arange(prob.nc), 1e-3)
    sub, x0, dofs = kinks.subproblem(prob, U, nodes)
    moved = x0 + 1e-3 * np.abs(x0).max() * np.random.default_rng(1).standard_normal(x0.size)
    fs, Js = sub(moved, True)
    U2 = U.copy()
    U2[dofs] = moved.reshape(dofs.size, prob.H)
    f, J = prob.residual(U2, True)
    rows = (dofs[:, None] * prob.H + np.arange(prob.H)).reshape(-1)
    assert np.abs(fs).max() > 1e-6 * np.abs(f).max()  # off the root
    np.testing.assert_allclose(fs, f[rows], rtol=0, atol=1e-12 * np.abs(f).max())
    np.testing.assert_allclose(Js.J, J[np.ix_(rows, rows)], rtol=0,
                               atol=1e-12 * np.abs(J).max())



def _jenkins_prescribed():
    """The 2D Jenkins oscillator of tests/hb/test_connectors.py: one tangential DOF in
    series with a contact spring (``kt`` 0.5) under a prescribed normal load, at a
    frequency where it sticks and slips."""
    model = from_matrices([[1.0]], [[1.0]],
                          contact=ContactDofs(normal_dofs=None, tangential_dofs=[0], mu=0.5,
                                              normal_load=1.0, kt=0.5),
                          damping=Damping(C=[[0.02]]), loads=[Load(np.array([0.2]), "cos")])
    basis = FourierBasis.up_to(3, 32)
    red = condense(model, 1.18 / (2 * np.pi), basis.orders)
    return DLFTProblem(red, model.contact, basis, jacobian="krylov")


def _block_2d_damped():
    """The 2D block in partial slip with hysteretic damping (complex ``Z_r`` blocks) on the
    operator path (``jacobian = "krylov"``: ``lambda_u`` by harmonic blocks)."""
    model = block(2, 0.02)
    basis = FourierBasis.up_to(3, 32)
    red = condense(model, 2000.0, basis.orders)
    return DLFTProblem(red, model.contact, basis, anchor=static_anchor(model),
                       jacobian="krylov")


@pytest.mark.parametrize("make", [_jenkins_prescribed, _block_2d_damped])
def test_subproblem_is_the_full_problem_on_its_rows_in_2d(make):
    """As :func:`test_subproblem_is_the_full_problem_on_its_rows`, in 2D: under a prescribed
    normal load with a contact spring (the law's ``lambda_N = N(t)`` and the spring's
    connection, which the subproblem takes from the problem), and with complex ``Z_r``
    blocks on the operator path (the subproblem's block cut from the reduced model, the
    full residual's products by harmonic blocks). Reference: the full residual and the
    operator's formed Jacobian (``toarray``) with the same unknowns moved; the same sums in
    another order, 1e-12 of their largest entry (measured 3e-13 and 1e-13)."""
    prob = make()

    def fun(x, jac=True):
        return prob.residual(x.reshape(prob.m, prob.H), jac)

    x, _, st = solve(fun, prob.initial_guess().reshape(-1),
                     lambda x: prob.scale(x.reshape(prob.m, prob.H)), tol=1e-10)
    assert st.success, st.message
    rng = np.random.default_rng(0)
    U = x.reshape(prob.m, prob.H) * (1.0 + 1e-3 * rng.standard_normal((prob.m, prob.H)))
    nodes = np.unique([0, prob.nc - 1])
    sub, x0, dofs = kinks.subproblem(prob, U, nodes)
    moved = x0 + 1e-3 * np.abs(x0).max() * rng.standard_normal(x0.size)
    fs, Js = sub(moved, True)
    U2 = U.copy()
    U2[dofs] = moved.reshape(dofs.size, prob.H)
    f, J = prob.residual(U2, True)
    J = J.toarray()
    rows = (dofs[:, None] * prob.H + np.arange(prob.H)).reshape(-1)
    assert np.abs(fs).max() > 1e-3 * np.abs(f).max()  # off the root on these rows
    np.testing.assert_allclose(fs, f[rows], rtol=0, atol=1e-12 * np.abs(f).max())
    np.testing.assert_allclose(Js.J, J[np.ix_(rows, rows)], rtol=0,
                               atol=1e-12 * np.abs(J).max())

def test_local_phase_returns_to_the_root(solved):
    """Two nodes moved off the root by 1e-3 of the largest unknown (the others at the root):
    the local phase reaches the root found by the dense Powell to 1e-9 relative and meets
    the convergence test."""
    prob, x = solved
    U = perturbed(prob, x, [1, 2], 1e-3)
    f, _ = prob.residual(U, False)
    target = 1e-12 * prob.scale(U)
    assert np.linalg.norm(f) > 1e3 * target
    assert {1, 2} <= set(kinks.worst_nodes(f, prob.nc))
    local = kinks.local_phase(prob)
    out = local(U.reshape(-1), f, target)
    assert local.njev >= 1 and local.nfev == 2 * local.njev  # a residual after each step
    fo, _ = prob.residual(out.reshape(prob.m, prob.H), False)
    assert np.linalg.norm(fo) <= target
    np.testing.assert_allclose(out, x, rtol=0, atol=1e-9 * np.abs(x).max())


def _three_locals(fun, x_star, scale):
    """Powell on a kinked problem from 0 with no local phase, one that returns its input and
    one that returns the known root: ``{name: (x, stats, |f| of every iterate)}``."""
    out = {}
    for name, local in (("none", None), ("same", lambda x, f, t: x),
                        ("root", lambda x, f, t, r=x_star: r)):
        seen = []
        x, _, st = solvers.powell(fun, np.zeros_like(x_star), lambda x, s=scale: s,
                                  tol=1e-12, local=local,
                                  callback=lambda i, x, fn, seen=seen: seen.append(fn))
        out[name] = (x, st, seen)
    return out


def test_powell_takes_a_better_point_of_the_local_phase(monkeypatch):
    """On the kinked piecewise-linear problems of test_solvers (their roots known), with the
    stretches on formed Jacobians: a local phase that returns the root ends every solve that
    calls it at the root in fewer iterations than without it, and one that returns its
    input (no better point) leaves every solve as without it, iterate for iterate (the
    default path where the local phase finds nothing: unchanged). Recorded: 36 of the 40
    draws reach the crawl that calls it (370 iterations in all without, 154 with the
    root's local phase entered after two crawling dog-leg steps, 226 after four)."""
    monkeypatch.setattr(solvers, "WATCHDOG_FORMED", True)
    called = 0
    for seed in range(40):
        fun, x_star, scale = kinked(seed)
        runs = {}
        for name, (x, st, seen) in _three_locals(fun, x_star, scale).items():
            assert st.success, (seed, name, st.message)
            np.testing.assert_allclose(x, x_star, rtol=0, atol=1e-11 * np.abs(x_star).max())
            runs[name] = (st.iterations, seen)
        assert runs["same"] == runs["none"]
        if runs["root"] != runs["none"]:
            called += 1
            assert runs["root"][0] < runs["none"][0]
    assert called >= 30


def test_worst_nodes_takes_at_least_min_nodes():
    """``worst_nodes``: the fewest nodes holding ``SHARE`` of ``|f|^2``, at least
    ``MIN_NODES``, at most ``MAX_NODES``, against a sort by hand of per-node sums of squares
    made distinct (one node holds 99.99 %: the share alone would take it only)."""
    nc, d, H = 40, 3, 5
    rng = np.random.default_rng(3)
    per = rng.permutation(np.arange(1.0, nc + 1.0))
    f = (np.sqrt(per / (d * H))[:, None] * np.ones(d * H)).reshape(-1)
    big = int(np.argmax(per))
    f.reshape(nc, -1)[big] *= 1e3
    order = np.argsort(-np.sum(np.reshape(f, (nc, -1)) ** 2, axis=1))
    np.testing.assert_array_equal(kinks.worst_nodes(f, nc), np.sort(order[:kinks.MIN_NODES]))
    np.testing.assert_array_equal(kinks.worst_nodes(f, nc, share=1.0, max_nodes=25),
                                  np.sort(order[:25]))
    assert kinks.MIN_NODES == 16


def test_local_phase_entered_after_two_crawling_steps(monkeypatch):
    """The entry rule (``solvers.LOCAL_CLIPPED``) on the kinked piecewise-linear problems of
    test_solvers (their roots known; stretches on formed Jacobians, as above): called after
    two crawling dog-leg steps instead of four, a local phase that returns the root ends the
    same draws' solves (36 of 40) and each in no more iterations than at four (recorded:
    154 iterations in all against 226 at four and 370 without), and one that returns its
    input leaves every solve as without it, iterate for iterate (a phase that finds nothing
    costs its own evaluations only: the forced stretch still follows at four). The counts
    are integers of a deterministic path: compared exactly."""
    monkeypatch.setattr(solvers, "WATCHDOG_FORMED", True)
    totals = {}
    for after in (4, 2):
        monkeypatch.setattr(solvers, "LOCAL_CLIPPED", after)
        totals[after] = {"none": [], "same": [], "root": []}
        for seed in range(40):
            fun, x_star, scale = kinked(seed)
            for name, (_, st, seen) in _three_locals(fun, x_star, scale).items():
                assert st.success, (after, seed, name, st.message)
                totals[after][name].append((st.iterations, seen))
        assert totals[after]["same"] == totals[after]["none"]
    assert totals[2]["none"] == totals[4]["none"]
    it = {a: [n for n, _ in totals[a]["root"]] for a in (2, 4)}
    assert all(i2 <= i4 for i2, i4 in zip(it[2], it[4], strict=True))
    changed = {a: {s for s in range(40) if it[a][s] != totals[a]["none"][s][0]} for a in (2, 4)}
    assert changed[2] == changed[4] and len(changed[2]) == 36
    assert (sum(it[2]), sum(it[4]), sum(n for n, _ in totals[4]["none"])) == (154, 226, 370)


def test_a_local_phase_that_made_progress_resets_the_progress_test(monkeypatch):
    """Powell's progress test (``max_slow``: stop after that many Jacobians without an
    iteration that decreased ``|f|^2`` by ``SLOW_DECREASE``) counts an accepted local phase
    as such an iteration when it decreased ``|f|^2`` that much. On the 40 kinked
    piecewise-linear problems (formed Jacobians with the stretches, as above) with a local
    phase that goes 90 % of the way to the known root and ``max_slow = 3``: 1 draw stops on
    the progress test (measured; 9 did before the local phase reset it, the phase's progress
    not counted). The counts are of a deterministic path: compared exactly."""
    monkeypatch.setattr(solvers, "WATCHDOG_FORMED", True)
    stopped = 0
    for seed in range(40):
        fun, x_star, scale = kinked(seed)
        _, _, st = solvers.powell(fun, np.zeros_like(x_star), lambda x, s=scale: s,
                                  tol=1e-12, local=lambda x, f, t, r=x_star: x + 0.9 * (r - x),
                                  max_slow=3)
        stopped += "not making good progress" in st.message
    assert stopped == 1


def test_powell_counts_the_evaluations_the_local_phase_says(monkeypatch):
    """A local phase that keeps its evaluations in ``nfev`` / ``njev`` (as kinks.local_phase
    does) has them added to Powell's: on the kinked problems whose solves call it, the
    stats exceed those of the same phase without the attributes by exactly what it says
    (7 and 3 a call; the paths are the same, the phase returning the root either way)."""
    monkeypatch.setattr(solvers, "WATCHDOG_FORMED", True)
    compared = 0
    for seed in range(40):
        fun, x_star, scale = kinked(seed)

        def plain(x, f, t, r=x_star):
            plain.calls += 1
            return r

        def counting(x, f, t, r=x_star):
            counting.nfev += 7
            counting.njev += 3
            return r

        plain.calls, counting.nfev, counting.njev = 0, 0, 0
        runs = [solvers.powell(fun, np.zeros_like(x_star), lambda x, s=scale: s, tol=1e-12,
                               local=local)[2] for local in (plain, counting)]
        if plain.calls:
            compared += 1
            assert runs[1].iterations == runs[0].iterations
            assert runs[1].nfev - runs[0].nfev == 7 * plain.calls
            assert runs[1].njev - runs[0].njev == 3 * plain.calls
    assert compared == 36  # the draws whose crawl calls the phase (as above)
