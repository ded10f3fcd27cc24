"""The slow-scale steps on periodic balances (paper eq. 29-30).

* ``"explicit"``: explicit Euler with cycle jumps ``dN`` (eq. 30), as the paper;
* ``"rosenbrock"`` (default): linearly implicit Euler ``W_{k+1} = W_k + dN (I - dN Js)^-1 g``
  with the slow Jacobian ``Js = dg/dW`` along balanced solutions, then the balance;
* ``"implicit"``: backward Euler ``W_{k+1} = W_k + dN g(W_{k+1})``, by a damped Newton method
  on ``W`` over balanced solutions (or, ``implicit_newton = "coupled"``, Newton on the coupled
  unknowns ``(U~, W_{k+1})`` with residuals ``f(U~; W_{k+1})`` (DLFT, eq. 22) and
  ``eps (W_{k+1} - W_k - dN g(U~, W_{k+1}))``).

The implicit schemes are stable for any jump, which explicit Euler is not (``dN < 2/rho(Js)``):
docs/wear.md measures all of them. Every scheme may adapt its jump to a tolerance on the local
error (:mod:`fretwear.wear.step_control`).

Each step starts from the previous periodic solution (warm start) and keeps the stick anchors
of its mean tangential position (the loading history rule of :mod:`fretwear.hb.sweep`). A step
whose solve fails is retried with a smaller jump; when that fails too the driver takes the step
from a time integration (:mod:`fretwear.wear.time_steps`) or stops.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from fretwear.errors import ConvergenceError, InputError
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.solvers import SolveStats
from fretwear.wear.options import (
    GROWTH_LIMIT,
    MIN_JUMP_FRACTION,
    RESCUE_START_FRACTION,
    WearOptions,
)
from fretwear.wear.slow_problem import SlowProblem
from fretwear.wear.state import SlowStep, StepRecord, StepStats
from fretwear.wear.step_control import local_error, next_jump, root
from fretwear.wear.time_steps import time_domain_start


@dataclass(frozen=True)
class StepStart:
    """Where a slow step starts: the wear depths ``W`` (nc,) [m], their balance ``U`` (m, H)
    [m] and rate ``g`` (nc,) [m/cycle], and the stick anchors ``anchor`` (nc, d-1) [m] of the
    step's balances."""

    W: np.ndarray
    U: np.ndarray
    g: np.ndarray
    anchor: np.ndarray


def first_state(sp: SlowProblem, wear0, anchor, U0, opts: WearOptions
                ) -> tuple[SlowStep, list[StepRecord]]:
    """The balanced initial state (step 0) at the wear depths ``wear0`` (nc,) [m], from the
    stick anchors ``anchor`` (nc, d-1) [m] and the start ``U0`` (or None) of the first solve;
    from a time integration when that balance fails and the problem has one
    (:func:`~fretwear.wear.time_steps.time_domain_start`)."""
    t0 = time.perf_counter()
    sp.set_state(wear0, anchor)
    # the first balance goes through solve_periodic (its start strategies for a cold start);
    # its attempts are opts.solve.strategy, by default the solver alone (WEAR_STEP): a wear
    # run has its own fallback (a start from a time integration). Its start is a single
    # solve's (from the first harmonic alone with more than one harmonic): on the 79 kHz
    # reduced example (3 harmonics) it finds the balance that the time integration from rest
    # led to at the next step, where the contact-closed guess failed (tests/test_examples.py)
    first = opts.solve.replace(max_iter=max(opts.solve.max_iter, 200))
    sol0 = solve_periodic(sp.model, sp.prob.basis, frequency=sp.prob.reduced.frequency,
                          quasi_static=sp.prob.reduced.quasi_static, options=first,
                          reduced=sp.prob.reduced, gap=sp.gap0 + wear0, eps=sp.eps,
                          anchor=anchor, U0=U0)
    st = sol0.stats
    if not sol0.success:
        if sp.time_domain is not None:
            return time_domain_start(sp, wear0, opts, st, t0)
        raise ConvergenceError(
            f"the periodic solve of the unworn interface did not converge ({st.message}, "
            f"relative residual {st.residual:.3g} > {opts.solve.tol:g}): no wear computed"
        )
    U = sol0.U.reshape(sp.m, sp.H)
    if opts.scheme != "explicit" and sp.needs_iterative_solves(U):
        raise InputError(
            f"scheme = {opts.scheme!r}: {sp.nc} contact nodes with a slipping set too large "
            "for a direct step; the slow Jacobian of this scheme would need one iterative "
            f"solve per contact node ({sp.nc}) at every step: use scheme = \"explicit\" "
            "(docs/theory.md, \"Large interfaces\")")
    g = sp.rate(U)
    rho = 0.0
    if np.any(g > 0):
        rho = sp.slow_radius(U)
    stab = 2.0 / rho if rho > 0 else math.inf
    if opts.initial_jump is not None:
        jump = float(opts.initial_jump)
    elif opts.adaptive:
        jump = opts.tolerance * stab if math.isfinite(stab) else 1.0
    else:
        jump = 0.5 * stab if math.isfinite(stab) else 1.0
    sol = sp.solution(U, wear0, anchor, st)
    record = StepRecord.balanced(sol, wear0, g, StepStats(0.0, 0.0, st.iterations, 0, 0.0,
                                                          time.perf_counter() - t0))
    return SlowStep.balanced(record, jump, stability_jump=stab), [record]


