"""The attempt ladder of a periodic solve (:mod:`fretwear.hb.attempts`): every attempt recorded
in order, the continuation in the penalty ending at the target eps, the start from a time
integration, and the report of a ladder in which no attempt ran at the target eps.
"""

import numpy as np
import pytest

from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.reduce import condense
from fretwear.model.core import Load


def test_strategy_records_every_attempt_and_ends_at_the_target_eps():
    """The issue's two-DOF chain (mass 2 rubbing on the ground under a prescribed normal
    force) at 15 harmonics with eps = 1 N/m: Powell stalls from the contact-closed start,
    Newton from its best iterate too, and the eps continuation (10 N/m, then back to 1 N/m)
    converges. Checked independently of the solver's own test: a fresh problem at eps = 1
    evaluates the residual of the returned harmonics below the tolerance, and the attempts
    are recorded in order with only the last one successful."""
    from fretwear.hb.fourier import FourierBasis as FB
    from fretwear.model.build import Damping
    from fretwear.model.matrices import ContactDofs, from_matrices

    model = from_matrices(np.array([[2.0, -1.0], [-1.0, 1.0]]), np.eye(2),
                          contact=ContactDofs(normal_dofs=None, tangential_dofs=[1], mu=0.5,
                                              normal_load=1.0),
                          damping=Damping(C=0.02 * np.eye(2)),
                          loads=[Load(np.array([0.2, 0.0]), "cos")], observed={"x": 0})
    basis = FB.up_to(15, 128)
    sol = solve_periodic(model, basis, frequency=1.4905405 / (2 * np.pi), eps=1.0)
    assert sol.success and sol.eps == 1.0
    methods = [a.method for a in sol.attempts]
    assert methods == ["start", "best-point", "eps-continuation"]
    assert [a.success for a in sol.attempts] == [False, False, True]
    assert sol.attempts[-1].eps == 1.0 and "eps path 10, " in sol.attempts[-1].message
    red = condense(model, sol.frequency, basis.orders)
    prob = DLFTProblem(red, model.contact, basis, eps=1.0, anchor=sol.anchor)
    U = sol.U.reshape(prob.m, prob.H)
    f, _ = prob.residual(U, jacobian=False)
    assert np.linalg.norm(f) <= 1e-8 * prob.scale(U)
    only = solve_periodic(model, basis, frequency=1.4905405 / (2 * np.pi), eps=1.0,
                          options=SolveOptions(strategy=("start",)))
    assert not only.success and [a.method for a in only.attempts] == ["start"]


# --- the time-domain start of solve_periodic ------------------------------------------------
def test_time_start_reaches_the_balance_of_the_standard_solve():
    """The attempt "time-start" alone (no other attempt) on the friction oscillator (continuous
    slip: one periodic solution, no stick anchors to choose): the balance started from a time
    integration's periodic steady state equals the one solved from the contact-closed guess.
    Two independent paths to one solution of one balance: they agree to the conditioning of
    the balance times its tolerance 1e-8 (1e-6 relative leaves that margin; measured 1e-13)."""
    from fretwear.timedomain.fallback import FALLBACK
    from tests.helpers.models import oscillator

    model, basis = oscillator(), FourierBasis.up_to(5, 64)
    ref = solve_periodic(model, basis, frequency=15.0)
    ts = solve_periodic(model, basis, frequency=15.0,
                        options=SolveOptions(strategy=("time-start",)), time_domain=FALLBACK)
    assert ref.success and ts.success
    assert [a.method for a in ts.attempts] == ["time-start"] and ts.attempts[0].success
    assert ts.time_domain.startswith("time integration: periodic steady state")
    assert not ts.flags
    assert np.abs(ts.U - ref.U).max() <= 1e-6 * np.abs(ref.U).max()


