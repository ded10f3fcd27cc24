"""Frequency sweeps of the DLFT periodic response: the nonlinear FRF (paper Fig. 14, 15, 22).

:func:`sweep` is the loop over the grid frequencies with its checkpoint. Each grid frequency
runs the ladder of a sweep point (:func:`fretwear.hb.attempts.point_ladder`): the solver from
its converged neighbours (secant predictor in frequency); when that fails, in order: bisection
of the step, the other solver from the neighbour, pseudo-arclength continuation from the last
converged points (which passes folds of the response curve, where frequency is not a good
parameter; before the other solver where a fold lies ahead), continuation in eps and in
harmonics, a fresh start as a single solve, and a time integration. A point that still does not
converge is kept in the result as *not converged*, with the reason, and never used as a
solution. The continuation state (the problems per frequency, the converged points, the stick
anchors of the loading history) is :mod:`fretwear.hb.branch`.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from fretwear.errors import InputError, interrupted
from fretwear.files import check_state_file
from fretwear.hb.attempts import Point, point_ladder
from fretwear.hb.branch import Branch, Problems
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.inputs import check_inputs
from fretwear.hb.options import SWEEP, SWEEP_POINT, SolveOptions, SweepOptions, sweep_options
from fretwear.hb.penalty import sweep_penalty
from fretwear.hb.preload import preload_anchor
from fretwear.hb.reduce import condenser_for
from fretwear.hb.solution import FINITE_ARRAYS
from fretwear.hb.sweep_checkpoint import (
    WHAT,
    fingerprint,
    load_sweep_checkpoint,
    save_sweep_checkpoint,
)
from fretwear.hb.sweep_result import SweepPoint, SweepResult
from fretwear.limits import check_range
from fretwear.model.core import Model
from fretwear.resources import require_memory

__all__ = ["SweepPoint", "SweepResult", "frequency_grid", "sweep"]

#: the settings of the point's solve that a checkpoint fingerprint always holds (the others
#: only when they differ from :data:`~fretwear.hb.options.SWEEP_POINT`)
CHECKPOINT_SOLVE_KEYS = ("solver", "tol", "max_iter", "time_domain_periods")


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
        ``"contact"`` (default): ``"stiff"`` where every contact node is a rigid slider under
        a prescribed normal load (:func:`fretwear.hb.penalty.rigid_slider`), ``"top"``
        elsewhere. ``"top"`` and ``"stiff"`` (ten times ``"top"``): the spectral radius of
        ``Z_r`` at the
        highest kept harmonic, its median over the band (``eps_band``, default the sweep's
        own: the chunks of a sweep split across workers, :mod:`fretwear.study`, give the whole
        band so that they all use the whole sweep's eps and join without an eps jump);
        ``"stiff"`` is more accurate on a rigid contact behind a mass and less robust on the
        paper's beam at 76-82 kHz (docs/theory.md, "The penalty eps"). ``"static"``: the
        spectral
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

    Raises
    ------
    KeyboardInterrupt
        On Ctrl-C (or the SystemError of a compiled function interrupted), the same
        exception with ``partial``: a :class:`SweepResult` of the points computed so far
        (``sweep-partial.nc`` of the sweep analysis).
    """
    t_start = time.perf_counter()
    opts = sweep_options(options)
    grid = frequency_grid(f_min, f_max, n_points, opts.spacing)
    check_inputs(model, basis, f_min, anchor=anchor)
    if model.contact.has_connectors:  # the time-domain solver has rigid contacts only
        opts = opts.replace(time_domain=None)
    condenser = condenser_for(model, condenser)  # one for every condensation of the sweep
    if not getattr(condenser, "models_in_time", True):  # a sector (hb/cyclic.py)
        opts = opts.replace(time_domain=None)
    band = (f_min, f_max) if opts.eps_band is None else opts.eps_band
    eps = sweep_penalty(opts.eps, model, [0, *basis.harmonics], *band, spacing=opts.spacing,
                        condenser=condenser)
    probs = Problems(model, basis, gap, eps, condenser, opts.solve.jacobian,
                     exact_at=2 * np.pi * grid, solve=opts.solve)
    warnings = []
    if anchor is None:
        preload = preload_anchor(model, condenser=condenser)
        anchor = preload.values
        if not preload.success:
            warnings.append(preload.warning)
    branch = Branch(model, anchor, opts.flag, probs)
    shape = (model.contact.n_nodes, model.contact.dim, basis.size)
    key = _checkpoint_key(probs, grid, opts, anchor)
    first = 0
    if key is not None and opts.resume and Path(opts.checkpoint).exists():
        first, entries = load_sweep_checkpoint(opts.checkpoint, key, shape)
        branch.resume(probs, entries)
    resumed = first if key is not None and opts.resume and first else -1
    try:
        for i in range(first, len(grid)):
            branch.lap()  # the point's time starts here (SweepPoint.seconds)
            pt = _grid_point(point_ladder(Point(grid[i], probs, branch, opts)))
            branch.points.append(pt)
            if key is not None:
                save_sweep_checkpoint(opts.checkpoint, key, i + 1, branch.points, shape)
            if opts.progress is not None:
                opts.progress(i, len(grid), pt)
    except (KeyboardInterrupt, SystemError) as exc:
        # Ctrl-C: the same exception goes on, carrying the points computed so far
        # (``exc.partial``, a SweepResult) for the caller to write as partial results
        if interrupted(exc) and not hasattr(exc, "partial"):
            done = sorted(branch.points, key=lambda p: p.frequency_hz)
            exc.partial = SweepResult(done, time.perf_counter() - t_start, resumed, warnings,
                                      dict(probs.counts))
        raise
    branch.points.sort(key=lambda p: p.frequency_hz)
    return SweepResult(branch.points, time.perf_counter() - t_start, resumed, warnings,
                       dict(probs.counts))


