"""Paper Table 1: cost of "DLFT with wear" on the beam of section 4.2, quasi-static and 79 kHz.

Runs the beam (30 x 4 Q4, 7 harmonics, 128 samples per period, Archard k_w = 1e-11 1/Pa)
to the plateau of the worn volume with the default adaptive scheme of :mod:`fretwear.wear`
(linearly implicit Euler),
and prints slow steps, Newton iterations and wall time next to the paper's Table 1 (Matlab
R2009, Core i7 920, explicit Euler with jumps capped at 1e8 / 1e7 cycles), then the final worn
volume and maximum depth. The quasi-static profile is compared with a fine-jump explicit Euler
reference (jumps of 2e5 cycles, a tenth of the explicit stability limit, 15000 steps, 822 s
once: embedded below; ``--reference`` recomputes it).

The last two lines are ``wall_79khz_s=<seconds>`` and ``wall_quasistatic_s=<seconds>``
(``nan`` for a case that did not reach its plateau, with the reason printed above). The 79 kHz
run stops at ``--max-cycles-79khz`` (default 2e8) if it has no plateau before: where the
periodic balance fails it goes on with time-domain steps (docs/wear.md). A run continued from
the reproduction's 2e8 checkpoint reached a plateau at 1.03e10 cycles (about 3200 s of step
wall time); the run from scratch follows another path and had none by 2.28e10: past 1e8
cycles the path is chaotic (studies/sensitivity_79khz.py; docs/studies/79khz-wear.md).
``--max-cycles-79khz 4e10`` lets the run go on to a plateau if it finds one.

BLAS threads: one by default (``--threads`` to change). On a 2-core machine shared with other
jobs, multithreaded LU of the ~900-unknown Jacobians was 10x slower than single-threaded.

Usage::

    python benchmarks/paper_table1.py [--threads N] [--reference] [--tolerance 1e-2]
"""

from __future__ import annotations

import argparse
import os
import sys
import time

PAPER = {  # Table 1: computed cycles (slow steps), total Newton iterations, CPU time [s]
    "quasi-static": (1510, 4474, 861.0),
    "79 kHz": (6007, 13977, 6127.0),
}
#: quasi-static reference: explicit Euler, fixed jumps of 2e5 cycles, wear depth [pm] at
#: N = 3e9 cycles for the 31 contact nodes from x = 0 to x = L (computed once, 822 s)
REFERENCE_QS_PM = [
    0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
    807.545, 1132.0425, 1291.826, 1299.1695, 1240.3586, 1207.8493, 1397.5878, 349.6257,
    5589.0259, 9669.2548, 14118.3689, 18717.3189, 23353.0004, 27935.6952,
]
REFERENCE_JUMP = 2e5
N_QS = 3e9  # quasi-static: the reference's rate is then 1.1e-4 of the initial one


def beam():
    """The beam of the paper's section 4.2 (as src/fretwear/examples/beam-linear-frf.toml)."""
    from fretwear.examples.builders import paper_beam

    return paper_beam()


def run_case(name, model, basis, *, frequency, quasi_static, options):
    """Run one case; returns (result or None, wall [s], message)."""
    from fretwear.errors import ConvergenceError
    from fretwear.wear import RunControl, simulate_wear

    t0 = time.perf_counter()
    try:
        r = simulate_wear(model, basis, frequency=frequency, quasi_static=quasi_static,
                          options=options, run=RunControl(progress=sys.stderr.isatty()))
    except ConvergenceError as exc:
        return None, time.perf_counter() - t0, f"{name}: {exc}"
    return r, time.perf_counter() - t0, f"{name}: {r.message}"


