"""Tests of the stick-set jump (:mod:`fretwear.wear.stick_set`).

Reference: the analytic worn state of the Winkler punch (tests/helpers/winkler.py): the nodes
with ``mu F_p < T`` slip and wear until they carry nothing, ``W_p = F_p / k_n``; the others
stick and keep ``W_p = 0`` (Ciavarella and Hills: wear stops once the slip zone is unloaded).
The jump computes it from the unworn balance without any slow step, so it is compared with
the formula directly. Where the jump lands elsewhere than the march (a reduced Stromberg
beam), the march to its plateau is the reference.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from helpers.wear_runs import reduced_example
from helpers.winkler import BASIS, KN, MU, F, T, winkler

from fretwear.errors import InputError
from fretwear.hb.options import SolveOptions
from fretwear.wear import WearOptions, simulate_wear
from fretwear.wear.schemes import first_state
from fretwear.wear.simulate import BalanceSetup, slow_setup
from fretwear.wear.stick_set import separation, stick_set_state
from fretwear.wear.worn_state import WornStateOptions, agreement, worn_state


def _unworn():
    """The slow problem of the Winkler punch and its unworn balanced state."""
    opts = WearOptions()
    _, _, _, wear0, anchor, _, sp = slow_setup(winkler(), BASIS, 1.0, True, BalanceSetup(),
                                               opts, None, None)
    state, _ = first_state(sp, wear0, anchor, None, opts)
    return sp, state


def test_jump_from_the_unworn_state_is_the_analytic_state():
    """One round from the unworn balance: the slipping nodes worn to ``F / k_n``, the stuck
    ones at 0 to the bit, the rate at the state 0. Tolerance 1e-9 of the deepest wear: the
    worn depth is read from the separation of the balance with the nodes lifted off, exact
    for these decoupled springs up to the balance's residual (1e-9 relative by default)."""
    sp, st = _unworn()
    g0 = float(np.max(st.g))
    jump, its = stick_set_state(sp, st.W, st.U, st.anchor, st.g, g0=g0,
                                options=SolveOptions())
    assert jump is not None and jump.rounds == 1 and its > 0
    exact = np.where(MU * F < T, F / KN, 0.0)
    np.testing.assert_array_equal(jump.worn, MU * F < T)
    assert np.max(np.abs(jump.W - exact)) <= 1e-9 * exact.max()
    assert np.all(jump.W[MU * F >= T] == 0.0)
    assert np.max(jump.g) <= 1e-6 * g0
    # the unloaded nodes just touch: clear of contact by no more than round-off
    sp.set_state(jump.W, st.anchor)
    assert np.all(separation(sp, jump.U) <= 1e-12 * exact.max())


def test_worn_state_with_the_jump_is_the_analytic_state_for_fewer_solves():
    """``stick_set = True`` ends on the analytic state (tolerance 1e-9 of the deepest wear,
    as above: the state is the jump's), with fewer DLFT solves than the path followed to the
    end (``stick_set = False``, the reference run of test_worn_state.py), and says that the
    state is a jump's."""
    model = winkler()
    path = worn_state(model, BASIS, quasi_static=True)
    fast = worn_state(model, BASIS, quasi_static=True, options=WornStateOptions(stick_set=True))
    assert fast.success and fast.kind == "null_wear_rate", fast.message
    assert "stick-set jump" in fast.message
    assert any("stick-set jump" in w for w in fast.warnings)
    exact = np.where(MU * F < T, F / KN, 0.0)
    assert np.max(np.abs(fast.wear - exact)) <= 1e-9 * exact.max()
    assert fast.dlft_solves < path.dlft_solves
    assert not any("stick-set" in w for w in path.warnings)


def test_stick_set_option_is_checked():
    """A stick_set that is not a boolean, a jump threshold outside (0, 1]: one InputError
    naming it."""
    with pytest.raises(InputError, match="stick_set = 'yes'"):
        WornStateOptions(stick_set="yes")
    for name, bad in (("jump_rate", 0.0), ("jump_progress", 1.5), ("jump_rate", float("nan"))):
        with pytest.raises(InputError, match=name):
            WornStateOptions(stick_set=True, **{name: bad})


