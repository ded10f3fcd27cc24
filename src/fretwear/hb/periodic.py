"""The periodic solve of the DLFT harmonic balance at one frequency (paper section 3.1-3.2):
:func:`solve_periodic` condenses the model, builds the balance (:mod:`fretwear.hb.problem`),
runs the attempt ladder (:mod:`fretwear.hb.attempts`) and assembles the result
(:mod:`fretwear.hb.solution`).
"""

from __future__ import annotations

import time

import numpy as np

from fretwear.errors import InputError
from fretwear.hb.attempts import (
    _first_harmonic_start,
    _time_start,
    _time_start_applies,
    solve_strategy,
)
from fretwear.hb.connectors import connect
from fretwear.hb.fallback import TimeDomainFallback
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.inputs import check_inputs
from fretwear.hb.options import PERIODIC, SolveOptions
from fretwear.hb.penalty import penalty
from fretwear.hb.preload import preload_anchor
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.reduce import Reduced, condense, exact_condenser
from fretwear.hb.solution import Attempt, PeriodicSolution, assemble_solution
from fretwear.model.core import Model


def _orders(basis):
    return np.array([0, *basis.harmonics], dtype=np.int64)


def solve_periodic(model: Model, basis: FourierBasis, *, frequency: float | None = None,
                   quasi_static: bool = False, options: SolveOptions = PERIODIC,
                   reduced: Reduced | None = None, gap=None, eps="auto", anchor=None, U0=None,
                   time_domain: TimeDomainFallback | None = None, raise_on_failure=False,
                   condenser=None) -> PeriodicSolution:
    """Periodic response of ``model`` at the excitation ``frequency`` [Hz] with the DLFT
    (section 3.1-3.2).

    Parameters
    ----------
    basis : kept harmonics and samples per period.
    frequency : excitation frequency [Hz], required; a ``quasi_static`` solve may omit it (it
        only scales time there: :data:`fretwear.hb.inputs.QUASI_STATIC_FREQUENCY`, a 1 s
        cycle, as case files).
    quasi_static : drop inertia and damping (slow cyclic loading).
    options : :class:`~fretwear.hb.options.SolveOptions` (default
        :data:`~fretwear.hb.options.PERIODIC`): ``solver`` (``"powell"``: dog-leg at LAPACK
        speed, ``"newton"`` or ``"hybr"``: MINPACK), ``tol`` (relative residual ``eps_r`` of
        the test ``|f| <= eps_r |Z_r U|``), ``max_iter``, ``strategy`` (the attempts made
        until one converges, each recorded in the result's ``attempts``; ``("start",)``: the
        solver alone), ``jacobian``, ``time_domain_periods``.
    reduced : a precomputed condensation on ``[0] + basis.harmonics`` (else computed here).
    gap : (nc,) gap + wear [m] (default: the model's initial gap).
    eps : DLFT penalty: ``"auto"`` (default) the spectral radius of ``Z_r`` over the kept
        harmonics (the paper), ``"static"`` that of the static ``K_r``, or a positive number
        [N/m] (:func:`fretwear.hb.penalty.penalty`).
    anchor : (nc, d-1) stick anchors [m]; default: the static preload state
        (:func:`~fretwear.hb.preload.preload_anchor`), the documented rule for the mean
        tangential position (when that static solve does not converge the anchors are 0 and
        ``warnings`` says so).
    U0 : (nc, d, H) starting point (e.g. a neighbouring solution).
    time_domain : a :class:`~fretwear.hb.fallback.TimeDomainFallback`
        (:data:`fretwear.timedomain.fallback.FALLBACK`, which :func:`fretwear.solve_periodic`
        passes by default; None: none). When every attempt before it failed, the rung
        ``"time-start"`` integrates in time from rest for at most
        ``options.time_domain_periods`` periods: a periodic steady state starts one more solve
        (its mean tangential positions as anchors); any other response (drifting,
        quasi-periodic, subharmonic) is what the result reports (``time_domain``, ``flags``):
        the solve then failed because there is no periodic state to find, or none the
        integration reached. Not with ``quasi_static``, a ``gap`` other than the model's,
        contact springs or prescribed normal loads (the time-domain solver models none of
        these).
    raise_on_failure : raise :class:`~fretwear.errors.ConvergenceError` when the solve does
        not converge instead of returning a solution with ``success`` False.
    condenser : the condenser of ``model`` (exact or modal) for every condensation of this
        solve (the balance's unless ``reduced`` is given, the preload's); default: one
        :func:`~fretwear.hb.reduce.exact_condenser`, built when needed.

    Returns
    -------
    :class:`~fretwear.hb.solution.PeriodicSolution`: ``success`` True when the balance
    converged; otherwise ``success`` False, ``message`` says why (``stats`` has the residual
    and counts) and the fields hold the last iterate (for inspection, never a result).
    """
    options = check_options(options)
    frequency = check_inputs(model, basis, frequency, quasi_static=quasi_static,
                             anchor=anchor, U0=U0)
    if condenser is None and (reduced is None or anchor is None or eps == "static"):
        condenser = exact_condenser(model)
    if reduced is None:
        reduced = condense(model, frequency, _orders(basis), quasi_static=quasi_static,
                           condenser=condenser)
    reduced = connect(reduced, model.contact)
    eps = penalty(eps, model=model, reduced=reduced, condenser=condenser)
    preload = None
    if anchor is None:
        preload = preload_anchor(model, condenser=condenser)
        anchor = preload.values
    prob = DLFTProblem(reduced, model.contact, basis, gap=gap, eps=eps, anchor=anchor,
                       jacobian=options.jacobian)
    if U0 is None and basis.k > 3:
        U0 = _harmonic_continuation_start(model, basis, reduced, prob, options)
    x0 = (prob.initial_guess() if U0 is None else np.asarray(U0, float).reshape(prob.m, prob.H))
    attempts: list = []
    t0 = time.perf_counter()
    x, st = solve_strategy(prob, x0, options=options, attempts=attempts)
    found = ""
    if not st.success and _time_start_applies(model, time_domain, quasi_static, gap,
                                              options.strategy):
        found, prob2, x2, st2 = _time_start(model, basis, frequency, reduced, prob, time_domain,
                                            options)
        if st2 is not None:
            attempts.append(Attempt.of("time-start", prob2.eps, st2))
            if st2.success or st2.residual < st.residual:
                prob, x, st = prob2, x2, st2
        else:
            attempts.append(Attempt("time-start", options.solver, prob.eps, False,
                                    float("nan"), 0, 0.0, found))
    st.wall_time = time.perf_counter() - t0
    if not st.success and raise_on_failure:
        from fretwear.errors import ConvergenceError

        raise ConvergenceError(
            f"periodic solve at f = {reduced.frequency:.6g} Hz did not converge: "
            f"{st.message} (relative residual {st.residual:.3g} > {options.tol:g}; "
            f"{len(attempts)} attempts: {', '.join(a.method for a in attempts)})"
        )
    sol = assemble_solution(prob, x.reshape(prob.m, prob.H), model, st)
    sol.attempts = attempts
    if found:
        sol.time_domain = found
        if not sol.success:
            sol.flags.append(found)
    if preload is not None and not preload.success:
        sol.warnings.append(preload.warning)
    return sol


def check_options(options) -> SolveOptions:
    """``options`` if it is a :class:`~fretwear.hb.options.SolveOptions` (else an
    InputError)."""
    if not isinstance(options, SolveOptions):
        raise InputError(f"options = {options!r}: expected a SolveOptions (e.g. "
                         "SolveOptions(tol=1e-10))")
    return options


def _harmonic_continuation_start(model, basis, reduced, prob, options: SolveOptions):
    """A starting point for a many-harmonic solve: the solution on the first kept harmonic,
    embedded in the full basis (None if that fails). From the contact-closed guess, the
    solvers can stall with 15+ harmonics where the one-harmonic problem converges and then
    starts the full one within a few iterations (docs/verification.md)."""
    return _first_harmonic_start(prob, options)

