"""Settings of a wear simulation: :class:`WearOptions`, the one definition of every option
and its default (case files take theirs from it, :mod:`fretwear.analyses.wear`), and the fixed
constants of the slow-scale steps.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import asdict, dataclass

from fretwear.errors import InputError
from fretwear.hb.options import WEAR_STEP, SolveOptions
from fretwear.wear.laws import LAWS

SCHEMES = ("implicit", "rosenbrock", "explicit")
#: how the ``"implicit"`` scheme solves its step (:class:`WearOptions` ``implicit_newton``)
IMPLICIT_NEWTONS = ("nested", "coupled")
STOP_REASONS = ("max_cycles", "max_depth", "plateau", "no_wear", "max_steps", "solver_failed")
#: retried jumps are not cut below this fraction of the cycle count
MIN_JUMP_FRACTION = 1e-5
#: with a time-domain step behind, failed solves do not cut the jump below this fraction of N
RESCUE_START_FRACTION = 1e-3
#: iteration cap of a balance started from a time integration
RESCUE_MAX_ITER = 400
#: periods integrated from rest when the unworn interface has no periodic balance
START_SETTLE = 2000
#: first jump of such a run [cycles] (no slow Jacobian to size it)
START_JUMP = 1e4
#: responses of a time-domain step from which the balance is tried
#: (:func:`~fretwear.wear.time_steps.time_domain_step`)
BALANCE_KINDS = ("periodic", "drifting", "transient")
#: implicit schemes keep dN lam <= this for the growing modes (lam > 0) of the slow Jacobian
GROWTH_LIMIT = 0.5


@dataclass
class WearOptions:
    """Settings of a wear simulation (:func:`~fretwear.wear.simulate.simulate_wear`).

    Attributes
    ----------
    law : ``"archard"`` (eq. 29, coefficient ``model.contact.wear_coefficient`` [1/Pa]) or
        ``"energy"`` (Fouvry et al. 2003, ``energy_coefficient`` [m^3/J]).
    energy_coefficient : ``k_e`` [m^3/J] of the energy law (the surface of every contact
        node).
    partner_energy_coefficient : ``k_e`` [m^3/J] of the partner surfaces of node-to-node
        pairs under the energy law (None: they do not wear); the gap of a pair opens by both.
    scheme : ``"rosenbrock"`` (linearly implicit Euler with the slow Jacobian; default: the
        cheapest for a given accuracy, docs/wear.md), ``"implicit"`` (backward Euler, every
        iterate a balanced solution) or ``"explicit"`` (explicit Euler, eq. 30).
    implicit_newton : how ``"implicit"`` solves its step: ``"nested"`` (Newton on W over
        balanced solutions) or ``"coupled"`` (Newton on (U~, W1) together).
    adaptive : adapt the jump to ``tolerance``; otherwise every jump is ``initial_jump``.
    tolerance : local error allowed per step, relative to the current maximum wear depth.
    initial_jump : first jump [cycles]; None: ``2 tolerance / rho`` with ``rho`` the spectral
        radius of the slow Jacobian at the start (adaptive), or ``1 / rho`` (fixed jumps: half
        the explicit stability limit).
    max_jump : cap on the jump [cycles] (the paper's 1e8 / 1e7).
    min_jump : smallest jump tried when retrying failed solves [cycles]; the floor is also at
        least 1e-5 of the cycle count (smaller jumps cannot change the outcome).
    max_cycles : stop at this cycle count.
    max_depth : stop when a wear depth reaches this [m].
    plateau_rate : stop when the worn-volume rate falls below this fraction of its initial
        value (the plateau of paper Fig. 25).
    max_steps : stop after this many slow steps.
    solve : :class:`~fretwear.hb.options.SolveOptions` of the periodic balances (default
        :data:`~fretwear.hb.options.WEAR_STEP`): the nonlinear solver, its relative residual
        tolerance ``eps_r`` and iteration cap, the Jacobian, and the attempts of the first
        (unworn) balance (``strategy``; later balances are warm-started and retried by the
        slow steps themselves).
    max_iter_coupled : iteration cap of the Newton method on the coupled unknowns
        (``implicit_newton = "coupled"``).
    max_iter_implicit : Newton iterations on ``W`` of a backward Euler step
        (``implicit_newton = "nested"``).
    max_retries : jump reductions (by 4) tried after a failed solve before stopping.
    time_domain_rescue : (dynamic cases) when a step's periodic balance fails, take the step
        from a time integration at the predicted wear
        (:func:`~fretwear.wear.time_steps.time_domain_step`): from its periodic state when it
        has one and the balance converges from there, otherwise with the wear rate averaged
        over its periods (:mod:`fretwear.timedomain.averaged_rate`).
    time_domain_settle, time_domain_average : periods integrated before averaging, and
        averaged, by such a step.
    time_domain_steps : time steps per period of such a step (default ``max(128, 8 x`` the
        highest harmonic)); stick-slip events are first order in the step (docs/wear.md).
    checkpoint_every_s : write the checkpoint at most this often [s] (0: every step).
    """

    law: str = "archard"
    energy_coefficient: float | None = None
    partner_energy_coefficient: float | None = None
    scheme: str = "rosenbrock"
    adaptive: bool = True
    tolerance: float = 1e-2
    initial_jump: float | None = None
    max_jump: float = math.inf
    min_jump: float = 1.0
    max_cycles: float = 1e12
    max_depth: float = math.inf
    plateau_rate: float = 1e-3
    max_steps: int = 10_000
    solve: SolveOptions = WEAR_STEP
    max_iter_coupled: int = 20
    max_iter_implicit: int = 8
    implicit_newton: str = "nested"
    max_retries: int = 6
    time_domain_rescue: bool = True
    time_domain_settle: int = 300
    time_domain_average: int = 500
    time_domain_steps: int | None = None
    checkpoint_every_s: float = 10.0

    def __post_init__(self):
        self.check()

    def check(self) -> WearOptions:
        """Validate (also done at construction); raise InputError (a ValueError) naming the
        option and the bad value."""
        if not isinstance(self.solve, SolveOptions):
            raise InputError(f"solve = {self.solve!r}: expected a SolveOptions (e.g. "
                             "WEAR_STEP.replace(tol=1e-10))")
        for name, choices in (("law", LAWS), ("scheme", SCHEMES),
                              ("implicit_newton", IMPLICIT_NEWTONS)):
            v = getattr(self, name)
            if not (isinstance(v, str) and v in choices):
                raise InputError(f"{name} = {v!r}: expected one of {choices}")
        for name in ("adaptive", "time_domain_rescue"):
            v = getattr(self, name)
            if not isinstance(v, bool):
                raise InputError(f"{name} = {v!r}: expected True or False")
        for name in ("tolerance", "max_jump", "min_jump", "max_cycles", "max_depth"):
            v = getattr(self, name)
            if not (_is_number(v) and v > 0):
                raise InputError(f"{name} = {v!r}: expected a positive number")
            if name == "tolerance" and not v <= 1.0:
                raise InputError(f"tolerance = {v!r}: expected a relative error in (0, 1]")
            if math.isfinite(v) and v > 1e20 or (math.isinf(v) and name in ("tolerance",
                                                                             "min_jump")):
                raise InputError(f"{name} = {v!r}: expected a positive number up to 1e20 "
                                 "(inf: no limit)")
        if self.initial_jump is not None and not (_is_number(self.initial_jump)
                                                  and self.initial_jump > 0):
            raise InputError(f"initial_jump = {self.initial_jump!r}: expected > 0 cycles")
        for name in ("energy_coefficient", "partner_energy_coefficient"):
            ke = getattr(self, name)
            if ke is not None and not (_is_number(ke) and ke >= 0):
                raise InputError(f"{name} = {ke!r}: expected k_e >= 0 [m^3/J] or None")
        if self.law == "energy" and self.energy_coefficient is None:
            raise InputError("energy_coefficient = None with law = 'energy': expected k_e "
                             "[m^3/J], the worn volume per unit friction energy")
        if self.law != "energy" and self.partner_energy_coefficient is not None:
            raise InputError(f"partner_energy_coefficient = {self.partner_energy_coefficient!r}"
                             f" with law = {self.law!r}: only the energy law uses it (the "
                             "partner's Archard coefficient is the contact's "
                             "partner_wear_coefficient)")
        for name in ("plateau_rate", "checkpoint_every_s"):
            v = getattr(self, name)
            if not (_is_number(v) and v >= 0):
                raise InputError(f"{name} = {v!r}: expected a number >= 0")
        if not self.plateau_rate <= 1.0:
            raise InputError(f"plateau_rate = {self.plateau_rate!r}: expected a fraction of the "
                             "initial rate in [0, 1]")
        for name, lo in (("max_steps", 1), ("max_iter_coupled", 1),
                         ("max_iter_implicit", 0), ("max_retries", 0)):
            v = getattr(self, name)
            if not (_is_integer(v) and v >= lo):
                raise InputError(f"{name} = {v!r}: expected a whole number >= {lo}")
        for name in ("time_domain_settle", "time_domain_average"):
            v = getattr(self, name)
            if not (_is_integer(v) and v >= (0 if name.endswith("settle") else 2)):
                raise InputError(f"{name} = {v!r}: expected a whole number of periods"
                                 + (" >= 0" if name.endswith("settle") else " >= 2"))
        ts = self.time_domain_steps
        if ts is not None and not (_is_integer(ts) and ts >= 8):
            raise InputError(f"time_domain_steps = {ts!r}: expected a whole number >= 8 of "
                             "time steps per period")
        return self

    def trajectory_key(self) -> dict:
        """The options that change the computed trajectory (for checkpoint matching). The stop
        criteria are not among them: a finished run can be extended (e.g. a larger
        ``max_cycles``) by resuming from its checkpoint. The solve's part is
        :meth:`~fretwear.hb.options.SolveOptions.key` (solver, tol, max_iter, and the other
        settings where they differ from :data:`~fretwear.hb.options.WEAR_STEP`: the keys of
        the checkpoints written before the record)."""
        d = {k: v for k, v in asdict(self).items() if k != "solve"}
        for k in ("checkpoint_every_s", "max_cycles", "max_depth", "plateau_rate", "max_steps"):
            d.pop(k)
        d.update(self.solve.key_changes(WEAR_STEP))
        if d["partner_energy_coefficient"] is None:  # the checkpoints written before it
            d.pop("partner_energy_coefficient")
        return d


def _is_number(v) -> bool:
    """A real number (numpy's included), not a boolean."""
    return isinstance(v, numbers.Real) and not isinstance(v, bool)


def _is_integer(v) -> bool:
    """A whole number of an integer type (numpy's included), not a boolean (2.0 is refused),
    of magnitude at most 2^62 (as the case files' integer keys)."""
    return isinstance(v, numbers.Integral) and not isinstance(v, bool) and abs(v) <= 2**62
