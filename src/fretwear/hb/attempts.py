"""The attempt ladder of the periodic solve: named rungs, each a small function of a context,
composed into the ladder of a single solve (:func:`solve_ladder`: the attempts of
:func:`fretwear.hb.periodic.solve_periodic`) and the ladder of one grid frequency of a sweep
(:func:`point_ladder`: the attempts of :func:`fretwear.hb.sweep.sweep` at each frequency).

A rung tries one way to a converged balance from what its context holds, records each try as
an :class:`~fretwear.hb.solution.Attempt` (their ``method`` names are those of the results
files) and says whether it converged; a ladder runs its rungs in order until one has.

Single solve (:class:`Trial`; :data:`~fretwear.hb.options.STRATEGY`, the rungs that
``SolveOptions.strategy`` names):

1. ``"start"``: the solver from the start;
2. ``"best-point"``: the other solver (``SolveOptions.other_solver``: Newton after Powell,
   Powell after Newton or hybr) from the best iterate so far (Newton converges where Powell's
   trust region stalls, and the reverse, on the paper's beam);
3. ``"eps-continuation"``: the balance at ``10 eps`` (then ``eps / 10``) from the start (the
   solver, then the other one, then the solver from the first harmonic alone at that eps),
   and from there geometric steps back to ``eps`` (:func:`eps_path`: halved where one
   fails), each starting from the previous answer: the answer is that of the target eps (no
   eps jump);
4. ``"harmonic-continuation"``: the first harmonic alone from the contact-closed guess, then
   all harmonics from it;
5. ``"time-start"``: a time integration from rest (a :class:`TimeStart`); its periodic
   steady state starts one more solve with its mean tangential positions as anchors.

Sweep point (:class:`Point`; :data:`POINT_RUNGS`): ``"grid"`` (the solver from the secant
predictor; after a grid point that did not converge, from the first harmonic alone,
:func:`after_failure`), ``"substep"`` (bisection of the step from the last converged
point), the same again with each step going on past its ``max_iter`` while the solver makes progress
(:func:`patient_substep`, :func:`go_on`; recorded as ``"substep"``), ``"retry"`` (the
other solver from the neighbour), ``"arclength"`` (pseudo-arclength continuation past a fold,
:mod:`fretwear.hb.arclength`; before ``"retry"`` when the branch turns back short of the grid
frequency, :data:`FOLD_RUNGS`, :func:`point_ladder`; before the patient halved steps too),
``"jump"`` (where the arclength turned
back at a fold short of the frequency: the grid attempt from the fold's point, :func:`jump`),
the rungs 3-4 of a single solve from
the neighbour (at the first point of a branch, which has none, from the contact-closed guess
with a single solve's iterations), ``"fresh-start"`` (as a single solve from the first harmonic
alone with the static anchors and five times the iterations: the neighbour's state can lie on
the wrong side of a jump of the mean position) and ``"time-start"`` (a time integration from
the neighbour). Single-solve rungs that ``SolveOptions.strategy`` leaves out are left out of a
sweep point too.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field

import numpy as np

from fretwear.hb.arclength import arclength, fold_ahead
from fretwear.hb.branch import Branch, Problems
from fretwear.hb.connectors import Connected
from fretwear.hb.fallback import TimeDomainFallback
from fretwear.hb.fallbacks import said
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import PERIODIC, STRATEGY, SolveOptions, SweepOptions
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.reduce import Reduced
from fretwear.hb.runs import run
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
#: iterations of the fresh start of a sweep point (as a single solve makes it), as a multiple
#: of the sweep's ``max_iter``: 5 x 40 is the single solve's default of 200
FRESH_ITER_FACTOR = 5
#: a halved step of a sweep point that used its ``max_iter`` iterations without converging
#: goes on from its last iterate for at most this many times ``max_iter`` more, while the
#: solver makes progress (MINPACK's test with :data:`STEP_MAX_SLOW` Jacobians,
#: :func:`go_on`): on the FE FRFs Powell was still converging at its 40th iteration where the
#: ladder then went on to the other solver (the dovetail at 2800 Hz: 1.9 -> 7.6e-2 in 40,
#: converged in 68; docs/studies/fallbacks.md, "The four crossings")
STEP_MORE_ITER = 4
STEP_MAX_SLOW = 5
#: a branch turned back at a fold (:func:`turned_back`, the rung ``"jump"``) when its last
#: point lies back from its farthest one by more than this fraction of the way it went: on
#: the platform damper's FRF the arclength went 360 Hz up to its fold at 38476.5 Hz and 63 Hz
#: back (0.17); its correctors' jitter at a fold's tip moves a few 1e-4 of that
TURN_BACK = 0.01
#: harmonics above which a single solve without a start begins from the first harmonic alone
#: (the first point of a sweep too): with more than one. From the contact-closed guess the
#: solvers stalled with 15+ harmonics (docs/verification.md), and with 3 wherever the
#: interface opens for most of the period: the tutorial's lap joint at its resonance (open 94 %
#: of the time) stalled at a relative residual of 2e-2 in 200 Powell iterations, where the
#: first harmonic alone started a 6-iteration solve to the same answer, and the wear run then
#: took its first state from a time integration (docs/studies/fallbacks.md)
COLD_START_HARMONICS = 1
#: on the operator path (large interfaces) the first-harmonic start gives up after this many
#: Jacobians in a row without an iteration that decreased ``|f|^2`` by 10 % (MINPACK's
#: progress test, fretwear.hb.solvers.powell): it is a start, and a stalled one is not used
#: (measured: the pad in partial slip crawled through its 200 iterations at a relative
#: residual of 1e-5, 55 % of the solve; docs/studies/large-interface-solve.md). Not on the
#: dense path: the paper's beam at 79.34 kHz (salles2011-79khz-periodic) progresses slowly
#: in its start and then needs 185 iterations; cut short there, 215
START_MAX_SLOW = 5


# --- solver runs and starts -----------------------------------------------------------------
def first_harmonic_start(prob: DLFTProblem, options: SolveOptions):
    """A starting point for a many-harmonic solve: the solution on the first kept harmonic
    from the contact-closed guess, embedded in the full basis (None if that fails). From the
    contact-closed guess, the solvers can stall with 15+ harmonics where the one-harmonic
    problem converges and then starts the full one within a few iterations
    (docs/verification.md)."""
    basis, reduced = prob.basis, prob.reduced
    sub = FourierBasis(basis.harmonics[:1], basis.n_samples)
    cut = {k: getattr(reduced, k)[:2] for k in ("orders", "Z", "F", "obs_A", "obs_b")}
    if isinstance(reduced, Connected):  # already seen through the contact springs
        cut.update(node_A=reduced.node_A[:2], node_b=reduced.node_b[:2])
    red = dataclasses.replace(reduced, **cut)
    p1 = DLFTProblem(red, prob.contact, sub, gap=prob.gap, eps=prob.eps, anchor=prob.anchor)
    p1.krylov = prob.krylov
    if p1.jacobian == "krylov":  # the full problem's blocks (and their real copies), shared
        p1.blocks = prob.blocks.leading(2)

    def fun(x, jac=True):
        return p1.residual(x.reshape(p1.m, p1.H), jac)

    x, _, st = solve(fun, p1.initial_guess().reshape(-1),
                     lambda x: p1.scale(x.reshape(p1.m, p1.H)), method=options.solver,
                     tol=options.tol, max_iter=options.max_iter,
                     max_slow=START_MAX_SLOW if prob.jacobian == "krylov" else None)
    if not st.success:
        return None
    U = np.zeros((prob.m, prob.H))
    x = x.reshape(p1.m, p1.H)
    U[:, 0] = x[:, 0]
    U[:, 1] = x[:, 1]
    U[:, 1 + basis.k] = x[:, 2]
    return U


def cold_start(prob: DLFTProblem, U0, options: SolveOptions) -> np.ndarray:
    """The start (m, H) of a single solve: ``U0`` when given; else, above
    :data:`COLD_START_HARMONICS` harmonics, the first harmonic alone
    (:func:`first_harmonic_start`), except on the operator path (large interfaces, where
    fretting puts the interface in partial slip: there the one-harmonic balance stalled on
    256 contact nodes or led the full one through 31 Powell iterations where the
    contact-closed guess needs 11 on 576; docs/studies/large-interface-solve.md; the rung
    ``"harmonic-continuation"`` remains if the solve fails); else the contact-closed guess."""
    if U0 is None and prob.basis.k > COLD_START_HARMONICS and prob.jacobian != "krylov":
        U0 = first_harmonic_start(prob, options)
    return prob.initial_guess() if U0 is None else np.asarray(U0, float).reshape(prob.m, prob.H)


def eps_path(prob: DLFTProblem, x, st, eps_from, options: SolveOptions):
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
    short = options.replace(max_iter=min(options.max_iter, EPS_STEP_MAX_ITER))
    while cur != target:
        remaining = np.log(target / cur)
        last = abs(remaining) <= abs(step) * (1.0 + 1e-12)
        e = target if last else float(cur * np.exp(step))
        xn, stn = run(prob if last else prob.with_eps(e), x, short)
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


# --- the ladder of a single solve -----------------------------------------------------------
@dataclass
class Found:
    """An answer of a ladder: ``x`` (m, H) of ``prob`` with its statistics (converged or the
    best iterate)."""

    x: np.ndarray
    stats: SolveStats
    prob: DLFTProblem


@dataclass
class TimeStart:
    """What the rung ``"time-start"`` of a single solve needs: a time integration of ``model``
    from rest at ``frequency`` [Hz] (``fallback``), and the condensation ``reduced`` of the
    balance it starts."""

    fallback: TimeDomainFallback
    model: Model
    frequency: float
    reduced: Reduced


@dataclass
class Trial:
    """The context of the ladder of a single solve: the balance ``prob`` at the target eps,
    the ``start`` (m, H), the ``options``, the attempts so far (appended to), the best answer
    so far, and the optional time-domain start (``found``: what its integration found)."""

    prob: DLFTProblem
    start: np.ndarray
    options: SolveOptions
    attempts: list = field(default_factory=list)
    time_start: TimeStart | None = None
    best: Found | None = None
    found: str = ""
    fallback_seconds: float = 0.0

    def __post_init__(self):
        self.start = np.asarray(self.start, float).reshape(self.prob.m, self.prob.H)

    def keep(self, x, st, prob: DLFTProblem | None = None) -> bool:
        """Keep ``x`` if it converged or has the smallest residual so far; its success."""
        if self.best is None or st.success or st.residual < self.best.stats.residual:
            self.best = Found(x, st, self.prob if prob is None else prob)
        return st.success

    def settle(self) -> Found:
        """The best answer so far; the start, unconverged, when no rung ran at the target eps
        (its relative residual as the solvers give it)."""
        if self.best is None:
            tried = ", ".join(a.method for a in self.attempts) or "none"
            x0 = self.start
            f, _ = self.prob.residual(x0, False)
            rel = float(vector_norm(f) / max(self.prob.scale(x0), 1e-300))
            self.best = Found(x0, SolveStats(False, rel, 0, 1, 0, 0.0,
                                             f"no attempt converged ({tried})",
                                             self.options.solver), self.prob)
        return self.best


def start(t: Trial) -> bool:
    """``"start"``: the solver from the start."""
    x, st = run(t.prob, t.start, t.options)
    t.attempts.append(Attempt.of("start", t.prob.eps, st))
    return t.keep(x, st)


def best_point(t: Trial) -> bool:
    """``"best-point"``: the other solver from the best iterate so far (the start before
    any)."""
    x0 = t.start if t.best is None else t.best.x
    x, st = run(t.prob, x0, t.options.replace(solver=t.options.other_solver))
    t.attempts.append(Attempt.of("best-point", t.prob.eps, st))
    return t.keep(x, st)


def eps_continuation(t: Trial) -> bool:
    """``"eps-continuation"``: converge at a shifted penalty (:data:`EPS_FACTORS`), then step
    back to the target one (:func:`eps_path`); one attempt per shifted penalty, its message
    gives the path. An answer that did not reach the target eps is not kept."""
    prob, opts = t.prob, t.options
    other = opts.replace(solver=opts.other_solver)
    for factor in EPS_FACTORS:
        t0 = time.perf_counter()
        shifted = prob.with_eps(factor * prob.eps)
        x, st = run(shifted, t.start, opts)
        if not st.success:  # the other solver at the shifted eps
            x, st = run(shifted, t.start, other)
        if not st.success and prob.basis.k > 1:  # the first harmonic alone, at that eps
            U1 = first_harmonic_start(shifted, opts)
            if U1 is not None:
                x, st = run(shifted, U1, opts)
        path = [factor * prob.eps]
        if st.success:
            x, st, path = eps_path(prob, x, st, factor * prob.eps, opts)
        st.wall_time = time.perf_counter() - t0
        msg = f"{st.message} (eps path {', '.join(f'{e:.3g}' for e in path)} N/m)"
        t.attempts.append(Attempt.of("eps-continuation", prob.eps if st.success else path[-1],
                                     st, msg))
        if st.success and path[-1] == prob.eps:
            return t.keep(x, st)
    return False


def harmonic_continuation(t: Trial) -> bool:
    """``"harmonic-continuation"``: the first harmonic alone, then every harmonic from it (not
    with a single harmonic)."""
    prob = t.prob
    if prob.basis.k <= 1:
        return False
    t0 = time.perf_counter()
    U1 = first_harmonic_start(prob, t.options)
    if U1 is None:
        t.attempts.append(Attempt("harmonic-continuation", t.options.solver, prob.eps, False,
                                  float("nan"), 0, time.perf_counter() - t0,
                                  "the first harmonic alone did not converge"))
        return False
    x, st = run(prob, U1, t.options)
    st.wall_time = time.perf_counter() - t0
    t.attempts.append(Attempt.of("harmonic-continuation", prob.eps, st))
    return t.keep(x, st)


def time_start(t: Trial) -> bool:
    """``"time-start"``: integrate in time from rest (``t.time_start``; none: the rung does
    not apply) for ``options.time_domain_periods`` periods; a periodic steady state starts
    the solver (twice the iterations) with its mean tangential positions as anchors, and the
    answer is kept if it converged or beats the best so far; any other response is what
    ``t.found`` says."""
    ts = t.time_start
    if ts is None:
        return False
    best = t.settle()
    opts, prob = t.options, t.prob
    said(f"{_where(prob)}: integrating in time from rest for up to "
         f"{opts.time_domain_periods} periods (a time integration can take minutes)")
    t0 = time.perf_counter()
    t.found, Ut, anchor = ts.fallback.start(ts.model, ts.frequency, prob.basis, None,
                                            max_periods=opts.time_domain_periods)
    if Ut is None:
        t.attempts.append(Attempt("time-start", opts.solver, prob.eps, False, float("nan"), 0,
                                  0.0, t.found))
        return False
    prob2 = DLFTProblem(ts.reduced, ts.model.contact, prob.basis, gap=prob.gap, eps=prob.eps,
                        anchor=anchor, jacobian=prob.jacobian)
    prob2.krylov = prob.krylov
    x, st = run(prob2, np.asarray(Ut, float).reshape(prob2.m, prob2.H),
                opts.replace(max_iter=2 * opts.max_iter))
    st.wall_time = time.perf_counter() - t0
    t.attempts.append(Attempt.of("time-start", prob2.eps, st))
    if st.success or st.residual < best.stats.residual:
        t.best = Found(x, st, prob2)
    return st.success


#: the rungs of a single solve, by the names of :data:`~fretwear.hb.options.STRATEGY`
SOLVE_RUNGS = {"start": start, "best-point": best_point, "eps-continuation": eps_continuation,
               "harmonic-continuation": harmonic_continuation, "time-start": time_start}


def solve_ladder(t: Trial, rungs=None) -> Found:
    """Run the rungs ``rungs`` (default ``t.options.strategy``) of a single solve, in the order
    of :data:`~fretwear.hb.options.STRATEGY`, until one converges: the converged answer, or
    the best iterate (the start when no rung ran at the target eps)."""
    rungs = t.options.strategy if rungs is None else rungs
    done, t_first = "", None
    for name in STRATEGY:
        if name not in rungs or (name == "time-start" and t.time_start is None):
            continue
        if done:
            t_first = time.perf_counter() if t_first is None else t_first
            said(f"{_where(t.prob)}: {done} failed (best residual "
                 f"{t.best.stats.residual if t.best else float('nan'):.2e}); trying {name}")
        if SOLVE_RUNGS[name](t):
            break
        done = name
    if t_first is not None:
        t.fallback_seconds = time.perf_counter() - t_first
    return t.settle()


def _where(prob: DLFTProblem) -> str:
    red = prob.reduced
    return ("quasi-static periodic solve" if red.quasi_static
            else f"periodic solve at {red.frequency:.6g} Hz")


# --- the ladder of a sweep point ------------------------------------------------------------
@dataclass
class Point:
    """The context of the ladder of one grid frequency of a sweep: the frequency [Hz] and
    ``omega`` [rad/s], the sweep's problems per frequency, its branch of converged points and
    its options; then what the rungs found: the problem, harmonics and statistics of the last
    solve, how it was made, every attempt, and what a time integration found (None: none
    ran); whether the halved steps failed down to the smallest (``halved_out``) and the index
    in the branch's history of the last converged point before the arclength ran
    (``neighbour``: None before it ran) and of its point at a fold it turned back from short
    of the frequency (``fold``: None if it did not, :func:`jump`)."""

    frequency: float
    probs: Problems
    branch: Branch
    options: SweepOptions
    prob: DLFTProblem | None = None
    U: np.ndarray | None = None
    stats: SolveStats | None = None
    how: str = "grid"
    tried: list = field(default_factory=list)
    time_domain: str | None = None
    fallback_seconds: float = 0.0
    halved_out: bool = False
    neighbour: int | None = None
    fold: int | None = None

    @property
    def omega(self) -> float:
        return 2 * np.pi * self.frequency

    def adopt(self, prob, U, stats, how) -> bool:
        """The solve of a rung becomes the point's; its success."""
        self.prob, self.U, self.stats, self.how = prob, U, stats, how
        return stats.success