def report(name, r, wall):
    import numpy as np

    from fretwear.wear import Rescue

    h = r.history
    steps, its = h.n_steps - 1, int(h.newton_iterations.sum())
    p = PAPER[name]
    print(f"{name:>12} | {steps:>8d} {its:>10d} {wall:>9.1f} | {p[0]:>8d} {p[1]:>10d} "
          f"{p[2]:>9.0f}")
    w = h.wear_depth[-1]
    vr = h.volume_rate / max(h.volume_rate[0], 1e-300)
    reached = np.flatnonzero(vr <= 1e-3)
    at = f"{h.cycles[reached[0]]:.3g}" if reached.size else "not reached"
    print(f"{'':>12}   N = {h.cycles[-1]:.4g} cycles, worn volume {h.worn_volume[-1]:.5e} m^3, "
          f"max depth {w.max():.5e} m at x = {r.final.coords[int(np.argmax(w)), 0]:.4g} m; "
          f"rate < 1e-3 x initial at N = {at}; rejected attempts {int(h.rejected.sum())}")
    td = int(np.sum(h.rescued == Rescue.TIME_AVERAGED))
    if td:
        print(f"{'':>12}   {td} steps took their wear rate from time integrations (no periodic "
              f"balance) from N = {h.cycles[np.argmax(h.rescued == Rescue.TIME_AVERAGED)]:.3g}"
              f"; "
              f"{int(np.sum(h.rescued == Rescue.TIME_START))} balances restarted from one")
    print(f"{'':>12}   explicit Euler stability limit at the start 2/rho = "
          f"{r.stability_jump:.3g} cycles; largest jump {h.jump.max():.3g} cycles")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int, default=1, help="BLAS threads (default 1)")
    ap.add_argument("--tolerance", type=float, default=1e-2, help="local error tolerance")
    ap.add_argument("--reference", action="store_true",
                    help="recompute the fine-jump explicit reference (~15 min)")
    ap.add_argument("--skip-79khz", action="store_true")
    ap.add_argument("--max-cycles-79khz", type=float, default=2e8,
                    help="stop the 79 kHz run here if it has no plateau before (default 2e8)")
    args = ap.parse_args(argv)
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[var] = str(args.threads)  # before numpy is imported

    import numpy as np

    from fretwear.hb.fourier import FourierBasis
    from fretwear.wear import WearOptions

    model = beam()
    basis = FourierBasis.up_to(7, 128)
    print("Salles et al. (2011) Table 1, beam of section 4.2: 7 harmonics, 128 samples")
    print(f"fretwear: adaptive linearly implicit Euler, tolerance {args.tolerance:g}; "
          f"BLAS threads {args.threads}; timings on a shared machine are noisy")
    print(f"{'case':>12} | {'steps':>8} {'Newton it':>10} {'wall [s]':>9} | "
          f"{'paper':>8} {'Newton it':>10} {'CPU [s]':>9}")
    walls = {}

    # quasi-static, to N = 3e9 (plateau)
    opts = WearOptions(tolerance=args.tolerance, max_cycles=N_QS, plateau_rate=0.0)
    r, wall, msg = run_case("quasi-static", model, basis, frequency=1.0, quasi_static=True,
                            options=opts)
    if r is not None and r.stop_reason == "max_cycles":
        report("quasi-static", r, wall)
        walls["qs"] = wall
        ref = np.array(REFERENCE_QS_PM) * 1e-12
        if args.reference:
            ref = reference_profile(model, basis)
        w = r.history.wear_depth[-1]
        print(f"{'':>12}   profile vs fine explicit reference (jumps {REFERENCE_JUMP:.0e}): "
              f"max |dW| = {np.abs(w - ref).max():.3e} m = "
              f"{np.abs(w - ref).max() / ref.max():.2%} of the max depth; worn volume "
              f"{float(model.contact.area @ w) / float(model.contact.area @ ref) - 1:+.2%}")
    else:
        print(f"quasi-static did not reach the plateau: {msg}")
        walls["qs"] = float("nan")

    # 79 kHz, to the plateau (rate below 1e-3 of the initial one)
    if args.skip_79khz:
        walls["79"] = float("nan")
    else:
        opts = WearOptions(tolerance=args.tolerance, plateau_rate=1e-3,
                           max_cycles=args.max_cycles_79khz)
        r, wall, msg = run_case("79 kHz", model, basis, frequency=79e3,
                                quasi_static=False, options=opts)
        if r is not None and r.stop_reason == "plateau":
            report("79 kHz", r, wall)
            walls["79"] = wall
        else:
            print(f"79 kHz did NOT reach the plateau: {msg}")
            if r is not None:
                report("79 kHz", r, wall)
                where = ("where the periodic solve failed" if r.stop_reason == "solver_failed"
                         else f"at {r.stop_reason} without a plateau")
                print(f"{'':>12}   (partial run: {wall:.1f} s; the figures above stop {where})")
            walls["79"] = float("nan")
    print(f"wall_79khz_s={walls['79']:.2f}")
    print(f"wall_quasistatic_s={walls['qs']:.2f}")
    return 0


def reference_profile(model, basis):
    """The quasi-static reference: explicit Euler, fixed jumps of 2e5 cycles, to N = 3e9."""
    import numpy as np

    from fretwear.wear import RunControl, WearOptions, simulate_wear

    t0 = time.perf_counter()
    r = simulate_wear(model, basis, frequency=1.0, quasi_static=True,
                      options=WearOptions(scheme="explicit", adaptive=False,
                                          initial_jump=REFERENCE_JUMP, max_cycles=N_QS,
                                          plateau_rate=0.0, max_steps=10**6),
                      run=RunControl(progress=sys.stderr.isatty()))
    w = r.history.wear_depth[-1]
    print(f"reference: {r.history.n_steps - 1} steps, {time.perf_counter() - t0:.0f} s; "
          f"profile [pm]: {np.round(w * 1e12, 4).tolist()}")
    return w


if __name__ == "__main__":
    sys.exit(main())
