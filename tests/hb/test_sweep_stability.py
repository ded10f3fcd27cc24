"""Stability along a sweep (:mod:`fretwear.hb.sweep_stability`) on the two-DOF oscillator with
a unilateral spring (NLvib's example-03 family), whose forced response folds.

References (none is the code under test's own bookkeeping):

* the determinant of the balance's Jacobian ``J = T(0)`` has the sign
  ``(-1)^(number of real Floquet multipliers above 1)``: an eigenvalue of ``T(0)`` passes
  through 0 exactly where a real exponent does (``T(s) p = 0`` at ``s = 0``), starting from
  ``det J > 0`` on the stable branch below the resonance. The sign comes from an LU of ``J``,
  the multipliers from the eigenvalues of the quadratic Hill problem refined on ``T(s)``: two
  computations that share only ``T``;
* the events listed are exactly where the neighbours' signs or stabilities differ (the
  definition, counted here independently).
"""

import dataclasses

import numpy as np
import pytest
from helpers.models import two_dof

from fretwear.hb.dynamics import structure_dynamics
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SweepOptions
from fretwear.hb.reduce import exact_condenser
from fretwear.hb.stability import (
    EDGE_TOL,
    HillOptions,
    HillProblem,
    problem_of,
    stability,
)
from fretwear.hb.sweep import sweep
from fretwear.hb.sweep_stability import (
    Computed,
    branch_events,
    nearest,
    point_problem,
    sweep_stability,
)
from fretwear.model.build import Damping
from fretwear.model.core import Load
from fretwear.model.matrices import ContactDofs, from_matrices


@pytest.fixture(scope="module")
def folded():
    model = two_dof()
    cond = exact_condenser(model)
    res = sweep(model, FourierBasis.up_to(15, 256), 0.56 / (2 * np.pi), 0.8 / (2 * np.pi), 30,
                options=SweepOptions(spacing="linear"), condenser=cond)
    return res, sweep_stability(model, res, condenser=cond)


def test_det_sign_is_the_parity_of_real_multipliers_above_one(folded):
    """At every point: sign det J = (-1)^(real multipliers > 1); and the band has unstable
    points (the fold's middle branch or a period doubling) and stable ones, so the check is
    not vacuous. Real: |Im rho| <= 1e-6 |rho| (the problem is real: a real exponent stays
    real, :func:`fretwear.hb.stability._track`); above 1: by 1e-6 (the stability margin)."""
    res, st = folded
    done = st.stable >= 0
    assert done.sum() == res.point_success.sum() and done.any()
    assert (st.stable[done] == 0).any() and (st.stable[done] == 1).any()
    assert (st.det_sign[done] == -1).any()
    for i in np.flatnonzero(done):
        rho = st.floquet[i].multipliers
        real = np.abs(rho.imag) <= 1e-6 * np.abs(rho)
        count = int(np.sum(real & (rho.real > 1 + 1e-6)))
        assert st.det_sign[i] == (-1) ** count, (i, rho)
        assert st.stable[i] == (st.max_multiplier[i] <= 1 + 1e-6)


def test_events_are_where_neighbours_differ(folded):
    """One event between two neighbouring computed points where ``det J`` changes sign (a
    fold) or the stability changes (classified by the critical multiplier), none elsewhere;
    a fold between a stable and an unstable neighbour has its real multiplier above 1."""
    res, st = folded
    f = res.frequency_hz
    done = np.flatnonzero(st.stable >= 0)
    expected = [(f[a], f[b]) for a, b in zip(done[:-1], done[1:], strict=True)
                if st.det_sign[a] != st.det_sign[b] or st.stable[a] != st.stable[b]]
    events = branch_events(f, st)
    assert [(e.f_lo, e.f_hi) for e in events] == expected and events
    for e in events:
        assert e.kind in ("fold", "period-doubling", "Neimark-Sacker",
                          "real multiplier through +1")
        if e.kind == "fold" and e.change:
            assert abs(e.multiplier.imag) < 1e-6 and e.multiplier.real > 1
        if e.kind == "period-doubling":
            assert e.multiplier.real < -1
        assert f"{e.f_lo:.6g}" in e.line()


@pytest.fixture(scope="module")
def dense(folded):
    """The dense eigensolve at every point of the folded sweep (``HillOptions(track=False)``)."""
    res, _ = folded
    model = two_dof()
    return sweep_stability(model, res, condenser=exact_condenser(model),
                           options=HillOptions(track=False))


