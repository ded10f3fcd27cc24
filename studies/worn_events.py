"""Where the steps of a wear march (and of the worn state directly) go: at changes of the
contact-state pattern (events) or on the smooth stretches between them (issue 29).

For each case (the examples of ``benchmarks/worn_state.py``), the march to a worn-volume rate
of 1e-8 of the initial one and the direct solve (``fretwear.worn_state``, default options),
then for every accepted step of each:

* whether the step changed the slipping set (nodes that slip during the period), the open
  set (nodes separated during part of the period), and how many (node, time sample) pairs
  changed contact state (the finer pattern);
* the DLFT solves (Newton iterations and slow Jacobians, as counted by the march) and the
  rejected attempts;
* what limited its jump: ``rejected`` (the error test or a failed balance cut it), ``growth``
  (``dN lam_+`` at the growth limit of a growing mode of the slow Jacobian), ``error`` (the
  controller's proposal, error estimate >= 0.3 of the tolerance), ``ser`` (a relaxation step
  of the direct solve), else ``growth-cap`` (the controller's factor 5);
* the nonlinearity of the slow equation over the step, ``|g1 - g0 - Js dW| / |g1 - g0|``
  with the slow Jacobian ``Js`` at the step's start (0: the rate is linear in the wear over
  the step).

Printed: one line per step with ``--verbose``, and per case and run one summary line: steps,
DLFT solves, steps and solves at events, the number of event groups (runs of successive
event steps), the median nonlinearity of the smooth steps and of the event steps, and the
count of each limit. Run: ``python studies/worn_events.py [--cases ...] [--verbose]``.
Write-up: docs/studies/method-costs.md, "Events along the path".
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from worn_state import _setup  # noqa: E402

from fretwear.wear import simulate_wear  # noqa: E402
from fretwear.wear.options import GROWTH_LIMIT  # noqa: E402
from fretwear.wear.simulate import slow_setup  # noqa: E402
from fretwear.wear.worn_state import WornStateOptions, worn_state  # noqa: E402

CASES = ("salles2011-quasistatic", "stromberg1997", "stromberg1997-triangle")


def patterns(sp, h, k):
    """(slipping set, open set, time-sample pattern) of record ``k`` of history ``h``."""
    frac = h.state_fraction[k]
    U = np.asarray(h.U[k], float).reshape(sp.m, sp.H)
    sp.set_state(h.wear_depth[k], h.anchor[k])
    _, _, state, _ = sp.prob.time_law(U)
    return frac[:, 2] > 0, frac[:, 0] > 0, np.asarray(state).copy()


def table(sp, h, tol: float, relaxed: set, verbose: bool, label: str):
    """The per-step classification of history ``h`` (module docstring), summed up."""
    rows = []
    prev = patterns(sp, h, 0)
    for k in range(1, h.n_steps):
        cur = patterns(sp, h, k)
        slip = not np.array_equal(prev[0], cur[0])
        opened = not np.array_equal(prev[1], cur[1])
        switches = int(np.count_nonzero(prev[2] != cur[2]))
        fine = switches > 0
        sp.set_state(h.wear_depth[k - 1], h.anchor[k])
        U0 = np.asarray(h.U[k - 1], float).reshape(sp.m, sp.H)
        Js = sp.slow_jacobian(U0)
        g0, g1 = h.wear_rate[k - 1], h.wear_rate[k]
        dW = h.wear_depth[k] - h.wear_depth[k - 1]
        dg = float(np.max(np.abs(g1 - g0)))
        nonlin = float(np.max(np.abs(g1 - g0 - Js @ dW))) / dg if dg > 0 else 0.0
        lam = float(np.max(np.linalg.eigvals(Js).real))
        jump = float(h.jump[k])
        if k in relaxed:
            limit = "ser"
        elif h.rejected[k] > 0:
            limit = "rejected"
        elif lam > 0 and jump * lam >= 0.95 * GROWTH_LIMIT:
            limit = "growth"
        elif h.error_estimate[k] >= 0.3 * tol:
            limit = "error"
        else:
            limit = "growth-cap"
        rows.append((k, slip, opened, fine, int(h.newton_iterations[k]), int(h.rejected[k]),
                     limit, nonlin, jump, lam * jump, switches))
        if verbose:
            print(f"  {label} {k:3d} N={h.cycles[k]:.3e} dN={jump:.3e} lam dN={lam * jump:7.3f} "
                  f"slip {'X' if slip else '.'} open {'X' if opened else '.'} "
                  f"pattern {switches:4d} solves {h.newton_iterations[k]:2d} "
                  f"rej {h.rejected[k]} {limit:10s} nonlin {nonlin:.3g} "
                  f"nslip {int(cur[0].sum())}")
        prev = cur
    ev = [r for r in rows if r[1] or r[2]]
    groups = sum(1 for i, r in enumerate(rows) if (r[1] or r[2])
                 and (i == 0 or not (rows[i - 1][1] or rows[i - 1][2])))
    smooth = [r[7] for r in rows if not (r[1] or r[2])]
    evn = [r[7] for r in ev]
    limits = {x: sum(1 for r in rows if r[6] == x)
              for x in ("rejected", "growth", "error", "growth-cap", "ser")}
    total = int(h.newton_iterations.sum())
    print(f"  {label}: {len(rows)} steps, {total} solves; at events {len(ev)} steps, "
          f"{sum(r[4] for r in ev)} solves in {groups} groups; fine pattern changed on "
          f"{sum(1 for r in rows if r[3])} steps (median {np.median([r[10] for r in rows]):.0f} "
          f"sample switches a step); nonlinearity median smooth "
          f"{np.median(smooth) if smooth else 0:.3g}, events {np.median(evn) if evn else 0:.3g}"
          f"; limits {limits}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--verbose", action="store_true")
    args = ap.parse_args()
    for name in args.cases.split(","):
        model, basis, f_hz, quasi, opts, balance = _setup(name, 300)
        kw = {"frequency": f_hz, "quasi_static": quasi, "balance": balance}
        march = simulate_wear(model, basis, options=opts, **kw)
        direct = worn_state(model, basis, options=WornStateOptions(wear=opts), **kw)
        *_, sp = slow_setup(model, basis, f_hz, quasi, balance, opts, None, None)
        print(f"{name}: {model.contact.n_nodes} contact nodes")
        table(sp, march.history, opts.tolerance, set(), args.verbose, "march")
        dh = direct.history
        table(sp, dh, opts.tolerance, _relaxed(dh.records()), args.verbose, "direct")


def _relaxed(records) -> set:
    """The steps taken after the path had settled: the relaxation (SER) steps."""
    from fretwear.wear.worn_state import _settled

    return {k for k in range(1, len(records)) if _settled(records[:k], 0.01)}


if __name__ == "__main__":
    main()
