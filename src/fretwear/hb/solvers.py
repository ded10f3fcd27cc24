"""Nonlinear solvers for the DLFT residual: hybrid Powell (dog-leg) and damped Newton.

All take ``fun(x, need_jacobian) -> (f, J or None)`` with an analytic Jacobian and stop when
``|f| <= tol * scale(x)`` (the paper's test ``|f(U)| <= eps_r |Z_r U|``, section 3.2, with
``scale`` supplied by the caller). A failed solve returns ``success = False`` with the reason;
callers never turn it into a result.

* ``"powell"``: Powell's hybrid dog-leg trust-region method (Powell 1970; the algorithm of
  MINPACK ``hybrj``) with the Newton step from a LAPACK LU of the analytic Jacobian, recomputed
  at every accepted step. MINPACK factorises with its own unblocked QR, which dominates the cost
  at ~1000 unknowns; this keeps the algorithm at LAPACK speed. Where the Newton step keeps
  crossing the contact law's kinks, watchdog stretches of nonmonotone Newton steps
  (:data:`WATCHDOG_AFTER`); where its dog-leg steps crawl, a local phase the caller gives
  (``local``: :func:`fretwear.hb.kinks.local_phase` for the DLFT balance).
* ``"hybr"``: MINPACK ``hybrj`` itself through :func:`scipy.optimize.root` (what the paper used).
* ``"newton"``: Newton with a backtracking line search on ``|f|^2``.
"""

from __future__ import annotations

import numbers
import time
from dataclasses import dataclass

import numpy as np
import scipy.optimize as so

from fretwear.errors import InputError

SOLVERS = ("powell", "newton", "hybr")


@dataclass
class SolveStats:
    """What a nonlinear solve did (in the spirit of :class:`scipy.optimize.OptimizeResult`).

    success : whether the convergence test was met.
    residual : final ``|f| / scale`` (the relative residual of the paper's test).
    iterations, nfev, njev : iterations, residual and Jacobian evaluations.
    wall_time : seconds.
    message : why it stopped.
    solver : the method used.
    """

    success: bool
    residual: float
    iterations: int
    nfev: int
    njev: int
    wall_time: float
    message: str
    solver: str


def solve_identity_rows(J, B):
    """Solve ``J X = B`` eliminating the rows of ``J`` that hold only their diagonal entry.

    A node that sticks all period (or is anchored) has ``G_p = 0``, so its rows of the DLFT
    Jacobian ``J = eps I - G (eps I - Z)`` are ``eps I``: those unknowns follow directly and
    only the block of the other nodes is factorised with LAPACK (on the paper's beam often
    less than half of the unknowns). Exact; least squares for a singular block.

    Parameters
    ----------
    J : (n, n), or the Jacobian as an operator (:class:`fretwear.hb.krylov.KrylovJacobian`,
        which eliminates those rows itself); B : (n,) or (n, k).
    """
    if not isinstance(J, np.ndarray):
        return J.solve(B)
    n = J.shape[0]
    idx = np.arange(n)
    diag_only = (np.count_nonzero(J, axis=1) == 1) & (J[idx, idx] != 0.0)
    B = np.asarray(B, float)
    if not diag_only.any():
        return _dense_solve(J, B)
    s = np.flatnonzero(diag_only)
    a = np.flatnonzero(~diag_only)
    X = np.empty_like(B)
    X[s] = B[s] / (J[s, s][:, None] if B.ndim == 2 else J[s, s])
    if a.size:
        X[a] = _dense_solve(J[np.ix_(a, a)], B[a] - J[np.ix_(a, s)] @ X[s])
    return X


def _dense_solve(A, B):
    """LAPACK LU solve (``gesv``: the factorisation and solve of ``scipy.linalg.lu_factor``
    and ``lu_solve`` without their wrappers' per-call checks, which weighed on small
    problems); least squares when ``A`` is singular."""
    try:
        X = np.linalg.solve(A, B)
        if np.all(np.isfinite(X)):
            return X
    except (np.linalg.LinAlgError, ValueError):
        pass
    return np.linalg.lstsq(A, B, rcond=None)[0]


def _lu_step(J, f, rtol=None):
    """The Newton step ``-J^-1 f``: LAPACK LU of a formed Jacobian (exact), or the operator's
    own solve (:class:`fretwear.hb.krylov.KrylovJacobian`: GMRES, to the relative residual
    ``rtol`` if given)."""
    if isinstance(J, np.ndarray):
        return -solve_identity_rows(J, f)
    if rtol is None:
        return -J.solve(f)
    return -J.solve(f, rtol=rtol)


def vector_norm(x):
    """The 2-norm of a real vector: ``sqrt(x . x)``, what ``numpy.linalg.norm`` computes for
    it, without that function's dispatch (a solve of a small problem calls it dozens of
    times)."""
    x = np.ravel(x)
    return np.sqrt(x.dot(x))