def test_time_start_reports_a_response_that_is_not_periodic():
    """When the time integration finds no periodic state, the solve fails with what the
    structure does: in ``time_domain``, in ``flags`` and as the last attempt's message; the
    integration is asked for the given number of periods, from rest."""
    from fretwear.hb.fallback import TimeDomainFallback
    from tests.helpers.models import oscillator

    calls = []
    msg = "time integration: quasi-periodic over 300 periods: no periodic steady state"

    def start(model, frequency, basis, solution, *, max_periods):
        calls.append((frequency, solution, max_periods))
        return msg, None, None

    fake = TimeDomainFallback(start=start, averaged_rate=None)
    sol = solve_periodic(oscillator(), FourierBasis.up_to(3, 32), frequency=15.0,
                         options=SolveOptions(strategy=("time-start",),
                                              time_domain_periods=300), time_domain=fake)
    assert not sol.success
    assert calls == [(15.0, None, 300)]
    assert sol.time_domain == msg and msg in sol.flags
    assert [a.method for a in sol.attempts] == ["time-start"]
    assert sol.attempts[0].message == msg and not sol.attempts[0].success


def test_time_start_is_skipped_where_the_time_domain_does_not_apply():
    """Quasi-static solves, a worn gap and contact springs take no time-domain start (the
    integration would answer another problem): the fallback is never called."""
    from fretwear.hb.fallback import TimeDomainFallback
    from tests.helpers.models import oscillator

    def start(*args, **kwargs):
        raise AssertionError("the time-domain start ran")

    fake = TimeDomainFallback(start=start, averaged_rate=None)
    basis = FourierBasis.up_to(3, 32)
    model = oscillator()
    for kw in ({"quasi_static": True}, {"gap": np.array([1e-9])}):
        sol = solve_periodic(model, basis, frequency=15.0,
                             options=SolveOptions(strategy=("time-start",)), time_domain=fake, **kw)
        assert not sol.success and sol.time_domain == ""


def test_strategy_without_an_attempt_at_the_target_reports_the_start_residual():
    """When no attempt runs at the target eps (a sweep passes only its later steps, and they
    fail or do not apply), the unconverged answer is the start and its reported relative
    residual is the start's, |f(x0)| / scale(x0) evaluated here with numpy's norm, not inf
    (which the sweeps' messages printed before)."""
    from fretwear.hb.attempts import Trial, solve_ladder
    from fretwear.hb.options import PERIODIC
    from fretwear.model.build import Damping
    from fretwear.model.matrices import ContactDofs, from_matrices

    model = from_matrices(np.array([[2.0, -1.0], [-1.0, 1.0]]), np.eye(2),
                          contact=ContactDofs(normal_dofs=None, tangential_dofs=[1], mu=0.5,
                                              normal_load=1.0),
                          damping=Damping(C=0.02 * np.eye(2)),
                          loads=[Load(np.array([0.2, 0.0]), "cos")], observed={"x": 0})
    basis = FourierBasis.up_to(3, 32)
    red = condense(model, 1.49 / (2 * np.pi), basis.orders)
    prob = DLFTProblem(red, model.contact, basis, eps=1.0)
    x0 = np.full((prob.m, prob.H), 0.1)
    best = solve_ladder(Trial(prob, x0, PERIODIC), rungs=())
    x, st = best.x, best.stats
    f, _ = prob.residual(x0, jacobian=False)
    assert not st.success and np.array_equal(x, x0)
    assert st.residual == pytest.approx(np.linalg.norm(f) / prob.scale(x0), rel=1e-12)
    assert "no attempt converged (none)" in st.message


