"""Frequency sweeps of the DLFT periodic response: the nonlinear FRF (paper Fig. 14, 15, 22).

Each grid frequency starts from its converged neighbours (secant predictor in frequency). When a
grid step fails, the sweep falls back, in order, to: the neighbour itself as start, the other
solver, pseudo-arclength continuation from the last converged point (which passes folds of the
response curve, where frequency is not a good parameter), and finally bisection of the step. A
point that still does not converge is kept in the result as *not converged*, with the reason,
and never used as a solution.

Mean tangential position (stick anchors): the sweep follows the loading history; the first
point starts from the static preload (:func:`fretwear.hb.preload.static_anchor`) and every later
point
takes the mean tangential positions of the previous converged point as its anchors (a node that
sticks all period stays where it was). See docs/theory.md, "Full stick and the mean position".
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fretwear.errors import InputError
from fretwear.files import check_state_file
from fretwear.hb.attempts import _first_harmonic_start, solve_strategy
from fretwear.hb.connectors import connect, springs
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.inputs import check_inputs
from fretwear.hb.options import (
    SWEEP,
    SWEEP_POINT,
    SolveOptions,
    SweepOptions,
    sweep_options,
)
from fretwear.hb.penalty import sweep_penalty
from fretwear.hb.preload import preload_anchor
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.reduce import exact_condenser
from fretwear.hb.solution import Attempt, PeriodicSolution, assemble_solution
from fretwear.hb.solvers import SolveStats, solve
from fretwear.hb.sweep_checkpoint import (
    WHAT,
    fingerprint,
    load_sweep_checkpoint,
    save_sweep_checkpoint,
)
from fretwear.limits import check_range
from fretwear.model.core import Model
from fretwear.resources import require_memory


@dataclass
class SweepPoint:
    """One frequency of a sweep.

    frequency_hz : the frequency [Hz]; solution : the converged periodic solution, or None
    when the solve did not converge (a failed solve is never kept as a solution); stats :
    solver statistics of the last solve; how : ``"grid"``, ``"substep"``, ``"retry"``,
    ``"arclength"``, ``"eps-continuation"``, ``"harmonic-continuation"``, ``"fresh-start"``
    or ``"time-start"``; attempts : every attempt made at this frequency, in order
    (:class:`~fretwear.hb.solution.Attempt`); flags : reasons for caution
    (``"not converged: ..."``, time-domain findings); on_grid : a requested grid frequency
    (False for the intermediate points the sweep added); time_domain : what the time
    integration found at a point whose balance failed (``""`` when none ran).
    """

    frequency_hz: float
    solution: PeriodicSolution | None
    stats: SolveStats
    how: str = "grid"
    flags: list = field(default_factory=list)
    on_grid: bool = False
    time_domain: str = ""
    attempts: list = field(default_factory=list)

    @property
    def success(self) -> bool:
        """The periodic solve converged (``solution`` is not None)."""
        return self.solution is not None

    @property
    def message(self) -> str:
        """Why the last solve stopped (``stats.message``)."""
        return self.stats.message


@dataclass
class SweepResult:
    """The points of a sweep, in the order computed (increasing frequency).

    ``success`` is True when every point converged; ``message`` counts the converged and
    failed grid frequencies; ``point_success`` is the per-point array; ``resumed_from`` is the
    number of grid frequencies read from a checkpoint (-1: none was read); ``warnings`` are
    reasons for caution that concern the whole sweep (e.g. the static preload solve that gives
    the stick anchors did not converge), one line each.
    """

    points: list
    wall_time: float = 0.0
    resumed_from: int = -1
    warnings: list = field(default_factory=list)

    @property
    def frequency_hz(self) -> np.ndarray:
        return np.array([p.frequency_hz for p in self.points])

    @property
    def point_success(self) -> np.ndarray:
        """(n,) bool: whether each point converged."""
        return np.array([p.success for p in self.points], dtype=bool)

    @property
    def success(self) -> bool:
        """Every point converged."""
        return bool(all(p.success for p in self.points))

    @property
    def message(self) -> str:
        """E.g. ``"187 of 200 points converged; 13 not converged (12 flagged by the time
        integration)"``, over the requested grid frequencies."""
        grid = [p for p in self.points if p.on_grid]
        failed = [p for p in grid if not p.success]
        text = f"{len(grid) - len(failed)} of {len(grid)} points converged"
        if failed:
            timed = sum(1 for p in failed if p.time_domain)
            text += f"; {len(failed)} not converged"
            if timed:
                text += f" ({timed} flagged by the time integration)"
        return text

    def amplitude(self, point: str, axis: int = 0, harmonic: int | None = 1) -> np.ndarray:
        """Amplitude of an observed point [m] per sweep point (nan where not converged):
        of one harmonic, or (``harmonic=None``) half the peak-to-peak range over the period."""
        out = np.full(len(self.points), np.nan)
        for i, p in enumerate(self.points):
            s = p.solution
            if s is None:
                continue
            c = s.observed[point][axis]
            if harmonic is None:
                u = s.basis.to_time(c)
                out[i] = 0.5 * (u.max() - u.min())
            else:
                j = s.basis.harmonics.index(harmonic)
                out[i] = np.hypot(c[1 + j], c[1 + s.basis.k + j])
        return out

    def summary(self) -> str:
        """``sweep_converged=k/n`` over the grid frequencies, then every flagged point."""
        grid = [p for p in self.points if p.on_grid]
        k = sum(p.success for p in grid)
        lines = [f"sweep_converged={k}/{len(grid)}"]
        for p in self.points:
            if p.flags:
                lines.append(f"  {p.frequency_hz:12.6g} Hz: " + "; ".join(p.flags))
        return "\n".join(lines)