def solve_at(probs: Problems, omega: float, anchor, U0, options: SolveOptions):
    """One solver run at ``omega`` [rad/s] with the stick anchors ``anchor`` from ``U0``
    (None: the contact-closed guess): ``(problem, U (m, H), stats)``."""
    prob = probs.get(omega, anchor)
    x, st = run(prob, prob.initial_guess() if U0 is None else U0, options)
    return prob, x, st


def go_on(prob: DLFTProblem, U, st: SolveStats, options: SolveOptions):
    """``(U, stats)`` of a solve that used its ``options.max_iter`` iterations without
    converging, continued from its last iterate ``U`` for at most :data:`STEP_MORE_ITER` times
    as many while it makes progress (MINPACK's test, ``max_slow`` =
    :data:`STEP_MAX_SLOW` Jacobians in a row without decreasing ``|f|^2`` by 10 %; a
    non-smooth stall or a failed line search ends it too); a solve that converged, or
    stopped for another reason, is returned as it is. The statistics add up both runs."""
    if st.success or st.iterations < options.max_iter:
        return U, st
    x, st2 = run(prob, U, options.replace(max_iter=STEP_MORE_ITER * options.max_iter),
                 max_slow=STEP_MAX_SLOW)
    merged = SolveStats(st2.success, st2.residual, st.iterations + st2.iterations,
                        st.nfev + st2.nfev, st.njev + st2.njev,
                        st.wall_time + st2.wall_time, st2.message, st2.solver)
    return x, merged


