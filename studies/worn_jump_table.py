"""From which step of the path does the stick-set jump land on the march's state (issue 29)?

For each case (the quasi-static examples of ``benchmarks/worn_state.py``): the march to a
worn-volume rate of 1e-8 of the initial one (the reference state ``Wm``), then the direct
solve's path (``fretwear.worn_state``, default options), and from EVERY record ``k`` of that
path the stick-set jump (:func:`fretwear.wear.stick_set.stick_set_state`, the active-set
iteration of up to 8 rounds). One line a record:

* ``k``, the path's cycles ``N``, the DLFT solves spent up to it (cumulative);
* the slipping set's size, whether it changed over the step, and the stuck set (nodes that
  carry load, pressure > 1e-3 of the largest, and do not slip) against the march's final
  stuck set: nodes stuck at ``k`` but not at the end (``+``), and at the end but not at ``k``
  (``-``);
* the jump: rounds, its DLFT solves, its distance to ``Wm`` (largest profile difference over
  the largest depth), how many of its worn nodes (the ones it unloads) differ from the
  march's (worn by more than 1e-6 of the deepest wear), its agreement with the jump from
  ``k - 1`` and the progress of the step ``k - 1 -> k`` towards that jump
  (:func:`fretwear.wear.worn_state.agreement`).

Then the first record from which every later jump lands within 1 % (the "safe" record) and
its share of the march's solves: the speedup a jump taken there could give at most (the
jump's own solves not counted); and, for a least progress of 0.25, 0.5, 0.9, where the rule
"jumps agree within 1e-3 and the step made that progress" first fires and how many wrong
jumps (over 1 %) it would take.

Run: ``python studies/worn_jump_table.py [--cases ...]``. Write-up:
docs/studies/worn-state-cost.md, "The stick-set jump along the path".
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from worn_state import _setup  # noqa: E402

from fretwear.wear import simulate_wear  # noqa: E402
from fretwear.wear.simulate import slow_setup  # noqa: E402
from fretwear.wear.stick_set import stick_set_state  # noqa: E402
from fretwear.wear.worn_state import WornStateOptions, agreement, worn_state  # noqa: E402

CASES = ("salles2011-quasistatic", "stromberg1997", "stromberg1997-triangle")


def stuck(h, k) -> np.ndarray:
    """Nodes that carry load and do not slip at record ``k`` of history ``h``."""
    p = h.pressure_mean[k]
    return (p > 1e-3 * p.max()) & ~(h.state_fraction[k][:, 2] > 0)


def table(name: str, verbose: bool = True) -> list[tuple]:
    """The per-record table of one case (module docstring): rows
    ``(k, N, solves, diff, rounds)``."""
    model, basis, f_hz, quasi, opts, balance = _setup(name, 300)
    kw = {"frequency": f_hz, "quasi_static": quasi, "balance": balance}
    c0 = time.process_time()
    march = simulate_wear(model, basis, options=opts, **kw)
    c_m = time.process_time() - c0
    c0 = time.process_time()
    direct = worn_state(model, basis, options=WornStateOptions(wear=opts), **kw)
    c_d = time.process_time() - c0
    *_, sp = slow_setup(model, basis, f_hz, quasi, balance, opts, None, None)
    hm, h = march.history, direct.history
    Wm = hm.wear_depth[-1]
    top, g0 = float(np.max(Wm)), float(np.max(h.wear_rate[0]))
    end_stuck = stuck(hm, hm.n_steps - 1)
    end_worn = Wm > 1e-6 * top
    n_march = int(hm.newton_iterations.sum())
    print(f"{name}: {model.contact.n_nodes} contact nodes; march {hm.n_steps - 1} steps, "
          f"{n_march} solves, processor {c_m:.2f} s; direct {h.n_steps - 1} steps, "
          f"{direct.dlft_solves} solves, processor {c_d:.2f} s, "
          f"{float(np.max(np.abs(direct.wear - Wm))) / top:.3g} from the march; "
          f"{int(end_stuck.sum())} stuck at the end")
    rows = []
    spent = 0
    prev = None
    before = None  # the jump from the record before
    for k in range(h.n_steps):
        spent += int(h.newton_iterations[k])
        slip = h.state_fraction[k][:, 2] > 0
        changed = prev is not None and not np.array_equal(prev, slip)
        prev = slip
        s = stuck(h, k)
        U = np.asarray(h.U[k], float).reshape(sp.m, sp.H)
        jump, its = stick_set_state(sp, h.wear_depth[k], U, h.anchor[k], h.wear_rate[k],
                                    g0=g0, options=opts.solve)
        if jump is None:
            diff, rounds, dworn = np.inf, 0, -1
        else:
            diff = float(np.max(np.abs(jump.W - Wm))) / top
            rounds = jump.rounds
            dworn = int(np.count_nonzero(jump.worn != end_worn))
        agree, progress = (agreement(h.wear_depth[k - 1], h.wear_depth[k], before.W, jump.W)
                           if jump is not None and before is not None else (np.inf, 0.0))
        before = jump
        rows.append((k, float(h.cycles[k]), spent, diff, rounds, agree, progress))
        if verbose:
            print(f"  {k:3d} N={h.cycles[k]:9.3e} solves {spent:4d} ({spent / n_march:5.1%}) "
                  f"slip {int(slip.sum()):3d}{'*' if changed else ' '} "
                  f"stuck {int(s.sum()):3d} (+{int(np.count_nonzero(s & ~end_stuck))} "
                  f"-{int(np.count_nonzero(~s & end_stuck))}) vrate "
                  f"{h.volume_rate[k] / h.volume_rate[0]:9.2e} | jump rounds {rounds} "
                  f"solves {its:3d} diff {diff:8.3g} worn-set diff {dworn} "
                  f"agree {agree:8.2g} progress {progress:8.2g}")
    ok = [r[3] <= 0.01 for r in rows]
    safe = next((i for i in range(len(rows)) if all(ok[i:])), None)
    if safe is None:
        print(f"  {name}: no record from which every jump lands within 1 %")
    else:
        k, N, solves, diff, *_ = rows[safe]
        print(f"  {name}: every jump from record {k} on (N = {N:.3g}, {solves} solves = "
              f"{solves / n_march:.1%} of the march's) lands within 1 %; best speedup in "
              f"solves {n_march / max(solves, 1):.3g}")
    for least in (0.25, 0.5, 0.9):
        hits = [r for r in rows if r[5] <= 1e-3 and r[6] >= least]
        if not hits:
            print(f"  {name}: agreement 1e-3 with progress >= {least}: no jump taken")
            continue
        k, N, solves, diff, *_ = hits[0]
        print(f"  {name}: agreement 1e-3 with progress >= {least}: first jump from record {k} "
              f"({solves} solves = {solves / n_march:.1%} of the march's), {diff:.3g} from "
              f"the march's state; wrong jumps it would take: "
              f"{sum(1 for r in hits if r[3] > 0.01)}")
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--quiet", action="store_true", help="summary lines only")
    args = ap.parse_args()
    for name in args.cases.split(","):
        table(name.strip(), not args.quiet)


if __name__ == "__main__":
    main()
