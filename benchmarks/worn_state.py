"""The worn state directly (fretwear.worn_state) against the march to the plateau
(fretwear.simulate_wear), in one run, on the quasi-static beam of Salles et al. 2011
(salles2011-quasistatic), the Stromberg beam (stromberg1997) and the shipped dovetail
(dovetail-wear).

For each case: the march with the case file's wear options, run to its final plateau (a
worn-volume rate of 1e-8 of the initial one, PLATEAU: the default 1e-3 stops short of the
final state on Stromberg's beam, and where the march passed it is printed too; the
dovetail's ``max_cycles`` and ``max_depth`` are lifted so that it can get there; ``--steps``
caps its slow steps), then the direct solve with the same wear law and solves; both on the
same condensation (built once, not timed). Printed: processor and wall seconds of each, the
number of DLFT solves (Newton iterations of the balances and slow Jacobians, as the march
counts them), the largest profile difference over the largest depth, whether the stuck
nodes agree, the null-wear-rate residual and the direct solve's estimate of the cycles a
march needs to get within 1 %. A warm-up solve first compiles the numba kernels (not timed).

Then, for each case, the stick-set jump (fretwear.wear.stick_set: the nodes that wear
unloaded until they just touch, every other node sticking; a few DLFT balances) from the
unworn state and from the state where the march passed its default plateau, and the direct
solve with ``stick_set = True`` (the path ended by a jump once the jumps from two of its
states agree and the path heads for them): how far each is from the march's final state (the
worn state depends on the path, which the jump does not follow). Its summary is printed
before the last two lines: ``worn_state_speedup_stick_set=`` and
``worn_state_diff_stick_set=`` (same definitions).

The dovetail (dynamic, 1024-odd DOFs condensed on its interface) is attempted with a step
budget, ``--dovetail-steps`` (each of its steps costs seconds); a case where the march or the
direct solve reaches no state within its budget is reported so and left out of the two last
lines.

Then ``--steps-79khz`` steps of the direct solve on the 79 kHz beam (salles2011-79khz),
with the time-domain rescue of the march: it must report the state not reached, with its
residual (the path is chaotic, docs/wear.md "Limits").

The last lines are ``worn_state_speedup=<geometric mean of march / direct processor time>``
and ``worn_state_diff=<largest profile difference / largest depth>``.

Run: ``python benchmarks/worn_state.py [--cases salles2011-quasistatic,stromberg1997]
[--steps 200] [--dovetail-steps 60] [--order 2] [--events] [--no-jumps]``
(``--events``: the direct solve with ``events = True``; ``--no-jumps``: without the
stick-set jumps). Quote the figures with the machine load
(``uptime``: printed before and after).
"""

from __future__ import annotations

import argparse
import math
import os
import time
from dataclasses import replace

import numpy as np

from fretwear import api
from fretwear.analyses.common import condenser_of
from fretwear.analyses.run import load_case
from fretwear.analyses.wear import options_from_table, penalty_of
from fretwear.examples import example_path
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.reduce import condense
from fretwear.io.case import build_model
from fretwear.wear import BalanceSetup, simulate_wear
from fretwear.wear.simulate import slow_setup
from fretwear.wear.stick_set import stick_set_state
from fretwear.wear.worn_state import WornStateOptions, worn_state

CASES = ("salles2011-quasistatic", "stromberg1997", "stromberg1997-triangle", "dovetail-wear")
#: the march runs to this worn-volume rate (relative to the initial one): its default plateau
#: (1e-3) is not the final state on Stromberg's beam (docs/examples.md); where it passed the
#: default plateau is reported too
PLATEAU = 1e-8


def _timed(fn):
    """``(fn(), processor seconds, wall seconds)``."""
    t0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.process_time() - c0, time.perf_counter() - t0


def _setup(name: str, steps: int):
    """Model, basis, frequency, the wear options (stop criteria of a march to the plateau)
    and the balance setup (a condensation shared by both runs) of the example ``name``."""
    case = load_case(example_path(name))
    model = build_model(case)
    a = case.analysis
    basis = FourierBasis.up_to(a["harmonics"], a["n_samples"])
    quasi = bool(a["quasi_static"])
    f_hz = float(a.get("frequency", 1.0))
    opts = replace(options_from_table(a), max_cycles=1e13, max_depth=math.inf,
                   max_steps=steps, checkpoint_every_s=1e9, plateau_rate=PLATEAU)
    cond = condenser_of(model, a, None if quasi else f_hz, max(basis.harmonics))
    reduced = condense(model, f_hz, basis.orders, quasi_static=quasi, condenser=cond)
    balance = BalanceSetup(reduced=reduced, condenser=cond, **penalty_of(a))
    return model, basis, f_hz, quasi, opts, balance