def grid(p: Point) -> bool:
    """``"grid"``: the solver from the secant predictor, with the anchors of the history; at
    the first point of a branch (no predictor) from the start of a single solve
    (:func:`cold_start`: the first harmonic alone with more than one) with a single solve's
    iterations (:data:`~fretwear.hb.options.PERIODIC`): the 40 of a warm-started point left
    the tutorial's lap joint at 400 Hz at a relative residual of 6e-2 from the contact-closed
    guess (then the eps continuation, 4 s: docs/studies/fallbacks.md). The same after a grid
    point that did not converge (:func:`after_failure`: the last converged point is no
    neighbour), with the last converged point's anchors: on the paper's beam at 54555.9 Hz,
    three times the frequency of the last converged point, the predictor and that point
    start at relative residuals of 0.84 and 0.78 and neither solver converges from them in
    200 iterations, where the first harmonic alone starts at 8.5e-2 and Powell converges in
    15 to the answer of the eps continuation (the fallback it took before;
    docs/studies/fallbacks.md, "The last fallbacks")."""
    b, so = p.branch, p.options.solve
    U0 = b.predict(p.omega)
    broken = U0 is not None and after_failure(b)
    if U0 is None or broken:
        so = so.replace(max_iter=max(so.max_iter, PERIODIC.max_iter))
        U0 = cold_start(p.probs.get(p.omega, b.anchor()), None, so)
    prob, U, st = solve_at(p.probs, p.omega, b.anchor(), U0, so)
    how = ""
    if broken:
        how = " (the grid point before did not converge: started as a branch's first point)"
        said(f"sweep at {p.frequency:.6g} Hz: the grid point before did not converge; "
             "starting as a branch's first point: "
             + ("converged" if st.success else f"not converged ({st.residual:.2e})"))
    p.tried.append(Attempt.of("grid", prob.eps, st, st.message + how if how else None))
    return p.adopt(prob, U, st, "grid")


