"""Where and how the periodic balance of the 79 kHz wear run ends (docs/studies/79khz-wear.md).

The 79 kHz wear run of the paper's beam (example ``salles2011-79khz``) keeps its DLFT balance for
17 slow steps; the step from N = 1.075e7 cycles fails and the run goes on with time-averaged
rates (:func:`fretwear.wear.time_steps.time_domain_step`) that cost 3-5 s each instead of ~0.1 s.
This
script finds out whether the balance is lost because the solver needs smaller steps, because its
tolerance sits at the round-off floor, because of the discretisation (samples, harmonics), or
because the periodic branch ends:

1. runs the case to ``--max-cycles`` (default 1.6e7: past the first failure) in ``--workdir``,
   and takes the last balanced step before the first time-averaged one: wear ``W0``, balance
   ``U0``, and the wear increment ``dW`` the failed step asked for;
2. measures the round-off floor of the relative residual ``|f| / |Z U|`` at ``(W0, U0)`` (the
   residual of ``U0`` perturbed by 1e-15 relative noise): the solver tolerance must be above it;
3. continues the balance along ``W = W0 + s dW`` by natural-parameter steps (start ``ds =
   0.02``, divided by 4 on a failure, grown by 1.5 after an easy step) until ``ds < 1e-7``,
   with the case's tolerance, with 10x that tolerance and with twice the samples per period,
   and prints where each stops (``s*`` and the cycle count ``N0 + s* (N1 - N0)``), the
   iterations and the wall time;
4. integrates the structure in time (the exact Newmark/contact solver of the time-averaged
   steps) at ``W0`` from the balanced state and prints the response found and the largest
   difference of its wear rate from the balance's, relative to the largest rate.

Usage::

    python studies/balance_end_79khz.py [--workdir DIR] [--max-cycles 1.6e7]
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
import tempfile
import time
from pathlib import Path

KEY = "wear-79khz"


def run_to_failure(workdir: Path, max_cycles: float) -> Path:
    """The reproduction's 79 kHz case run (or resumed) to ``max_cycles``; its folder."""
    from fretwear.analyses.run import run_case
    from fretwear.paper.catalogue import RUNS, edit_case_text, run_case_text

    folder = workdir / KEY
    folder.mkdir(parents=True, exist_ok=True)
    spec = next(r for r in RUNS if r.key == KEY)
    text = edit_case_text(run_case_text(spec, False), "analysis",
                          {"max_cycles": float(max_cycles)})
    (folder / "case.toml").write_text(text, encoding="utf-8")
    run_case(folder / "case.toml", folder, progress=False, resume=True, echo=False)
    return folder


