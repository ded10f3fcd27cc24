"""Tests of the wear rate averaged over a time integration (fretwear.timedomain.averaged_rate),
the call the wear driver makes of it (fretwear.timedomain.fallback), and of the time-domain
steps of the slow-scale driver (fretwear.wear.simulate, fretwear.wear.time_steps).

References, each independent of the code under test:

* the DLFT wear rate (eq. 29 on the converged harmonic balance, :mod:`fretwear.wear.kernels`),
  a different method (frequency domain, truncated to a few harmonics) for the same periodic
  response: the two agree to the truncation error of the balance;
* Coulomb's law in the time integrator: in slip the tangential force is mu times the normal
  force along the slip, so the friction energy per cycle (computed from lambda_T . dx) is mu
  times the slip work (computed from lambda_N |dx|) up to the contact solver's tolerance;
* contact states of the time integration: a node that sticks over the whole window has no slip
  step and must not wear, to the last bit;
* an uninterrupted run for interrupt-and-resume of a run that takes time-domain steps (bitwise).
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers.wear_checkpoints import assert_format_3_is_refused

import fretwear.wear.schemes as wear_schemes  # the first balance calls its solve_periodic
import fretwear.wear.simulate as wear_driver  # the driver calls its advance (balanced steps)
from fretwear import simulate_wear  # the public driver: time-domain fallback on
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.reduce import condense
from fretwear.hb.solution import initial_state
from fretwear.model.build import ContactSpec, Damping, Material, Spring, Traction, from_mesh
from fretwear.model.mesh import rectangle
from fretwear.timedomain.averaged_rate import RESPONSE_KINDS, time_averaged_rate
from fretwear.timedomain.options import AveragingOptions
from fretwear.wear import (
    Rescue,
    RunControl,
    SlowProblem,
    WearOptions,
    wear_coefficients,
    without_growth,
)
from fretwear.wear.options import START_JUMP, START_SETTLE

KW = 1e-11
MU = 0.3
F_HZ = 2e3  # [Hz] well below the block's first resonance (~60 kHz): mild dynamics


def damped_block(q_ratio=0.5):
    """Steel block 20 x 4 mm (10 x 2 Q4) on a rigid flat, spring 1e5 N/m in x at the
    bottom-left node, 1 MPa on top, sinusoidal end pressure worth ``q_ratio`` of the friction
    capacity; Rayleigh damping (2 % at 60 kHz) so that the time integration settles."""
    q = q_ratio * 1e6 * MU * 0.02 / 0.004
    return from_mesh(rectangle(0.02, 0.004, 10, 2), Material(210e9, 0.3, 7800), thickness=0.01,
                     damping=Damping(rayleigh_stiffness=0.04 / (2 * np.pi * 6e4)),
                     supports=[Spring("bottom_left", "x", 1e5)],
                     loads=[Traction("top", pressure=1e6),
                            Traction("right", pressure=q, waveform="sin")],
                     contact=ContactSpec("bottom", mu=MU, normal=(0, -1), wear_coefficient=KW),
                     observed={"Pe": (0.02, 0.002)})


@pytest.fixture(scope="module")
def periodic():
    """The DLFT periodic solution of the damped block (15 harmonics, 256 samples) and the
    time-averaged rate started from it (1024 steps per period: stick-slip events are first
    order in the step; with 256 steps the worn volume differs by 5.4 %, with 1024 by 0.8 %)."""
    m = damped_block()
    basis = FourierBasis.up_to(15, 256)
    sol = solve_periodic(m, basis, frequency=F_HZ, options=SolveOptions(tol=1e-10))
    st = sol.stats
    assert st.success
    coef = wear_coefficients(m)
    U0, V0 = initial_state(m, sol)
    tr = time_averaged_rate(m, F_HZ, basis, coef, np.zeros(len(coef)), U0=U0, V0=V0,
                            options=AveragingOptions(settle=200, average=100,
                                                     steps_per_period=1024))
    return m, basis, sol, coef, tr


def test_time_average_matches_the_dlft_rate(periodic):
    """Same periodic response by two methods: the worn-volume rate and the profile of the
    time average agree with the DLFT's (eq. 29). Measured gaps: worn volume 0.83 %, largest node
    difference 0.42 % of the largest rate, harmonics 0.38 % of the largest amplitude (HBM
    truncation and the time step); tolerances are about twice these."""
    m, basis, sol, coef, tr = periodic
    area = m.contact.area
    red = condense(m, F_HZ, basis.orders)
    sp = SlowProblem(m, red, basis, coef, eps=sol.eps, anchor=sol.anchor)
    sp.set_state(np.zeros(len(coef)), sol.anchor)
    g_hb = sp.rate(sol.U.reshape(sp.m, sp.H))
    assert tr.kind == "periodic"
    assert g_hb.max() > 0 and np.count_nonzero(g_hb) < g_hb.size  # partial slip
    assert area @ tr.g == pytest.approx(area @ g_hb, rel=0.017)
    assert np.abs(tr.g - g_hb).max() <= 0.01 * g_hb.max()
    # the harmonics of the last period are those of the balance (truncation-level gap)
    amp = np.abs(sol.U[:, :, 1:]).max()
    assert np.abs(tr.U[:, :, 1:] - sol.U[:, :, 1:]).max() <= 0.008 * amp


def test_friction_energy_is_mu_times_slip_work(periodic):
    """Coulomb slip in the time integrator: friction energy = mu x slip work per node, to the
    contact solver's relative tolerance (1e-10), well inside 1e-7."""
    *_, tr = periodic
    assert tr.friction_energy.max() > 0
    np.testing.assert_allclose(tr.friction_energy, MU * tr.slip_work,
                               atol=1e-7 * tr.friction_energy.max())


