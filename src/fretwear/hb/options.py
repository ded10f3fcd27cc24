"""Settings of a periodic solve: :class:`SolveOptions`, the one record of the nonlinear solver,
its tolerance and iteration cap, the attempt ladder and the Jacobian, with one set of
defaults, taken by every driver (``solve_periodic``, ``sweep``, the wear slow steps, the
worn FRF) as ``options=`` and embedded by :class:`fretwear.wear.options.WearOptions` and by
:class:`SweepOptions`, the settings of a frequency sweep.

A driver whose own defaults differ (a sweep point is a warm start, so it spends fewer
iterations before its own ladder moves on) names them here, once, as a preset
(:data:`SWEEP_POINT`, :data:`WEAR_STEP`): no other module spells a tolerance or an iteration
cap of the periodic solve.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import os
from collections.abc import Callable
from dataclasses import dataclass

from fretwear.errors import InputError
from fretwear.hb.fallback import TimeDomainFallback
from fretwear.hb.solvers import KRYLOV as KRYLOV
from fretwear.hb.solvers import PRECONDITIONERS as PRECONDITIONERS
from fretwear.hb.solvers import SOLVERS, KrylovOptions

#: how the Newton step is computed: ``"dense"`` (LAPACK LU of the formed Jacobian),
#: ``"krylov"`` (GMRES on the Jacobian as an operator, :mod:`fretwear.hb.krylov`), ``"auto"``
JACOBIANS = ("auto", "dense", "krylov")
#: the rungs of the attempt ladder of a single solve, in the order they are tried
#: (:mod:`fretwear.hb.attempts`)
STRATEGY = ("start", "best-point", "eps-continuation", "harmonic-continuation", "time-start")
def _is_integer(v) -> bool:
    """A whole number of an integer type (numpy's included), not a boolean, of magnitude at
    most 2^62 (as the case files' integer keys: no count comes near it)."""
    return isinstance(v, numbers.Integral) and not isinstance(v, bool) and abs(v) <= 2**62


#: the solver a rung "other solver" switches to
OTHER_SOLVER = {"powell": "newton", "newton": "powell", "hybr": "powell"}


@dataclass(frozen=True)
class SolveOptions:
    """Settings of the DLFT periodic solve (paper section 3.2: the nonlinear system eq. 22 is
    solved by hybrid Powell with the quasi-analytic Jacobian eq. 28).

    Attributes
    ----------
    solver : ``"powell"`` (hybrid Powell, default), ``"newton"`` (damped Newton) or ``"hybr"``
        (MINPACK's hybrj through SciPy).
    tol : relative residual ``eps_r`` at which a solve has converged (``|f| / |F| <= tol``).
    max_iter : iteration cap of one attempt.
    strategy : the rungs of the attempt ladder tried until one converges, a subset of
        :data:`STRATEGY` in that order.
    jacobian : :data:`JACOBIANS`; ``"auto"`` forms the Jacobian up to
        ``fretwear.hb.problem.DENSE_JACOBIAN_MAX`` unknowns and uses it as an operator above.
    time_domain_periods : forcing periods allowed to the time integration of the rung
        ``"time-start"`` (single solves and sweep points, when the driver is given a
        time-domain fallback).
    krylov : :class:`KrylovOptions`, the linear algebra of the Newton step on the operator
        path (a dict of its fields is taken too); default :data:`KRYLOV`.
    """

    solver: str = "powell"
    tol: float = 1e-8
    max_iter: int = 200
    strategy: tuple = STRATEGY
    jacobian: str = "auto"
    time_domain_periods: int = 3000
    krylov: KrylovOptions = KRYLOV

    def __post_init__(self):
        if isinstance(self.strategy, list):
            object.__setattr__(self, "strategy", tuple(self.strategy))
        if isinstance(self.krylov, dict):
            names = [f.name for f in dataclasses.fields(KrylovOptions)]
            unknown = sorted(set(self.krylov) - set(names))
            if unknown:
                raise InputError(f"krylov = {self.krylov!r}: unknown field(s) {unknown}; "
                                 f"expected fields from {names}")
            object.__setattr__(self, "krylov", KrylovOptions(**self.krylov))
        self.check()

    def check(self) -> SolveOptions:
        """Validate (also done at construction): one InputError naming the option, the value
        and what is expected."""
        if not (isinstance(self.solver, str) and self.solver in SOLVERS):
            raise InputError(f"solver = {self.solver!r}: expected one of {SOLVERS}")
        if not (isinstance(self.jacobian, str) and self.jacobian in JACOBIANS):
            raise InputError(f"jacobian = {self.jacobian!r}: expected one of {JACOBIANS}")
        t = self.tol
        if not (isinstance(t, numbers.Real) and not isinstance(t, bool) and math.isfinite(t)
                and 0 < t < 1):
            raise InputError(f"tol = {t!r}: expected a relative residual between 0 and 1 "
                             "(e.g. 1e-8)")
        n = self.max_iter
        if not (_is_integer(n) and n >= 1):
            raise InputError(f"max_iter = {n!r}: expected a whole number >= 1")
        s = self.strategy
        if not (isinstance(s, tuple) and s and all(isinstance(r, str) for r in s)):
            raise InputError(f"strategy = {s!r}: expected a non-empty list of rungs from "
                             f"{STRATEGY}")
        unknown = [r for r in s if r not in STRATEGY]
        if unknown:
            raise InputError(f"strategy = {list(s)}: unknown rung(s) {unknown}; expected "
                             f"rungs from {STRATEGY}")
        if len(set(s)) != len(s):
            raise InputError(f"strategy = {list(s)}: a rung is named twice")
        p = self.time_domain_periods
        if not (_is_integer(p) and p >= 1):
            raise InputError(f"time_domain_periods = {p!r}: expected a whole number of "
                             "periods >= 1")
        if not isinstance(self.krylov, KrylovOptions):
            raise InputError(f"krylov = {self.krylov!r}: expected a KrylovOptions record")
        return self

    def replace(self, **changes) -> SolveOptions:
        """A copy with ``changes`` (checked)."""
        return dataclasses.replace(self, **changes)

    @property
    def other_solver(self) -> str:
        """The solver a retry with "the other solver" uses (:data:`OTHER_SOLVER`)."""
        return OTHER_SOLVER[self.solver]

    def key(self) -> dict:
        """The settings as plain values, for checkpoint fingerprints."""
        return {"solver": self.solver, "tol": float(self.tol), "max_iter": int(self.max_iter),
                "strategy": list(self.strategy), "jacobian": self.jacobian,
                "time_domain_periods": int(self.time_domain_periods),
                "krylov": self.krylov.key()}

    def key_changes(self, preset: SolveOptions, always=("solver", "tol", "max_iter")) -> dict:
        """The part of :meth:`key` that a checkpoint fingerprint takes: the settings
        ``always``, and any other that differs from ``preset`` (a fingerprint written before
        a setting existed still matches while that setting keeps its default)."""
        mine, ref = self.key(), preset.key()
        return {k: v for k, v in mine.items() if k in always or v != ref[k]}


#: a single periodic solve (``solve_periodic``)
PERIODIC = SolveOptions()
#: one point of a sweep: warm-started from its neighbour, few iterations before the sweep's
#: own ladder (substeps, other solver, arclength, ...) takes over
SWEEP_POINT = SolveOptions(max_iter=40)
#: the balance of a wear slow step (a tighter tolerance: the wear rate is a derivative of
#: the balance); the first (unworn) balance tries the solver alone: a wear run has its own
#: fallback, a start from a time integration (:mod:`fretwear.wear.time_steps`)
WEAR_STEP = SolveOptions(tol=1e-9, max_iter=60, strategy=("start",))

#: grid spacings of a sweep (:func:`fretwear.hb.sweep.frequency_grid`)
SPACINGS = ("log", "linear")


@dataclass(frozen=True)
class SweepOptions:
    """Settings of a frequency sweep (:func:`fretwear.hb.sweep.sweep`): the solve of one point,
    the grid spacing, the penalty, the steps of the sweep point's ladder, the time-domain parts
    and the checkpoint.

    Attributes
    ----------
    solve : :class:`SolveOptions` of one point (default :data:`SWEEP_POINT`: a warm start from
        the neighbours, 40 iterations before the sweep's own ladder takes over).
    spacing : ``"log"`` or ``"linear"`` grid.
    eps : DLFT penalty, one value for every point (:func:`fretwear.hb.penalty.sweep_penalty`):
        ``"contact"`` (default: ``"stiff"`` on rigid sliders under a prescribed normal load,
        ``"top"`` elsewhere), ``"top"`` (the spectral radius of ``Z_r`` at the highest kept
        harmonic, its median over the band), ``"stiff"`` (ten times ``"top"``), ``"static"``,
        ``"auto"`` (the paper's rule at each frequency) or a positive number [N/m].
    eps_band : ``(f_min, f_max)`` [Hz] over which ``"contact"``, ``"stiff"`` and ``"top"``
        take their median
        (default: the
        sweep's band; the chunks of a split sweep give the whole band).
    continuation : pseudo-arclength continuation when a grid step fails.
    max_bisections : halvings of a failed frequency step.
    flag : ``(PeriodicSolution) -> list[str]``, reasons for caution about every converged
        point (e.g. the time-domain stability check of :mod:`fretwear.timedomain.stability`);
        None: none.
    time_domain : the :class:`~fretwear.hb.fallback.TimeDomainFallback` of the last rung of a
        point (``"time-start"``, for ``solve.time_domain_periods`` periods); None: none.
    progress : ``(i, n, point)`` called after each grid point; None: none.
    checkpoint : path of the ``.npz`` file of the points computed so far
        (:mod:`fretwear.hb.sweep_checkpoint`); None: none.
    resume : continue from ``checkpoint`` when it exists.
    """

    solve: SolveOptions = SWEEP_POINT
    spacing: str = "log"
    eps: str | float = "contact"
    eps_band: tuple | None = None
    continuation: bool = True
    max_bisections: int = 4
    flag: Callable | None = None
    time_domain: TimeDomainFallback | None = None
    progress: Callable | None = None
    checkpoint: str | os.PathLike | None = None
    resume: bool = False

    def __post_init__(self):
        if self.eps_band is not None:
            object.__setattr__(self, "eps_band", _band(self.eps_band))
        self.check()

    def check(self) -> SweepOptions:
        """Validate (also done at construction): one InputError naming the option."""
        if not isinstance(self.solve, SolveOptions):
            raise InputError(f"solve = {self.solve!r}: expected a SolveOptions")
        if self.spacing not in SPACINGS:
            raise InputError(f"spacing = {self.spacing!r}: expected \"log\" or \"linear\"")
        for name in ("continuation", "resume"):
            if not isinstance(getattr(self, name), bool):
                raise InputError(f"{name} = {getattr(self, name)!r}: expected True or False")
        n = self.max_bisections
        if not (_is_integer(n) and n >= 0):
            raise InputError(f"max_bisections = {n!r}: expected a whole number >= 0")
        for name in ("flag", "progress"):
            v = getattr(self, name)
            if v is not None and not callable(v):
                raise InputError(f"{name} = {v!r}: expected a callable or None")
        if self.time_domain is not None and not isinstance(self.time_domain,
                                                            TimeDomainFallback):
            raise InputError(f"time_domain = {self.time_domain!r}: expected a "
                             "TimeDomainFallback or None")
        if self.checkpoint is not None and not isinstance(self.checkpoint, str | os.PathLike):
            raise InputError(f"checkpoint = {self.checkpoint!r}: expected a path or None")
        return self

    def replace(self, **changes) -> SweepOptions:
        """A copy with ``changes`` (checked)."""
        return dataclasses.replace(self, **changes)


#: a sweep as case files and ``fretwear.sweep`` run it by default
SWEEP = SweepOptions()


def sweep_options(options, base: SweepOptions = SWEEP) -> SweepOptions:
    """The :class:`SweepOptions` of a driver's ``options`` argument: itself, ``base`` for None,
    or ``base`` with that solve for a :class:`SolveOptions` (``sweep(..., options=SWEEP_POINT
    .replace(tol=1e-10))``)."""
    if options is None:
        return base
    if isinstance(options, SolveOptions):
        return base.replace(solve=options)
    if isinstance(options, SweepOptions):
        return options
    raise InputError(f"options = {options!r}: expected a SweepOptions or a SolveOptions")


def _band(eps_band) -> tuple[float, float]:
    try:
        lo, hi = (float(v) for v in eps_band)
    except (TypeError, ValueError):
        raise InputError(f"eps_band = {eps_band!r}: expected (f_min, f_max) in Hz") from None
    if not (0.0 < lo <= hi < math.inf):
        raise InputError(f"eps_band = {eps_band!r}: expected 0 < f_min <= f_max [Hz]")
    return lo, hi