def test_tracked_candidates_give_the_dense_multipliers(folded, dense):
    """Hill's method along the sweep continues each point's candidates from those of the
    nearest point already computed (:func:`nearest`; inverse iteration,
    :func:`fretwear.hb.stability.track_eigen`) instead of the dense
    eigensolve of the quadratic problem; the reference is the dense eigensolve at every point
    (``HillOptions(track=False)``): the same multipliers, one for one, to 1e-10 (both are
    the same simple eigenvalues of the same matrices, each computed to about 1e-14; the
    tolerance leaves room for their condition). Some points must be tracked and some not
    (the arclength's jumps between branches and the period-doubling stretch fall back to the
    dense eigensolve), so that the comparison covers both."""
    res, st = folded
    tracked = [fl.tracked for fl in st.floquet if fl is not None]
    assert any(tracked) and not all(tracked)
    assert not any(fl.tracked for fl in dense.floquet if fl is not None)
    for a, b in zip(st.floquet, dense.floquet, strict=True):
        assert (a is None) == (b is None)
        if a is not None:
            assert a.multipliers.shape == b.multipliers.shape
            np.testing.assert_allclose(a.multipliers, b.multipliers, rtol=0, atol=1e-10)


def test_period_doubling_members_are_tracked_as_the_dense_eigensolve(folded, dense):
    """Points whose dense eigensolve has real negative multipliers (exponents on the
    period-doubling line ``Im s = w/2``, within ``EDGE_TOL``: two per period doubling, born
    where a complex pair met on the line) are continued from the nearest point by inverse
    iteration, each member on the line followed alone (its mirror ``conj(s) + i`` checked):
    some of them are tracked (none was before: the tracker refused the line), and at each
    the multipliers and exponents are the dense eigensolve's, one for one, to 1e-10 (the
    same simple eigenvalues of the same matrices, each to about 1e-14, as in the test
    above), with the real negative multipliers among them."""
    _, st = folded
    on_line = []
    for a, b in zip(st.floquet, dense.floquet, strict=True):
        if b is None:
            continue
        line = np.abs(np.abs(b.exponents.imag / b.omega) - 0.5) <= EDGE_TOL
        if line.any():
            on_line.append((a, b, line))
    assert len(on_line) >= 3
    tracked = [(a, b, line) for a, b, line in on_line if a.tracked]
    assert len(tracked) >= 2
    for a, b, line in tracked:
        np.testing.assert_allclose(a.multipliers, b.multipliers, rtol=0, atol=1e-10)
        np.testing.assert_allclose(a.exponents / a.omega, b.exponents / b.omega, rtol=0,
                                   atol=1e-10)
        neg = b.multipliers[line]
        assert np.all(neg.imag == 0) and np.all(neg.real < 0)


def test_the_sweeps_own_problems_give_the_rebuilt_problems_multipliers(folded):
    """Every converged point of the sweep keeps the problem it was solved on, and Hill's
    method runs on it (:func:`point_problem`) instead of condensing the model again; the
    reference is the problem rebuilt from the solution (:func:`problem_of`, the only path
    before; the points copied without their problem, as a checkpoint's are): the balance's
    Jacobian equal to 1e-12 relative and the multipliers, one for one, to 1e-10 (the same
    condensation at the frequency recorded in hertz rather than in rad/s, a rounding of
    1e-16 relative; the multipliers' tolerance as in the test above)."""
    res, st = folded
    model = two_dof()
    cond = exact_condenser(model)
    dyn = structure_dynamics(model, cond)
    bare = [dataclasses.replace(p, problem=None) for p in res.points]
    assert all(p.problem is not None for p in res.points if p.success)
    for p, q in zip(res.points, bare, strict=True):
        if not p.success:
            continue
        assert point_problem(model, p, cond) is p.problem
        a = HillProblem(p.problem, p.solution.U, dyn).jacobian()
        b = HillProblem(problem_of(model, q.solution, condenser=cond), q.solution.U,
                        dyn).jacobian()
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-12 * np.abs(b).max())
    rebuilt = sweep_stability(model, dataclasses.replace(res, points=bare), condenser=cond)
    np.testing.assert_array_equal(rebuilt.stable, st.stable)
    np.testing.assert_array_equal(rebuilt.det_sign, st.det_sign)
    for a, b in zip(st.floquet, rebuilt.floquet, strict=True):
        assert (a is None) == (b is None)
        if a is not None:
            assert a.multipliers.shape == b.multipliers.shape
            np.testing.assert_allclose(a.multipliers, b.multipliers, rtol=0, atol=1e-10)


def _jenkins(force, kt, slip, c):
    """A mass (1 kg) on a spring (1 N/m) and a Jenkins element (``kt`` in series with a slider
    of threshold ``slip`` = mu N, N prescribed), viscous damping ``c``, a cosine force."""
    return from_matrices([[1.0]], [[1.0]],
                         contact=ContactDofs(normal_dofs=None, tangential_dofs=[0], mu=slip,
                                             normal_load=1.0, kt=kt),
                         damping=Damping(C=[[c]]), loads=[Load(np.array([force]), "cos")],
                         observed={"x": 0})


def _against_dense(model, res, cond):
    """Hill's method along ``res`` with each point given the previous one's result, and the
    dense eigensolve with refinements from the candidates at every point
    (``HillOptions(track=False)``), pairwise."""
    dyn = structure_dynamics(model, cond)
    prev, out = None, []
    for p in res.points:
        if p.solution is None:
            continue
        a = stability(model, p.solution, dyn=dyn, condenser=cond, previous=prev)
        b = stability(model, p.solution, dyn=dyn, condenser=cond,
                      options=HillOptions(track=False))
        out.append((a, b))
        prev = a
    return out