# --- the cold start of a single solve -------------------------------------------------------
def test_cold_start_on_the_operator_path_is_the_contact_closed_guess(monkeypatch):
    """With more than one harmonic a single solve on the dense path starts from the first harmonic
    alone; on the operator path (large interfaces, in partial slip where fretting happens) it
    starts from the contact-closed guess, and converges from there to the dense path's answer.
    The reference is independent of the start: the dense path's converged harmonics (formed
    Jacobian, LU). Both solves stop at a relative residual of 1e-12, where two converged
    answers of this 3D block (separation, stick and slip in its period) agree to ~1e-11; 1e-8
    of the largest coefficient would catch a start that led to another solution."""
    from helpers.blocks import block

    from fretwear.hb import attempts

    calls = []
    real = attempts.first_harmonic_start

    def counted(prob, options):
        calls.append(prob.jacobian)
        return real(prob, options)

    monkeypatch.setattr(attempts, "first_harmonic_start", counted)
    model = block(3)
    basis = FourierBasis.up_to(5, 32)
    sols = {}
    for jac in ("dense", "krylov"):
        sols[jac] = solve_periodic(model, basis, frequency=2000.0,
                                   options=SolveOptions(tol=1e-12, jacobian=jac,
                                                        strategy=("start",)))
        assert sols[jac].success, sols[jac].message
    assert calls == ["dense"]
    U, V = sols["dense"].U, sols["krylov"].U
    assert np.abs(U - V).max() <= 1e-8 * np.abs(U).max()


def _lap_joint():
    """Two steel plates (60 x 4 mm, 2D) overlapping over 30 mm, the lower one clamped, the
    upper one held across and by a 1e7 N/m spring along x at its far end, pressed together
    over the overlap by 2 MPa and shaken along x: the interface is mostly stuck, and a cold
    start from the contact-closed guess needs more than a warm-started point's 40
    iterations (a bolted lap joint built as in docs/tutorial.md)."""
    import fretwear as fw
    from fretwear.model import join

    mesh = join(("lower", fw.rectangle(0.060, 0.004, nx=30, ny=2)),
                ("upper", fw.rectangle(0.060, 0.004, nx=30, ny=2, origin=(0.030, 0.004))))
    x = mesh.points[:, 0]
    for name, edge in (("upper.overlap", "upper.bottom"), ("upper.bolt", "upper.top")):
        f = mesh.boundaries[edge]
        mesh.boundaries[name] = f[np.all(x[f] <= 0.060 + 1e-9, axis=1)]
    return fw.from_mesh(
        mesh, fw.Material(E=210e9, nu=0.3, rho=7800.0), thickness=0.020,
        damping=fw.Damping(loss_factor=0.002),
        supports=[("lower.left", "all"), ("upper.right", "y"),
                  fw.Spring("upper.right", "x", 1e7)],
        loads=[fw.Traction("upper.bolt", pressure=2e6),
               fw.Traction("upper.right", traction=(5e5, 0.0), waveform="cos")],
        contact=fw.ContactSpec("upper.overlap", partner="lower.top", mu=0.3),
        observed={"end": (0.090, 0.004)})


def test_first_sweep_point_is_as_robust_as_a_single_solve():
    """The first point of a sweep has no neighbour: it is solved with a single solve's
    iterations. On the lap joint its grid attempt and 40-iteration continuations failed
    (the sweep reported the point not converged) while fw.solve_periodic converged at the
    same frequency. Compared with fw.solve_periodic's answer, found by its own ladder and its
    own penalty eps: a converged DLFT balance does not depend on eps (eq. 22 holds exactly at
    convergence), so the observed amplitudes agree to the solvers' tolerance (1e-6 relative)."""
    import fretwear as fw

    model = _lap_joint()
    basis = fw.FourierBasis.up_to(3, 64)
    res = fw.sweep(model, basis, 13000.0, 13200.0, 2, time_domain=False)
    assert res.points[0].success, res.points[0].stats.message
    single = fw.solve_periodic(model, basis, 13000.0)
    assert single.success
    a_sweep = res.amplitude("end", "x")[0]
    a_single = single.observed_amplitude("end")[0, list(basis.harmonics).index(1)]
    assert abs(a_sweep - a_single) <= 1e-6 * a_single


@pytest.fixture(scope="module")
def tutorial():
    """The tutorial's lap joint and its basis (harmonics 0-3, 64 samples)."""
    from helpers.lap_joint import tutorial_joint

    return tutorial_joint(), FourierBasis.up_to(3, 64)