def _stuck(rate, pressure, rate0):
    """Nodes that carry load and do not wear at a state: pressure > 1e-3 of the largest,
    rate <= 1e-9 of the largest initial one ``rate0``."""
    return (pressure > 1e-3 * pressure.max()) & (rate <= 1e-9 * rate0)


def jumps(model, basis, f_hz, quasi, opts, balance, h, k: int) -> None:
    """The stick-set jump from the unworn state and from the march's step ``k`` (where it
    passed its default plateau): its distance to the march's final state, printed."""
    *_, sp = slow_setup(model, basis, f_hz, quasi, balance, opts, None, None)
    Wm = h.wear_depth[-1]
    top, g0 = float(np.max(Wm)), float(np.max(h.wear_rate[0]))
    for j in (0, k):
        U = np.asarray(h.U[j], float).reshape(sp.m, sp.H)
        (jump, its), c, w = _timed(lambda U=U, j=j: stick_set_state(
            sp, h.wear_depth[j], U, h.anchor[j], h.wear_rate[j], g0=g0, options=opts.solve))
        where = "unworn state" if j == 0 else f"march step {j}"
        if jump is None:
            print(f"  stick-set jump from the {where}: none ({its} DLFT solves)")
            continue
        print(f"  stick-set jump from the {where}: {jump.rounds} rounds, {its} DLFT solves, "
              f"processor {c:.2f} s; {int(jump.worn.sum())} nodes unloaded; "
              f"{float(np.max(np.abs(jump.W - Wm))) / top:.3g} of the largest depth from the "
              "march's final state")


def run_case(name: str, steps: int, order: int = 1, events: bool = False,
             with_jumps: bool = True) -> tuple[float, float, float, float] | None:
    """March and direct solve (its path steps of ``order``, :class:`WornStateOptions`) of
    one example: ``(speedup, profile difference)`` of the default direct solve and of the
    one with ``stick_set = True`` (NaN without ``with_jumps``), None when either reached no
    state within ``steps``."""
    model, basis, f_hz, quasi, opts, balance = _setup(name, steps)
    kw = {"frequency": f_hz, "quasi_static": quasi, "balance": balance}
    march, c_m, w_m = _timed(lambda: simulate_wear(model, basis, options=opts, **kw))
    direct, c_d, w_d = _timed(lambda: worn_state(
        model, basis, options=WornStateOptions(wear=opts, max_steps=steps, order=order,
                                               events=events), **kw))
    h = march.history
    Wm, Wd = h.wear_depth[-1], direct.wear
    top = float(np.max(Wm))
    diff = float(np.max(np.abs(Wd - Wm))) / top if top > 0 else 0.0
    pm = h.pressure_mean[-1]
    pd = direct.history.pressure_mean[-1]
    g0 = float(h.wear_rate[0].max())
    same_stuck = bool(np.array_equal(_stuck(h.wear_rate[-1], pm, g0),
                                     _stuck(direct.rate, pd, g0)))
    pdiff = float(np.max(np.abs(pd - pm))) / float(np.max(pm))
    n_march = int(h.newton_iterations.sum())
    print(f"{name}: {model.contact.n_nodes} contact nodes; march to a worn-volume rate "
          f"{PLATEAU:g} x initial (or {steps} steps)")
    print(f"  march : {march.message}")
    print(f"          processor {c_m:.2f} s, wall {w_m:.2f} s, {h.n_steps - 1} slow steps, "
          f"{n_march} DLFT solves, max depth {top:.4g} m")
    print(f"  direct: {direct.message}")
    print(f"          processor {c_d:.2f} s, wall {w_d:.2f} s, "
          f"{direct.history.n_steps - 1} pseudo-time steps, {direct.dlft_solves} DLFT solves, "
          f"max depth {float(np.max(Wd)):.4g} m; estimated cycles to 1 %: "
          f"{direct.cycles_to_1pc:.3g} (march reached its plateau at {h.cycles[-1]:.3g})")
    k = int(np.argmax(h.volume_rate <= 1e-3 * h.volume_rate[0])) if np.any(
        h.volume_rate <= 1e-3 * h.volume_rate[0]) else h.n_steps - 1
    d3 = float(np.max(np.abs(Wd - h.wear_depth[k]))) / top if top > 0 else 0.0
    passed = bool(np.any(h.volume_rate <= 1e-3 * h.volume_rate[0]))
    print(f"  the march {'passed' if passed else 'did NOT pass'} its default plateau (1e-3)"
          f" {'at' if passed else 'by'} step {k}, N = {h.cycles[k]:.3g} "
          f"({int(h.newton_iterations[:k + 1].sum())} DLFT solves): {d3:.3g} of the largest "
          "depth from the direct state")
    print(f"  profile difference {diff:.3g} of the largest depth, same stuck nodes "
          f"{same_stuck}, mean pressure difference {pdiff:.3g} of the largest; "
          f"speedup (processor) {c_m / c_d:.3g}, (wall) {w_m / w_d:.3g}")
    fast_out = (math.nan, math.nan)
    if with_jumps:
        jumps(model, basis, f_hz, quasi, opts, balance, h, k)
        fast, c_j, w_j = _timed(lambda: worn_state(
            model, basis, options=WornStateOptions(wear=opts, max_steps=steps, stick_set=True),
            **kw))
        print(f"  direct, stick_set = True: {fast.message}")
        print(f"          processor {c_j:.2f} s, wall {w_j:.2f} s, {fast.dlft_solves} DLFT "
              f"solves; {float(np.max(np.abs(fast.wear - Wm))) / top:.3g} of the largest depth "
              f"from the march's final state; speedup (processor) {c_m / c_j:.3g}")
        if fast.success:
            fast_out = (c_m / c_j, float(np.max(np.abs(fast.wear - Wm))) / top)
    if march.stop_reason != "plateau" or not direct.success:
        print(f"  {name}: no state reached within {steps} steps (march: {march.stop_reason}, "
              f"direct: {direct.kind}); left out of the summary")
        return None
    return c_m / c_d, diff, *fast_out


