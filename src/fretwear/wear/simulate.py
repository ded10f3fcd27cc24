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
from pathlib import Path

import numpy as np

from fretwear.errors import InputError, interrupted
from fretwear.hb.fallback import TimeDomainFallback
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.inputs import check_inputs
from fretwear.hb.preload import preload_anchor
from fretwear.hb.reduce import Reduced, condense
from fretwear.hb.solution import PeriodicSolution
from fretwear.hb.solvers import SolveStats
from fretwear.model.core import Model
from fretwear.wear.checkpoint import (
    check_checkpoint_path,
    fingerprint,
    load_checkpoint,
    save_checkpoint,
)
from fretwear.wear.history import WearHistory, WearResult
from fretwear.wear.laws import wear_coefficients, worn_volume
from fretwear.wear.options import WearOptions
from fretwear.wear.schemes import advance, first_state
from fretwear.wear.slow_problem import SlowProblem
from fretwear.wear.time_steps import time_domain_step


def simulate_wear(model: Model, basis: FourierBasis, *, frequency: float = 1.0,
                  quasi_static: bool = False, options: WearOptions | None = None,
                  reduced: Reduced | None = None, eps: str | float = "auto", anchor=None,
                  W0=None, U0=None, checkpoint: Path | str | None = None, resume: bool = False,
                  progress: bool = False, callback: Callable | None = None,
                  time_domain: TimeDomainFallback | None = None) -> WearResult:
    """Integrate fretting wear over the slow time scale (paper Fig. 3, eq. 29-30).

    Parameters
    ----------
    model : the structure (``contact.wear_coefficient`` k_w [1/Pa] for Archard's law).
    basis : Fourier basis of the periodic solutions.
    frequency : excitation frequency [Hz] (only scales time when ``quasi_static``).
    quasi_static : drop inertia and damping.
    options : :class:`WearOptions` (defaults: adaptive linearly implicit, tolerance 1e-2).
    reduced : precomputed condensation on ``[0] + basis.harmonics``.
    eps : DLFT penalty: ``"auto"`` (default) the spectral radius of ``Z_r`` (the paper),
        ``"static"`` that of the static ``K_r``, or a positive number [N/m]
        (:func:`fretwear.hb.penalty.penalty`).
    anchor : (nc, d-1) stick anchors of the first solve [m] (default: static preload state;
        0 when that static solve does not converge, and the result's ``warnings`` says so).
    W0 : (nc,) initial wear [m] (default 0).
    U0 : (nc, d, H) or (m, H) start of the first periodic solve.
    checkpoint : ``.npz`` file for the state (written atomically as the run goes).
    resume : continue from ``checkpoint`` when it exists (same model and options; a damaged
        checkpoint is an InputError, never silently replaced).
    progress : show a tqdm bar (cycles, worn volume, rate, time left).
    callback : ``callback(step, history_row)`` after each accepted step (and after the
        checkpoint is written); raising ``KeyboardInterrupt`` there stops the run as Ctrl-C.
    time_domain : the :class:`~fretwear.hb.fallback.TimeDomainFallback` of the steps whose
        balance fails (``options.time_domain_rescue``, dynamic cases); ``None``: no fallback
        (a failed balance stops the run). :func:`fretwear.simulate_wear` passes
        :data:`fretwear.timedomain.fallback.FALLBACK`.

    Returns
    -------
    :class:`WearResult`: ``success`` False when it stopped on a failed solve, ``message`` why
    and when it stopped (``stop_reason``), the ``history`` of every slow step.

    Raises
    ------
    ConvergenceError
        The first periodic solve (unworn interface) did not converge and no time-domain start
        is allowed (quasi-static, or ``time_domain_rescue = False``): nothing to integrate.
    KeyboardInterrupt
        On Ctrl-C (the last accepted state is in the checkpoint first).
    """
    frequency = check_inputs(model, basis, frequency, quasi_static=quasi_static,
                             anchor=anchor, U0=U0)
    if model.contact.prescribed_nodes().any():
        raise InputError("contact normal_load: wear needs the normal contact to come from the "
                         "structure (a prescribed normal load does not move with the worn gap)")
    if model.contact.has_connectors:  # the time-domain solver has rigid contacts only
        time_domain = None
    if options is not None and not isinstance(options, WearOptions):
        raise TypeError(f"options = {options!r}: expected a WearOptions")
    opts = (options or WearOptions()).check()
    ckpt = Path(checkpoint) if checkpoint is not None else None
    if ckpt is not None:
        check_checkpoint_path(ckpt)  # a folder there: refused before anything is computed
    t_start = time.perf_counter()
    nc, d = model.contact.dofs.shape
    if reduced is None:
        reduced = condense(model, frequency, basis.orders, quasi_static=quasi_static)
    coef = wear_coefficients(model, opts.law, opts.energy_coefficient,
                             opts.partner_energy_coefficient)
    W0 = np.zeros(nc) if W0 is None else np.broadcast_to(np.asarray(W0, float), (nc,)).copy()
    warnings = []
    if anchor is None:
        preload = preload_anchor(model)
        anchor = preload.values
        if not preload.success:
            warnings.append(preload.warning)
    anchor = np.array(anchor, float).reshape(nc, d - 1)
    sp = SlowProblem(model, reduced, basis, coef, eps=eps, anchor=anchor,
                     time_domain=time_domain if opts.time_domain_rescue and not quasi_static
                     else None, jacobian=opts.solve.jacobian)
    key = fingerprint(model, reduced, basis, sp.eps, coef, opts, W0, anchor)

    state, rows, resumed_from = None, [], -1
    if resume and ckpt is not None and ckpt.exists():  # damaged: an InputError, never ignored
        state, rows = load_checkpoint(ckpt, key, shape=(nc, d, sp.H))
        resumed_from = int(state["step"])
    if state is None:
        state, rows = first_state(sp, W0, anchor, U0, opts)
    balanced = [r for r in rows if int(r["rescued"]) != 2]
    initial = _assemble(sp, balanced[0]) if balanced else None

    bar = _Bar(progress, opts, model.contact.area)
    last_ckpt = -math.inf
    reason = _stop_reason(state, opts)
    extra = ""
    try:
        bar.show(state)
        while not reason:
            if np.size(state["td_U"]):  # the previous step came from a time integration
                new_state, row, failure = time_domain_step(sp, state, opts)
            else:
                new_state, row, failure = advance(sp, state, opts)
                if failure and sp.time_domain is not None:
                    new_state, row, why = time_domain_step(sp, state, opts)
                    failure = f"{failure}; {why}" if why else ""
            if failure:
                reason, extra = "solver_failed", f": {failure}"
                break
            state = new_state
            rows.append(row)
            bar.show(state)
            if ckpt is not None and (time.perf_counter() - last_ckpt >= opts.checkpoint_every_s):
                save_checkpoint(ckpt, state, rows, key)
                last_ckpt = time.perf_counter()
            if callback is not None:
                callback(int(state["step"]), row)
            reason = _stop_reason(state, opts)
    except (KeyboardInterrupt, SystemError) as exc:
        if not interrupted(exc):
            raise
        if ckpt is not None:
            save_checkpoint(ckpt, state, rows, key)
        bar.close()
        raise KeyboardInterrupt from None
    bar.close()
    state["stop_reason"] = np.asarray(reason)
    if ckpt is not None:
        save_checkpoint(ckpt, state, rows, key)
    hist = WearHistory.from_rows(rows, reason)
    last = [r for r in rows if int(r["rescued"]) != 2]
    final = _assemble(sp, last[-1]) if last else None
    return WearResult(hist, initial, final, reason, _message(reason, state, opts, extra),
                      reason != "solver_failed", time.perf_counter() - t_start,
                      float(state["stability_jump"]), resumed_from, penalty=sp.eps,
                      warnings=warnings)


