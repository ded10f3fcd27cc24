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

import numpy as np

from fretwear.errors import ConvergenceError, InputError
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.solvers import SolveStats
from fretwear.wear.history import solution_row
from fretwear.wear.options import (
    GROWTH_LIMIT,
    MIN_JUMP_FRACTION,
    RESCUE_START_FRACTION,
    WearOptions,
)
from fretwear.wear.slow_problem import SlowProblem
from fretwear.wear.step_control import local_error, next_jump
from fretwear.wear.time_steps import time_domain_start


def first_state(sp: SlowProblem, W0, anchor, U0, opts: WearOptions) -> tuple[dict, list[dict]]:
    """The balanced initial state (step 0)."""
    t0 = time.perf_counter()
    sp.set_state(W0, anchor)
    # the first balance goes through solve_periodic (its start strategies for a cold start);
    # its attempts are opts.solve.strategy, by default the solver alone (WEAR_STEP): a wear
    # run has its own fallback (a start from a time integration), and its examples are
    # validated with it (the further attempts of solve_periodic find a balance of the 79 kHz
    # reduced example that the time-domain start replaces today)
    first = opts.solve.replace(max_iter=max(opts.solve.max_iter, 200))
    sol0 = solve_periodic(sp.model, sp.prob.basis, frequency=sp.prob.reduced.frequency,
                          quasi_static=sp.prob.reduced.quasi_static, options=first,
                          reduced=sp.prob.reduced, gap=sp.gap0 + W0, eps=sp.eps,
                          anchor=anchor, U0=U0)
    st = sol0.stats
    if not sol0.success:
        if sp.time_domain is not None:
            return time_domain_start(sp, W0, opts, st, t0)
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
    sol = sp.solution(U, W0, anchor, st)
    row = solution_row(sol, W0, g, 0.0, 0.0, st.iterations, 0, 0.0, time.perf_counter() - t0)
    state = {
        "step": 0, "cycles": 0.0, "W": np.array(W0, float), "U": U.copy(),
        "anchor": np.array(anchor, float), "g": g, "jump": float(jump),
        "vrate": row["volume_rate"], "vrate0": row["volume_rate"],
        "stability_jump": float(stab), "stop_reason": np.asarray(""),
        "td_U": np.zeros(0), "td_V": np.zeros(0), "td_retry_at": 0.0, "Js": np.zeros(0),
    }
    return state, [row]


def advance(sp: SlowProblem, st: dict, opts: WearOptions):
    """One accepted slow step from state ``st``: ``(new_state, row, failure_message)``.

    Retries a failed solve with the jump divided by 4 (up to ``max_retries`` times, not below
    ``min_jump``); with ``adaptive``, rejects a step whose error estimate exceeds the
    tolerance and retries with the jump the controller proposes.
    """
    t0 = time.perf_counter()
    W_k, U_k, g_k = st["W"], st["U"], st["g"]
    anchor = U_k.reshape(sp.nc, sp.d, sp.H)[:, 1:, 0].copy()  # history rule: previous mean
    dN = min(float(st["jump"]), opts.max_jump, opts.max_cycles - float(st["cycles"]))
    floor = max(opts.min_jump, MIN_JUMP_FRACTION * float(st["cycles"]))  # error control
    rescue = sp.time_domain is not None
    # failed solves: with a time-domain rescue behind, stop cutting where the rescue starts
    fail_floor = max(floor, RESCUE_START_FRACTION * float(st["cycles"])) if rescue else floor
    iters = rejected = failures = 0
    lin = None
    if opts.scheme != "explicit":
        sp.set_state(W_k, anchor)
        lin = sp.slow_jacobian(U_k, with_dUdW=True)  # Js, dU/dW at the start of the step
        iters += 1
        # a growing mode (eigenvalue lam > 0: wear moving load onto a neighbour) is only
        # followed accurately with dN lam small, and I - dN Js is singular at dN lam = 1
        lam_plus = float(np.max(np.linalg.eigvals(lin[0]).real))
        if lam_plus > 0:
            dN = min(dN, GROWTH_LIMIT / lam_plus)
    while True:
        W1, U1, stats = _attempt(sp, opts, W_k, U_k, g_k, anchor, dN, lin)
        iters += stats.iterations
        if not stats.success:
            failures += 1
            rejected += 1
            if failures > opts.max_retries or dN <= fail_floor:
                return None, None, (f"{stats.message} at N = {float(st['cycles']):.4g} with a "
                                    f"jump of {dN:.3g} cycles after {failures} attempts")
            dN = max(dN / 4.0, fail_floor)
            continue
        sp.set_state(W1, anchor)
        g1 = sp.rate(U1)
        err = local_error(dN, W1, W_k, g1, g_k)
        if opts.adaptive and err > opts.tolerance and dN > floor:
            rejected += 1
            dN = max(dN * max(0.1, 0.9 * math.sqrt(opts.tolerance / err)), floor)
            continue
        break
    # no growth right after a failed solve (stiff ODE practice)
    jump = next_jump(dN, err, opts, float(st["jump"]), 1.0 if failures else 5.0)
    sol = sp.solution(U1, W1, anchor, stats)
    cycles = float(st["cycles"]) + dN
    row = solution_row(sol, W1, g1, cycles, dN, iters, rejected, err, time.perf_counter() - t0)
    new = dict(st)
    new.update({"step": int(st["step"]) + 1, "cycles": cycles, "W": np.array(W1, float),
                "U": U1.copy(), "anchor": anchor, "g": g1, "jump": float(jump),
                "vrate": row["volume_rate"]})
    return new, row, ""