def test_tutorial_joint_at_its_resonance_converges_at_the_first_attempt(tutorial):
    """The tutorial's lap joint at its resonance (interface open 94 % of the period): from the
    contact-closed guess Powell stalled at a relative residual of 2e-2 in 200 iterations and
    the ladder went on to the harmonic continuation; the start from the first harmonic alone
    converges at the first attempt. Checked against the same model's sweep through the
    resonance (every point warm-started from its neighbour, recorded as a number before this
    start existed): a converged balance at one eps and one set of anchors is one point of the
    response, so the amplitudes agree to the solvers' tolerance (1e-6 relative; measured
    1e-10); and a fresh problem evaluates the residual of the answer below 1e-8."""
    from helpers.lap_joint import AMPLITUDE_AT_PEAK, F_PEAK

    import fretwear as fw

    model, basis = tutorial
    sol = fw.solve_periodic(model, basis, F_PEAK)
    assert sol.success and [a.method for a in sol.attempts] == ["start"], sol.attempts
    amp = sol.observed_amplitude("joint")[1, list(basis.harmonics).index(1)]
    assert abs(amp - AMPLITUDE_AT_PEAK) <= 1e-6 * AMPLITUDE_AT_PEAK
    red = condense(model, F_PEAK, basis.orders)
    prob = DLFTProblem(red, model.contact, basis, eps=sol.eps, anchor=sol.anchor)
    U = sol.U.reshape(prob.m, prob.H)
    f, _ = prob.residual(U, jacobian=False)
    assert np.linalg.norm(f) <= 1e-8 * prob.scale(U)


def test_first_sweep_point_of_the_tutorial_converges_at_its_grid_attempt(tutorial):
    """The first point of the tutorial's sweep (400 Hz) has no neighbour: from the
    contact-closed guess in a warm-started point's 40 iterations it stalled at a relative
    residual of 6e-2 and the point needed the eps continuation; started as a single solve
    (the first harmonic alone, 200 iterations) its grid attempt converges. Compared with
    fw.solve_periodic at the sweep's own eps (its own ladder and start): one converged
    balance, so the amplitudes agree to the solvers' tolerance (1e-6 relative)."""
    import fretwear as fw

    model, basis = tutorial
    res = fw.sweep(model, basis, 400.0, 410.0, 2, time_domain=False)
    pt = res.points[0]
    assert pt.success and [a.method for a in pt.attempts] == ["grid"], pt.attempts
    single = fw.solve_periodic(model, basis, 400.0, eps=pt.solution.eps)
    assert single.success
    a_single = single.observed_amplitude("joint")[1, list(basis.harmonics).index(1)]
    assert abs(res.amplitude("joint", "y")[0] - a_single) <= 1e-6 * a_single


