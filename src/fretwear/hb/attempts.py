"""The attempts of a periodic solve: one solver run (:func:`_run`), the ladder of a single
solve (:func:`solve_strategy`), the continuation in the penalty (:func:`_eps_path`), the start
from the first harmonic alone (:func:`_first_harmonic_start`) and from a time integration
(:func:`_time_start`).
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from fretwear.hb.connectors import Connected
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import PERIODIC, SolveOptions
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.solution import Attempt
from fretwear.hb.solvers import SolveStats, solve, vector_norm
from fretwear.model.core import Model

#: penalties tried by the eps continuation, as factors of the target eps, and the number of
#: geometric steps back to the target (the first try: a failed step is halved in log eps)
EPS_FACTORS = (10.0, 0.1)
EPS_STEPS = 4
#: the eps continuation gives up when a step would be smaller than this ratio of penalties
EPS_MIN_RATIO = 1.02
#: iterations allowed to one step of the eps continuation (it starts from the answer at a
#: nearby eps: a step that needs more is better halved)
EPS_STEP_MAX_ITER = 20


def _eps_path(prob, x, st, eps_from, options: SolveOptions):
    """From the converged ``x`` at ``eps_from`` back to ``prob.eps`` by geometric steps: a
    step that fails is halved (in log eps) and retried from the last converged answer, a step
    that converges grows by 1.5, until ``prob.eps`` is reached or a step would be below
    :data:`EPS_MIN_RATIO`. On the paper's beam at 79.34 kHz the four equal steps from 10 eps
    failed where steps of 10 % converge in 3-4 iterations each (docs/studies/eps-rule.md).
    Returns ``(x, stats, path)``: ``path`` the penalties of the converged answers and, last,
    that of the failed step if it did not reach ``prob.eps``."""
    target = float(prob.eps)
    cur = float(eps_from)
    step = np.log(target / cur) / EPS_STEPS
    path = [cur]
    while cur != target:
        remaining = np.log(target / cur)
        last = abs(remaining) <= abs(step) * (1.0 + 1e-12)
        e = target if last else float(cur * np.exp(step))
        xn, stn = _run(prob if last else prob.with_eps(e), x,
                       options.replace(max_iter=min(options.max_iter, EPS_STEP_MAX_ITER)))
        if stn.success:
            cur, x, st = e, xn, stn
            path.append(e)
            step *= 1.5
            continue
        step *= 0.5
        if abs(step) < np.log(EPS_MIN_RATIO):
            path.append(e)
            return xn, stn, path
    return x, st, path


def _run(prob: DLFTProblem, x0, options: SolveOptions):
    """One run of ``options.solver`` on ``prob`` from ``x0`` (m, H): ``(x (m, H), stats)``."""

    def fun(x, jac=True):
        return prob.residual(x.reshape(prob.m, prob.H), jac)

    t0 = time.perf_counter()
    x, _, st = solve(fun, np.asarray(x0, float).reshape(-1),
                     lambda x: prob.scale(x.reshape(prob.m, prob.H)), method=options.solver,
                     tol=options.tol, max_iter=options.max_iter)
    st.wall_time = time.perf_counter() - t0
    return x.reshape(prob.m, prob.H), st


def solve_strategy(prob: DLFTProblem, x0, *, options: SolveOptions = PERIODIC,
                   attempts: list | None = None, steps=None):
    """Solve the balance of ``prob`` from ``x0`` (m, H), trying in order until one converges
    (``steps``, default ``options.strategy``):

    1. ``"start"``: ``solver`` from ``x0``;
    2. ``"best-point"``: the other solver (Newton after Powell, Powell after Newton or hybr)
       from the best iterate so far (Newton converges where Powell's trust region stalls, and
       the reverse, on the paper's beam);
    3. ``"eps-continuation"``: the balance at ``10 eps`` (then ``eps / 10``) from ``x0`` (the
       solver, then the other one, then the solver from the first harmonic alone at that
       eps), and from there geometric steps back to ``eps`` (:func:`_eps_path`: halved where
       one fails), each starting from the previous answer: the answer is that of the target
       eps (no eps jump);
    4. ``"harmonic-continuation"``: the first harmonic alone from the contact-closed guess,
       then all harmonics from it.

    Every attempt is appended to ``attempts`` (:class:`Attempt`). Returns ``(x, stats)``: the
    converged answer, or the iterate with the smallest residual when none converged.
    """
    attempts = [] if attempts is None else attempts
    steps = options.strategy if steps is None else steps
    solver = options.solver
    other = options.replace(solver=options.other_solver)
    best = None

    def keep(x, st):
        nonlocal best
        if best is None or st.success or st.residual < best[1].residual:
            best = (x, st)
        return st.success

    x0 = np.asarray(x0, float).reshape(prob.m, prob.H)
    if "start" in steps:
        x, st = _run(prob, x0, options)
        attempts.append(Attempt.of("start", prob.eps, st))
        if keep(x, st):
            return best
    if "best-point" in steps:
        start = x0 if best is None else best[0]
        x, st = _run(prob, start, other)
        attempts.append(Attempt.of("best-point", prob.eps, st))
        if keep(x, st):
            return best
    if "eps-continuation" in steps:
        for factor in EPS_FACTORS:
            t0 = time.perf_counter()
            shifted = prob.with_eps(factor * prob.eps)
            x, st = _run(shifted, x0, options)
            if not st.success:  # the other solver at the shifted eps
                x, st = _run(shifted, x0, other)
            if not st.success and prob.basis.k > 1:  # the first harmonic alone, at that eps
                U1 = _first_harmonic_start(shifted, options)
                if U1 is not None:
                    x, st = _run(shifted, U1, options)
            path = [factor * prob.eps]
            if st.success:
                x, st, path = _eps_path(prob, x, st, factor * prob.eps, options)
            st.wall_time = time.perf_counter() - t0
            msg = (f"{st.message} (eps path {', '.join(f'{e:.3g}' for e in path)} N/m)")
            attempts.append(Attempt.of("eps-continuation", prob.eps if st.success else
                                       path[-1], st, msg))
            if st.success and path[-1] == prob.eps:
                keep(x, st)
                return best
    if "harmonic-continuation" in steps and prob.basis.k > 1:
        t0 = time.perf_counter()
        U1 = _first_harmonic_start(prob, options)
        if U1 is not None:
            x, st = _run(prob, U1, options)
            st.wall_time = time.perf_counter() - t0
            attempts.append(Attempt.of("harmonic-continuation", prob.eps, st))
            if keep(x, st):
                return best
        else:
            attempts.append(Attempt("harmonic-continuation", solver, prob.eps, False,
                                    float("nan"), 0, time.perf_counter() - t0,
                                    "the first harmonic alone did not converge"))
    if best is None:  # nothing ran at the target eps: the start, unconverged
        tried = ", ".join(a.method for a in attempts) or "none"
        x0 = np.asarray(x0, float).reshape(prob.m, prob.H)
        f, _ = prob.residual(x0, False)  # the start's relative residual, as the solvers give
        rel = float(vector_norm(f) / max(prob.scale(x0), 1e-300))
        best = (x0, SolveStats(False, rel, 0, 1, 0, 0.0, f"no attempt converged ({tried})",
                               solver))
    return best


def _time_start_applies(model: Model, time_domain, quasi_static: bool, gap, strategy) -> bool:
    if time_domain is None or quasi_static or "time-start" not in strategy:
        return False
    if model.contact.has_connectors:  # the time-domain solver has rigid contacts only
        return False
    return gap is None or np.array_equal(np.broadcast_to(np.asarray(gap, float),
                                                         model.contact.gap.shape),
                                         model.contact.gap)


def _time_start(model, basis, frequency, reduced, prob, time_domain, options: SolveOptions):
    """The ``"time-start"`` attempt: ``(message, problem, x, stats)``; ``stats`` None when
    the integration did not settle to a periodic state (the message says what it does)."""
    t0 = time.perf_counter()
    msg, Ut, anchor = time_domain.start(model, frequency, basis, None,
                                        max_periods=options.time_domain_periods)
    if Ut is None:
        return msg, prob, None, None
    prob2 = DLFTProblem(reduced, model.contact, basis, gap=prob.gap, eps=prob.eps,
                        anchor=anchor, jacobian=prob.jacobian)
    x, st = _run(prob2, np.asarray(Ut, float).reshape(prob2.m, prob2.H),
                 options.replace(max_iter=2 * options.max_iter))
    st.wall_time = time.perf_counter() - t0
    return msg, prob2, x, st


def _first_harmonic_start(prob, options: SolveOptions):
    """:func:`_harmonic_continuation_start` from the problem alone."""
    basis, reduced = prob.basis, prob.reduced
    sub = FourierBasis(basis.harmonics[:1], basis.n_samples)
    cut = {k: getattr(reduced, k)[:2] for k in ("orders", "Z", "F", "obs_A", "obs_b")}
    if isinstance(reduced, Connected):  # already seen through the contact springs
        cut.update(node_A=reduced.node_A[:2], node_b=reduced.node_b[:2])
    red = dataclasses.replace(reduced, **cut)
    p1 = DLFTProblem(red, prob.contact, sub, gap=prob.gap, eps=prob.eps, anchor=prob.anchor)
    if p1.jacobian == "krylov":  # the full problem's blocks (and their real copies), shared
        p1.blocks = prob.blocks.leading(2)

    def fun(x, jac=True):
        return p1.residual(x.reshape(p1.m, p1.H), jac)

    x, _, st = solve(fun, p1.initial_guess().reshape(-1),
                     lambda x: p1.scale(x.reshape(p1.m, p1.H)), method=options.solver,
                     tol=options.tol, max_iter=options.max_iter)
    if not st.success:
        return None
    U = np.zeros((prob.m, prob.H))
    x = x.reshape(p1.m, p1.H)
    U[:, 0] = x[:, 0]
    U[:, 1] = x[:, 1]
    U[:, 1 + basis.k] = x[:, 2]
    return U