def frequency_grid(f_min: float, f_max: float, n: int, spacing: str = "log") -> np.ndarray:
    """``n`` frequencies [Hz] from ``f_min`` to ``f_max``, log or linear spacing.

    Raises InputError unless ``0 < f_min < f_max`` (finite, within
    :data:`fretwear.limits.RANGES`), ``n >= 2`` an integer that fits in memory, and
    ``spacing`` is ``"log"`` or ``"linear"``."""
    f_min = check_range(f_min, "frequency", "f_min")
    f_max = check_range(f_max, "frequency", "f_max")
    if not 0.0 < f_min < f_max:
        raise InputError(f"frequency band f_min = {f_min:g} Hz, f_max = {f_max:g} Hz: expected "
                         "0 < f_min < f_max")
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 2:
        raise InputError(f"n_points = {n!r}: expected an integer >= 2")
    if spacing not in ("log", "linear"):
        raise InputError(f"spacing = {spacing!r}: expected \"log\" or \"linear\"")
    require_memory(2000.0 * n, f"a sweep of {n} frequencies")  # per point: grid, results
    if spacing == "log":
        return np.geomspace(f_min, f_max, n)
    return np.linspace(f_min, f_max, n)


#: reduced models a sweep keeps (it revisits the last few frequencies: sub-steps, retries,
#: arclength) at most, and the memory they may take together [bytes]: at 1024 contact nodes
#: and 7 harmonics one reduced model is 1.2 GB, so two are kept there (docs/theory.md,
#: "Large interfaces")
CACHE_SIZE = 8
CACHE_BYTES = 3 * 2**30


