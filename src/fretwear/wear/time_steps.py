"""Slow steps taken from a time integration, where the periodic balance fails (dynamic cases):
the first state of a run whose unworn interface has no balance, the steps after a failed
balance (back to the DLFT as soon as a balance converges), and the predictor matrix of those
steps (:func:`without_growth`).

The time integration is the :class:`~fretwear.hb.fallback.TimeDomainFallback` the driver is
given (``SlowProblem.time_domain``); this package never imports the time-domain solver.
"""

from __future__ import annotations

import math
import time

import numpy as np

from fretwear.errors import ConvergenceError
from fretwear.hb.solution import initial_state
from fretwear.hb.solvers import SolveStats
from fretwear.wear.options import (
    BALANCE_KINDS,
    MIN_JUMP_FRACTION,
    RESCUE_MAX_ITER,
    START_JUMP,
    START_SETTLE,
    WearOptions,
)
from fretwear.wear.slow_problem import SlowProblem
from fretwear.wear.state import Rescue, SlowStep, StepRecord, StepStats
from fretwear.wear.step_control import local_error, next_jump


def time_domain_start(sp: SlowProblem, wear0, opts: WearOptions, st: SolveStats, t0: float
                      ) -> tuple[SlowStep, list[StepRecord]]:
    """Step 0 from a time integration when the unworn interface has no periodic balance
    (dynamic cases; e.g. a subharmonic or quasi-periodic response): the structure is integrated
    from rest for ``START_SETTLE`` periods, then its wear rate is averaged as in
    :func:`time_domain_step`, and the run goes on with time-domain steps (which go back to the
    DLFT as soon as a balance converges). The first jump is ``initial_jump``, default
    ``START_JUMP`` cycles (no slow Jacobian without a balance; the error control adapts it).
    ``wear0`` (nc,) [m] the initial wear depths; ``st`` the failed solve; ``t0`` the start
    time of the step [s]."""
    tr = sp.time_domain.averaged_rate(sp.model, sp.prob.reduced.frequency, sp.prob.basis,
                                      sp.coef, wear0, U0=None, V0=None,
                                      settle=max(opts.time_domain_settle, START_SETTLE),
                                      average=opts.time_domain_average,
                                      steps_per_period=opts.time_domain_steps)
    record = StepRecord.time_averaged(tr, sp.model.contact.area, wear0, StepStats(
        0.0, 0.0, st.iterations, 1, 0.0, time.perf_counter() - t0))
    jump = float(opts.initial_jump) if opts.initial_jump is not None else START_JUMP
    return SlowStep.time_averaged(record, jump, (tr.U_end, tr.V_end)), [record]


