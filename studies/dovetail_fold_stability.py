"""The shipped dovetail's fold near 2.40 kHz: a stable and an unstable periodic state of its
folded FRF, classified by Hill's method (fretwear.hb.stability) and by the exact time
integration started from the perturbed state (fretwear.timedomain.check_periodic).

The FRF of the example (one harmonic, 16 samples, eps "static") on a modal condensation (Hill's
method needs the structure in modal coordinates: 6618 DOFs), swept by arclength from 2380 to
2430 Hz; the sign of det J at every point (an LU of the balance's Jacobian) marks the middle
branch (det J < 0: a real multiplier above 1). One point on a stable branch and one on the
middle branch get Hill's multipliers (dense) and a time integration from the state with its
velocity perturbed by 1e-3 of its largest value. About 5 s of CPU per period of the time
integration (128 steps): a study, run once (results in docs/studies/dovetail-fold-stability.md).

Run: ``python studies/dovetail_fold_stability.py [max_periods] [--no-residual] [--refine=N]``
(0 periods: no time integration; ``--no-residual``: the modal condensation without its
residual vectors, checked as the default one is, so that Hill's quadratic problem is small
enough to be dense; ``--refine=N``: Hill's exponents refined on the exact ``T(s)``, default 2).
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

from fretwear.analyses.run import load_case
from fretwear.errors import InputError
from fretwear.examples import example_path
from fretwear.hb.condensers import condenser
from fretwear.hb.dynamics import structure_dynamics
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SweepOptions
from fretwear.hb.stability import HillOptions, HillProblem, hill_stability, problem_of
from fretwear.hb.sweep import sweep
from fretwear.io.case import build_model
from fretwear.timedomain.stability import check_periodic


def stamp(text):
    print(f"[{time.strftime('%H:%M:%S')} load {os.getloadavg()[0]:.1f} "
          f"cpu {time.process_time():.0f} s] {text}", flush=True)


def main():
    max_periods = int(sys.argv[1]) if len(sys.argv) > 1 and sys.argv[1].isdigit() else 150
    residual = "--no-residual" not in sys.argv  # fewer coordinates for Hill's dense problem
    refine = next((int(a.split("=")[1]) for a in sys.argv if a.startswith("--refine=")), 2)
    model = build_model(load_case(example_path("dovetail-frf")))
    if residual:
        cond = condenser(model, "auto", f_max=2800.0, max_order=1)
    else:
        cond = condenser(model, "modal", f_max=2800.0, max_order=1, residual=False)
    stamp(f"condenser: {cond.choice}")
    basis = FourierBasis.up_to(1, 16)
    res = sweep(model, basis, 2380.0, 2430.0, 11,
                options=SweepOptions(spacing="linear", eps="static"), condenser=cond)
    stamp(f"sweep: {len(res.points)} points, {int(res.point_success.sum())} converged")
    dyn = structure_dynamics(model, cond)
    rows = []
    for p in res.points:
        if not p.success:
            continue
        prob = problem_of(model, p.solution, condenser=cond)
        U = p.solution.U.reshape(prob.m, prob.H)
        sign = int(np.sign(np.linalg.slogdet(np.real(HillProblem(prob, U, dyn).matrix(0.0)))[0]))
        amp = float(np.max(np.abs(p.solution.observed["tip"][0, 1:])))
        rows.append((p, prob, U, sign, amp))
        print(f"  {p.frequency_hz:9.3f} Hz  tip amplitude {amp:.4e} m  sign det J {sign:+d}",
              flush=True)
    stable_pick = [r for r in rows if r[3] > 0]
    unstable_pick = [r for r in rows if r[3] < 0]
    picks = []
    if unstable_pick:
        picks.append(("middle branch (det J < 0)", unstable_pick[len(unstable_pick) // 2]))
    if stable_pick:  # the largest-amplitude point with det J > 0 near the fold
        picks.append(("det J > 0", max(stable_pick, key=lambda r: r[4])))
    for label, (p, prob, U, sign, _amp) in picks:
        c0 = time.process_time()
        try:
            fl = hill_stability(prob, U, dyn, options=HillOptions(refine=refine))
            crit = fl.critical(2)
            stamp(f"{label}: {p.frequency_hz:.3f} Hz, Hill: "
                  f"{'stable' if fl.stable else 'unstable'}, largest |rho| "
                  f"{fl.max_multiplier:.4f}, critical {np.round(crit, 4)}, kinds "
                  f"{list(fl.kind[:4])}, reliable {fl.reliable}, neutral {fl.neutral}, "
                  f"{time.process_time() - c0:.1f} s CPU")
        except InputError as exc:  # the dense quadratic problem is too large: det J only
            stamp(f"{label}: {p.frequency_hz:.3f} Hz, Hill's spectrum not computed ({exc}); "
                  f"sign det J {sign:+d}"
                  + (": a real multiplier above 1, unstable" if sign < 0 else ""))
        if max_periods <= 0:
            continue
        c0 = time.process_time()
        chk = check_periodic(model, p.solution, max_periods=max_periods, condenser=cond)
        stamp(f"{label}: {p.frequency_hz:.3f} Hz, time integration: {chk.verdict} "
              f"(distance {chk.distance:.3g}, {chk.periods} periods, "
              f"{time.process_time() - c0:.0f} s CPU): {chk.message}")


if __name__ == "__main__":
    main()
