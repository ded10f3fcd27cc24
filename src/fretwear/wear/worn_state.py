"""The worn state directly: where fretting wear stops, without marching through every cycle.

The slow-scale equation of a wear run (paper eq. 29) is ``dW/dN = g(W)``, ``g_p >= 0`` the wear
depth per cycle of contact node ``p`` on the DLFT balance at the worn gap ``gap + W``. Its
asymptotic (worn) state ``W*`` has a null wear rate, ``g(W*) = 0``: every node that still
carries load sticks, every node that slipped has worn until it no longer carries load (the
Ciavarella-Hills result for a partial-slip punch). :func:`worn_state` finds it by
pseudo-transient continuation (Kelley and Keyes, SIAM J. Numer. Anal. 35, 1998):

    W_{k+1} = W_k + dN_k (I - dN_k Js_k)^-1 g(W_k),      then the DLFT balance at W_{k+1}

the linearly implicit Euler step of the march (:mod:`fretwear.wear.schemes`, ``Js = dg/dW``
along balanced solutions). While the set of slipping nodes changes, ``dN_k`` comes from the
march's error control (``path_tolerance``): the state is not unique, it depends on the path
(which nodes stick, and when), so that part is followed. Once the slipping set has settled
and the rate decays (below ``settle_rate`` of the initial one), the step is set by switched
evolution relaxation (SER),
``dN_{k+1} = dN_k min_growth V'_k / V'_{k+1}`` (``V'`` the worn-volume rate, growth capped at
``max_growth``): it grows without bound as the rate falls, and the iteration turns into
Newton's method on ``g(W) = 0`` (``dW -> -Js^-1 g``), the direct solve of the null-wear-rate
condition. A step that wears a node into separation for the whole period (past its lift-off,
where the rate is 0 too) is pulled back to the lift-off (:func:`_pull_back`). Where a
growing mode of ``Js`` (a stuck neighbour loaded until it slips) would cut the march's step,
the step is the exponential Euler one, which follows the growth exactly in fewer steps
(``exponential``, :mod:`fretwear.wear.exponential_step`).

Honesty (issue 29): the state is reported reached only when the null-wear-rate residual

    r = max_p g_p(W) / max_p g_p(W0)

(the wear rate left, relative to the initial one) is at most ``tolerance`` AND the last
correction is at most ``depth_tolerance`` of the deepest wear (a small rate with a slow mode
that would still carry the profile far is not a state). Otherwise ``success`` is False with
the residual and the steps tried; the state is never claimed from a plateau of the march.

The stick-set jump (``stick_set``, :mod:`fretwear.wear.stick_set`) characterises the state
by its stick set instead: the nodes that wear unloaded until they just touch, every other
node sticking, one balance. Once the worn-volume rate has fallen to ``jump_rate`` (0.3) of
the initial one it is tried from the path's states, and the run ends on it when the jumps
from two states agree AND the path step between them covered at least ``jump_progress``
(0.25) of the way to the first (:class:`_Jumps`): agreement alone is not enough, the jumps
from many successive states of Stromberg's beam agree on a state 8.1 % of the deepest wear
from the march's (two loaded nodes that stick there slip and wear a million cycles later).
It is off by default: the rule is measured on three cases, not proved, and gains little
(docs/theory.md).

Wear that goes on (gross slip) has no null-rate state; when the rate stops changing (``max
|g_{k+1} - g_k| <= tolerance max g``) over a step that moved the profile by
``depth_tolerance`` of the larger of the deepest wear and the contact's displacement
(:func:`_moved`) while the residual stays large, the result says so
(``kind = "steady_wear"``) with the steady rate profile.

The number of cycles a march needs to get within 1 % of the state is estimated (it is an
estimate, :func:`cycles_to_one_percent`): each step's worn volume over the log-mean of the
worn-volume rates at its ends (the time an exponentially decaying rate takes to wear it).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from fretwear.errors import InputError, interrupted
from fretwear.hb.fallback import TimeDomainFallback
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.inputs import check_inputs
from fretwear.hb.solution import PeriodicSolution
from fretwear.hb.solvers import SolveStats
from fretwear.model.core import Model
from fretwear.resources import require_memory
from fretwear.validate import number, whole
from fretwear.wear.checkpoint import check_checkpoint_path, fingerprint
from fretwear.wear.exponential_step import exponential_step
from fretwear.wear.history import WearHistory
from fretwear.wear.laws import coefficient_keys, worn_volume
from fretwear.wear.options import WearOptions
from fretwear.wear.schemes import first_state
from fretwear.wear.simulate import (
    BalanceSetup,
    RunControl,
    _assemble,
    _frequency,
    _Saver,
    _step,
    slow_setup,
)
from fretwear.wear.slow_problem import SlowProblem
from fretwear.wear.state import SlowStep, StepRecord, StepStats
from fretwear.wear.stick_set import separation, stick_set_state

#: what a worn-state result found: the null-wear-rate state, steady wear (gross slip), none
KINDS = ("null_wear_rate", "steady_wear", "not_reached", "no_wear")


@dataclass(frozen=True)
class WornStateOptions:
    """Options of :func:`worn_state`.

    Attributes
    ----------
    wear : :class:`~fretwear.wear.options.WearOptions`: the wear law and its coefficients,
        the periodic solves (``solve``), the retries of a failed step (``max_retries``) and
        the time-domain rescue; its scheme, error control and stop criteria are not used.
    tolerance : the null-wear-rate residual ``max g / max g0`` at which the state is reached.
    depth_tolerance : the largest last correction, relative to the deepest wear, of a
        reached state.
    max_steps : pseudo-time steps before giving up.
    initial_jump : first step [cycles]; None: the march's (``path_tolerance x 2 / rho``,
        rho the spectral radius of ``Js`` at the start).
    path_tolerance : the local error per step (relative to the deepest wear) of the steps
        that follow the path while the set of slipping nodes changes (the march's error
        control, :mod:`fretwear.wear.step_control`).
    max_growth : largest growth of the step from one step to the next.
    min_growth : the SER factor ``|g_k| / |g_{k+1}|`` (worn-volume rates) is multiplied by
        this: the step grows by it while the rate stays, faster as it falls; a step that
        changed the set of slipping nodes is not followed by a larger one (the stick
        events decide where the state ends).
    stick_set : try the stick-set jump (:mod:`fretwear.wear.stick_set`) from the states of
        the path once the worn-volume rate has fallen to ``jump_rate`` of the initial one, and
        end there when the jumps from two states agree and the path heads for them (module
        docstring).
        Off by default: the rule that says when the jump lands on the march's state is
        measured on three quasi-static examples (safe on each, 0.94-1.56 times the march's
        speed in DLFT solves), not proved; the result then warns.
    jump_rate : with ``stick_set``, the jumps are tried once the worn-volume rate has fallen
        to this fraction of the initial one (before, the jumps from successive states keep
        moving: docs/studies/worn-state-cost.md, "The stick-set jump along the path").
    jump_progress : with ``stick_set``, a jump is taken when the last path step covered at
        least this fraction of the way from the state before to the jump from there (and the
        jumps from both states agree): the path is heading for the jump's state. Measured on
        the three quasi-static examples: the jumps that land away from the march's state
        (Stromberg's beam, 8.1 %) had 0.11-0.22 with agreeing jumps; the first taken jumps
        0.26-0.33 (a margin of 1.2, not a proof).
    exponential : where a growing mode of the slow Jacobian would cut the step (wear moving
        load onto a stuck neighbour until it slips), take the exponential Euler step, which
        follows it exactly (:mod:`fretwear.wear.exponential_step`; on Stromberg's beam 51
        steps instead of 63 to the same state); elsewhere the step is the march's. False:
        the march's step throughout.
    order : 1: the path steps as above (first order, the march's error control); 2: the
        exponential Rosenbrock-Euler step on every path step, second order with the exact
        slow Jacobian, its error estimated by the embedded third-order correction and the
        jump controlled with the cube root (:mod:`fretwear.wear.exponential_step`; measured
        in docs/studies/method-costs.md).
    settle_rate : the path counts as settled (the relaxation steps may start) only once the
        worn-volume rate has fallen to this fraction of the initial one, besides the same
        slipping nodes over three records and a falling rate (without it the relaxation
        started at the third step of a reduced triangle beam, whose rate had fallen by
        0.1 %, and jumped over the slip events to come: 0.73 % of the deepest wear from the
        march's state instead of 1e-5).
    events : end a path step whose slow Jacobian has a growing mode at the first change of
        the contact-state pattern (a node starting or ending to slip or to open) predicted
        along the linearised path (:mod:`fretwear.wear.events`), instead of at the growth
        limit. Off by default: measured on the three quasi-static examples it does not pay
        (the steps that land past an event need more Newton iterations than those it saves;
        docs/studies/method-costs.md, "Events along the path").
    """

    wear: WearOptions = field(default_factory=WearOptions)
    tolerance: float = 1e-6
    depth_tolerance: float = 1e-3
    max_steps: int = 200
    initial_jump: float | None = None
    max_growth: float = 100.0
    min_growth: float = 5.0
    path_tolerance: float = 1e-2
    stick_set: bool = False
    jump_rate: float = 0.3
    jump_progress: float = 0.25
    exponential: bool = True
    order: int = 1
    settle_rate: float = 0.01
    events: bool = False

    def __post_init__(self):
        if not isinstance(self.wear, WearOptions):
            raise InputError(f"wear = {self.wear!r}: expected a WearOptions")
        for name in ("tolerance", "depth_tolerance"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and not isinstance(v, bool) and 0 < v < 1):
                raise InputError(f"{name} = {v!r}: expected a number in (0, 1)")
        whole(self.max_steps, "max_steps", low=1, high=2**62)
        j = self.initial_jump
        if j is not None and not (isinstance(j, (int, float)) and j > 0):
            raise InputError(f"initial_jump = {j!r}: expected > 0 cycles or None")
        if self.order not in (1, 2) or isinstance(self.order, bool):
            raise InputError(f"order = {self.order!r}: expected 1 or 2")
        for name in ("stick_set", "exponential", "events"):
            if not isinstance(getattr(self, name), bool):
                raise InputError(f"{name} = {getattr(self, name)!r}: expected true or false")
        number(self.max_growth, "max_growth", low=1.0, open_low=True, high=1e6)
        number(self.min_growth, "min_growth", low=0.0, open_low=True, high=1e6)
        number(self.path_tolerance, "path_tolerance", low=0.0, open_low=True, high=1.0)
        number(self.settle_rate, "settle_rate", low=0.0, open_low=True, high=1.0)
        number(self.jump_rate, "jump_rate", low=0.0, open_low=True, high=1.0)
        number(self.jump_progress, "jump_progress", low=0.0, open_low=True, high=1.0)

    def march_options(self, path: bool = False) -> WearOptions:
        """The wear options of the steps: linearly implicit, no stop criterion of the march;
        with ``path`` the march's error control at ``path_tolerance``, else none (the step
        is set by SER)."""
        return replace(self.wear, scheme="rosenbrock", adaptive=path,
                       tolerance=self.path_tolerance, initial_jump=self.initial_jump,
                       max_cycles=math.inf, max_depth=math.inf, plateau_rate=0.0,
                       max_steps=10**9)

    def key(self) -> dict:
        """What changes the path (the checkpoint's fingerprint)."""
        key = {"initial_jump": self.initial_jump, "max_growth": self.max_growth,
               "min_growth": self.min_growth, "path_tolerance": self.path_tolerance,
               "stick_set": self.stick_set, "exponential": self.exponential,
               "settle_rate": self.settle_rate}
        if self.order != 1:  # (the checkpoints of first-order runs keep their key)
            key["order"] = self.order
        if self.events:
            key["events"] = True
        if self.stick_set:  # the jump rule's thresholds change where the run ends
            key["jump_rate"], key["jump_progress"] = self.jump_rate, self.jump_progress
        return key


@dataclass
class WornStateResult:
    """What :func:`worn_state` found.

    Attributes
    ----------
    success : the null-wear-rate state (or steady wear) was reached within the tolerances.
    kind : one of :data:`KINDS`.
    message : what was found or tried, with the residual.
    wear : (nc,) worn depths ``W`` [m] of the last iterate (the state when ``success``).
    rate : (nc,) wear depth per cycle there [m].
    residual : the null-wear-rate residual ``max g / max g0`` of the last iterate.
    correction : the last correction ``max |W_{k+1} - W_k| / max W``.
    cycles_to_1pc : an ESTIMATE of the cycles a march needs to get within 1 % of the
        deepest wear of the state (module docstring); NaN when not reached.
    worn_volume : sum ``area W`` [m^3].
    history : the pseudo-time steps (:class:`~fretwear.wear.history.WearHistory`; its
        ``cycles`` are pseudo-time, not physical cycles).
    initial, final : periodic solutions at the start and at the last iterate.
    penalty : DLFT penalty [N/m]; dlft_solves : periodic balances solved (Newton iterations
        and slow Jacobians, as counted by the march); wall_time : [s].
    resumed_from : step of the checkpoint it resumed from (-1: a fresh run).
    warnings : reasons for caution.
    """

    success: bool
    kind: str
    message: str
    wear: np.ndarray
    rate: np.ndarray
    residual: float
    correction: float
    cycles_to_1pc: float
    worn_volume: float
    history: WearHistory
    initial: PeriodicSolution | None
    final: PeriodicSolution | None
    penalty: float
    dlft_solves: int
    wall_time: float
    resumed_from: int = -1
    warnings: list = field(default_factory=list)


def worn_state(model: Model, basis: FourierBasis, *, frequency: float | None = None,
               quasi_static: bool = False, options: WornStateOptions | None = None,
               wear0=None, balance: BalanceSetup | None = None, run: RunControl | None = None,
               time_domain: TimeDomainFallback | None = None) -> WornStateResult:
    """The asymptotic worn state ``g(W*) = 0`` by pseudo-transient continuation on the slow
    equation ``dW/dN = g(W)`` (eq. 29; module docstring), with the DLFT balance (eq. 22)
    solved at every iterate.

    Parameters are those of :func:`fretwear.wear.simulate.simulate_wear` (``run.checkpoint``
    keeps the pseudo-time state, ``run.resume`` continues it), with ``options`` a
    :class:`WornStateOptions`.

    Returns
    -------
    :class:`WornStateResult`; ``success`` False (with the residual) when the state was not
    reached in ``options.max_steps`` steps or a step failed.
    """
    if options is None:
        options = WornStateOptions()
    if not isinstance(options, WornStateOptions):
        raise InputError(f"options = {options!r}: expected a WornStateOptions")
    balance = balance or BalanceSetup()
    run = run or RunControl()
    opts = options.march_options()
    frequency = check_inputs(model, basis, _frequency(frequency, quasi_static),
                             quasi_static=quasi_static, anchor=balance.anchor, U0=balance.U0)
    if model.contact.prescribed_nodes().any():
        raise InputError("contact normal_load: the worn state needs the normal contact to come "
                         "from the structure (a prescribed normal load does not move with the "
                         "worn gap)")
    if model.contact.has_connectors or not getattr(balance.condenser, "models_in_time", True):
        time_domain = None
    if run.checkpoint is not None:
        check_checkpoint_path(run.checkpoint)
    t_start = time.perf_counter()
    nc, d = model.contact.dofs.shape
    check_history(options.max_steps, nc, d, basis.size)
    condenser, reduced, coef, wear0, anchor, warnings, sp = slow_setup(
        model, basis, frequency, quasi_static, balance, opts, wear0, time_domain)
    key = fingerprint(model, reduced, basis, sp.eps, coef,
                      replace(opts, initial_jump=options.initial_jump), wear0, anchor)
    key = f"worn-state {options.key()} {key}"
    saver = _Saver(run.checkpoint, key, opts.checkpoint_every_s)
    if run.resume and saver.exists():
        state, records = saver.load(shape=(nc, d, sp.H))
        resumed_from = state.step
    else:
        state, records = first_state(sp, wear0, anchor, balance.U0,
                                     options.march_options(path=True))
        resumed_from = -1
    state, found = _continue(sp, state, records, options, opts, run, saver)
    if found.by_jump:
        warnings.append("the state is a stick-set jump's (stick_set = True): a null-wear-rate "
                        "state, taken where the jumps agreed and the path headed for them; "
                        "the jump does not follow the rest of the path, and the march may "
                        "reach another state (Stromberg's beam: agreeing jumps 8.1 % of the "
                        "deepest wear away, docs/theory.md); stick_set = False follows the "
                        "path")
    saver.save(state, records, now=True)
    hist = WearHistory.from_records(records, found.kind)
    balanced = [r for r in records if r.has_balance]
    area = np.asarray(model.contact.area, float)
    return WornStateResult(
        found.success, found.kind, found.message, state.W.copy(), state.g.copy(),
        found.residual, found.correction,
        cycles_to_one_percent(records) if found.kind == "null_wear_rate" else math.nan,
        worn_volume(state.W, area), hist,
        _assemble(sp, balanced[0]) if balanced else None,
        _assemble(sp, balanced[-1]) if balanced else None, sp.eps,
        int(hist.newton_iterations.sum()) + found.jump_iterations,
        time.perf_counter() - t_start, resumed_from, warnings)


def check_history(max_steps: int, nc: int, d: int, H: int) -> None:
    """Refuse (one InputError with the estimate and the machine's memory) a march of
    ``max_steps`` steps whose history cannot fit, before it starts: every step's record is
    kept (the Fourier coefficients of the contact displacements and forces, ``nc d H`` each,
    and about ten per-node quantities)."""
    record = 8.0 * (2 * nc * d * H + (10 + d) * nc) + 600.0
    require_memory(max_steps * record, f"max_steps = {max_steps:,}: the history of a march "
                   f"of up to {max_steps:,} steps ({nc:,} contact nodes, {H} Fourier "
                   "coefficients)")


@dataclass(frozen=True)
class _Found:
    success: bool
    kind: str
    message: str
    residual: float
    correction: float
    jump_iterations: int = 0  # Newton iterations of the stick-set jumps tried
    by_jump: bool = False  # the state is a stick-set jump's


def rate_residual(records: list[StepRecord]) -> float:
    """The null-wear-rate residual ``max g / max g0`` of the last record (0 with no wear)."""
    g0 = float(np.max(records[0].wear_rate))
    return float(np.max(records[-1].wear_rate)) / g0 if g0 > 0 else 0.0


def _correction(records: list[StepRecord]) -> float:
    """The last step's ``max |W_{k+1} - W_k| / max W_{k+1}`` (inf before any step)."""
    if len(records) < 2:
        return math.inf
    W1, W0 = records[-1].wear_depth, records[-2].wear_depth
    top = float(np.max(W1))
    return float(np.max(np.abs(W1 - W0))) / top if top > 0 else 0.0


def _moved(records: list[StepRecord]) -> float:
    """The last step's ``max |W_{k+1} - W_k|`` over the larger of the deepest wear and the
    largest contact displacement coefficient ``max |U~|`` (0 before any step)."""
    if len(records) < 2:
        return 0.0
    W1, W0 = records[-1].wear_depth, records[-2].wear_depth
    scale = max(float(np.max(W1)), float(np.max(np.abs(records[-1].U))))
    return float(np.max(np.abs(W1 - W0))) / scale if scale > 0 else 0.0


def _rate_change(records: list[StepRecord]) -> float:
    """``max |g_{k+1} - g_k| / max g_{k+1}`` over the last step (inf before any step)."""
    if len(records) < 2:
        return math.inf
    g1, g0 = records[-1].wear_rate, records[-2].wear_rate
    top = float(np.max(g1))
    return float(np.max(np.abs(g1 - g0))) / top if top > 0 else math.inf


def _judge(records: list[StepRecord], options: WornStateOptions, can_wear: bool = True
           ) -> _Found | None:
    """The verdict on the last iterate, or None to go on (``can_wear`` False: every wear
    coefficient is 0, the reason a zero rate is then given)."""
    r, c = rate_residual(records), _correction(records)
    n = len(records) - 1
    if float(np.max(records[0].wear_rate)) <= 0:
        why = ("no contact node slips at the start" if can_wear else
               f"every wear coefficient is 0 (set {coefficient_keys(options.wear.law)})")
        return _Found(True, "no_wear", f"no wear: {why} (wear rate 0); the worn state is the "
                      "initial one", 0.0, 0.0)
    if r <= options.tolerance and c <= options.depth_tolerance:
        return _Found(True, "null_wear_rate",
                      f"worn state reached after {n} pseudo-time steps: null-wear-rate "
                      f"residual max g / max g0 = {r:.3g} <= {options.tolerance:g}, last "
                      f"correction {c:.3g} of the deepest wear <= {options.depth_tolerance:g}",
                      r, c)
    # steady: the rate profile did not change over a step that moved the profile (a tiny
    # step, e.g. after failed balances or from a small initial_jump, leaves any rate
    # unchanged), measured against the interface's motion as well as the wear (from the
    # unworn state every step moves the profile by much of its own deepest wear)
    if (n >= 3 and _rate_change(records) <= options.tolerance and r > 0.1
            and _moved(records) >= options.depth_tolerance):
        return _Found(True, "steady_wear",
                      f"no null-wear-rate state: the wear goes on at a steady rate (residual "
                      f"{r:.3g}, the rate profile changed by {_rate_change(records):.3g} over "
                      f"the last step, which moved the profile by {c:.3g} of the deepest "
                      "wear); the rate profile is the steady one", r, c)
    return None


def _continue(sp: SlowProblem, state: SlowStep, records: list[StepRecord],
              options: WornStateOptions, opts: WearOptions, run: RunControl, saver: _Saver
              ) -> tuple[SlowStep, _Found]:
    """Steps from ``state`` until :func:`_judge` decides or ``max_steps``: error-controlled
    (the march's steps) while the set of slipping nodes changes, with SER once it has
    settled (:func:`_settled`); with ``stick_set``, the stick-set jump (:class:`_Jumps`)."""
    path = options.march_options(path=True)
    jumps = _Jumps(sp, options, opts)
    while True:
        found = _judge(records, options, bool(np.any(sp.coef)))
        if found is not None:
            return state, replace(found, jump_iterations=jumps.iterations)
        if state.step >= options.max_steps:
            r, c = rate_residual(records), _correction(records)
            return state, _Found(False, "not_reached",
                                 f"worn state NOT reached after {state.step} pseudo-time steps "
                                 f"(SER from {records[1].jump if len(records) > 1 else 0:.3g} "
                                 f"to {state.jump:.3g} cycles): null-wear-rate residual max g "
                                 f"/ max g0 = {r:.3g} (tolerance {options.tolerance:g}), last "
                                 f"correction {c:.3g} of the deepest wear", r, c,
                                 jumps.iterations)
        if options.stick_set:
            hit = jumps.accept(state, records)
            if hit is not None:
                state = hit[0]
                saver.save(state, records)
                if run.callback is not None:
                    run.callback(state.step, records[-1])
                return hit
        try:
            settled = _settled(records, options.settle_rate)
            new, record, msg = _path_step(sp, state, opts if settled else path,
                                          options.exponential, 1 if settled else options.order,
                                          path_cycles(records, options.settle_rate)
                                          if options.order == 2 else None, options.events)
            if new is not None and not new.in_time_integration:
                new, record = _pull_back(sp, state, new, record, opts)
                msg = msg or "the balance after pulling back over-worn nodes failed"
            if new is None:
                r, c = rate_residual(records), _correction(records)
                return state, _Found(False, "not_reached",
                                     f"worn state NOT reached: a pseudo-time step failed "
                                     f"({msg}); null-wear-rate residual {r:.3g} after "
                                     f"{state.step} steps", r, c, jumps.iterations)
            if settled:  # SER; else the jump the error control proposed
                new.jump = record.jump * _growth(state, new, records[-1], record, options)
            records.append(record)
            state = new
            saver.save(state, records)
            if run.callback is not None:
                run.callback(state.step, record)
        except (KeyboardInterrupt, SystemError) as exc:
            if not interrupted(exc):
                raise
            saver.save(state, records, now=True)
            raise KeyboardInterrupt from None


def path_cycles(records: list[StepRecord], settle_rate: float) -> float:
    """The cycles of the steps that followed the path (taken before the path had settled,
    :func:`_settled`), without the pseudo-time of the relaxation (SER) steps; from the
    records alone, so a resumed run counts the same."""
    return sum(records[k].jump for k in range(1, len(records))
               if not _settled(records[:k], settle_rate))


def _path_step(sp: SlowProblem, state: SlowStep, opts: WearOptions, exponential: bool,
               order: int = 1, cycles: float | None = None, events: bool = False):
    """The next pseudo-time step: the exponential Euler step
    (:func:`~fretwear.wear.exponential_step.exponential_step`) with ``exponential``, else
    or where it failed or from a time integration the march's step
    (:func:`fretwear.wear.simulate._step`, with its time-domain rescue)."""
    if exponential and not state.in_time_integration:
        new, record, msg = exponential_step(sp, state, opts, order, cycles, events)
        if new is not None:
            return new, record, msg
    return _step(sp, state, opts)


class _Jumps:
    """The stick-set jumps (:func:`~fretwear.wear.stick_set.stick_set_state`) from the
    recorded states, each computed once (by record index).

    Once the worn-volume rate is at most ``options.jump_rate`` of the initial one, the jump from
    that record is the target ``J``. At each later record ``k`` the path step from ``k - 1``
    is measured against it: when it covered at least ``options.jump_progress`` of the way from
    ``W_k-1`` to ``J``, the jump from ``k`` is computed; it is accepted when it gives the
    same state as ``J``, to ``depth_tolerance`` of the deepest wear, else it becomes the new
    target (a step that covered less computes no jump: the jumps cost balances). A resumed
    run first replays the rule over the records it resumed with (the jumps the run before
    computed are computed again), so that it takes the same jump as a run never stopped.
    Agreement alone is not enough: on Stromberg's beam the jumps
    from 23 successive records agree on a state 8.1 % of the deepest wear from the march's,
    where two loaded nodes that stick through them slip and wear 1e6 cycles later, once their
    neighbours have unloaded; those records' steps covered 11-22 % of the way to the jump
    (the path was still far from where it ends, by more than the decay in sight says; on a
    reduced copy, jumps equal to 1e-12 land 103 % away, with steps covering 0.1 % of the
    way). The jump's state is a balance with a null-wear-rate residual at most
    ``tolerance`` (:func:`stick_set_state` checks it); a refused jump leaves the path to go
    on."""

    def __init__(self, sp: SlowProblem, options: WornStateOptions, opts: WearOptions):
        self.sp, self.options, self.opts = sp, options, opts
        self.found: dict[int, object] = {}
        self.latest = None  # (record, jump) of the last jump tried
        self.replayed = False  # the records a run resumed with seen (accept)
        self.iterations = 0  # Newton iterations of every jump tried

    def of(self, records: list[StepRecord], k: int):
        """The jump from record ``k`` (None: none found)."""
        if k not in self.found:
            r = records[k]
            jump, its = stick_set_state(
                self.sp, r.wear_depth, np.asarray(r.U, float).reshape(self.sp.m, self.sp.H),
                r.anchor, r.wear_rate, g0=float(np.max(records[0].wear_rate)),
                options=self.opts.solve, tolerance=self.options.tolerance)
            self.iterations += its
            self.found[k] = jump
        return self.found[k]

    def _consider(self, records: list[StepRecord], k: int):
        """Record ``k`` seen by the rule of the class: the target updated, and ``(j, jump, c,
        progress)`` when the jump from ``k`` agrees with the target's from ``j`` (else None).
        Reads ``records[:k + 1]`` only, so a resumed run replays the run before it."""
        if (k < 1 or not records[k].has_balance or not records[k - 1].has_balance
                or records[k].volume_rate > self.options.jump_rate * records[0].volume_rate):
            return None
        if self.latest is None or self.latest[1] is None:  # no target yet (none, or the
            self.latest = k, self.of(records, k)  # last jump found none): the path's
            return None  # progress is measured to the jump from here
        j, before = self.latest
        W0, W1 = records[k - 1].wear_depth, records[k].wear_depth
        _, progress = agreement(W0, W1, before.W, before.W)
        if progress < self.options.jump_progress:  # not heading there yet: no jump tried
            return None
        last = self.of(records, k)
        self.latest = k, last
        if last is None:
            return None
        c, _ = agreement(W0, W1, before.W, last.W)
        return None if c > self.options.depth_tolerance else (j, last, c, progress)

    def accept(self, state: SlowStep, records: list[StepRecord]
               ) -> tuple[SlowStep, _Found] | None:
        """The state of the jump from the last record when the class's conditions hold (its
        record appended to ``records``), else None."""
        k = len(records) - 1
        t0 = time.perf_counter()
        if not self.replayed:  # a resumed run: the targets the run before it set, from its
            self.replayed = True  # records (the jumps it computed are computed again)
            for i in range(1, k):
                self._consider(records, i)
        hit = self._consider(records, k)
        if hit is None:
            return None
        j, last, c, progress = hit
        sp, r = self.sp, records[k]
        st = SolveStats(True, 0.0, 0, 0, 0, time.perf_counter() - t0, "stick-set jump", "")
        sol = sp.solution(last.U, last.W, r.anchor, st)
        rec = StepRecord.balanced(sol, last.W, last.g, StepStats(
            r.cycles, 0.0, 0, 0, 0.0, time.perf_counter() - t0))
        records.append(rec)
        res = rate_residual(records)
        return SlowStep.balanced(rec, state.jump, state), _Found(
            True, "null_wear_rate",
            f"worn state reached after {k} pseudo-time steps and a stick-set jump (the "
            f"{int(np.count_nonzero(last.worn))} nodes that wear unloaded until they just "
            f"touch, every other node sticking): null-wear-rate residual max g / max g0 = "
            f"{res:.3g} <= {self.options.tolerance:g}; the jumps from steps {j} and {k} "
            f"agree within {c:.3g} of the deepest wear <= {self.options.depth_tolerance:g}, "
            f"the last step covered {progress:.2f} of the way to the first "
            f"(>= {self.options.jump_progress:g})",
            res, c, self.iterations, True)


def agreement(W0, W1, J0, J1) -> tuple[float, float]:
    """``(c, progress)`` of a path step from wear ``W0`` to ``W1`` with the jumps ``J0``,
    ``J1`` from its ends: ``c = max |J1 - J0| / max J1`` and ``progress = max |W1 - W0| /
    max |J0 - W0|`` (inf when the state before was already the jump's)."""
    top = float(np.max(J1))
    c = float(np.max(np.abs(J1 - J0))) / top if top > 0 else 0.0
    left = float(np.max(np.abs(J0 - W0)))
    step = float(np.max(np.abs(W1 - W0)))
    return c, step / left if left > 0 else math.inf


def _settled(records: list[StepRecord], settle_rate: float = 1.0) -> bool:
    """Whether the path has settled: the same slipping nodes over the last three records, a
    worn-volume rate that fell over both steps and is at most ``settle_rate`` of the initial
    one. Then only the decay to the state is left, and the steps may grow as fast as SER lets
    them."""
    if len(records) < 3 or records[-1].volume_rate > settle_rate * records[0].volume_rate:
        return False
    last = records[-3:]
    same = all(np.array_equal(state_slip(last[0]), state_slip(r)) for r in last[1:])
    return same and last[0].volume_rate > last[1].volume_rate > last[2].volume_rate


def _growth(old: SlowStep, new: SlowStep, old_record: StepRecord, record: StepRecord,
            options: WornStateOptions) -> float:
    """The factor from this step to the next: SER on the worn-volume rate (smoother than the
    largest node's rate, which rises where the load moves) times ``min_growth``, within
    ``[0.5, max_growth]``; at most 1 after a step that changed the set of slipping nodes."""
    ratio = old.volume_rate / new.volume_rate if new.volume_rate > 0 else options.max_growth
    grow = min(options.max_growth, max(ratio * options.min_growth, 0.5))
    if not np.array_equal(state_slip(old_record), state_slip(record)):
        grow = min(grow, 1.0)
    return grow


def _pull_back(sp: SlowProblem, before: SlowStep, new: SlowStep, record: StepRecord,
               opts: WearOptions) -> tuple[SlowStep | None, StepRecord | None]:
    """A node can only wear while it touches: one that the step wore into separation for
    the whole period (a Newton-like step overshoots the lift-off, where the rate is 0) is
    pulled back by its separation, no further than where the step started, and the balance
    solved again. ``(state, record)`` unchanged when no node overshot; ``(None, None)`` when
    the new balance fails."""
    sp.set_state(new.W, new.anchor)
    sep = separation(sp, new.U)
    worn = new.W > before.W
    if not np.any(sep[worn] > 0):
        return new, record
    t0 = time.perf_counter()
    W = np.where(worn, np.maximum(new.W - sep, before.W), new.W)
    U, st = sp.solve_balance(W, new.anchor, sp.shift_guess(new.U, W - new.W),
                             options=opts.solve)
    if not st.success:
        return None, None
    sp.set_state(W, new.anchor)
    g = sp.rate(U)
    sol = sp.solution(U, W, new.anchor, st)
    stats = StepStats(record.cycles, record.jump, record.newton_iterations + st.iterations,
                      record.rejected, record.error_estimate,
                      record.wall_time + time.perf_counter() - t0)
    rec = StepRecord.balanced(sol, W, g, stats)
    return SlowStep.balanced(rec, new.jump, before), rec


def state_slip(record: StepRecord) -> np.ndarray:
    """The nodes that slip during the period of a record."""
    return record.state_fraction[:, 2] > 0


def cycles_to_one_percent(records: list[StepRecord]) -> float:
    """An ESTIMATE of the physical cycles a march needs to get within 1 % of the deepest
    wear of the last record (module docstring): each pseudo-time step's worn volume ``dV``
    over the log-mean of the volume rates ``r0, r1`` at its ends (the time an exponential
    decay of the rate takes to wear ``dV``), summed up to the first step within 1 %, of which
    only the part that brings the distance to the state down to 1 % (same decay)."""
    Wf = records[-1].wear_depth
    top = float(np.max(Wf))
    if top <= 0:
        return 0.0
    n = 0.0
    for k in range(1, len(records)):
        r0, r1 = records[k - 1].volume_rate, records[k].volume_rate
        dV = records[k].worn_volume - records[k - 1].worn_volume
        d0 = float(np.max(np.abs(records[k - 1].wear_depth - Wf)))
        d1 = float(np.max(np.abs(records[k].wear_depth - Wf)))
        decays = dV > 0 and r0 > r1 >= 0
        if d1 <= 0.01 * top:
            if d0 > 0.01 * top and decays:
                n += math.log(d0 / (0.01 * top)) * dV / (r0 - r1)  # 1/mu = dV / (r0 - r1)
            elif d0 > 0.01 * top and r0 > 0:
                n += dV / r0
            return n
        if decays and r1 > 0:
            n += dV * math.log(r0 / r1) / (r0 - r1)
        elif r0 + r1 > 0:
            n += max(dV, 0.0) / (0.5 * (r0 + r1))
    return n
