"""The periodic solve of the DLFT harmonic balance at one frequency (paper section 3.1-3.2):
:func:`solve_periodic` condenses the model, builds the balance (:mod:`fretwear.hb.problem`),
runs the attempt ladder of a single solve (:mod:`fretwear.hb.attempts`) and assembles the
result (:mod:`fretwear.hb.solution`).
"""

from __future__ import annotations

import time

import numpy as np

from fretwear.errors import ConvergenceError, InputError
from fretwear.hb.attempts import TimeStart, Trial, cold_start, solve_ladder
from fretwear.hb.connectors import connect
from fretwear.hb.fallback import TimeDomainFallback
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.inputs import check_inputs
from fretwear.hb.options import PERIODIC, SolveOptions
from fretwear.hb.penalty import penalty
from fretwear.hb.preload import preload_anchor
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.reduce import Reduced, condense, condenser_for
from fretwear.hb.solution import PeriodicSolution, assemble_solution
from fretwear.model.core import Model


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
    if condenser is not None or reduced is None or anchor is None or eps == "static":
        condenser = condenser_for(model, condenser)  # checked against the model
    if not getattr(condenser, "models_in_time", True):  # a sector (hb/cyclic.py): the time
        time_domain = None  # integration would not see its cyclic boundaries
    if reduced is None:
        reduced = condense(model, frequency, basis.orders, quasi_static=quasi_static,
                           condenser=condenser)
    reduced = connect(reduced, model.contact)
    eps = penalty(eps, model=model, reduced=reduced, condenser=condenser)
    preload = preload_anchor(model, condenser=condenser) if anchor is None else None
    prob = DLFTProblem(reduced, model.contact, basis, gap=gap,
                       eps=eps, anchor=anchor if preload is None else preload.values,
                       jacobian=options.jacobian)
    prob.krylov = options.krylov
    trial = Trial(prob, cold_start(prob, U0, options), options,
                  time_start=_time_start(model, frequency, reduced, time_domain, quasi_static,
                                         gap))
    t0 = time.perf_counter()
    best = solve_ladder(trial)
    st = best.stats
    st.wall_time = time.perf_counter() - t0
    sol = assemble_solution(best.prob, best.x.reshape(best.prob.m, best.prob.H), model, st)
    if not st.success and raise_on_failure:  # (after assembly: a NaN solution is a failure)
        raise ConvergenceError(
            f"periodic solve at f = {reduced.frequency:.6g} Hz did not converge: "
            f"{st.message} (relative residual {st.residual:.3g} > {options.tol:g}; "
            f"{len(trial.attempts)} attempts: {', '.join(a.method for a in trial.attempts)})")
    sol.attempts = trial.attempts
    sol.fallback_seconds = trial.fallback_seconds
    if trial.found:
        sol.time_domain = trial.found
        if not sol.success:
            sol.flags.append(trial.found)
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


def _time_start(model: Model, frequency: float, reduced: Reduced, time_domain, quasi_static,
                gap) -> TimeStart | None:
    """The time-domain start of the ladder, where it answers the same problem: not with
    ``quasi_static``, a ``gap`` other than the model's, or contact springs (the time-domain
    solver models none of these)."""
    if time_domain is not None and not isinstance(time_domain, TimeDomainFallback):
        raise InputError(f"time_domain = {time_domain!r}: expected None (no time-domain start) "
                         "or a fretwear.hb.fallback.TimeDomainFallback "
                         "(fretwear.timedomain.FALLBACK)")
    if time_domain is None or quasi_static or model.contact.has_connectors:
        return None
    if gap is not None and not np.array_equal(
            np.broadcast_to(np.asarray(gap, float), model.contact.gap.shape), model.contact.gap):
        return None
    return TimeStart(time_domain, model, frequency, reduced)