def test_refinements_started_from_the_neighbour_give_the_candidates_refinements():
    """A Jenkins oscillator that sticks part of every period along a sweep (the law's memory:
    every exponent refined on the exact ``T(s)``): refinements started from the previous
    point's refined exponent with its secant slope reach the same exponents as those started
    from the candidates with a forward difference (``track=False``), the multipliers to 1e-8
    (both stop at a relative residual of ``newton_tol`` = 1e-10 of the same simple root;
    measured 6e-10), the same verdicts, in fewer evaluations of ``T(s)`` (the reason for
    the warm start: 199 against 272 on the benchmark's 30 points)."""
    model = _jenkins(0.2, 1.0, 0.1, 0.02)
    cond = exact_condenser(model)
    res = sweep(model, FourierBasis.up_to(7, 128), 0.15, 0.23, 12,
                options=SweepOptions(spacing="linear"), condenser=cond)
    pairs = _against_dense(model, res, cond)
    assert len(pairs) >= 10 and sum(a.tracked for a, _ in pairs) >= 5
    assert all("refined" in b.kind for _, b in pairs)
    for a, b in pairs:
        assert a.multipliers.shape == b.multipliers.shape and a.stable == b.stable
        np.testing.assert_allclose(a.multipliers, b.multipliers, rtol=0, atol=1e-8)
    assert sum(a.evaluations for a, _ in pairs) < sum(b.evaluations for _, b in pairs)


def test_candidates_are_not_continued_out_of_full_stick():
    """A Jenkins branch that leaves full stick between two points: the frozen-memory problem's
    held pair goes and two real exponents come, with the same number of eigenvalues; the
    candidates continued from the neighbour's kept the held pair only (the count of families
    could not see it). Across a change of the contact regime the dense eigensolve is used:
    the multipliers are those of ``track=False`` at every point (to rounding: 1e-12), and the
    point out of full stick has two real ones."""
    model = _jenkins(0.2, 0.5, 0.5, 0.02)
    cond = exact_condenser(model)
    res = sweep(model, FourierBasis.up_to(7, 128), 1.1 / (2 * np.pi), 1.16 / (2 * np.pi), 4,
                options=SweepOptions(spacing="linear"), condenser=cond)
    pairs = _against_dense(model, res, cond)
    held = [set(a.kind) == {"held"} for a, _ in pairs]
    assert held[0] and not held[-1]
    for a, b in pairs:
        assert a.multipliers.shape == b.multipliers.shape
        np.testing.assert_allclose(a.multipliers, b.multipliers, rtol=0, atol=1e-12)
    last = pairs[held.index(False)][0]
    assert not last.tracked and np.all(last.multipliers.imag == 0) and last.multipliers.size == 2


def test_nearest_is_the_closest_solution_that_can_be_continued(folded):
    """:func:`nearest` returns the result of the solution closest to ``U`` (Euclidean norm of
    the harmonics, computed here directly) among those with a track, skipping a closer one
    without (its candidates cannot be continued), and None when none has one."""
    _, st = folded
    with_track = [fl for fl in st.floquet if fl is not None and fl.track is not None]
    without = [fl for fl in st.floquet if fl is not None and fl.track is None]
    assert len(with_track) >= 2 and without
    U = np.zeros((2, 3))
    seen = [(U + 3.0, with_track[0]), (U - 1.0, with_track[1]), (U + 0.5, without[0])]
    assert nearest(U, seen) is with_track[1]
    assert nearest(U + 2.0, seen) is with_track[0]
    assert nearest(U, seen[2:]) is None and nearest(U, []) is None


def test_computed_points_give_the_lists_nearest(folded):
    """:class:`Computed` (the sweep's stacked record) returns what the list of pairs does:
    the same result object for queries near each point, past its first growth (8 rows), with
    results without a track and of another size skipped; ``len`` counts every point."""
    _, st = folded
    with_track = [fl for fl in st.floquet if fl is not None and fl.track is not None]
    without = [fl for fl in st.floquet if fl is not None and fl.track is None]
    rng = np.random.default_rng(2)
    pairs = [(rng.standard_normal((2, 3)), with_track[i % len(with_track)]) for i in range(11)]
    pairs += [(np.zeros((2, 3)), without[0]), (np.zeros(4), with_track[0])]
    comp = Computed()
    for item in pairs:
        comp.append(item)
    assert len(comp) == len(pairs)
    for U, _ in pairs[:11]:
        for q in (U, U + 0.1 * rng.standard_normal(U.shape)):
            assert nearest(q, comp) is nearest(q, pairs)
    assert nearest(np.zeros(5), comp) is None and nearest(np.zeros(5), Computed()) is None