def test_sticking_nodes_do_not_wear_in_time(periodic):
    """Nodes that stick over the whole averaging window have exactly zero wear rate, and every
    node with a non-zero rate slipped during the window."""
    *_, tr = periodic
    stuck = tr.state_fraction[:, 2] == 0.0
    assert stuck.any() and (~stuck).any()
    assert np.all(tr.g[stuck] == 0.0)
    assert np.all(tr.g[~stuck] >= 0.0)


def test_rate_scatter_is_the_difference_of_the_two_half_windows():
    """The scatter of a time-averaged rate against the worn-volume rates of the two halves of
    its window computed by two separate, consecutive integrations (the second continues the
    first exactly from its end state). Started from rest, the response is still settling, so
    the halves differ (scatter 0.83). The separate second window cannot count the one step
    that straddles the two calls (1 of 4096): measured gap 1.7e-5, tolerance 1e-4."""
    m = damped_block()
    coef = wear_coefficients(m)
    area = m.contact.area
    W = np.zeros(len(coef))
    kw = dict(settle=0, steps_per_period=256)
    full = time_averaged_rate(m, F_HZ, BASIS, coef, W, U0=None, V0=None,
                              options=AveragingOptions(average=32, **kw))
    first = time_averaged_rate(m, F_HZ, BASIS, coef, W, U0=None, V0=None,
                               options=AveragingOptions(average=16, **kw))
    second = time_averaged_rate(m, F_HZ, BASIS, coef, W, U0=first.U_end, V0=first.V_end,
                                options=AveragingOptions(average=16, **kw))
    v1, v2 = area @ first.g, area @ second.g
    expected = abs(v1 - v2) / (v1 + v2)
    assert expected > 0.05  # the check is not trivial: the halves differ
    assert full.scatter == pytest.approx(expected, abs=1e-4)


