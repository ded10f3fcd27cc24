"""What the paper's beam's periodic state at 79 kHz is (issue 31): a state whose mean
tangential position the balance holds only weakly, reached by a slow drift.

The example ``salles2011-79khz-periodic`` (exact condensation, 7 harmonics, 128 samples,
``eps = "auto"``, Powell) is solved as the ``periodic`` analysis solves it; then

1. the balance's Jacobian ``J`` (930 x 930): its smallest singular values, and where its
   near-null vector lives (harmonic 0, tangential components: the rigid shift);
2. the real Floquet multiplier along that direction (:func:`fretwear.hb.slow_mode.slow_mode`);
3. the exact time integration (``Integrator``, 128 and 1024 steps a period) started from the
   periodic state with the whole beam shifted along x by -8, 0 and +8 um: the period mean of
   x(P_e) and its slope (the drift per period) after each 500 periods;
4. ``check_periodic`` from the state (1024 steps, 500 periods): verdict and distance of the
   vibration from the balance's.

Run: ``python studies/slow_mean_79khz.py [periods_128] [periods_1024]`` (default 3000 and
1500; about 2 minutes of CPU). Results: docs/studies/79khz-slow-mean.md.
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

from fretwear.analyses.common import basis_of, condenser_of, solve_options_of
from fretwear.analyses.run import load_case
from fretwear.examples import example_path
from fretwear.hb.dynamics import structure_dynamics
from fretwear.hb.options import PERIODIC
from fretwear.hb.penalty import penalty
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.reduce import condense
from fretwear.hb.slow_mode import slow_mode
from fretwear.hb.solution import initial_state
from fretwear.hb.stability import problem_of
from fretwear.io.case import build_model
from fretwear.timedomain.integrate import Integrator
from fretwear.timedomain.options import InitialState, IntegrationOptions
from fretwear.timedomain.stability import check_periodic


def stamp(text):
    print(f"[{time.strftime('%H:%M:%S')} load {os.getloadavg()[0]:.1f} "
          f"cpu {time.process_time():.0f} s] {text}", flush=True)


def drift(model, sol, U0, V0, shift, periods, steps):
    """Period means of x(P_e) from the state shifted rigidly along x by ``shift`` [m]."""
    U = U0.copy()
    U[0::model.dim] += shift
    integ = Integrator(model, sol.omega, IntegrationOptions(steps_per_period=steps),
                       InitialState(U0=U, V0=V0))
    means = []
    while len(means) < periods:
        raw = integ.run(500, 0, 500)
        means.extend(raw["mon_mean"][:, 0])
        mm = np.array(means)
        slope = np.polyfit(np.arange(200), mm[-200:], 1)[0]
        stamp(f"  {steps} steps, shift {shift * 1e6:+.0f} um: {len(mm)} periods, mean x(Pe) "
              f"{mm[-1] * 1e6:.4f} um, drift {slope:.3e} m/period")
    return slope, mm[-1]


def main():
    p128 = int(sys.argv[1]) if len(sys.argv) > 1 else 3000
    p1024 = int(sys.argv[2]) if len(sys.argv) > 2 else 1500
    case = load_case(example_path("salles2011-79khz-periodic"))
    model = build_model(case)
    an = case.analysis
    basis = basis_of(an)
    f = float(an["frequency"])
    cond = condenser_of(model, an, f, max(basis.harmonics))
    red = condense(model, f, basis.orders, condenser=cond)
    eps = penalty(an["eps"], model=model, reduced=red, condenser=cond)
    sol = solve_periodic(model, basis, frequency=f, options=solve_options_of(an, PERIODIC),
                         reduced=red, eps=eps, time_domain=None, condenser=cond)
    c = sol.observed["Pe"]
    stuck = int(np.all(sol.state == 1, axis=1).sum())
    stamp(f"solve: {sol.message}; mean x(Pe) {c[0, 0] * 1e6:.4f} um; interface mean "
          f"tangential position {sol.U[:, 1, 0].mean() * 1e6:.4f} um (spread "
          f"{np.ptp(sol.U[:, 1, 0]):.2e} m); nodes stuck all period {stuck}")
    prob = problem_of(model, sol, condenser=cond)
    U = sol.U.reshape(prob.m, prob.H)
    J = prob.residual(U, jacobian=True)[1]
    _, s, vt = np.linalg.svd(J)
    v = vt[-1].reshape(prob.nc, prob.d, prob.H)
    stamp(f"J: singular values {s[0]:.3e} (largest), {s[-2]:.3e}, {s[-1]:.3e} (smallest); "
          f"near-null vector: {np.sum(v[:, 1, 0] ** 2):.12f} of it on the tangential means, "
          f"spread of those {np.ptp(v[:, 1, 0]):.2e}")
    sm = slow_mode(prob, U, structure_dynamics(model, cond))
    stamp(f"slow mode: multiplier 1 {sm.multiplier - 1:+.4e}, relaxation {sm.periods:.3e} "
          f"periods, eigenvalue {sm.eigenvalue:.3e} of eps, rigid {sm.rigid:.12f}")
    print(sm.line())
    U0, V0 = initial_state(model, sol, cond)
    rows = []
    for steps, periods in ((128, p128), (1024, p1024)):
        for shift in (0.0, -8e-6, 8e-6):
            if periods > 0:
                rows.append((steps, shift, *drift(model, sol, U0, V0, shift, periods, steps)))
    for steps in (128, 1024):
        sel = [(m, d) for st, sh, d, m in rows if st == steps and sh != 0.0]
        if len(sel) == 2:
            (m1, d1), (m2, d2) = sel
            rate = (d1 - d2) / (m1 - m2)
            stamp(f"{steps} steps: relaxation per period from the two shifted starts "
                  f"{-rate:.3e} (balance: {1 - sm.multiplier:.3e})")
    chk = check_periodic(model, sol, max_periods=500, steps_per_period=1024, condenser=cond)
    stamp(f"check_periodic from the state (1024 steps): {chk.verdict}, distance "
          f"{chk.distance:.3g}: {chk.message}")


if __name__ == "__main__":
    main()