def _column_norms(J):
    if isinstance(J, np.ndarray):
        return np.linalg.norm(J, axis=0)
    return J.column_norms()


def _rescaled(dscale, J):
    """Powell's variable scales after a new Jacobian ``J``: the running maximum of the
    column norms (MINPACK), or ``dscale`` itself on an operator Jacobian whose options keep
    the first Jacobian's scales (:attr:`KrylovOptions.first_scales`)."""
    if not isinstance(J, np.ndarray) and getattr(J, "first_scales", False):
        return dscale
    return np.maximum(dscale, _column_norms(J))


#: preconditioners of the Newton step's GMRES when the operator carries compressed forms
#: (:class:`KrylovOptions`)
PRECONDITIONERS = ("mean-gain", "nearfield")


@dataclass(frozen=True)
class KrylovOptions:
    """The linear algebra of the Newton step on the operator path (``jacobian = "krylov"``,
    :mod:`fretwear.hb.krylov`; large interfaces): settings that change how fast a step is
    solved, never the converged answer (GMRES multiplies by the operator in double and
    solves each step to the forcing term's relative residual).

    Attributes
    ----------
    single_factors : the mean-gain preconditioner's LU factors in single precision
        (float32, complex64 when damped; default True): half the memory traffic of its
        triangular solves and LAPACK's ``sgetrf`` for its builds. A preconditioner in single
        precision is rebuilt in double after a GMRES failure, and once a GMRES solve with it
        needs more than ``single_max_iterations`` iterations.
    single_max_iterations : that bound (GMRES iterations of one Newton step; default 60, one
        restart cycle of :data:`fretwear.hb.krylov.GMRES_RESTART`: on the partial-slip pad
        of benchmarks/scale_3d.py a step took 4-40 with single factors,
        docs/studies/large-interface-solve.md). From then on the problem's preconditioners
        are factored in double.
    preconditioner : for an operator that carries compressed forms (``compress=`` of the
        modal condenser): ``"mean-gain"`` (default: dense LU factors of the active block,
        faster up to 1024 contact nodes) or ``"nearfield"``
        (:class:`fretwear.hb.nearfield_preconditioner.NearFieldPreconditioner`: no dense
        ``m_a x m_a`` factors, for interfaces whose dense factors do not fit). Without
        compressed forms the mean gain is used whatever this says.
    single_products : GMRES multiplies by a single-precision copy of the condensed
        operator's matrices (:meth:`fretwear.hb.modal_operator.ReducedOperator.single`:
        half the memory traffic, twice the BLAS rate; the copy adds half of their memory)
        where a Newton step is solved to a relative residual of at least
        ``single_products_rtol`` (operators of the modal condensation without compressed
        forms only). The step is then that of an operator off by about ``1e-7`` relative,
        far below its tolerance: the residual, the dog-leg and the convergence test stay in
        double, so a converged answer is the same to the solve's tolerance. Default True:
        on the partial-slip pad of benchmarks/scale_3d.py the 256-node solve took the same
        iterations (solution 6e-12 from the double one's, products 0.39 to 0.30 s); at 1024
        nodes the other rounding took Powell onto a path that crawled at ``|f|`` 1e-4
        (docs/studies/large-interface-solve.md, "Iteration counts and per-call terms"),
        which the local phase of :mod:`fretwear.hb.kinks` now ends; with the first
        Jacobian's variable scales (``first_scales``) the solve took 38-42 s CPU against
        51-52 s ("Entering the local phase sooner").
    single_products_rtol : that bound (default ``1e-5``).
    compressed_products_min_dofs : from this many contact DOFs (``m`` of the whole
        operator) the single-precision copy of ``single_products`` is a compressed one:
        the operator's matrices compressed hierarchically (:mod:`fretwear.hb.hmatrix`) to
        ``1e-2 single_products_rtol`` relative (:func:`fretwear.hb.krylov.twin_tolerance`:
        of the order of float32's own rounding) and held in float32 (products below
        ``m^2`` per column; the compression is made once per condensation, on the first
        step that needs it). Operators that know their contact nodes' positions only (those
        of the modal condensers); the residual stays the dense operator's, so the converged
        answer is the same to the solve's tolerance. None (the default): never. On the
        partial-slip pad of benchmarks/scale_3d.py a product with 15 columns (compiled,
        :mod:`fretwear.hb.hmatrix`) took 9.2 ms against the dense single copy's 22.2 ms at
        1024 contact nodes (3072 DOFs; compression 0.72 s CPU, once), 29.1 against 111.1
        ms at 2304 and 3.1 against 8.2 ms at 576; the 1024-node solve's CPU per Powell
        iteration fell by a fifth to a half, but its Powell path was longer from five of
        six starts (12-32 iterations against the dense copy's 13 from six: the other
        rounding of the steps) and the solve slower on average (26.5 against 25.0 s CPU), and at
        576 nodes the gain was 0.3 s in 4.6; hence off by default. It holds 0.125 (1024
        nodes) to 0.074 (2304) of the double matrices' bytes against the dense copy's
        0.5: for interfaces where that copy does not fit (docs/studies/
        large-interface-solve.md, "The compressed twin's product compiled").
    first_scales : Powell's variable scales from the first Jacobian only (default True);
        False: renewed at every Jacobian as MINPACK (the running maximum of its column
        norms), as formed Jacobians always are. The column norms of each new Jacobian cost
        as much as a Newton step's GMRES on a large interface (10 s of the 1024-node
        partial-slip solve's 50); with ``single_products`` this took that solve from
        51-52 s to 38-42 s CPU, to the same root within the spread of the old defaults from
        perturbed starts, once the local phase ended its crawl.
    node_correction : the mean-gain preconditioner followed by a node-local correction
        (default True; :func:`fretwear.hb.krylov.node_local_inverse`): ``Q = eps I + G (Z_D -
        eps I)`` with ``Z_D`` each node's own blocks of ``Z~``, exact in the coupling of a
        node's harmonics by its time-varying gain, which the mean gain drops; ``x = Q^-1 r``,
        then ``x + P^-1 (r - J x)``, one more product (in single precision) per GMRES
        iteration and a batched ``dH x dH`` inverse per Jacobian. Used from
        ``node_correction_min_dofs`` active DOFs: on the
        partial-slip pad of benchmarks/scale_3d.py it halved the GMRES iterations per
        Newton step at 256, 576 and 1024 contact nodes (40-55 %), and paid at 1024 only
        (solve 35 to 25 s CPU; docs/studies/large-interface-solve.md, "The
        preconditioner's builds and a node-local correction").
    node_correction_min_dofs : the active DOFs (contact nodes x d) from which the
        correction is used (default 2048: it paid at 1024 contact nodes of the pad, 3072
        DOFs, and not at 576, 1728 DOFs; the break-even between them was not measured).
    """

    single_factors: bool = True
    single_max_iterations: int = 60
    preconditioner: str = "mean-gain"
    single_products: bool = True
    single_products_rtol: float = 1e-5
    first_scales: bool = True
    local_phase: bool = True
    node_correction: bool = True
    node_correction_min_dofs: int = 2048
    compressed_products_min_dofs: int | None = None

    def __post_init__(self):
        self.check()

    def check(self) -> KrylovOptions:
        """Validate (also done at construction): one InputError naming the option."""
        if not isinstance(self.single_factors, bool):
            raise InputError(f"krylov.single_factors = {self.single_factors!r}: expected "
                             "True or False")
        n = self.single_max_iterations
        if not (isinstance(n, numbers.Integral) and not isinstance(n, bool)
                and 1 <= n <= 2**62):
            raise InputError(f"krylov.single_max_iterations = {n!r}: expected a whole "
                             "number of GMRES iterations >= 1")
        if not (isinstance(self.preconditioner, str)
                and self.preconditioner in PRECONDITIONERS):
            raise InputError(f"krylov.preconditioner = {self.preconditioner!r}: expected "
                             f"one of {PRECONDITIONERS}")
        if not isinstance(self.single_products, bool):
            raise InputError(f"krylov.single_products = {self.single_products!r}: expected "
                             "True or False")
        if not isinstance(self.local_phase, bool):
            raise InputError(f"krylov.local_phase = {self.local_phase!r}: expected "
                             "True or False")
        if not isinstance(self.node_correction, bool):
            raise InputError(f"krylov.node_correction = {self.node_correction!r}: expected "
                             "True or False")
        if not isinstance(self.first_scales, bool):
            raise InputError(f"krylov.first_scales = {self.first_scales!r}: expected "
                             "True or False")
        n = self.node_correction_min_dofs
        if not (isinstance(n, numbers.Integral) and not isinstance(n, bool) and n >= 0):
            raise InputError(f"krylov.node_correction_min_dofs = {n!r}: expected a whole "
                             "number of active DOFs >= 0")
        n = self.compressed_products_min_dofs
        if n is not None and not (isinstance(n, numbers.Integral) and not isinstance(n, bool)
                                  and n >= 1):
            raise InputError(f"krylov.compressed_products_min_dofs = {n!r}: expected a whole "
                             "number of contact DOFs >= 1, or None (never)")
        t = self.single_products_rtol
        if not (isinstance(t, numbers.Real) and not isinstance(t, bool) and 1e-6 <= t < 1):
            raise InputError(f"krylov.single_products_rtol = {t!r}: expected a relative "
                             "residual between 1e-6 (single precision's reach) and 1")
        return self

    def key(self) -> dict:
        """The settings as plain values (checkpoint fingerprints)."""
        return {"single_factors": self.single_factors,
                "single_max_iterations": int(self.single_max_iterations),
                "preconditioner": self.preconditioner,
                "single_products": self.single_products,
                "single_products_rtol": float(self.single_products_rtol)}