def advance(sp: SlowProblem, st: SlowStep, opts: WearOptions):
    """One accepted slow step from the state ``st``: ``(new_state, record, failure_message)``
    (``(None, None, message)`` when it failed).

    Retries a failed solve with the jump divided by 4 (up to ``max_retries`` times, not below
    ``min_jump``); with ``adaptive``, rejects a step whose error estimate exceeds the
    tolerance and retries with the jump the controller proposes.
    """
    t0 = time.perf_counter()
    # history rule: the stick anchors are the previous mean tangential positions
    anchor = st.U.reshape(sp.nc, sp.d, sp.H)[:, 1:, 0].copy()
    start = StepStart(st.W, st.U, st.g, anchor)
    dN = min(st.jump, opts.max_jump, opts.max_cycles - st.cycles)
    floor = max(opts.min_jump, MIN_JUMP_FRACTION * st.cycles)  # error control
    rescue = sp.time_domain is not None
    # failed solves: with a time-domain rescue behind, stop cutting where the rescue starts
    fail_floor = max(floor, RESCUE_START_FRACTION * st.cycles) if rescue else floor
    iters = rejected = 0
    lin = None
    if opts.scheme != "explicit":
        sp.set_state(st.W, anchor)
        lin = sp.slow_jacobian(st.U, with_dUdW=True)  # Js, dU/dW at the start of the step
        iters += 1
        # a growing mode (eigenvalue lam > 0: wear moving load onto a neighbour) is only
        # followed accurately with dN lam small, and I - dN Js is singular at dN lam = 1
        lam_plus = float(np.max(np.linalg.eigvals(lin[0]).real))
        if lam_plus > 0:
            dN = min(dN, GROWTH_LIMIT / lam_plus)
    return accept(sp, opts, st, anchor, lambda dn: _attempt(sp, opts, start, dn, lin),
                  (dN, floor, fail_floor), (t0, iters, rejected))


def accept(sp: SlowProblem, opts: WearOptions, st: SlowStep, anchor, attempt, jumps,
           counts, error=None):
    """The acceptance loop of a slow step from ``st`` (:func:`advance` and
    :func:`fretwear.wear.exponential_step.exponential_step`): ``attempt(dN) -> (W1, U1,
    stats)`` tries a jump of ``dN`` cycles; a failed balance is retried with the jump divided
    by 4 (up to ``max_retries`` times, not below ``fail_floor``); with ``adaptive``, a step
    whose error estimate exceeds the tolerance is retried with the jump the controller
    proposes (not below ``floor``). ``jumps`` = ``(dN, floor, fail_floor)``, ``counts`` =
    ``(t0, iterations, rejected)`` so far. ``error`` = ``(estimate, order)``: the local error
    estimate ``estimate(dN, W1, g1)`` of a scheme of that order (the jump scales with its
    ``order + 1``-th root); None: the first-order defect of :func:`local_error`. Returns
    ``(new_state, record, "")`` or ``(None, None, message)``."""
    dN, floor, fail_floor = jumps
    t0, iters, rejected = counts
    if error is None:
        error = (lambda dn, W1, g1: local_error(dn, W1, st.W, g1, st.g), 1)
    estimate, order = error
    failures = 0
    while True:
        W1, U1, stats = attempt(dN)
        iters += stats.iterations
        if not stats.success:
            failures += 1
            rejected += 1
            if failures > opts.max_retries or dN <= fail_floor:
                return None, None, (f"{stats.message} at N = {st.cycles:.4g} with a "
                                    f"jump of {dN:.3g} cycles after {failures} attempts")
            dN = max(dN / 4.0, fail_floor)
            continue
        sp.set_state(W1, anchor)
        g1 = sp.rate(U1)
        err = estimate(dN, W1, g1)
        if opts.adaptive and err > opts.tolerance and dN > floor:
            rejected += 1
            dN = max(dN * max(0.1, 0.9 * root(opts.tolerance / err, order)), floor)
            continue
        break
    # no growth right after a failed solve (stiff ODE practice)
    jump = next_jump(dN, err, opts, st.jump, 1.0 if failures else 5.0, order)
    sol = sp.solution(U1, W1, anchor, stats)
    record = StepRecord.balanced(sol, W1, g1, StepStats(st.cycles + dN, dN, iters, rejected,
                                                        err, time.perf_counter() - t0))
    return SlowStep.balanced(record, jump, st), record, ""