class _Problems:
    """DLFT problems per frequency, condensed once and cached (the sweep revisits them): at
    most ``cache_size`` reduced models and :data:`CACHE_BYTES` of them (the newest always).
    ``eps``: a number [N/m], or ``"auto"`` (the spectral radius of each frequency's ``Z_r``)."""

    def __init__(self, model, basis, gap, eps, condenser, jacobian="auto", cache_size=CACHE_SIZE):
        self.model, self.basis, self.gap, self.eps = model, basis, gap, eps
        self.jacobian = jacobian
        self.orders = np.array([0, *basis.harmonics])
        self.cache: dict = {}
        self.size = cache_size
        self.last = None  # the last problem handed out
        # the model does not change during a sweep: its condenser (and loads) are read once,
        # the contact springs prepared once, and the problems share their set-up
        self.condenser = condenser
        self.springs = springs(model.contact)
        self.template = None

    def get(self, omega: float, anchor) -> DLFTProblem:
        """The problem at the circular frequency ``omega`` [rad/s] (the continuation
        variable of the sweep) with the stick anchors ``anchor``."""
        key = float(omega)
        red = self.cache.get(key)
        if red is None:
            # room is made before the new model is condensed (every frequency's has the
            # size of the cached ones): at 1024 nodes one model less held at the peak
            size = next(iter(self.cache.values())).Z.nbytes if self.cache else 0
            while self.cache and (len(self.cache) >= self.size or size + sum(
                    r.Z.nbytes for r in self.cache.values()) > CACHE_BYTES):
                self.cache.pop(next(iter(self.cache)))
            red = self.condenser.reduced(omega, self.orders)
            if self.springs is not None:
                red = connect(red, self.model.contact, self.springs)
            self.cache[key] = red
        if self.template is None:
            prob = DLFTProblem(red, self.model.contact, self.basis, gap=self.gap,
                               eps=self.eps, anchor=anchor, jacobian=self.jacobian)
            # the set-up the other frequencies share (DLFTProblem.at), without this
            # frequency's reduced model and blocks: they are not pinned for the whole sweep
            self.template = object.__new__(DLFTProblem)
            self.template.__dict__.update(prob.__dict__)
            self.template.reduced = self.template.blocks = self.template.F = None
        else:
            prob = self.template.at(red, anchor)
        # the GMRES preconditioner of large interfaces (fretwear.hb.krylov) is carried from
        # the neighbouring frequency: GMRES still solves each step to its tolerance, and
        # rebuilds it when it has become slow
        prob._precond = getattr(self.last, "_precond", None)
        self.last = prob
        return prob


def rebuild_point(probs: _Problems, entry: dict) -> SweepPoint:
    """A sweep point from a checkpoint entry
    (:func:`fretwear.hb.sweep_checkpoint.load_sweep_checkpoint`): its solution re-assembled
    from its harmonics, anchors and penalty by the code that assembled it first, so it equals
    the original bit for bit."""
    rec = entry["record"]
    stats = SolveStats(**rec["stats"])
    sol = None
    if "U" in entry:
        model, basis = probs.model, probs.basis
        prob = DLFTProblem(probs.condenser.reduced(entry["omega"], probs.orders), model.contact,
                           basis, gap=probs.gap, eps=entry["eps"], anchor=entry["anchor"],
                           jacobian=probs.jacobian)
        sol = assemble_solution(prob, np.array(entry["U"], float), model, stats)
    pt = SweepPoint(rec["frequency_hz"], sol, stats, rec["how"], list(rec["flags"]),
                    bool(rec["on_grid"]), rec["time_domain"],
                    [Attempt(**a) for a in rec.get("attempts", [])])
    if sol is not None:
        sol.attempts = pt.attempts
    return pt


def _solve_at(probs, omega, anchor, U0, options: SolveOptions):
    prob = probs.get(omega, anchor)
    x0 = prob.initial_guess() if U0 is None else np.asarray(U0, float).reshape(prob.m, prob.H)

    def fun(x, jac=True):
        return prob.residual(x.reshape(prob.m, prob.H), jac)

    x, _, st = solve(fun, x0.reshape(-1), lambda x: prob.scale(x.reshape(prob.m, prob.H)),
                     method=options.solver, tol=options.tol, max_iter=options.max_iter)
    return prob, x.reshape(prob.m, prob.H), st


#: the settings of the point's solve that a checkpoint fingerprint always holds (the others
#: only when they differ from :data:`~fretwear.hb.options.SWEEP_POINT`)
CHECKPOINT_SOLVE_KEYS = ("solver", "tol", "max_iter", "time_domain_periods")
#: iterations of the last attempt of a sweep point before the time integration (a fresh start
#: as :func:`fretwear.hb.periodic.solve_periodic` makes it), as a multiple of the sweep's
#: ``max_iter``: 5 x 40 is the single solve's default of 200
FRESH_ITER_FACTOR = 5
#: Newton iterations of an arclength corrector without halving its best residual after which
#: the step is shortened (rather than spending the rest of ``max_iter`` on a diverging step)
STALL_ITERATIONS = 5