def after_failure(b: Branch) -> bool:
    """Whether the last grid point of the branch ``b`` did not converge: its last converged
    point then lies a grid step or more back (the paper's beam, 20 points from 1 Hz to
    100 kHz: 17928.5 Hz, a halved step before 29763.5 Hz, which has no periodic response,
    for the grid point at 54555.9 Hz) and is no neighbour to start from (:func:`grid`)."""
    for pt in reversed(b.points):
        if pt.on_grid:
            return not pt.success
    return False


def substep(p: Point, patient: bool = False) -> bool:
    """``"substep"``: from the last converged point, steps halved on failure (at most
    ``max_bisections`` times) and grown by 1.5 on success, each converged intermediate point
    kept in the sweep; with ``patient`` (:func:`patient_substep`) each step's solve goes on
    while it makes progress (:func:`go_on`). A failure that halved the step below its
    smallest sets
    ``p.halved_out`` (a fold's sign, :func:`~fretwear.hb.arclength.fold_ahead`)."""
    b, omega, opts = p.branch, p.omega, p.options
    if not b.history:
        return False
    w_cur = b.history[-1][0]
    step = 0.5 * (omega - w_cur)
    min_step = (omega - w_cur) / 2**opts.max_bisections
    budget = 6 * opts.max_bisections
    while budget > 0 and abs(step) >= abs(min_step) * (1 - 1e-12):
        budget -= 1
        w_try = w_cur + step
        last = abs(omega - w_try) <= 1e-9 * abs(omega)
        if last:
            w_try = omega
        pb, Ub, stb = solve_at(p.probs, w_try, b.anchor(), b.predict(w_try), opts.solve)
        if patient:
            Ub, stb = go_on(pb, Ub, stb, opts.solve)
        if not stb.success:
            step *= 0.5
            continue
        if last:
            p.tried.append(Attempt.of("substep", pb.eps, stb))
            return p.adopt(pb, Ub, stb, "substep")
        b.add(w_try, pb, Ub, stb, "substep")
        w_cur = w_try
        step = step * 1.5
        if abs(step) > abs(omega - w_cur):
            step = omega - w_cur
    p.halved_out = abs(step) < abs(min_step) * (1 - 1e-12)
    return False