def test_agreeing_early_jumps_that_land_elsewhere_are_refused(tmp_path):
    """The reduced Stromberg beam (30 x 2 Q4, 3 harmonics, 32 samples), against the march
    to its plateau (a separate integration of the same slow equation): the jumps from the
    first two records of the direct path agree with each other (within ``depth_tolerance``;
    measured 1e-12) but land on another null-wear-rate state, more than half the deepest
    wear from the march's (measured 103 %), so agreement alone would end the run there.
    The path's step between them covers under a tenth of ``jump_progress`` (0.25) of the way
    to the jump (measured 0.09 %), and the run with ``stick_set = True`` goes on along the path and
    ends on the march's state, by a jump, within 1 % of the deepest wear (issue 29's
    tolerance; measured 4e-9)."""
    model, basis = reduced_example("stromberg1997", 30, tmp_path)
    march = simulate_wear(model, basis, quasi_static=True,
                          options=WearOptions(plateau_rate=1e-8, max_steps=300))
    Wm = march.history.wear_depth[-1]
    top = float(np.max(Wm))
    path = worn_state(model, basis, quasi_static=True).history
    opts = WearOptions()
    *_, sp = slow_setup(model, basis, 1.0, True, BalanceSetup(), opts, None, None)
    g0 = float(np.max(path.wear_rate[0]))
    jumps = []
    for k in (1, 2):
        jump, _ = stick_set_state(sp, path.wear_depth[k],
                                  np.asarray(path.U[k], float).reshape(sp.m, sp.H),
                                  path.anchor[k], path.wear_rate[k], g0=g0, options=opts.solve)
        assert jump is not None
        assert np.max(np.abs(jump.W - Wm)) > 0.5 * top
        jumps.append(jump.W)
    c, progress = agreement(path.wear_depth[1], path.wear_depth[2], *jumps)
    assert c <= WornStateOptions().depth_tolerance
    assert progress < 0.1 * WornStateOptions().jump_progress
    fast = worn_state(model, basis, quasi_static=True, options=WornStateOptions(stick_set=True))
    assert fast.success and "stick-set jump" in fast.message, fast.message
    assert np.max(np.abs(fast.wear - Wm)) <= 0.01 * top


def test_a_resumed_run_takes_the_jump_of_the_run_never_stopped(tmp_path):
    """``stick_set = True`` on the Winkler punch, interrupted (a callback raising
    KeyboardInterrupt) after the last path step before its jump, then resumed from its
    checkpoint: the same records, the same state bit for bit and the same message as the run
    never stopped (the target jump of the rule is found again from the resumed records; a
    run that started with no target took its jump a step later, 8e-22 m away)."""
    from fretwear.wear import RunControl

    model, options = winkler(), WornStateOptions(stick_set=True)
    ref = worn_state(model, BASIS, quasi_static=True, options=options)
    assert "stick-set jump" in ref.message
    last_path_step = ref.history.wear_depth.shape[0] - 2  # the last record is the jump's
    ck = tmp_path / "worn.npz"

    def stop(step, record):
        if step == last_path_step:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        worn_state(model, BASIS, quasi_static=True, options=options,
                   run=RunControl(checkpoint=ck, callback=stop))
    # the jump rule's thresholds decide where the run ends: a resume with another one is
    # refused (they were module constants outside the checkpoint's fingerprint before)
    for other in (replace(options, jump_progress=0.5), replace(options, jump_rate=0.2)):
        with pytest.raises(InputError, match="different wear settings"):
            worn_state(model, BASIS, quasi_static=True, options=other,
                       run=RunControl(checkpoint=ck, resume=True))
    res = worn_state(model, BASIS, quasi_static=True, options=options,
                     run=RunControl(checkpoint=ck, resume=True))
    assert res.resumed_from == last_path_step
    assert res.history.wear_depth.shape == ref.history.wear_depth.shape
    np.testing.assert_array_equal(res.wear, ref.wear)
    assert res.message == ref.message