def _checkpoint_key(probs: Problems, grid, opts: SweepOptions, anchor) -> str | None:
    """The fingerprint of the sweep's checkpoint (None without one): the model, basis, grid
    and everything that determines the points."""
    if opts.checkpoint is None:
        return None
    check_state_file(opts.checkpoint, WHAT)
    settings = {"eps": probs.eps, "gap": probs.gap, "anchor": anchor,
                **opts.solve.key_changes(SWEEP_POINT, CHECKPOINT_SOLVE_KEYS),
                "continuation": opts.continuation, "max_bisections": opts.max_bisections,
                "check": opts.flag is not None, "time_domain": opts.time_domain is not None}
    sector = getattr(probs.condenser, "sector", None)
    if sector is not None:  # a sector (hb/cyclic.py): its symmetry and the engine order
        settings["cyclic"] = [sector.n_sectors, probs.condenser.engine_order, sector.axis,
                              sector.point, sector.left_dofs, sector.right_dofs,
                              sector.neighbour]
    return fingerprint(probs.model, probs.basis, grid, settings)


def _grid_point(p: Point) -> SweepPoint:
    """The grid point of a ladder's outcome: converged (recorded on the branch, with its
    attempts) or not (no solution; why, and what a time integration found, in its flags)."""
    st = p.stats
    if st.success and not np.all(np.isfinite(p.U)):  # never a converged point of NaN or inf
        st.success = False
        st.message = f"the solution holds non-finite values (NaN or inf) in {FINITE_ARRAYS['U']}"
    if st.success:
        pt = p.branch.record(p.omega, p.prob, p.U, st, p.how)
        pt.solution.attempts = p.tried
    else:
        pt = SweepPoint(p.frequency, None, st, p.how,
                        [f"not converged: {st.message} (relative residual {st.residual:.2e}; "
                         f"{len(p.tried)} attempts)"])
        if p.time_domain is not None:
            pt.flags.append(p.time_domain)
            pt.time_domain = p.time_domain
        pt.seconds, pt.cpu_seconds = p.branch.lap()
    pt.on_grid = True
    pt.attempts = p.tried
    pt.fallback_seconds = p.fallback_seconds
    return pt
