"""Tests of fretting wear on the slow scale through its driver (:mod:`fretwear.wear.simulate`:
simulate_wear, with its rates, derivatives, stops and checkpoints). The tests of the wear laws,
the slow-step schemes and the worn FRF are in tests/wear/test_laws.py, test_schemes.py and
test_worn_frf.py.

References, each independent of the code under test:

* the post-processed Archard rate of eq. 29 (pressure_t x slip_t), a separate code path from
  the integrators' kernel;
* contact states of the DLFT (:mod:`fretwear.hb.contact`): a node that sticks all period must
  not wear, to the last bit;
* finite differences for every derivative of the implicit scheme;
* an uninterrupted run for interrupt-and-resume (bitwise);
* statics of the mean state of the paper's beam: mean contact forces = preload, resultant at
  L/2.

Models are small (a 10 x 2 block, 3 harmonics, 32 samples, quasi-static; the statics test
takes three slow steps of the paper's 30 x 4 beam) so that the file runs in well under a
minute.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers.wear_block import BASIS, KW, block

from fretwear.hb import contact as law
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.solvers import solve_identity_rows
from fretwear.wear import (
    BalanceSetup,
    RunControl,
    SlowProblem,
    WearOptions,
    read_history,
    simulate_wear,
    wear_coefficients,
    wear_per_cycle,
)
from fretwear.wear.kernels import slip_work, slip_work_gradient


# --- wear rates ---------------------------------------------------------------------------------
def test_kernel_matches_post_processing(blk, sol_block):
    """The integrators' kernel (slip work on lambda_u, lambda_x) gives the post-processed
    Archard rate of eq. 29 (pressure_t x slip_t): two code paths, rounding only (1e-12)."""
    m, red, anc = blk
    spb = SlowProblem(m, red, BASIS, wear_coefficients(m), anchor=anc)
    U = sol_block.U.reshape(spb.m, spb.H)
    np.testing.assert_allclose(spb.rate(U), wear_per_cycle(sol_block, wear_coefficient=KW),
                               rtol=1e-12, atol=1e-30)


def test_sticking_nodes_do_not_wear(blk, sol_block):
    """Partial slip: nodes whose DLFT state is stick for the whole period wear exactly 0, at
    the start and after a wear run; a node that wears has slipped at some step."""
    sol = sol_block
    dw = wear_per_cycle(sol, wear_coefficient=KW)
    stuck = np.all(sol.state == law.STICK, axis=1)
    assert stuck.sum() >= 4 and (~stuck).sum() >= 3  # really partial slip
    assert np.all(dw[stuck] == 0.0)
    m, red, anc = blk
    r = simulate_wear(m, BASIS, quasi_static=True, balance=BalanceSetup(reduced=red, anchor=anc),
                      options=WearOptions(max_cycles=3e5, tolerance=0.05))
    h = r.history
    never = np.all(h.state_fraction[:, :, law.STICK] == 1.0, axis=0)
    assert never.sum() >= 3
    assert np.all(h.wear_depth[-1, never] == 0.0)
    worn = h.wear_depth[-1] > 0
    assert worn.sum() >= 4 and np.all(h.slip_path.max(axis=0)[worn] > 0)


# --- derivatives ------------------------------------------------------------------------------
def _fd(fun, x, h):
    return (fun(x + h) - fun(x - h)) / (2 * h)


def test_slip_work_gradient_vs_finite_differences(blk, sol_block):
    """dS/d lambda_u~ of the kernel (recursion of contact.dlft_jacobian, wrap-around seed)
    against central differences through the periodic DLFT law. S is piecewise smooth; a step of
    1e-7 of max |lambda_u~| changes no contact state here, so FD is exact up to the periodicity
    tolerance and rounding: 1e-6 relative."""
    m, red, anc = blk
    spb = SlowProblem(m, red, BASIS, wear_coefficients(m), anchor=anc)
    p = spb.prob
    Lu = p.lambda_u(sol_block.U.reshape(spb.m, spb.H))
    nc, d, H = spb.nc, spb.d, spb.H

    def S_of(L):
        t = np.ascontiguousarray(BASIS.to_time(L).reshape(nc, d, -1))
        lx, st, _ = law.dlft_time(t, p.mu, p.eps * p.anchor, 1e-14, 1000)
        return slip_work(t, lx, st, p.eps)

    t = np.ascontiguousarray(BASIS.to_time(Lu).reshape(nc, d, -1))
    lx, st, _ = law.dlft_time(t, p.mu, p.eps * p.anchor, 1e-14, 1000)
    S, dS = slip_work_gradient(t, lx, st, p.mu, p.Q, p.eps)
    np.testing.assert_allclose(S, S_of(Lu), rtol=1e-13)
    h = 1e-7 * np.abs(Lu).max()
    checked = 0
    for q in np.flatnonzero(S > 0):
        fd = np.zeros(d * H)
        for c in range(d):
            for k in range(H):
                E = np.zeros_like(Lu)
                E[q * d + c, k] = 1.0
                fd[c * H + k] = _fd(lambda s, E=E, q=q: S_of(Lu + s * E)[q], 0.0, h)
        np.testing.assert_allclose(dS[q], fd, rtol=0, atol=1e-6 * np.abs(fd).max())
        checked += 1
    assert checked >= 3


def test_coupled_jacobian_vs_finite_differences(blk, sol_block):
    """Every block of the backward Euler Jacobian [[J, df/dW], [-eps dN dg/dU, eps (I - dN
    dg/dW)]] against central differences of the coupled residual, at a worn state. FD steps
    1e-7 (U) / 1e-6 (W) relative: truncation and rounding ~1e-6 of each block's largest entry.
    A column whose +-h evaluations change a contact state sits on a kink of the piecewise
    smooth residual, where no derivative exists: those (at most 2 of 165) are skipped."""
    m, red, anc = blk
    spb = SlowProblem(m, red, BASIS, wear_coefficients(m), anchor=anc)
    U0 = sol_block.U.reshape(spb.m, spb.H)
    g = spb.rate(U0)
    W = 3e4 * g
    U, st = spb.solve_balance(W, anc, spb.shift_guess(U0, W),
                              options=SolveOptions(tol=1e-12, max_iter=100))
    assert st.success
    dN, Wk = 1e5, 0.9 * W
    x = np.concatenate([U.ravel(), W])
    R, J = spb.coupled(x, Wk, dN)
    n = spb.n

    def states(y):
        spb.prob.set_gap(spb.gap0 + y[n:])
        return spb.prob.time_law(y[:n].reshape(spb.m, spb.H))[2]

    Jfd = np.full_like(J, np.nan)
    uscale = np.abs(x[:n]).max()
    for j in range(x.size):
        h = 1e-7 * uscale if j < n else 1e-6 * W.max()
        E = np.zeros_like(x)
        E[j] = h
        if not np.array_equal(states(x + E), states(x - E)):
            continue
        Jfd[:, j] = (spb.coupled(x + E, Wk, dN, False)[0]
                     - spb.coupled(x - E, Wk, dN, False)[0]) / (2 * h)
    ok = ~np.isnan(Jfd[0])
    assert (~ok).sum() <= 2
    for rows in (slice(0, n), slice(n, None)):
        for cols in (slice(0, n), slice(n, None)):
            a, b = J[rows, cols][:, ok[cols]], Jfd[rows, cols][:, ok[cols]]
            scale = max(np.abs(b).max(), 1e-300)
            assert np.abs(a - b).max() <= 2e-6 * scale


def test_slow_jacobian_vs_finite_differences(blk, sol_block):
    """The total dg/dW along the balanced solution (implicit function theorem) against central
    differences of g(W) with the balance re-solved: 1e-4 relative (solves to 1e-13, steps of
    1e-3 of the local wear, no change of contact state)."""
    m, red, anc = blk
    spb = SlowProblem(m, red, BASIS, wear_coefficients(m), anchor=anc)
    U0 = sol_block.U.reshape(spb.m, spb.H)
    W = 3e4 * spb.rate(U0)
    U, _ = spb.solve_balance(W, anc, spb.shift_guess(U0, W),
                             options=SolveOptions(tol=1e-13, max_iter=100))
    spb.set_state(W, anc)
    Js = spb.slow_jacobian(U)
    h = 1e-3 * W.max()
    for q in np.flatnonzero(W > 0.05 * W.max()):
        def g_of(s, q=q):
            Wq = W.copy()
            Wq[q] += s
            Uq, st = spb.solve_balance(Wq, anc, U, options=SolveOptions(tol=1e-13, max_iter=100))
            assert st.success
            return spb.rate(Uq)
        fd = _fd(g_of, 0.0, h)
        np.testing.assert_allclose(Js[:, q], fd, rtol=0, atol=1e-4 * np.abs(fd).max())


def test_identity_row_elimination_is_exact():
    """solve_identity_rows against a dense solve: rounding only."""
    rng = np.random.default_rng(0)
    J = rng.random((40, 40)) + 40 * np.eye(40)
    J[5:15] = 0.0
    J[5:15, 5:15] = 3e9 * np.eye(10)
    B = rng.random((40, 3))
    np.testing.assert_allclose(solve_identity_rows(J, B), np.linalg.solve(J, B), rtol=1e-10)


# --- slow-scale integrators ---------------------------------------------------------------------
def test_plateau_stop_and_history(blk):
    """The run stops at the plateau (worn-volume rate below plateau_rate x the initial one),
    the history is consistent (cycles = cumulative jumps, worn volume = area . W) and every
    recorded step is a converged balance."""
    m, red, anc = blk
    r = simulate_wear(m, BASIS, quasi_static=True, balance=BalanceSetup(reduced=red, anchor=anc),
                      options=WearOptions(tolerance=0.05, plateau_rate=0.05))
    h = r.history
    assert r.stop_reason == "plateau" and r.success and h.stop_reason == "plateau"
    assert h.volume_rate[-1] <= 0.05 * h.volume_rate[0]
    np.testing.assert_allclose(h.cycles, np.cumsum(h.jump), rtol=1e-12)
    np.testing.assert_allclose(h.worn_volume, h.wear_depth @ m.contact.area, rtol=1e-12)
    assert np.all(np.diff(h.wear_depth, axis=0) >= 0)
    np.testing.assert_allclose(h.state_fraction.sum(axis=2), 1.0)


def test_failed_solve_stops_cleanly(blk, monkeypatch):
    """A balance that never converges after step 2: the run stops with "solver_failed", says
    so, and keeps the converged steps only."""
    m, red, anc = blk
    real = SlowProblem.solve_balance  # the class the driver's slow steps call
    calls = {"n": 0}

    def flaky(self, *a, **k):
        U, st = real(self, *a, **k)
        calls["n"] += 1
        if calls["n"] > 3:
            st.success = False
            st.message = "forced failure"
        return U, st

    monkeypatch.setattr(SlowProblem, "solve_balance", flaky)
    r = simulate_wear(m, BASIS, quasi_static=True, balance=BalanceSetup(reduced=red, anchor=anc),
                      options=WearOptions(scheme="explicit", max_retries=2))
    assert r.stop_reason == "solver_failed" and not r.success
    assert "forced failure" in r.message
    assert 1 <= r.history.n_steps <= 4


def test_non_finite_step_stops_the_run_naming_the_column(blk, monkeypatch):
    """A step whose wear rate comes out NaN (as an overflowing law would give) is a failure
    naming the column, and no non-finite value reaches the history; without the check the
    NaN rate was recorded and the run went on (the reference: the issue's silent accepts)."""
    import dataclasses

    import fretwear.wear.simulate as simulate

    m, red, anc = blk
    real = simulate.advance
    calls = {"n": 0}

    def poisoned(sp, state, opts):
        new_state, record, failure = real(sp, state, opts)
        calls["n"] += 1
        if calls["n"] == 2 and not failure:
            record = dataclasses.replace(record, wear_rate=np.full_like(record.wear_rate,
                                                                        np.nan))
        return new_state, record, failure

    monkeypatch.setattr(simulate, "advance", poisoned)
    r = simulate_wear(m, BASIS, quasi_static=True, balance=BalanceSetup(reduced=red, anchor=anc),
                      options=WearOptions(tolerance=0.05, max_steps=4))
    assert r.stop_reason == "solver_failed" and not r.success
    assert "non-finite values (NaN or inf) in wear_rate" in r.message
    assert r.history.n_steps == 2  # the initial state and the first step
    assert np.all(np.isfinite(r.history.wear_rate))


# --- checkpoints ------------------------------------------------------------------------------
@pytest.mark.parametrize("every", [0.0, 1e9])
def test_interrupt_and_resume_equals_uninterrupted(blk, tmp_path, every):
    """Ctrl-C after 3 steps (KeyboardInterrupt from the callback), then resume from the
    checkpoint: the history equals the uninterrupted run's bit for bit (wall times aside).
    With every = 1e9 s the checkpoint is only written by the interrupt handler."""
    m, red, anc = blk
    opts = WearOptions(max_cycles=1e6, tolerance=0.02, checkpoint_every_s=every)
    bal = BalanceSetup(reduced=red, anchor=anc)
    full = simulate_wear(m, BASIS, quasi_static=True, balance=bal, options=opts)
    ck = tmp_path / "wear.npz"

    def stop(step, row):
        if step == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        simulate_wear(m, BASIS, quasi_static=True, balance=bal, options=opts,
                      run=RunControl(checkpoint=ck, callback=stop))
    assert ck.is_file() and not list(tmp_path.glob(".*tmp"))
    resumed = simulate_wear(m, BASIS, quasi_static=True, balance=bal, options=opts,
                            run=RunControl(checkpoint=ck, resume=True))
    assert resumed.resumed_from == 3
    a, b = full.history, resumed.history
    assert a.n_steps == b.n_steps > 4 and a.stop_reason == b.stop_reason
    for name in ("cycles", "jump", "wear_depth", "wear_rate", "pressure_max", "slip_path",
                 "worn_volume", "U", "lam", "newton_iterations"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


def test_resume_extends_a_finished_run(blk, tmp_path):
    """A finished run resumed with a larger max_cycles continues from its last step (the
    stop criteria are not part of the checkpoint fingerprint)."""
    m, red, anc = blk
    ck = tmp_path / "wear.npz"
    bal, resume = BalanceSetup(reduced=red, anchor=anc), RunControl(checkpoint=ck, resume=True)
    a = simulate_wear(m, BASIS, quasi_static=True, balance=bal, run=RunControl(checkpoint=ck),
                      options=WearOptions(max_cycles=2e5))
    b = simulate_wear(m, BASIS, quasi_static=True, balance=bal, run=resume,
                      options=WearOptions(max_cycles=6e5))
    n = a.history.n_steps
    assert b.resumed_from == n - 1 and b.history.cycles[-1] == pytest.approx(6e5)
    np.testing.assert_array_equal(b.history.wear_depth[:n], a.history.wear_depth)
    # the checkpoint's history, read without the case's fingerprint, is the run's history
    h = read_history(ck)
    for name in ("cycles", "wear_depth", "pressure_mean", "volume_rate", "wall_time"):
        np.testing.assert_array_equal(getattr(h, name), getattr(b.history, name))
    # a checkpoint with a column taken out (as those written before rate_scatter was
    # recorded, with no content checksum) is refused, not read with that column made up
    from fretwear.errors import InputError

    with np.load(ck) as z:
        old = {k: z[k] for k in z.files if k != "hist_rate_scatter"}
    np.savez(ck, **old)
    with pytest.raises(InputError, match="does not match its checksum"):
        read_history(ck)
    with pytest.raises(InputError, match="does not match its checksum"):
        simulate_wear(m, BASIS, quasi_static=True, balance=bal, run=resume,
                      options=WearOptions(max_cycles=8e5))


def test_resume_refuses_other_settings(blk, tmp_path):
    """A checkpoint written with other settings is not silently continued."""
    from fretwear.errors import InputError

    m, red, anc = blk
    ck = tmp_path / "wear.npz"
    bal = BalanceSetup(reduced=red, anchor=anc)
    simulate_wear(m, BASIS, quasi_static=True, balance=bal, run=RunControl(checkpoint=ck),
                  options=WearOptions(max_cycles=1e4))
    with pytest.raises(InputError, match="different"):
        simulate_wear(m, BASIS, quasi_static=True, balance=bal,
                      run=RunControl(checkpoint=ck, resume=True),
                      options=WearOptions(max_cycles=1e4, tolerance=0.3))


# --- the case-file analysis -------------------------------------------------------------------
def test_no_wear_without_slip(tmp_path):
    """A fully stuck interface: zero rate at the start, stop reason "no_wear" at once."""
    m = block(q_ratio=0.01)
    r = simulate_wear(m, BASIS, quasi_static=True)
    assert r.stop_reason == "no_wear" and r.history.n_steps == 1
    assert np.all(r.final_wear == 0.0) and math.isfinite(r.wall_time)


def test_no_wear_names_the_zero_coefficient_not_the_slip():
    """The same block in partial slip (q_ratio 0.5, where the other tests see nodes slip) with
    every Archard coefficient 0: the rate is 0 because nothing CAN wear, so the stop message
    (of the march and of the direct worn state) names the coefficient, not the slip; with a
    fully stuck block and k_w > 0 it still names the slip."""
    from fretwear.wear.worn_state import worn_state

    m = block(q_ratio=0.5, wear_coefficient=0.0)
    r = simulate_wear(m, BASIS, quasi_static=True)
    assert r.stop_reason == "no_wear" and "every wear coefficient is 0" in r.message
    assert "slips" not in r.message
    ws = worn_state(m, BASIS, quasi_static=True)
    assert ws.kind == "no_wear" and "every wear coefficient is 0" in ws.message
    stuck = simulate_wear(block(q_ratio=0.01), BASIS, quasi_static=True)
    assert "no contact node slips" in stuck.message


def test_no_wear_under_the_energy_law_names_its_coefficient():
    """The block of :func:`test_no_wear_names_the_zero_coefficient_not_the_slip` under the
    energy law with ``k_e = 0`` (and k_w > 0, which that law does not use): the stop message
    names what sets that law's factors (``energy_coefficient``, ``mu``), not the Archard
    ``wear_coefficient``."""
    r = simulate_wear(block(q_ratio=0.5), BASIS, quasi_static=True,
                      options=WearOptions(law="energy", energy_coefficient=0.0))
    assert r.stop_reason == "no_wear" and "every wear coefficient is 0" in r.message
    assert "energy_coefficient" in r.message and "wear_coefficient)" not in r.message


def test_dynamic_run_needs_a_frequency(monkeypatch):
    """A dynamic wear run without ``frequency`` (which used to default to 1 Hz) is refused in
    one line naming it, before anything is computed, at both entry points; settings records of
    the wrong kind are refused by name."""
    import fretwear
    import fretwear.wear.simulate as driver
    from fretwear.errors import InputError

    def no_condensation(*args, **kwargs):
        raise AssertionError("condensed before the check")

    monkeypatch.setattr(driver, "condense", no_condensation)
    m = block()
    for func in (simulate_wear, fretwear.simulate_wear):
        with pytest.raises(InputError, match="frequency = None") as err:
            func(m, BASIS, options=WearOptions(max_steps=1))
        assert "\n" not in str(err.value) and "quasi_static" in str(err.value)
    for name, value in (("balance", {"eps": 1e9}), ("run", {"resume": True})):
        with pytest.raises(TypeError, match=f"{name} = .*: expected a"):
            simulate_wear(m, BASIS, quasi_static=True, **{name: value})


def test_progress_bar_shows_cycles_volume_rate_and_time_left(blk, capsys):
    """The progress bar (stderr) names the cycles reached, the worn volume, the worn-volume
    rate and the time left; its worn volume is the history's (area . W)."""
    m, red, anc = blk
    r = simulate_wear(m, BASIS, quasi_static=True, balance=BalanceSetup(reduced=red, anchor=anc),
                      run=RunControl(progress=True),
                      options=WearOptions(max_steps=3, tolerance=0.05))
    err = capsys.readouterr().err
    assert "cycles" in err and "m^3/cycle" in err and "<" in err  # tqdm's [elapsed<left]
    assert f"worn {r.history.worn_volume[-1]:.3g} m^3" in err


def test_mean_normal_force_balances_the_preload_on_the_paper_beam():
    """Equilibrium of the mean (zeroth-harmonic) state of the paper's beam at 10 kHz along a
    short wear history: the mean normal contact forces add up to the preload ``P L l`` and
    their resultant acts at ``x = L/2``, where the uniform ``P`` acts. Friction and the
    x-spring act on the contact line ``y = 0`` and ``Q`` has zero mean, so neither moves the
    resultant: a statics check independent of the solver, at every step (worn or not). The
    tolerance (1e-6) is far above the balance residual (``tol = 1e-9``; measured deviations
    are at round-off) and far below what a wrong static part, area or pressure would give
    (one node's load misplaced by one element moves the resultant by ~1e-3 L)."""
    from fretwear.examples.builders import paper_beam

    m = paper_beam()
    basis = FourierBasis.up_to(3, 32)
    r = simulate_wear(m, basis, frequency=10e3,
                      options=WearOptions(max_steps=3, time_domain_rescue=False))
    h = r.history
    area = np.asarray(m.contact.area, float)
    x = np.asarray(m.contact.coords, float)[:, 0]
    L, P, width = 0.1, 1e4, 0.01
    assert r.success and h.n_steps == 4 and h.wear_depth[-1].max() > 0
    for p in h.pressure_mean:
        force = float(area @ p)
        np.testing.assert_allclose(force, P * L * width, rtol=1e-6)
        np.testing.assert_allclose(float((area * p) @ x) / force, L / 2, rtol=1e-6)


def test_wear_bar_counts_steps_not_log_cycles():
    """The bar's fraction is in slow steps: with jumps doubling from 1 cycle, 3 steps are left
    to 7 more cycles (1 + 2 + 4, by hand), so after 3 steps the bar is at 3 / 6; with
    constant jumps it is steps / (steps + cycles left / jump). The old measure,
    log(1 + cycles) / log(1 + max_cycles), said 0.81 here whatever the steps left."""
    from types import SimpleNamespace

    from fretwear.wear.simulate import _progress_fraction, steps_left

    assert steps_left(9.0, 1.0, 2.0, 16.0) == pytest.approx(3.0, rel=1e-12)
    assert steps_left(10.0, 2.0, 1.0, 16.0) == pytest.approx(3.0, rel=1e-12)
    assert steps_left(16.0, 2.0, 1.0, 16.0) == 0.0
    assert steps_left(0.0, 1.0, 100.0, 1.0 + 4.0 + 16.0) == pytest.approx(3.0)  # q clipped
    opts = WearOptions(max_cycles=16.0, max_steps=1000)
    st = SimpleNamespace(step=3, cycles=9.0, jump=1.0, volume_rate=1.0, volume_rate0=1.0,
                         W=np.zeros(2))
    assert _progress_fraction(st, 2.0, opts) == pytest.approx(0.5, rel=1e-12)


def test_tutorial_joint_wears_from_balances_without_time_integrations():
    """The tutorial's lap joint worn at its resonance to 1e6 cycles: the first balance (three
    harmonics, interface open 94 % of the period) converges from the first harmonic alone, so
    no step takes its rate from a time integration (before, the first state came from one,
    integrated from rest for 2000 periods). Checked against the same
    run with ten times smaller jumps (max_jump 1e5): the adaptive steps keep their local error
    below the run's tolerance 1e-2 of the deepest wear, so the deepest wear of both agrees to
    1e-2 (measured 1.7e-4; 2e-3 over 1e7 cycles)."""
    from helpers.lap_joint import F_PEAK, tutorial_joint

    from fretwear.wear import simulate_wear

    model, basis = tutorial_joint(), FourierBasis.up_to(3, 64)
    runs = [simulate_wear(model, basis, frequency=F_PEAK,
                          options=WearOptions(max_cycles=1e6, **kw))
            for kw in ({}, {"max_jump": 1e5})]
    for w in runs:
        assert w.history.cycles[-1] == 1e6 and not np.any(w.history.rescued), w.message
    deep = [float(np.max(w.final_wear)) for w in runs]
    assert deep[0] > 0 and abs(deep[0] - deep[1]) <= 1e-2 * deep[1]