def patient_substep(p: Point) -> bool:
    """``"substep"`` again after the halved steps failed (and, with a fold ahead, after the
    arclength did not reach the frequency), each step's solve going on past ``max_iter``
    while the solver makes progress (:func:`go_on`): the sweep's own path along the branch
    where the solver converges slowly (:func:`point_ladder`). Recorded as ``"substep"``."""
    return substep(p, patient=True)


def retry(p: Point) -> bool:
    """``"retry"``: the other solver from the last converged point before the arclength ran
    (``p.neighbour``; the last converged point when it did not), with its anchors: after an
    arclength that did not reach the frequency (a fold ahead, :data:`FOLD_RUNGS`) this is the
    start the retry had before the arclength went first, so the ladder from there on is the
    same and so are its answers."""
    b, so = p.branch, p.options.solve
    if not b.history:
        return False
    at = -1 if p.neighbour is None else p.neighbour
    prob, U, st = solve_at(p.probs, p.omega, b.anchor(at), b.history[at][1],
                           so.replace(solver=so.other_solver))
    p.tried.append(Attempt.of("retry", prob.eps, st))
    return p.adopt(prob, U, st, "retry")


def arclength_branch(p: Point) -> bool:
    """``"arclength"``: pseudo-arclength continuation from the last two converged points past
    this frequency (its points kept in the sweep), then the solver from the last one."""
    b, opts = p.branch, p.options
    if not (opts.continuation and len(b.history) >= 2):
        return False
    anc = b.anchor()
    p.neighbour = len(b.history) - 1
    t_arc = time.perf_counter()
    found = arclength(p.probs, anc, (b.history[-2][1].reshape(-1), b.history[-2][0]),
                      (b.history[-1][1].reshape(-1), b.history[-1][0]), p.omega,
                      opts.solve.tol)
    for Ub, wb, stb, pb in found:
        b.add(wb, pb, Ub.reshape(pb.m, pb.H), stb, "arclength")
    p.fold = turned_back(b.history, p.neighbour, p.omega)
    if not found:
        p.tried.append(Attempt("arclength", "arclength", p.probs.get(p.omega, anc).eps, False,
                               float("nan"), 0, time.perf_counter() - t_arc,
                               "the continuation did not reach this frequency"))
        return False
    prob, U, st = solve_at(p.probs, p.omega, b.anchor(), b.history[-1][1], opts.solve)
    # the attempt's time is the whole continuation (its points and this solve), the point's
    # solve statistics this solve's alone
    p.tried.append(dataclasses.replace(Attempt.of("arclength", prob.eps, st),
                                       wall_time=time.perf_counter() - t_arc))
    return p.adopt(prob, U, st, "arclength")