def _attempt(sp: SlowProblem, opts: WearOptions, start: StepStart, dN: float, lin):
    """One try of a slow step of ``dN`` cycles from ``start``: ``(W1, U1, stats)``; ``lin``
    the slow Jacobian ``Js`` (nc, nc) and ``dU~/dW`` (n, nc) at the start (None for the
    explicit scheme).

    explicit (eq. 30): ``W1 = W_k + dN g_k``, then the balance at ``W1``;
    rosenbrock: ``W1 = W_k + dN (I - dN Js)^-1 g_k``, then the balance at ``W1``;
    implicit: backward Euler from the Rosenbrock predictor (:class:`_BackwardEuler`, or the
    Newton method on the coupled unknowns ``(U~, W1)`` when ``implicit_newton = "coupled"``).
    """
    kw = {"options": opts.solve}
    W_k, U_k, anchor = start.W, start.U, start.anchor
    if opts.scheme == "explicit":
        W1 = W_k + dN * start.g
        U1, stats = sp.solve_balance(W1, anchor, sp.shift_guess(U_k, W1 - W_k), **kw)
        return W1, U1, stats
    Js, dUdW = lin
    dW = dN * np.linalg.solve(np.eye(sp.nc) - dN * Js, start.g)
    dW = np.maximum(dW, 0.0)  # a node's wear never decreases (g >= 0)
    if opts.scheme == "rosenbrock":
        return balance_after(sp, opts, start, dW, dUdW)
    Wp = W_k + dW  # the predictor of the implicit step
    Up = U_k + (dUdW @ dW).reshape(sp.m, sp.H)
    if opts.implicit_newton == "coupled":
        kw["options"] = opts.solve.replace(max_iter=opts.max_iter_coupled)
        U1, W1, stats = sp.solve_implicit(W_k, dN, anchor, Up, Wp, **kw)
        return W1, U1, stats
    return _BackwardEuler(sp, opts, start, dN).solve(Wp, Up, lin)


def balance_after(sp: SlowProblem, opts: WearOptions, start: StepStart, dW: np.ndarray,
                  dUdW: np.ndarray):
    """``(W1, U1, stats)``: the balance at ``W1 = W_k + dW`` from the predictor
    ``U_k + dU~/dW dW``, else from the previous balance shifted by the wear
    (:meth:`SlowProblem.shift_guess`); ``stats.iterations`` counts both solves. The end of a
    linearly implicit (rosenbrock) or exponential step."""
    W1 = start.W + dW
    U1, stats = sp.solve_balance(W1, start.anchor,
                                 start.U + (dUdW @ dW).reshape(sp.m, sp.H), options=opts.solve)
    if not stats.success:
        its = stats.iterations
        U1, stats = sp.solve_balance(W1, start.anchor, sp.shift_guess(start.U, dW),
                                     options=opts.solve)
        stats.iterations += its
    return W1, U1, stats


