"""Fretting wear on the slow time scale: the driver of "DLFT with wear" (paper section 3.3,
Fig. 3, eq. 29-30).

Two time scales (paper section 2): the vibration period (fast) is solved by the DLFT harmonic
balance (:mod:`fretwear.hb.periodic`); the wear depth ``W`` of every contact node evolves over the
cycle count ``N`` (slow) by

    dW/dN = g(W),       g_p = dW1_p = wear depth per cycle of node p on the periodic
                        solution balanced with the normal gap ``gap + W``          (eq. 29)

with the wear laws of :mod:`fretwear.wear.laws`. :func:`simulate_wear` takes slow steps
(:mod:`fretwear.wear.schemes`; from a time integration where the balance fails,
:mod:`fretwear.wear.time_steps`) until a stop criterion holds, records one history row per step
(:mod:`fretwear.wear.history`) and keeps a checkpoint (:mod:`fretwear.wear.checkpoint`). When a
step fails even with smaller jumps the run stops, says so, and keeps every converged step.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import numpy as np

from fretwear.errors import InputError, interrupted
from fretwear.hb.fallback import TimeDomainFallback
from fretwear.hb.fallbacks import said
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.inputs import QUASI_STATIC_FREQUENCY, check_inputs
from fretwear.hb.preload import preload_anchor
from fretwear.hb.reduce import Reduced, condense, condenser_for
from fretwear.hb.solution import PeriodicSolution
from fretwear.hb.solvers import SolveStats
from fretwear.model.core import Model
from fretwear.validate import ArgumentTypeError, flag, reals
from fretwear.validate import path as file_path
from fretwear.wear.checkpoint import (
    check_checkpoint_path,
    fingerprint,
    load_checkpoint,
    save_checkpoint,
)
from fretwear.wear.history import WearHistory, WearResult
from fretwear.wear.laws import coefficient_keys, wear_coefficients, worn_volume
from fretwear.wear.options import WearOptions
from fretwear.wear.schemes import advance, first_state
from fretwear.wear.slow_problem import SlowProblem
from fretwear.wear.state import SlowStep, StepRecord
from fretwear.wear.time_steps import time_domain_step


@dataclass(frozen=True)
class BalanceSetup:
    """How the periodic balances of a wear run are set up (every field optional).

    Attributes
    ----------
    reduced : precomputed condensation on ``[0] + basis.harmonics`` (:func:`fretwear.condense`;
        default: computed by the run).
    eps : DLFT penalty: ``"auto"`` (default) the spectral radius of ``Z_r`` (the paper),
        ``"static"`` that of the static ``K_r``, or a positive number [N/m]
        (:func:`fretwear.hb.penalty.penalty`).
    anchor : (nc, d-1) stick anchors of the first solve [m] (default: static preload state;
        0 when that static solve does not converge, and the result's ``warnings`` says so).
    U0 : (nc, d, H) or (m, H) start of the first periodic solve [m].
    condenser : the condenser of the model (:func:`fretwear.hb.reduce.exact_condenser` or
        :func:`fretwear.hb.modal.modal_condenser`), used for every condensation of the run
        (default: a new exact one, built once for the run).
    """

    reduced: Reduced | None = None
    eps: str | float = "auto"
    anchor: np.ndarray | None = None
    U0: np.ndarray | None = None
    condenser: object | None = None


@dataclass(frozen=True)
class RunControl:
    """How a wear run is kept, shown and watched (every field optional).

    Attributes
    ----------
    checkpoint : ``.npz`` file for the state (written atomically as the run goes, every
        ``WearOptions.checkpoint_every_s``, on Ctrl-C and at the end).
    resume : continue from ``checkpoint`` when it exists (same model and options; a damaged
        checkpoint is an InputError, never silently replaced).
    progress : show a tqdm bar (cycles, worn volume, rate, time left).
    callback : ``callback(step, record)`` after each accepted step (and after the checkpoint
        is written), ``record`` its :class:`~fretwear.wear.state.StepRecord`; raising
        ``KeyboardInterrupt`` there stops the run as Ctrl-C.
    """

    checkpoint: Path | str | None = None
    resume: bool = False
    progress: bool = False
    callback: Callable | None = None

    def __post_init__(self):
        if self.checkpoint is not None:
            file_path(self.checkpoint, "checkpoint")
        flag(self.resume, "resume")
        flag(self.progress, "progress")
        if self.callback is not None and not callable(self.callback):
            raise InputError(f"callback = {self.callback!r}; expected a function or None")



class SlowSetup(NamedTuple):
    """What a slow-scale run starts from (:func:`slow_setup`)."""

    condenser: object
    reduced: object
    coef: object
    wear0: np.ndarray
    anchor: np.ndarray
    warnings: list
    sp: SlowProblem


def slow_setup(model, basis, frequency, quasi_static: bool, balance, opts, wear0,
               time_domain) -> SlowSetup:
    """The pieces every run on the slow scale starts from, the march
    (:func:`simulate_wear`) and the worn state directly
    (:func:`fretwear.wear.worn_state.worn_state`): the initial wear checked (one depth or one
    per contact node [m], >= 0), one condenser for every condensation of the run, the reduced
    model, the wear coefficients of eq. (29), the stick anchors of the first balance and the
    slow problem (the time-domain rescue only for a dynamic run that asks for it)."""
    nc = model.contact.dofs.shape[0]
    if wear0 is not None:
        wear0 = reals(wear0, "wear0", low=0.0)
        if wear0.size != 1 and wear0.shape != (nc,):
            raise InputError(f"wear0 has shape {wear0.shape}; expected one depth or {nc} "
                             "(one per contact node) [m]")
    condenser = condenser_for(model, balance.condenser)
    reduced = balance.reduced
    if reduced is None:
        reduced = condense(model, frequency, basis.orders, quasi_static=quasi_static,
                           condenser=condenser)
    coef = wear_coefficients(model, opts.law, opts.energy_coefficient,
                             opts.partner_energy_coefficient)
    wear0 = np.zeros(nc) if wear0 is None else np.broadcast_to(np.asarray(wear0, float),
                                                                 (nc,)).copy()
    anchor, warnings = _first_anchor(model, balance.anchor, condenser)
    sp = SlowProblem(model, reduced, basis, coef, eps=balance.eps, anchor=anchor,
                     time_domain=time_domain if opts.time_domain_rescue and not quasi_static
                     else None, condenser=condenser, jacobian=opts.solve.jacobian)
    return SlowSetup(condenser, reduced, coef, wear0, anchor, warnings, sp)


def simulate_wear(model: Model, basis: FourierBasis, *, frequency: float | None = None,
                  quasi_static: bool = False, options: WearOptions | None = None,
                  wear0=None, balance: BalanceSetup | None = None, run: RunControl | None = None,
                  time_domain: TimeDomainFallback | None = None) -> WearResult:
    """Integrate fretting wear over the slow time scale (paper Fig. 3, eq. 29-30).

    Parameters
    ----------
    model : the structure (``contact.wear_coefficient`` k_w [1/Pa] for Archard's law).
    basis : Fourier basis of the periodic solutions.
    frequency : excitation frequency [Hz]; required unless ``quasi_static`` (then it only
        scales time, default :data:`QUASI_STATIC_FREQUENCY`).
    quasi_static : drop inertia and damping.
    options : :class:`WearOptions` (defaults: adaptive linearly implicit, tolerance 1e-2).
    wear0 : (nc,) initial wear depths [m] (default 0).
    balance : :class:`BalanceSetup`: the condensation, the DLFT penalty, the stick anchors and
        the start of the first periodic solve (default: all computed).
    run : :class:`RunControl`: checkpoint and resume, progress bar, callback (default: none).
    time_domain : the :class:`~fretwear.hb.fallback.TimeDomainFallback` of the steps whose
        balance fails (``options.time_domain_rescue``, dynamic cases); ``None``: no fallback
        (a failed balance stops the run). :func:`fretwear.simulate_wear` passes
        :data:`fretwear.timedomain.fallback.FALLBACK`.
    condenser : the condenser of ``model`` (:func:`fretwear.hb.reduce.exact_condenser` or
        :func:`fretwear.hb.modal.modal_condenser`) used by every condensation and recovery of
        the run; None: a new exact one, built once for the run.

    Returns
    -------
    :class:`WearResult`: ``success`` False when it stopped on a failed solve, ``message`` why
    and when it stopped (``stop_reason``), the ``history`` of every slow step.

    Raises
    ------
    InputError
        Bad input, e.g. a dynamic run without ``frequency``.
    ConvergenceError
        The first periodic solve (unworn interface) did not converge and no time-domain start
        is allowed (quasi-static, or ``time_domain_rescue = False``): nothing to integrate.
    KeyboardInterrupt
        On Ctrl-C (the last accepted state is in the checkpoint first).
    """
    balance, run, opts = _settings(balance, run, options)
    frequency = check_inputs(model, basis, _frequency(frequency, quasi_static),
                             quasi_static=quasi_static, anchor=balance.anchor, U0=balance.U0)
    if model.contact.prescribed_nodes().any():
        raise InputError("contact normal_load: wear needs the normal contact to come from the "
                         "structure (a prescribed normal load does not move with the worn gap)")
    if model.contact.has_connectors:  # the time-domain solver has rigid contacts only
        time_domain = None
    if not getattr(balance.condenser, "models_in_time", True):  # a sector (hb/cyclic.py)
        time_domain = None
    if run.checkpoint is not None:
        check_checkpoint_path(run.checkpoint)  # a folder: refused before anything is computed
    if opts.partner_energy_coefficient is not None and not np.any(model.contact.paired()):
        raise InputError(f"partner_energy_coefficient = {opts.partner_energy_coefficient!r}, "
                         "but the model has no node-to-node pair (a rigid obstacle does not "
                         "wear): leave it out, or give the contact a partner")
    t_start = time.perf_counter()
    nc, d = model.contact.dofs.shape
    condenser, reduced, coef, wear0, anchor, warnings, sp = slow_setup(
        model, basis, frequency, quasi_static, balance, opts, wear0, time_domain)
    saver = _Saver(run.checkpoint, fingerprint(model, reduced, basis, sp.eps, coef, opts, wear0,
                                               anchor), opts.checkpoint_every_s)
    if run.resume and saver.exists():  # damaged: an InputError, never ignored
        state, records = saver.load(shape=(nc, d, sp.H))
        resumed_from = state.step
    else:
        state, records = first_state(sp, wear0, anchor, balance.U0, opts)
        resumed_from = -1
    balanced = [r for r in records if r.has_balance]
    initial = _assemble(sp, balanced[0]) if balanced else None
    state, reason, extra = _integrate(sp, state, records, opts, run, saver)
    state.stop_reason = reason
    saver.save(state, records, now=True)
    balanced = [r for r in records if r.has_balance]
    final = _assemble(sp, balanced[-1]) if balanced else None
    return WearResult(WearHistory.from_records(records, reason), initial, final, reason,
                      _message(reason, state, opts, extra, can_wear=bool(np.any(coef))),
                      reason != "solver_failed",
                      time.perf_counter() - t_start, state.stability_jump, resumed_from,
                      penalty=sp.eps, warnings=warnings)


def _settings(balance, run, options) -> tuple[BalanceSetup, RunControl, WearOptions]:
    """The settings records of a run, checked, defaults for those not given."""
    for name, value, kind in (("balance", balance, BalanceSetup), ("run", run, RunControl),
                              ("options", options, WearOptions)):
        if value is not None and not isinstance(value, kind):
            raise ArgumentTypeError(f"{name} = {value!r}: expected a {kind.__name__}")
    return balance or BalanceSetup(), run or RunControl(), (options or WearOptions()).check()


def _frequency(frequency, quasi_static: bool):
    """The excitation frequency [Hz]: required for a dynamic run; a quasi-static run without
    one gets :data:`QUASI_STATIC_FREQUENCY` (it only scales time)."""
    if frequency is not None:
        return frequency
    if not quasi_static:
        raise InputError("frequency = None: a dynamic wear run needs the excitation frequency "
                         "[Hz] (frequency=...), or quasi_static=True")
    return QUASI_STATIC_FREQUENCY


def _first_anchor(model: Model, anchor, condenser) -> tuple[np.ndarray, list]:
    """The stick anchors (nc, d-1) [m] of the first solve: ``anchor``, or those of the static
    preload state; and the warnings (the static solve did not converge)."""
    warnings = []
    if anchor is None:
        preload = preload_anchor(model, condenser=condenser)
        anchor = preload.values
        if not preload.success:
            warnings.append(preload.warning)
    nc, d = model.contact.dofs.shape
    return np.array(anchor, float).reshape(nc, d - 1), warnings


class _Saver:
    """The checkpoint of a run (``path`` None: none): written at most every ``every_s``
    seconds as steps are accepted, and at once on an interrupt and at the end; ``key`` the
    run's fingerprint (:func:`~fretwear.wear.checkpoint.fingerprint`)."""

    def __init__(self, path: Path | str | None, key: str, every_s: float):
        self.path = Path(path) if path is not None else None
        self.key, self.every_s = key, every_s
        self.last = -math.inf

    def exists(self) -> bool:
        return self.path is not None and self.path.exists()

    def load(self, shape) -> tuple[SlowStep, list[StepRecord]]:
        return load_checkpoint(self.path, self.key, shape=shape)

    def save(self, state: SlowStep, records: list[StepRecord], now: bool = False) -> None:
        if self.path is None or not (now or time.perf_counter() - self.last >= self.every_s):
            return
        save_checkpoint(self.path, state, records, self.key)
        self.last = time.perf_counter()


def _integrate(sp: SlowProblem, state: SlowStep, records: list[StepRecord], opts: WearOptions,
               run: RunControl, saver: _Saver) -> tuple[SlowStep, str, str]:
    """Slow steps from ``state`` until a stop criterion holds or a step fails, each step's
    record appended to ``records``: ``(last state, stop reason, what failed)``. On Ctrl-C
    the last accepted state is saved, then ``KeyboardInterrupt`` raised."""
    bar = _Bar(run.progress, opts, sp.model.contact.area)
    reason, extra = _stop_reason(state, opts), ""
    try:
        bar.show(state)
        while not reason:
            new_state, record, failure = _step(sp, state, opts)
            bad = "" if failure else record.non_finite()
            if bad:
                failure = (f"step {state.step + 1} produced non-finite values (NaN or inf) in "
                           f"{bad}; the last finite state is kept")
            if failure:
                reason, extra = "solver_failed", f": {failure}"
                break
            state = new_state
            records.append(record)
            bar.show(state)
            saver.save(state, records)
            if run.callback is not None:
                run.callback(state.step, record)
            reason = _stop_reason(state, opts)
    except (KeyboardInterrupt, SystemError) as exc:
        if not interrupted(exc):
            raise
        saver.save(state, records, now=True)
        bar.close()
        raise KeyboardInterrupt from None
    bar.close()
    return state, reason, extra


def _step(sp: SlowProblem, state: SlowStep, opts: WearOptions):
    """The next slow step: ``(state, record, failure)``. From a time integration while the
    previous step came from one; else on periodic balances (:func:`advance`), and from a time
    integration where those fail and the problem has one."""
    if state.in_time_integration:
        return time_domain_step(sp, state, opts)
    new_state, record, failure = advance(sp, state, opts)
    if failure and sp.time_domain is not None:
        said(f"wear step {state.step + 1} (N = {state.cycles:.4g} cycles): {failure}; taking "
             "the step from a time integration (each can take minutes; the next steps too, "
             "until a balance converges again)")
        new_state, record, why = time_domain_step(sp, state, opts)
        failure = f"{failure}; {why}" if why else ""
    return new_state, record, failure


def _assemble(sp: SlowProblem, record: StepRecord) -> PeriodicSolution:
    """The periodic solution of a recorded step (no solve: ``U`` is converged)."""
    U = np.asarray(record.U, float).reshape(sp.m, sp.H)
    stats = SolveStats(True, 0.0, int(record.newton_iterations), 0, 0, float(record.wall_time),
                       "recorded", "")
    return sp.solution(U, record.wear_depth, record.anchor, stats)


def _stop_reason(st: SlowStep, opts: WearOptions) -> str:
    if st.volume_rate0 <= 0.0:
        return "no_wear"
    if st.cycles >= opts.max_cycles * (1 - 1e-12):
        return "max_cycles"
    if float(np.max(st.W)) >= opts.max_depth:
        return "max_depth"
    if st.volume_rate <= opts.plateau_rate * st.volume_rate0:
        return "plateau"
    if st.step >= opts.max_steps:
        return "max_steps"
    return ""


def _message(reason: str, st: SlowStep, opts: WearOptions, extra: str = "",
             can_wear: bool = True) -> str:
    """The run's stop message; ``can_wear`` False: every wear coefficient is 0, which is then
    the reason given for "no_wear" (not the slip)."""
    txt = {
        "max_cycles": f"reached max_cycles = {opts.max_cycles:.4g}",
        "max_depth": f"a wear depth reached max_depth = {opts.max_depth:.4g} m",
        "plateau": (f"plateau: worn-volume rate {st.volume_rate:.3g} m^3/cycle <= "
                    f"{opts.plateau_rate:g} x initial {st.volume_rate0:.3g}"),
        "no_wear": ("no wear: no contact node slips (worn-volume rate 0)" if can_wear else
                    "no wear: every wear coefficient is 0 (worn-volume rate 0; set "
                    f"{coefficient_keys(opts.law)})"),
        "max_steps": f"reached max_steps = {opts.max_steps}",
        "solver_failed": "stopped: a periodic solve failed even with smaller jumps",
    }[reason]
    return f"{txt} after {st.step} steps, N = {st.cycles:.4g} cycles{extra}"


#: the largest growth of the jump per step assumed when counting the steps left
JUMP_GROWTH_MAX = 4.0


def steps_left(cycles: float, jump: float, growth: float, max_cycles: float) -> float:
    """The slow steps left to reach ``max_cycles`` from ``cycles`` with the next ``jump``
    [cycles] growing by ``growth`` per step (clipped to [1, :data:`JUMP_GROWTH_MAX`]): the
    ``k`` with ``jump (1 + q + ... + q^(k-1)) = max_cycles - cycles``."""
    left = max(0.0, max_cycles - cycles)
    if left <= 0.0:
        return 0.0
    if not (jump > 0 and math.isfinite(jump)):
        return math.inf
    q = min(max(growth, 1.0), JUMP_GROWTH_MAX) if math.isfinite(growth) else 1.0
    if q < 1.0 + 1e-6:
        return left / jump
    return math.log1p(left * (q - 1.0) / jump) / math.log(q)


def _progress_fraction(st: SlowStep, growth: float, opts: WearOptions) -> float:
    """How far the run is towards its nearest stop criterion, in [0, 1], measured in what the
    run does (so that the bar's time left means something): the slow steps taken against
    those left to ``max_cycles`` at the current jump and its growth (:func:`steps_left`),
    the worn depth against ``max_depth``, the steps against ``max_steps``, and the worn-volume
    rate's fall towards the plateau (in log)."""
    k = steps_left(st.cycles, st.jump, growth, opts.max_cycles)
    fr = [st.step / (st.step + k) if st.step + k > 0 else 1.0, st.step / opts.max_steps]
    vrate, vrate0 = st.volume_rate, st.volume_rate0
    if vrate0 > 0 and opts.plateau_rate > 0 and vrate > 0:
        fr.append(math.log(vrate / vrate0) / math.log(opts.plateau_rate))
    if math.isfinite(opts.max_depth):
        fr.append(float(np.max(st.W)) / opts.max_depth)
    return min(1.0, max(0.0, max(fr)))


class _Bar:
    """tqdm progress towards the nearest stop criterion, with cycles, worn volume and rate."""

    def __init__(self, enabled: bool, opts: WearOptions, area):
        self.opts = opts
        self.area = np.asarray(area, float)
        self.bar = None
        self.last_jump = math.nan  # the jump proposed at the previous step, for its growth
        if enabled:
            from tqdm import tqdm

            self.bar = tqdm(total=1000, desc="wear", unit="", leave=False,
                            bar_format="{desc}: {percentage:3.0f}%|{bar}| {postfix} "
                            "[{elapsed}<{remaining}]")

    def show(self, st: SlowStep):
        if self.bar is None:
            return
        frac = _progress_fraction(st, st.jump / self.last_jump, self.opts)
        self.last_jump = st.jump
        self.bar.n = max(self.bar.n, int(1000 * frac))
        vol = worn_volume(st.W, self.area)
        self.bar.set_postfix_str(f"N={st.cycles:.3g} cycles, worn {vol:.3g} m^3, "
                                 f"rate {st.volume_rate:.3g} m^3/cycle, "
                                 f"step {st.step}", refresh=False)
        self.bar.refresh()

    def close(self):
        if self.bar is not None:
            self.bar.close()