def turned_back(history, start: int, omega: float) -> int | None:
    """The index in ``history`` of the point where the branch after ``history[start]`` turned
    back short of ``omega`` [rad/s] (the farthest towards ``omega``, with the last point back
    from it by at least :data:`TURN_BACK` of the way from ``history[start]`` to it: a fold the
    arclength went round, not the jitter of its correctors), None if it did not (it went on
    towards ``omega``, or reached it)."""
    march = np.sign(omega - history[start][0])
    ws = [march * float(w) for w, _ in history[start:]]
    tip = int(np.argmax(ws))
    if tip == 0 or ws[tip] >= march * omega or ws[tip] - ws[-1] <= TURN_BACK * (ws[tip]
                                                                                - ws[0]):
        return None
    return start + tip


def jump(p: Point) -> bool:
    """``"jump"``: after an arclength that turned back at a fold short of this frequency and
    did not come back to it (``p.fold``, :func:`turned_back`), the sweep's first attempt (its
    solver, :func:`go_on`) from the branch's point at the fold, with its anchors: the jump a
    stepped-sine test makes there (the response leaves the branch at its fold for the branch
    that exists at the next frequency). Said as a line, and in the run's summary
    (:func:`fretwear.hb.fallbacks.of_solutions`). Not tried where no fold was passed."""
    if p.fold is None:
        return False
    b, so = p.branch, p.options.solve
    w_fold = float(b.history[p.fold][0])
    prob, U, st = solve_at(p.probs, p.omega, b.anchor(p.fold), b.history[p.fold][1], so)
    U, st = go_on(prob, U, st, so)
    f_fold = w_fold / (2 * np.pi)
    p.tried.append(Attempt.of("jump", prob.eps, st,
                              f"{st.message} (from the fold at {f_fold:.6g} Hz)", f_fold))
    said(f"sweep at {p.frequency:.6g} Hz: the branch turns back at a fold at {f_fold:.6g} Hz; "
         f"jump from there to {p.frequency:.6g} Hz: "
         + ("converged" if st.success else f"not converged ({st.residual:.2e})"))
    return p.adopt(prob, U, st, "jump")