def test_sweep_passes_a_fold_by_its_continuation_alone():
    """The folded frictional FRF of :func:`helpers.folded.inclined` (3 harmonics, 64
    samples, 0.60 to 0.78 rad/s on 19 points): the grid step from 0.76 to 0.77 rad/s crosses
    the fold where the upper branch (the node touching the wall) ends. The branch turns back
    short of 0.77 rad/s (:func:`fretwear.hb.arclength.fold_ahead`), so the arclength goes
    first and follows the middle branch back below 0.70 rad/s, round the lower fold and up the
    lower branch past 0.77 rad/s: the point needs no fallback (attempts ``grid``,
    ``arclength``; before, the other solver was tried first, failed at a relative residual of
    0.11 and made the point a fallback). Independent check of the point reached: on the lower
    branch the node never touches the wall (separation all period), so the balance is the
    linear response of the model with the contact open, ``(K - w^2 M + i w C) X = F``
    (1e-8 relative: the solve's tolerance; measured 1e-11)."""
    from helpers.folded import inclined

    from fretwear.hb import fallbacks
    from fretwear.hb.options import SweepOptions
    from fretwear.hb.reduce import exact_condenser
    from fretwear.hb.sweep import sweep

    model = inclined()
    res = sweep(model, FourierBasis.up_to(3, 64), 0.60 / (2 * np.pi), 0.78 / (2 * np.pi), 19,
                options=SweepOptions(spacing="linear"), condenser=exact_condenser(model))
    grid = [p for p in res.points if p.on_grid]
    assert all(p.success for p in grid)
    assert fallbacks.of_solutions(grid, res.wall_time).count == 0
    w = np.array([2 * np.pi * p.frequency_hz for p in grid])
    at = grid[int(np.argmin(np.abs(w - 0.77)))]
    assert [a.method for a in at.attempts] == ["grid", "arclength"], at.attempts
    traced = [2 * np.pi * p.frequency_hz for p in res.points if p.how == "arclength"]
    assert min(traced) < 0.70 < 0.77 < max(traced)
    assert at.solution.state_fractions()[0, 0] == 1.0  # separated all period
    K, M, C = (np.asarray(a.todense()) if hasattr(a, "todense") else np.asarray(a)
               for a in (model.K, model.M, model.C))
    wa = 2 * np.pi * at.frequency_hz
    open_x1 = abs(np.linalg.solve(K - wa**2 * M + 1j * wa * C, model.loads[0].vector)[0])
    amp = res.amplitude("x1", 0)[res.points.index(at)]
    assert abs(amp - open_x1) <= 1e-8 * open_x1


def test_halved_steps_go_on_while_the_solver_makes_progress():
    """The folded frictional model of :func:`helpers.folded.inclined` below its fold (0.60 to
    0.74 rad/s, 8 points, 3 harmonics) with one iteration a point: the grid attempts stop at
    their first iteration. The old ladder's halved steps stopped there too, and at 0.74 rad/s
    every one failed: the arclength, the other solver (a fallback), then the eps continuation
    from the last point, which landed on the lower branch (0.29 against 1.05, a jump the
    sweep did not see). The halved steps are now tried again with each step going on from its
    last iterate while the solver makes progress (:func:`fretwear.hb.attempts.
    patient_substep`, :func:`~fretwear.hb.attempts.go_on`), so every point is reached by the
    sweep's own path (no fallback). Independent check: the same grid points as the sweep
    with the default 40 iterations a point (which converges at every grid attempt), to 1e-8
    of the amplitude (the solve's relative tolerance; measured 1e-15)."""
    from helpers.folded import inclined

    from fretwear.hb import fallbacks
    from fretwear.hb.options import SWEEP_POINT, SweepOptions
    from fretwear.hb.reduce import exact_condenser
    from fretwear.hb.sweep import sweep

    model = inclined()
    basis = FourierBasis.up_to(3, 64)

    def run(max_iter):
        return sweep(model, basis, 0.60 / (2 * np.pi), 0.74 / (2 * np.pi), 8,
                     options=SweepOptions(spacing="linear",
                                          solve=SWEEP_POINT.replace(max_iter=max_iter)),
                     condenser=exact_condenser(model))

    short, ref = run(1), run(40)
    assert all([a.method for a in p.attempts] == ["grid"] for p in ref.points)
    grid = [p for p in short.points if p.on_grid]
    assert fallbacks.of_solutions(grid, short.wall_time).count == 0, [
        [a.method for a in p.attempts] for p in grid]
    assert any("substep" in [a.method for a in p.attempts] for p in grid)
    a = np.array([short.amplitude("x1", 0)[short.points.index(p)] for p in grid])
    np.testing.assert_allclose(a, ref.amplitude("x1", 0), rtol=1e-8, atol=0)


