"""Tests of the error control of the slow steps (:mod:`fretwear.wear.step_control`).

Reference: the linear slow problem ``dW/dN = c - lam W`` (a wear rate that decreases as the
wear grows, node by node), whose exact solution ``W* + (W_k - W*) exp(-lam dN)``,
``W* = c / lam``, gives the true local error of one explicit or backward Euler step, both
written here in closed form (no code of fretwear.wear.schemes). With ``x = lam dN``:

* both true local errors are ``|W_k - W*| x^2 / 2 (1 + O(x))``, and so is the trapezoidal
  defect :func:`local_error` computes: their ratio is ``1 + O(x)`` (expanding both:
  ``1 + x/3`` for explicit Euler, ``1 + 2x/3`` for backward Euler), checked to ``x`` for x
  from 1e-3 to 1e-1 (a missing or doubled factor 1/2 would be off by 100 %);
* a first-order step's error grows as ``dN^2``: the jump :func:`next_jump` proposes after a step
  of error ``err`` must give, on the same problem, the error ``0.9^2 tolerance`` (its safety
  factor 0.9), up to the same ``O(x)``: checked to 5 % (x <= 0.02 here).

The module runs in well under a second.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from fretwear.wear.options import WearOptions
from fretwear.wear.step_control import local_error, next_jump

LAM = np.array([1e-6, 2e-6, 5e-7])  # [1/cycle], one per node
W_STAR = np.array([1e-6, 3e-6, 2e-6])  # [m], the depths the rates vanish at
W_K = np.array([1e-7, 2e-7, 0.0])  # [m], the depths at the start of the step


def rate(W):
    return LAM * (W_STAR - W)


def exact(dN):
    return W_STAR + (W_K - W_STAR) * np.exp(-LAM * dN)


def explicit_euler(dN):
    return W_K + dN * rate(W_K)


def backward_euler(dN):
    """``W1 = W_k + dN (c - lam W1)`` solved for ``W1``."""
    return (W_K + dN * LAM * W_STAR) / (1.0 + LAM * dN)


def estimate(step, dN):
    W1 = step(dN)
    return local_error(dN, W1, W_K, rate(W1), rate(W_K))


def true_error(step, dN):
    W1 = step(dN)
    return float(np.max(np.abs(W1 - exact(dN))) / np.max(np.abs(W1)))


@pytest.mark.parametrize("step", [explicit_euler, backward_euler])
@pytest.mark.parametrize("x", [1e-3, 1e-2, 1e-1])
def test_local_error_is_the_true_local_error_of_a_first_order_step(step, x):
    dN = x / LAM.max()
    est, true = estimate(step, dN), true_error(step, dN)
    assert true > 0
    assert abs(est / true - 1) < x, (est, true)


def test_local_error_of_a_step_on_the_trapezoidal_rule_and_of_nothing_worn():
    """A constant rate is integrated exactly by both Euler steps and the trapezoidal rule:
    no error (exactly 0); a defect without any wear has no relative size: inf."""
    g = np.array([1e-12, 3e-12])
    assert local_error(1e4, 1e4 * g, np.zeros(2), g, g) == 0.0
    assert local_error(1e4, np.zeros(2), np.zeros(2), g, g) == math.inf


def test_next_jump_reaches_the_tolerance_with_its_safety_factor():
    opts = WearOptions(tolerance=1e-4)
    for step in (explicit_euler, backward_euler):
        dN = 1e-3 / LAM.max()
        err = estimate(step, dN)
        proposed = next_jump(dN, err, opts, fixed=123.0)
        assert 1.0 < proposed / dN < 5.0  # the rule itself, not its limits
        assert LAM.max() * proposed < 0.02
        assert estimate(step, proposed) == pytest.approx(0.81 * opts.tolerance, rel=0.05)
        assert true_error(step, proposed) == pytest.approx(0.81 * opts.tolerance, rel=0.05)


def test_next_jump_limits_and_fixed_jumps():
    """Growth at most x5 (and at most ``grow_limit``), shrinking at most x0.2, x5 after a step
    without error; without ``adaptive`` the fixed jump whatever the error."""
    opts = WearOptions(tolerance=1e-2)
    assert next_jump(100.0, 1e-12, opts, fixed=7.0) == 500.0
    assert next_jump(100.0, 1e-12, opts, fixed=7.0, grow_limit=2.0) == 200.0
    assert next_jump(100.0, 0.0, opts, fixed=7.0) == 500.0
    assert next_jump(100.0, 1e3, opts, fixed=7.0) == pytest.approx(20.0)
    assert next_jump(100.0, 1e-2, opts, fixed=7.0) == pytest.approx(90.0)
    fixed = WearOptions(tolerance=1e-2, adaptive=False)
    for err in (0.0, 1e-12, 1e3):
        assert next_jump(100.0, err, fixed, fixed=7.0) == 7.0