def _attempt(sp: SlowProblem, opts: WearOptions, W_k, U_k, g_k, anchor, dN, lin):
    """One try of a slow step of ``dN`` cycles: ``(W1, U1, stats)``.

    explicit (eq. 30): ``W1 = W_k + dN g_k``, then the balance at ``W1``;
    rosenbrock: ``W1 = W_k + dN (I - dN Js)^-1 g_k``, then the balance at ``W1``;
    implicit: backward Euler from the Rosenbrock predictor (:func:`_backward_euler`, or the
    Newton method on the coupled unknowns ``(U~, W1)`` when ``implicit_newton = "coupled"``).
    """
    kw = {"options": opts.solve}
    if opts.scheme == "explicit":
        W1 = W_k + dN * g_k
        U1, stats = sp.solve_balance(W1, anchor, sp.shift_guess(U_k, W1 - W_k), **kw)
        return W1, U1, stats
    Js, dUdW = lin
    dW = dN * np.linalg.solve(np.eye(sp.nc) - dN * Js, g_k)
    dW = np.maximum(dW, 0.0)  # a node's wear never decreases (g >= 0)
    Wp = W_k + dW
    Up = U_k + (dUdW @ dW).reshape(sp.m, sp.H)
    if opts.scheme == "rosenbrock":
        U1, stats = sp.solve_balance(Wp, anchor, Up, **kw)
        if not stats.success:
            its = stats.iterations
            U1, stats = sp.solve_balance(Wp, anchor, sp.shift_guess(U_k, dW), **kw)
            stats.iterations += its
        return Wp, U1, stats
    if opts.implicit_newton == "coupled":
        kw["options"] = opts.solve.replace(max_iter=opts.max_iter_coupled)
        U1, W1, stats = sp.solve_implicit(W_k, dN, anchor, Up, Wp, **kw)
        return W1, U1, stats
    return _backward_euler(sp, opts, W_k, U_k, dN, anchor, Up, Wp, Js, dUdW)


def _backward_euler(sp: SlowProblem, opts: WearOptions, W_k, U_start, dN, anchor, U, W, Js,
                    dUdW):
    """Backward Euler ``W1 = W_k + dN g(W1)`` by a damped Newton method on ``W``.

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

    Returns ``(W1, U1, stats)``; ``stats.success`` is False when the balance or the
    iteration fails.
    """
    t0 = time.perf_counter()
    kw = {"options": opts.solve}
    its = 0
    msg = "backward Euler iteration did not converge"

    def evaluate(W, U):
        nonlocal its
        U1, st = sp.solve_balance(W, anchor, U, **kw)
        its += st.iterations
        if not st.success:  # retry from the previous balance, shifted by the wear change
            U1, st = sp.solve_balance(W, anchor, sp.shift_guess(U_start, W - W_k), **kw)
            its += st.iterations
        if not st.success:
            return None
        U = U1
        r = W - W_k - dN * sp.rate(U)
        return U, r, float(np.max(np.abs(r))), st.residual

    ev = evaluate(W, U)
    if ev is None:
        return W, U, SolveStats(False, math.inf, its, 0, 0, time.perf_counter() - t0,
                                "balance failed at the predictor", opts.solve.solver)
    U, r, rn, res = ev
    best = (rn, W, U, res)
    M = np.eye(sp.nc) - dN * Js
    fresh = True
    for _k in range(opts.max_iter_implicit):
        if rn <= 0.1 * opts.tolerance * max(float(np.max(W)), 1e-300):
            break
        dW = -np.linalg.solve(M, r)
        t, accepted = 1.0, False
        for _ls in range(4):
            W_try = np.maximum(W + t * dW, W_k)  # BE keeps W1 >= W_k since g >= 0
            ev = evaluate(W_try, U + (dUdW @ (W_try - W)).reshape(sp.m, sp.H))
            if ev is not None and ev[2] < (1.0 - 1e-4 * t) * rn:
                accepted = True
                break
            t *= 0.5
        if not accepted:
            if fresh:
                msg = "backward Euler iteration stalled (no decrease of the defect)"
                break
            Js, dUdW = sp.slow_jacobian(U, with_dUdW=True)  # retry with a fresh Jacobian
            its += 1
            M = np.eye(sp.nc) - dN * Js
            fresh = True
            continue
        contraction = ev[2] / rn
        W, (U, r, rn, res) = W_try, ev
        if rn < best[0]:
            best = (rn, W, U, res)
        if contraction > 0.5:  # poor contraction: Jacobian at the new iterate
            Js, dUdW = sp.slow_jacobian(U, with_dUdW=True)
            its += 1
            M = np.eye(sp.nc) - dN * Js
            fresh = True
        else:
            fresh = False
    rn, W, U, res = best
    if rn <= 0.5 * opts.tolerance * max(float(np.max(W)), 1e-300):
        return W, U, SolveStats(True, res, its, 0, 0, time.perf_counter() - t0, "converged",
                                opts.solve.solver)
    return W, U, SolveStats(False, math.inf, its, 0, 0, time.perf_counter() - t0, msg,
                            opts.solve.solver)