def _arclength(probs, model, anchor, y_prev, y_last, omega_target, solver_tol, max_steps=20,
               max_iter=20):
    """Pseudo-arclength continuation from ``y_last`` (secant from ``y_prev``) until the
    frequency passes ``omega_target``. ``y = (U (m*H,), omega)``. Returns the list of converged
    ``(U, omega, stats, problem)`` along the branch (the last one is past or at the target) or
    [] (the problem is the one the point converged on: recording the point needs no new
    condensation)."""
    U1, w1 = y_last
    U0, w0 = y_prev
    sx = max(np.linalg.norm(U1), 1e-30)
    sw = max(abs(w1), 1e-30)

    def scaled(U, w):
        return np.concatenate([U / sx, [w / sw]])

    t = scaled(U1, w1) - scaled(U0, w0)
    ds = np.linalg.norm(t)
    if ds == 0:
        return []
    t /= ds
    if t[-1] * (omega_target - w1) < 0:  # march towards the target
        t = -t
    out = []
    yk = scaled(U1, w1)
    for _ in range(max_steps):
        converged = False
        for _shrink in range(4):
            yp = yk + ds * t
            y = yp.copy()
            t0 = time.perf_counter()
            nit = nf = 0
            fw = None
            best = []
            for _it in range(max_iter):
                U, w = y[:-1] * sx, y[-1] * sw
                prob = probs.get(w, anchor)
                f, J = prob.residual(U.reshape(prob.m, prob.H))
                nf += 1
                if fw is None:
                    # df/dw by a forward difference, once per corrector (a chord: each one
                    # costs a condensation at w + dw; the residual itself is exact at every
                    # iterate, so the converged point is the same)
                    dw = 1e-7 * w
                    f2, _ = probs.get(w + dw, anchor).residual(U.reshape(prob.m, prob.H),
                                                               False)
                    fw = (f2 - f) / dw
                g = t @ (y - yp)
                rel = np.linalg.norm(f) / prob.scale(U.reshape(prob.m, prob.H))
                if rel <= solver_tol:
                    converged = True
                    break
                best.append(rel)
                if len(best) > STALL_ITERATIONS and min(best[-STALL_ITERATIONS:]) > \
                        0.5 * min(best[:-STALL_ITERATIONS]):
                    break  # no progress: a shorter step rather than more iterations
                try:
                    dy = _bordered_step(J, f, fw, g, t, sx, sw)
                except np.linalg.LinAlgError:
                    break
                if abs(dy[-1] * sw) > abs(omega_target - w1):
                    # a Newton step of the corrector that moves the frequency by more than
                    # the whole step to the target is diverging (seen past folds of the
                    # dovetail's FRF: 70 Hz jumps on an 18 Hz grid): a shorter step at once,
                    # rather than more iterates, each a condensation at a new frequency
                    break
                y = y + dy
                nit += 1
            if converged:
                break
            ds *= 0.5
        if not converged:
            return out
        U, w = y[:-1] * sx, y[-1] * sw
        st = SolveStats(True, float(np.linalg.norm(f) / prob.scale(U.reshape(prob.m, prob.H))),
                        nit, nf * 2, nf, time.perf_counter() - t0, "converged (arclength)",
                        "arclength")
        out.append((U, w, st, prob))
        tn = y - yk
        tn /= np.linalg.norm(tn)
        t = tn
        yk = y
        if (w - omega_target) * (omega_target - w1) >= 0:  # passed the target frequency
            break
        if nit <= 3:
            ds *= 1.5
    return out