def time_domain_step(sp: SlowProblem, st: SlowStep, opts: WearOptions):
    """A slow step taken from a time integration: ``(state, record, failure)``.

    Used where the periodic balance fails (dynamic cases). The wear is advanced from the rate at
    the start of the step: by explicit Euler (eq. 30), ``W1 = W_k + dN g_k``, with
    ``scheme = "explicit"``; otherwise by the linearly implicit predictor
    ``W1 = W_k + dN (I - dN Js+)^-1 g_k`` with ``Js+`` the slow Jacobian of the last balanced
    state (no balance, no fresher one) without its growing modes (:func:`without_growth`; a
    W-method: first order with any matrix). The stiff part of ``Js`` is local (wear unloads the
    node that slips) and changes little, and without it the jumps stay at the explicit
    stability limit with rates that flip from step to step. Then the
    structure is integrated in time at ``W1``
    (:func:`fretwear.timedomain.averaged_rate.time_averaged_rate`),
    continuing the previous time integration when there is one (so that the transient and the
    slow drift of the mean position carry over), else from the last periodic solution. The rate
    at ``W1`` is the mean of Archard's integrand over ``time_domain_average`` periods; the
    error test compares it with ``g_k`` as for every step (:func:`local_error`), and a rejected jump
    is retried smaller.

    Unless the integrated response is clearly not periodic (subharmonic, quasi-periodic,
    irregular), the balance at ``W1`` is tried from the harmonics of its last period
    with its mean tangential positions as stick anchors (the history selects where nodes that
    stop slipping stick): if it converges and passes the error test the step is an ordinary
    balanced step (:attr:`Rescue.TIME_START`) and the next step goes back to the DLFT.
    Otherwise the step keeps the time-averaged rate (:attr:`Rescue.TIME_AVERAGED`), and so do
    the next steps until the balance converges again. A balance that failed is not retried
    before the cycle count has doubled (each try costs up to hundreds of iterations).
    """
    t0 = time.perf_counter()
    W_k, g_k, cycles = st.W, st.g, st.cycles
    if st.in_time_integration:
        U0, V0 = st.time_U, st.time_V
    else:
        last = sp.solution(st.U, W_k, st.anchor, SolveStats(True, 0.0, 0, 0, 0, 0.0, "", ""))
        U0, V0 = initial_state(sp.model, last, sp.condenser)
    dN = min(st.jump, opts.max_jump, opts.max_cycles - cycles)
    floor = max(opts.min_jump, MIN_JUMP_FRACTION * cycles)
    rejected = iters = 0
    Js = np.asarray(st.Js, float)
    if opts.scheme != "explicit" and Js.size == 0 and not st.in_time_integration:
        sp.set_state(W_k, st.anchor)  # the last balanced state: its slow Jacobian
        Js = sp.slow_jacobian(st.U)
        iters += 1
    if Js.size:
        # Js is the Jacobian of an older (balanced) state: its growing modes are not those of
        # the current wear and must not cap the jump. Without them the predictor is explicit
        # Euler along those modes and linearly implicit along the others (a W-method).
        Js = without_growth(Js)
    while True:
        if Js.size:  # linearly implicit (the scheme's predictor) with that Jacobian
            W1 = W_k + np.maximum(dN * np.linalg.solve(np.eye(sp.nc) - dN * Js, g_k), 0.0)
        else:
            W1 = W_k + dN * g_k
        try:
            tr = sp.time_domain.averaged_rate(sp.model, sp.prob.reduced.frequency, sp.prob.basis,
                                              sp.coef, W1, U0=U0, V0=V0,
                                              settle=opts.time_domain_settle,
                                              average=opts.time_domain_average,
                                              steps_per_period=opts.time_domain_steps)
        except ConvergenceError as exc:
            return None, None, f"time integration at N + {dN:.3g}: {exc}"
        err = local_error(dN, W1, W_k, tr.g, g_k)
        if opts.adaptive and err > opts.tolerance and dN > floor:
            rejected += 1
            dN = max(dN * max(0.1, 0.9 * math.sqrt(opts.tolerance / err)), floor)
            continue
        break
    cycles1 = cycles + dN
    retry_at = st.retry_balance_at
    if tr.kind in BALANCE_KINDS and cycles1 >= retry_at:
        U1, stats = sp.solve_balance(W1, tr.anchor, tr.U.reshape(sp.m, sp.H),
                                     options=opts.solve.replace(
                                         max_iter=max(opts.solve.max_iter, RESCUE_MAX_ITER)))
        iters += stats.iterations
        if stats.success:
            sp.set_state(W1, tr.anchor)
            g1 = sp.rate(U1)
            err_b = local_error(dN, W1, W_k, g1, g_k)
            if not opts.adaptive or err_b <= opts.tolerance:
                sol = sp.solution(U1, W1, tr.anchor, stats)
                record = StepRecord.balanced(
                    sol, W1, g1, StepStats(cycles1, dN, iters, rejected, err_b,
                                           time.perf_counter() - t0),
                    rescued=Rescue.TIME_START, response=tr.kind_code)
                jump = next_jump(dN, err_b, opts, st.jump, 1.0)
                return SlowStep.balanced(record, jump, st), record, ""
        retry_at = 2.0 * cycles1
    record = StepRecord.time_averaged(tr, sp.model.contact.area, W1, StepStats(
        cycles1, dN, iters, rejected, err, time.perf_counter() - t0))
    jump = next_jump(dN, err, opts, st.jump)
    return (SlowStep.time_averaged(record, jump, (tr.U_end, tr.V_end), st, Js=Js,
                                   retry_balance_at=retry_at), record, "")


def without_growth(Js: np.ndarray, max_condition: float = 1e8) -> np.ndarray:
    """``Js`` with the real part of every eigenvalue ``mu`` with ``Re mu > 0`` set to zero,
    eigenvectors unchanged: ``Js - V diag(max(Re mu, 0)) V^-1`` (real: conjugate pairs get
    the same shift).

    Used as the matrix of the linearly implicit predictor of time-domain steps (an old slow
    Jacobian): along a growing mode the step is then explicit Euler, along every other mode it
    is the linearly implicit step with the mode's own eigenvalue, so neutral and decaying
    modes keep their accuracy and ``I - dN Js+`` is never singular. Where the eigenvectors are
    too ill-conditioned for the projection (``cond V > max_condition``) the whole matrix is
    shifted by the largest growth rate instead (stable, but it damps every mode by
    ``1 / (1 + dN lam_+)``: a first-order error that the error test sees).
    """
    Js = np.asarray(Js, float)
    mu, V = np.linalg.eig(Js)
    shift = np.maximum(mu.real, 0.0)
    if not np.any(shift > 0):
        return Js
    if np.linalg.cond(V) > max_condition:
        return Js - float(shift.max()) * np.eye(Js.shape[0])
    return (Js - (V * shift) @ np.linalg.inv(V)).real