#: the linear algebra of the operator path by default (:class:`KrylovOptions`; defined with
#: the solvers so that fretwear.hb.krylov reads it, exported by fretwear.hb.options with the
#: other option records)
KRYLOV = KrylovOptions()


#: a decrease of ``|f|^2`` by less than this fraction in an iteration is slow progress
#: (MINPACK ``hybrj``'s test on its ``actred``)
SLOW_DECREASE = 0.1
#: inexact Newton steps of an operator Jacobian (Eisenstat and Walker 1996, their choice 2):
#: the step's linear system is solved to the relative residual ``eta_k = FORCING_GAMMA
#: (|f_k| / |f_k-1|)^2``, at most FORCING_MAX (the first step), at least ``gamma
#: eta_k-1^2`` when that exceeds 0.1, and no tighter than a tenth of the convergence test
FORCING_MAX = 1e-2
FORCING_GAMMA = 0.9
#: after a step that the model served poorly, redo a rejected inexact step and solve the
#: next Newton steps to the full accuracy of the operator (``True``), or keep the inexact
#: forcing (``False``, the default): on the partial-slip pad of benchmarks/scale_3d.py the
#: poor steps come from the non-smooth law, not from the inexact solve (exact steps took as
#: many Powell iterations), and the full-accuracy re-solves cost ten decades of GMRES
#: (docs/studies/large-interface-solve.md)
POOR_STEP_FULL_ACCURACY = False
#: a nonmonotone stretch (the watchdog of Chamberlain, Powell, Lemarechal and Pedersen 1982)
#: once Powell has had this many full Newton steps rejected since ``|f|`` last fell by a
#: decade: a rejected Newton step is then taken anyway and Newton steps follow from it, each
#: from the Jacobian at its start, for at most :data:`WATCHDOG_STEPS` steps; the stretch ends
#: when ``|f|`` falls below ``(1 - WATCHDOG_DECREASE)`` times its value before it (the
#: iterate kept) or, failing that, returns to where it began and continues as if the step
#: had been rejected. On the DLFT residual of a large interface in partial slip the Newton
#: step crosses the law's kinks (stick, slip, separation at some sample) near the solution,
#: ``|f|`` rises at the trial point and the ratio test rejects it; the trust region then
#: crawls (docs/studies/large-interface-solve.md, "Powell near the law's kinks")
WATCHDOG_AFTER = 2
WATCHDOG_STEPS = 2
WATCHDOG_DECREASE = 1e-4
#: the watchdog on formed (LU) Jacobians too. Off: it was measured to cure the crawl on the
#: operator (Krylov) Jacobians of large interfaces, while on the formed Jacobian of the paper's
#: beam at 79 kHz (reduced: 3 harmonics, 32 samples, started from the first harmonic alone) a
#: stretch led Powell to where it stalled at a relative residual of 0.06 for 200 iterations,
#: where the monotone test converges in 55 (tests/test_examples.py, the 79 kHz wear run)
WATCHDOG_FORMED = False
#: a watchdog stretch from the full Newton step also once this many iterations in a row took
#: a dog-leg step because the Newton step did not fit the trust region, without ``|f|``
#: falling below :data:`WATCHDOG_CLIPPED_PROGRESS` times its value when they began (every so
#: many such iterations are judged anew): on the partial-slip pad of benchmarks/scale_3d.py
#: at 1024 contact nodes, with the GMRES products in single precision or the variable scales
#: of the first Jacobian, the trust region had shrunk below the Newton step (0.004 against
#: 0.67 in the scaled variables) at ``|f|`` 1e-4 and the dog-leg steps crawled for 150
#: iterations with no Newton step rejected, so the stretches of :data:`WATCHDOG_AFTER` never
#: began (docs/studies/large-interface-solve.md, "Iteration counts and per-call terms").
#: It does not rescue that crawl (the Newton steps from the full step stall near 1e-3 there:
#: undone), and never begins on the converging paths measured; on the 40 piecewise-linear
#: problems of tests/hb/test_solvers.py it cuts Powell's iterations from 1690 to 370
WATCHDOG_CLIPPED = 4
WATCHDOG_CLIPPED_PROGRESS = 0.5
#: the local phase (``local`` of :func:`powell`) is called once this many dog-leg steps in a
#: row have not fitted the Newton step nor halved ``|f|`` (from its value at the first of
#: them or at the start of :data:`WATCHDOG_CLIPPED`'s count, the smaller), at most once in
#: such a run of them (the stretch of :data:`WATCHDOG_CLIPPED` follows if it did not reduce
#: ``|f|``). Two: on the 1024-node crawls of docs/studies/large-interface-solve.md
#: ("Entering the local phase sooner") it was called 2-6 iterations sooner than at four
LOCAL_CLIPPED = 2
#: such a stretch takes at most this many Newton steps, each of which must reduce ``|f|`` by
#: this factor: at 1024 contact nodes the full Newton step from ``|f|`` 1.4e-4 raised it to
#: 4.7e-2 (17 nodes changing regime) and the Newton steps from there fell by a decade each
#: (4.4e-3 after two: the two steps of :data:`WATCHDOG_STEPS` did not get back below the start)
WATCHDOG_CLIPPED_STEPS = 5
WATCHDOG_CLIPPED_RATE = 0.5
#: the value a stretch must get below: the largest ``|f|`` of this many iterates before it
#: (1: the iterate where it began; more: nonmonotone, as Grippo, Lampariello and Lucidi 1986)
WATCHDOG_MEMORY = 1