def _bordered_step(J, f, fw, g, t, sx, sw):
    """The Newton step ``dy`` of the arclength system ``[[J sx, fw sw], [t]] dy = -[f, g]``
    (scaled variables): by LU of the bordered matrix for a formed Jacobian, by block
    elimination with two solves of ``J`` for the operator of large interfaces
    (:class:`~fretwear.hb.krylov.KrylovJacobian`)."""
    n = f.size
    if isinstance(J, np.ndarray):
        A = np.zeros((n + 1, n + 1))
        A[:n, :n] = J * sx
        A[:n, n] = fw * sw
        A[n] = t
        return np.linalg.solve(A, -np.concatenate([f, [g]]))
    a, b = J.solve(np.column_stack([-f, fw * sw])).T  # J a = -f, J b = fw sw
    den = t[n] - t[:n] @ b / sx
    if not np.isfinite(den) or den == 0.0:
        raise np.linalg.LinAlgError("singular bordered system")
    dw = (-g - t[:n] @ a / sx) / den
    return np.concatenate([(a - dw * b) / sx, [dw]])


def sweep(model: Model, basis: FourierBasis, f_min: float, f_max: float, n_points: int, *,
          options: SweepOptions | SolveOptions = SWEEP, gap=None, anchor=None,
          condenser=None) -> SweepResult:
    """Nonlinear FRF: periodic solutions from ``f_min`` to ``f_max`` [Hz] on ``n_points`` grid
    frequencies.

    Parameters
    ----------
    model, basis : the structure and the Fourier basis.
    f_min, f_max, n_points : the frequency grid [Hz] (spacing ``options.spacing``).
    options : :class:`~fretwear.hb.options.SweepOptions` (default
        :data:`~fretwear.hb.options.SWEEP`): the solve of one point (``solve``, default
        :data:`~fretwear.hb.options.SWEEP_POINT`), ``spacing``, the penalty ``eps`` and
        ``eps_band``, ``continuation``, ``max_bisections``, the time-domain parts ``flag``
        and ``time_domain``, ``progress``, ``checkpoint`` and ``resume``. A
        :class:`~fretwear.hb.options.SolveOptions` stands for ``SweepOptions(solve=...)``.

        The penalty is one value for every point (:func:`fretwear.hb.penalty.sweep_penalty`).
        ``"top"`` (default): the spectral radius of ``Z_r`` at the highest kept harmonic, its
        median over the band (``eps_band``, default the sweep's own: the chunks of a sweep
        split across workers, :mod:`fretwear.study`, give the whole band so that they all use
        the whole sweep's eps and join without an eps jump). ``"static"``: the spectral
        radius of the static reduced stiffness ``Z_r(0) = K_r``. ``"auto"``: the spectral
        radius of ``Z_r`` over the kept harmonics at each frequency (the paper's rule applied
        point by point; kept for comparison: the harmonics of ``Z_r(n w)`` have poles at the
        clamped-interface resonances, so it jumps by orders of magnitude between
        neighbouring frequencies, and with 7 harmonics the solution depends measurably on
        eps, so the FRF is jagged). A positive number [N/m]: that penalty everywhere
        (docs/theory.md, "The penalty eps").

        ``time_domain`` (e.g. :data:`fretwear.timedomain.fallback.FALLBACK`; None: none): at
        a point that still did not converge, integrate in time from the neighbour for at most
        ``solve.time_domain_periods`` periods (not with contact springs or prescribed normal
        loads, which the time-domain solver does not model): if the structure settles to a
        periodic state, its harmonics and mean positions start one more solve (``how =
        "time-start"``); otherwise the point is flagged with what the structure does there
        (drifting, quasi-periodic...). ``checkpoint``: a ``.npz`` file where the points
        computed so far are saved after every grid frequency
        (:mod:`fretwear.hb.sweep_checkpoint`); with ``resume`` the sweep continues from it when
        it exists (it must have been written by the same sweep: same model, grid and
        settings) and the result equals the uninterrupted sweep's bit for bit. A damaged or
        foreign checkpoint is an :class:`~fretwear.errors.InputError`, never silently
        replaced.
    gap : (nc,) gap + wear [m] (a worn interface); default the model's initial gap.
    anchor : stick anchors of the first point (default: static preload state).
    condenser : the condenser of ``model`` (exact or modal) for every condensation of the
        sweep; default: one :func:`~fretwear.hb.reduce.exact_condenser`.

    Returns
    -------
    :class:`SweepResult`: ``success`` (every point converged), ``message`` (how many did),
    the points in increasing frequency (a point that did not converge has no solution and
    says why in ``flags``).
    """
    t_start = time.perf_counter()
    opts = sweep_options(options)
    so = opts.solve
    spacing, check, checkpoint, resume = opts.spacing, opts.flag, opts.checkpoint, opts.resume
    continuation, max_bisections = opts.continuation, opts.max_bisections
    time_domain, progress = opts.time_domain, opts.progress
    grid = frequency_grid(f_min, f_max, n_points, spacing)
    check_inputs(model, basis, f_min, anchor=anchor)
    if model.contact.has_connectors:  # the time-domain solver has rigid contacts only
        time_domain = None
    if condenser is None:
        condenser = exact_condenser(model)
    band = (f_min, f_max) if opts.eps_band is None else opts.eps_band
    eps = sweep_penalty(opts.eps, model, [0, *basis.harmonics], *band, spacing=spacing,
                        condenser=condenser)
    probs = _Problems(model, basis, gap, eps, condenser, so.jacobian)
    warnings = []
    if anchor is None:
        preload = preload_anchor(model, condenser=condenser)
        anchor = preload.values
        if not preload.success:
            warnings.append(preload.warning)
    history: list = []  # converged (omega, U (m, H)) in order
    last_solution: list = [None]
    points: list = []
    shape = (model.contact.n_nodes, model.contact.dim, basis.size)
    key = None
    first = 0
    if checkpoint is not None:
        check_state_file(checkpoint, WHAT)
        settings = {"eps": probs.eps, "gap": gap, "anchor": anchor,
                    **so.key_changes(SWEEP_POINT, CHECKPOINT_SOLVE_KEYS),
                    "continuation": continuation, "max_bisections": max_bisections,
                    "check": check is not None, "time_domain": time_domain is not None}
        key = fingerprint(model, basis, grid, settings)
        if resume and Path(checkpoint).exists():
            first, entries = load_sweep_checkpoint(checkpoint, key, shape)
            for e in entries:
                pt = rebuild_point(probs, e)
                points.append(pt)
                if pt.solution is not None:
                    history.append((e["omega"], e["U"]))
                    last_solution[0] = pt.solution
    other = so.replace(solver=so.other_solver)

    def record(omega, prob, U, st, how, flags=()):
        sol = assemble_solution(prob, U, model, st)
        pt = SweepPoint(omega / (2 * np.pi), sol, st, how, list(flags))
        if check is not None:
            pt.flags.extend(check(sol))
        history.append((omega, U))
        last_solution[0] = sol
        return pt

    def predict(omega):
        if not history:
            return None
        if len(history) == 1:
            return history[-1][1]
        (w0, U0), (w1, U1) = history[-2], history[-1]
        if w1 == w0:
            return U1
        return U1 + (U1 - U0) * (omega - w1) / (w1 - w0)

    def current_anchor():
        if not history:
            return anchor
        U = history[-1][1].reshape(model.contact.n_nodes, model.contact.dim, -1)
        return U[:, 1:, 0].copy()

    for i, f in enumerate(grid):
        if i < first:
            continue
        omega = 2 * np.pi * f
        prob, U, st = _solve_at(probs, omega, current_anchor(), predict(omega), so)
        how = "grid"
        tried = [Attempt.of("grid", prob.eps, st)]
        if not st.success and history:
            # adaptive step from the last converged point: halve on failure, grow on success
            w_cur = history[-1][0]
            step = 0.5 * (omega - w_cur)
            min_step = (omega - w_cur) / 2**max_bisections
            budget = 6 * max_bisections
            while budget > 0 and abs(step) >= abs(min_step) * (1 - 1e-12):
                budget -= 1
                w_try = w_cur + step
                last = abs(omega - w_try) <= 1e-9 * abs(omega)
                if last:
                    w_try = omega
                pb, Ub, stb = _solve_at(probs, w_try, current_anchor(), predict(w_try), so)
                if not stb.success:
                    step *= 0.5
                    continue
                if last:
                    prob, U, st, how = pb, Ub, stb, "substep"
                    tried.append(Attempt.of("substep", pb.eps, stb))
                    break
                points.append(record(w_try, pb, Ub, stb, "substep"))
                w_cur = w_try
                step = step * 1.5
                if abs(step) > abs(omega - w_cur):
                    step = omega - w_cur
        if not st.success and history:
            prob, U, st = _solve_at(probs, omega, current_anchor(), history[-1][1], other)
            how = "retry"
            tried.append(Attempt.of("retry", prob.eps, st))
        if not st.success and continuation and len(history) >= 2:
            anc = current_anchor()
            t_arc = time.perf_counter()
            branch = _arclength(probs, model, anc, (history[-2][1].reshape(-1), history[-2][0]),
                                (history[-1][1].reshape(-1), history[-1][0]), omega, so.tol)
            for Ub, wb, stb, pb in branch:
                points.append(record(wb, pb, Ub.reshape(pb.m, pb.H), stb, "arclength"))
            if branch:
                prob, U, st = _solve_at(probs, omega, current_anchor(), history[-1][1], so)
                how = "arclength"
                tried.append(Attempt.of("arclength", prob.eps, st))
            else:
                tried.append(Attempt("arclength", "arclength", probs.get(omega, anc).eps,
                                     False, float("nan"), 0, time.perf_counter() - t_arc,
                                     "the continuation did not reach this frequency"))
        if not st.success:
            # continuation in eps (ending at the sweep's eps: no jump), then in harmonics
            pb = probs.get(omega, current_anchor())
            start = history[-1][1] if history else pb.initial_guess()
            n0 = len(tried)
            Ub, stb = solve_strategy(pb, start, options=so, attempts=tried,
                                     steps=("eps-continuation", "harmonic-continuation"))
            if stb.success:
                prob, U, st, how = pb, Ub, stb, tried[-1].method
            elif len(tried) > n0:
                st = stb
        if not st.success:
            # as a single solve would: from the first harmonic alone with the static anchors,
            # the solver and the eps continuation with the single solve's iterations (the
            # neighbour's state can lie on the wrong side of a jump of the mean position)
            pb = probs.get(omega, anchor)
            fresh = so.replace(max_iter=FRESH_ITER_FACTOR * so.max_iter)
            U1 = _first_harmonic_start(pb, fresh)
            tried.append(Attempt("fresh-start", so.solver, pb.eps, U1 is not None, float("nan"),
                                 0, 0.0, "the first harmonic alone" + ("" if U1 is not None
                                                                       else " did not converge")))
            if U1 is not None:
                n0 = len(tried)
                Ub, stb = solve_strategy(pb, U1, options=fresh, attempts=tried,
                                         steps=("start", "eps-continuation"))
                if stb.success:
                    prob, U, st, how = pb, Ub, stb, "fresh-start"
                elif len(tried) > n0:
                    st = stb
        td_msg = None
        if not st.success and time_domain is not None:
            td_msg, Ut, anc_t = time_domain.start(model, f, basis, last_solution[0],
                                                  max_periods=so.time_domain_periods)
            if Ut is not None:
                prob, U, st = _solve_at(probs, omega, anc_t, Ut.reshape(-1, basis.size),
                                        so.replace(max_iter=2 * so.max_iter))
                how = "time-start"
                tried.append(Attempt.of("time-start", prob.eps, st))
        if st.success:
            pt = record(omega, prob, U, st, how)
            pt.on_grid = True
            pt.solution.attempts = tried
        else:
            pt = SweepPoint(f, None, st, how, [f"not converged: {st.message} "
                                                f"(relative residual {st.residual:.2e}; "
                                                f"{len(tried)} attempts)"])
            pt.on_grid = True
            if td_msg is not None:
                pt.flags.append(td_msg)
                pt.time_domain = td_msg
        pt.attempts = tried
        points.append(pt)
        if key is not None:
            save_sweep_checkpoint(checkpoint, key, i + 1, points, shape)
        if progress is not None:
            progress(i, len(grid), pt)
    points.sort(key=lambda p: p.frequency_hz)
    return SweepResult(points, time.perf_counter() - t_start,
                       first if key is not None and resume and first else -1, warnings)
