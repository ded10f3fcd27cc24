"""Tests of the exponential Euler slow step (:mod:`fretwear.wear.exponential_step`).

References, each independent of the code under test:

* the increment ``dN phi1(dN Js) g`` against its eigen-decomposition
  ``V diag(expm1(dN lam) / lam) V^-1 g`` (``lam`` the eigenvalues of ``Js``), i.e. the exact
  solution of the linear ODE ``dW/dN = g + Js (W - W_k)``, and, in the stiff limit, against
  Newton's step ``-Js^-1 g``;
* a step on the Winkler punch (tests/helpers/winkler.py: decoupled nodes, so ``Js`` is
  diagonal) against the same formula on the slow Jacobian taken by finite differences of the
  wear rate over balanced solutions (not the implicit-function derivative the step uses).
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers.winkler import BASIS, winkler

from fretwear.wear import WearOptions
from fretwear.wear.exponential_step import exponential_step, increment, rosenbrock_error
from fretwear.wear.schemes import advance, first_state
from fretwear.wear.simulate import BalanceSetup, slow_setup


def _phi1_by_eigenvectors(Js, g, dN):
    lam, V = np.linalg.eig(Js)
    z = dN * lam
    phi = np.where(z == 0, 1.0, np.expm1(z) / np.where(z == 0, 1.0, z))
    return np.real(dN * V @ (phi * np.linalg.solve(V, g)))


def test_increment_is_the_exact_solution_of_the_linearised_equation():
    """A non-normal ``Js`` with a decaying, a stiff, a neutral and a growing mode (the
    growing one at ``dN lam = 2``, EXP_GROWTH_LIMIT): the increment equals the
    eigen-decomposition formula to 1e-10 relative (both are exact in exact arithmetic; the
    tolerance is far above the rounding of a 4 x 4 exponential and far below any
    first-order step's error, which here is O(1))."""
    rng = np.random.default_rng(3)
    V = np.eye(4) + 0.3 * rng.standard_normal((4, 4))
    Js = V @ np.diag([-1e-3, -5.0, 0.0, 2e-3]) @ np.linalg.inv(V)
    g = np.array([1.0, 0.5, 2.0, 0.1]) * 1e-9
    for dN in (1.0, 1e2, 1e3):
        exact = _phi1_by_eigenvectors(Js, g, dN)
        np.testing.assert_allclose(increment(Js, g, dN), exact, rtol=1e-10,
                                   atol=1e-10 * np.abs(exact).max())
    # the linearly implicit Euler increment is not it (a test that could not fail otherwise)
    lie = 1e3 * np.linalg.solve(np.eye(4) - 1e3 * Js, g)
    assert np.abs(lie - _phi1_by_eigenvectors(Js, g, 1e3)).max() > 1e-3 * np.abs(lie).max()


def test_stiff_limit_is_newtons_step():
    """With every eigenvalue of ``Js`` negative and ``dN |lam|`` above 1e9 the increment is
    Newton's step on ``g = 0``, ``-Js^-1 g`` (``e^{dN lam}`` underflows to 0, so
    ``dN phi1(dN lam) = -1 / lam`` exactly): to 1e-8 relative (the exponential of a matrix
    of norm 1e12 by scaling and squaring loses about that much)."""
    A = np.array([[-2.0, 0.5, 0.0], [0.3, -1.0, 0.2], [0.0, 0.4, -3.0]]) * 1e-3
    g = np.array([3.0, 1.0, 2.0]) * 1e-10
    np.testing.assert_allclose(increment(A, g, 1e12), -np.linalg.solve(A, g), rtol=1e-8)


def _winkler(jump):
    opts = WearOptions(adaptive=False, initial_jump=jump)
    _, _, _, wear0, anchor, _, sp = slow_setup(winkler(), BASIS, 1.0, True, BalanceSetup(),
                                               opts, None, None)
    st, _ = first_state(sp, wear0, anchor, None, opts)
    return sp, st, opts


def test_winkler_step_is_exponential_euler_on_the_finite_difference_jacobian():
    """One step of 3e5 cycles from the unworn Winkler punch. Its three slipping nodes have
    ``dg_p/dW_p = -k_n a (T - 2 mu N_p)``: negative, zero and positive (a growing mode, so
    the march would cut this jump and the step is exponential). The new depths equal
    ``W_k + (e^{dN Js_pp} - 1) / Js_pp dN g_p`` with ``Js_pp`` a central finite difference of
    the rate over balanced solutions (each node's depth moved by 1e-3 of its step; nodes whose
    one-sided differences differ by more than 10 % are at a kink and left out), to 1e-4 of
    the largest increment (the finite difference's error; the step is exact for the
    linearised equation). The stuck nodes stay at 0 to the bit."""
    sp, st, opts = _winkler(3e5)
    new, record, failure = exponential_step(sp, st, opts)
    assert not failure and record.jump == 3e5
    anchor = st.U.reshape(sp.nc, sp.d, sp.H)[:, 1:, 0].copy()
    wears = st.g > 0
    assert wears.sum() == 3
    dW = new.W - st.W
    h = 1e-3 * dW
    js, smooth = np.zeros(sp.nc), np.zeros(sp.nc, bool)
    for p in np.flatnonzero(wears):
        rates = []
        for s in (1.0, 0.0, -1.0):
            W = st.W.copy()
            W[p] += s * h[p]
            U, stats = sp.solve_balance(W, anchor, sp.shift_guess(st.U, W - st.W),
                                        options=opts.solve.replace(tol=1e-12))
            assert stats.success
            sp.set_state(W, anchor)
            rates.append(sp.rate(U)[p])
        fwd, bwd = (rates[0] - rates[1]) / h[p], (rates[1] - rates[2]) / h[p]
        js[p] = 0.5 * (fwd + bwd)
        smooth[p] = abs(fwd - bwd) <= 0.1 * abs(js[p])
    # the node with F = 2 sits at N = T / (2 mu), where dg/dW = 0 analytically and the
    # sampled slip work has a kink (its one-sided differences differ): left out
    keep = wears & smooth
    assert keep.sum() == 2
    z = 3e5 * js[keep]
    assert z.min() < -0.5 and z.max() > 0.5  # a decaying and a growing mode
    expect = np.expm1(z) / z * 3e5 * st.g[keep]
    np.testing.assert_allclose(dW[keep], expect, rtol=0, atol=1e-4 * dW.max())
    assert np.all(new.W[~wears] == 0.0)
    lie = 3e5 * st.g[keep] / (1 - z)  # the linearly implicit step: not it
    assert np.abs(lie - expect).max() > 1e-2 * dW.max()


def test_without_a_growing_mode_binding_it_is_the_marchs_step():
    """A jump of 2e4 cycles (``dN lam`` far below the march's GROWTH_LIMIT): the step is the
    march's (:func:`fretwear.wear.schemes.advance`), the same depths and rates to the bit."""
    sp, st, opts = _winkler(2e4)
    new, record, _ = exponential_step(sp, st, opts)
    sp2, st2, _ = _winkler(2e4)
    ref, rec2, _ = advance(sp2, st2, opts)
    np.testing.assert_array_equal(new.W, ref.W)
    np.testing.assert_array_equal(record.wear_rate, rec2.wear_rate)
    assert record.cycles == rec2.cycles


# -- the second-order step (order = 2): exponential Rosenbrock-Euler with its estimate ----

A_RATE = np.array([2e-9, 1e-9, 3e-9])  # [m/cycle], the initial rates of the modes
D_DEPTH = np.array([1e-6, 2e-6, 1.5e-6])  # [m], the depths where their rates vanish
MIX = np.array([[1.0, 0.3, 0.0], [0.2, 1.0, 0.1], [0.0, 0.4, 1.0]])  # full, non-normal


def _exact(W0, N):
    """The slow equation ``dy/dN = a (1 - y / D)^2`` per mode (a rate that falls as the
    mode wears towards its null-wear-rate depth ``D``), closed form
    ``y(N) = D - D / (1 / (1 - y0 / D) + a N / D)``, in the mixed coordinates
    ``W = MIX y`` (so that ``dg/dW`` is full)."""
    y0 = np.linalg.solve(MIX, W0)
    return MIX @ (D_DEPTH - D_DEPTH / (1.0 / (1.0 - y0 / D_DEPTH) + A_RATE * N / D_DEPTH))


def _rate_jac(W):
    """``g(W) = MIX a (1 - y / D)^2`` and its Jacobian ``MIX diag(dg_y/dy) MIX^-1``."""
    y = np.linalg.solve(MIX, W)
    g = MIX @ (A_RATE * (1 - y / D_DEPTH) ** 2)
    J = MIX @ np.diag(-2 * A_RATE / D_DEPTH * (1 - y / D_DEPTH)) @ np.linalg.inv(MIX)
    return g, J


def test_rosenbrock_euler_is_exact_on_a_linear_slow_equation():
    """``dW/dN = g0 + A (W - W0)`` with a full, non-normal ``A`` (a decaying, a stiff and a
    growing mode): one step of any length is the exact solution
    ``W0 + V diag(expm1(dN lam) / lam) V^-1 g0`` (the eigen-decomposition, independent of
    the bordered exponential), to 1e-10 relative, and its error estimate vanishes (the
    nonlinear remainder ``D = g1 - g0 - A dW`` is 0 to rounding: 1e-12 of the step)."""
    rng = np.random.default_rng(5)
    V = np.eye(3) + 0.3 * rng.standard_normal((3, 3))
    A = V @ np.diag([-1e-3, -3e-2, 5e-4]) @ np.linalg.inv(V)
    g0 = np.array([2.0, 1.0, 0.5]) * 1e-9
    for dN in (10.0, 1e3, 4e3):
        dW = increment(A, g0, dN)
        exact = _phi1_by_eigenvectors(A, g0, dN)
        np.testing.assert_allclose(dW, exact, rtol=1e-10, atol=1e-10 * np.abs(exact).max())
        err = rosenbrock_error(A, dN, dW, g0, g0 + A @ dW)
        assert np.abs(err).max() <= 1e-12 * np.abs(dW).max()


def test_rosenbrock_euler_converges_with_order_two_and_its_estimate_with_order_three():
    """The nonlinear slow equation of :func:`_exact` (exact solution in closed form),
    integrated over 1000 cycles (the rates fall by a factor of 3 to 7) with ``n`` equal
    steps of ``W + increment(Js(W), g(W), dN)``: the global error falls by ``2^2`` when
    ``n`` doubles (observed orders 2.06 and 2.03 from n = 16 to 64, checked within 0.1 of
    2: a first-order method gives 1). One step's error estimate :func:`rosenbrock_error`
    (the exprb32 correction: the difference of the second- and third-order solutions)
    tends to the true local error as ``1 - O(dN)``: within 5 % at dN = 12.5 (measured
    1.3 %), and falls as ``dN^3`` (observed 2.91 from 25 to 12.5 cycles, checked to 0.15;
    the first-order defect would fall as ``dN^2``)."""
    W0, N = np.array([0.0, 2e-7, 5e-7]), 1e3
    errors = []
    for n in (16, 32, 64):
        W = W0.copy()
        for _ in range(n):
            g, Js = _rate_jac(W)
            W = W + increment(Js, g, N / n)
        errors.append(np.abs(W - _exact(W0, N)).max())
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    np.testing.assert_allclose(orders, 2.0, atol=0.1)
    est, true = [], []
    for dN in (25.0, 12.5):
        g, Js = _rate_jac(W0)
        dW = increment(Js, g, dN)
        est.append(np.abs(rosenbrock_error(Js, dN, dW, g, _rate_jac(W0 + dW)[0])).max())
        true.append(np.abs(W0 + dW - _exact(W0, dN)).max())
    assert est[1] == pytest.approx(true[1], rel=0.05)
    assert np.log2(est[0] / est[1]) == pytest.approx(3.0, abs=0.15)