@dataclass
class _Checkpoint:
    """Where a watchdog stretch of :func:`powell` began: the iterate, its residual and norm,
    Jacobian, Newton step, variable scales and the trust radius after the rejection; ``left``
    the Newton steps the stretch may still take; ``ref`` the ``|f|`` it must get below."""

    x: np.ndarray
    f: np.ndarray
    fn: float
    J: object
    sn: np.ndarray
    dscale: np.ndarray
    delta: float
    left: int
    ref: float
    rate: float = 1.0  # each Newton step must bring |f| below rate x |f| before it


def powell(fun, x0, scale, *, tol=1e-8, max_iter=200, callback=None, max_slow=None,
           trace=None, local=None):
    """Powell's hybrid dog-leg trust region on ``f(x) = 0`` with analytic Jacobian.

    As MINPACK ``hybrj``: the variables are scaled by the running maximum of the Jacobian's
    column norms, the trust region is halved on a poor step and doubled on a good one; the
    Newton step comes from a LAPACK LU (computed once per Jacobian: a rejected step keeps
    the iterate, and the next iteration reuses its Newton step with a smaller trust
    region), or for an operator Jacobian (:class:`fretwear.hb.krylov.KrylovJacobian`) from
    GMRES to the relative residual of the forcing terms :data:`FORCING_MAX`,
    :data:`FORCING_GAMMA` (an inexact Newton step far from the solution, tighter as
    ``|f|`` decreases: the dog-leg's predicted reduction is taken with the operator
    itself, and the converged answer is that of the residual test; after a step that the
    model served poorly, steps to the full accuracy until it serves well again if
    :data:`POOR_STEP_FULL_ACCURACY`).
    On an operator Jacobian (or on any with :data:`WATCHDOG_FORMED`), after
    :data:`WATCHDOG_AFTER` rejected Newton steps without ``|f|`` falling a decade, a
    rejected Newton step starts a watchdog stretch (:data:`WATCHDOG_STEPS` Newton steps
    from its point, kept if ``|f|`` ends below its start, else undone); so does the full
    Newton step tried after :data:`WATCHDOG_CLIPPED` dog-leg steps in a row that it did not
    fit and that did not halve ``|f|`` (kept with the radius widened to it if it decreases
    ``|f|``; else up to :data:`WATCHDOG_CLIPPED_STEPS` Newton steps from it, each halving
    ``|f|``).
    ``local``: a local phase for that crawl, ``local(x, f, target) -> x'`` (``target`` the
    convergence test's ``|f|``; for the DLFT balance
    :func:`fretwear.hb.kinks.local_phase`, nonlinear elimination of the nodes that hold the
    residual): called once :data:`LOCAL_CLIPPED` dog-leg steps in a row have not fitted the
    Newton step nor halved ``|f|`` (once in such a run), and a point it returns with a
    smaller ``|f|`` is taken as the iterate (its full Newton step tried next, the trust
    radius set to it as at the start); else the dog-leg steps and the forced step go on as
    without it.
    Its own evaluations are counted in ``nfev``, ``njev`` where it keeps them in attributes
    of the same names (as :func:`fretwear.hb.kinks.local_phase` does).
    ``max_slow``: stop (unconverged) after that many iterations on a new Jacobian
    in a row without one that decreased ``|f|^2`` by :data:`SLOW_DECREASE` (MINPACK's "not
    making good progress" test, ``info = 4`` of ``hybrj`` with 5); None: no such test.
    ``trace``: a list to which every iteration appends a dict (``|f|``, trust radius,
    predicted and actual decrease of ``|f|^2``, whether the step was the Newton step, its
    linear relative residual ``|f + J s| / |f|``, the GMRES iterations of a new Newton step,
    whether it was accepted), for studies of the convergence.
    Returns ``(x, f, stats)``.
    """
    t0 = time.perf_counter()
    x = np.array(x0, dtype=float)
    f, J = fun(x, True)
    nfev = njev = 1
    fn = vector_norm(f)
    # the column norms that scale the variables are formed when the first step is taken: a
    # start that already meets the test (a sweep's predictor, a continuation's last stage)
    # does not pay for them (on a large interface they cost as much as a step)
    dscale = None
    delta = None  # first trial: the full Newton step
    it = 0
    msg = "maximum number of iterations reached"
    ok = False
    stall = 0
    nsuc = 0
    slow = 0  # iterations on a new Jacobian since one decreased |f|^2 by SLOW_DECREASE
    sn = None  # the Newton step at x (one per Jacobian)
    exact = isinstance(J, np.ndarray)  # a formed Jacobian: exact LU steps
    eta = FORCING_MAX  # the forcing term of an inexact step (operator Jacobians)
    tight = False  # after a poor step: Newton steps to the full accuracy
    watch = None  # the checkpoint of a watchdog stretch (nonmonotone Newton steps)
    rejected, ref = 0, fn  # rejected Newton steps since |f| fell below ref / 10
    kept = [fn]  # |f| of the iterates (a stretch's only once it is kept)
    clipped, clip_ref = 0, fn  # dog-leg steps in a row (Newton step too long), |f| before
    local_tried = False  # the local phase called since the dog-leg steps began
    local_ref = fn  # |f| at the first dog-leg step of the run
    while True:
        target = tol * scale(x)
        if fn <= target:
            ok, msg = True, "converged"
            break
        if it >= max_iter:
            break
        if max_slow is not None and slow >= max_slow:
            msg = (f"not making good progress: {slow} Jacobians in a row without an iteration "
                   f"that decreased |f|^2 by {SLOW_DECREASE:g}")
            break
        it += 1
        if dscale is None:
            dscale = _column_norms(J)
            dscale[dscale == 0] = 1.0
        new_step = sn is None
        gm0 = getattr(J, "gmres_iterations", 0)
        if new_step:  # an iteration on a new Jacobian (or an inexact step redone)
            loose = not (exact or (tight and POOR_STEP_FULL_ACCURACY))
            sn = _lu_step(J, f, max(eta, 0.1 * target / fn) if loose else None)
            slow += 1
        snd = vector_norm(dscale * sn)
        if delta is None:
            delta = snd
        forced = False
        crawl = (watch is None and snd > delta and (WATCHDOG_FORMED or not exact)
                 and fn > WATCHDOG_CLIPPED_PROGRESS * clip_ref)
        if (local is not None and not local_tried and watch is None and snd > delta
                and (WATCHDOG_FORMED or not exact)
                and clipped >= min(LOCAL_CLIPPED, WATCHDOG_CLIPPED)
                and fn > WATCHDOG_CLIPPED_PROGRESS * min(local_ref, clip_ref)):
            # the dog-leg steps crawl: the local phase (once in a crawl)
            local_tried = True
            counts = getattr(local, "nfev", 0), getattr(local, "njev", 0)
            xl = np.array(local(x, f, target), dtype=float)
            fl, Jl = fun(xl, True)
            nfev += 1 + getattr(local, "nfev", 0) - counts[0]
            njev += 1 + getattr(local, "njev", 0) - counts[1]
            fnl = vector_norm(fl)
            if fnl < fn:  # its point the iterate, its full Newton step tried next
                if trace is not None:
                    trace.append({"it": it, "f": fn, "f_trial": fnl, "delta": delta,
                                  "pred": 0.0, "actual": fn * fn - fnl * fnl,
                                  "ratio": 1.0, "newton": False, "lin": 1.0,
                                  "new_step": False, "gmres": 0, "accepted": True,
                                  "watchdog": False, "forced": False, "local": True})
                if fnl * fnl <= (1.0 - SLOW_DECREASE) * fn * fn:  # progress, as a step's
                    slow = 0
                x, f, fn, J = xl, fl, fnl, Jl
                dscale = _rescaled(dscale, J)
                eta, sn, delta, stall = FORCING_MAX, None, None, 0
                clipped, clip_ref, local_tried = 0, fn, False
                kept.append(fn)
                if callback is not None:
                    callback(it, x, fn)
                continue
        if watch is None and snd > delta and clipped >= WATCHDOG_CLIPPED:
            # the dog-leg steps crawl (|f| not halved by the last ones): the full Newton step
            # tried (a stretch); else the next ones are judged from here
            forced = crawl
            clipped, clip_ref, local_tried = 0, fn, False
        if snd <= delta or watch is not None or forced:  # (a watchdog stretch: Newton steps)
            s = sn
            if not forced:
                clipped, clip_ref, local_tried = 0, fn, False
        else:
            if clipped == 0:  # the first dog-leg step of a run: the local phase's reference
                local_ref = fn
            clipped += 1
            g = (J.T @ f) / dscale  # gradient in scaled variables
            Jg = J @ (g / dscale)
            alpha = (g @ g) / max(Jg @ Jg, 1e-300)
            sc_s = -alpha * g  # scaled Cauchy step
            scn = vector_norm(sc_s)
            if scn >= delta:
                s_s = sc_s * (delta / scn)
            else:
                dd = dscale * sn - sc_s
                a = dd @ dd
                b = 2.0 * (sc_s @ dd)
                c = scn * scn - delta * delta
                t = (-b + np.sqrt(max(b * b - 4.0 * a * c, 0.0))) / (2.0 * a)
                s_s = sc_s + t * dd
            s = s_s / dscale
        pnorm = vector_norm(dscale * s)
        lin = vector_norm(f + J @ s)
        pred = fn * fn - lin * lin
        xn = x + s
        fn_old, J_old, delta_old, newton_step = fn, J, delta, s is sn
        watching = watch is not None
        fnew, _ = fun(xn, False)
        nfev += 1
        fnn = vector_norm(fnew)
        actual = fn * fn - fnn * fnn
        ratio = actual / pred if pred > 0 else -1.0
        if watch is not None:  # a watchdog stretch: measured against its start
            done = fnn <= (1.0 - WATCHDOG_DECREASE) * watch.ref
            if done or (fnn < watch.rate * fn and watch.left > 1):
                watch.left -= 1
                eta = FORCING_MAX
                x, f, fn = xn, fnew, fnn
                _, J = fun(x, True)
                njev += 1
                sn = None
                dscale = _rescaled(dscale, J)
                if done:  # the stretch succeeded: the trust region admits its last step
                    delta, watch, stall, nsuc = max(watch.delta, 2.0 * pnorm), None, 0, 0
                    kept.append(fn)
            else:  # back to its start, as after the rejection that began it
                x, f, fn, J, sn = watch.x, watch.f, watch.fn, watch.J, watch.sn
                dscale, delta, watch = watch.dscale, watch.delta, None
                stall += 1
        else:
            if ratio < 0.1:
                nsuc = 0
                delta = 0.5 * min(delta, pnorm)
                if loose and fnn >= fn and POOR_STEP_FULL_ACCURACY:  # redo it to full accuracy
                    sn, slow = None, slow - 1
                tight = True  # the model served poorly: full accuracy until it serves well
            else:
                tight = False
                nsuc += 1
                if ratio >= 0.5 or nsuc > 1:
                    delta = max(delta, 2.0 * pnorm)
                if abs(ratio - 1.0) <= 0.1:
                    delta = 2.0 * pnorm
            if actual >= SLOW_DECREASE * fn * fn:
                slow = 0
            if fnn < fn:  # accept any decrease (non-smooth residual: ratios are noisy)
                floor = FORCING_GAMMA * eta * eta
                eta = FORCING_GAMMA * (fnn / fn) ** 2
                eta = min(FORCING_MAX, max(eta, floor) if floor > 0.1 else eta)
                x, f, fn = xn, fnew, fnn
                _, J = fun(x, True)
                njev += 1
                sn = None
                dscale = _rescaled(dscale, J)
                stall = 0
                kept.append(fn)
                if forced:  # the trust region admits the Newton step that served
                    delta = max(delta, pnorm)
            else:
                stall += 1
                if (newton_step and (WATCHDOG_FORMED or not exact)
                        and sn is not None  # (not when the step is redone exactly)
                        and (forced or rejected + 1 >= WATCHDOG_AFTER)):  # a stretch
                    # (after a forced trial the radius of before it: the crawl's own)
                    watch = _Checkpoint(x, f, fn, J, sn, dscale.copy(),
                                        delta_old if forced else delta,
                                        WATCHDOG_CLIPPED_STEPS if forced else WATCHDOG_STEPS,
                                        max(kept[-WATCHDOG_MEMORY:]),
                                        WATCHDOG_CLIPPED_RATE if forced else 1.0)
                    x, f, fn = xn, fnew, fnn
                    _, J = fun(x, True)
                    njev += 1
                    sn = None
                    dscale = _rescaled(dscale, J)
                    eta = FORCING_MAX
                if newton_step:
                    rejected += 1
        if fn <= 0.1 * ref:
            rejected, ref = 0, fn
        if trace is not None:
            trace.append({"it": it, "f": fn_old, "f_trial": fnn, "delta": delta_old,
                          "pred": pred, "actual": actual, "ratio": ratio,
                          "newton": newton_step, "lin": lin / fn_old, "new_step": new_step,
                          "gmres": getattr(J_old, "gmres_iterations", 0) - gm0,
                          "accepted": fnn < fn_old, "watchdog": watching, "forced": forced})
        if callback is not None:
            callback(it, x, fn)
        if delta <= 1e-14 * max(vector_norm(dscale * x), 1e-300) or stall > 40:
            msg = "trust region collapsed: no further decrease of |f| (non-smooth stall)"
            break
    if not ok and watch is not None and watch.fn < fn:  # stopped within a stretch
        x, f, fn = watch.x, watch.f, watch.fn
    wall = time.perf_counter() - t0
    st = SolveStats(ok, float(fn / max(scale(x), 1e-300)), it, nfev, njev, wall, msg, "powell")
    return x, f, st