def _assemble(sp: SlowProblem, row: dict) -> PeriodicSolution:
    """The periodic solution of a recorded step (no solve: ``U`` is converged)."""
    U = np.asarray(row["U"], float).reshape(sp.m, sp.H)
    stats = SolveStats(True, 0.0, int(row["newton_iterations"]), 0, 0, float(row["wall_time"]),
                       "recorded", "")
    return sp.solution(U, row["wear_depth"], row["anchor"], stats)


def _stop_reason(st: dict, opts: WearOptions) -> str:
    if float(st["vrate0"]) <= 0.0:
        return "no_wear"
    if float(st["cycles"]) >= opts.max_cycles * (1 - 1e-12):
        return "max_cycles"
    if float(np.max(st["W"])) >= opts.max_depth:
        return "max_depth"
    if float(st["vrate"]) <= opts.plateau_rate * float(st["vrate0"]):
        return "plateau"
    if int(st["step"]) >= opts.max_steps:
        return "max_steps"
    return ""


def _message(reason: str, st: dict, opts: WearOptions, extra: str = "") -> str:
    n = float(st["cycles"])
    txt = {
        "max_cycles": f"reached max_cycles = {opts.max_cycles:.4g}",
        "max_depth": f"a wear depth reached max_depth = {opts.max_depth:.4g} m",
        "plateau": (f"plateau: worn-volume rate {float(st['vrate']):.3g} m^3/cycle <= "
                    f"{opts.plateau_rate:g} x initial {float(st['vrate0']):.3g}"),
        "no_wear": "no wear: no contact node slips (worn-volume rate 0)",
        "max_steps": f"reached max_steps = {opts.max_steps}",
        "solver_failed": "stopped: a periodic solve failed even with smaller jumps",
    }[reason]
    return f"{txt} after {int(st['step'])} steps, N = {n:.4g} cycles{extra}"


def _progress_fraction(cycles, vrate, vrate0, wmax, opts: WearOptions) -> float:
    """How far the run is towards its nearest stop criterion, in [0, 1]."""
    fr = [math.log1p(cycles) / math.log1p(opts.max_cycles)]
    if vrate0 > 0 and opts.plateau_rate > 0 and vrate > 0:
        fr.append(math.log(vrate / vrate0) / math.log(opts.plateau_rate))
    if math.isfinite(opts.max_depth):
        fr.append(wmax / opts.max_depth)
    return min(1.0, max(0.0, max(fr)))


class _Bar:
    """tqdm progress towards the nearest stop criterion, with cycles, worn volume and rate."""

    def __init__(self, enabled: bool, opts: WearOptions, area):
        self.opts = opts
        self.area = np.asarray(area, float)
        self.bar = None
        if enabled:
            from tqdm import tqdm

            self.bar = tqdm(total=1000, desc="wear", unit="", leave=False,
                            bar_format="{desc}: {percentage:3.0f}%|{bar}| {postfix} "
                            "[{elapsed}<{remaining}]")

    def show(self, st: dict):
        if self.bar is None:
            return
        frac = _progress_fraction(float(st["cycles"]), float(st["vrate"]), float(st["vrate0"]),
                                  float(np.max(st["W"])), self.opts)
        self.bar.n = max(self.bar.n, int(1000 * frac))
        vol = worn_volume(st["W"], self.area)
        self.bar.set_postfix_str(f"N={float(st['cycles']):.3g} cycles, worn {vol:.3g} m^3, "
                                 f"rate {float(st['vrate']):.3g} m^3/cycle, "
                                 f"step {int(st['step'])}", refresh=False)
        self.bar.refresh()

    def close(self):
        if self.bar is not None:
            self.bar.close()