def test_turned_back_finds_the_fold_the_branch_went_round():
    """Points on a circle ``omega = 1 + 0.1 cos a`` (its frequency turns back at ``a = 0``,
    omega = 1.1) marching towards 1.2: from -40 to +30 degrees the branch went round the
    turn (the fold is the point at 0 degrees, the one farthest towards the target); up to
    0 degrees it has not turned back yet, and one that comes back past the target (an
    S-shaped branch, as the folded friction model's) or never reaches the turn has no fold
    to jump from, nor one whose last point lies back from the turn by less than 1 % of the
    way (a corrector's jitter). The same marching down (target 0.8, the circle mirrored)."""
    from fretwear.hb.attempts import turned_back

    def arc(degrees, sign=1.0):
        return [(1.0 + sign * 0.1 * np.cos(np.radians(d)), np.zeros(1)) for d in degrees]

    went_round = arc([-40, -20, 0, 15, 30])
    assert turned_back(went_round, 0, 1.2) == 2
    assert turned_back(went_round, 1, 1.2) == 2
    assert turned_back(went_round[:3], 0, 1.2) is None  # the turn is its last point
    assert turned_back(arc([-60, -40, -20]), 0, 1.2) is None  # still marching
    back_past = [*went_round, (1.25, np.zeros(1))]
    assert turned_back(back_past, 0, 1.2) is None  # reached the target after all
    assert turned_back(arc([-40, -20, 0, 15, 30], -1.0), 0, 0.8) == 2
    jitter = [*arc([-40, -20, 0]), (1.1 - 1e-6, np.zeros(1))]  # back by 4e-5 of the way
    assert turned_back(jitter, 0, 1.2) is None


def test_grid_point_after_one_that_failed_starts_as_a_branch_first_point(monkeypatch):
    """The paper's beam (salles2011-frf's model, 7 harmonics, 128 samples, the static eps) on
    16237.8, 29763.5 and 54555.9 Hz: the middle point has no periodic response (a time
    integration finds a quasi-periodic one there, docs/studies/fallbacks.md); here it is
    made to fail without a try. Its neighbour at 16237.8 Hz, three times lower, is no start
    for 54555.9 Hz (before, the grid attempt from it failed and the point needed more rungs),
    so the grid
    attempt starts as a branch's first point (the first harmonic alone) and converges
    (:func:`fretwear.hb.attempts.after_failure`). Independent check: the eps continuation
    alone (from 0.1 eps, where it converges there) from the contact-closed guess at the same
    eps and anchors (the answer the ladder reached before), to 1e-8 of the largest harmonic
    (the solves' relative tolerance; measured 5e-15)."""
    from helpers.cases import EXAMPLES

    from fretwear.analyses.run import load_case
    from fretwear.hb import attempts
    from fretwear.hb import sweep as sweep_module
    from fretwear.hb.options import SWEEP_POINT, SweepOptions
    from fretwear.hb.solvers import SolveStats
    from fretwear.io.case import build_model

    model = build_model(load_case(EXAMPLES / "salles2011-frf.toml"))
    basis = FourierBasis.up_to(7, 128)
    f_lo, f_hi = 16237.8, 54555.9
    real = attempts.point_ladder

    def ladder(p):
        if f_lo < p.frequency < f_hi:  # no periodic response here
            p.stats = SolveStats(False, float("nan"), 0, 0, 0, 0.0, "made to fail", "powell")
            return p
        return real(p)

    monkeypatch.setattr(sweep_module, "point_ladder", ladder)
    res = sweep_module.sweep(model, basis, f_lo, f_hi, 3, options=SweepOptions(eps="static"))
    grid = [p for p in res.points if p.on_grid]
    last = grid[-1]
    assert [p.success for p in grid] == [True, False, True]
    assert [a.method for a in last.attempts] == ["grid"], [a.method for a in last.attempts]
    assert "did not converge" in last.attempts[0].message
    sol = last.solution
    monkeypatch.setattr(attempts, "EPS_FACTORS", (0.1,))  # the one that converges there
    ref = solve_periodic(model, basis, frequency=f_hi, eps=sol.eps, anchor=sol.anchor,
                         options=SWEEP_POINT.replace(strategy=("eps-continuation",)))
    assert ref.success
    assert np.abs(sol.U - ref.U).max() <= 1e-8 * np.abs(ref.U).max()