def not_reached(steps: int, order: int = 1, events: bool = False) -> None:
    """The 79 kHz beam (salles2011-79khz), whose wear path is chaotic: the direct solve
    must say that it did not reach a state, with the residual."""
    model, basis, f_hz, quasi, opts, balance = _setup("salles2011-79khz", steps)
    res, c, w = _timed(lambda: api.worn_state(
        model, basis, frequency=f_hz,
        options=WornStateOptions(wear=opts, max_steps=steps, order=order, events=events),
        balance=balance))
    print(f"salles2011-79khz: {res.message}")
    print(f"  kind {res.kind}, success {res.success}, residual {res.residual:.3g}; processor "
          f"{c:.1f} s, wall {w:.1f} s")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default=",".join(CASES), help="examples, comma-separated")
    ap.add_argument("--steps", type=int, default=300, help="slow steps of the march at most")
    ap.add_argument("--dovetail-steps", type=int, default=60,
                    help="slow steps of the dovetail's march and direct solve at most")
    ap.add_argument("--steps-79khz", type=int, default=20,
                    help="steps of the direct solve on the 79 kHz beam (0: skip it)")
    ap.add_argument("--order", type=int, default=1, choices=(1, 2),
                    help="the direct solve's path steps: 1 (default) or 2 (second order)")
    ap.add_argument("--events", action="store_true",
                    help="the direct solve locates the contact-state events along its path")
    ap.add_argument("--no-jumps", action="store_true",
                    help="skip the stick-set jumps and the stick_set = True solve")
    args = ap.parse_args()
    print("load before:", os.getloadavg())
    # warm-up: compiles the numba kernels (not timed)
    model, basis, f_hz, quasi, opts, balance = _setup("stromberg1997", 2)
    worn_state(model, basis, quasi_static=True, balance=balance,
               options=WornStateOptions(wear=opts, max_steps=1))
    speed, diffs, fast_speed, fast_diffs = [], [], [], []
    for name in args.cases.split(","):
        name = name.strip()
        out = run_case(name, args.dovetail_steps if name == "dovetail-wear" else args.steps,
                       args.order, args.events, not args.no_jumps)
        if out is not None:
            speed.append(out[0])
            diffs.append(out[1])
            if not math.isnan(out[2]):
                fast_speed.append(out[2])
                fast_diffs.append(out[3])
    if args.steps_79khz > 0:
        not_reached(args.steps_79khz, args.order, args.events)
    print("load after:", os.getloadavg())
    if not speed:
        print("no case reached a state: no summary")
        return
    if fast_speed:
        print("worn_state_speedup_stick_set="
              f"{math.exp(np.mean(np.log(fast_speed))):.3g}")
        print(f"worn_state_diff_stick_set={max(fast_diffs):.3g}")
    print(f"worn_state_speedup={math.exp(np.mean(np.log(speed))):.3g}")
    print(f"worn_state_diff={max(diffs):.3g}")


if __name__ == "__main__":
    main()