def newton(fun, x0, scale, *, tol=1e-8, max_iter=100, callback=None, max_slow=None):
    """Newton's method with a backtracking line search on ``|f|^2``. ``max_slow``: stop
    (unconverged) after that many iterations in a row that decreased ``|f|^2`` by less than
    :data:`SLOW_DECREASE` (as :func:`powell`). Returns ``(x, f, stats)``."""
    t0 = time.perf_counter()
    x = np.array(x0, dtype=float)
    f, J = fun(x, True)
    nfev = njev = 1
    fn = vector_norm(f)
    it = 0
    ok = False
    msg = "maximum number of iterations reached"
    slow = 0
    while True:
        if fn <= tol * scale(x):
            ok, msg = True, "converged"
            break
        if it >= max_iter:
            break
        if max_slow is not None and slow >= max_slow:
            msg = (f"not making good progress: {slow} iterations in a row without a decrease "
                   f"of |f|^2 by {SLOW_DECREASE:g}")
            break
        it += 1
        s = _lu_step(J, f)
        t = 1.0
        accepted = False
        for _ in range(30):
            fnew, _ = fun(x + t * s, False)
            nfev += 1
            fnn = vector_norm(fnew)
            if fnn <= (1.0 - 1e-4 * t) * fn:
                accepted = True
                break
            t *= 0.5
        if not accepted:
            msg = "line search failed: no decrease of |f| along the Newton direction"
            break
        slow = 0 if fnn * fnn <= (1.0 - SLOW_DECREASE) * fn * fn else slow + 1
        x, f, fn = x + t * s, fnew, fnn
        _, J = fun(x, True)
        njev += 1
        if callback is not None:
            callback(it, x, fn)
    wall = time.perf_counter() - t0
    st = SolveStats(ok, float(fn / max(scale(x), 1e-300)), it, nfev, njev, wall, msg, "newton")
    return x, f, st