def _single(p: Point, prob: DLFTProblem, x0, options: SolveOptions, rungs, how) -> bool:
    """Rungs of a single solve at this point (those ``options.strategy`` names), recorded
    with the point's attempts: a converged answer is adopted (``how``: its method when None);
    a failed one gives the point its statistics when a rung ran."""
    n0 = len(p.tried)
    best = solve_ladder(Trial(prob, x0, options, p.tried),
                        [r for r in rungs if r in options.strategy])
    if best.stats.success:
        return p.adopt(prob, best.x, best.stats, how or p.tried[-1].method)
    if len(p.tried) > n0:
        p.stats = best.stats
    return False


def continuation(p: Point) -> bool:
    """``"eps-continuation"``, then ``"harmonic-continuation"``, from the last converged
    point (the contact-closed guess before any), ending at the sweep's eps (no eps jump)."""
    b, so = p.branch, p.options.solve
    pb = p.probs.get(p.omega, b.anchor())
    if b.history:
        return _single(p, pb, b.history[-1][1], so,
                       ("eps-continuation", "harmonic-continuation"), None)
    # the first point of a branch has no neighbour to start from: it gets the iterations of a
    # single solve (PERIODIC), not the few of a warm-started point
    first = so.replace(max_iter=max(so.max_iter, PERIODIC.max_iter))
    return _single(p, pb, pb.initial_guess(), first,
                   ("eps-continuation", "harmonic-continuation"), None)


def fresh_start(p: Point) -> bool:
    """``"fresh-start"``: as a single solve would, from the first harmonic alone with the
    sweep's first anchors, then ``"start"`` and ``"eps-continuation"``, with
    :data:`FRESH_ITER_FACTOR` times the iterations (the neighbour's state can lie on the wrong
    side of a jump of the mean position)."""
    so = p.options.solve
    pb = p.probs.get(p.omega, p.branch.first_anchor)
    fresh = so.replace(max_iter=FRESH_ITER_FACTOR * so.max_iter)
    U1 = first_harmonic_start(pb, fresh)
    p.tried.append(Attempt("fresh-start", so.solver, pb.eps, U1 is not None, float("nan"), 0,
                           0.0, "the first harmonic alone" + ("" if U1 is not None
                                                              else " did not converge")))
    if U1 is None:
        return False
    return _single(p, pb, U1, fresh, ("start", "eps-continuation"), "fresh-start")


def point_time_start(p: Point) -> bool:
    """``"time-start"``: integrate in time from the neighbour (``options.time_domain``; none:
    the rung does not apply); a periodic steady state starts the solver (twice the
    iterations) with its mean tangential positions as anchors; what the integration found is
    ``p.time_domain``."""
    td, so = p.options.time_domain, p.options.solve
    if td is None or "time-start" not in so.strategy:
        return False
    p.time_domain, Ut, anc_t = td.start(p.probs.model, p.frequency, p.probs.basis,
                                        p.branch.last_solution,
                                        max_periods=so.time_domain_periods)
    if Ut is None:
        return False
    prob, U, st = solve_at(p.probs, p.omega, anc_t, Ut.reshape(-1, p.probs.basis.size),
                           so.replace(max_iter=2 * so.max_iter))
    p.tried.append(Attempt.of("time-start", prob.eps, st))
    return p.adopt(prob, U, st, "time-start")


#: the rungs of a sweep point, in order
POINT_RUNGS = (("grid", grid), ("substep", substep), ("patient-substep", patient_substep),
               ("retry", retry), ("arclength", arclength_branch), ("jump", jump),
               ("continuation", continuation), ("fresh-start", fresh_start),
               ("time-start", point_time_start))
#: the rungs of a sweep point with a fold ahead (:func:`point_ladder`): the arclength (and the
#: jump from a fold it turned back at) before the patient halved steps and the other solver,
#: the rest in order
FOLD_RUNGS = (POINT_RUNGS[0], POINT_RUNGS[1], POINT_RUNGS[4], POINT_RUNGS[5], POINT_RUNGS[2],
              POINT_RUNGS[3], *POINT_RUNGS[6:])