def continue_in_wear(sp, W0, dW, anchor, U0, *, tol, max_iter=60, ds_min=1e-7):
    """Natural-parameter continuation of the balance along ``W0 + s dW`` from ``s = 0``.

    Returns ``(s_reached, U_reached, iterations, failed_attempts, wall)``."""
    from fretwear.hb.options import SolveOptions

    s, U, ds = 0.0, U0, 0.02
    its = fails = 0
    t0 = time.perf_counter()
    while s < 1.0 and ds >= ds_min:
        s1 = min(1.0, s + ds)
        Ux, st = sp.solve_balance(W0 + s1 * dW, anchor, sp.shift_guess(U, (s1 - s) * dW),
                                  options=SolveOptions(tol=tol, max_iter=max_iter))
        its += st.iterations
        if st.success:
            s, U = s1, Ux
            if st.iterations <= 3:
                ds *= 1.5
        else:
            fails += 1
            ds /= 4.0
    return s, U, its, fails, time.perf_counter() - t0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workdir", type=Path, default=None,
                    help="folder of the run (default: a temporary folder)")
    ap.add_argument("--max-cycles", type=float, default=1.6e7)
    args = ap.parse_args(argv)
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    import numpy as np

    from fretwear.analyses.run import load_case
    from fretwear.hb.fourier import FourierBasis
    from fretwear.hb.options import SolveOptions
    from fretwear.hb.reduce import condense
    from fretwear.hb.solution import initial_state
    from fretwear.hb.solvers import SolveStats
    from fretwear.io.case import build_model
    from fretwear.timedomain.averaged_rate import time_averaged_rate
    from fretwear.timedomain.options import AveragingOptions
    from fretwear.wear import Rescue, SlowProblem, read_history, wear_coefficients

    with contextlib.ExitStack() as stack:
        workdir = args.workdir or Path(stack.enter_context(tempfile.TemporaryDirectory()))
        t0 = time.perf_counter()
        folder = run_to_failure(workdir, args.max_cycles)
        print(f"run to N = {args.max_cycles:.3g}: {time.perf_counter() - t0:.1f} s")
        h = read_history(folder / "wear-checkpoint.npz")
        averaged = np.flatnonzero(np.asarray(h.rescued) == Rescue.TIME_AVERAGED)
        if averaged.size == 0:
            print("the balance held to the end of the run: raise --max-cycles")
            return 1
        k = int(averaged[0])
        N0, N1 = float(h.cycles[k - 1]), float(h.cycles[k])
        print(f"balance lost at step {k}: from N0 = {N0:.4g} (last balanced step) to "
              f"N1 = {N1:.4g}")

        case = load_case(folder / "case.toml")
        model = build_model(case)
        a = case.analysis
        basis = FourierBasis.up_to(int(a["harmonics"]), int(a["n_samples"]))
        f_hz = float(a["frequency"])
        reduced = condense(model, f_hz, basis.orders)
        coef = wear_coefficients(model)
        sp = SlowProblem(model, reduced, basis, coef, eps=a.get("eps", "auto"))
        U0 = np.asarray(h.U[k - 1], float).reshape(sp.m, sp.H)
        anchor = np.asarray(h.anchor[k - 1], float)
        W0 = np.asarray(h.wear_depth[k - 1], float)
        dW = np.asarray(h.wear_depth[k], float) - W0
        tol = float(a["tol"])

        sp.set_state(W0, anchor)
        scale = sp.prob.scale(U0)
        rng = np.random.default_rng(0)
        floor = [np.linalg.norm(sp.balance(U0 * (1 + 1e-15 * rng.standard_normal(U0.shape)),
                                           False)[0]) / scale for _ in range(8)]
        print(f"round-off floor of |f|/|Z U| at N0 (1e-15 relative noise on U): "
              f"{min(floor):.2e} .. {max(floor):.2e} (tolerance {tol:.0e})")

        print("continuation of the balance along W0 + s dW (s = 1 is the failed step):")
        ends = []
        for label, spx, tolx in (
                (f"{basis.n_samples} samples, tol {tol:.0e}", sp, tol),
                (f"{basis.n_samples} samples, tol {10 * tol:.0e}", sp, 10 * tol),
                (f"{2 * basis.n_samples} samples, tol {tol:.0e}",
                 SlowProblem(model, reduced, FourierBasis(basis.harmonics, 2 * basis.n_samples),
                             coef, eps=a.get("eps", "auto")), tol)):
            Ustart = U0
            if spx is not sp:  # the balance with the finer sampling at N0 first
                Ustart, st = spx.solve_balance(W0, anchor, U0,
                                               options=SolveOptions(tol=tolx, max_iter=400))
                if not st.success:
                    print(f"  {label}: no balance at N0 ({st.message})")
                    continue
            s, Us, its, fails, wall = continue_in_wear(spx, W0, dW, anchor, Ustart, tol=tolx)
            ends.append((s, Us))
            print(f"  {label}: s* = {s:.6f}, N* = {N0 + s * (N1 - N0):.5g}; "
                  f"{its} iterations, {fails} failed attempts, {wall:.1f} s")

        ok = SolveStats(True, 0.0, 0, 0, 0, 0.0, "", "")
        s_end, U_end = ends[0]
        print("time integration (600 + 200 periods) started from the balance at:")
        for label, s, Ub in (("N0", 0.0, U0), ("N*", s_end, U_end)):
            W = W0 + s * dW
            sp.set_state(W, anchor)
            g = sp.rate(Ub)
            Ut, Vt = initial_state(model, sp.solution(Ub, W, anchor, ok))
            tr = time_averaged_rate(model, f_hz, basis, coef, W, U0=Ut, V0=Vt,
                                    options=AveragingOptions(settle=600, average=200))
            print(f"  {label} = {N0 + s * (N1 - N0):.5g}: {tr.kind}; its wear rate differs from "
                  f"the balance's by {np.abs(tr.g - g).max() / g.max():.3f} of the largest rate")
            if label == "N*":  # and on to N1 from there
                tr1 = time_averaged_rate(model, f_hz, basis, coef, W0 + dW,
                                         options=AveragingOptions(settle=600, average=200),
                                         U0=tr.U_end, V0=tr.V_end)
                print(f"  N1 = {N1:.5g} (continuing from N*): {tr1.kind}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