def hybr(fun, x0, scale, *, tol=1e-8, max_iter=200, callback=None):
    """MINPACK ``hybrj`` via :func:`scipy.optimize.root` with the analytic Jacobian."""
    t0 = time.perf_counter()
    counts = {"f": 0}

    def fj(x):
        counts["f"] += 1
        f, J = fun(x, True)
        return f, (J if isinstance(J, np.ndarray) else J.toarray())

    sol = so.root(fj, np.array(x0, dtype=float), jac=True, method="hybr",
                  options={"xtol": 1e-13, "maxfev": max_iter * 10})
    f, _ = fun(sol.x, False)
    fn = vector_norm(f)
    ok = bool(fn <= tol * scale(sol.x))
    wall = time.perf_counter() - t0
    st = SolveStats(ok, float(fn / max(scale(sol.x), 1e-300)), int(sol.nfev), int(sol.nfev),
                    int(getattr(sol, "njev", 0)), wall,
                    "converged" if ok else f"MINPACK: {sol.message}", "hybr")
    return sol.x, f, st


def solve(fun, x0, scale, *, method="powell", tol=1e-8, max_iter=200, callback=None,
          max_slow=None, local=None):
    """Dispatch to one of :data:`SOLVERS`. ``max_slow``: the progress test of
    :func:`powell` and :func:`newton` (``"hybr"`` has MINPACK's own); ``local``: the local
    phase of :func:`powell` (the other methods have none)."""
    table = {"powell": powell, "newton": newton, "hybr": hybr}
    if method not in table:
        raise InputError(f"solver = {method!r}: expected one of {SOLVERS}")
    extra = {} if max_slow is None or method == "hybr" else {"max_slow": max_slow}
    if local is not None and method == "powell":
        extra["local"] = local
    return table[method](fun, x0, scale, tol=tol, max_iter=max_iter, callback=callback,
                         **extra)