class _BackwardEuler:
    """Backward Euler ``W1 = W_k + dN g(W1)`` by a damped Newton method on ``W``, for one
    step of ``dN`` cycles from ``start`` (:class:`StepStart`).

    Every iterate is a converged periodic balance at its ``W`` (the ordinary DLFT solve,
    warm-started), so no unbalanced state is ever returned. The BE defect
    ``r = W - W_k - dN g(W)`` is reduced with the iteration matrix ``I - dN Js``: frozen while
    the defect contracts well, refreshed at the current iterate otherwise, with backtracking
    when a full step does not decrease ``max|r|``. It stops when
    ``max|r| <= 0.1 tolerance max W`` (the algebraic error an order below the local error
    allowed, as in stiff ODE codes). ``g`` is only piecewise smooth (contact states switch),
    and the iteration can stall at a kink: the best iterate is then returned if
    ``max|r| <= 0.5 tolerance max W``. The step's error estimate (:func:`local_error`) contains
    ``r``, so the error test judges such a step.
    """

    def __init__(self, sp: SlowProblem, opts: WearOptions, start: StepStart, dN: float):
        self.sp, self.opts, self.start, self.dN = sp, opts, start, dN
        self.kw = {"options": opts.solve}
        self.its = 0  # nonlinear iterations, slow Jacobians included

    def evaluate(self, W, U):
        """The balance at ``W`` from ``U`` and the BE defect there: ``(U, r, max|r|,
        residual)``, or None when the balance fails (also from the start's balance)."""
        sp, start = self.sp, self.start
        U1, st = sp.solve_balance(W, start.anchor, U, **self.kw)
        self.its += st.iterations
        if not st.success:  # retry from the previous balance, shifted by the wear change
            U1, st = sp.solve_balance(W, start.anchor, sp.shift_guess(start.U, W - start.W),
                                      **self.kw)
            self.its += st.iterations
        if not st.success:
            return None
        U = U1
        r = W - start.W - self.dN * sp.rate(U)
        return U, r, float(np.max(np.abs(r))), st.residual

    def matrix(self, U):
        """The iteration matrix ``I - dN Js`` and ``dU~/dW`` at the balance ``U``."""
        Js, dUdW = self.sp.slow_jacobian(U, with_dUdW=True)
        self.its += 1
        return np.eye(self.sp.nc) - self.dN * Js, dUdW

    def backtrack(self, W, U, dW, dUdW, rn):
        """The Newton step ``dW`` from ``(W, U)``, halved until ``max|r|`` decreases (at most
        4 tries): ``(W_try, evaluation)``, or None."""
        t = 1.0
        for _ls in range(4):
            W_try = np.maximum(W + t * dW, self.start.W)  # BE keeps W1 >= W_k since g >= 0
            ev = self.evaluate(W_try, U + (dUdW @ (W_try - W)).reshape(self.sp.m, self.sp.H))
            if ev is not None and ev[2] < (1.0 - 1e-4 * t) * rn:
                return W_try, ev
            t *= 0.5
        return None

    def solve(self, W, U, lin):
        """The step from the predictor ``(W, U)`` with the linearization ``lin = (Js, dUdW)``
        at the start: ``(W1, U1, stats)``; ``stats.success`` is False when the balance or
        the iteration fails."""
        t0 = time.perf_counter()
        opts, sp = self.opts, self.sp
        msg = "backward Euler iteration did not converge"
        ev = self.evaluate(W, U)
        if ev is None:
            return W, U, SolveStats(False, math.inf, self.its, 0, 0, time.perf_counter() - t0,
                                    "balance failed at the predictor", opts.solve.solver)
        U, r, rn, res = ev
        best = (rn, W, U, res)
        Js, dUdW = lin
        M = np.eye(sp.nc) - self.dN * Js
        fresh = True
        for _k in range(opts.max_iter_implicit):
            if rn <= 0.1 * opts.tolerance * max(float(np.max(W)), 1e-300):
                break
            tried = self.backtrack(W, U, -np.linalg.solve(M, r), dUdW, rn)
            if tried is None:
                if fresh:
                    msg = "backward Euler iteration stalled (no decrease of the defect)"
                    break
                M, dUdW = self.matrix(U)  # retry with a fresh Jacobian
                fresh = True
                continue
            contraction = tried[1][2] / rn
            W, (U, r, rn, res) = tried
            if rn < best[0]:
                best = (rn, W, U, res)
            fresh = contraction > 0.5
            if fresh:  # poor contraction: Jacobian at the new iterate
                M, dUdW = self.matrix(U)
        rn, W, U, res = best
        ok = rn <= 0.5 * opts.tolerance * max(float(np.max(W)), 1e-300)
        return W, U, SolveStats(ok, res if ok else math.inf, self.its, 0, 0,
                                time.perf_counter() - t0, "converged" if ok else msg,
                                opts.solve.solver)
