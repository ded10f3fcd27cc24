"""Tests of the stick-set jump (:mod:`fretwear.wear.stick_set`).

Reference: the analytic worn state of the Winkler punch (tests/helpers/winkler.py): the nodes
with ``mu F_p < T`` slip and wear until they carry nothing, ``W_p = F_p / k_n``; the others
stick and keep ``W_p = 0`` (Ciavarella and Hills: wear stops once the slip zone is unloaded).
The jump computes it from the unworn balance without any slow step, so it is compared with
the formula directly.
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers.winkler import BASIS, KN, MU, F, T, winkler

from fretwear.errors import InputError
from fretwear.hb.options import SolveOptions
from fretwear.wear import WearOptions
from fretwear.wear.schemes import first_state
from fretwear.wear.simulate import BalanceSetup, slow_setup
from fretwear.wear.stick_set import separation, stick_set_state
from fretwear.wear.worn_state import WornStateOptions, worn_state


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
    """A stick_set that is not a boolean: one InputError naming it."""
    with pytest.raises(InputError, match="stick_set = 'yes'"):
        WornStateOptions(stick_set="yes")