#: the rungs of a sweep point said as they start (the costly ones, after the sweep's own path:
#: the grid step, the halved steps, the arclength and the jump), with the words said
SAID_RUNGS = {"continuation": "the eps and harmonic continuations from the last converged point",
              "fresh-start": "a fresh start from the first harmonic alone",
              "time-start": "a time integration (it can take minutes)"}


def point_ladder(p: Point) -> Point:
    """Run the rungs of a sweep point until one converges: :data:`POINT_RUNGS`, or
    :data:`FOLD_RUNGS` when the grid step and its halvings failed before a fold; the wall time
    after the first rung is ``p.fallback_seconds``, the costly rungs are said as they start
    (:func:`~fretwear.hb.fallbacks.said`).

    Why the arclength goes first at a fold: past a fold of the response curve (a turning point
    in frequency) the branch the sweep follows has no point at the grid frequency, so no
    solver started from the neighbour can land on it. The other solver (``"retry"``) then
    either fails after a full solve (the dovetail's FRF at 2440 Hz: Newton stopped at a
    relative residual of 0.13; the folded friction model of the tests at 0.77 rad/s: 0.11) or
    converges on another branch after a jump the sweep does not see, and the point counts as
    a fallback, while the pseudo-arclength continuation follows the branch round the fold,
    which is the sweep's own path. Whether a fold lies ahead is read from the branch itself,
    free (no solve, no condensation): :func:`~fretwear.hb.arclength.fold_ahead`, the frequency
    along the arclength through the last three converged points (the halved steps' among
    them, which crowd at the fold) decelerating and turning back short of the grid frequency,
    or decelerating where the halved steps failed down to the smallest. Where it does
    not (a solver that stalls on a smooth stretch or at a corner of the branch, where Newton
    converges after Powell's trust region stalled, and the reverse: the dovetail's FRF at
    2800 Hz, where the arclength's corrector diverged and Newton from the neighbour
    converged), the other solver keeps its place before the arclength: one solve at the grid
    frequency, where the arclength pays a condensation per corrector iterate at every new
    frequency.

    Why the patient halved steps (:func:`patient_substep`: each step going on past
    ``max_iter`` while the solver makes progress, :func:`go_on`) come before the other
    solver: on the FE FRFs the points that fell back away from a fold (the other solver from
    the neighbour converging after the halved steps failed) were Powell solves still
    converging at their 40th iteration (docs/studies/fallbacks.md, "The four crossings"):
    the dovetail at 2800 Hz (from the predictor 1.9 -> 7.6e-2 in 40, converged in 68), the
    bladed disk at 3100 Hz (converged in 88) and at 2900 Hz (where Powell stalls over the
    whole 100 Hz step, but converges over its half). Cut at 40, every halved step failed
    down to the smallest and the point went to the other solver; going on, a halved step
    converges and the point is reached along the branch. They come after the plain halved
    steps (and after the arclength where a fold lies ahead) so that wherever those pass, the
    path is the same as before: going on at once, the halved steps stepped over the lap
    joint's resonance peak (recorded up to 5.04e-5 m where the arclength's points resolve
    6.15e-5 m). The grid attempt keeps its ``max_iter``: a longer solve over the whole grid
    step landed, where the friction state depends on the loading path, on the state of the
    coarser path (the bladed disk at 3100 Hz: 5 % from a sweep of 10 Hz steps). Where the
    solver stalls (a fold with no point ahead, a non-smooth stall) MINPACK's progress test
    ends the extension within a few Jacobians.

    Why a jump (:func:`jump`): where the arclength went round a fold and turned back short of
    the grid frequency without coming back to it (the platform damper's FRF: the branch
    turns at 38476.5 Hz and leads back down, 41016.8 Hz lies beyond the fold), the response
    of a stepped-sine test leaves the branch at the fold for the branch that exists at the
    next frequency. The sweep computes that jump with its own first attempt (its solver, its
    iterations) from the branch's point at the fold and its stick anchors, says it, and
    lists it in the run's summary; the other solver and the eps continuation from the last
    point of the arclength (on the branch leading away, which the test never visits) came
    after it and remain for a jump that does not converge."""
    t_first = None
    rungs = POINT_RUNGS
    for i in range(len(rungs)):
        if i == 1:
            t_first = time.perf_counter()
        elif i == 2 and p.options.continuation and fold_ahead(p.branch.history, p.omega,
                                                               p.halved_out):
            rungs = FOLD_RUNGS
        name, rung = rungs[i]
        if name in SAID_RUNGS:
            said(f"sweep at {p.frequency:.6g} Hz: the sweep's own path and the other solver "
                 f"failed; trying {SAID_RUNGS[name]} ({name})")
        if rung(p):
            break
    if t_first is not None:
        p.fallback_seconds = time.perf_counter() - t_first
    return p