def test_fallback_call_is_the_averaged_rate_with_its_options():
    """The fallback the wear driver calls takes the averaging settings as keywords (the wear
    package cannot import the time-domain records): the same rate, bit for bit, as
    time_averaged_rate with the AveragingOptions of those keywords; an unknown keyword is
    refused."""
    from fretwear.timedomain.fallback import FALLBACK

    m = damped_block()
    coef = wear_coefficients(m)
    W = np.zeros(len(coef))
    a = FALLBACK.averaged_rate(m, F_HZ, BASIS, coef, W, U0=None, V0=None, settle=2, average=3,
                               steps_per_period=64)
    b = time_averaged_rate(m, F_HZ, BASIS, coef, W, U0=None, V0=None,
                           options=AveragingOptions(settle=2, average=3, steps_per_period=64))
    assert a.periods == 5
    for name in ("g", "slip_work", "U", "lam", "U_end", "V_end"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    with pytest.raises(TypeError, match="settling"):
        FALLBACK.averaged_rate(m, F_HZ, BASIS, coef, W, U0=None, V0=None, settling=2)


def test_bad_window_is_refused():
    with pytest.raises(Exception, match="time_domain_average"):
        WearOptions(time_domain_average=1).check()


# --- the slow-scale driver: steps from time integrations -------------------------------------
def _forced_failures(monkeypatch, balance_fails: bool, first_ok: bool = True):
    """Every ordinary step fails after the first (every one without ``first_ok``); with
    ``balance_fails`` the balances of the time-domain steps fail too (the DLFT has no solution
    there), so their rates are averaged."""
    monkeypatch.undo()
    real_advance = wear_driver.advance
    calls = {"n": 0 if first_ok else 2}

    def advance(sp, st, opts):
        calls["n"] += 1
        if calls["n"] > 1:
            return None, None, "forced failure"
        return real_advance(sp, st, opts)

    monkeypatch.setattr(wear_driver, "advance", advance)
    if balance_fails:
        real_solve = SlowProblem.solve_balance

        def solve_balance(self, W, anchor, U0, **kw):
            U, stats = real_solve(self, W, anchor, U0, **kw)
            if calls["n"] > 1:
                stats.success = False
            return U, stats

        monkeypatch.setattr(SlowProblem, "solve_balance", solve_balance)


OPTS = dict(max_steps=4, tolerance=0.05, time_domain_settle=100, time_domain_average=64,
            time_domain_steps=512)
BASIS = FourierBasis.up_to(3, 32)


def test_time_domain_steps_return_to_balanced_solutions(monkeypatch):
    """A failed balance is followed by a step from a time integration; the response there is
    periodic, so the balance is restarted from its harmonics: the steps are converged balances
    (residual re-evaluated at the recorded U, W and anchors: below the solver tolerance)."""
    m = damped_block()
    _forced_failures(monkeypatch, balance_fails=False)
    r = simulate_wear(m, BASIS, frequency=F_HZ, options=WearOptions(**OPTS))
    h = r.history
    assert r.success and h.n_steps == 5
    np.testing.assert_array_equal(h.rescued[:2], [Rescue.BALANCED] * 2)
    assert np.all(h.rescued[2:] == Rescue.TIME_START)
    assert np.all(h.response[2:] == RESPONSE_KINDS.index("periodic"))
    red = condense(m, F_HZ, BASIS.orders)
    spb = SlowProblem(m, red, BASIS, wear_coefficients(m), eps=r.penalty)
    for k in range(2, 5):
        spb.set_state(h.wear_depth[k], h.anchor[k])
        U = h.U[k].reshape(spb.m, spb.H)
        f, _ = spb.balance(U, False)
        assert np.linalg.norm(f) <= 1e-9 * spb.prob.scale(U)


@pytest.mark.parametrize("scheme", ["explicit", "rosenbrock"])
def test_time_averaged_steps_follow_the_time_integration(monkeypatch, tmp_path, scheme):
    """With no balance at all after step 1, the run goes on with time-averaged rates
    (rescued = Rescue.TIME_AVERAGED). Each step's wear is the explicit Euler update (eq. 30)
    with the previous step's rate, or the linearly implicit one with the slow Jacobian of the
    last balanced step (recomputed here from the recorded step 1) without its growing modes.
    Interrupting after step 3 and resuming gives the same history bit for bit (the
    integration state is in the checkpoint); the same state in format 3 (its earlier names,
    written by the format-3 writer kept in tests/helpers, with no content checksum) is
    refused, never resumed."""
    m = damped_block()
    _forced_failures(monkeypatch, balance_fails=True)
    opts = WearOptions(scheme=scheme, **OPTS)
    full = simulate_wear(m, BASIS, frequency=F_HZ, options=opts)
    h = full.history
    assert full.success and h.n_steps == 5
    assert np.all(h.rescued[2:] == Rescue.TIME_AVERAGED)
    # the uncertainty of the averaged rates is recorded; balanced rates are exact (NaN)
    assert np.all(np.isnan(h.rate_scatter[:2]))
    assert np.all((h.rate_scatter[2:] >= 0) & (h.rate_scatter[2:] < 1))
    Js = np.zeros((h.wear_depth.shape[1],) * 2)
    if scheme == "rosenbrock":
        red = condense(m, F_HZ, BASIS.orders)
        spb = SlowProblem(m, red, BASIS, wear_coefficients(m), eps=full.penalty)
        spb.set_state(h.wear_depth[1], h.anchor[1])
        Js = spb.slow_jacobian(h.U[1].reshape(spb.m, spb.H))
    eye = np.eye(Js.shape[0])
    Js = without_growth(Js)  # checked in tests/wear/test_time_steps.py
    for k in range(2, 5):
        dN = h.jump[k]
        dW = np.maximum(dN * np.linalg.solve(eye - dN * Js, h.wear_rate[k - 1]), 0.0)
        np.testing.assert_allclose(h.wear_depth[k], h.wear_depth[k - 1] + dW, rtol=1e-9,
                                   atol=1e-12 * h.wear_depth[k].max())
    assert full.final is not None  # the last balanced step
    # resume
    _forced_failures(monkeypatch, balance_fails=True)
    ck = tmp_path / "wear.npz"

    def stop(step, row):
        if step == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        simulate_wear(m, BASIS, frequency=F_HZ, options=opts,
                      run=RunControl(checkpoint=ck, callback=stop))
    saved = ck.read_bytes()
    _forced_failures(monkeypatch, balance_fails=True, first_ok=False)
    resumed = simulate_wear(m, BASIS, frequency=F_HZ, options=opts,
                            run=RunControl(checkpoint=ck, resume=True))
    assert resumed.resumed_from == 3
    for name in ("cycles", "wear_depth", "wear_rate", "U", "rescued", "rate_scatter"):
        np.testing.assert_array_equal(getattr(h, name), getattr(resumed.history, name),
                                      err_msg=name)
    ck.write_bytes(saved)
    assert_format_3_is_refused(ck)


def test_run_starts_from_a_time_integration_when_the_unworn_balance_fails(monkeypatch):
    """No balance of the unworn interface (forced): step 0 is the time-averaged rate of the
    response integrated from rest, which equals what time_averaged_rate gives from rest with
    the same windows (bitwise: same integration), and the run goes on (here back to balanced
    steps, the response being periodic)."""
    import fretwear.hb.periodic

    m = damped_block()
    real = wear_schemes.solve_periodic

    def failing(*args, **kwargs):
        sol = real(*args, **kwargs)
        sol.stats.success = False
        return sol

    monkeypatch.setattr(wear_schemes, "solve_periodic", failing)
    opts = WearOptions(**OPTS)
    r = simulate_wear(m, BASIS, frequency=F_HZ, options=opts)
    h = r.history
    assert r.success and h.n_steps == 5 and h.rescued[0] == Rescue.TIME_AVERAGED
    ref = time_averaged_rate(m, F_HZ, BASIS, wear_coefficients(m), np.zeros(h.wear_depth.shape[1]),
                             U0=None, V0=None,
                             options=AveragingOptions(settle=START_SETTLE, average=64,
                                                      steps_per_period=512))
    np.testing.assert_array_equal(h.wear_rate[0], ref.g)
    assert h.jump[1] == START_JUMP
    # the response is periodic: the balance converges from it at step 1, then ordinary steps
    assert h.rescued[1] == Rescue.TIME_START and np.all(h.rescued[2:] == Rescue.BALANCED)
    # only the wear module's start was forced
    assert fretwear.hb.periodic.solve_periodic is not failing
