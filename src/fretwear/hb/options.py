"""Settings of a periodic solve: :class:`SolveOptions`, the one record of the nonlinear solver,
its tolerance and iteration cap, the attempt ladder and the Jacobian, with one set of
defaults, taken by every driver (``solve_periodic``, ``sweep``, the wear slow steps, the
worn FRF) as ``options=`` and embedded by :class:`fretwear.wear.options.WearOptions`.

A driver whose own defaults differ (a sweep point is a warm start, so it spends fewer
iterations before its own ladder moves on) names them here, once, as a preset
(:data:`SWEEP_POINT`, :data:`WEAR_STEP`): no other module spells a tolerance or an iteration
cap of the periodic solve.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from dataclasses import dataclass

from fretwear.errors import InputError

#: the nonlinear solvers (:func:`fretwear.hb.solvers.solve`)
SOLVERS = ("powell", "newton", "hybr")
#: how the Newton step is computed: ``"dense"`` (LAPACK LU of the formed Jacobian),
#: ``"krylov"`` (GMRES on the Jacobian as an operator, :mod:`fretwear.hb.krylov`), ``"auto"``
JACOBIANS = ("auto", "dense", "krylov")
#: the rungs of the attempt ladder of a single solve, in the order they are tried
#: (:mod:`fretwear.hb.attempts`)
STRATEGY = ("start", "best-point", "eps-continuation", "harmonic-continuation", "time-start")
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
    """

    solver: str = "powell"
    tol: float = 1e-8
    max_iter: int = 200
    strategy: tuple = STRATEGY
    jacobian: str = "auto"

    def __post_init__(self):
        if isinstance(self.strategy, list):
            object.__setattr__(self, "strategy", tuple(self.strategy))
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
        if not (isinstance(n, numbers.Integral) and not isinstance(n, bool) and n >= 1):
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
                "strategy": list(self.strategy), "jacobian": self.jacobian}


#: a single periodic solve (``solve_periodic``)
PERIODIC = SolveOptions()
#: one point of a sweep: warm-started from its neighbour, few iterations before the sweep's
#: own ladder (substeps, other solver, arclength, ...) takes over
SWEEP_POINT = SolveOptions(max_iter=40)
#: the balance of a wear slow step (a tighter tolerance: the wear rate is a derivative of
#: the balance)
WEAR_STEP = SolveOptions(tol=1e-9, max_iter=60)
