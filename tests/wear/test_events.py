"""Tests of the events located along the linearised slow path (:mod:`fretwear.wear.events`).

References, each independent of the code under test:

* a linear slow equation ``dW/dN = g0 + Js (W - W0)`` with a diagonal ``Js`` (a growing and
  a decaying mode), whose path is ``W_p(N) = W0_p + g0_p (e^{lam_p N} - 1) / lam_p`` in closed
  form: the first ``N`` at which a depth reaches a threshold is
  ``ln(1 + lam c / g0) / lam``, against which :func:`first_event` on
  :func:`~fretwear.wear.exponential_step.increment` (the exponential step's path) is
  checked;
* the Winkler punch (tests/helpers/winkler.py): decoupled nodes whose contact force is
  ``F_p - k_n W_p``, so the linearised path of each slipping node and the depth at which
  it separates are known in closed form, and with them the first event along the path.
"""

from __future__ import annotations

import math

import numpy as np
from helpers.winkler import BASIS, KN, MU, F, T, winkler

from fretwear.wear import WearOptions
from fretwear.wear.events import first_event, pattern, pattern_along
from fretwear.wear.exponential_step import increment
from fretwear.wear.schemes import first_state
from fretwear.wear.simulate import BalanceSetup, slow_setup

LAM = np.array([3e-4, -2e-3])  # [1/cycle]: a growing and a decaying mode
G0 = np.array([1e-9, 4e-9])  # [m/cycle]


def _crossing(p, c):
    """Closed-form first N at which W_p - W0_p reaches c on the linear equation."""
    return math.log1p(LAM[p] * c / G0[p]) / LAM[p]


def test_first_event_brackets_the_analytic_crossing():
    """A threshold on the growing mode (reached at N* = 3.66e3 cycles) and one on the
    decaying mode (reached at 1.01e2): :func:`first_event` over a step of 1e4 cycles
    brackets the earlier crossing, ``before < N* <= after`` to its relative tolerance
    (1e-3: the bisection's; the path itself is the exponential of a 3 x 3 matrix, exact to
    rounding), and the later one when only it is asked for. A step that ends before any
    crossing finds none."""
    Js = np.diag(LAM)
    c = np.array([2e-5, 3.9e-7])  # thresholds on W - W0 [m]
    exact = [_crossing(0, c[0]), _crossing(1, c[1])]
    assert exact[1] < exact[0] < 1e4

    def key(N, which=(0, 1)):
        dW = increment(Js, G0, N)
        return tuple(bool(dW[p] >= c[p]) for p in which)

    lo, hi = first_event(key, 1e4)
    assert lo < exact[1] <= hi and hi - lo <= 1e-3 * hi
    lo, hi = first_event(lambda N: key(N, (0,)), 1e4)
    assert lo < exact[0] <= hi and hi - lo <= 1e-3 * hi
    assert first_event(lambda N: key(N, (0,)), 0.9 * exact[0]) is None


def test_first_event_ignores_a_flip_at_the_start():
    """A pattern that differs only at ``N = 0`` (a node exactly on its boundary, which
    the first rounding flips) is no event: the reference is taken at ``start dN``."""
    assert first_event(lambda N: N == 0.0, 10.0) is None
    # ...but a change just after the reference is found
    lo, hi = first_event(lambda N: N > 0.02, 10.0)
    assert lo < 0.02 <= hi


def _punch():
    opts = WearOptions(adaptive=False, initial_jump=1e5)
    _, _, _, wear0, anchor, _, sp = slow_setup(winkler(), BASIS, 1.0, True, BalanceSetup(),
                                               opts, None, None)
    st, _ = first_state(sp, wear0, anchor, None, opts)
    return sp, st


def test_winkler_event_is_the_analytic_unloading_on_the_linearised_path():
    """On the Winkler punch the nodes decouple: ``Js`` is diagonal and the contact force of
    a slipping node is ``F_p - k_n W_p`` on its pattern, exactly linear in the wear, so the
    balance's derivative predicts it exactly. Along the linearised path
    ``W_p(N) = g_p (e^{j_p N} - 1) / j_p`` (``j_p = Js_pp``) a slipping node opens when
    ``W_p`` reaches ``F_p / k_n``, at ``N_p = ln(1 + j_p F_p / (k_n g_p)) / j_p``: the first
    event :func:`pattern_along` predicts is the earliest ``N_p``, to the bisection's 1e-3
    (the nodes' linear paths are written out here, not taken from the exponential step's
    :func:`~fretwear.wear.exponential_step.increment`, which the key is given). The analytic
    march itself never gets there (the rate falls with the load: the unloading is
    asymptotic), which is why an event step must be judged by the balance at its end."""
    sp, st = _punch()
    anchor = st.U.reshape(sp.nc, sp.d, sp.H)[:, 1:, 0].copy()
    sp.set_state(st.W, anchor)
    Js, dUdW = sp.slow_jacobian(st.U, with_dUdW=True)
    slips = MU * F < T
    assert np.array_equal(pattern(sp, st.W, st.U, anchor)[0], slips)
    assert np.abs(Js - np.diag(np.diag(Js))).max() <= 1e-12 * np.abs(Js).max()
    j, g = np.diag(Js)[slips], st.g[slips]
    arg = 1.0 + j * F[slips] / (KN * g)
    N_open = np.where(arg > 0, np.log(np.where(arg > 0, arg, 1.0)) / j, np.inf)
    exact = float(N_open.min())
    assert math.isfinite(exact)
    key = pattern_along(sp, st.W, st.U, anchor,
                        lambda N: np.maximum(increment(Js, st.g, N), 0.0), dUdW)
    lo, hi = first_event(key, 4.0 * exact)
    assert lo < exact * (1 + 1e-9) and exact <= hi * (1 + 1e-9)
    assert hi - lo <= 1e-3 * hi
    assert first_event(key, 0.9 * exact) is None
